//! `render`'s and `score`'s arguments: every option with its help and default (clap derives
//! the command line from them, Python's keyword arguments deserialize into them:
//! [`crate::kwargs`]), and the parsers of their values.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use lineao::lighting::LineShading;
use lineao::{Colormap, Named, VoCombine};
use lineao_tracts::SceneKind;

#[derive(Args, Debug)]
pub struct ScoreArgs {
    /// The frame to score on: a file or --scene, the camera, the geometry and every method
    /// setting as for `render`; -o writes a labelled grid (per method its AO, the truth, the
    /// signed error).
    #[command(flatten)]
    pub render: RenderArgs,
    /// Methods to score, comma-separated [default: all of them].
    #[arg(long, value_delimiter = ',', value_parser = Listed { parse: parse_score_method, values: ScoreMethod::listed })]
    pub methods: Vec<ScoreMethod>,
    /// Print JSON (docs/reference.md `lineao score --json`) instead of a table.
    #[arg(long)]
    pub json: bool,
    /// The bundle-scale truth's reach (obscurance with the linear falloff, the second truth
    /// beside the local one of --ao-distance and --ao-falloff): world units or a share of the
    /// scene's longest side.
    #[arg(long, default_value = "20%", value_parser = parse_ao_distance)]
    pub bundle_distance: AoDistance,
    /// Calibrate: search each method's main parameters and strength for the least RMSE against
    /// the truth over every built-in scene and every tractogram under --data, --fit-views cameras
    /// each; fit on half the views, report on the other half.
    #[arg(long)]
    pub fit: bool,
    /// --fit: the folder searched for tractograms.
    #[arg(long, default_value = "../shared/data", requires = "fit")]
    pub data: PathBuf,
    /// --fit: cameras per scene, orbiting the scene's own about its up axis (even ones fit, odd
    /// ones report).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(2..=64), requires = "fit")]
    pub fit_views: u32,
}

/// A method `score` compares with the truth: a registry's method in its main form, or its
/// [`lineao::method::Variant`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScoreMethod {
    pub method: lineao::AoMethod,
    pub variant: Option<&'static lineao::method::Variant>,
}

impl ScoreMethod {
    /// What `score` compares, in the registry's order: every method with a picture of its own
    /// (not `none`), each one's variant after it.
    pub fn all() -> Vec<ScoreMethod> {
        let mut all = Vec::new();
        for &method in lineao::AoMethod::REGISTRY.iter().filter(|&&m| m != lineao::AoMethod::None) {
            all.push(ScoreMethod::main(method));
            if let Some(variant) = &method.info().variant {
                all.push(ScoreMethod { method, variant: Some(variant) });
            }
        }
        all
    }

    /// `method` in its main form.
    pub const fn main(method: lineao::AoMethod) -> ScoreMethod {
        ScoreMethod { method, variant: None }
    }

    pub fn name(&self) -> &'static str {
        self.variant.map_or(self.method.name(), |v| v.name)
    }

    /// Every row's name and help, for `--help`.
    pub fn listed() -> Vec<(&'static str, &'static str)> {
        let help = |m: ScoreMethod| match m.variant {
            Some(variant) => variant.help,
            None if m.method.info().traces_scene => {
                "The truth again with the next --ray-seed, traced on the GPU (on the CPU with --cpu)"
            }
            None => m.method.info().help,
        };
        ScoreMethod::all().into_iter().map(|m| (m.name(), help(m))).collect()
    }
}

pub fn parse_score_method(s: &str) -> Result<ScoreMethod, String> {
    ScoreMethod::all().into_iter().find(|m| m.name() == s).ok_or_else(|| {
        let names: Vec<_> = ScoreMethod::all().iter().map(|m| m.name()).collect();
        format!("unknown method '{s}' (one of {})", names.join(", "))
    })
}

/// A positive, finite number (a radius, a range).
pub fn parse_positive(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) => Err(format!("must be positive and finite, got {v}")),
        Err(e) => Err(format!("'{s}': {e}")),
    }
}

/// How far a truth's rays look: world units, or a share of the scene's longest side (`20%`,
/// LineVis's default reach), resolved against the scene's bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AoDistance {
    World(f32),
    /// A share in (0, 1] of the longest side of the scene's axis-aligned bounds.
    Share(f32),
}

impl AoDistance {
    /// The reach in world units in a scene whose bounds' longest side is `longest_side`.
    pub fn world(self, longest_side: f32) -> f32 {
        match self {
            AoDistance::World(d) => d,
            AoDistance::Share(s) => s * longest_side,
        }
    }
}

impl std::fmt::Display for AoDistance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AoDistance::World(d) => write!(f, "{d}"),
            AoDistance::Share(s) => write!(f, "{}%", s * 100.0),
        }
    }
}

pub fn parse_ao_distance(s: &str) -> Result<AoDistance, String> {
    match s.trim().strip_suffix('%') {
        Some(share) => match share.trim().parse::<f32>() {
            Ok(p) if p > 0.0 && p <= 100.0 => Ok(AoDistance::Share(p / 100.0)),
            Ok(p) => Err(format!("a share of the scene's longest side must be in (0 %, 100 %], got {p} %")),
            Err(e) => Err(format!("'{s}': {e} (a distance in world units, or a share such as 20%)")),
        },
        None => parse_positive(s)
            .map(AoDistance::World)
            .map_err(|e| format!("{e} (a distance in world units, or a share such as 20%)")),
    }
}

/// What `--method` and `--compare` name: a screen-space method (docs/reference.md: none, lineao,
/// ssao, vo-line, vo-area), object-space AO (sweep, variance-volume), or both (`lineao+sweep`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Method {
    pub screen: lineao::AoMethod,
    pub volume: Option<lineao::volume::VolumeMethod>,
}

impl Method {
    /// Every method the viewer lists and `--grid` shows (the grid all but the last, with
    /// LineAO's other variant inserted third), in that order: the registry's screen-space ones,
    /// the object-space ones, and LineAO with each object-space one.
    pub fn all() -> Vec<Method> {
        use lineao::volume::VolumeMethod;
        let screen = lineao::AoMethod::screen_space().map(|screen| Method { screen, volume: None });
        let volume = VolumeMethod::ALL.map(|v| Method { screen: lineao::AoMethod::None, volume: Some(v) });
        let both = VolumeMethod::ALL.map(|v| Method { screen: lineao::AoMethod::LineAo, volume: Some(v) });
        screen.chain(volume).chain(both).collect()
    }

