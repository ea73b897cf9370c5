//! The pass chain: geometry → ND pyramid → LineAO → composite, for one chosen method. It owns
//! the passes and every size-dependent texture ([`FrameTargets`]); `resize` follows the window,
//! `prepare` follows the camera (and grows the guard band when the sampling radius needs it),
//! `encode` records a frame into the caller's encoder and target view.
//!
//! ```text
//!   LineGeometry ─▶ LineRenderer ─▶ color, nd[0], zoom, specular, depth
//!                                       │
//!                          NdPyramid ◀──┘ nd[1..s_r]
//!                                       │
//!                          LineAo    ◀──┘ ao
//!                                       │
//!   target view ◀─ Composite ◀──────────┘ color · (1 − strength · ao) + specular
//! ```
//!
//! With [`AoMethod::Ssao`] the pyramid and LineAO give way to Crytek SSAO (`nd[0]` → its raw occlusion)
//! and its 4 × 4 blur (→ `ao`); with [`AoMethod::VoLine`] to Volumetric Obscurance
//! with line samples (`nd[0]`, `zoom` → `ao`); with [`AoMethod::VoArea`] to the moments pyramid
//! (`nd[0]` → `moments`) and VO with area samples (→ `ao`). With `ChainSettings::blur` the
//! bilateral blur follows any method (`ao` → `ao_blurred`, which the composite then shows);
//! with anatomy slices and no such blur it smooths the slices' pixels alone
//! ([`ChainSettings::bilateral`]).
//! With `ChainSettings::volume` the line renderer also writes the geometry's octant
//! visibilities (`octants`), the [`VolumeAo`] pass makes object-space AO of them with each
//! pixel's normal (`volume_ao`), and the composite shows it alone (method `None`) or combined
//! with the method's occlusion.
//!
//! With `ChainSettings::transparency` the lines of opacity below 1 are left out of the G-buffer
//! and composited over the composite's picture in depth order, each darkened by its own
//! object-space AO ([`crate::passes::transparency`]).
//!
//! Two wrappers embed the chain in a host renderer: [`HostAo`] runs it over the host's own depth
//! (and normals, color) instead of lineao's lines, and [`OverlayAo`] draws lineao's lines with
//! their occlusion into the host's frame.
//!
//! Each method is a [`crate::method::Stage`]: the chain builds only the active method's stage
//! (keeping a few built ones for settings it may switch back to), asks it how far it reads for
//! the guard band and which timing spans it records, and binds, prepares and records it without
//! branching on the method.
//!
//! Every pass is labelled and the frame sits in a `lineao` debug group, so GPU debuggers show
//! the chain by name. With [`AoChain::set_timing`] each pass also records timestamp queries under
//! the names `lineao bench` uses (docs/reference.md): `lines`, `nd-pyramid`, `lineao`, `raytraced`,
//! `ray-denoise`, `ssao`, `ssao-blur`, `vo-line`, `moments`, `vo-area`, `blur`, `volume-ao`, `composite`,
//! `transparency`.

mod host;
mod overlay;

use std::sync::Arc;

use crate::LineGeometry;
use crate::camera::{self, Bounds, Camera, FrameView, Tile};
use crate::gbuffer::{self, Load};
use crate::lighting::LightingShape;
use crate::method::{self, Reach};
use crate::passes::bilateral::{Bilateral, Region};
use crate::passes::composite::{Composite, Shown};
use crate::passes::cull::Frozen;
use crate::passes::lines::LineRenderer;
use crate::passes::lines::LineStyle;
use crate::passes::meshes::{MeshGeometry, MeshRenderer};
use crate::passes::seed_depth::SeedDepth;
use crate::passes::slices::{SliceRenderer, SliceVolume};
use crate::passes::transparency::{self, Transparency};
use crate::passes::tubes::TubeRenderer;
use crate::passes::volume_ao::VolumeAo;
use crate::ray_scene::RayScene;
use crate::settings::{AoMethod, ChainSettings};
use crate::stage::Stages;
use crate::targets::FrameTargets;
use crate::timing::{PassTime, PassTimer, Span};
use crate::{DebugView, LineColor};
use crate::{Error, Misuse};

pub use host::HostAo;
pub use overlay::OverlayAo;

