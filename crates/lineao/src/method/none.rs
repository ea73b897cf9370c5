//! Plain lines: no pass, no settings — the picture every method darkens.

pub(crate) const METHOD: super::MethodInfo = super::MethodInfo {
    name: "none",
    label: "none",
    help: "Plain lines (with the illuminated-lines specular), no occlusion",
    screen_space: true,
    estimates: super::Estimate::Occlusion,
    traces_scene: false,
    spans: &[],
    library: crate::shader::Library::SHARED,
    build: None,
    fits: super::fits_always,
    own: super::info::NO_SETTINGS,
    bench: &[],
    variant: None,
    fit: None,
    #[cfg(feature = "reference")]
    reference: None,
};
