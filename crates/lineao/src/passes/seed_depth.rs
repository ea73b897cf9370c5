//! **A host's depth seeds the G-buffer's** ([`crate::OverlayAo`] given a depth texture it can
//! read): before the geometry is drawn, each pixel of the G-buffer's depth gets the depth, in the
//! chain's projection, of what the host drew there — pushed farther by a relative 1e-5, never
//! nearer. The lines (tubes, surfaces, slices) behind the host's picture then leave no
//! fragment: they occlude nothing in the methods' G-buffer — the lines in front are darkened by
//! what lies in front of the host's picture, not by what it hides — and the line cull, whose
//! pyramid is built from this depth ([`crate::passes::cull`]), leaves them out like any hidden
//! line. The G-buffer is then the one drawing every line over that depth leaves, culled or not.
//!
//! The host's depth d of a view-space z is (a z + b) / (c z + e) for the z and w rows of its
//! projection (standard or reversed-Z, a finite or an infinite far plane: the rows say which), so
//! z = (b − e d) / (c d − a); the same view is assumed, as the overlay's composite assumes it.
//! Where the host's depth is its cleared value (nothing drawn), at infinity or behind the eye,
//! and in the guard band, the seed is the far plane.

use glam::Mat4;

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::targets::{self, FrameTargets};

/// The z and w rows of `proj`: depth = (x z + y) / (z z + w) of a view-space z.
pub(crate) fn depth_rows(proj: &Mat4) -> [f32; 4] {
    let (z, w) = (proj.row(2), proj.row(3));
    [z.z, z.w, w.z, w.w]
}

/// The depth of a host's frame that an overlay writes and tests against: its format and the
/// projection the host draws with (any convention: standard or reversed-Z, finite or infinite
/// far plane; perspective or orthographic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlayDepth {
    /// The host's depth format.
    pub format: wgpu::TextureFormat,
    /// The projection the host draws with.
    pub proj: Mat4,
}

impl OverlayDepth {
    /// The z and w rows of the projection: depth = (x z + y) / (z z + w) of a view-space z.
    pub(crate) fn rows(&self) -> [f32; 4] {
        depth_rows(&self.proj)
    }

    /// Whether depth grows toward the eye (reversed-Z), so the test keeps the greater.
    pub(crate) fn reversed(&self) -> bool {
        let [a, b, c, d] = self.rows();
        let depth = |z: f32| (a * z + b) / (c * z + d);
        depth(-1.0) > depth(-2.0)
    }
}

/// Whether the chain can read `depth` (a host's depth texture) to seed its own: it needs
/// `TEXTURE_BINDING` and one sample.
pub fn can_read(depth: &wgpu::TextureView) -> bool {
    let texture = depth.texture();
    texture.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) && texture.sample_count() == 1
}

/// Keep in sync with `Seed` in `shaders/seed_depth.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct SeedUniform {
    guard: [u32; 2],
    size: [u32; 2],
    host_rows: [f32; 4],
    chain_rows: [f32; 4],
    cleared: f32,
    _pad: [u32; 3],
}

/// Writes a host's depth into the G-buffer's (see the module documentation).
pub struct SeedDepth {
    device: wgpu::Device,
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
}

impl SeedDepth {
    /// Its pipelines and layout.
    pub fn new(device: &wgpu::Device) -> SeedDepth {
        let label = "lineao::SeedDepth";
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::FRAGMENT,
            &[Slot::Uniform, Slot::DepthTexture { multisampled: false }],
        );
        let module = crate::shader::module(device, "seed_depth.wgsl");
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&binding::pipeline_layout(device, label, &layout)),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: targets::DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_seed"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniform = binding::uniform_buffer::<SeedUniform>(device, label);
        SeedDepth { device: device.clone(), layout, pipeline, uniform }
    }

    /// The frame's projections: the host's (`host`) and the chain's (`view`).
    pub fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, host: &OverlayDepth) {
        let uniform = SeedUniform {
            guard: [targets.guard; 2],
            size: [view.width, view.height],
            host_rows: depth_rows(&host.proj),
            chain_rows: depth_rows(&view.proj),
            cleared: if host.reversed() { 0.0 } else { 1.0 },
            _pad: [0; 3],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the seeding of `targets.depth` from the host's `depth` (its depth aspect, the
    /// chain's visible size, one sample, `TEXTURE_BINDING`: [`can_read`]).
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, depth: &wgpu::TextureView) {
        let host = depth.texture().create_view(&wgpu::TextureViewDescriptor {
            label: Some("lineao::SeedDepth::host"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        let group = binding::group(
            &self.device,
            "lineao::SeedDepth",
            &self.layout,
            &[self.uniform.as_entire_binding(), wgpu::BindingResource::TextureView(&host)],
        );
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lineao::SeedDepth"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.depth.view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        SeedUniform,
        "seed_depth.wgsl",
        "Seed",
        [guard, size, host_rows, chain_rows, cleared]
    );
}
