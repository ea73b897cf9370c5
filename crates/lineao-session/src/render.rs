//! `lineao render`: a tractography file or a built-in scene through the pass chain into a PNG
//! (and `--dump`); with `--compare A,B` a split screen of two methods, with `--grid` all of
//! them side by side, labelled.

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result};
use glam::Vec3;
use lineao::method::setting::Value;
use lineao::passes::meshes::MeshGeometry;
use lineao::volume::density::DensityOptions;
use lineao::volume::sweep::SweepSettings;
use lineao::volume::{ScalarForm, Sky, VolumeAoOptions, VolumeMethod};
use lineao::{
    AoChain, BilateralSettings, ChainSettings, Gpu, LineColor, SliceSettings, SliceVolume, SurfaceSettings,
    TubeSettings, VolumeAoSettings,
};
use lineao::{Bounds, Camera, Projection};
use lineao_tracts::scenes::ViewHint;

use crate::args::{ColorArg, GeometryArg, Method, RenderArgs, SkyArg, VolumeNormal};
use crate::label::Rgba8;
use crate::source::{AttributeKey, FrameScene, Keep, Lines, Loaded, Sampled, Source, vertex_field};

/// The sky of object-space AO: open, or lit from the world axis nearest to the camera's `up`.
pub fn sky(args: &RenderArgs, up: Vec3) -> Sky {
    match args.volume.sky {
        SkyArg::Uniform => Sky::Uniform,
        SkyArg::Cloudy => Sky::above_nearest_axis(up.to_array()),
    }
}

/// How object-space AO is computed, from the command line.
pub fn volume_options(args: &RenderArgs, method: VolumeMethod, sky: Sky, zoom_unit: f32) -> VolumeAoOptions {
    VolumeAoOptions {
        method,
        density: DensityOptions {
            resolution: args.volume.volume_resolution as usize,
            occupancy_radius: args.volume.occupancy_radius.unwrap_or(match args.style.geometry {
                GeometryArg::Tubes => tube_radius(args, zoom_unit),
                GeometryArg::Lines => 0.5 * zoom_unit,
            }),
            threads: 0,
        },
        sweep: SweepSettings { alpha: args.volume.sweep_alpha, threads: 0 },
        form: match args.volume.volume_normal {
            VolumeNormal::Pixel => None,
            VolumeNormal::Tangent => Some(ScalarForm::AroundTangent),
            VolumeNormal::None => Some(ScalarForm::NoGeometryTerm),
        },
        sky,
        ..VolumeAoOptions::default()
    }
}

/// The tubes' radius in world units: --tube-radius or 0.5 mm.
fn tube_radius(args: &RenderArgs, zoom_unit: f32) -> f32 {
    args.style.tube_radius.unwrap_or(0.5 * zoom_unit)
}

/// The lines from which `render` culls a single picture where `--cull` is not given
/// ([`Session::culls_one_picture`]).
pub const CULL_POINTS: usize = 8_000_000;

/// The chain's settings from the command line, for `method` (object-space AO lit by `sky`), in
/// a scene whose bounds' longest side is `longest_side` world units.
pub fn settings(args: &RenderArgs, method: Method, zoom_unit: f32, sky: Sky, longest_side: f32) -> ChainSettings {
    let volume = method.volume.map(|_| VolumeAoSettings {
        // The view-independent forms hold the sky already.
        sky: if args.volume.volume_normal == VolumeNormal::Pixel { sky.weights() } else { [1.0; 8] },
        combine: args.volume.volume_combine,
    });
    let method = method.screen;
    let mut settings = ChainSettings {
        method,
        volume,
        // Over anatomy slices without it the chain blurs the slices' pixels alone
        // (`ChainSettings::bilateral`, docs/render.md).
        blur: args.chain.bilateral.then_some(BilateralSettings {
            radius_px: args.chain.bilateral_radius,
            depth_sigma_world: args.chain.bilateral_sigma,
        }),
        line_width_px: args.style.line_width,
        lighting: lineao::lighting::Lighting {
            line_shading: args.style.line_shading,
            ..lineao::lighting::Lighting::default()
        },
        tubes: (args.style.geometry == GeometryArg::Tubes)
            .then(|| TubeSettings { radius_world: tube_radius(args, zoom_unit) }),
        surfaces: (!args.style.surfaces.is_empty()).then_some(SurfaceSettings { color: args.style.surface_color }),
        slices: slice_settings(args),
        slab: args.context.slab,
        transparency: args.context.transparency.settings(),
        line_color: match &args.style.color {
            ColorArg::Tangent => LineColor::Tangent,
            ColorArg::Constant(rgb) => LineColor::Constant(*rgb),
            // The range comes from the data (`run` sets it).
            ColorArg::Field(_) | ColorArg::Volume(_) | ColorArg::Tsf(_) => {
                LineColor::Scalar { colormap: args.style.colormap, range: [0.0, 1.0] }
            }
            // A colour each, whatever --colormap says.
            ColorArg::Groups => {
                let last = (lineao::COLORMAP_ENTRIES - 1) as f32;
                LineColor::Scalar { colormap: lineao::Colormap::Categories, range: [0.0, last] }
            }
        },
        background: args.style.background,
        strength: 1.0,
        debug_view: args.image.debug_view,
        zoom_unit: args.camera.zoom_unit.unwrap_or(zoom_unit),
        guard_max_px: args.chain.guard_max,
        cull: args.style.cull.unwrap_or(false),
        lod: args.style.lod.unwrap_or(true),
        ..ChainSettings::papers()
    };
    let seed = args.chain.noise_seed;
    (settings.line_ao.noise_seed, settings.ssao.noise_seed, settings.vo.noise_seed) = (seed, seed, seed);
    // The described settings (LineAO's, SSAO's, …) before the preset, which depends on some of
    // them (LineAO's variant), and again after it: what is given wins.
    args.methods.apply(&mut settings);
    let mut settings = settings.with_preset(args.shown.preset);
    // What the command line names explicitly wins over the preset.
    if let Some(strength) = args.shown.strength {
        settings.strength = strength;
    }
    args.methods.apply_with(&mut settings, method, args.shown.samples, args.shown.radius);
    crate::truth::budget(&mut settings.raytraced, args, longest_side);
    match &args.shown.settings {
        // Checked against the same types when parsed: it applies to any settings.
        Some(patch) => patch.apply(&settings).expect("--settings was checked when parsed"),
        None => settings,
    }
}

