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
//! The scene's bounds ([`FrameView::from_matrices`]) set the normalized depth range: geometry
//! nearer than their near end or beyond their far end is clamped to it and gets wrong
//! occlusion. Each frame counts such pixels ([`NdFromDepth::try_outside`], through
//! `HostAo::pixels_outside_bounds`), so a host whose bounds miss part of its scene hears of it.
//!
//! Background is where the depth equals the host's clear depth (1, or 0 for reversed-Z). The
//! projection must be symmetric (the optical axis at the image centre), as the VO and SSAO passes
//! assume. The host's textures must be the chain's size (no guard band: AO fades within the
//! largest sampling radius of the image border).

use glam::Mat4;

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_full_screen;
use crate::readback::LateReadback;
use crate::targets::{AO_FORMAT, COLOR_FORMAT, FrameTargets, ND_FORMAT, Target};
use crate::timing::Span;
use crate::{Error, Misuse};

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

/// What each host texture must be (checked by [`check_inputs`] before anything is recorded, so
/// a mismatch is an [`Error::Usage`] that says what to change, never a wgpu panic):
///
/// | texture | usage | format | samples | size |
/// |---|---|---|---|---|
/// | `depth` | `TEXTURE_BINDING` (and stored: `StoreOp::Store`) | a depth format | [`HostConfig::depth_samples`] | the chain's |
/// | `normals` | `TEXTURE_BINDING` | float or unorm color; present iff [`HostConfig::normals`] | 1 | the chain's |
/// | `color` | `TEXTURE_BINDING` | float or unorm color (sRGB decodes) | 1 | the chain's |
/// | composite target | `RENDER_ATTACHMENT` | the format given to `AoChain::new` | 1 | the chain's |
pub fn check_inputs(config: &HostConfig, inputs: &HostInputs, size: (u32, u32)) -> Result<(), Error> {
    let depth = inputs.depth.texture();
    if !depth.format().has_depth_aspect() {
        return Err(Error::Usage(Misuse::TextureFormat {
            texture: "the host depth".into(),
            format: depth.format(),
            samples: depth.sample_count(),
            expected: "a depth format".into(),
        }));
    }
    if depth.sample_count() != config.depth_samples {
        return Err(Error::Usage(Misuse::TextureFormat {
            texture: "the host depth".into(),
            format: depth.format(),
            samples: depth.sample_count(),
            expected: format!(
                "of HostConfig::depth_samples' {} samples: make the HostAo with the depth's sample count",
                config.depth_samples
            ),
        }));
    }
    match (inputs.normals, config.normals) {
        (Some(_), None) => {
            return Err(Error::Usage(Misuse::Input {
                input: "HostInputs::normals",
                given: true,
                config: "HostConfig::normals",
                fix: "say how they are stored in HostConfig, or pass none (normals then come from the depth)",
            }));
        }
        (None, Some(_)) => {
            return Err(Error::Usage(Misuse::Input {
                input: "HostInputs::normals",
                given: false,
                config: "HostConfig::normals",
                fix: "pass the normals, or set HostConfig::normals to None",
            }));
        }
        _ => {}
    }
    check_texture("depth", depth, size)?;
    for (name, view) in [("normals", inputs.normals), ("color", inputs.color)] {
        let Some(view) = view else { continue };
        let texture = view.texture();
        check_texture(name, texture, size)?;
        if texture.sample_count() != 1 {
            return Err(Error::Usage(Misuse::TextureFormat {
                texture: format!("the host {name} texture"),
                format: texture.format(),
                samples: texture.sample_count(),
                expected: "of one sample: resolve it first".into(),
            }));
        }
        if !matches!(texture.format().sample_type(None, None), Some(wgpu::TextureSampleType::Float { .. })) {
            return Err(Error::Usage(Misuse::TextureFormat {
                texture: format!("the host {name} texture"),
                format: texture.format(),
                samples: texture.sample_count(),
                expected: "a float or unorm color format".into(),
            }));
        }
    }
    Ok(())
}