    /// The single methods' names and help, for `--help`: the registry's, then the object-space
    /// ones (a sum such as `lineao+sweep` is parsed, not listed).
    pub fn listed() -> Vec<(&'static str, &'static str)> {
        use lineao::volume::VolumeMethod;
        let volume = |v: VolumeMethod| match v {
            VolumeMethod::Sweep => {
                "Object space: fast occlusion sweeping (Singh, Yuksel, House 2009) over a density volume"
            }
            VolumeMethod::VarianceVolume => {
                "Object space: variance occlusion maps (Penner & Mitchell 2008) over a density volume"
            }
        };
        let screen = lineao::AoMethod::REGISTRY.iter().map(|m| (m.name(), m.info().help));
        screen.chain(VolumeMethod::ALL.into_iter().map(|v| (v.name(), volume(v)))).collect()
    }

    pub fn name(&self) -> String {
        match (self.screen, self.volume) {
            (screen, None) => screen.name().to_string(),
            (lineao::AoMethod::None, Some(volume)) => volume.name().to_string(),
            (screen, Some(volume)) => format!("{}+{}", screen.name(), volume.name()),
        }
    }
}

pub fn parse_method(s: &str) -> Result<Method, String> {
    use lineao::volume::VolumeMethod;
    let screen = |name: &str| lineao::AoMethod::from_name(name);
    let unknown = || {
        let screen: Vec<_> = lineao::AoMethod::screen_space().map(|m| m.name()).collect();
        let volume: Vec<_> = VolumeMethod::ALL.iter().map(|m| m.name()).collect();
        format!(
            "unknown method '{s}' (one of {}, {}, or SCREEN+VOLUME such as lineao+sweep)",
            screen.join(", "),
            volume.join(", ")
        )
    };
    match s.split_once('+') {
        None => match (screen(s), VolumeMethod::from_name(s)) {
            (Some(screen), _) => Ok(Method { screen, volume: None }),
            (None, Some(volume)) => Ok(Method { screen: lineao::AoMethod::None, volume: Some(volume) }),
            (None, None) => Err(unknown()),
        },
        Some((a, b)) => match (screen(a.trim()), VolumeMethod::from_name(b.trim())) {
            (Some(lineao::AoMethod::None), Some(_)) => Err(format!("'{s}': name the volume method alone")),
            (Some(screen), Some(volume)) => Ok(Method { screen, volume: Some(volume) }),
            _ => Err(unknown()),
        },
    }
}

