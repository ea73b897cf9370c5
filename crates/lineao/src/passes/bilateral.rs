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
//!
//! Over anatomy slices the chain runs it on their pixels only
//! ([`crate::ChainSettings::bilateral`]): the slices' pass writes the G-buffer colour's alpha
//! as 0, every other writer 1, and a pixel whose alpha is not 0 keeps its occlusion (it still
//! gives it to the slices' pixels around it). Then `ao` is copied to `ao_blurred` and the two
//! halves run over the slices' rectangle on screen only (the x half `radius` rows taller,
//! which the y half reads): a pass over every pixel costs as much as the taps on lavapipe.

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
    /// 1: only the anatomy slices' pixels receive.
    pub slices_only: u32,
    /// The first pixel of the x half (xy) and of the y half (zw).
    pub origin: [i32; 4],
}

impl BilateralUniform {
    pub fn new(view: &FrameView, settings: &BilateralSettings, region: Region) -> BilateralUniform {
        let sigma_s = settings.radius_px as f32 * 0.5;
        BilateralUniform {
            view: ViewParams::of(view).into(),
            radius: settings.radius_px as i32,
            spatial: 1.0 / (2.0 * sigma_s * sigma_s),
            depth: 1.0 / (2.0 * settings.depth_sigma_world * settings.depth_sigma_world),
            slices_only: matches!(region, Region::Slices(_)) as u32,
            origin: region
                .origins(settings.radius_px)
                .map(|[x, y]| [x as i32, y as i32])
                .as_flattened()
                .try_into()
                .unwrap(),
        }
    }
}

/// Which pixels the blur smooths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// Every geometry pixel.
    All,
    /// The anatomy slices' pixels, all within the guard-banded rectangle `[x0, y0, x1, y1)`.
    Slices([u32; 4]),
}

impl Region {
    /// The first pixel of the x half and of the y half.
    fn origins(self, radius: u32) -> [[u32; 2]; 2] {
        match self {
            Region::All => [[0, 0]; 2],
            Region::Slices([x0, y0, ..]) => [[x0, y0.saturating_sub(radius)], [x0, y0]],
        }
    }

    /// The pixels the x half and the y half run over, within a `size` target.
    fn extents(self, radius: u32, size: (u32, u32)) -> [(u32, u32); 2] {
        match self {
            Region::All => [size; 2],
            Region::Slices([x0, y0, x1, y1]) => {
                let (x1, y1) = (x1.min(size.0), y1.min(size.1));
                let taller = (y1 + radius).min(size.1) - y0.saturating_sub(radius).min(y1);
                [(x1.saturating_sub(x0), taller), (x1.saturating_sub(x0), y1.saturating_sub(y0))]
            }
        }
    }
}

pub struct Bilateral {
    /// Along x, then along y.
    pipelines: [wgpu::ComputePipeline; 2],
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    groups: Vec<wgpu::BindGroup>,
    /// The radius and region of the last `prepare`.
    region: (u32, Region),
}

impl Bilateral {
    pub fn new(device: &wgpu::Device) -> Bilateral {
        let label = "lineao::Bilateral";
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::Texture, Slot::Texture, Slot::StorageTexture(AO_FORMAT), Slot::Texture],
        );
        let axis =
            |a: f64| binding::compute_pipeline(device, label, &layout, "bilateral.wgsl", "bilateral", &[("AXIS", a)]);
        Bilateral {
            pipelines: [axis(0.0), axis(1.0)],
            uniform: binding::uniform_buffer::<BilateralUniform>(device, label),
            layout,
            groups: Vec::new(),
            region: (0, Region::All),
        }
    }

    /// `ao` → `ao_blur_tmp` (x) → `ao_blurred` (y), depth from `nd[0]`, the slices' mark from
    /// `color` (without the blur's targets the pass records nothing).
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
                        wgpu::BindingResource::TextureView(&targets.color.view),
                    ],
                )
            })
            .collect();
    }

    /// Writes the uniform for `view`, `settings` and the pixels of `region`.
    pub fn prepare(&mut self, queue: &wgpu::Queue, view: &FrameView, settings: &BilateralSettings, region: Region) {
        let uniform = BilateralUniform::new(view, settings, region);
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        self.region = (settings.radius_px, region);
    }

    /// Records both halves, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let (Some(blurred), false) = (&targets.ao_blurred, self.groups.is_empty()) else { return };
        let (radius, region) = self.region;
        if let Region::Slices(_) = region {
            // What is not in the rectangle is no slice: it keeps its occlusion.
            encoder.copy_texture_to_texture(
                targets.ao.texture.as_image_copy(),
                blurred.texture.as_image_copy(),
                targets.ao.texture.size(),
            );
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lineao::Bilateral"),
            timestamp_writes: timing::compute_writes(span),
        });
        for ((pipeline, group), extent) in
            self.pipelines.iter().zip(&self.groups).zip(region.extents(radius, targets.size))
        {
            let (x, y) = dispatch_size(extent);
            if x * y == 0 {
                continue;
            }
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
        [view, radius, spatial, depth, slices_only, origin]
    );
}
