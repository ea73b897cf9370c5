//! Volumetric Obscurance with line samples (Loos & Sloan, "Volumetric Obscurance", I3D 2010,
//! §4.1, §4.3–4.5).
//!
//! Ambient obscurance as a volume: the fraction of a sphere of radius R around P that the depth
//! buffer leaves empty. A *line sample* at disk point s integrates that exactly along the
//! vertical chord of the unit sphere through s: with the chord [−z_s, z_s] (z_s = √(1 − |s|²),
//! z_d pointing away from the camera) and the visible surface at d_r (depth at the sample's pixel
//! minus depth at P, over R), the free length is max(min(z_s, d_r) + z_s, 0) — one depth fetch
//! buys a whole line integral, which is why 5 line samples beat 12 point samples.
//!
//! ```text
//!   ao(P) = 1 − Σ A_i |free ∩ allowed|_i / Σ A_i |allowed|_i
//! ```
//!
//! - **Weights** A_i come with the sample sets ([`crate::sample_sets`]): the Voronoi column of
//!   each disk point, so every line stands for its share of the sphere.
//! - **Normal clamp** (§4.4): only the half above the tangent plane n · q ≥ 0 is allowed, a
//!   bound on z_d per sample (the plane's depth at s). A plane facing the camera is then wholly
//!   free (ao 0); without the clamp exactly half (ao 0.5).
//! - **Thickness** (§4.3): surfaces are `thickness` deep, free again behind that, so silhouettes
//!   stop casting obscurance on what lies far behind them.
//! - **Randomization** (§4.5): each pixel reflects its samples about a 2D direction from a 4 × 4
//!   tile (a reflection keeps |s|, so chords and weights stay valid).
//!
//! The sphere's radius is in world units, mapped to pixels by the zoom map. The CPU reference
//! is [`crate::reference::vo_line`].

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::noise;
use crate::passes::dispatch_full_screen;
use crate::passes::ssao::ViewUniform;
use crate::reference::ViewParams;
use crate::sample_sets;
use crate::settings::VoSettings;
use crate::targets::{AO_FORMAT, FrameTargets};
use crate::timing::Span;

/// Keep in sync with `VoUniform` in `shaders/vo_line.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct VoUniform {
    pub view: ViewUniform,
    pub noise_origin: [i32; 2],
    pub radius: f32,
    pub zoom_unit: f32,
    pub thickness: f32,
    pub normal_clamp: u32,
    pub _pad: [u32; 2],
}

pub struct VoLine {
    samples: u32,
    noise_seed: u32,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    tables: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

impl VoLine {
    /// `settings` must be valid (`ChainSettings::validate`): its sample count has a table.
    pub fn new(device: &wgpu::Device, settings: &VoSettings) -> VoLine {
        let layout = binding::layout(
            device,
            "lineao::VoLine::layout",
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::Uniform, Slot::Texture, Slot::Texture, Slot::StorageTexture(AO_FORMAT)],
        );
        let pipeline = binding::compute_pipeline(
            device,
            "lineao::VoLine::pipeline",
            &layout,
            "vo_line.wgsl",
            "vo_line",
            &[("SAMPLES", settings.samples as f64)],
        );
        let samples = sample_sets::vo_disk_samples(settings.samples).unwrap_or_default();
        let tile: Vec<[f32; 3]> = noise::vo_noise(settings.noise_seed).iter().map(|u| [u[0], u[1], 0.0]).collect();
        VoLine {
            samples: settings.samples,
            noise_seed: settings.noise_seed,
            pipeline,
            layout,
            uniform: binding::uniform_buffer::<VoUniform>(device, "lineao::VoLine::uniform"),
            // (x, y, A_i) in entries 0..16, the 4 × 4 tile of directions in 16..32.
            tables: binding::two_tables(device, "lineao::VoLine::tables", samples, 16, &tile),
            group: None,
        }
    }

    /// Whether `settings` can reuse this pipeline and its tables.
    pub fn matches(&self, settings: &VoSettings) -> bool {
        (self.samples, self.noise_seed) == (settings.samples, settings.noise_seed)
    }

    /// Reads `nd[0]` and `zoom`, writes `ao`.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        self.group = Some(binding::group(
            device,
            "lineao::VoLine::group",
            &self.layout,
            &[
                self.uniform.as_entire_binding(),
                self.tables.as_entire_binding(),
                wgpu::BindingResource::TextureView(&targets.nd[0].view),
                wgpu::BindingResource::TextureView(&targets.zoom.view),
                wgpu::BindingResource::TextureView(&targets.ao.view),
            ],
        ));
    }

    pub fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &VoSettings) {
        let guard = targets.guard as i32;
        let uniform = VoUniform {
            view: ViewParams::of(view).into(),
            noise_origin: [guard, guard],
            radius: settings.radius_world,
            zoom_unit: view.zoom_unit,
            thickness: settings.thickness_world / settings.radius_world,
            normal_clamp: settings.normal_clamp as u32,
            _pad: [0; 2],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the pass, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let Some(group) = &self.group else { return };
        dispatch_full_screen(encoder, "lineao::VoLine", &self.pipeline, group, targets.size, span);
    }
}