/// What one image of the output shows: a label, the chain's settings and the object-space
/// method whose visibilities the geometry must carry.
pub struct Panel {
    pub label: String,
    /// The method's name (`params.json` `method`).
    pub name: String,
    pub settings: ChainSettings,
    pub volume: Option<VolumeMethod>,
}

impl Panel {
    pub fn new(method: Method, settings: ChainSettings) -> Panel {
        let name = method.name();
        let mut label = name.clone();
        if let Some(variant) = method.screen.info().variant_of(&settings) {
            label += &format!(" ({})", variant.value);
        }
        Panel { label, name, settings, volume: method.volume }
    }
}

/// The methods of `--grid`, in order (LineAO's other variant is inserted third).
fn grid_methods() -> Vec<Method> {
    let mut methods = Method::all();
    methods.pop();
    methods
}

/// The panels the command line asks for: one method, two (--compare) or all (--grid).
fn panels(args: &RenderArgs, zoom_unit: f32, sky: Sky, longest_side: f32) -> Vec<Panel> {
    let panel = |method| Panel::new(method, settings(args, method, zoom_unit, sky, longest_side));
    if let Some(pair) = args.shown.compare {
        return pair.into_iter().map(panel).collect();
    }
    if !args.shown.grid {
        return vec![panel(args.shown.method)];
    }
    let methods = grid_methods();
    let mut all: Vec<Panel> = methods.iter().copied().map(panel).collect();
    // After the first method with a variant, its other form (LineAO as the authors' code
    // computes it, next to the paper's: the third tile).
    let with_variant = methods.iter().enumerate().find_map(|(i, m)| Some((i, *m, m.screen.info().variant.as_ref()?)));
    if let Some((i, method, variant)) = with_variant {
        let shown = method.screen.info().variant_of(&all[i].settings).is_some();
        let mut other = args.clone();
        other.methods.give(variant.setting, Value::Choice(if shown { variant.main } else { variant.value }));
        all.insert(i + 1, Panel::new(method, settings(&other, method, zoom_unit, sky, longest_side)));
    }
    all
}

/// What every panel of a `render` (or `score`) shares: the data on the CPU and on the GPU, and
/// the camera.
pub struct Session {
    /// The streamlines on the GPU with their attributes.
    pub lines: Lines,
    /// The attributes every panel has: the scalar of `--color field:NAME`, the radii of
    /// `--tube-radius-field`.
    pub base: AttributeKey,
    pub camera: Camera,
    pub sky: Sky,
    pub surfaces: Vec<lineao_tracts::TriangleMesh>,
    pub gpu: Gpu,
    pub meshes: Vec<MeshGeometry>,
    /// The `--volume` the slices cut, on the GPU, where it loaded.
    pub anatomy: Option<Arc<SliceVolume>>,
    pub bounds: Bounds,
    /// The longest side of the axis-aligned box around the streamlines and surfaces, world
    /// units: what `--ao-distance 20%` is a share of.
    pub longest_side: f32,
    /// The ray tracer's scene on the GPU, built when a panel first needs it.
    ray_scene: std::sync::OnceLock<std::sync::Arc<lineao::RayScene>>,
    /// With a selection, the streamlines shown, for the truth (made when it is traced).
    selected_tracts: std::sync::OnceLock<lineao_tracts::Tractogram>,
}

impl Session {
    /// Streams the file (or makes the scene) onto the GPU and loads the surfaces; the points
    /// stay on the CPU only where a panel asked for needs them there (object-space AO, the ray
    /// tracers): a whole-brain file is never held whole as f32.
    pub fn open(args: &RenderArgs) -> Result<Session> {
        Self::open_keeping(args, needs_points(args))
    }

    /// [`Session::open`] keeping the points on the CPU whatever the panels: for later frames
    /// of any method (Python's `Renderer`) and the truth (`score`).
    pub fn open_with_points(args: &RenderArgs) -> Result<Session> {
        Self::open_keeping(args, true)
    }

    fn open_keeping(args: &RenderArgs, points: bool) -> Result<Session> {
        let source = match &args.file {
            Some(path) => Source::File(path.clone()),
            None => Source::Scene {
                kind: args.source.scene,
                vertices: args.source.vertices.unwrap_or(args.source.scene.default_vertices()),
                seed: args.source.seed,
            },
        };
        let surfaces = load_surfaces(args)?;
        let base = base_attributes(args);
        let gpu = Gpu::headless()?;
        let sampled = Sampled::of(&args.style.color)?;
        // The groups' colours are known once the file is read (its groups come last).
        let groups = args.style.color == ColorArg::Groups;
        let keep = Keep {
            points: points || groups,
            scalar: base.scalar.clone().filter(|_| !groups),
            radius: base.radius.clone(),
            fields: false,
            sampled,
            selection: args.select.selection(),
            lengths: false,
        };
        let bar = match &source {
            Source::File(path) => crate::source::progress_bar(path),
            _ => None,
        };
        let mut report = |p: lineao_tracts::Progress| {
            if let Some(bar) = &bar {
                bar.set_position(p.bytes);
            }
            std::ops::ControlFlow::Continue(())
        };
        let lines = Lines::stream(&source, &keep, Some(&mut report), &gpu);
        if let Some(bar) = &bar {
            bar.finish_and_clear();
        }
        let mut lines = lines?;
        if groups {
            crate::source::add_group_field(&mut lines.tracts);
            lines.hold((&gpu.device, &gpu.queue), &base, || {})?;
        }
        Self::assemble(args, lines, surfaces, base, gpu)
    }

