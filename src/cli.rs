//! The command line: the subcommands, over `render`'s and `score`'s arguments
//! ([`lineao_session::args`]).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use lineao::Colormap;
use lineao::lighting::LineShading;
use lineao_tracts::SceneKind;
// `render`'s and `score`'s arguments are the session's.
pub use lineao_session::args::*;

#[derive(Parser, Debug)]
#[command(name = "lineao", version, about = "Ambient occlusion for dense 3D lines (LineAO) on wgpu")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a tractography file or a built-in scene to a PNG.
    Render(Box<RenderArgs>),
    /// Describe a tractography file (docs/reference.md `lineao info --json`).
    Info(InfoArgs),
    /// Time loading .tck, .trk and .trx files against reading their bytes and against nibabel.
    BenchLoad(BenchLoadArgs),
    /// Convert between formats: reads any, writes .tck, .trk or .trx (by OUT's extension).
    Convert(ConvertArgs),
    /// Time every pass on a built-in scene (docs/reference.md `lineao bench --json`).
    Bench(BenchArgs),
    /// Open a window: orbit a tractogram and compare LineAO with the other methods side by side.
    View(Box<ViewArgs>),
    /// Score AO methods against the ray-traced truth on one G-buffer (table, --json, -o grid).
    Score(Box<ScoreArgs>),
}

#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Tractography file to open (any format `lineao info` reads); default a built-in scene.
    #[arg(conflicts_with = "scene")]
    pub file: Option<PathBuf>,
    /// Built-in scene [default: bundles].
    #[arg(long, value_parser = parse_scene)]
    pub scene: Option<SceneKind>,
    /// Approximate vertex count of the built-in scene [default: 400000].
    #[arg(long)]
    pub vertices: Option<usize>,
    /// The method shown first (as `render --method`).
    #[arg(long, default_value = "lineao", value_parser = Listed { parse: parse_method, values: Method::listed })]
    pub method: Method,
    /// Start in compare mode with these two methods (e.g. `lineao,ssao`).
    #[arg(long, value_name = "A,B", value_parser = parse_pair, conflicts_with = "method")]
    pub compare: Option<[Method; 2]>,
    /// Streamlines as lines or tubes.
    #[arg(long, value_enum, default_value_t = GeometryArg::Lines)]
    pub geometry: GeometryArg,
    /// Parameters: lineao's default (legible), fitted to the local truth (physical), the
    /// papers' values for dense tractography (paper, or dense), or for sparse streamlines
    /// (sparse; the viewer also draws them 3 px wide).
    #[arg(long, default_value = "legible", value_parser = parse_preset)]
    pub preset: lineao::Preset,
    /// How lines are lit (as `render --line-shading`).
    #[arg(long, value_parser = named::<LineShading>(), default_value = "specular")]
    pub line_shading: LineShading,
    /// Draw only the lines that can be seen, culled on the GPU against the last frame (`on`),
    /// or every line (`off`).
    #[arg(long, value_parser = parse_on_off, default_value = "on")]
    pub cull: bool,
    /// Where lines or tubes are culled, draw each visible piece at the coarsest level of detail
    /// within half a pixel of it (`on`), or every point (`off`: the full strip, every tube, exactly).
    #[arg(long, value_parser = parse_on_off, default_value = "on")]
    pub lod: bool,
    /// Cut the lines to a slab: AXIS (x, y, z or view), CENTRE and THICKNESS in world mm
    /// (`z,0,8`); `[` and `]` move it (see `render --slab`).
    #[arg(long, value_name = "AXIS,CENTRE,THICKNESS", value_parser = lineao_session::args::parse_slab, allow_hyphen_values = true)]
    pub slab: Option<lineao::Slab>,
    /// Lines seen through one another (see `render --alpha`; `t` turns it on and off).
    #[command(flatten)]
    pub transparency: lineao_session::args::TransparencyArgs,
    /// Anatomy: a NIfTI-1 or NIfTI-2 volume shown as slices with each dataset opened (see `render
    /// --volume`); the side panel moves them.
    #[arg(long, value_name = "NIFTI")]
    pub volume: Option<PathBuf>,
    /// Where the slices cut x, y and z (mm; `none` or `-` for none) [default: all three through the
    /// volume's centre].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_slices, allow_hyphen_values = true, requires = "volume")]
    pub slices: Option<[Option<f32>; 3]>,
    /// Show the voxels without data (0 or NaN) too (see `render --opaque-slices`; the side
    /// panel's checkbox; the page's `opaque-slices`).
    #[arg(long, requires = "volume")]
    pub opaque_slices: bool,
    /// Line color: `tangent`, R,G,B in [0, 1], or `field:NAME` (see `render --color`).
    #[arg(long, default_value = "tangent", value_parser = parse_color)]
    pub color: ColorArg,
    /// The colormap of `--color field:NAME`.
    #[arg(long, value_parser = named::<Colormap>(), default_value = "viridis")]
    pub colormap: Colormap,
    /// What to show: final, ao, normals, depth, zoom, level:K, pieces, frozen or culled (as
    /// `render --debug-view`; the viewer's debug view menu).
    #[arg(long, default_value = "final", value_parser = parse_debug_view)]
    pub debug_view: lineao::DebugView,
    /// Start with an orthographic camera.
    #[arg(long)]
    pub ortho: bool,
    /// Start the orbit camera at AZIMUTH and ELEVATION (degrees around the data's up) and ZOOM
    /// times the data's default distance: what a web page's link keeps of the view.
    #[arg(long, value_name = "AZIMUTH,ELEVATION,ZOOM", value_parser = lineao_session::cameras::parse_orbit)]
    pub orbit: Option<[f32; 3]>,
    /// Show each pass's GPU time over the image.
    #[arg(long)]
    pub timings: bool,
    /// Window size in points, WIDTHxHEIGHT.
    #[arg(long, default_value = "1400x900", value_parser = parse_size)]
    pub size: [u32; 2],
    /// Save the window as a PNG once N frames (--frames) have passed and the image is complete,
    /// then exit: scripted use, and tests under Xvfb.
    #[arg(long, value_name = "PNG")]
    pub screenshot: Option<PathBuf>,
    /// Pictures saved (File ▸ Save picture at K×…, and --screenshot) are the view rendered at K ×
    /// the image's size, by `render`'s own path from the same data, camera and settings (tiles
    /// past 4096 px); 1: --screenshot saves the window.
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub scale: u32,
    /// Record what the window shows into this movie (.apng, or .mp4, .webm… through ffmpeg), its
    /// frames as PNGs beside it: --frames of them once the image is complete, then exit (File ▸
    /// Record movie… and M record in the window).
    #[arg(long, value_name = "MOVIE", conflicts_with = "screenshot")]
    pub record: Option<PathBuf>,
    /// With --screenshot: UI frames to run at least before saving; with --record: the frames
    /// recorded.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: u32,
    /// The methods' own settings, from their descriptions (as `render`'s).
    #[command(flatten)]
    pub methods: lineao_session::method_args::MethodArgs,
    /// The streamlines shown (as `render`'s; the side panel changes them).
    #[command(flatten)]
    pub select: SelectArgs,
}