/// A host texture the chain reads: sampled, 2D, at the chain's size.
fn check_texture(name: &str, texture: &wgpu::Texture, (width, height): (u32, u32)) -> Result<(), Error> {
    if !texture.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(Error::Usage(Misuse::TextureUsage {
            texture: format!("the host {name} texture"),
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            has: texture.usage(),
        }));
    }
    if texture.dimension() != wgpu::TextureDimension::D2 || (texture.width(), texture.height()) != (width, height) {
        return Err(Error::Usage(Misuse::Size {
            texture: format!("the host {name} texture ({:?})", texture.dimension()),
            size: (texture.width(), texture.height()),
            chain: (width, height),
        }));
    }
    Ok(())
}

/// Keep in sync with `HostUniform` in `shaders/nd_from_depth.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct HostUniform {
    /// The host's inverse projection.
    pub inv_proj: [[f32; 4]; 4],
    /// The host's world-to-view rotation (for world-space normals).
    pub view_rotation: [[f32; 4]; 4],
    /// The target's size in pixels.
    pub size: [f32; 2],
    /// The near end of the depth range, as −z_view.
    pub near: f32,
    /// The far end of the depth range, as −z_view.
    pub far: f32,
    /// The focal length in pixels.
    pub f_px: f32,
    /// World units per zoom unit.
    pub zoom_unit: f32,
    /// 1 for an orthographic projection.
    pub orthographic: u32,
    /// The depth value of the far plane (background).
    pub far_depth: f32,
    /// Padding to WGSL's 16-byte alignment.
    pub _pad: [u32; 4],
}

/// The G-buffer from a host's depth (and normals, colour): the ND map and zoom map that the
/// methods read.
pub struct NdFromDepth {
    config: HostConfig,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    /// Stands in for the normal and color textures a host does not have.
    placeholder: Target,
    /// `has_color` = 0 and 1, bound per frame.
    has_color: [wgpu::Buffer; 2],
    /// The count of pixels outside the depth range (one u32, cleared per frame), and its way
    /// back to the CPU.
    outside: wgpu::Buffer,
    outside_readback: LateReadback,
}

impl NdFromDepth {
    /// The pass for a host configured by `config`.
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
                Slot::Uniform,
                Slot::StorageReadWrite,
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
            has_color: [0u32, 1].map(|flag| {
                use wgpu::util::DeviceExt;
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("lineao::NdFromDepth::has_color"),
                    contents: bytemuck::cast_slice(&[flag, 0, 0, 0]),
                    usage: wgpu::BufferUsages::UNIFORM,
                })
            }),
            outside: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lineao::NdFromDepth::outside"),
                size: 4,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            outside_readback: LateReadback::new(device, "lineao::NdFromDepth::outside_readback", 4),
        }
    }

    /// Never waits: how many pixels of an earlier frame held geometry outside the bounds'
    /// depth range, once the GPU has finished that frame; else `None` (ask again next frame).
    pub fn try_outside(&self, device: &wgpu::Device) -> Result<Option<u32>, Error> {
        Ok(self.outside_readback.try_take(device)?.map(|bytes| bytemuck::pod_read_unaligned(&bytes[..4])))
    }

    /// How it is configured.
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
            _pad: [0; 4],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the pass over the host's `inputs` into `targets` (timed into `span` when given).
    /// The bind group is the frame's: the host's views may change every frame.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        inputs: &HostInputs,
        span: Option<Span>,
    ) {
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
                self.has_color[inputs.color.is_some() as usize].as_entire_binding(),
                self.outside.as_entire_binding(),
            ],
        );
        encoder.clear_buffer(&self.outside, 0, None);
        dispatch_full_screen(encoder, "lineao::NdFromDepth", &self.pipeline, &group, targets.size, span);
        self.outside_readback.copy(encoder, &self.outside);
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        HostUniform,
        "nd_from_depth.wgsl",
        "HostUniform",
        [inv_proj, view_rotation, size, near, far, f_px, zoom_unit, orthographic, far_depth]
    );
}