    /// [`Session::open`] on streamlines already in memory (the Python package's).
    pub fn with_loaded(args: &RenderArgs, mut loaded: Loaded) -> Result<Session> {
        let surfaces = load_surfaces(args)?;
        let base = base_attributes(args);
        if let Some(sampled) = Sampled::of(&args.style.color)? {
            sampled.add_to(&mut loaded.tracts, 0, &loaded.name)?;
            sampled.check_whole(loaded.tracts.streamlines(), &loaded.name)?;
        }
        if args.style.color == ColorArg::Groups {
            crate::source::add_group_field(&mut loaded.tracts);
        }
        for field in base.scalar.iter().chain(&base.radius) {
            loaded.tracts.spread_streamline_field(field);
        }
        // The fields exist, before any GPU work.
        for field in base.scalar.iter().chain(&base.radius) {
            vertex_field(&loaded.name, &loaded.tracts, field)?;
        }
        let gpu = Gpu::headless()?;
        let mut lines = Lines::new(loaded, &gpu)?;
        lines.hold((&gpu.device, &gpu.queue), &base, || {})?;
        if let Some(selection) = args.select.selection() {
            lines.select(selection, &gpu)?;
        }
        Self::assemble(args, lines, surfaces, base, gpu)
    }

    /// The session of `lines` on the GPU with the surfaces: the camera, the bounds of both.
    fn assemble(
        args: &RenderArgs,
        lines: Lines,
        surfaces: Vec<lineao_tracts::TriangleMesh>,
        base: AttributeKey,
        gpu: Gpu,
    ) -> Result<Session> {
        let camera = camera(args, &lines.hint)?;
        let sky = sky(args, camera.up);
        let meshes = surfaces
            .iter()
            .map(|m| MeshGeometry::new(&gpu.device, &gpu.queue, &m.positions, &m.normals, &m.indices))
            .collect::<Result<Vec<_>, _>>()?;
        let anatomy = load_anatomy(args, &gpu);
        let lines_bounds = lines.geometry.bounds.expect("checked at upload");
        let slice_bounds =
            anatomy.as_ref().zip(slice_settings(args)).and_then(|(v, s)| v.slice_bounds(&fit_slices(v, s)));
        let bounds = meshes.iter().filter_map(|m| m.bounds).chain(slice_bounds).fold(lines_bounds, |b, m| b.union(&m));
        let corners = lines.geometry.corners().map(|(lo, hi)| [lo.to_array(), hi.to_array()]);
        let points = corners.iter().flatten().chain(surfaces.iter().flat_map(|m| &m.positions));
        let longest_side = longest_side(points);
        Ok(Session {
            lines,
            base,
            camera,
            sky,
            surfaces,
            gpu,
            meshes,
            anatomy,
            bounds,
            longest_side,
            ray_scene: Default::default(),
            selected_tracts: Default::default(),
        })
    }

    /// The chain's settings for `method` from the command line, the colour range from the data.
    pub fn settings(&self, args: &RenderArgs, method: Method) -> ChainSettings {
        let mut settings = settings(args, method, self.lines.hint.zoom_unit, self.sky, self.longest_side);
        self.fit_color_range(&mut settings);
        settings
    }

    /// The colour range from the data, and the slices placed in the volume.
    fn fit_color_range(&self, settings: &mut ChainSettings) {
        if self.base.scalar.as_deref() == Some(crate::args::GROUP_FIELD) {
            return;
        }
        if let (Some(volume), Some(slices)) = (&self.anatomy, settings.slices.take()) {
            settings.slices = Some(fit_slices(volume, slices));
        }
        let scalars = self.base.scalar.as_deref().and_then(|field| self.lines.field(field).ok());
        if let (Some(values), LineColor::Scalar { range, .. }) = (scalars, &mut settings.line_color) {
            *range = percentile_range(values);
        }
    }

    /// What the truth is traced against (the session keeps the points for a method that
    /// traces them): the streamlines shown.
    pub fn truth_scene(&self) -> Result<crate::truth::Scene<'_>> {
        let points = self.lines.points()?;
        let tracts = match &self.lines.selected {
            Some(selected) if selected.contains(&false) => self.selected_tracts.get_or_init(|| points.select(selected)),
            _ => points,
        };
        let radius = self.base.radius.as_deref();
        let radii = radius.and_then(|f| crate::source::vertex_field(&self.lines.name, tracts, f).ok());
        Ok(crate::truth::Scene { tracts, surfaces: &self.surfaces, radii })
    }
}

/// The picture `args` asks for, composed by `session`, written to `output` (`lineao render`
/// without a turntable: [`crate::figure::run`]).
pub fn write(args: &RenderArgs, session: &mut Session, output: &Path) -> Result<()> {
    let (image, panels) = session.compose(args, &mut Vec::new())?;
    crate::output::write_png(output, image.width, image.height, &image.data)?;
    let methods: Vec<&str> = panels.iter().map(|p| p.label.as_str()).collect();
    if session.lines.selected.is_some() {
        let (shown, all) = (session.lines.selected_count(), session.lines.geometry.streamlines);
        eprintln!("lineao: {shown} of {all} streamlines selected");
    }
    eprintln!(
        "lineao: {} ({} streamlines, {} vertices) with {} at {} x {} on {} -> {}",
        session.lines.name,
        session.lines.geometry.streamlines,
        session.lines.geometry.vertices,
        methods.join(", "),
        args.image.width,
        args.image.height,
        session.gpu.describe(),
        output.display()
    );
    Ok(())
}

impl Session {
    /// The image the command line asks for: one method, a split screen (--compare) or the
    /// labelled grid (--grid), or with --views a figure of such images, one a view; with the
    /// panels it shows. `chains` keeps a chain per panel between calls (pipelines and targets
    /// are made once for many frames); pass an empty `Vec` for one image.
    pub fn compose(&mut self, args: &RenderArgs, chains: &mut Vec<AoChain>) -> Result<(Rgba8, Vec<Panel>)> {
        match &args.figure.views[..] {
            [] => self.compose_panels(args, chains),
            views => self.compose_views(args, views, chains),
        }
    }