pub fn parse_pair(s: &str) -> Result<[Method; 2], String> {
    match s.split(',').collect::<Vec<_>>()[..] {
        [a, b] => match [parse_method(a.trim())?, parse_method(b.trim())?] {
            [a, b] if a == b => Err(format!("compare two different methods, got '{s}'")),
            pair => Ok(pair),
        },
        _ => Err(format!("expected two methods A,B, got '{s}'")),
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GeometryArg {
    /// Lines of a fixed width in pixels (--line-width).
    Lines,
    /// Tubes of a radius in world units (--tube-radius), ray-cast with true depth and normals.
    Tubes,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SkyArg {
    /// Light from every direction.
    Uniform,
    /// Light only from above (the octants toward the camera's up axis; +z, superior, for
    /// tractograms): a cloudy day.
    Cloudy,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VolumeNormal {
    /// The geometry term with each pixel's (view-dependent) line normal, as the paper does it.
    Pixel,
    /// The geometry term averaged over the normals around the tangent: view-independent.
    Tangent,
    /// No geometry term: every octant counts the same (view-independent).
    None,
}

/// `lineao render`'s arguments (and `score`'s frame), in groups: each option's name, help and
/// default are here once; clap derives the command line from them, Python's keyword
/// arguments deserialize into them ([`crate::kwargs`]: the groups' fields are the keywords).
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[serde(default)]
pub struct RenderArgs {
    /// Tractography file to render (any format `lineao info` reads) instead of a built-in scene.
    pub file: Option<PathBuf>,
    #[command(flatten)]
    #[serde(flatten)]
    pub source: SourceArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub shown: ShownArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub image: ImageArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub style: StyleArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub context: ContextArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub select: SelectArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub camera: CameraArgs,
    /// The methods' settings that describe themselves (`lineao::method::setting`).
    #[command(flatten)]
    #[serde(flatten)]
    pub methods: crate::method_args::MethodArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub chain: ChainArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub volume: VolumeArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub truth: TruthArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub figure: FigureArgs,
}

/// Where the streamlines come from: a built-in scene (the file is the positional argument).
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Source")]
#[serde(default)]
pub struct SourceArgs {
    /// Built-in scene.
    #[arg(long, default_value = "bundles", value_parser = parse_scene)]
    #[serde(deserialize_with = "crate::kwargs::scene")]
    pub scene: SceneKind,
    /// Approximate vertex count of the built-in scene [default: 400000].
    #[arg(long)]
    pub vertices: Option<usize>,
    /// Seed of the built-in scene.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// What is shown: the method or methods, the preset and typed settings, and the shorthands for the shown method.
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Method")]
#[serde(default)]
pub struct ShownArgs {
    /// Ambient occlusion method: one of the list, or a screen-space method with an object-space
    /// one, e.g. lineao+sweep (see --volume-combine).
    #[arg(long, default_value = "lineao", value_parser = Listed { parse: parse_method, values: Method::listed })]
    #[serde(deserialize_with = "crate::kwargs::method")]
    pub method: Method,
    /// Split screen: method A on the left, B on the right, a labelled divider (e.g.
    /// `lineao,ssao`).
    #[arg(long, value_name = "A,B", value_parser = parse_pair, conflicts_with = "grid")]
    #[serde(deserialize_with = "crate::kwargs::opt_pair")]
    pub compare: Option<[Method; 2]>,
    /// Every method in one labelled image (a grid of --width × --height tiles, three a row:
    /// the screen-space methods with LineAO's `reference` variant third, the object-space ones
    /// and lineao+sweep).
    #[arg(long)]
    pub grid: bool,
    /// Parameter set: `legible` (each method's strength and reach chosen so that visibly darker
    /// lines lie deeper, `lineao score --fit`), `physical` (fitted to binary AO within 2 mm, was
    /// `calibrated`: faint) or `paper` (the papers' values). Explicit options win.
    #[arg(long, default_value = "legible", value_parser = parse_preset)]
    #[serde(deserialize_with = "crate::kwargs::preset")]
    pub preset: lineao::Preset,
    /// Settings over the preset and every other option: `lineao::ChainSettings` as JSON, a file
    /// or the text itself (starting with `{`). Only the keys it names change, e.g.
    /// `{"ssao": {"samples": 12}, "strength": 0.8}` (docs/render.md); not `method`, which
    /// --method, --compare and --grid choose.
    #[arg(long, value_name = "FILE|JSON", value_parser = parse_settings)]
    #[serde(deserialize_with = "crate::kwargs::opt_settings")]
    pub settings: Option<SettingsPatch>,
    /// AO strength in the composite [default: the preset's for the method; paper 1].
    #[arg(long)]
    pub strength: Option<f32>,
    /// The shown method's samples (each panel's with --grid or --compare): --ssao-samples,
    /// --vo-samples or --vo-area-samples, whichever method it shows.
    #[arg(long)]
    pub samples: Option<u32>,
    /// The shown method's sphere radius: --ssao-radius or --vo-radius, whichever --method names
    /// (with --grid or --compare, both).
    #[arg(long, value_parser = parse_positive)]
    #[serde(deserialize_with = "crate::kwargs::opt_positive")]
    pub radius: Option<f32>,
}

/// The picture: its file and size, the debug view, the dump of every input, timings.
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Image")]
#[serde(default)]
pub struct ImageArgs {
    /// Output PNG [default: lineao.png; `score`: no grid].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The picture's width in pixels; past the device's textures it is rendered as tiles
    /// (--tile).
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE as i64))]
    pub width: u32,
    /// The picture's height in pixels.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE as i64))]
    pub height: u32,
    /// What to show: final, ao, normals, depth, zoom, level:K (pyramid level K), pieces (the
    /// final image, each culled piece of line colored by its level of detail: blue every point,
    /// green every 2nd, orange every 4th, red every 8th; with `--cull on`), frozen (pieces, the
    /// cull frozen after its first frame) or culled (frozen, every piece drawn: those it left out
    /// light gray outside the view, purple behind what it drew).
    #[arg(long, default_value = "final", value_parser = parse_debug_view)]
    #[serde(deserialize_with = "crate::kwargs::debug_view")]
    pub debug_view: lineao::DebugView,
    /// Write the method's inputs and output as .npy files and params.json into this folder.
    #[arg(long)]
    pub dump: Option<PathBuf>,
    /// Print the time of each pass (GPU timestamps, or the frame's CPU wall time without them).
    #[arg(long)]
    pub timings: bool,
    /// With `--timings`: time this many frames of the same picture and print each pass's median
    /// (and the frames' sums' median, least and most): single frames on lavapipe vary by ±15 %.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub timed_frames: u32,
    /// With `--timings`: also time the same picture with these settings changed (as
    /// `--settings`, e.g. `{"slices": null}` for the picture without its anatomy slices), its
    /// frames interleaved with the picture's in this one run, and print what the change costs.
    #[arg(long, value_name = "FILE|JSON", value_parser = parse_settings, requires = "timings")]
    #[serde(deserialize_with = "crate::kwargs::opt_settings")]
    pub timings_against: Option<SettingsPatch>,
    /// Draw the colour bar of `--color field:NAME` or `volume:FILE` with its range's numbers
    /// into the picture (bottom left).
    #[arg(long)]
    pub legend: bool,
}

/// How the streamlines and surfaces are drawn.
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Drawing")]
#[serde(default)]
pub struct StyleArgs {
    /// Line width in pixels.
    #[arg(long, default_value_t = 2.0)]
    pub line_width: f32,
    /// Streamlines as lines or tubes.
    #[arg(long, value_enum, default_value_t = GeometryArg::Lines)]
    #[serde(deserialize_with = "crate::kwargs::geometry")]
    pub geometry: GeometryArg,
    /// Tubes: radius in world units [default: 0.5 mm].
    #[arg(long)]
    pub tube_radius: Option<f32>,
    /// Tubes: the file's per-vertex field holding each vertex's radius in world units (e.g. a
    /// TRX dpv or a .trk scalar); vertices without a positive value take --tube-radius.
    #[arg(long, requires = "file")]
    pub tube_radius_field: Option<String>,
    /// Lines: the illuminated-lines specular on top of the AO (`specular`, the paper's), or
    /// diffuse and specular averaged over the visible half of the line's cylinder (`cylinder`:
    /// Mallo et al. 2005).
    #[arg(long, value_parser = named::<LineShading>(), default_value = "specular")]
    pub line_shading: LineShading,
    /// Context surface shown with the tracts (OBJ or glTF triangles, optionally gzipped); may be
    /// given several times. It occludes the lines and is occluded, and the AO sees it.
    #[arg(long = "surface", value_name = "MESH")]
    #[serde(deserialize_with = "crate::kwargs::paths")]
    pub surfaces: Vec<PathBuf>,
    /// Linear RGB of the context surfaces.
    #[arg(long, default_value = "0.8,0.8,0.8", value_parser = parse_vec3)]
    #[serde(deserialize_with = "crate::kwargs::vec3")]
    pub surface_color: [f32; 3],
    /// Line color: `tangent` (|T| as RGB), R,G,B in [0, 1], `field:NAME` (the file's
    /// per-vertex field NAME, or per-streamline one over its vertices, through --colormap, its 2nd to 98th percentile spanning the map), or
    /// `volume:FILE` (a NIfTI volume sampled at every vertex, trilinear between voxel centres;
    /// gray outside it), `tsf:FILE` (an MRtrix track scalar file written beside the .tck: a
    /// value a vertex, its streamlines the tractogram's), or `groups` (TRX groups, a colour each;
    /// gray outside every group).
    #[arg(long, default_value = "tangent", value_parser = parse_color)]
    #[serde(deserialize_with = "crate::kwargs::color")]
    pub color: ColorArg,
    /// The colormap of `--color field:NAME`.
    #[arg(long, value_parser = named::<Colormap>(), default_value = "viridis")]
    pub colormap: Colormap,
    /// Background color R,G,B in [0, 1].
    #[arg(long, default_value = "1,1,1", value_parser = parse_vec3)]
    #[serde(deserialize_with = "crate::kwargs::vec3")]
    pub background: [f32; 3],
    /// Draw only the lines that can be seen, culled on the GPU against the frame before (`on`:
    /// the picture is the second frame, at the levels of detail the first found), or every
    /// line (`off`) [default: culled from 8 M points (a whole brain), one frame that culls
    /// against every 8th cluster drawn first, the picture every line draws with the full
    /// strip; below, every line; `--timings` says which; the viewer culls].
    #[arg(long, value_parser = parse_on_off)]
    pub cull: Option<bool>,
    /// Where lines or tubes are culled, draw each visible piece at the coarsest level of detail
    /// within half a pixel of it (`on`), or every point (`off`: the full strip, every tube,
    /// exactly) [default: on].
    #[arg(long, value_parser = parse_on_off)]
    pub lod: Option<bool>,
}

/// What the tracts are shown in: anatomy slices, a slab.
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Context")]
#[serde(default)]
pub struct ContextArgs {
    /// Anatomy: a NIfTI-1 or NIfTI-2 volume (.nii, .nii.gz) placed by its sform (else qform, else voxel
    /// sizes: nibabel's rule), shown as slices that occlude the lines and that their AO darkens
    /// (the bilateral blur then smooths the slices' pixels: the occlusion's sampling noise is
    /// grain on a slice).
    #[arg(long, value_name = "NIFTI")]
    pub volume: Option<PathBuf>,
    /// Where the sagittal, coronal and axial slices cut x, y and z (world mm, RAS+), `none` (or
    /// `-`) for no slice on an axis: `0,-18,10`, `none,none,10` [default: all three through the
    /// volume's centre].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_slices, allow_hyphen_values = true, requires = "volume")]
    #[serde(deserialize_with = "crate::kwargs::opt_slices")]
    pub slices: Option<[Option<f32>; 3]>,
    /// The slices' values at the colormap's ends [default: the volume's 2nd and 98th percentiles].
    #[arg(long, value_name = "MIN,MAX", value_parser = parse_window, allow_hyphen_values = true, requires = "volume")]
    #[serde(deserialize_with = "crate::kwargs::opt_window")]
    pub window: Option<[f32; 2]>,
    /// The slices' colormap.
    #[arg(long, value_parser = named::<Colormap>(), default_value = "gray")]
    pub slice_colormap: Colormap,
    /// Show the voxels that hold no data (0 or NaN) as the colormap's low end too [default: a
    /// slice is transparent where they weigh half its sample: the data's cross-section only].
    #[arg(long, requires = "volume")]
    pub opaque_slices: bool,
    /// Cut the lines to a slab: AXIS (x, y, z, or view: facing the eye, the centre measured
    /// from the middle of the scene), its CENTRE and THICKNESS in world mm: `z,0,8`.
    #[arg(long, value_name = "AXIS,CENTRE,THICKNESS", value_parser = parse_slab, allow_hyphen_values = true)]
    #[serde(deserialize_with = "crate::kwargs::opt_slab")]
    pub slab: Option<lineao::Slab>,
    /// Lines seen through one another.
    #[command(flatten)]
    #[serde(flatten)]
    pub transparency: TransparencyArgs,
}

/// Lines seen through one another (`render`, `view`, the page, Python): their opacities and
/// the K of the K-buffer.
#[derive(Args, Clone, Debug, Default, serde::Deserialize)]
#[serde(default)]
pub struct TransparencyArgs {
    /// Opacity of the streamlines shown (the selected ones), in (0, 1]: below 1 they are seen
    /// through one another, composited in depth order, each darkened by its object-space AO
    /// (with `--method sweep`, `lineao+sweep`, …; lit but unoccluded without) [default: 1,
    /// opaque with the method's AO].
    #[arg(long, value_parser = parse_alpha)]
    pub alpha: Option<f32>,
    /// Opacity of the streamlines the selection leaves out, in [0, 1]: above 0 they stay as a
    /// transparent context around the selected ones (focus + context) [default: 0, hidden].
    #[arg(long, value_parser = parse_unit)]
    pub context_alpha: Option<f32>,
    /// Transparent fragments per pixel composited exactly, nearest first (the K-buffer's K,
    /// 1–16; those behind are blended into an approximate tail; 12 bytes a pixel each)
    /// [default: 8].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub layers: Option<u32>,
}

impl TransparencyArgs {
    /// The transparency these flags ask for, or none where every line is opaque.
    pub fn settings(&self) -> Option<lineao::TransparencySettings> {
        if self.alpha.is_none() && self.context_alpha.is_none() {
            return None;
        }
        let defaults = lineao::TransparencySettings::default();
        Some(lineao::TransparencySettings {
            alpha: self.alpha.unwrap_or(defaults.alpha),
            context_alpha: self.context_alpha.unwrap_or(defaults.context_alpha),
            layers: self.layers.unwrap_or(defaults.layers),
        })
    }
}

/// Which streamlines are shown (`lineao_tracts::selection`): each rule keeps fewer.
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Selection")]
#[serde(default)]
pub struct SelectArgs {
    /// Show a random share of the streamlines (0–1, or N%), the same ones for the same
    /// --subset-seed.
    #[arg(long, value_parser = parse_share)]
    #[serde(deserialize_with = "crate::kwargs::opt_share")]
    pub subset: Option<f64>,
    /// The seed of --subset.
    #[arg(long, default_value_t = 0)]
    pub subset_seed: u64,
    /// Show the streamlines whose arc length in world mm lies in MIN,MAX.
    #[arg(long, value_name = "MIN,MAX", value_parser = parse_window)]
    #[serde(deserialize_with = "crate::kwargs::opt_window")]
    pub length: Option<[f32; 2]>,
    /// Show the streamlines whose per-streamline field NAME (TRX dps, .trk property) lies in
    /// MIN,MAX.
    #[arg(long, value_name = "NAME,MIN,MAX", value_parser = parse_field_range, allow_hyphen_values = true)]
    #[serde(deserialize_with = "crate::kwargs::opt_field_range")]
    pub field: Option<(String, [f32; 2])>,
    /// Show the streamlines of this group (TRX groups); may be given several times (any of them).
    #[arg(long = "group", value_name = "NAME")]
    #[serde(deserialize_with = "crate::kwargs::strings")]
    pub groups: Vec<String>,
    /// Show only the streamlines that pass through this region (`sphere:X,Y,Z,R` or
    /// `box:X0,Y0,Z0,X1,Y1,Z1`, world mm); several: through every one (mrview's rule).
    #[arg(long = "include", value_name = "REGION", value_parser = parse_region, allow_hyphen_values = true)]
    #[serde(deserialize_with = "crate::kwargs::regions")]
    pub include: Vec<lineao_tracts::Region>,
    /// Hide the streamlines that pass through this region; may be given several times.
    #[arg(long = "exclude", value_name = "REGION", value_parser = parse_region, allow_hyphen_values = true)]
    #[serde(deserialize_with = "crate::kwargs::regions")]
    pub exclude: Vec<lineao_tracts::Region>,
}

impl SelectArgs {
    /// Its keywords (the options' ids, as `render` takes them from Python).
    pub fn keywords() -> Vec<String> {
        let command = SelectArgs::augment_args(clap::Command::new("select"));
        command.get_arguments().map(|a| a.get_id().to_string()).collect()
    }

    /// The selection these flags ask for, or none where they keep every streamline.
    pub fn selection(&self) -> Option<std::sync::Arc<lineao_tracts::Selection>> {
        let selection = lineao_tracts::Selection {
            subset: self.subset.map(|share| (share, self.subset_seed)),
            length: self.length,
            field: self.field.clone(),
            groups: self.groups.clone(),
            include: self.include.clone(),
            exclude: self.exclude.clone(),
        };
        (!selection.is_everything()).then(|| std::sync::Arc::new(selection))
    }
}

/// `--subset`: a share in [0, 1], or a percentage `N%`.
pub fn parse_share(s: &str) -> Result<f64, String> {
    let (text, scale) = match s.strip_suffix('%') {
        Some(percent) => (percent, 0.01),
        None => (s, 1.0),
    };
    match text.trim().parse::<f64>() {
        Ok(v) if (0.0..=1.0).contains(&(v * scale)) => Ok(v * scale),
        _ => Err(format!("expected a share in [0, 1] or a percentage, got '{s}'")),
    }
}

/// `--field`: NAME,MIN,MAX.
pub fn parse_field_range(s: &str) -> Result<(String, [f32; 2]), String> {
    let Some((name, range)) = s.split_once(',').filter(|(name, _)| !name.is_empty()) else {
        return Err(format!("expected NAME,MIN,MAX, got '{s}'"));
    };
    Ok((name.to_string(), parse_window(range)?))
}

/// `--include`/`--exclude`: `sphere:X,Y,Z,R` or `box:X0,Y0,Z0,X1,Y1,Z1`.
pub fn parse_region(s: &str) -> Result<lineao_tracts::Region, String> {
    let numbers = |text: &str| -> Result<Vec<f32>, String> {
        text.split(',')
            .map(|p| p.trim().parse::<f32>().ok().filter(|v| v.is_finite()).ok_or(format!("'{p}' is not a number")))
            .collect()
    };
    match s.split_once(':') {
        Some(("sphere", rest)) => match numbers(rest)?[..] {
            [x, y, z, r] if r > 0.0 => Ok(lineao_tracts::Region::Sphere { center: [x, y, z], radius: r }),
            _ => Err(format!("expected sphere:X,Y,Z,R with R > 0, got '{s}'")),
        },
        Some(("box", rest)) => match numbers(rest)?[..] {
            [x0, y0, z0, x1, y1, z1] => Ok(lineao_tracts::Region::Box {
                min: [x0.min(x1), y0.min(y1), z0.min(z1)],
                max: [x0.max(x1), y0.max(y1), z0.max(z1)],
            }),
            _ => Err(format!("expected box:X0,Y0,Z0,X1,Y1,Z1, got '{s}'")),
        },
        _ => Err(format!("expected sphere:X,Y,Z,R or box:X0,Y0,Z0,X1,Y1,Z1, got '{s}'")),
    }
}

/// `--slices`: three positions, each a number, or `none` (docs/reference.md) or `-` for no slice.
pub fn parse_slices(s: &str) -> Result<[Option<f32>; 3], String> {
    let parts: Vec<Option<f32>> = s
        .split(',')
        .map(|p| match p.trim() {
            "-" | "" => Ok(None),
            p if p.eq_ignore_ascii_case("none") => Ok(None),
            p => match p.parse::<f32>() {
                Ok(v) if v.is_finite() => Ok(Some(v)),
                _ => Err(format!("'{p}' is neither a position in mm nor 'none' (or '-')")),
            },
        })
        .collect::<Result<_, _>>()?;
    parts.try_into().map_err(|_| format!("expected X,Y,Z (a position or 'none' each), got '{s}'"))
}

/// `--window`: MIN,MAX with MIN < MAX.
pub fn parse_window(s: &str) -> Result<[f32; 2], String> {
    let parts: Vec<f32> =
        s.split(',').map(|p| p.trim().parse::<f32>().map_err(|e| format!("'{p}': {e}"))).collect::<Result<_, _>>()?;
    match parts[..] {
        [lo, hi] if lo.is_finite() && hi.is_finite() && lo < hi => Ok([lo, hi]),
        [_, _] => Err(format!("expected finite MIN < MAX, got '{s}'")),
        _ => Err(format!("expected MIN,MAX, got '{s}'")),
    }
}

/// `--alpha`: an opacity in (0, 1].
pub fn parse_alpha(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(a) if a > 0.0 && a <= 1.0 => Ok(a),
        _ => Err(format!("'{s}' is not an opacity in (0, 1]")),
    }
}

/// `--context-alpha`: a number in [0, 1].
pub fn parse_unit(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(a) if (0.0..=1.0).contains(&a) => Ok(a),
        _ => Err(format!("'{s}' is not a number in [0, 1]")),
    }
}

