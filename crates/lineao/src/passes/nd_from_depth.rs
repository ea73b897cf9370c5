//! Embedding: the G-buffer from a host renderer's own buffers, so a host that renders its own
//! geometry gets LineAO, VO and SSAO without changing its shaders (`shaders/nd_from_depth.wgsl`).
//!
//! Per pixel, from the host's depth texture (any depth format, single- or multisampled — MSAA
//! resolves to the mean of the samples that hold geometry where at least half do, the centre's
//! depth on a plane for the symmetric standard patterns — standard or reversed-Z: the inverse
//! projection undoes it):
//!
//! - the view-space point P = proj⁻¹ · (ndc, depth);
//! - the normal: the host's (view or world space, signed floats or packed into unorm as
//!   n · 0.5 + 0.5), or reconstructed as the cross product of the tangents along the image
//!   axes — central differences where both neighbours continue the surface (their depth steps
//!   differ by at most two pixel footprints or a quarter), else toward the neighbour whose depth
//!   differs least from P's (so a silhouette on one side does not tilt it) — turned toward the
//!   eye;
//! - the ND map (normal, normalized linear depth over the scene's bounds), the zoom map, and the
//!   host's lit color (linear: sRGB textures decode on load) with no specular, for the
//!   composite: color · (1 − strength · ao).
//!
//! Background is where the depth equals the host's clear depth (1, or 0 for reversed-Z). The
//! projection must be symmetric (the optical axis at the image centre), as the VO and SSAO passes
//! assume. The host's textures must be the chain's size (no guard band: AO fades within the
//! largest sampling radius of the image border).

use glam::Mat4;

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_full_screen;
use crate::targets::{AO_FORMAT, COLOR_FORMAT, FrameTargets, ND_FORMAT, Target};
use crate::timing::Span;

/// How a host's normals are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HostNormals {
    /// World-space normals (rotated into view space here) or view-space ones.
    pub world_space: bool,
    /// Packed into a unorm format as n · 0.5 + 0.5 (else signed floats).
    pub unorm: bool,
}

impl HostNormals {
    fn code(self) -> u32 {
        1 + self.unorm as u32 + 2 * self.world_space as u32
    }
}

/// What a host's buffers are like: fixed for the pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HostConfig {
    /// Samples of the host's depth texture (1, or its MSAA count).
    pub depth_samples: u32,
    /// The depth buffer holds 1 near and 0 far (and clears to 0).
    pub reversed_z: bool,
    /// The host's normal texture, if it has one; else normals come from the depth.
    pub normals: Option<HostNormals>,
}

impl Default for HostConfig {
    fn default() -> Self {
        HostConfig { depth_samples: 1, reversed_z: false, normals: None }
    }
}

/// A host's textures for one frame, at the chain's size.
#[derive(Clone, Copy, Debug)]
pub struct HostInputs<'a> {
    /// Depth (a depth-aspect view; multisampled as [`HostConfig::depth_samples`] says).
    pub depth: &'a wgpu::TextureView,
    /// Normals as [`HostConfig::normals`] says (any float or unorm color format).
    pub normals: Option<&'a wgpu::TextureView>,
    /// The lit color the composite darkens; without it the color is white (the output is the
    /// AO's brightness).
    pub color: Option<&'a wgpu::TextureView>,
}

/// Keep in sync with `HostUniform` in `shaders/nd_from_depth.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct HostUniform {
    pub inv_proj: [[f32; 4]; 4],
    pub view_rotation: [[f32; 4]; 4],
    pub size: [f32; 2],
    pub near: f32,
    pub far: f32,
    pub f_px: f32,
    pub zoom_unit: f32,
    pub orthographic: u32,
    pub far_depth: f32,
    pub has_color: u32,
    pub _pad: [u32; 3],
}

pub struct NdFromDepth {
    config: HostConfig,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    /// Stands in for the normal and color textures a host does not have.
    placeholder: Target,
}

