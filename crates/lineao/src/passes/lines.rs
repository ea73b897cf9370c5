//! Line renderer: polylines at a fixed pixel width, the way LineAO expects them ("the intrinsic
//! fixed line width on screen", paper §2–3). wgpu has no wide lines, so each polyline is one
//! triangle strip whose vertices the vertex shader pushes half a line width to either side of
//! the curve (see `shaders/lines.wgsl`).
//!
//! Per pixel it writes the G-buffer of docs/reference.md: base color, the ND map (n = (T × C) × T
//! normalized, facing the eye; normalized linear depth), the zoom map, the illuminated-lines
//! specular and hardware depth.
//!
//! The geometry it draws — clusters its vertex shader pulls, and which of them may be drawn as
//! the alternating strip — is `line_geometry`'s.

use std::sync::atomic::{AtomicU32, Ordering};

use crate::camera::FrameView;
use crate::gbuffer::{self, GeometryBindings, GeometryUniform, Load, PipelineSpec};
use crate::lighting::{Lighting, LightingShape};
#[cfg(feature = "reference")]
pub use crate::line_geometry::strip::{StripGeometry, StripRenderer};
pub use crate::line_geometry::{
    CLUSTER_POINTS, ClusterRecord, DEFAULT_PAGE_BYTES, GeometryOptions, VertexAttributes, stored_radius,
    validate_offsets,
};
use crate::line_geometry::{
    LineGeometry, MAX_ALTERNATING_WIDTH_PX, MAX_TOLERANCE_PX, Page, alternating_vertices, class_segments, full_vertices,
};
use crate::passes::cull::{Culled, Shape};
use crate::passes::raster::ComputeRaster;
use crate::settings::{LineColor, Slab};
use crate::targets::FrameTargets;
use crate::timing::Span;

/// The most pixels one world unit can cover in `view` (at the near end of its depth range,
/// off axis up to the viewport's corners): the Jacobian of (f x / z, f y / z) has norm at most
/// f / z · √(1 + (x² + y²) / z²).
pub(crate) fn max_px_per_world(view: &FrameView) -> f32 {
    if view.orthographic {
        return view.f_px;
    }
    // A tile's is its picture's: every tile draws the same strips.
    let guard = 2.0 * view.guard as f32;
    let (w, h) = view.picture_size();
    let half_diagonal = 0.5 * (w as f32 + guard).hypot(h as f32 + guard) / view.f_px;
    view.f_px / view.near * (1.0 + half_diagonal * half_diagonal).sqrt()
}

/// How segments are rasterized.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineStyle {
    /// Screen-aligned quads of the chain's line width (the paper's fixed-width lines), from the
    /// alternating strip where it stays within about half a pixel of the full one (see
    /// `line_geometry`), else the full strip.
    #[default]
    Quads,
    /// Quads always from the full strip: both sides of every point.
    FullStrip,
    /// The rasterizer's native 1-pixel lines (a `LineList` pulled from the same clusters),
    /// ignoring the line width: the cheapest way to put segments on screen, and the baseline
    /// `lineao bench` measures quads against.
    Native1px,
}

/// The pipelines of one output set: the full strip (or native lines) and the alternating strip.
struct Pipelines {
    full: wgpu::RenderPipeline,
    alternating: Option<wgpu::RenderPipeline>,
}

/// Renders [`LineGeometry`] into the G-buffer of [`FrameTargets`].
pub struct LineRenderer {
    style: LineStyle,
    /// Its fragments test the slab ([`LineRenderer::with_slab`]): a `discard` in the shader,
    /// which costs the rasterizer its early depth test, so only where a slab is asked for.
    slab: bool,
    plain: Pipelines,
    /// Culling on the GPU ([`LineRenderer::culled`]): the visible pieces' full strips.
    culled: Option<Culled>,
    /// The culled pieces rasterized in compute ([`LineRenderer::rasterized_in_compute`]), or
    /// why they are not though asked.
    compute: Option<Result<ComputeRaster, String>>,
    /// Writing `octants` too: the points' octant visibilities, fully visible where a page
    /// holds none.
    octants: Option<Pipelines>,
    bindings: GeometryBindings,
    /// The frame's [`max_px_per_world`] (f32 bits) when the alternating strip may be drawn
    /// (∞ otherwise), from [`LineRenderer::prepare`].
    px_per_world: AtomicU32,
}