/// The pass chain of one method: the line geometry's G-buffer, the method's passes and the
/// composite, with every size-dependent texture ([`FrameTargets`](crate::targets::FrameTargets)).
/// `resize` to the image, `prepare` each frame with the camera, then `encode` into a command encoder.
pub struct AoChain {
    settings: ChainSettings,
    lines: LineRenderer,
    /// Made when the settings ask for tubes.
    tubes: Option<TubeRenderer>,
    /// Made when the settings ask for context surfaces.
    meshes: Option<MeshRenderer>,
    /// Made when the settings ask for anatomy slices; draws them once a volume is set.
    slices: Option<SliceRenderer>,
    /// The volume the slices cut ([`AoChain::set_slice_volume`]).
    slice_volume: Option<Arc<SliceVolume>>,
    /// The method's stage (built for the active method only; [`crate::stage`]).
    stages: Stages,
    bilateral: Bilateral,
    /// Made when the settings ask for object-space AO.
    volume_ao: Option<VolumeAo>,
    /// Made when the settings draw lines transparent.
    transparency: Option<Transparency>,
    composite: Composite,
    /// An overlay's seeding of the G-buffer's depth from the host's ([`OverlayAo::set_depth`]).
    seed: Option<SeedDepth>,
    /// The composite's target format.
    format: wgpu::TextureFormat,
    size: (u32, u32),
    /// Where the frame lies in a larger picture rendered as tiles ([`AoChain::set_tile`]).
    tile: Option<Tile>,
    /// The device's limits, which the sizes are checked against.
    limits: wgpu::Limits,
    targets: Option<FrameTargets>,
    view: Option<FrameView>,
    timer: Option<PassTimer>,
}

/// What a frame draws into its G-buffer ([`AoChain::encode`]): the lines (or tubes), and the
/// context surfaces drawn after them.
#[derive(Clone, Copy)]
pub struct Drawn<'g> {
    /// The lines.
    pub lines: &'g LineGeometry,
    /// The context surfaces (drawn with [`ChainSettings::surfaces`]).
    pub meshes: &'g [&'g MeshGeometry],
}

impl<'g> From<&'g LineGeometry> for Drawn<'g> {
    fn from(lines: &'g LineGeometry) -> Drawn<'g> {
        Drawn { lines, meshes: &[] }
    }
}

