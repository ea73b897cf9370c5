//! Line renderer: polylines at a fixed pixel width, the way LineAO expects them ("the intrinsic
//! fixed line width on screen", paper §2–3). wgpu has no wide lines, so each polyline is one
//! triangle strip whose vertices the vertex shader pushes half a line width to either side of
//! the curve (see `shaders/lines.wgsl`).
//!
//! Per pixel it writes the G-buffer of CONTRACT.md: base color, the ND map (n = (T × C) × T
//! normalized, facing the eye; normalized linear depth), the zoom map, the illuminated-lines
//! specular and hardware depth.
//!
//! The geometry it draws — the strip, its buffers and the alternating strip — is
//! `line_geometry.rs`'s.

use std::sync::atomic::{AtomicU32, Ordering};

use crate::camera::FrameView;
use crate::gbuffer::{self, GeometryBindings, GeometryUniform, Load, PipelineSpec};
use crate::lighting::Lighting;
use crate::line_geometry::LineGeometry;
pub use crate::line_geometry::{
    DEFAULT_CHUNK_BYTES, FLAG_UNIT, GeometryOptions, LineAttributes, LinePoint, VertexAttributes, VertexFlags,
    validate_offsets,
};
use crate::line_geometry::{
    MAX_ALTERNATING_WIDTH_PX, MAX_TOLERANCE_PX, STRIP_ATTRIBUTES, attribute_layout, strip_layout,
};
use crate::settings::LineColor;
use crate::targets::FrameTargets;
use crate::timing::Span;

/// The most pixels one world unit can cover in `view` (at the near end of its depth range,
/// off axis up to the viewport's corners): the Jacobian of (f x / z, f y / z) has norm at most
/// f / z · √(1 + (x² + y²) / z²).
fn max_px_per_world(view: &FrameView) -> f32 {
    if view.orthographic {
        return view.f_px;
    }
    let guard = 2.0 * view.guard as f32;
    let half_diagonal = 0.5 * (view.width as f32 + guard).hypot(view.height as f32 + guard) / view.f_px;
    view.f_px / view.near * (1.0 + half_diagonal * half_diagonal).sqrt()
}

/// How segments are rasterized.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineStyle {
    /// Screen-aligned quads of the chain's line width (the paper's fixed-width lines), from the
    /// alternating strip where it stays within about half a pixel of the full one (see the
    /// module documentation), else the full strip.
    #[default]
    Quads,
    /// Quads always from the full strip: both sides of every point.
    FullStrip,
    /// The rasterizer's native 1-pixel lines (an indexed `LineList` over the same vertices),
    /// ignoring the line width: the cheapest way to put segments on screen, and the baseline
    /// `lineao bench` measures quads against. Needs geometry uploaded with
    /// [`GeometryOptions::native_lines`]; without it nothing is drawn.
    Native1px,
}

/// Renders [`LineGeometry`] into the G-buffer of [`FrameTargets`].
pub struct LineRenderer {
    style: LineStyle,
    pipeline: wgpu::RenderPipeline,
    /// With the geometry's attributes (the scalar's color), quads only.
    attributes: Option<wgpu::RenderPipeline>,
    /// Writing `octants` too: from the geometry's attributes, and fully visible for geometry
    /// without them.
    octants: Option<OctantPipelines>,
    bindings: GeometryBindings,
    /// The frame's [`max_px_per_world`] (f32 bits) when the alternating strip may be drawn
    /// (∞ otherwise), from [`LineRenderer::prepare`].
    px_per_world: AtomicU32,
}

/// The pipelines of a geometry pass that also writes the `octants` target.
pub(crate) struct OctantPipelines {
    pub attributes: wgpu::RenderPipeline,
    pub visible: wgpu::RenderPipeline,
}

impl LineRenderer {
    /// The renderer of fixed-width lines.
    pub fn new(device: &wgpu::Device) -> LineRenderer {
        Self::with_style(device, LineStyle::Quads)
    }

    pub fn with_style(device: &wgpu::Device, style: LineStyle) -> LineRenderer {
        Self::with_outputs(device, style, false)
    }