impl LineRenderer {
    /// The renderer of fixed-width lines.
    pub fn new(device: &wgpu::Device) -> LineRenderer {
        Self::with_style(device, LineStyle::Quads)
    }

    /// A line renderer drawing in `style`.
    pub fn with_style(device: &wgpu::Device, style: LineStyle) -> LineRenderer {
        Self::with_outputs(device, style, false)
    }

    /// With `octants`, targets that have an `octants` texture also get the geometry's
    /// per-vertex octant visibilities, interpolated ([`crate::passes::volume_ao`]); quads only.
    pub fn with_outputs(device: &wgpu::Device, style: LineStyle, octants: bool) -> LineRenderer {
        Self::with_slab(device, style, octants, false, LightingShape::ANY)
    }

    /// [`LineRenderer::with_outputs`] whose fragments outside the frame's slab are discarded,
    /// with `slab` (the slab itself comes with each frame's [`LineRenderer::prepare`]; without
    /// `slab` it is ignored). Measured on lavapipe at 10 M points: the test alone, never
    /// discarding, made drawing every line 1.5 × slower (8.6 s against 5.8 s). Its pipelines
    /// are compiled for lightings of `shape` ([`LightingShape::ANY`] for every one): each
    /// [`LineRenderer::prepare`] must give one.
    pub fn with_slab(
        device: &wgpu::Device,
        style: LineStyle,
        octants: bool,
        slab: bool,
        shape: LightingShape,
    ) -> LineRenderer {
        let bindings = GeometryBindings::new(device, "lineao::LineRenderer::bindings", shape);
        let page = crate::line_geometry::page_layout(device);
        let module = crate::shader::module(device, "lines.wgsl");
        let topology = match style {
            LineStyle::Quads | LineStyle::FullStrip => wgpu::PrimitiveTopology::TriangleStrip,
            LineStyle::Native1px => wgpu::PrimitiveTopology::LineList,
        };
        let create = |label, vertex, fragment| {
            let octants = fragment == "fs_octants";
            gbuffer::pipeline(
                device,
                &bindings,
                PipelineSpec {
                    label,
                    groups: &[&page],
                    module: &module,
                    vertex,
                    fragment,
                    buffers: &[],
                    topology,
                    octants,
                    constants: &[("SLAB", slab as u32 as f64)],
                },
            )
        };
        let plain = match style {
            LineStyle::Native1px => {
                Pipelines { full: create("lineao::LineRenderer::native", "vs_native", "fs_main"), alternating: None }
            }
            _ => Pipelines {
                full: create("lineao::LineRenderer::full", "vs_full", "fs_main"),
                alternating: (style == LineStyle::Quads)
                    .then(|| create("lineao::LineRenderer::alternating", "vs_alternating", "fs_main")),
            },
        };
        let octants = (octants && style != LineStyle::Native1px).then(|| Pipelines {
            full: create("lineao::LineRenderer::full_octants", "vs_full_octants", "fs_octants"),
            alternating: (style == LineStyle::Quads)
                .then(|| create("lineao::LineRenderer::alternating_octants", "vs_alternating_octants", "fs_octants")),
        });
        LineRenderer {
            style,
            slab,
            plain,
            octants,
            culled: None,
            compute: None,
            bindings,
            px_per_world: AtomicU32::new(f32::INFINITY.to_bits()),
        }
    }