impl<'g> From<(&'g LineGeometry, &'g [&'g MeshGeometry])> for Drawn<'g> {
    fn from((lines, meshes): (&'g LineGeometry, &'g [&'g MeshGeometry])) -> Drawn<'g> {
        Drawn { lines, meshes }
    }
}

impl AoChain {
    /// A chain that composites into targets of `format`. A device that cannot run the passes
    /// (whose adapter [`crate::gpu::check_adapter`] refuses) or a `format` that cannot be
    /// rendered to is an [`Error::Unsupported`], not wgpu's panic.
    ///
    /// Blocks on wgpu's validation answer, which native wgpu gives at once; a host that must
    /// never block (the web, an async runtime) awaits [`AoChain::new_async`].
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat, settings: ChainSettings) -> Result<AoChain, Error> {
        pollster::block_on(Self::new_async(device, format, settings))
    }

    /// [`AoChain::new`] as a future.
    pub async fn new_async(
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        settings: ChainSettings,
    ) -> Result<AoChain, Error> {
        settings.validate()?;
        if format.is_depth_stencil_format() {
            return Err(Error::Usage(Misuse::TextureFormat {
                texture: "AoChain::new's format".into(),
                format,
                samples: 1,
                expected: "the colour format the composite writes, not the depth's".into(),
            }));
        }
        if settings.transparent().is_some() {
            transparency::check_format(device, format)?;
        }
        crate::gpu::validated_async(device, "creating the pass chain's pipelines", || {
            let lines = line_renderer(device, &settings);
            AoChain {
                stages: {
                    let mut stages = Stages::default();
                    stages.select(&settings, None, device, || method::build(device, &settings));
                    stages
                },
                transparency: transparency_passes(device, &settings, &lines, format),
                lines,
                tubes: tube_renderer(device, &settings),
                meshes: settings
                    .surfaces
                    .as_ref()
                    .map(|_| MeshRenderer::new(device, settings.volume.is_some(), lit(&settings))),
                slices: settings.slices.as_ref().map(|_| SliceRenderer::new(device, settings.volume.is_some())),
                slice_volume: None,
                bilateral: Bilateral::new(device),
                volume_ao: settings.volume.as_ref().map(|_| VolumeAo::new(device)),
                composite: Composite::new(device, format),
                seed: None,
                format,
                settings,
                size: (0, 0),
                tile: None,
                limits: device.limits(),
                targets: None,
                view: None,
                timer: None,
            }
        })
        .await
    }

    /// The settings it runs with.
    pub fn settings(&self) -> &ChainSettings {
        &self.settings
    }

    /// Changes settings; pipelines and targets are rebuilt only where needed. Blocks on wgpu's
    /// validation answer as [`AoChain::new`] does; [`AoChain::set_settings_async`] awaits it.
    pub fn set_settings(&mut self, device: &wgpu::Device, settings: ChainSettings) -> Result<(), Error> {
        pollster::block_on(self.set_settings_async(device, settings))
    }

    /// [`AoChain::set_settings`] as a future.
    pub async fn set_settings_async(&mut self, device: &wgpu::Device, settings: ChainSettings) -> Result<(), Error> {
        settings.validate()?;
        self.check_size(&settings, self.size.0, self.size.1)?;
        if settings.transparent().is_some() {
            transparency::check_format(device, self.format)?;
        }
        // The method's pipelines: kept when they still compute the settings, else a kept or a
        // new stage (the targets stay; a new stage binds them).
        let (stages, targets) = (&mut self.stages, self.targets.as_ref());
        crate::gpu::validated_async(device, "creating the method's pipelines", || {
            stages.select(&settings, targets, device, || method::build(device, &settings))
        })
        .await?;
        let octants = settings.volume.is_some();
        let shape = lit(&settings);
        let lines_stale = octants != self.lines.writes_octants()
            || shape != self.lines.lighting_shape()
            || settings.slab.is_some() != self.lines.cuts()
            || settings.cull != self.lines.culls()
            || (settings.cull && settings.levels_of_detail() != self.lines.lods());
        if lines_stale {
            // Writing octants or not, testing a slab or not, culling (at levels of detail) or not,
            // the lighting's shape, are matters of the geometry pipelines.
            self.lines = line_renderer(device, &settings);
            self.volume_ao = settings.volume.as_ref().map(|_| VolumeAo::new(device));
        }
        let tubes_match = match (&self.tubes, &settings.tubes) {
            (Some(renderer), Some(_)) => {
                renderer.writes_octants() == octants
                    && renderer.cull().is_some() == settings.cull
                    && (!settings.cull || renderer.lods() == settings.levels_of_detail())
                    && renderer.lighting_shape() == shape
            }
            (None, None) => true,
            _ => false,
        };
        if !tubes_match {
            self.tubes = tube_renderer(device, &settings);
        }
        // The transparent lines' pipelines bind the line renderer's group 0.
        let slab = settings.slab.is_some();
        let transparency_stale = match (&self.transparency, settings.transparent()) {
            (Some(pass), Some(t)) => lines_stale || !pass.made_for(t.layers, octants, slab, shape),
            (None, None) => false,
            _ => true,
        };
        if transparency_stale {
            self.transparency = transparency_passes(device, &settings, &self.lines, self.format);
        }
        // Surfaces and slices: there when asked for, writing the octants where object-space AO is on.
        let meshes = |m: &MeshRenderer| (m.writes_octants(), m.lighting_shape());
        if self.meshes.as_ref().map(meshes) != settings.surfaces.as_ref().map(|_| (octants, shape)) {
            self.meshes = settings.surfaces.as_ref().map(|_| MeshRenderer::new(device, octants, shape));
        }
        if self.slices.as_ref().map(SliceRenderer::writes_octants) != settings.slices.as_ref().map(|_| octants) {
            self.slices = settings.slices.as_ref().map(|_| SliceRenderer::new(device, octants));
            if let Some(renderer) = &mut self.slices {
                renderer.set_volume(device, self.slice_volume.clone());
                if let Some(targets) = &self.targets {
                    renderer.resize(device, targets);
                }
            }
        }
        // The pyramid's depth, the method's own targets, the blur's and object-space AO's, and
        // what the composite shows are bound at allocation.
        let layout = |s: &ChainSettings| (s.levels(), s.bilateral().is_some(), s.volume.is_some());
        if layout(&settings) != layout(&self.settings) {
            self.targets = None;
        }
        self.settings = settings;
        Ok(())
    }

    /// The geometry the ray-traced method ([`AoMethod::RayTraced`]) traces: what the frame draws,
    /// uploaded once per geometry ([`RayScene::new`]). Without a scene that method shows no
    /// occlusion. A new scene starts the progressive picture again; the same one again keeps it.
    pub fn set_ray_scene(&mut self, device: &wgpu::Device, scene: Option<Arc<RayScene>>) {
        self.stages.set_scene(device, scene, self.targets.as_ref());
    }

    /// The volume whose anatomy slices the frame shows with [`ChainSettings::slices`] (kept
    /// while the settings change; none: no slices are drawn). The frame's `bounds` given to
    /// `prepare` should hold the slices ([`SliceVolume::slice_bounds`]).
    pub fn set_slice_volume(&mut self, device: &wgpu::Device, volume: Option<Arc<SliceVolume>>) {
        if crate::stage::same(&self.slice_volume, &volume) {
            return;
        }
        if let Some(renderer) = &mut self.slices {
            renderer.set_volume(device, volume.clone());
        }
        self.slice_volume = volume;
    }

    /// The active method's stage (none after `none`): its occlusion before its own blur
    /// ([`method::Stage::unblurred`]); as its own type (`downcast::<T>()`), its own targets and state
    /// for readback: VO area's moments, [`crate::method::vo_area::VoArea::moments`]; the ray
    /// tracer's accumulation and how far its picture has come,
    /// [`crate::method::raytraced::RayTracedAo::accumulation`] and
    /// [`crate::method::raytraced::RayTracedAo::progress`].
    pub fn stage(&self) -> Option<&dyn method::Stage> {
        self.stages.active()
    }

    /// Turns per-pass GPU timing on or off (a timer that is on stays as it is, so a host may
    /// call it every frame). Returns whether timing is on: it stays off on adapters without
    /// timestamp queries.
    pub fn set_timing(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, enabled: bool) -> bool {
        if enabled != self.timer.is_some() {
            self.timer = if enabled { PassTimer::new(device, queue, &method::pass_names()) } else { None };
        }
        self.timer.is_some()
    }

    /// What the cull drew of `geometry` in the last frame (lines, or tubes where the settings
    /// ask for them), read back (waits for the device); `None` where it does not cull, or
    /// cannot on this device.
    pub fn cull_counts(
        &self,
        queue: &wgpu::Queue,
        geometry: &LineGeometry,
    ) -> Result<Option<crate::passes::cull::CullCounts>, Error> {
        let culled = match &self.tubes {
            Some(tubes) => tubes.cull(),
            None => self.lines.cull(),
        };
        culled.filter(|c| c.note().is_none()).map(|c| c.counts(queue, geometry)).transpose()
    }

    /// GPU time of each pass of a frame, or `None` when timing is off; passes the method skips
    /// are left out. With `wait`, of the last submitted frame (it waits for the GPU); without,
    /// for a host's render loop, of a finished earlier frame, or `None` while the GPU is still
    /// at it (frames submitted while a readback is pending are not timed).
    pub fn pass_times(&self, device: &wgpu::Device, wait: bool) -> Result<Option<Vec<PassTime>>, Error> {
        let Some(timer) = &self.timer else { return Ok(None) };
        match wait {
            true => timer.read(device, &self.timed_spans()).map(Some),
            false => timer.try_read(device, &self.timed_spans()),
        }
    }

    /// The spans a frame with the current settings records.
    fn timed_spans(&self) -> Vec<&'static str> {
        let method = self.stages.active().map_or(&[][..], |stage| stage.spans(&self.settings));
        let blur: &[&str] = if self.settings.bilateral().is_some() { &["blur"] } else { &[] };
        let volume: &[&str] = if self.settings.volume.is_some() { &["volume-ao"] } else { &[] };
        let transparency: &[&str] = if self.transparency.is_some() { &["transparency"] } else { &[] };
        [&["lines"], method, blur, volume, &["composite"], transparency].concat()
    }

    /// Sets the visible size. 0 × 0 (a minimized window) is allowed: nothing is rendered until a
    /// real size comes back.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), Error> {
        self.check_size(&self.settings, width, height)?;
        if (width, height) != self.size {
            self.size = (width, height);
            self.targets = None;
        }
        Ok(())
    }

    /// Renders the chain's size as one tile of a larger picture (`None`: the frame is the
    /// picture): at `tile.origin` of a picture of `tile.picture`, seen by the picture's camera,
    /// with the guard band, noise and levels of detail of the picture, so that tiles stitch
    /// into what one frame of the picture's size shows. The tile must lie inside the picture.
    pub fn set_tile(&mut self, tile: Option<Tile>) -> Result<(), Error> {
        if let Some(t) = tile {
            let (w, h) = self.size;
            let fits = |origin: u32, size: u32, picture: u32| origin as u64 + size as u64 <= picture as u64;
            if !fits(t.origin[0], w, t.picture[0]) || !fits(t.origin[1], h, t.picture[1]) {
                return Err(Error::Usage(Misuse::TileOutside { size: (w, h), tile: t }));
            }
        }
        self.tile = tile;
        Ok(())
    }

    /// Whether `settings` fit the adapter at `width` × `height` with the largest guard band.
    fn check_size(&self, settings: &ChainSettings, width: u32, height: u32) -> Result<(), Error> {
        let guard = settings.guard_max_px;
        let limit = self.limits.max_texture_dimension_2d.saturating_sub(2 * guard);
        if width > limit || height > limit {
            let message = format!(
                "{width} x {height} px exceeds the adapter's {} px textures less the guard band",
                self.limits.max_texture_dimension_2d
            );
            let (value, max) = (width.max(height) as u64, limit as u64);
            return Err(Error::TooLarge { limit: crate::Limit::TextureDimension2d, value, max, message });
        }
        let banded = (width + 2 * guard, height + 2 * guard);
        (settings.method.info().fits)(banded, &self.limits)?;
        if let Some(t) = settings.transparent() {
            transparency::fits(t, banded, &self.limits)?;
        }
        Ok(())
    }

    /// The guard band for this view: the largest sampling radius over the image (docs/reference.md).
    fn guard_for(&self, camera: &Camera, bounds: &Bounds) -> u32 {
        let s = &self.settings;
        // Plain lines read no neighbours on screen.
        let Some(stage) = self.stages.active() else { return 0 };
        // A tile's reach is its picture's: every tile has the same band.
        let (width, height) = self.tile.map_or(self.size, |t| (t.picture[0], t.picture[1]));
        let unguarded = FrameView::new(camera, bounds, width, height, 0, s.zoom_unit);
        match stage.reach(s, &unguarded) {
            Reach::Unbounded => s.guard_max_px,
            // The bilateral blur reaches its radius further.
            Reach::Pixels { radius_px, levels } => {
                let blur = s.bilateral().map_or(0.0, |(b, _)| b.radius_px as f32);
                camera::guard_band(radius_px + blur, levels, s.guard_max_px)
            }
        }
    }

    /// Writes the frame's uniforms for `camera` over geometry within `bounds`, (re)allocating
    /// the targets when the size, guard band or pyramid depth changed. Returns the frame's view,
    /// or `None` while the size is 0 × 0.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        camera: &Camera,
        bounds: &Bounds,
    ) -> Option<FrameView> {
        let (width, height) = self.size;
        if width == 0 || height == 0 {
            self.view = None;
            return None;
        }
        let guard = self.guard_for(camera, bounds);
        let zoom_unit = self.settings.zoom_unit;
        let view = match self.tile {
            Some(tile) => FrameView::tile(camera, bounds, tile, (width, height), guard, zoom_unit),
            None => FrameView::new(camera, bounds, width, height, guard, zoom_unit),
        };
        self.prepare_frame(device, queue, view)
    }

    /// [`AoChain::prepare`] for a view made elsewhere (a host's own matrices); the view's zoom
    /// unit is replaced by [`ChainSettings::zoom_unit`], the one place it is set.
    fn prepare_view(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        view: FrameView,
    ) -> Result<Option<FrameView>, Error> {
        let (width, height) = self.size;
        if (view.width, view.height) != (width, height) {
            self.view = None;
            return Err(Error::Usage(Misuse::Size {
                texture: "the view".into(),
                size: (view.width, view.height),
                chain: (width, height),
            }));
        }
        let view = FrameView { zoom_unit: self.settings.zoom_unit, ..view };
        Ok(self.prepare_frame(device, queue, view))
    }

    /// The uniforms for `view` (of the chain's size), reallocating targets when needed.
    fn prepare_frame(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, view: FrameView) -> Option<FrameView> {
        let (width, height) = self.size;
        if width == 0 || height == 0 {
            self.view = None;
            return None;
        }
        let guard = view.guard;
        let s = &self.settings;
        let levels = s.levels();
        let stale = self.targets.as_ref().is_none_or(|t| t.guard != guard || t.nd.len() != levels as usize);
        if stale {
            let mut targets = FrameTargets::new(device, width, height, guard, levels);
            if s.bilateral().is_some() {
                targets = targets.with_blur(device);
            }
            if s.volume.is_some() {
                targets = targets.with_volume(device);
            }
            self.stages.resize(device, &targets);
            self.bilateral.resize(device, &targets);
            if let Some(renderer) = &mut self.slices {
                renderer.resize(device, &targets);
            }
            if let Some(pass) = &mut self.volume_ao {
                pass.resize(device, &targets);
            }
            let shown = targets.shown();
            self.composite.resize(device, &targets, shown);
            self.targets = Some(targets);
        }
        let targets = self.targets.as_ref()?;
        let pieces = matches!(s.debug_view, DebugView::Pieces | DebugView::Frozen | DebugView::Culled);
        let color = if pieces { LineColor::Pieces } else { s.line_color };
        let culls = [self.lines.cull(), self.tubes.as_ref().and_then(TubeRenderer::cull)];
        let frozen = match s.debug_view {
            DebugView::Frozen => Frozen::Visible,
            DebugView::Culled => Frozen::All,
            _ => Frozen::No,
        };
        for culled in culls.into_iter().flatten() {
            culled.cull().set_frozen(frozen);
        }
        match (&self.tubes, &s.tubes) {
            (Some(tubes), Some(t)) => tubes.prepare(queue, &view, t.radius_world, color, &s.lighting, s.slab.as_ref()),
            _ => self.lines.prepare(queue, &view, s.line_width_px, color, &s.lighting, s.slab.as_ref()),
        }
        if let (Some(meshes), Some(surfaces)) = (&self.meshes, &s.surfaces) {
            meshes.prepare(queue, &view, surfaces.color, &s.lighting);
        }
        if let (Some(renderer), Some(slices)) = (&self.slices, &s.slices) {
            renderer.prepare(queue, &view, slices, &s.lighting);
        }
        if let Some(stage) = self.stages.active() {
            stage.prepare(queue, targets, &view, s);
        }
        if let Some((blur, slices_only)) = s.bilateral() {
            let region = if slices_only { Region::Slices } else { Region::All };
            self.bilateral.prepare(queue, &view, &blur, region);
        }
        if let (Some(pass), Some(volume)) = (&self.volume_ao, &s.volume) {
            pass.prepare(queue, &view, volume.sky);
        }
        let shown = match (s.method, &s.volume) {
            (_, None) => Shown::Screen,
            (AoMethod::None, Some(_)) => Shown::Volume,
            (_, Some(volume)) => Shown::Both(volume.combine),
        };
        let strength = if s.method == AoMethod::None && s.volume.is_none() { 0.0 } else { s.strength };
        if let (Some(pass), Some(t)) = (&mut self.transparency, s.transparent()) {
            pass.resize(device, targets);
            let sky = s.volume.as_ref().map_or([1.0; 8], |v| v.sky);
            pass.prepare(queue, &view, t, strength, sky);
        }
        self.composite.prepare(queue, targets, &view, strength, s.debug_view, shown);
        if let (Some(seed), Some(Some(host))) = (&self.seed, self.composite.overlay_depth()) {
            seed.prepare(queue, targets, &view, &host);
        }
        self.view = Some(view);
        Some(view)
    }

    /// The composite's target: a render attachment of the chain's format and visible size.
    fn check_target(&self, target: &wgpu::TextureView) -> Result<(), Error> {
        self.check_attachment("the composite's target", target.texture(), self.format, "the chain was made for")
    }

    /// A texture the chain draws into: `RENDER_ATTACHMENT`, `format` (or, for color, its sRGB
    /// twin: a view may reinterpret it), one sample, the visible size; `source` says where the
    /// format was set.
    fn check_attachment(
        &self,
        what: &str,
        texture: &wgpu::Texture,
        format: wgpu::TextureFormat,
        source: &str,
    ) -> Result<(), Error> {
        let (width, height) = self.size;
        if !texture.usage().contains(wgpu::TextureUsages::RENDER_ATTACHMENT) {
            return Err(Error::Usage(Misuse::TextureUsage {
                texture: what.into(),
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                has: texture.usage(),
            }));
        }
        if texture.format().remove_srgb_suffix() != format.remove_srgb_suffix() || texture.sample_count() != 1 {
            return Err(Error::Usage(Misuse::TextureFormat {
                texture: what.into(),
                format: texture.format(),
                samples: texture.sample_count(),
                expected: format!("{format:?} with 1 sample ({source} it)"),
            }));
        }
        if (texture.width(), texture.height()) != (width, height) {
            return Err(Error::Usage(Misuse::Size {
                texture: what.into(),
                size: (texture.width(), texture.height()),
                chain: (width, height),
            }));
        }
        Ok(())
    }

    /// The occlusion the composite shows (after the blur when there is one): what a host that
    /// lights its own pixels samples. `None` before the first `prepare`.
    pub fn ao_view(&self) -> Option<&wgpu::TextureView> {
        let targets = self.targets.as_ref()?;
        Some(&targets.shown().view)
    }

    /// Records the frame into `encoder`, compositing into `target`: `RENDER_ATTACHMENT`, the
    /// visible size, the format given to `new` (or its sRGB twin), one sample. `drawn` is the
    /// lines (`&geometry`), or the lines and context surfaces drawn after them into the same
    /// G-buffer (`(&geometry, &meshes[..])`, with [`ChainSettings::surfaces`]; the frame's
    /// `bounds` given to `prepare` should hold them too). A mismatch, or a frame not prepared,
    /// is an [`Error::Usage`] with nothing recorded; a 0 × 0 chain records nothing — as
    /// [`crate::HostAo::encode`] and [`crate::OverlayAo::encode`].
    pub fn encode<'g>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        drawn: impl Into<Drawn<'g>>,
        target: &wgpu::TextureView,
    ) -> Result<(), Error> {
        let Drawn { lines: geometry, meshes } = drawn.into();
        if self.size.0 == 0 || self.size.1 == 0 {
            return Ok(());
        }
        if self.targets.is_none() || self.view.is_none() {
            return Err(Error::Usage(Misuse::Order { call: "AoChain::encode", first: "AoChain::prepare" }));
        }
        self.check_target(target)?;
        self.record(
            encoder,
            |encoder, targets, span| {
                self.draw_geometry(encoder, targets, geometry, meshes, Load::Clear(self.settings.background), span)
            },
            |composite, encoder, span| {
                composite.encode(encoder, target, span("composite"));
                self.encode_transparency(encoder, geometry, target, span("transparency"));
            },
        );
        Ok(())
    }

    /// Records a frame: `gbuffer` writes the G-buffer, then the method, its blur and
    /// object-space AO, then `composite` (the last step, which targets the caller's views), in a
    /// `lineao` debug group with the timer's spans. Does nothing before the first `prepare` with
    /// a non-zero size.
    fn record<'s>(
        &'s self,
        encoder: &mut wgpu::CommandEncoder,
        gbuffer: impl FnOnce(&mut wgpu::CommandEncoder, &'s FrameTargets, Option<Span<'s>>),
        composite: impl FnOnce(&'s Composite, &mut wgpu::CommandEncoder, &dyn Fn(&'static str) -> Option<Span<'s>>),
    ) {
        let (Some(targets), Some(_)) = (&self.targets, &self.view) else { return };
        let span = |name| self.timer.as_ref().and_then(|t| t.span(name));
        encoder.push_debug_group("lineao");
        gbuffer(encoder, targets, span("lines"));
        self.encode_method(encoder, targets, &span);
        composite(&self.composite, encoder, &span);
        if let Some(timer) = &self.timer {
            timer.resolve(encoder);
        }
        encoder.pop_debug_group();
    }

    /// The anatomy slices, the lines (or tubes) and the context surfaces into the G-buffer, under
    /// one `span`. The slices first: they are three quads, and the lines behind them then fail
    /// the depth test before they are shaded, and the cull leaves their pieces out.
    fn draw_geometry(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        meshes: &[&MeshGeometry],
        load: Load,
        span: Option<Span<'_>>,
    ) {
        let meshes = self.meshes.as_ref().filter(|_| !meshes.is_empty()).map(|renderer| (renderer, meshes));
        let slices = self.slices.as_ref().filter(|renderer| renderer.has_volume());
        // The span starts with the first pass and ends with the last.
        let (mut first_span, mut last_span) = match (&meshes, slices) {
            (None, None) => (span, None),
            _ => Span::split(span),
        };
        let mut load = load;
        if let Some(renderer) = slices {
            renderer.encode(encoder, targets, load, first_span.take());
            load = Load::Keep;
        }
        let lines_span = match (first_span, meshes.is_some()) {
            (Some(first), _) => Some(first),
            (None, false) => last_span.take(),
            (None, true) => None,
        };
        match &self.tubes {
            Some(tubes) => tubes.encode(encoder, targets, geometry, load, lines_span),
            // The selected lines are the transparency's: the G-buffer is only cleared.
            None if self.settings.transparent().is_some_and(|t| t.focus_transparent()) => {
                drop(gbuffer::begin(
                    encoder,
                    "lineao::LineRenderer",
                    targets,
                    load,
                    targets.octants.is_some(),
                    lines_span,
                ));
            }
            None => self.lines.encode(encoder, targets, geometry, load, lines_span),
        }
        if let Some((renderer, meshes)) = meshes {
            renderer.encode(encoder, targets, meshes, Load::Keep, last_span);
        }
    }

    /// The transparent lines of `geometry` over the opaque picture in `target`, where the
    /// settings draw any.
    fn encode_transparency(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &LineGeometry,
        target: &wgpu::TextureView,
        span: Option<Span<'_>>,
    ) {
        if let Some(pass) = &self.transparency {
            pass.encode(encoder, geometry, &self.lines, target, span);
        }
    }

    /// Records only the composite of the last prepared frame over the targets as they are: for a
    /// caller that wrote its own occlusion into `targets().ao` after the frame's G-buffer was
    /// rendered (the CPU truth, `lineao render --method raytraced --cpu`). Does nothing before the first
    /// `prepare` with a non-zero size; before it, and with a target `encode` would refuse, it is
    /// the same [`Error::Usage`], with nothing recorded.
    pub fn encode_composite(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
    ) -> Result<(), Error> {
        if self.size.0 == 0 || self.size.1 == 0 {
            return Ok(());
        }
        if self.targets.is_none() || self.view.is_none() {
            return Err(Error::Usage(Misuse::Order { call: "AoChain::encode_composite", first: "AoChain::prepare" }));
        }
        self.check_target(target)?;
        self.composite.encode(encoder, target, None);
        Ok(())
    }

    /// The method, its blur and object-space AO over a G-buffer already written.
    fn encode_method<'s>(
        &'s self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'s>>,
    ) {
        // None has no stage.
        if let Some(stage) = self.stages.active() {
            stage.encode(encoder, targets, span);
        }
        if self.settings.bilateral().is_some() {
            self.bilateral.encode(encoder, targets, span("blur"));
        }
        if let Some(pass) = &self.volume_ao {
            pass.encode(encoder, targets, span("volume-ao"));
        }
    }

    /// The targets of the last `prepare` (for readback, debugging, or a host's own passes).
    pub fn targets(&self) -> Option<&FrameTargets> {
        self.targets.as_ref()
    }

    /// The view of the last `prepare`.
    pub fn frame_view(&self) -> Option<&FrameView> {
        self.view.as_ref()
    }
}