    /// [`Session::compose`] seen by the session's camera alone.
    pub fn compose_panels(&mut self, args: &RenderArgs, chains: &mut Vec<AoChain>) -> Result<(Rgba8, Vec<Panel>)> {
        let mut panels = panels(args, self.lines.hint.zoom_unit, self.sky, self.longest_side);
        for panel in &mut panels {
            panel.settings.validate().with_context(|| format!("method {}", panel.label))?;
            self.fit_color_range(&mut panel.settings);
        }
        let (sky, zoom_unit) = (self.sky, self.lines.hint.zoom_unit);
        let volume_options = |method| volume_options(args, method, sky, zoom_unit);
        if panels.iter().any(|p| p.volume.is_some()) {
            volume_options(VolumeMethod::Sweep).sweep.validate()?;
        }
        let mut kept: Vec<Option<AoChain>> = std::mem::take(chains).into_iter().map(Some).collect();
        kept.resize_with(panels.len(), || None);
        // Object-space AO once per method (the session keeps it), uploaded as the geometry's
        // attributes when a panel needs another method's than the last.
        let mut images = Vec::new();
        for (i, panel) in panels.iter().enumerate() {
            if let Some(method) = panel.volume {
                let wanted = AttributeKey { volume: Some(volume_options(method)), ..self.base.clone() };
                let (start, mut computed) = (std::time::Instant::now(), false);
                let gpu = &self.gpu;
                self.lines.hold((&gpu.device, &gpu.queue), &wanted, || computed = true)?;
                if computed {
                    eprintln!(
                        "lineao: {} at {} voxels along the longest axis: {:.2} s on the CPU",
                        method.name(),
                        args.volume.volume_resolution,
                        start.elapsed().as_secs_f64()
                    );
                }
            }
            // One method dumps into DIR itself, several into DIR/<label>/.
            let dump = args.image.dump.as_ref().map(|dir| match panels.len() {
                1 => dir.clone(),
                _ => dir.join(panel.label.replace(" (reference)", "-reference")),
            });
            let volume = panel.volume.map(&volume_options);
            let rendered = self.render(args, panel, dump.as_deref(), volume.as_ref(), kept[i].take())?;
            images.push(rendered.image);
            chains.push(rendered.chain);
        }
        let mut image = match &images[..] {
            [single] => single.clone(),
            [a, b] if args.shown.compare.is_some() => {
                crate::label::split(a, b, [&panels[0].label, &panels[1].label]).context("composing --compare")?
            }
            tiles => {
                let labelled: Vec<(&str, &Rgba8)> = panels.iter().map(|p| p.label.as_str()).zip(tiles).collect();
                crate::label::grid(&labelled, 3)
            }
        };
        if let (true, LineColor::Scalar { colormap, range }) = (args.image.legend, panels[0].settings.line_color) {
            let title = match (&args.style.color, args.style.color.values_file()) {
                (ColorArg::Field(name), _) => name.clone(),
                (_, Some(path)) => path.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned()),
                _ => String::new(),
            };
            match args.style.color {
                ColorArg::Groups => {
                    let names: Vec<&str> = self.lines.tracts.groups.iter().map(|g| g.name.as_str()).collect();
                    image.group_legend(&names);
                }
                _ => image.legend(&title, colormap, range),
            }
        }
        Ok((image, panels))
    }
}

/// The grid of a figure of `n` panels: as square as it goes, rows no longer than columns.
pub fn columns(n: usize) -> u32 {
    (n as f64).sqrt().ceil().max(1.0) as u32
}

/// The size of the tiles a picture of `args`' size is rendered in: --tile, or where a side
/// exceeds [`crate::args::DEFAULT_TILE`] or what the device renders in one frame (its textures less the
/// largest guard band `settings` allow), tiles of that size; `None`: one frame.
pub fn tile_size(args: &RenderArgs, limits: &wgpu::Limits, settings: &lineao::ChainSettings) -> Option<u32> {
    let (width, height) = (args.image.width, args.image.height);
    let fits = limits.max_texture_dimension_2d.saturating_sub(2 * settings.guard_max_px) / crate::args::TILE_ALIGN
        * crate::args::TILE_ALIGN;
    let tile = args.figure.tile.unwrap_or(crate::args::DEFAULT_TILE).min(fits).max(crate::args::TILE_ALIGN);
    (width > tile || height > tile).then_some(tile)
}

/// What tiles do not take: an error naming the flag.
pub fn check_tiled(args: &RenderArgs, panel: &Panel, dump: Option<&Path>) -> Result<()> {
    let what = if dump.is_some() {
        Some("--dump (one G-buffer a frame)")
    } else if args.image.timings {
        Some("--timings (time a frame of the device's size)")
    } else if panel.settings.method.info().traces_scene {
        Some("the ray-traced method (its rays are seeded per frame)")
    } else {
        None
    };
    match what {
        Some(what) => anyhow::bail!(
            "--width {} --height {} is rendered as tiles (--tile), which do not take {what}",
            args.image.width,
            args.image.height
        ),
        None => Ok(()),
    }
}

impl Session {
    /// The figure of `--views`: each view's image (one method, or the split of --compare) in a
    /// labelled grid, the session's camera put back after.
    pub fn compose_views(
        &mut self,
        args: &RenderArgs,
        views: &[crate::cameras::AnatomicalView],
        chains: &mut Vec<AoChain>,
    ) -> Result<(Rgba8, Vec<Panel>)> {
        crate::cameras::check_views(views).map_err(anyhow::Error::msg)?;
        let base = self.camera;
        let mut images = Vec::new();
        let mut panels = Vec::new();
        for view in views {
            self.camera = view.camera(&base);
            let composed = self.compose_panels(args, chains);
            self.camera = base;
            let (image, shown) = composed.with_context(|| format!("the view from the {}", view.name()))?;
            images.push(image);
            panels = shown;
        }
        let labelled: Vec<(&str, &Rgba8)> = views.iter().map(|v| v.name()).zip(&images).collect();
        Ok((crate::label::grid(&labelled, columns(views.len())), panels))
    }

