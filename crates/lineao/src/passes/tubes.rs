//! Tube renderer: streamlines as tubes of a world-space radius, per vertex where the geometry
//! carries radii ([`VertexAttributes::radius`](crate::passes::lines::VertexAttributes)). Every
//! segment is a *rounded cone* — the two spheres at its ends and the cone tangent to both; a
//! capsule when the radii agree — ray-cast per pixel on a billboard that bounds its projection
//! (`shaders/tubes.wgsl`). The fragment shader writes the hit's true depth, its normal, the
//! zoom map at its depth and Phong lighting (diffuse in the color, the specular apart, as for
//! lines: LineAO stands for the ambient part). Neighbouring segments share their end spheres, and
//! the depth test keeps the nearest of the overlapping hits, so the tube is the exact union of
//! the segments' solids: seamless at any joint, round at the ends.
//!
//! Impostors, not geometry: a faceted tube needs ≥ 8 quads per segment for round silhouettes
//! (16 triangles against 2 here), and on a CPU rasterizer triangles cost per triangle
//! (`lineao bench`: the 2-triangle line strip is already most of a line frame). The billboards
//! cost per pixel instead, with exact silhouettes, depth and normals at every zoom.
//!
//! No new buffers: the billboards are instances over [`LineGeometry`]'s strip, read with twice
//! its stride so that instance k sees strip vertex 2k (a point's left vertex) and, through a
//! second binding 40 bytes ahead, vertex 2k + 2 (the next point's). Instances that are no
//! segment (joins, a run's last point) collapse to nothing. The strip's chunks start at even
//! positions and overlap by two vertices, so each segment is an instance of exactly one chunk
//! (the padding of two vertices keeps the second binding within bounds).
//!
//! LineAO on tubes takes r0 = 1.5 · z(P) · t_s (paper Eq. 16, t_s = 2 · radius in zoom units).

use crate::camera::FrameView;
use crate::gbuffer::{self, GeometryBindings, GeometryUniform, Load, PipelineSpec};
use crate::lighting::Lighting;
use crate::line_geometry::{ATTRIBUTE_SIZE, LineGeometry, POINT_SIZE};
use crate::settings::LineColor;
use crate::targets::FrameTargets;
use crate::timing::Span;

/// Renders [`LineGeometry`] as tubes into the G-buffer of [`FrameTargets`].
pub struct TubeRenderer {
    /// Without and with the geometry's attributes.
    plain: wgpu::RenderPipeline,
    attributes: wgpu::RenderPipeline,
    octants: bool,
    bindings: GeometryBindings,
}

impl TubeRenderer {
    /// With `octants`, targets that have an `octants` texture also get the geometry's octant
    /// visibilities along each segment ([`crate::passes::volume_ao`]).
    pub fn new(device: &wgpu::Device, octants: bool) -> TubeRenderer {
        let bindings = GeometryBindings::new(device, "lineao::TubeRenderer::bindings");
        let module = crate::shader::module(device, "tubes.wgsl");
        let point = |a, t| wgpu::vertex_attr_array![a => Float32x3, t => Snorm16x4];
        let (at_a, at_b) = (point(0, 1), point(2, 3));
        let attribute =
            |lo, hi, r, s| wgpu::vertex_attr_array![lo => Unorm8x4, hi => Unorm8x4, r => Float32, s => Float32];
        let (attr_a, attr_b) = (attribute(4, 5, 6, 10), attribute(7, 8, 9, 11));
        let instance = |stride, attributes| {
            Some(wgpu::VertexBufferLayout {
                array_stride: stride,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes,
            })
        };
        let segments = [instance(2 * POINT_SIZE, &at_a[..]), instance(2 * POINT_SIZE, &at_b[..])];
        let with_attributes = [
            segments[0].clone(),
            segments[1].clone(),
            instance(2 * ATTRIBUTE_SIZE, &attr_a[..]),
            instance(2 * ATTRIBUTE_SIZE, &attr_b[..]),
        ];
        let fragment = if octants { "fs_tube_octants" } else { "fs_tube" };
        let create = |label, vertex, buffers| {
            gbuffer::pipeline(
                device,
                &bindings.layout,
                PipelineSpec {
                    label,
                    module: &module,
                    vertex,
                    fragment,
                    buffers,
                    topology: wgpu::PrimitiveTopology::TriangleStrip,
                    octants,
                },
            )
        };
        TubeRenderer {
            plain: create("lineao::TubeRenderer::pipeline", "vs_tube", &segments),
            attributes: create("lineao::TubeRenderer::attributes", "vs_tube_attributes", &with_attributes),
            octants,
            bindings,
        }
    }

    /// Whether this renderer writes the `octants` target.
    pub fn writes_octants(&self) -> bool {
        self.octants
    }

    /// `radius_world`: the tubes' radius where the geometry carries none.
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        view: &FrameView,
        radius_world: f32,
        color: LineColor,
        lighting: &Lighting,
    ) {
        self.bindings.write(queue, &GeometryUniform::new(view, color, 0.0, radius_world), lighting);
    }

    /// Draws `geometry` as tubes into the G-buffer, clearing it first or over earlier passes
    /// (`load`), timed into `span` when given.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        load: Load,
        span: Option<Span>,
    ) {
        let octants = self.octants && targets.octants.is_some();
        let mut pass = gbuffer::begin(encoder, "lineao::TubeRenderer", targets, load, octants, span);
        let attributes = geometry.has_attributes();
        pass.set_pipeline(if attributes { &self.attributes } else { &self.plain });
        pass.set_bind_group(0, &self.bindings.group, &[]);
        for (vertices, count, extra) in geometry.chunk_buffers() {
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.set_vertex_buffer(1, vertices.slice(2 * POINT_SIZE..));
            if let (true, Some(buffer)) = (attributes, extra) {
                pass.set_vertex_buffer(2, buffer.slice(..));
                pass.set_vertex_buffer(3, buffer.slice(2 * ATTRIBUTE_SIZE..));
            }
            pass.draw(0..4, 0..count / 2);
        }
    }
}