/// The chain's line renderer for `settings`: fixed-width quads, writing the octants with
/// object-space AO, testing the slab where there is one, culled on the GPU with [`ChainSettings::cull`] (at levels of detail with
/// [`ChainSettings::lod`]).
fn line_renderer(device: &wgpu::Device, settings: &ChainSettings) -> LineRenderer {
    let (octants, slab) = (settings.volume.is_some(), settings.slab.is_some());
    let renderer = LineRenderer::with_slab(device, LineStyle::Quads, octants, slab, lit(settings));
    if settings.cull { renderer.culled(device, settings.levels_of_detail()) } else { renderer }
}

/// The lighting the chain's geometry pipelines are compiled for: exactly the settings' (a new
/// one rebuilds them, [`AoChain::set_settings`]).
fn lit(settings: &ChainSettings) -> LightingShape {
    LightingShape::of(&settings.lighting)
}

/// The chain's tube renderer where `settings` asks for tubes: writing the octants with
/// object-space AO, culled on the GPU with [`ChainSettings::cull`] (at levels of detail with
/// [`ChainSettings::lod`]).
fn tube_renderer(device: &wgpu::Device, settings: &ChainSettings) -> Option<TubeRenderer> {
    settings.tubes.as_ref()?;
    let renderer = TubeRenderer::new(device, settings.volume.is_some(), lit(settings));
    Some(if settings.cull { renderer.culled(device, settings.levels_of_detail()) } else { renderer })
}

/// The transparent lines' passes where `settings` draw any, for the line renderer `lines`
/// compositing into `format`.
fn transparency_passes(
    device: &wgpu::Device,
    settings: &ChainSettings,
    lines: &LineRenderer,
    format: wgpu::TextureFormat,
) -> Option<Transparency> {
    let t = settings.transparent()?;
    Some(Transparency::new(device, lines, t.layers, settings.volume.is_some(), settings.slab.is_some(), format))
}