    /// Renders the picture `args` asks for with `chain` (set for its panel) as tiles of `tile`
    /// pixels, row by row: each row of tiles is handed to `band` (its first row in the picture,
    /// its pixels) once its tiles are read back, so at most one row is held. The chain is left
    /// untiled, at the last tile's size.
    pub fn render_tiles(
        &self,
        args: &RenderArgs,
        chain: &mut lineao::AoChain,
        tile: u32,
        options: FrameOptions,
        mut band: impl FnMut(u32, Rgba8) -> Result<()>,
    ) -> Result<()> {
        let gpu = &self.gpu;
        let (width, height) = (args.image.width, args.image.height);
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        let picture = [width, height];
        for y in (0..height).step_by(tile as usize) {
            let rows = tile.min(height - y);
            let mut row = Rgba8::filled(width, rows, [0, 0, 0, 0]);
            for x in (0..width).step_by(tile as usize) {
                let size = (tile.min(width - x), rows);
                chain.set_tile(None)?;
                chain.resize(size.0, size.1)?;
                chain.set_tile(Some(lineao::Tile { picture, origin: [x, y] }))?;
                let target = lineao::targets::Target::output(&gpu.device, "lineao::render::tile", size, format);
                self.frame(chain, &target.view, options).with_context(|| format!("the tile at ({x}, {y})"))?;
                let pixels = lineao::readback::read_texture(&gpu.device, &gpu.queue, &target.texture)?;
                row.paste(&Rgba8 { width: size.0, height: size.1, data: pixels.bytes }, x, 0);
            }
            band(y, row)?;
        }
        chain.set_tile(None)?;
        Ok(())
    }
}

/// The 2nd and 98th percentiles of the finite `values` (robust to outliers), or [0, 1].
pub fn percentile_range(values: &[f32]) -> [f32; 2] {
    let mut finite: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return [0.0, 1.0];
    }
    finite.sort_by(f32::total_cmp);
    let at = |p: f32| finite[((finite.len() - 1) as f32 * p).round() as usize];
    [at(0.02), at(0.98)]
}

/// How [`Session::frame`] renders a frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameOptions {
    /// The ray-traced method traces on the GPU (not `--cpu`): the scene is given, the rays
    /// accumulate.
    pub gpu_rays: bool,
    /// Culled lines: the picture is a still camera's second frame.
    pub settled: bool,
    /// Times the picture's frame (`--timings`).
    pub timings: bool,
}

/// One rendered panel: the image, and the chain that made it (its targets hold the frame).
pub struct Rendered {
    pub image: Rgba8,
    pub chain: AoChain,
}

/// Each pass's median over `frames` (each a frame's pass times, the same passes), then the
/// frames' sums: median, least and most. Returns the sums' median.
fn print_medians(label: &str, frames: &[Vec<lineao::timing::PassTime>]) -> f64 {
    let median = |mut values: Vec<f64>| {
        values.sort_by(f64::total_cmp);
        let n = values.len();
        0.5 * (values[(n - 1) / 2] + values[n / 2])
    };
    let n = frames.len();
    for (k, pass) in frames[0].iter().enumerate() {
        let ms = median(frames.iter().map(|times| times[k].ms).collect());
        eprintln!("lineao: {label}: {:<12} {ms:9.2} ms (GPU, median of {n} frames)", pass.name);
    }
    let sums: Vec<f64> = frames.iter().map(|times| times.iter().map(|t| t.ms).sum()).collect();
    let (least, most) = sums.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &s| (lo.min(s), hi.max(s)));
    let frame = median(sums);
    eprintln!(
        "lineao: {label}: {:<12} {frame:9.2} ms (GPU, sum: median of {n} frames, {least:.2}..{most:.2})",
        "frame"
    );
    frame
}

