//! Pictures larger than the window (`--scale K`, File ▸ Save picture at K×…): the view on
//! screen rendered by `lineao render`'s own path at K × the image's size — tiles past 4096 px
//! ([`lineao_session::figure`]) — from the same data (read again), camera and chain settings,
//! on a thread of its own.

use std::path::PathBuf;

use clap::{Args, FromArgMatches};
use lineao::Projection;
use lineao_session::args::RenderArgs;

use super::worker::{Source, View};

/// `lineao render`'s arguments for `view` of `source` at `scale` × its size, written to
/// `output`: the camera as --eye, --target, --up and --fov (or --ortho), each panel's method
/// (two: --compare), the first panel's settings as --settings, the colour and the selection.
pub fn render_args(source: &Source, view: &View, scale: u32, output: PathBuf) -> Result<RenderArgs, String> {
    let mut argv: Vec<String> = Vec::new();
    let mut flag = |name: &str, value: String| argv.extend([format!("--{name}"), value]);
    match source {
        Source::File(path) => flag("file-placeholder", path.display().to_string()),
        Source::Scene { kind, vertices, seed } => {
            flag("scene", kind.name().to_string());
            flag("vertices", vertices.to_string());
            flag("seed", seed.to_string());
        }
        _ => return Err("a picture at a scale reads the data again: open it from a file".into()),
    }
    let vec3 = |v: glam::Vec3| format!("{},{},{}", v.x, v.y, v.z);
    flag("eye", vec3(view.camera.eye));
    flag("target", vec3(view.camera.target));
    flag("up", vec3(view.camera.up));
    match view.camera.projection {
        Projection::Perspective { fov_y_deg } => flag("fov", fov_y_deg.to_string()),
        Projection::Orthographic { height } => flag("ortho", height.to_string()),
    }
    let (width, height) = (view.size.0.saturating_mul(scale), view.size.1.saturating_mul(scale));
    flag("width", width.to_string());
    flag("height", height.to_string());
    let methods: Vec<String> = view
        .panels
        .iter()
        .map(|p| crate::cli::Method { screen: p.settings.method, volume: p.volume.as_ref().map(|v| v.method) }.name())
        .collect();
    match &methods[..] {
        [one] => flag("method", one.clone()),
        many => flag("compare", many.join(",")),
    }
    let first = view.panels.first().ok_or("nothing is shown")?;
    let mut settings = serde_json::to_value(&first.settings).map_err(|e| e.to_string())?;
    if let Some(object) = settings.as_object_mut() {
        object.remove("method");
    }
    flag("settings", settings.to_string());
    match view.scalar_field.as_deref() {
        None => {}
        Some(crate::args::GROUP_FIELD) => flag("color", "groups".into()),
        Some(name) if name.starts_with("volume:") || name.starts_with("tsf:") => flag("color", name.into()),
        Some(name) => flag("color", format!("field:{name}")),
    }
    let selection = &view.selection;
    if let Some((share, seed)) = selection.subset {
        flag("subset", share.to_string());
        flag("subset-seed", seed.to_string());
    }
    if let Some([lo, hi]) = selection.length {
        flag("length", format!("{lo},{hi}"));
    }
    if let Some((name, [lo, hi])) = &selection.field {
        flag("field", format!("{name},{lo},{hi}"));
    }
    for group in &selection.groups {
        flag("group", group.clone());
    }
    for (key, regions) in [("include", &selection.include), ("exclude", &selection.exclude)] {
        for region in regions {
            let text = match region {
                lineao_tracts::Region::Sphere { center: [x, y, z], radius } => format!("sphere:{x},{y},{z},{radius}"),
                lineao_tracts::Region::Box { min: [a, b, c], max: [d, e, f] } => format!("box:{a},{b},{c},{d},{e},{f}"),
            };
            flag(key, text);
        }
    }
    flag("output", output.display().to_string());
    // The file is the positional argument.
    let mut args: Vec<String> = Vec::new();
    let mut words = argv.into_iter();
    while let Some(word) = words.next() {
        match word.as_str() {
            "--file-placeholder" => args.extend(words.next()),
            _ => args.push(word),
        }
    }
    let command = RenderArgs::augment_args(clap::Command::new("render").no_binary_name(true));
    let matches = command.try_get_matches_from(&args).map_err(|e| e.to_string())?;
    RenderArgs::from_arg_matches(&matches).map_err(|e| e.to_string())
}

/// Renders `args` (from [`render_args`]) on a thread of its own: the picture's file, or why not.
pub fn save(args: RenderArgs) -> std::thread::JoinHandle<Result<PathBuf, String>> {
    std::thread::spawn(move || {
        let output = args.image.output.clone().unwrap_or_else(|| "lineao.png".into());
        lineao_session::figure::run(&args).map(|()| output).map_err(|e| format!("{e:#}"))
    })
}