fn parse_size(s: &str) -> Result<[u32; 2], String> {
    let parse = |p: &str| p.trim().parse::<u32>().ok().filter(|v| (64..=16384).contains(v));
    match s.split_once(['x', 'X']).map(|(w, h)| (parse(w), parse(h))) {
        Some((Some(w), Some(h))) => Ok([w, h]),
        _ => Err(format!("expected WIDTHxHEIGHT between 64 and 16384, got '{s}'")),
    }
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Built-in scene.
    #[arg(long, default_value = "bundles", value_parser = parse_scene)]
    pub scene: SceneKind,
    /// Approximate vertex count of the scene.
    #[arg(long, default_value_t = 1_000_000)]
    pub vertices: usize,
    /// Seed of the built-in scene.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub width: u32,
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub height: u32,
    /// Timed frames per pass (after the warm-up).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Untimed frames first (pipeline compilation, caches).
    #[arg(long, default_value_t = 3)]
    pub warmup: u32,
    /// Vertical field of view in degrees [default: the scene's]. A narrower one fills more of
    /// the frame with lines (on lavapipe the screen-space passes cost more per pixel with lines
    /// than per background pixel).
    #[arg(long)]
    pub fov: Option<f32>,
    /// Disable LineAO's light attenuation (g_light = 1).
    #[arg(long)]
    pub no_light_attenuation: bool,
    /// LineAO's parameters: the preset of `render` (`legible` by default, as every front end;
    /// `paper` for the papers' values). The other methods keep the papers' values.
    #[arg(long, default_value = "legible", value_parser = parse_preset)]
    pub preset: lineao::Preset,
    /// Print docs/reference.md's JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Time with CPU wall clocks around submit + wait even where timestamp queries exist.
    #[arg(long)]
    pub no_timestamps: bool,
    /// Only these passes, comma-separated (default: all of them).
    #[arg(long, value_delimiter = ',', value_parser = parse_bench_pass)]
    pub passes: Vec<String>,
}

fn parse_bench_pass(s: &str) -> Result<String, String> {
    if is_pass(s) {
        Ok(s.to_string())
    } else {
        let all = [gpu_passes(), CPU_PASSES.to_vec()].concat();
        Err(format!("unknown pass '{s}' (one of {})", all.join(", ")))
    }
}

#[derive(Args, Debug)]
pub struct BenchLoadArgs {
    /// Approximate vertex count of the synthetic tractogram.
    #[arg(long, default_value_t = 10_000_000)]
    pub vertices: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Formats to write and load, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "tck,trk,trx", value_parser = ["tck", "trk", "trx"])]
    pub formats: Vec<String>,
    /// Runs per measurement (the median is reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
    /// Where to write the files (kept); default a temporary folder that is removed.
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// Skip the nibabel comparison.
    #[arg(long)]
    pub no_nibabel: bool,
    /// Print the measurements as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

// The passes `lineao bench --passes` names (its vocabulary, so the CLI needs nothing of the
// bench itself).
/// The bench's own GPU passes: the geometry and what every method shares.
const OWN_GPU_PASSES: [&str; 17] = [
    "lines",
    "lines-native-1px",
    "lines-full-strip",
    "lines-strip",
    "nd-pyramid",
    "lines-all",
    "lines-culled",
    "lines-culled-exact",
    "lines-compute",
    "cull",
    "composite",
    "bilateral",
    "tubes",
    "tubes-culled",
    "tubes-culled-exact",
    "nd-from-depth",
    "lines-transparent",
];

/// The GPU passes of one run: the bench's own, then every method's from the registry
/// ([`lineao::method::BenchPass`]), in its order.
pub fn gpu_passes() -> Vec<&'static str> {
    OWN_GPU_PASSES.into_iter().chain(lineao::method::bench_passes().map(|(_, pass)| pass.name)).collect()
}

/// The CPU passes, after the GPU's.
pub const CPU_PASSES: [&str; 7] =
    ["density-256", "sweep-256", "variance-volume-256", "bvh-build-1m", "bvh-upload", "raytraced-cpu-64", "select"];

/// Whether `name` is a pass of the benchmark.
pub fn is_pass(name: &str) -> bool {
    gpu_passes().contains(&name) || CPU_PASSES.contains(&name)
}
