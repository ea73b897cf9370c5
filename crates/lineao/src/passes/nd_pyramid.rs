//! ND pyramid (paper §3.4): the Gaussian pyramid n_l(P), d_l(P) that lets LineAO's wider
//! hemispheres see merged bundles instead of single lines.
//!
//! Level j is the separable binomial [1 4 6 4 1]/16 of level j−1 centred at texel (2x, 2y)
//! with clamp-to-edge, over normal and depth alike (background included: sparse lines fade into
//! the background at coarse levels, dense bundles merge into solid surfaces). The normal is
//! renormalized, or zero (background) when its filtered length is below 1e-6. See
//! `shaders/nd_pyramid.wgsl` and [`crate::reference::nd_downsample`].

use crate::binding::{self, Slot};
use crate::passes::dispatch_size;
use crate::targets::{FrameTargets, ND_FORMAT};
use crate::timing::{self, Span};

/// The Gaussian pyramid of normals and depth (reference.md "Pyramid").
pub struct NdPyramid {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    /// One bind group per level ≥ 1, reading level j−1 and writing level j.
    groups: Vec<wgpu::BindGroup>,
}

impl NdPyramid {
    /// Its pipeline and layout.
    pub fn new(device: &wgpu::Device) -> NdPyramid {
        let layout = binding::layout(
            device,
            "lineao::NdPyramid::layout",
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Texture, Slot::StorageTexture(ND_FORMAT)],
        );
        let pipeline = binding::compute_pipeline(
            device,
            "lineao::NdPyramid::pipeline",
            &layout,
            "nd_pyramid.wgsl",
            "downsample",
            &[],
        );
        NdPyramid { pipeline, layout, groups: Vec::new() }
    }

    /// Binds the levels of `targets`.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        self.groups = targets
            .nd
            .windows(2)
            .enumerate()
            .map(|(j, pair)| {
                binding::group(
                    device,
                    &format!("lineao::NdPyramid::group[{}]", j + 1),
                    &self.layout,
                    &[
                        wgpu::BindingResource::TextureView(&pair[0].view),
                        wgpu::BindingResource::TextureView(&pair[1].view),
                    ],
                )
            })
            .collect();
    }

    /// Records levels 1.. from level 0, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lineao::NdPyramid"),
            timestamp_writes: timing::compute_writes(span),
        });
        pass.set_pipeline(&self.pipeline);
        for (group, level) in self.groups.iter().zip(&targets.nd[1..]) {
            let (x, y) = dispatch_size(level.size());
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}