impl NdFromDepth {
    pub fn new(device: &wgpu::Device, config: HostConfig) -> NdFromDepth {
        let multisampled = config.depth_samples > 1;
        let layout = binding::layout(
            device,
            "lineao::NdFromDepth::layout",
            wgpu::ShaderStages::COMPUTE,
            &[
                Slot::Uniform,
                Slot::DepthTexture { multisampled },
                Slot::Texture,
                Slot::Texture,
                Slot::StorageTexture(ND_FORMAT),
                Slot::StorageTexture(AO_FORMAT),
                Slot::StorageTexture(COLOR_FORMAT),
                Slot::StorageTexture(AO_FORMAT),
            ],
        );
        let replacements: &[(&str, &str)] =
            if multisampled { &[("texture_depth_2d", "texture_depth_multisampled_2d")] } else { &[] };
        let module = crate::shader::module_with(device, "nd_from_depth.wgsl", replacements);
        let constants =
            [("SAMPLES", config.depth_samples as f64), ("NORMALS", config.normals.map_or(0, HostNormals::code) as f64)];
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("lineao::NdFromDepth::pipeline"),
            layout: Some(&binding::pipeline_layout(device, "lineao::NdFromDepth::pipeline_layout", &layout)),
            module: &module,
            entry_point: Some("nd_from_depth"),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            cache: None,
        });
        let placeholder = Target::new(
            device,
            "lineao::NdFromDepth::placeholder",
            (1, 1),
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureUsages::TEXTURE_BINDING,
        );
        NdFromDepth {
            config,
            pipeline,
            layout,
            uniform: binding::uniform_buffer::<HostUniform>(device, "lineao::NdFromDepth::uniform"),
            placeholder,
        }
    }

    pub fn config(&self) -> HostConfig {
        self.config
    }

    /// The uniform for a frame seen through `view` (the host's matrices:
    /// [`FrameView::from_matrices`]).
    pub fn prepare(&self, queue: &wgpu::Queue, view: &FrameView) {
        let (w, h) = view.banded_size();
        let uniform = HostUniform {
            inv_proj: view.proj.inverse().to_cols_array_2d(),
            view_rotation: Mat4::from_mat3(glam::Mat3::from_mat4(view.view)).to_cols_array_2d(),
            size: [w as f32, h as f32],
            near: view.near,
            far: view.far,
            f_px: view.f_px,
            zoom_unit: view.zoom_unit,
            orthographic: view.orthographic as u32,
            far_depth: if self.config.reversed_z { 0.0 } else { 1.0 },
            has_color: 0,
            _pad: [0; 3],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the pass over the host's `inputs` into `targets` (timed into `span` when given).
    /// The bind group is the frame's: the host's views may change every frame.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        inputs: &HostInputs,
        span: Option<Span>,
    ) {
        // Whether a color comes with this frame: the uniform's one per-frame word.
        let has_color = inputs.color.is_some() as u32;
        queue.write_buffer(
            &self.uniform,
            std::mem::offset_of!(HostUniform, has_color) as u64,
            bytemuck::bytes_of(&has_color),
        );
        let placeholder = &self.placeholder.view;
        let group = binding::group(
            device,
            "lineao::NdFromDepth::group",
            &self.layout,
            &[
                self.uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(inputs.depth),
                wgpu::BindingResource::TextureView(inputs.normals.unwrap_or(placeholder)),
                wgpu::BindingResource::TextureView(inputs.color.unwrap_or(placeholder)),
                wgpu::BindingResource::TextureView(&targets.nd[0].view),
                wgpu::BindingResource::TextureView(&targets.zoom.view),
                wgpu::BindingResource::TextureView(&targets.color.view),
                wgpu::BindingResource::TextureView(&targets.specular.view),
            ],
        );
        dispatch_full_screen(encoder, "lineao::NdFromDepth", &self.pipeline, &group, targets.size, span);
    }
}
