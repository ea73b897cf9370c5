//! The ambient occlusion methods: one folder each, and one registry line.
//!
//! A method's folder holds everything that is the method's own: its passes and their WGSL, the
//! [`Stage`] that puts them in the chain, its settings (units, ranges, defaults, validation and
//! its values in each [`Preset`]), and its CPU reference (re-exported by
//! [`crate::reference`]). The folder ends in one [`MethodInfo`], and the `registry!` below
//! lists every method by that value. Everything that names methods derives from the registry:
//! [`AoMethod`] itself, its names and help, the chain's timing spans ([`pass_names`]), the
//! shaders the naga test validates, the presets, and — in the front ends — the command line's
//! values, the bench's passes, `score`'s rows, the viewer's labels and Python's `methods()`.
//!
//! ```text
//!   method/<name>/mod.rs        the passes, the Stage, `pub(crate) const METHOD: MethodInfo`
//!   method/<name>/settings.rs   the settings, their descriptions (`setting::Setting`), presets
//!   method/<name>/reference.rs  the CPU reference, line by line the WGSL's arithmetic
//!   method/<name>/*.wgsl        the shaders
//! ```
//!
//! Adding a method: its folder and its line in `for_each_method!` (with its settings' field of
//! [`ChainSettings`] when it has settings of its own). Its settings' descriptions
//! ([`MethodInfo::settings`]) give the front ends its flags, keywords, controls and URL keys.

use crate::camera::FrameView;
use crate::settings::{ChainSettings, Preset};
use crate::targets::FrameTargets;
use crate::timing::Span;

pub mod line_ao;
pub mod raytraced;
pub mod setting;
pub mod ssao;
#[cfg(any(test, feature = "toy-method"))]
pub mod toy;
pub mod vo_area;
pub mod vo_line;

/// How a method builds its stage for a device and settings.
pub(crate) type BuildStage = fn(&wgpu::Device, &ChainSettings) -> Box<dyn Stage>;

/// Everything the library and the front ends know of a method besides its settings.
pub struct MethodInfo {
    /// The name on the command line, in `params.json`, in Python and in docs/reference.md.
    pub name: &'static str,
    /// What a method list in a user interface shows.
    pub label: &'static str,
    /// One line of help: what the method is and where it comes from.
    pub help: &'static str,
    /// Whether the method is screen-space AO in the chain, shown by `--grid` and the viewer's
    /// list among the others (the ray-traced truth, progressive and scene-bound, is not).
    pub screen_space: bool,
    /// The timing spans its stage can record, in chain order (docs/reference.md's names).
    pub spans: &'static [&'static str],
    /// Its WGSL files, by the name its passes compose them under, and the numbers its WGSL
    /// shares with its CPU reference, which Rust writes into the WGSL
    /// ([`crate::shader::CONSTANTS`]).
    pub library: crate::shader::Library,
    /// Its stage; `None` for a method that runs no pass (`none`).
    pub(crate) build: Option<BuildStage>,
    /// Whether what its stage allocates for a guard-banded frame of this size fits the device's
    /// limits (an [`crate::Error::TooLarge`] saying what does not), checked before a frame of
    /// that size is made. The targets a method alone reads and writes are its stage's own,
    /// allocated in [`Stage::resize`].
    pub(crate) fits: fn((u32, u32), &wgpu::Limits) -> Result<(), crate::Error>,
    /// Sets `preset`'s values of its own settings and the strength it is shown with.
    pub(crate) preset: fn(Preset, &mut ChainSettings),
    /// Checks its own settings in a chain's (every method's, whichever runs: settings are
    /// switched between methods), an [`crate::Error::InvalidSettings`] naming the one out of
    /// range.
    pub(crate) validate: fn(&ChainSettings) -> Result<(), crate::Error>,
    /// The levels of the G-buffer's ND pyramid its stage reads under those settings (1: the
    /// full-resolution maps alone).
    pub(crate) levels: fn(&ChainSettings) -> u32,
    /// Its settings as they describe themselves, from which the front ends make their flags,
    /// keywords, controls and URL keys ([`setting`]); [`ChainSettings::validate`] checks each
    /// value's range before the method's own validation runs. Empty for a method whose settings
    /// its front ends still list by hand.
    pub settings: &'static [setting::Setting],
    /// What a panel calls after one of its controls moved a value: the others changed so that
    /// the settings stay valid (SSAO's sphere kernel takes only its sample counts). The command
    /// line calls nothing: what it is given is checked, not changed.
    pub conform: fn(&mut ChainSettings),
    /// What `lineao bench` times of it, by docs/reference.md's names.
    pub bench: &'static [BenchPass],
}

