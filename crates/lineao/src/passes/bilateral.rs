//! Separable bilateral blur, usable after any method.
//!
//! Sparse samples leave noise (SSAO's 4 × 4 pattern, VO's reflected line sets, LineAO's random
//! hemispheres); a plain blur would remove it but also smear occlusion across depth edges —
//! from a line in front onto the bundle behind it. A bilateral blur weighs each neighbour by
//! its distance on screen *and* in depth:
//!
//! ```text
//!   ao'(P) = Σ_k w_k ao(P + k e) / Σ_k w_k,   w_k = exp(−k²/(2σ_s²) − (z_k − z_P)²/(2σ_z²))
//! ```
//!
//! over k ∈ [−r, r] along x, then along y (separable: 2(2r + 1) taps instead of (2r + 1)²),
//! σ_s = r/2, σ_z in world units (`BilateralSettings`). Background pixels neither receive nor
//! give occlusion. Reads `ao`, writes `ao_blur_tmp` then `ao_blurred`, which the composite
//! shows when the blur is on. The CPU reference is [`crate::reference::bilateral`].

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_size;
use crate::settings::BilateralSettings;
use crate::targets::{AO_FORMAT, FrameTargets};
use crate::timing::{self, Span};
use crate::view_params::ViewParams;
use crate::view_params::ViewUniform;

/// Keep in sync with `BilateralUniform` in `shaders/bilateral.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BilateralUniform {
    pub view: ViewUniform,
    pub radius: i32,
    /// 1/(2σ_s²), σ_s = radius/2.
    pub spatial: f32,
    /// 1/(2σ_z²).
    pub depth: f32,
    pub _pad: u32,
}

impl BilateralUniform {
    pub fn new(view: &FrameView, settings: &BilateralSettings) -> BilateralUniform {
        let sigma_s = settings.radius_px as f32 * 0.5;
        BilateralUniform {
            view: ViewParams::of(view).into(),
            radius: settings.radius_px as i32,
            spatial: 1.0 / (2.0 * sigma_s * sigma_s),
            depth: 1.0 / (2.0 * settings.depth_sigma_world * settings.depth_sigma_world),
            _pad: 0,
        }
    }
}

pub struct Bilateral {
    /// Along x, then along y.
    pipelines: [wgpu::ComputePipeline; 2],
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    groups: Vec<wgpu::BindGroup>,
}

impl Bilateral {
    pub fn new(device: &wgpu::Device) -> Bilateral {
        let label = "lineao::Bilateral";
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::Texture, Slot::Texture, Slot::StorageTexture(AO_FORMAT)],
        );
        let axis =
            |a: f64| binding::compute_pipeline(device, label, &layout, "bilateral.wgsl", "bilateral", &[("AXIS", a)]);
        Bilateral {
            pipelines: [axis(0.0), axis(1.0)],
            uniform: binding::uniform_buffer::<BilateralUniform>(device, label),
            layout,
            groups: Vec::new(),
        }
    }

    /// `ao` → `ao_blur_tmp` (x) → `ao_blurred` (y), depth from `nd[0]` (without the blur's
    /// targets the pass records nothing).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let (Some(tmp), Some(blurred)) = (&targets.ao_blur_tmp, &targets.ao_blurred) else {
            self.groups.clear();
            return;
        };
        let halves = [(&targets.ao, tmp), (tmp, blurred)];
        self.groups = halves
            .iter()
            .map(|(src, dst)| {
                binding::group(
                    device,
                    "lineao::Bilateral",
                    &self.layout,
                    &[
                        self.uniform.as_entire_binding(),
                        wgpu::BindingResource::TextureView(&targets.nd[0].view),
                        wgpu::BindingResource::TextureView(&src.view),
                        wgpu::BindingResource::TextureView(&dst.view),
                    ],
                )
            })
            .collect();
    }

    pub fn prepare(&self, queue: &wgpu::Queue, view: &FrameView, settings: &BilateralSettings) {
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&BilateralUniform::new(view, settings)));
    }

    /// Records both halves, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        if self.groups.is_empty() {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lineao::Bilateral"),
            timestamp_writes: timing::compute_writes(span),
        });
        let (x, y) = dispatch_size(targets.size);
        for (pipeline, group) in self.pipelines.iter().zip(&self.groups) {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        BilateralUniform,
        "bilateral.wgsl",
        "BilateralUniform",
        [view, radius, spatial, depth]
    );
}