/// `--slab`: AXIS,CENTRE,THICKNESS.
pub fn parse_slab(s: &str) -> Result<lineao::Slab, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [axis, center, thickness] = parts[..] else {
        return Err(format!("expected AXIS,CENTRE,THICKNESS (e.g. z,0,8), got '{s}'"));
    };
    let axis = lineao::SlabAxis::from_name(axis)
        .ok_or_else(|| format!("'{axis}' is not a slab axis (one of x, y, z, view)"))?;
    let number = |p: &str| p.parse::<f32>().ok().filter(|v| v.is_finite());
    match (number(center), number(thickness)) {
        (Some(center), Some(thickness)) if thickness > 0.0 => Ok(lineao::Slab { axis, center, thickness }),
        _ => Err(format!("expected a centre and a thickness > 0 in mm, got '{s}'")),
    }
}

/// `on` or `off`.
pub fn parse_on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("expected on or off, got '{s}'")),
    }
}

/// The camera (the rest from the scene).
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Camera")]
#[serde(default)]
pub struct CameraArgs {
    /// Camera position, world units: X,Y,Z [default: the scene's].
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    #[serde(deserialize_with = "crate::kwargs::opt_vec3")]
    pub eye: Option<[f32; 3]>,
    /// Point the camera looks at: X,Y,Z [default: the scene's].
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    #[serde(deserialize_with = "crate::kwargs::opt_vec3")]
    pub target: Option<[f32; 3]>,
    /// Camera up vector: X,Y,Z [default: the scene's].
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    #[serde(deserialize_with = "crate::kwargs::opt_vec3")]
    pub up: Option<[f32; 3]>,
    /// Vertical field of view in degrees (perspective) [default: the scene's].
    #[arg(long, conflicts_with = "ortho")]
    pub fov: Option<f32>,
    /// Orthographic camera showing this many world units vertically.
    #[arg(long)]
    pub ortho: Option<f32>,
    /// World units per zoom unit of z(P) [default: the scene's, 1 mm].
    #[arg(long)]
    pub zoom_unit: Option<f32>,
}