/// A pass of `lineao bench` that times a method: its stage, built and prepared with the bench's
/// settings as [`BenchPass::settings`] changes them, on the bench's G-buffer.
pub struct BenchPass {
    /// The pass's name in `lineao bench` (docs/reference.md's).
    pub name: &'static str,
    /// Changes the bench's settings (the papers', LineAO's preset, and this method) for frame
    /// `frame` of the run: a sample count, a variant, a new seed each frame for a new picture.
    pub settings: fn(&mut ChainSettings, u32),
    /// Of the stage's spans, those timed as one, from the first's start to the last's end; the
    /// stage's others run untimed in the same submission (so without timestamp queries, where
    /// the bench times the submission, the pass reports its whole stage).
    pub spans: &'static [&'static str],
    /// Its stage when not the method's (`lineao-tap-floor`: LineAO's shader that only sums its
    /// taps).
    pub(crate) build: Option<BuildStage>,
}

impl BenchPass {
    /// A pass of the method's own stage.
    pub(crate) const fn of(
        name: &'static str,
        spans: &'static [&'static str],
        settings: fn(&mut ChainSettings, u32),
    ) -> BenchPass {
        BenchPass { name, settings, spans, build: None }
    }

    /// The stage it times, for `method` (whose registry entry lists it).
    pub fn stage(&self, method: AoMethod, device: &wgpu::Device, settings: &ChainSettings) -> Option<Box<dyn Stage>> {
        self.build.or(method.info().build).map(|build| build(device, settings))
    }

    /// The bench's settings for this pass of `method` in frame `frame`.
    pub fn settings_for(&self, method: AoMethod, bench: &ChainSettings, frame: u32) -> ChainSettings {
        let mut settings = ChainSettings { method, ..bench.clone() };
        (self.settings)(&mut settings, frame);
        settings
    }
}

/// Every method's bench passes, in the registry's order.
pub fn bench_passes() -> impl Iterator<Item = (AoMethod, &'static BenchPass)> {
    AoMethod::REGISTRY.iter().flat_map(|&m| m.info().bench.iter().map(move |pass| (m, pass)))
}

/// The registry: the methods, in the order front ends list them, each by its [`MethodInfo`]
/// and — when it has settings of its own — the field of [`ChainSettings`] that holds them
/// (`{ field: Type }`, the `--settings` JSON's key). A method is its folder and one line here.
///
/// The list is handed to a macro (`for_each_method!(callback)`): here `registry!` makes
/// [`AoMethod`] of it, and [`crate::settings`] makes [`ChainSettings`]'s fields.
macro_rules! for_each_method {
    ($callback:ident) => {
        $callback! {
            /// Plain lines (with the illuminated-lines specular), no occlusion.
            None => crate::method::NONE,
            /// LineAO (Eichelbaum et al. 2013).
            LineAo => crate::method::line_ao::METHOD { line_ao: crate::method::line_ao::LineAoSettings },
            /// Volumetric Obscurance with line samples (Loos & Sloan 2010, §4.1).
            VoLine => crate::method::vo_line::METHOD { vo: crate::method::vo_line::VoSettings },
            /// Volumetric Obscurance with area samples over a pyramid of depth moments (§4.2),
            /// with VO line's settings.
            VoArea => crate::method::vo_area::METHOD,
            /// Crytek SSAO (Mittring 2007), the LineAO paper's baseline, with its 4 × 4 blur.
            Ssao => crate::method::ssao::METHOD { ssao: crate::method::ssao::SsaoSettings },
            /// Ray-traced AO on the GPU, progressive: the ground truth ([`crate::truth`]) where
            /// the view rests. Rays go through the scene, not the screen, so it needs no guard band.
            RayTraced => crate::method::raytraced::METHOD { raytraced: crate::method::raytraced::RayTracedSettings },
            /// A method made by the registry alone, which the tests find everywhere methods are
            /// listed (feature `toy-method`, for tests only).
            #[cfg(any(test, feature = "toy-method"))]
            Toy => crate::method::toy::METHOD { toy: crate::method::toy::ToySettings },
        }
    };
}
pub(crate) use for_each_method;