    /// With `octants`, targets that have an `octants` texture also get the geometry's
    /// per-vertex octant visibilities, interpolated ([`crate::passes::volume_ao`]); quads only.
    pub fn with_outputs(device: &wgpu::Device, style: LineStyle, octants: bool) -> LineRenderer {
        let bindings = GeometryBindings::new(device, "lineao::LineRenderer::bindings");
        let module = crate::shader::module(device, "lines.wgsl");
        // Octants at 0 and 4, the scalar at 12 (the tubes' radius at 8 is skipped).
        let octant_attributes = [
            wgpu::VertexAttribute { format: wgpu::VertexFormat::Unorm8x4, offset: 0, shader_location: 2 },
            wgpu::VertexAttribute { format: wgpu::VertexFormat::Unorm8x4, offset: 4, shader_location: 3 },
            wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32, offset: 12, shader_location: 5 },
        ];
        let strip = [Some(strip_layout(&STRIP_ATTRIBUTES))];
        let with_attributes = [Some(strip_layout(&STRIP_ATTRIBUTES)), Some(attribute_layout(&octant_attributes))];
        let topology = match style {
            LineStyle::Quads | LineStyle::FullStrip => wgpu::PrimitiveTopology::TriangleStrip,
            LineStyle::Native1px => wgpu::PrimitiveTopology::LineList,
        };
        let create = |label, vertex, fragment, buffers| {
            let octants = fragment == "fs_octants";
            gbuffer::pipeline(
                device,
                &bindings.layout,
                PipelineSpec { label, module: &module, vertex, fragment, buffers, topology, octants },
            )
        };
        let vertex = match style {
            LineStyle::Quads | LineStyle::FullStrip => "vs_main",
            LineStyle::Native1px => "vs_native",
        };
        let pipeline = create("lineao::LineRenderer::pipeline", vertex, "fs_main", &strip);
        let quads = style != LineStyle::Native1px;
        let attributes =
            quads.then(|| create("lineao::LineRenderer::attributes", "vs_attributes", "fs_main", &with_attributes));
        let octants = (octants && quads).then(|| OctantPipelines {
            attributes: create("lineao::LineRenderer::octants", "vs_octants", "fs_octants", &with_attributes),
            visible: create("lineao::LineRenderer::visible", "vs_visible", "fs_octants", &strip),
        });
        LineRenderer {
            style,
            pipeline,
            attributes,
            octants,
            bindings,
            px_per_world: AtomicU32::new(f32::INFINITY.to_bits()),
        }
    }

    /// Whether this renderer writes the `octants` target.
    pub fn writes_octants(&self) -> bool {
        self.octants.is_some()
    }

    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        view: &FrameView,
        line_width_px: f32,
        color: LineColor,
        lighting: &Lighting,
    ) {
        self.bindings.write(queue, &GeometryUniform::new(view, color, line_width_px, 0.0), lighting);
        let scale = if line_width_px <= MAX_ALTERNATING_WIDTH_PX { max_px_per_world(view) } else { f32::INFINITY };
        self.px_per_world.store(scale.to_bits(), Ordering::Relaxed);
    }

    /// Whether [`LineRenderer::encode`] draws `geometry` from the alternating strip in the frame
    /// of the last [`LineRenderer::prepare`].
    pub fn alternates(&self, geometry: &LineGeometry) -> bool {
        let scale = f32::from_bits(self.px_per_world.load(Ordering::Relaxed));
        self.style == LineStyle::Quads && geometry.tolerance * scale <= MAX_TOLERANCE_PX
    }

    /// Draws `geometry` into the G-buffer, clearing it first or over earlier passes (`load`),
    /// timed into `span` when given.
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
        let mut pass = gbuffer::begin(encoder, "lineao::LineRenderer", targets, load, octants.is_some(), span);
        let attributes = geometry.has_attributes() && (octants.is_some() || self.attributes.is_some());
        pass.set_pipeline(match (octants, &self.attributes) {
            (Some(pipelines), _) if attributes => &pipelines.attributes,
            (Some(pipelines), _) => &pipelines.visible,
            (None, Some(pipeline)) if attributes => pipeline,
            _ => &self.pipeline,
        });
        pass.set_bind_group(0, &self.bindings.group, &[]);
        let alternates = self.alternates(geometry);
        for chunk in &geometry.chunks {
            pass.set_vertex_buffer(0, chunk.vertices.slice(..));
            if let (true, Some(buffer)) = (attributes, &chunk.attributes) {
                pass.set_vertex_buffer(1, buffer.slice(..));
            }
            match (self.style, &chunk.segments) {
                (LineStyle::Quads, _) if alternates => {
                    let (indices, count) = &chunk.alternating;
                    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..*count, 0, 0..1);
                }
                (LineStyle::Quads | LineStyle::FullStrip, _) => pass.draw(0..chunk.count, 0..1),
                (LineStyle::Native1px, Some((indices, count))) => {
                    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..*count, 0, 0..1);
                }
                (LineStyle::Native1px, None) => {}
            }
        }
    }
}