/// What every screen-space method shares: the noise, the guard band, the bilateral blur.
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Noise, guard band, blur")]
#[serde(default)]
pub struct ChainArgs {
    /// Seed of the R1/R2 noise.
    #[arg(long, default_value_t = 1)]
    pub noise_seed: u32,
    /// Upper bound of the guard band in pixels.
    #[arg(long, default_value_t = 128)]
    pub guard_max: u32,
    /// Bilateral (depth-aware, separable) blur after the method.
    #[arg(long)]
    pub bilateral: bool,
    /// Bilateral blur: taps on each side (1..=16).
    #[arg(long, default_value_t = 4, requires = "bilateral")]
    pub bilateral_radius: u32,
    /// Bilateral blur: σ of the depth weight, world units.
    #[arg(long, default_value_t = 1.0, requires = "bilateral")]
    pub bilateral_sigma: f32,
}

/// Object-space AO (occlusion sweeping, variance occlusion maps).
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Object-space AO")]
#[serde(default)]
pub struct VolumeArgs {
    /// Object-space AO: voxels of the density volume along its longest axis (64–256 typical).
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(8..=1024))]
    pub volume_resolution: u32,
    /// Object-space AO: occupancy radius of the streamlines in world units [default: the tube
    /// radius with --geometry tubes, else 0.5 mm].
    #[arg(long)]
    pub occupancy_radius: Option<f32>,
    /// Object-space AO: where the light comes from.
    #[arg(long, value_enum, default_value_t = SkyArg::Uniform)]
    #[serde(deserialize_with = "crate::kwargs::sky")]
    pub sky: SkyArg,
    /// Object-space AO: how the eight octant visibilities meet the line's normal.
    #[arg(long, value_enum, default_value_t = VolumeNormal::Pixel)]
    #[serde(deserialize_with = "crate::kwargs::volume_normal")]
    pub volume_normal: VolumeNormal,
    /// Occlusion sweeping: opacity α of the translucent transmittance (Eq. 8), in (0, 1].
    #[arg(long, default_value_t = 1.0)]
    pub sweep_alpha: f32,
    /// A screen-space method with object-space AO: brightness multiplied (`product`) or the
    /// darker of the two (`min`).
    #[arg(long, value_parser = named::<VoCombine>(), default_value = "product")]
    pub volume_combine: VoCombine,
}