/// Makes [`AoMethod`] of the registry.
macro_rules! registry {
    ($( $(#[doc = $doc:literal])* $(#[cfg($cfg:meta)])? $variant:ident => $info:path $({ $($own:tt)* })? ),+ $(,)?) => {
        /// Which ambient occlusion the chain computes: one variant per method of the registry
        /// ([`crate::method`]), each described by [`AoMethod::info`].
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum AoMethod {
            $( $(#[doc = $doc])* $(#[cfg($cfg)])? $variant, )+
        }

        impl AoMethod {
            /// Every method, in the registry's order.
            pub const REGISTRY: &'static [AoMethod] = &[$( $(#[cfg($cfg)])? AoMethod::$variant, )+];

            /// The methods built for tests only (behind a feature), which a user's build lacks:
            /// generated docs leave them out.
            pub const FOR_TESTS: &'static [AoMethod] = &[$( $( #[cfg($cfg)] AoMethod::$variant, )? )+];

            /// What the registry holds for the method.
            pub fn info(self) -> &'static MethodInfo {
                match self {
                    $( $(#[cfg($cfg)])? AoMethod::$variant => &$info, )+
                }
            }
        }
    };
}

for_each_method!(registry);

impl Default for AoMethod {
    /// LineAO.
    fn default() -> AoMethod {
        AoMethod::LineAo
    }
}

/// Plain lines: no pass, no settings.
const NONE: MethodInfo = MethodInfo {
    name: "none",
    label: "none",
    help: "Plain lines (with the illuminated-lines specular), no occlusion",
    screen_space: true,
    spans: &[],
    library: crate::shader::Library::SHARED,
    build: None,
    fits: fits_always,
    preset: |_, settings| settings.strength = 1.0,
    validate: valid_always,
    levels: one_level,
    settings: &[],
    conform: conform_always,
    bench: &[],
};

impl AoMethod {
    /// The name used on the command line and in `params.json`.
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// The screen-space methods, in the order `--grid` shows them (not the ray-traced truth,
    /// which is progressive and needs the scene).
    pub fn screen_space() -> impl Iterator<Item = AoMethod> {
        AoMethod::REGISTRY.iter().copied().filter(|m| m.info().screen_space)
    }

    /// The method called `name`.
    pub fn from_name(name: &str) -> Option<AoMethod> {
        AoMethod::REGISTRY.iter().copied().find(|m| m.name() == name)
    }

    /// Every method's name, comma-separated: what an error about an unknown one lists.
    pub fn names() -> String {
        AoMethod::REGISTRY.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
    }
}

crate::named::serde_by_name!(AoMethod);

/// The registry's names and help, as every other setting with a fixed set of values.
impl crate::named::Named for AoMethod {
    const VALUES: &'static [AoMethod] = AoMethod::REGISTRY;

    fn name(self) -> &'static str {
        self.info().name
    }

    fn help(self) -> &'static str {
        self.info().help
    }
}

impl std::fmt::Display for AoMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for AoMethod {
    type Err = String;

    fn from_str(name: &str) -> Result<AoMethod, String> {
        AoMethod::from_name(name).ok_or_else(|| format!("unknown method '{name}' (one of {})", AoMethod::names()))
    }
}

/// The spans of a timed frame, in chain order (docs/reference.md): the geometry, every method's, the
/// blur, object-space AO and the composite.
pub fn pass_names() -> Vec<&'static str> {
    let methods = AoMethod::REGISTRY.iter().flat_map(|m| m.info().spans.iter().copied());
    let mut names: Vec<&'static str> = std::iter::once("lines").chain(methods).collect();
    names.dedup();
    names.extend(["blur", "volume-ao", "composite", "transparency"]);
    names
}

/// How far from a pixel a stage reads, for the guard band (docs/reference.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reach {
    /// At most `radius_px` pixels (before any blur), on a pyramid of `levels` levels (the band
    /// is rounded to the deepest level's texel).
    Pixels {
        /// The reach in pixels.
        radius_px: f32,
        /// The pyramid's levels.
        levels: u32,
    },
    /// Without bound (it grows toward the far plane): the largest band allowed.
    Unbounded,
}

/// [`MethodInfo::fits`] of a method that allocates nothing the device could refuse.
pub(crate) fn fits_always(_: (u32, u32), _: &wgpu::Limits) -> Result<(), crate::Error> {
    Ok(())
}

/// [`MethodInfo::fits`] of a method's storage buffer of `bytes` for a guard-banded `size`:
/// more than the device's storage buffers take is [`crate::Error::TooLarge`], saying what
/// (`what`) needs it.
pub(crate) fn fits_storage(
    what: &str,
    size: (u32, u32),
    bytes: u64,
    limits: &wgpu::Limits,
) -> Result<(), crate::Error> {
    let max_storage = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    if bytes <= max_storage {
        return Ok(());
    }
    let message = format!(
        "{what} for {} x {} px (with the guard band) needs {bytes} bytes, more than the adapter's {max_storage} \
         byte storage buffers",
        size.0, size.1
    );
    Err(crate::Error::TooLarge { limit: crate::Limit::StorageBuffer, value: bytes, max: max_storage, message })
}

/// [`MethodInfo::conform`] of a method whose values are valid apart.
pub(crate) fn conform_always(_: &mut ChainSettings) {}

/// [`MethodInfo::validate`] of a method without settings.
pub(crate) fn valid_always(_: &ChainSettings) -> Result<(), crate::Error> {
    Ok(())
}

/// [`MethodInfo::levels`] of a method that reads the full-resolution maps alone.
pub(crate) fn one_level(_: &ChainSettings) -> u32 {
    1
}

/// What a method does in the chain: it reads the G-buffer in [`FrameTargets`] and writes `ao`,
/// between the geometry and the composite. The timing span names are docs/reference.md's.
///
/// Why a trait object and not an enum of stage types: a stage is called a handful of times per
/// frame (not per pixel), so dynamic dispatch costs nothing measurable, and the chain, the
/// guard band and the timings follow from the trait without naming a method.
pub trait Stage: wgpu::WasmNotSendSync + std::any::Any {
    /// Whether this stage, as built, computes `settings`' method (else the chain builds another).
    fn matches(&self, settings: &ChainSettings) -> bool;
    /// How far it reads for a frame seen as `unguarded` (the frame's size, no guard band).
    fn reach(&self, settings: &ChainSettings, unguarded: &FrameView) -> Reach;
    /// The spans it records, in order, under `settings` (of its method's [`MethodInfo::spans`]).
    fn spans(&self, settings: &ChainSettings) -> &'static [&'static str];
    /// Binds newly allocated targets, and allocates at their size what the stage alone reads
    /// and writes (checked by its method's size check in the registry).
    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets);
    /// Writes the frame's uniforms.
    fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings);
    /// Records the stage; `span(name)` times one of [`Stage::spans`].
    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    );
}

/// The stage of `settings`' method; `None` for a method without passes.
pub fn build(device: &wgpu::Device, settings: &ChainSettings) -> Option<Box<dyn Stage>> {
    settings.method.info().build.map(|build| build(device, settings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_round_trip() {
        for &method in AoMethod::REGISTRY {
            assert_eq!(AoMethod::from_name(method.name()), Some(method));
            assert_eq!(method.name().parse::<AoMethod>(), Ok(method));
            let same = AoMethod::REGISTRY.iter().filter(|m| m.name() == method.name()).count();
            assert_eq!(same, 1, "{method}");
        }
        assert!("gtao".parse::<AoMethod>().unwrap_err().contains("lineao, vo-line"));
    }

    #[test]
    fn every_span_is_timed_once_in_chain_order() {
        let names = pass_names();
        let mut unique = names.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{names:?}");
        for &method in AoMethod::REGISTRY {
            for span in method.info().spans {
                assert!(names.contains(span), "{method}: {span}");
            }
        }
        assert_eq!(names.first(), Some(&"lines"));
        // The transparent lines blend over the composite's picture: after it.
        assert_eq!(names[names.len() - 2..], ["composite", "transparency"]);
    }
}
