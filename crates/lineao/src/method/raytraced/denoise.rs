//! The ray tracer's edge-aware denoiser: a few rays per pixel are noisy (after k binary rays a
//! pixel's mean has a standard error of √(p(1 − p)/k), 0.25 at 4 rays), and neighbouring
//! pixels on the same surface see nearly the same hemisphere, so averaging them trades a little
//! bias for much less noise — as long as the average never crosses to another surface.
//!
//! ```text
//!   ao'(P) = Σ_Q w(Q) m(Q) / Σ_Q w(Q),   m(Q) = sum(Q) / rays(Q)
//!   w(Q)  = exp(−|Q − P|²/(2σ²)) · max(n_P · n_Q, 0)^p · same(P, Q),   σ = σ_4 · √(4/rays)
//! ```
//!
//! over a (2r + 1)² window. `same` is where lines differ from meshes. Dense lines put other
//! lines one pixel away at nearly the same depth and facing — a depth-aware blur (the bilateral
//! pass) averages across them and measurably worsens the picture against the truth (docs/
//! ground-truth.md). The ray tracer knows more: each line pixel's *own segment* (found on the
//! picture's first frame and kept in its accumulation; with the denoiser tube pixels find theirs
//! too). Two line or tube pixels are the same surface when their own segments are at most
//! `reach_vertices` apart along the polyline; mesh pixels (no own segment) when their depths
//! differ by at most `depth_tolerance` of the pixel's. σ shrinks as 1/√rays with the noise, so the denoiser smooths the first frames and
//! fades out (below a quarter pixel it copies the mean) as the picture converges.
//!
//! It reads the ray tracer's accumulation and `nd[0]`, and writes `ao` in place of the plain
//! mean; [`crate::method::raytraced::RayTracedAo`] runs it after each frame's rays. The CPU
//! reference is [`crate::reference::ray_denoise`].

use super::settings::RayDenoiseSettings;
use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_full_screen;
use crate::shader::Library;
use crate::targets::{AO_FORMAT, FrameTargets};
use crate::timing::Span;
use crate::view_params::{ViewParams, ViewUniform};

/// Keep in sync with `Denoise` in `ray_denoise.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct DenoiseUniform {
    view: ViewUniform,
    radius: i32,
    spatial: f32,
    normal_power: f32,
    depth_tolerance: f32,
    reach: u32,
    width: u32,
    height: u32,
    rays: u32,
}

const LABEL: &str = "lineao::RayDenoise";

/// Its WGSL file, one of the ray tracer's ([`super::METHOD`]'s library lists it).
pub(crate) const WGSL: (&str, &str) = ("ray_denoise.wgsl", include_str!("ray_denoise.wgsl"));
const LIBRARY: Library = Library { files: &[WGSL], constants: &[] };

/// The edge-aware denoiser after the rays: a window over the same line or surface that narrows
/// as 1/√rays.
pub struct RayDenoise {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    uniform: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

impl RayDenoise {
    /// Its pipeline and layout.
    pub fn new(device: &wgpu::Device) -> RayDenoise {
        let slots = [Slot::Uniform, Slot::Texture, Slot::StorageTexture(AO_FORMAT), Slot::Storage];
        let layout = binding::layout(device, LABEL, wgpu::ShaderStages::COMPUTE, &slots);
        RayDenoise {
            pipeline: binding::compute_pipeline(device, LABEL, &layout, LIBRARY.source(WGSL.0), "ray_denoise", &[]),
            uniform: binding::uniform_buffer::<DenoiseUniform>(device, LABEL),
            layout,
            group: None,
        }
    }

    /// Binds `nd[0]`, `ao` and the ray tracer's `accumulation` (16 bytes per pixel of `targets`).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets, accumulation: &wgpu::Buffer) {
        let resources = [
            self.uniform.as_entire_binding(),
            wgpu::BindingResource::TextureView(&targets.nd[0].view),
            wgpu::BindingResource::TextureView(&targets.ao.view),
            accumulation.as_entire_binding(),
        ];
        self.group = Some(binding::group(device, LABEL, &self.layout, &resources));
    }

    /// The frame's parameters: `rays` per pixel once the frame's rays are in, over lines or
    /// `tubes`.
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        targets: &FrameTargets,
        view: &FrameView,
        settings: &RayDenoiseSettings,
        (rays, tubes): (u32, bool),
    ) {
        let uniform = DenoiseUniform {
            view: ViewParams::of(view).into(),
            radius: settings.radius_px as i32,
            spatial: settings.spatial(rays, tubes),
            normal_power: settings.normal_power,
            depth_tolerance: settings.depth_tolerance,
            reach: settings.reach_vertices,
            width: targets.size.0,
            height: targets.size.1,
            rays,
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the denoiser over every pixel, timed into `span`.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        if let Some(group) = &self.group {
            dispatch_full_screen(encoder, LABEL, &self.pipeline, group, targets.size, span);
        }
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        DenoiseUniform,
        LIBRARY.source(WGSL.0),
        "Denoise",
        [view, radius, spatial, normal_power, depth_tolerance, reach, width, height, rays]
    );
}
