//! Object-space AO per pixel (occlusion sweeping, seed 000 §2, Eq. 4–5; or variance occlusion
//! maps, seed 002): the eight octant visibilities V_o the geometry carries per vertex
//! ([`crate::volume`]), interpolated into the `octants` target by the line renderer, meet the
//! pixel's normal N through the integrated geometry term G_o(N) = ∫_{Ω_o} max(N·ω, 0) dω:
//!
//! ```text
//!   ao = 1 − Σ_o w_o V_o G_o(N) / Σ_o G_o(N)
//! ```
//!
//! with w_o the sky's intensity per octant (1 everywhere for an open sky; seed 000 §4.1 lights
//! the octants as eight area lights). Octants are world-axis aligned, so N is the ND map's
//! view-space normal rotated back to world space. A line's normal depends on the view, which is
//! why this happens per pixel, as the paper does it; a view-independent result (V stored in all
//! eight channels, the sky already applied) passes through unchanged with w = 1.
//!
//! G_o(N) comes from [`GeometryTable`]: an octahedral map of N with eight values per texel (the
//! paper's two RGBA lookup textures, Fig. 2), read bilinearly — in a storage buffer, so the
//! arithmetic is the CPU reference's ([`crate::reference::volume_ao`]), not a sampler's.
//! Reads `nd[0]` and `octants`, writes `volume_ao`; the composite combines it with the
//! screen-space method's occlusion.

use glam::Mat3;
use wgpu::util::DeviceExt;

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_full_screen;
use crate::targets::{AO_FORMAT, FrameTargets};
use crate::timing::Span;
use crate::volume::geometry_term::{GeometryTable, TABLE_SIZE};

/// Keep in sync with `VolumeAoUniform` in `shaders/shared/object_ao.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct VolumeAoUniform {
    /// Columns of the rotation from view to world space (w unused).
    pub view_to_world: [[f32; 4]; 3],
    /// w_o for octants 0–3 and 4–7.
    pub weights: [[f32; 4]; 2],
    /// Texels a side of the geometry term's table.
    pub table_size: u32,
    /// Padding to WGSL's 16-byte alignment.
    pub _pad: [u32; 3],
}

impl VolumeAoUniform {
    /// The uniform for `view` and the sky's eight weights.
    pub fn new(view: &FrameView, sky: [f32; 8]) -> VolumeAoUniform {
        let r = view_to_world(view);
        let column = |v: glam::Vec3| [v.x, v.y, v.z, 0.0];
        VolumeAoUniform {
            view_to_world: [column(r.x_axis), column(r.y_axis), column(r.z_axis)],
            weights: [[sky[0], sky[1], sky[2], sky[3]], [sky[4], sky[5], sky[6], sky[7]]],
            table_size: TABLE_SIZE as u32,
            _pad: [0; 3],
        }
    }
}

/// The rotation taking view-space directions to world space.
pub fn view_to_world(view: &FrameView) -> Mat3 {
    Mat3::from_mat4(view.view).inverse()
}

/// [`GeometryTable::normals`] as the shaders read it (`volume_table` of
/// `shaders/shared/object_ao.wgsl`): two vec4 per texel, octants 0–3 and 4–7, row-major.
pub(crate) fn table_buffer(device: &wgpu::Device, label: &str) -> wgpu::Buffer {
    let table: Vec<[f32; 8]> = GeometryTable::normals(TABLE_SIZE).values;
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(&table),
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// Object-space AO per pixel: the octant visibilities against the geometry term.
pub struct VolumeAo {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    /// [`GeometryTable::normals`] as two vec4 per texel (octants 0–3, 4–7), row-major.
    table: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

impl VolumeAo {
    /// Its pipeline and layout.
    pub fn new(device: &wgpu::Device) -> VolumeAo {
        let layout = binding::layout(
            device,
            "lineao::VolumeAo::layout",
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::Texture, Slot::UintTexture, Slot::Storage, Slot::StorageTexture(AO_FORMAT)],
        );
        let pipeline = binding::compute_pipeline(
            device,
            "lineao::VolumeAo::pipeline",
            &layout,
            "volume_ao.wgsl",
            "volume_ao",
            &[],
        );
        VolumeAo {
            pipeline,
            layout,
            uniform: binding::uniform_buffer::<VolumeAoUniform>(device, "lineao::VolumeAo::uniform"),
            table: table_buffer(device, "lineao::VolumeAo::table"),
            group: None,
        }
    }

    /// Binds the targets' `nd[0]`, `octants` and `volume_ao` (made by
    /// [`FrameTargets::with_volume`]); without them the pass records nothing.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        self.group = targets.octants.as_ref().zip(targets.volume_ao.as_ref()).map(|(octants, out)| {
            binding::group(
                device,
                "lineao::VolumeAo::group",
                &self.layout,
                &[
                    self.uniform.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&targets.nd[0].view),
                    wgpu::BindingResource::TextureView(&octants.view),
                    self.table.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&out.view),
                ],
            )
        });
    }

    /// `sky`: w_o per octant, in [0, 1] ([`crate::volume::Sky::weights`]).
    pub fn prepare(&self, queue: &wgpu::Queue, view: &FrameView, sky: [f32; 8]) {
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&VolumeAoUniform::new(view, sky)));
    }

    /// Records the pass, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let Some(group) = &self.group else { return };
        dispatch_full_screen(encoder, "lineao::VolumeAo", &self.pipeline, group, targets.size, span);
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        VolumeAoUniform,
        "volume_ao.wgsl",
        "VolumeAoUniform",
        [view_to_world, weights, table_size]
    );
}