    /// This renderer drawing only the pieces of line that can be seen, found on the GPU each
    /// frame ([`crate::passes::cull`]): the full strip's G-buffer, exactly — or, where `lod`,
    /// each piece at the coarsest level of detail within [`crate::passes::cull::LOD_PIXELS`] of
    /// it. Native lines are always drawn whole.
    pub fn culled(mut self, device: &wgpu::Device, lod: bool) -> LineRenderer {
        if self.style == LineStyle::Native1px || self.culled.is_some() {
            return self;
        }
        let page = crate::line_geometry::page_layout(device);
        let pieces = crate::passes::cull::pieces_layout(device);
        let module = crate::shader::module(device, "lines.wgsl");
        let create = |octants: bool, coarse: bool| {
            let (vertex, fragment) = match (octants, coarse) {
                (false, false) => ("vs_piece", "fs_main"),
                (true, false) => ("vs_piece_octants", "fs_octants"),
                (false, true) => ("vs_piece_coarse", "fs_main"),
                (true, true) => ("vs_piece_coarse_octants", "fs_octants"),
            };
            gbuffer::pipeline(
                device,
                &self.bindings,
                PipelineSpec {
                    label: "lineao::LineRenderer::pieces",
                    groups: &[&page, &pieces],
                    module: &module,
                    vertex,
                    fragment,
                    buffers: &[],
                    topology: wgpu::PrimitiveTopology::TriangleStrip,
                    octants,
                    constants: &[("SLAB", self.slab as u32 as f64)],
                },
            )
        };
        let culled = Culled::new(device, &self.bindings.layout, Shape::Lines, lod, self.octants.is_some(), create);
        self.culled = Some(culled);
        self
    }

    /// This culled renderer drawing its visible pieces by compute shaders into a visibility
    /// buffer ([`crate::passes::raster`]) where the device has 64-bit atomics and the frame
    /// allows it, else by the hardware rasterizer ([`LineRenderer::raster_note`] says why).
    pub fn rasterized_in_compute(mut self, device: &wgpu::Device) -> LineRenderer {
        if self.culled.is_none() || self.octants.is_some() || self.slab {
            let why = "only culled lines without a slab or octants are rasterized in compute";
            self.compute = Some(Err(why.to_string()));
            return self;
        }
        let page = crate::line_geometry::page_layout(device);
        let pieces = crate::passes::cull::pieces_layout(device);
        self.compute = Some(ComputeRaster::new(device, &self.bindings, &page, &pieces));
        self
    }

    /// Why it draws in hardware though asked to rasterize in compute, if it does.
    pub fn raster_note(&self) -> Option<&str> {
        match &self.compute {
            Some(Err(why)) => Some(why),
            _ => None,
        }
    }

    /// Its culling, where it culls.
    pub fn cull(&self) -> Option<&Culled> {
        self.culled.as_ref()
    }

    /// Whether its fragments test the slab ([`LineRenderer::with_slab`]).
    pub fn cuts(&self) -> bool {
        self.slab
    }

    /// Whether it culls ([`LineRenderer::culled`]).
    pub fn culls(&self) -> bool {
        self.culled.is_some()
    }

    /// Whether it culls at levels of detail ([`LineRenderer::culled`]).
    pub fn lods(&self) -> bool {
        self.culled.as_ref().is_some_and(|c| c.cull().lod())
    }

    /// Why it draws every line though asked to cull, once a frame found it out (the device's
    /// limits): what a front end shows once.
    pub fn cull_note(&self) -> Option<&str> {
        self.culled.as_ref().and_then(Culled::note)
    }

    /// The cull's compute alone, as [`LineRenderer::encode`] records it but for the draws (the
    /// bench's `cull`); nothing where it does not cull.
    pub fn encode_cull(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        span: Option<Span>,
    ) {
        if let Some(culled) = &self.culled {
            culled.encode_compute(encoder, targets, geometry, &self.bindings.group, span);
        }
    }

    /// Whether this renderer writes the `octants` target.
    pub fn writes_octants(&self) -> bool {
        self.octants.is_some()
    }

    /// The lighting its pipelines are compiled for.
    pub fn lighting_shape(&self) -> LightingShape {
        self.bindings.shape
    }

    /// Its group 0 (the frame's uniform and lighting), which the transparent lines' passes bind.
    pub(crate) fn bindings(&self) -> &GeometryBindings {
        &self.bindings
    }