/// How the ray-traced truth is traced (`--method raytraced`, `score`); its rays, reach,
/// falloff and seed are the ray-traced method's described settings (`--rays`, `--ao-distance`,
/// …: [`crate::method_args`]), which the CPU truth reads too.
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Ray-traced truth")]
#[serde(default)]
pub struct TruthArgs {
    /// Ray-traced AO: trace on the CPU (the reference, f64, all cores) instead of the GPU.
    /// The reference is shown as traced: `--denoise` and `--bilateral` are the GPU tracer's.
    #[arg(long, conflicts_with_all = ["bilateral", "denoise"])]
    pub cpu: bool,
}

/// Each group's defaults are the command line's (`RenderArgs::default`).
macro_rules! defaults_from_render_args {
    ($($field:ident: $ty:ty),* $(,)?) => {$(
        impl Default for $ty {
            fn default() -> $ty {
                RenderArgs::default().$field
            }
        }
    )*};
}

defaults_from_render_args! {
    source: SourceArgs,
    shown: ShownArgs,
    image: ImageArgs,
    style: StyleArgs,
    context: ContextArgs,
    select: SelectArgs,
    camera: CameraArgs,
    chain: ChainArgs,
    volume: VolumeArgs,
    truth: TruthArgs,
    figure: FigureArgs,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ColorArg {
    Tangent,
    Constant([f32; 3]),
    /// A per-vertex field of the file through --colormap.
    Field(String),
    /// A NIfTI volume sampled at every vertex (trilinear, NaN outside: gray) through --colormap.
    Volume(std::path::PathBuf),
    /// An MRtrix track scalar file's values (.tsf, a value a vertex) through --colormap.
    Tsf(std::path::PathBuf),
    /// Each streamline by its (first) group, a colour each; gray outside every group.
    Groups,
}

/// The per-vertex field `--color groups` colours by: each vertex's streamline's first group
/// (its index among the file's groups, modulo 16), NaN outside every group.
pub const GROUP_FIELD: &str = "groups:";

impl ColorArg {
    /// The file beside the tractogram whose values colour it (`volume:FILE`, `tsf:FILE`).
    pub fn values_file(&self) -> Option<&std::path::Path> {
        match self {
            ColorArg::Volume(path) | ColorArg::Tsf(path) => Some(path),
            _ => None,
        }
    }

    /// The per-vertex field it colours by: the file's, or the volume's samples (named
    /// `volume:PATH`), or the .tsf's values (`tsf:PATH`).
    pub fn field(&self) -> Option<String> {
        match self {
            ColorArg::Field(name) => Some(name.clone()),
            ColorArg::Volume(path) => Some(format!("volume:{}", path.display())),
            ColorArg::Tsf(path) => Some(format!("tsf:{}", path.display())),
            ColorArg::Groups => Some(GROUP_FIELD.to_string()),
            _ => None,
        }
    }
}

/// Keys of `lineao::ChainSettings` in JSON that replace what the options give, checked against
/// the settings' types when parsed (a typo is a bad command line, naming the key).
#[derive(Clone, Debug, PartialEq)]
pub struct SettingsPatch(serde_json::Map<String, serde_json::Value>);

impl SettingsPatch {
    /// `settings` with the patch's keys: objects merge key by key, anything else replaces.
    pub fn apply(&self, settings: &lineao::ChainSettings) -> Result<lineao::ChainSettings, String> {
        fn merge(into: &mut serde_json::Value, patch: &serde_json::Value) {
            match (into, patch) {
                (serde_json::Value::Object(into), serde_json::Value::Object(patch)) => {
                    for (key, value) in patch {
                        merge(into.entry(key.clone()).or_insert(serde_json::Value::Null), value);
                    }
                }
                (into, patch) => *into = patch.clone(),
            }
        }
        let mut value = serde_json::to_value(settings).map_err(|e| e.to_string())?;
        merge(&mut value, &serde_json::Value::Object(self.0.clone()));
        serde_path_to_error::deserialize(value).map_err(|e| match e.path().to_string().as_str() {
            "." => e.inner().to_string(),
            path => format!("{path}: {}", e.inner()),
        })
    }
}

/// The patch as compact JSON.
impl std::fmt::Display for SettingsPatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", serde_json::Value::Object(self.0.clone()))
    }
}

