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
//! No buffers of their own: the vertex shader pulls each segment from
//! [`LineGeometry`]'s clusters (instance = a cluster, six vertices — two triangles — per
//! segment, as many segments as the cluster's size class holds; those past its end lie
//! outside the clip volume), so tubes and lines share one copy of the points.
//!
//! **Culled** ([`TubeRenderer::culled`], the chain's default): the pieces of eight segments
//! that can be seen, found on the GPU each frame as for lines ([`crate::passes::cull`]), each
//! segment bounded by its billboard for the largest radius of its page's points; the G-buffer
//! of drawing every segment (`tests/cull.rs`). The billboards' fragments are shaded before the
//! depth test where the device ignores the early-depth promise (lavapipe), so what the cull
//! saves there is most of the frame: a whole brain of 10 M points seen from outside 68.6 s → 9.6 s.
//!
//! LineAO on tubes takes r0 = 1.5 · z(P) · t_s (paper Eq. 16, t_s = 2 · radius in zoom units).

use crate::camera::FrameView;
use crate::gbuffer::{self, GeometryBindings, GeometryUniform, Load, PipelineSpec};
use crate::lighting::{Lighting, LightingShape};
use crate::line_geometry::{LineGeometry, class_segments};
use crate::passes::cull::{Culled, Shape};
use crate::settings::{LineColor, Slab};
use crate::targets::FrameTargets;
use crate::timing::Span;

/// Renders [`LineGeometry`] as tubes into the G-buffer of [`FrameTargets`].
pub struct TubeRenderer {
    pipeline: wgpu::RenderPipeline,
    octants: bool,
    bindings: GeometryBindings,
    /// Culling on the GPU ([`TubeRenderer::culled`]).
    culled: Option<Culled>,
    /// `tubes.wgsl` with the fragment shader's depth promise where the device takes it (the
    /// culled pipelines are made from it too).
    module: wgpu::ShaderModule,
}

impl TubeRenderer {
    /// With `octants`, targets that have an `octants` texture also get the geometry's octant
    /// visibilities along each segment ([`crate::passes::volume_ao`]). Its pipelines are
    /// compiled for lightings of `shape` ([`LightingShape::ANY`] for every one): each
    /// [`TubeRenderer::prepare`] must give one.
    pub fn new(device: &wgpu::Device, octants: bool, shape: LightingShape) -> TubeRenderer {
        let bindings = GeometryBindings::new(device, "lineao::TubeRenderer::bindings", shape);
        let page = crate::line_geometry::page_layout(device);
        // The depth test before shading where the device takes the shader's promise that its
        // depth is never nearer than the billboard's (`tubes.wgsl`).
        let early = device.features().contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST);
        let promise = if early { "@early_depth_test(greater_equal)" } else { "" };
        let module = crate::shader::module_with(device, "tubes.wgsl", &[("//@conservative_depth", promise)]);
        let pipeline = tube_pipeline(device, &bindings, &module, &[&page], "vs_tube", octants);
        TubeRenderer { pipeline, octants, bindings, culled: None, module }
    }

    /// This renderer drawing only the pieces of tube that can be seen, found on the GPU each
    /// frame ([`crate::passes::cull`]): the same G-buffer as drawing every segment; with `lod`,
    /// each piece through the fewest of its points that keep it within
    /// [`LOD_PIXELS`](crate::passes::cull::LOD_PIXELS) of its full tube on screen.
    pub fn culled(mut self, device: &wgpu::Device, lod: bool) -> TubeRenderer {
        if self.culled.is_some() {
            return self;
        }
        let page = crate::line_geometry::page_layout(device);
        let pieces = crate::passes::cull::pieces_layout(device);
        let groups = [&page, &pieces];
        let create = |octants, coarse| {
            let vertex = if coarse { "vs_tube_piece_coarse" } else { "vs_tube_piece" };
            tube_pipeline(device, &self.bindings, &self.module, &groups, vertex, octants)
        };
        self.culled = Some(Culled::new(device, &self.bindings.layout, Shape::Tubes, lod, self.octants, create));
        self
    }

    /// Its culling, where it culls.
    pub fn cull(&self) -> Option<&Culled> {
        self.culled.as_ref()
    }

    /// Whether it culls at levels of detail ([`TubeRenderer::culled`]).
    pub fn lods(&self) -> bool {
        self.culled.as_ref().is_some_and(|c| c.cull().lod())
    }

    /// Whether this renderer writes the `octants` target.
    pub fn writes_octants(&self) -> bool {
        self.octants
    }

    /// The lighting its pipelines are compiled for.
    pub fn lighting_shape(&self) -> LightingShape {
        self.bindings.shape
    }

    /// `radius_world`: the tubes' radius where the geometry carries none.
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        view: &FrameView,
        radius_world: f32,
        color: LineColor,
        lighting: &Lighting,
        slab: Option<&Slab>,
    ) {
        let uniform = GeometryUniform::new(view, color, 0.0, radius_world).with_slab(view, slab);
        self.bindings.write(queue, &uniform, lighting);
        if let Some(culled) = &self.culled {
            culled.cull().set_view(view);
        }
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
        let (label, frame) = ("lineao::TubeRenderer", &self.bindings.group);
        let culled = self.culled.as_ref();
        if culled.is_some_and(|c| c.encode(encoder, targets, geometry, frame, label, load, octants, span)) {
            return;
        }
        let mut pass = gbuffer::begin(encoder, label, targets, load, octants, span);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bindings.group, &[]);
        for page in geometry.pages() {
            pass.set_bind_group(1, &page.group, &[]);
            for (class, range) in page.classes.iter().enumerate().filter(|(_, r)| !r.is_empty()) {
                for batch in geometry.draw_batches(range.clone()) {
                    pass.draw(0..6 * class_segments(class), batch);
                }
            }
        }
    }
}

/// A tube pipeline: `vertex` (every cluster's segments, or the visible pieces') with the
/// fragment shader that writes the octants too or not.
fn tube_pipeline(
    device: &wgpu::Device,
    bindings: &GeometryBindings,
    module: &wgpu::ShaderModule,
    groups: &[&wgpu::BindGroupLayout],
    vertex: &str,
    octants: bool,
) -> wgpu::RenderPipeline {
    gbuffer::pipeline(
        device,
        bindings,
        PipelineSpec {
            label: "lineao::TubeRenderer::pipeline",
            groups,
            module,
            vertex,
            fragment: if octants { "fs_tube_octants" } else { "fs_tube" },
            buffers: &[],
            topology: wgpu::PrimitiveTopology::TriangleList,
            octants,
            constants: &[("OCTANTS", f64::from(u8::from(octants)))],
        },
    )
}
