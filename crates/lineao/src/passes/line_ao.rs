//! LineAO (Eichelbaum et al., TVCG 2013, Eq. 7): ambient occlusion made for dense lines.
//!
//! Plain SSAO samples one hemisphere of fixed radius: on thin lines it sees too little volume,
//! and the fixed line width on screen makes bundles look sparser as one zooms in. LineAO sums
//! s_r hemispheres instead. Hemisphere j has radius r_j = r0 + j · z(P) pixels (the zoom map
//! keeps the effect coherent under zoom), takes n_j = ⌈s_h/(j+1)⌉ samples and reads level j of
//! the Gaussian ND pyramid, so wide hemispheres see merged bundles, not single lines:
//!
//! ```text
//!   LineAO(P) = clamp( Σ_j (1/n_j) Σ_i [Δd > ε] · g_depth(Δd, j) · g_light(n_j(P), ω_i), 0, 1 )
//!   Δd        = d_j(P) − d_j(P + r_j (ω.x, −ω.y))                     (Eq. 10, height-field test)
//!   g_depth   = 1 below δ0, 0 above δ(j) = (1 − j/s_r)², 1 − h(·) between   (Eq. 11–13)
//!   g_light   = 1 − min(Σ_lights BRDF(L, I, n_j(P), ω), 1)                  (Eq. 14–15)
//! ```
//!
//! ω_i = reflect(R1(P), R2[j][i]) flipped into the hemisphere of n_j(P) (§3.4, [`crate::noise`]).
//! Where we depart from the paper (the ε test, the third case of Eq. 12) is in CONTRACT.md.
//! The CPU reference is [`crate::reference::line_ao`]; `shaders/line_ao.wgsl` is the shader.

use wgpu::util::DeviceExt;

use crate::binding::{self, Slot};
use crate::lighting::{Lighting, LightingUniform};
use crate::noise;
use crate::passes::dispatch_size;
use crate::settings::LineAoSettings;
use crate::targets::{AO_FORMAT, FrameTargets, LevelsUniform};

/// Keep in sync with `LineAoUniform` in `shaders/line_ao.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LineAoUniform {
    pub levels: LevelsUniform,
    pub noise_origin: [i32; 2],
    pub r0_px: f32,
    pub delta0: f32,
    pub epsilon: f32,
    pub light_attenuation: u32,
    pub _pad: [u32; 2],
}

/// The compile-time shape of the pass: sample counts and the noise they index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Shape {
    s_r: u32,
    s_h: u32,
    noise_seed: u32,
}

pub struct LineAo {
    shape: Shape,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    lighting: wgpu::Buffer,
    noise: wgpu::Buffer,
    samples: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

fn vec4_buffer(device: &wgpu::Device, label: &str, vectors: &[[f32; 3]]) -> wgpu::Buffer {
    let padded: Vec<[f32; 4]> = vectors.iter().map(|v| [v[0], v[1], v[2], 0.0]).collect();
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(&padded),
        usage: wgpu::BufferUsages::STORAGE,
    })
}

impl LineAo {
    pub fn new(device: &wgpu::Device, settings: &LineAoSettings) -> LineAo {
        let layout = binding::layout(device, "lineao::LineAo::layout", wgpu::ShaderStages::COMPUTE, &{
            let mut slots = vec![
                Slot::Uniform,
                Slot::Uniform,
                Slot::Storage,
                Slot::Storage,
                Slot::Texture,
                Slot::StorageTexture(AO_FORMAT),
            ];
            slots.extend([Slot::Texture; crate::MAX_LEVELS as usize]);
            slots
        });
        let shape = Shape { s_r: settings.s_r, s_h: settings.s_h, noise_seed: settings.noise_seed };
        let constants = [("S_R", shape.s_r as f64), ("S_H", shape.s_h as f64)];
        let pipeline = binding::compute_pipeline(
            device,
            "lineao::LineAo::pipeline",
            &layout,
            "line_ao.wgsl",
            "line_ao",
            &constants,
        );
        LineAo {
            shape,
            pipeline,
            uniform: binding::uniform_buffer::<LineAoUniform>(device, "lineao::LineAo::uniform"),
            lighting: binding::uniform_buffer::<LightingUniform>(device, "lineao::LineAo::lighting"),
            noise: vec4_buffer(device, "lineao::LineAo::noise", &noise::noise_tile(shape.noise_seed)),
            samples: vec4_buffer(
                device,
                "lineao::LineAo::samples",
                &noise::sample_table(shape.noise_seed, shape.s_r, shape.s_h),
            ),
            layout,
            group: None,
        }
    }

    /// Whether `settings` need a new pipeline or noise (then make a new pass and `resize` it).
    pub fn matches(&self, settings: &LineAoSettings) -> bool {
        self.shape == Shape { s_r: settings.s_r, s_h: settings.s_h, noise_seed: settings.noise_seed }
    }

    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let mut resources = vec![
            self.uniform.as_entire_binding(),
            self.lighting.as_entire_binding(),
            self.noise.as_entire_binding(),
            self.samples.as_entire_binding(),
            wgpu::BindingResource::TextureView(&targets.zoom.view),
            wgpu::BindingResource::TextureView(&targets.ao.view),
        ];
        resources.extend(targets.level_views().into_iter().map(wgpu::BindingResource::TextureView));
        self.group = Some(binding::group(device, "lineao::LineAo::group", &self.layout, &resources));
    }

    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        targets: &FrameTargets,
        settings: &LineAoSettings,
        r0_px: f32,
        lighting: &Lighting,
    ) {
        let guard = targets.guard as i32;
        let uniform = LineAoUniform {
            levels: targets.levels_uniform(),
            noise_origin: [guard, guard],
            r0_px,
            delta0: settings.delta0,
            epsilon: settings.epsilon,
            light_attenuation: settings.light_attenuation as u32,
            _pad: [0; 2],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        queue.write_buffer(&self.lighting, 0, bytemuck::bytes_of(&lighting.uniform()));
    }

    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets) {
        let Some(group) = &self.group else { return };
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("lineao::LineAo"), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        let (x, y) = dispatch_size(targets.size);
        pass.dispatch_workgroups(x, y, 1);
    }
}