pub fn parse_settings(s: &str) -> Result<SettingsPatch, String> {
    let (text, source) = if s.trim_start().starts_with('{') {
        (s.to_string(), "the settings".to_string())
    } else {
        (std::fs::read_to_string(s).map_err(|e| format!("{s}: {e}"))?, s.to_string())
    };
    let patch = match serde_json::from_str(&text) {
        Ok(serde_json::Value::Object(map)) => SettingsPatch(map),
        Ok(_) => return Err(format!("{source}: expected a JSON object of settings")),
        Err(e) => return Err(format!("{source}: {e}")),
    };
    if patch.0.contains_key("method") {
        return Err(format!("{source}: `method` is chosen by --method, --compare or --grid"));
    }
    patch.apply(&lineao::ChainSettings::default()).map_err(|e| format!("{source}: {e}"))?;
    Ok(patch)
}

pub fn parse_preset(s: &str) -> Result<lineao::Preset, String> {
    lineao::Preset::from_name(s).ok_or_else(|| format!("unknown preset '{s}' (legible, physical, paper, sparse)"))
}

pub fn parse_scene(s: &str) -> Result<SceneKind, String> {
    s.parse()
}

pub fn parse_vec3(s: &str) -> Result<[f32; 3], String> {
    let parts: Vec<f32> =
        s.split(',').map(|p| p.trim().parse::<f32>().map_err(|e| format!("'{p}': {e}"))).collect::<Result<_, _>>()?;
    let v: [f32; 3] = parts.try_into().map_err(|_| format!("expected three numbers X,Y,Z, got '{s}'"))?;
    if v.iter().all(|c| c.is_finite()) { Ok(v) } else { Err(format!("'{s}' is not finite")) }
}

pub fn parse_color(s: &str) -> Result<ColorArg, String> {
    if let Some(path) = s.strip_prefix("volume:").filter(|p| !p.is_empty()) {
        return Ok(ColorArg::Volume(path.into()));
    }
    if let Some(path) = s.strip_prefix("tsf:").filter(|p| !p.is_empty()) {
        return Ok(ColorArg::Tsf(path.into()));
    }
    match s.strip_prefix("field:") {
        Some(name) if !name.is_empty() => Ok(ColorArg::Field(name.to_string())),
        _ if s == "tangent" => Ok(ColorArg::Tangent),
        _ if s == "groups" => Ok(ColorArg::Groups),
        _ => parse_vec3(s).map(ColorArg::Constant),
    }
}

pub fn parse_debug_view(s: &str) -> Result<lineao::DebugView, String> {
    use lineao::DebugView as D;
    Ok(match s {
        "final" => D::Final,
        "ao" => D::Ao,
        "normals" => D::Normals,
        "depth" => D::Depth,
        "zoom" => D::Zoom,
        "pieces" => D::Pieces,
        "frozen" => D::Frozen,
        "culled" => D::Culled,
        _ => match s.strip_prefix("level:").map(str::parse::<u32>) {
            Some(Ok(k)) => D::Level(k),
            _ => {
                return Err(format!(
                    "unknown debug view '{s}' (final, ao, normals, depth, zoom, level:K, pieces, frozen, culled)"
                ));
            }
        },
    })
}

/// A `ValueEnum` by its command-line name (for keyword arguments).
pub fn parse_value_enum<T: ValueEnum>(s: &str) -> Result<T, String> {
    T::from_str(s, false)
}

/// A parser that lists its values with their help in `--help` (from the registry, not a copy)
/// and parses with `parse`, which also takes what the list does not show (`lineao+sweep`).
#[derive(Clone)]
pub struct Listed<T> {
    pub parse: fn(&str) -> Result<T, String>,
    pub values: fn() -> Vec<(&'static str, &'static str)>,
}

impl<T: Clone + Send + Sync + 'static> clap::builder::TypedValueParser for Listed<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        self.parse.parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        let values = (self.values)().into_iter();
        Some(Box::new(values.map(|(name, help)| clap::builder::PossibleValue::new(name).help(help))))
    }
}

/// A parser of a library setting's own names ([`lineao::Named`]), listing each with its help:
/// the CLI mirrors no enum of the library's.
pub fn named<T: Named>() -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(T::VALUES.iter().map(|v| PossibleValue::new(v.name()).help(v.help())))
        .map(|name| T::from_name(&name).expect("clap accepts the listed names only"))
}

/// `lineao info`'s arguments.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// A .trk, .tck, .tsf, .trx (zip or directory), .vtk, .vtp, .tt.gz, .gltf/.glb or .obj file,
    /// optionally gzip-wrapped.
    pub file: PathBuf,
    /// Print docs/reference.md's JSON.
    #[arg(long)]
    pub json: bool,
    /// With a selection, the count it keeps is reported (`"selected"`).
    #[command(flatten)]
    pub select: SelectArgs,
}

/// `lineao convert`'s arguments.
#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Any file `lineao info` reads (with `--scene`: the file to write).
    pub input: PathBuf,
    /// .tck, .trk or .trx.
    #[arg(required_unless_present = "scene")]
    pub output: Option<PathBuf>,
    /// Write a built-in scene instead of converting a file: a whole-brain tractogram of any
    /// size (`--scene wholebrain --vertices 50000000 brain.tck`) without a 10 GB download.
    #[arg(long, value_parser = parse_scene)]
    pub scene: Option<SceneKind>,
    /// The scene's approximate vertex count [default: the scene's].
    #[arg(long, requires = "scene")]
    pub vertices: Option<usize>,
    /// The scene's seed.
    #[arg(long, default_value_t = 1, requires = "scene")]
    pub seed: u64,
}