    /// Writes this frame's uniform.
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        view: &FrameView,
        line_width_px: f32,
        color: LineColor,
        lighting: &Lighting,
        slab: Option<&Slab>,
    ) {
        let uniform = GeometryUniform::new(view, color, line_width_px, 0.0).with_slab(view, slab);
        self.bindings.write(queue, &uniform, lighting);
        if let Some(culled) = &self.culled {
            culled.cull().set_view(view);
        }
        let scale = if line_width_px <= MAX_ALTERNATING_WIDTH_PX { max_px_per_world(view) } else { f32::INFINITY };
        self.px_per_world.store(scale.to_bits(), Ordering::Relaxed);
    }

    /// Whether `page` is drawn as the alternating strip in the frame of the last
    /// [`LineRenderer::prepare`].
    pub(crate) fn page_alternates(&self, page: &Page) -> bool {
        let scale = f32::from_bits(self.px_per_world.load(Ordering::Relaxed));
        self.style == LineStyle::Quads && page.tolerance * scale <= MAX_TOLERANCE_PX
    }

    /// Whether [`LineRenderer::encode`] draws any of `geometry` as the alternating strip in the
    /// frame of the last [`LineRenderer::prepare`].
    pub fn alternates(&self, geometry: &LineGeometry) -> bool {
        geometry.pages().iter().any(|page| self.page_alternates(page))
    }

    /// The share of `geometry`'s clusters drawn as the alternating strip in the frame of the
    /// last [`LineRenderer::prepare`].
    pub fn alternating_share(&self, geometry: &LineGeometry) -> f64 {
        let drawn: u32 = geometry.pages().iter().filter(|p| self.page_alternates(p)).map(|p| p.records).sum();
        drawn as f64 / geometry.clusters().max(1) as f64
    }

    /// Draws `geometry` into the G-buffer, clearing it first or over earlier passes (`load`),
    /// timed into `span` when given: per page, each draw class of clusters with its vertex
    /// count (the alternating strip's where the frame allows it, else the full strip's).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        load: Load,
        span: Option<Span>,
    ) {
        // The octants too when both the pipelines and the target exist.
        let octants = self.octants.as_ref().filter(|_| targets.octants.is_some());
        let label = "lineao::LineRenderer";
        let frame = &self.bindings.group;
        let culled = self.culled.as_ref();
        if let (Some(culled), Some(Ok(raster))) = (culled, &self.compute) {
            let cull = culled.cull();
            if cull.unsupported(targets).or_else(|| raster.unsupported(targets, geometry, load)).is_none() {
                let draw = |encoder: &mut wgpu::CommandEncoder, phase, span| {
                    raster.encode(encoder, targets, geometry, cull, frame, phase, load, span);
                };
                return cull.encode(encoder, targets, geometry, frame, span, draw);
            }
        }
        if culled.is_some_and(|c| c.encode(encoder, targets, geometry, frame, label, load, octants.is_some(), span)) {
            return;
        }
        let mut pass = gbuffer::begin(encoder, "lineao::LineRenderer", targets, load, octants.is_some(), span);
        let pipelines = octants.unwrap_or(&self.plain);
        pass.set_bind_group(0, &self.bindings.group, &[]);
        for page in geometry.pages() {
            pass.set_bind_group(1, &page.group, &[]);
            let alternating = pipelines.alternating.as_ref().filter(|_| self.page_alternates(page));
            // (vertices, instances) of every non-empty draw class, full strips first.
            let (mut full, mut alternated) = (Vec::new(), Vec::new());
            for (class, range) in page.classes.iter().enumerate().filter(|(_, range)| !range.is_empty()) {
                match (self.style, alternating) {
                    (LineStyle::Native1px, _) => full.push((2 * class_segments(class), range.clone())),
                    (_, Some(_)) => alternated.push((alternating_vertices(class), range.clone())),
                    (_, None) => full.push((full_vertices(class), range.clone())),
                }
            }
            for (pipeline, draws) in [(Some(&pipelines.full), full), (alternating, alternated)] {
                let Some(pipeline) = pipeline.filter(|_| !draws.is_empty()) else { continue };
                pass.set_pipeline(pipeline);
                for (vertices, instances) in draws {
                    for batch in geometry.draw_batches(instances) {
                        pass.draw(0..vertices, batch);
                    }
                }
            }
        }
    }
}