impl Session {
    /// Renders `panel` to sRGB bytes (with `--timings`, prints its passes; with `dump`, writes
    /// its inputs and output there, with `volume`'s settings when it has object-space AO). The
    /// ray-traced method traces on the GPU, frame after frame until `--rays` rays per pixel;
    /// with `--cpu` it renders the G-buffer, traces the truth on the CPU, writes it into the
    /// chain's `ao` and composites.
    pub fn render(
        &self,
        args: &RenderArgs,
        panel: &Panel,
        dump: Option<&Path>,
        volume: Option<&VolumeAoOptions>,
        kept: Option<AoChain>,
    ) -> Result<Rendered> {
        let gpu = &self.gpu;
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        let tile = tile_size(args, &gpu.device.limits(), &panel.settings);
        let mut settings = panel.settings.clone();
        let culled = args.style.cull.is_none() && self.culls_one_picture(&settings, tile.is_some());
        if culled {
            // Every piece at full detail: the first frame draws them so, and a frame timed after
            // it (`--timed-frames`) draws the same picture.
            (settings.cull, settings.lod) = (true, false);
        }
        if args.image.timings && args.style.cull.is_none() {
            let (points, chosen) = (self.lines.geometry.points(), if culled { "on" } else { "off" });
            eprintln!("lineao: {}: cull {chosen} ({points} points; culled from {CULL_POINTS})", panel.label);
        }
        let mut chain = match kept {
            Some(mut chain) => {
                chain.set_settings(&gpu.device, settings)?;
                chain
            }
            None => AoChain::new(&gpu.device, format, settings)?,
        };
        let gpu_rays = panel.settings.method.info().traces_scene && !args.truth.cpu;
        // `--cull on` draws what a viewer shows of a still camera (its second frame, at the
        // levels of detail the first found); the cull chosen for a single picture, its first.
        let options = FrameOptions { gpu_rays, settled: !culled, timings: args.image.timings };
        if let Some(tile) = tile {
            check_tiled(args, panel, dump)?;
            let (width, height) = (args.image.width, args.image.height);
            let mut image = Rgba8::filled(width, height, [0, 0, 0, 0]);
            self.render_tiles(args, &mut chain, tile, options, |y, band| {
                image.paste(&band, 0, y);
                Ok(())
            })?;
            return Ok(Rendered { image, chain });
        }
        chain.set_tile(None)?;
        chain.resize(args.image.width, args.image.height)?;
        let size = (args.image.width, args.image.height);
        let target = lineao::targets::Target::output(&gpu.device, "lineao::render::output", size, format);
        let start = std::time::Instant::now();
        self.frame(&mut chain, &target.view, options)?;
        if args.image.timings {
            gpu.wait()?;
            let wall_ms = start.elapsed().as_secs_f64() * 1e3;
            let label = &panel.label;
            // The picture's frames, each followed by one of the settings it is timed against.
            let mut against = match &args.image.timings_against {
                Some(patch) => {
                    let settings = patch.apply(&panel.settings).map_err(anyhow::Error::msg)?;
                    let mut chain = AoChain::new(&gpu.device, format, settings)?;
                    chain.resize(args.image.width, args.image.height)?;
                    Some((patch, chain, Vec::new()))
                }
                None => None,
            };
            let mut frames = Vec::new();
            for k in 0..args.image.timed_frames {
                if k > 0 {
                    self.frame(&mut chain, &target.view, options)?;
                    gpu.wait()?;
                }
                let Some(times) = chain.pass_times(&gpu.device, true)? else { break };
                frames.push(times);
                if let Some((_, other, times)) = &mut against {
                    self.frame(other, &target.view, options)?;
                    gpu.wait()?;
                    times.extend(other.pass_times(&gpu.device, true)?);
                }
            }
            match &frames[..] {
                [] => eprintln!("lineao: {label}: frame {wall_ms:.2} ms (CPU wall time: no timestamp queries)"),
                [times] if against.is_none() => {
                    for t in times {
                        eprintln!("lineao: {label}: {:<12} {:9.2} ms (GPU)", t.name, t.ms);
                    }
                    let sum: f64 = times.iter().map(|t| t.ms).sum();
                    eprintln!("lineao: {label}: {:<12} {sum:9.2} ms (GPU, sum)", "frame");
                }
                _ => {
                    let frame = print_medians(label, &frames);
                    if let Some((patch, _, times)) = &against {
                        // The picture's own frame last, for the image read below.
                        self.frame(&mut chain, &target.view, options)?;
                        let label = format!("{label} against {patch}");
                        if times.is_empty() {
                            eprintln!("lineao: {label}: no GPU times came back");
                        } else {
                            let base = print_medians(&label, times);
                            eprintln!(
                                "lineao: {label}: the picture's frame {frame:.2} ms, {:+.1} % of {base:.2} ms",
                                100.0 * (frame / base - 1.0)
                            );
                        }
                    }
                }
            }
            if let Some(counts) = chain.cull_counts(&gpu.queue, &self.lines.geometry)? {
                eprintln!("lineao: {label}: cull: {counts}");
            }
        }
        let truth_settings = crate::truth::settings(args, self.longest_side);
        let truth = if panel.settings.method.info().traces_scene && args.truth.cpu {
            let truth = self.trace(&chain, &truth_settings)?;
            let targets = chain.targets().context("nothing was rendered")?;
            lineao::readback::write_target(&gpu.queue, &targets.ao, &truth.ao);
            let mut encoder = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::render::composite") });
            chain.encode_composite(&mut encoder, &target.view)?;
            gpu.queue.submit([encoder.finish()]);
            Some(truth)
        } else if gpu_rays && dump.is_some() {
            // The dump's truth keys and standard error, from the GPU's accumulation.
            Some(crate::truth::from_gpu(gpu, &chain)?)
        } else {
            None
        };
        let image = lineao::readback::read_texture(&gpu.device, &gpu.queue, &target.texture)?;
        if let Some(dir) = dump {
            crate::dump::write(dir, gpu, &chain, &self.camera, &panel.name, volume)?;
            if let Some(selected) = &self.lines.selected {
                crate::dump::write_selection(dir, selected)?;
            }
            if let Some(truth) = &truth {
                crate::dump::write_truth(dir, truth, &truth_settings)?;
            }
        }
        let image = Rgba8 { width: args.image.width, height: args.image.height, data: image.bytes };
        Ok(Rendered { image, chain })
    }

    /// Whether `render` culls a picture with `settings` where `--cull` is not given: where the
    /// lines are many enough that the first frame's seeded cull (every 8th cluster drawn, the
    /// rest culled against their depth: [`lineao::passes::cull`]) costs less than drawing every
    /// line — whole brains — in an untiled, opaque frame of a screen-space method.
    fn culls_one_picture(&self, settings: &ChainSettings, tiled: bool) -> bool {
        let opaque_lines = settings.tubes.is_none() && settings.transparent().is_none();
        let screen_space = !settings.method.info().traces_scene;
        opaque_lines && screen_space && !tiled && self.lines.geometry.points() >= CULL_POINTS
    }

    /// One frame of `chain` (sized, with its settings) over the session's lines, surfaces and
    /// anatomy, seen by its camera, into `target`: the one frame path of `render`, `score` and
    /// Python. With `options.gpu_rays` the ray tracer gets the session's scene and its picture
    /// accumulates until its rays per pixel; `options.settled` draws culled lines twice, the
    /// picture being the second frame — what a viewer shows of a still camera, drawn from what
    /// the first found visible at the levels of detail it found —, which `options.timings` times
    /// (the timer skips a frame submitted while it reads the one before).
    pub fn frame(&self, chain: &mut AoChain, target: &wgpu::TextureView, options: FrameOptions) -> Result<()> {
        let gpu = &self.gpu;
        let meshes: Vec<&MeshGeometry> = self.meshes.iter().collect();
        let frame = FrameScene {
            geometry: &self.lines.geometry,
            meshes: &meshes,
            camera: &self.camera,
            bounds: &self.bounds,
            rays: if options.gpu_rays { Some(self.ray_scene()?) } else { None },
            anatomy: self.anatomy.clone(),
        };
        let again = options.settled && chain.settings().cull;
        if options.timings && !again {
            chain.set_timing(&gpu.device, &gpu.queue, true);
        }
        frame.submit(gpu, chain, target)?;
        if again {
            if options.timings {
                chain.set_timing(&gpu.device, &gpu.queue, true);
            }
            frame.submit(gpu, chain, target)?;
        }
        if options.gpu_rays {
            crate::truth::accumulate(gpu, chain, |chain| frame.submit(gpu, chain, target))?;
        }
        Ok(())
    }

    /// The ray tracer's scene on the GPU (built and uploaded once per session), with a line on
    /// stderr saying what it cost.
    pub fn ray_scene(&self) -> Result<std::sync::Arc<lineao::RayScene>> {
        if let Some(scene) = self.ray_scene.get() {
            return Ok(scene.clone());
        }
        let scene = std::sync::Arc::new(crate::truth::ray_scene(&self.gpu, &self.truth_scene()?)?);
        Ok(self.ray_scene.get_or_init(|| scene).clone())
    }

