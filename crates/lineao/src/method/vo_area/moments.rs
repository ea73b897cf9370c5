//! The moments pyramid of VO area sampling (Loos & Sloan §4.2; CONTRACT.md "VO area").
//!
//! Area sampling needs the distribution of depth over a sample's footprint, at any footprint
//! size. As in variance shadow maps, the first two moments M₁ = E\[z\] and M₂ = E\[z²\] of depth
//! filter linearly: level l holds them over a footprint of about 2^l pixels, and a trilinear
//! read gives the mean μ = M₁ and the variance σ² = M₂ − M₁² of any footprint. Level 0 is the
//! linear depth z = −z_view (world units) of each pixel and its square, the background at the
//! far plane; each further level is the binomial 5 × 5 of the one below at half resolution
//! (`moments.wgsl`) — a Gaussian, as the paper recommends for its mip-map, so that
//! large footprints read smoothly. Everything in f32 (M₂ − M₁² cancels in f16). The levels
//! have mip-chain sizes, ⌊W/2^l⌋ down to 1, in one storage buffer ([`Moments`]). The CPU
//! reference is [`crate::reference::moments_pyramid`].

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_size;
use crate::targets::{FrameTargets, Moments};
use crate::timing::{self, Span};
use crate::view_params::ViewParams;
use crate::view_params::ViewUniform;

pub struct MomentsPyramid {
    level0: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    /// Per level: the bind group that writes it (with its own level-index uniform), its size.
    groups: Vec<(wgpu::BindGroup, (u32, u32))>,
}

impl MomentsPyramid {
    pub fn new(device: &wgpu::Device) -> MomentsPyramid {
        let label = "lineao::MomentsPyramid";
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::Uniform, Slot::Uniform, Slot::Texture, Slot::StorageReadWrite],
        );
        let pipeline = |entry| binding::compute_pipeline(device, label, &layout, "moments.wgsl", entry, &[]);
        MomentsPyramid {
            level0: pipeline("level0"),
            downsample: pipeline("downsample"),
            uniform: binding::uniform_buffer::<ViewUniform>(device, label),
            layout,
            groups: Vec::new(),
        }
    }

    /// Reads `nd[0]`, writes every level of `targets.moments` (nothing when there are none).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let Some(moments) = &targets.moments else {
            self.groups.clear();
            return;
        };
        self.groups = (0..moments.levels.len()).map(|l| self.level_group(device, targets, moments, l)).collect();
    }

    fn level_group(
        &self,
        device: &wgpu::Device,
        targets: &FrameTargets,
        moments: &Moments,
        l: usize,
    ) -> (wgpu::BindGroup, (u32, u32)) {
        use wgpu::util::DeviceExt;
        let index = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lineao::MomentsPyramid::level"),
            contents: bytemuck::cast_slice(&[l as u32, 0, 0, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let group = binding::group(
            device,
            &format!("lineao::MomentsPyramid[{l}]"),
            &self.layout,
            &[
                self.uniform.as_entire_binding(),
                moments.layout.as_entire_binding(),
                index.as_entire_binding(),
                wgpu::BindingResource::TextureView(&targets.nd[0].view),
                moments.buffer.as_entire_binding(),
            ],
        );
        (group, (moments.levels[l].width, moments.levels[l].height))
    }

    pub fn prepare(&self, queue: &wgpu::Queue, view: &FrameView) {
        let uniform: ViewUniform = ViewParams::of(view).into();
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records every level, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, span: Option<Span>) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lineao::MomentsPyramid"),
            timestamp_writes: timing::compute_writes(span),
        });
        for (l, (group, size)) in self.groups.iter().enumerate() {
            pass.set_pipeline(if l == 0 { &self.level0 } else { &self.downsample });
            pass.set_bind_group(0, group, &[]);
            let (x, y) = dispatch_size(*size);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}