/// `lineao render ARGS…` as the command line parses it (`argv` from the program's name on).
#[cfg(test)]
pub(crate) fn parse_render<I, T>(argv: I) -> Box<RenderArgs>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    try_parse_render(argv).expect("a valid command line")
}

/// [`parse_render`], or clap's refusal.
#[cfg(test)]
pub(crate) fn try_parse_render<I, T>(argv: I) -> Result<Box<RenderArgs>, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    #[derive(clap::Parser)]
    struct Cli {
        #[command(subcommand)]
        command: Command,
    }
    #[derive(clap::Subcommand)]
    enum Command {
        Render(Box<RenderArgs>),
    }
    let Command::Render(args) = <Cli as clap::Parser>::try_parse_from(argv)?.command;
    Ok(args)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_ao_distance_is_world_units_or_a_share_of_the_longest_side() {
        assert_eq!(parse_ao_distance("2"), Ok(AoDistance::World(2.0)));
        assert_eq!(parse_ao_distance("20%"), Ok(AoDistance::Share(0.2)));
        assert_eq!(parse_ao_distance(" 100 % "), Ok(AoDistance::Share(1.0)));
        // 20 % of a 150 mm brain is 30 mm; a world distance ignores the scene.
        assert!((AoDistance::Share(0.2).world(150.0) - 30.0).abs() < 1e-5);
        assert_eq!(AoDistance::World(2.0).world(150.0), 2.0);
        assert_eq!(AoDistance::Share(0.2).to_string(), "20%");
        for bad in ["0%", "100.5%", "-1%", "x%", "0", "-2", "inf", ""] {
            assert!(parse_ao_distance(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_slice_s_position_is_a_number_or_none() {
        assert_eq!(parse_slices("0,-18.5,10"), Ok([Some(0.0), Some(-18.5), Some(10.0)]));
        assert_eq!(parse_slices("none,-18,None"), Ok([None, Some(-18.0), None]));
        assert_eq!(parse_slices("-,-, 10"), Ok([None, None, Some(10.0)]));
        for bad in ["0,0", "0,0,0,0", "x,0,0", "0,inf,0", "0,NaN,0"] {
            assert!(parse_slices(bad).is_err(), "{bad}");
        }
        let args = parse_render(["lineao", "render", "f.trk", "--volume", "t1.nii.gz", "--slices", "none,none,12"]);
        assert_eq!(args.context.slices, Some([None, None, Some(12.0)]));
    }
}

/// Figures and movies: views in one figure, turntables.
#[derive(Args, Clone, Debug, serde::Deserialize)]
#[command(next_help_heading = "Figures and movies")]
#[serde(default)]
pub struct FigureArgs {
    /// Standard anatomical views of the same data in one labelled figure, a panel each, seen
    /// from the view's side of RAS+ world space at the camera's distance from its target:
    /// left, right, front, back, top, bottom (or anterior, posterior, superior, inferior),
    /// e.g. `left,right,top,front`; with --compare each panel shows both methods.
    #[arg(long, value_name = "VIEW,...", value_delimiter = ',', value_parser = crate::cameras::parse_view, conflicts_with_all = ["grid", "dump", "turntable"])]
    #[serde(deserialize_with = "crate::kwargs::views")]
    pub views: Vec<crate::cameras::AnatomicalView>,
    /// A turntable: N frames with the eye turned about the target around the camera's up
    /// axis (or along the --orbit keyframes), written as OUTPUT-000.png, OUTPUT-001.png, …
    /// with their cameras (OUTPUT.json) and a movie (--movie).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100_000), conflicts_with = "dump")]
    pub turntable: Option<u32>,
    /// The camera as the viewer's and the page's `--orbit`: AZIMUTH and ELEVATION (degrees
    /// around the data's up) and ZOOM (times the data's default distance), around the data's
    /// default target; given twice or more with --turntable N, the keyframes of a camera path
    /// (N frames from the first to the last, each stretch between two keyframes as many frames
    /// as its share of the turn).
    #[arg(long, value_name = "AZIMUTH,ELEVATION,ZOOM", value_parser = crate::cameras::parse_orbit, allow_hyphen_values = true)]
    #[serde(deserialize_with = "crate::kwargs::orbits")]
    pub orbit: Vec<[f32; 3]>,
    /// The turntable's turn in degrees, counter-clockwise seen from above its up axis (negative:
    /// clockwise); the last frame is one step short of it.
    #[arg(long, default_value_t = 360.0, allow_hyphen_values = true, requires = "turntable")]
    pub turntable_degrees: f32,
    /// The turntable's movie: a .png or .apng file (an animated PNG, written by lineao), a
    /// file the `ffmpeg` program writes (.mp4, .mkv, .mov: H.264; .webm: VP9; .gif), or
    /// `none` (the PNG frames only) [default: OUTPUT with the extension .apng].
    #[arg(long, value_name = "FILE|none", requires = "turntable")]
    pub movie: Option<PathBuf>,
    /// The movie's frames per second.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=240), requires = "turntable")]
    pub fps: u32,
    /// Render the picture as tiles of at most SIZE × SIZE pixels (a multiple of 64), each seen
    /// through the picture's camera with its own guard band, stitched without a seam: the
    /// picture a single frame of its size shows, in the memory of one row of tiles [default:
    /// tiles of 4096 px where --width or --height exceeds it].
    #[arg(long, value_name = "SIZE", value_parser = parse_tile, conflicts_with = "dump")]
    #[serde(deserialize_with = "crate::kwargs::opt_tile")]
    pub tile: Option<u32>,
}

/// The largest --width and --height: 64 K pixels a side (tiles reach any size; a PNG's rows
/// of 64 K RGBA pixels are 256 KiB).
pub const MAX_SIDE: u32 = 65_536;

/// The alignment of tiles: their origins in the picture are multiples of it, so that every
/// level of every pyramid (LineAO's ND pyramid, VO's moments) covers the same pixels in a tile
/// as in the picture.
pub const TILE_ALIGN: u32 = 64;

/// `--tile`: a multiple of 64, at least 64.
pub fn parse_tile(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(size) if size >= TILE_ALIGN && size % TILE_ALIGN == 0 => Ok(size),
        _ => Err(format!("expected a tile size in pixels, a multiple of {TILE_ALIGN} (64, 128, … 4096), got '{s}'")),
    }
}

/// The tiles of a picture wider or taller than this, unless --tile says otherwise: a frame's
/// targets at 4096² (and the guard band) take about 1 GiB, as much as a device is sure to give.
pub const DEFAULT_TILE: u32 = 4096;