    /// The truth on `chain`'s last frame, with a line on stderr saying what it cost.
    pub fn trace(&self, chain: &AoChain, settings: &lineao::truth::TruthSettings) -> Result<lineao::truth::Truth> {
        let start = std::time::Instant::now();
        let bvh = crate::truth::bvh(chain, &self.truth_scene()?)?;
        let built = start.elapsed().as_secs_f64();
        let truth = crate::truth::trace(&self.gpu, chain, &bvh, settings)?;
        let seconds = start.elapsed().as_secs_f64() - built;
        let second = settings.second.map_or(String::new(), |r| {
            format!(" and to {} ({} falloff) from the same rays", r.distance_world, r.falloff.name())
        });
        eprintln!(
            "lineao: ray traced {} rays to {} ({} falloff){second} over {} geometry pixels in {seconds:.1} s ({:.0} k \
             rays/s; BVH {built:.2} s, {} MB); {:.1} % of the pixels buried in another line",
            truth.rays,
            settings.distance_world,
            settings.falloff.name(),
            truth.geometry_pixels,
            truth.rays as f64 / seconds.max(1e-9) / 1e3,
            bvh.bytes() >> 20,
            100.0 * truth.buried_share()
        );
        Ok(truth)
    }
}

/// The slices of `--volume` as the command line gives them (where they lie by default comes
/// from the volume: [`fit_slices`]).
fn slice_settings(args: &RenderArgs) -> Option<SliceSettings> {
    args.context.volume.as_ref().map(|_| SliceSettings {
        positions: args.context.slices.unwrap_or([None; 3]),
        window: args.context.window,
        colormap: args.context.slice_colormap,
        opaque: args.context.opaque_slices,
    })
}

/// `slices` with every axis through the volume's centre where none was asked for.
fn fit_slices(volume: &SliceVolume, slices: SliceSettings) -> SliceSettings {
    if slices.positions.iter().any(Option::is_some) {
        return slices;
    }
    let (lo, hi) = volume.world_box();
    let center = 0.5 * (lo + hi);
    SliceSettings { positions: center.to_array().map(Some), ..slices }
}

/// The volume of `--volume` on the GPU; one that does not load is said on stderr and left out
/// (the tractogram is still shown).
fn load_anatomy(args: &RenderArgs, gpu: &Gpu) -> Option<Arc<SliceVolume>> {
    let path = args.context.volume.as_ref()?;
    let uploaded = lineao_tracts::Volume::load(path).map_err(anyhow::Error::from).and_then(|v| {
        let dims = v.dims.map(|d| d as u32);
        let affine = v.affine.as_mat4();
        SliceVolume::new(&gpu.device, &gpu.queue, dims, &v.values, affine)
            .with_context(|| format!("uploading {}", path.display()))
    });
    match uploaded {
        Ok(volume) => Some(Arc::new(volume)),
        Err(e) => {
            eprintln!("lineao: warning: {e:#}; the tractogram is shown without its slices");
            None
        }
    }
}

/// The context surfaces of `--surface`.
fn load_surfaces(args: &RenderArgs) -> Result<Vec<lineao_tracts::TriangleMesh>> {
    args.style.surfaces.iter().map(|path| lineao_tracts::load_mesh(path).map_err(anyhow::Error::from)).collect()
}

/// The attributes every panel has: the scalar of `--color field:NAME`, the radii of
/// `--tube-radius-field`.
fn base_attributes(args: &RenderArgs) -> AttributeKey {
    AttributeKey { scalar: args.style.color.field(), radius: args.style.tube_radius_field.clone(), volume: None }
}

/// Whether a panel `args` asks for needs the streamlines on the CPU: object-space AO (its
/// volumes are made there) and the ray tracers (their BVH is built there).
fn needs_points(args: &RenderArgs) -> bool {
    let methods = match (args.shown.compare, args.shown.grid) {
        (Some(pair), _) => pair.to_vec(),
        (None, true) => grid_methods(),
        (None, false) => vec![args.shown.method],
    };
    methods.iter().any(|m| m.volume.is_some() || m.screen.info().traces_scene)
}

/// The longest side of the axis-aligned box around the finite `points` (0 without any).
fn longest_side<'a>(points: impl Iterator<Item = &'a [f32; 3]>) -> f32 {
    lineao::Bounds::corners_of(points).map_or(0.0, |(lo, hi)| (hi - lo).max_element())
}

/// The camera of the command line (--eye, --target, --up, --fov, --ortho; or one --orbit around
/// the data's own), the rest from `hint`.
pub fn camera(args: &RenderArgs, hint: &ViewHint) -> Result<Camera> {
    let given = args.camera.eye.is_some() || args.camera.target.is_some() || args.camera.up.is_some();
    anyhow::ensure!(
        args.figure.orbit.is_empty() || !given,
        "--orbit places the camera around the data's: not with --eye, --target or --up"
    );
    let camera = Camera {
        eye: Vec3::from_array(args.camera.eye.unwrap_or(hint.eye)),
        target: Vec3::from_array(args.camera.target.unwrap_or(hint.target)),
        up: Vec3::from_array(args.camera.up.unwrap_or(hint.up)),
        projection: match (args.camera.ortho, args.camera.fov) {
            (Some(height), _) => Projection::Orthographic { height },
            (None, fov) => Projection::Perspective { fov_y_deg: fov.unwrap_or(hint.fov_y_deg) },
        },
    };
    validate_camera(&camera)?;
    match args.figure.orbit[..] {
        [orbit] => Ok(crate::cameras::orbit_camera(&camera, orbit)),
        _ => Ok(camera),
    }
}

/// The camera a built-in scene suggests.
pub fn camera_from_hint(hint: &ViewHint) -> Camera {
    Camera {
        eye: Vec3::from_array(hint.eye),
        target: Vec3::from_array(hint.target),
        up: Vec3::from_array(hint.up),
        projection: Projection::Perspective { fov_y_deg: hint.fov_y_deg },
    }
}

pub fn validate_camera(camera: &Camera) -> Result<()> {
    let forward = camera.target - camera.eye;
    anyhow::ensure!(forward.length() > 0.0, "the camera's eye and target coincide");
    anyhow::ensure!(
        forward.cross(camera.up).length() > 1e-6 * forward.length() * camera.up.length(),
        "the camera's up vector is parallel to its view direction (or zero)"
    );
    match camera.projection {
        Projection::Perspective { fov_y_deg } => {
            anyhow::ensure!(fov_y_deg > 0.0 && fov_y_deg < 180.0, "--fov must be in (0, 180) degrees, got {fov_y_deg}")
        }
        Projection::Orthographic { height } => {
            anyhow::ensure!(height > 0.0 && height.is_finite(), "--ortho must be a positive height, got {height}")
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// docs/reference.md: the library's default settings are the front ends' default — what
    /// `lineao render` with no option gives each method is `ChainSettings::default()`'s preset.
    #[test]
    fn the_librarys_default_is_the_command_lines() {
        let args = crate::args::parse_render(["lineao", "render"]);
        for screen in [lineao::AoMethod::LineAo, lineao::AoMethod::Ssao, lineao::AoMethod::VoLine] {
            let method = crate::args::Method { screen, volume: None };
            let cli = super::settings(&args, method, 1.0, lineao::volume::Sky::Uniform, 100.0);
            let library = lineao::ChainSettings { method: screen, ..lineao::ChainSettings::default() }
                .with_preset(lineao::Preset::default());
            assert_eq!(cli.line_ao, library.line_ao, "{screen:?}");
            assert_eq!(
                (cli.strength, &cli.ssao, &cli.vo),
                (library.strength, &library.ssao, &library.vo),
                "{screen:?}"
            );
        }
        // And the library's default itself is LineAO at the default preset.
        let default = lineao::ChainSettings::default();
        assert_eq!(default, lineao::ChainSettings::papers().with_preset(lineao::Preset::Legible));
        assert_eq!((default.line_ao.s_r, default.r0_px(), default.strength), (2, 9.0, 0.6));
    }

    /// A streamed file keeps the field it is coloured by, every chunk of it, so the colour
    /// range is the field's (the first chunk once went unseen and the range was [0, 1]); a
    /// per-streamline field spreads over its streamlines' vertices; a volume's samples are kept
    /// as a field.
    #[test]
    fn a_streamed_file_keeps_the_field_it_is_coloured_by() {
        let images =
            concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/niivue+niivue/packages/niivue/demos/images");
        let trx = format!("{images}/dpsv.trx");
        let mut loaded = lineao_tracts::load(&trx).unwrap();
        loaded.tractogram.spread_streamline_field("DataSetID");
        let volume = format!("volume:{images}/strokez.nii.gz");
        for color in ["field:z", "field:DataSetID", &volume] {
            let args = crate::args::parse_render(["lineao", "render", &trx, "--color", color]);
            let session = super::Session::open(&args).unwrap();
            let field = args.style.color.field().unwrap();
            let kept = session.lines.field(&field).unwrap();
            assert_eq!(kept.len(), 95865, "{color}");
            let expected = match loaded.tractogram.vertex_field(&field) {
                Some(f) => f.values.clone(),
                None => lineao_tracts::Volume::load(format!("{images}/strokez.nii.gz"))
                    .unwrap()
                    .sample_points(&loaded.tractogram.positions),
            };
            assert!(kept.iter().zip(&expected).all(|(a, b)| a.to_bits() == b.to_bits()), "{color}");
        }
    }

    /// Each method's samples and radius have flags of their own, so a grid sets them all; the
    /// shorthand `--samples` counts the shown method's only (each panel's).
    #[test]
    fn each_method_takes_its_own_samples_and_radius() {
        use lineao::AoMethod;
        let parse = |extra: &[&str]| {
            let args = crate::args::parse_render(["lineao", "render"].iter().chain(extra));
            move |screen| {
                let method = crate::args::Method { screen, volume: None };
                super::settings(&args, method, 1.0, lineao::volume::Sky::Uniform, 100.0)
            }
        };
        let grid = parse(&["--grid", "--ssao-samples", "12", "--vo-samples", "5", "--vo-area-samples", "7"]);
        let (ssao, vo_line, vo_area) = (grid(AoMethod::Ssao), grid(AoMethod::VoLine), grid(AoMethod::VoArea));
        assert_eq!((ssao.ssao.samples, vo_line.vo.samples, vo_area.vo.area_samples), (12, 5, 7));
        let radii = parse(&["--grid", "--ssao-radius", "3", "--vo-radius", "1.5"]);
        assert_eq!((radii(AoMethod::Ssao).ssao.radius_world, radii(AoMethod::VoLine).vo.radius_world), (3.0, 1.5));
        // --samples: the panel's own method's, the others' untouched.
        let shown = parse(&["--method", "vo-line", "--samples", "13"])(AoMethod::VoLine);
        assert_eq!((shown.vo.samples, shown.vo.area_samples, shown.ssao.samples), (13, 1, 16));
    }

    /// `--settings` changes the keys it names, over the preset and the options, and nothing else.
    #[test]
    fn settings_as_json_change_only_their_keys() {
        let settings = |extra: &[&str]| {
            let args = crate::args::parse_render(["lineao", "render", "--ssao-samples", "24"].iter().chain(extra));
            let method = crate::args::Method { screen: lineao::AoMethod::Ssao, volume: None };
            super::settings(&args, method, 1.0, lineao::volume::Sky::Uniform, 100.0)
        };
        let plain = settings(&[]);
        assert_eq!(settings(&["--settings", "{}"]), plain);
        let patched = settings(&["--settings", r#"{"ssao": {"samples": 12}, "strength": 0.25, "blur": {}}"#]);
        let expected = lineao::ChainSettings {
            ssao: lineao::SsaoSettings { samples: 12, ..plain.ssao.clone() },
            strength: 0.25,
            blur: Some(lineao::BilateralSettings::default()),
            ..plain
        };
        assert_eq!(patched, expected);
    }

    #[test]
    fn the_longest_side_is_the_boxs_over_finite_points() {
        let points = [[0.0, 0.0, 0.0], [10.0, -5.0, 2.0], [f32::NAN, 1e9, 0.0], [3.0, 25.0, 1.0]];
        // x spans 10, y 30 (the NaN point left out), z 2.
        assert_eq!(super::longest_side(points.iter()), 30.0);
        assert_eq!(super::longest_side([].iter()), 0.0);
    }
}
