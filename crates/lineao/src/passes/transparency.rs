//! **Transparent lines**, composited in depth order (hybrid transparency, Maule et al. 2013):
//! of each pixel the K nearest fragments exactly, from a K-buffer, and those beyond blended into
//! an approximate tail.
//!
//! With `C` the colour and `T` the transmittance, the K kept fragments (colour c_i, opacity α_i),
//! sorted by depth, give
//!
//! ```text
//!   C = Σ_{i<K} T_i α_i c_i,   T_i = Π_{j<i} (1 − α_j),
//! ```
//!
//! and the tail (every fragment behind the K-th) adds its opacity-weighted mean colour
//! `Σ α_t c_t / Σ α_t` with the coverage the tail has whatever its order, `1 − Π (1 − α_t)`,
//! behind T_K. Where a pixel has at most K fragments the picture is exact; beyond, the error of
//! a channel is at most `T_K · (1 − Π (1 − α_t))` (the tail's true and approximate colours both
//! lie in [0, 1] times that coverage), which the tests check.
//!
//! A frame is three passes (`shaders/transparency.wgsl`), each fragment shaded once per pass:
//! 1. **depths**: every transparent line's fragment inserts its key into the pixel's K slots by
//!    32-bit `atomicMax`, carrying the evicted one on — the slots end with the K nearest. A key
//!    is the inverted depth (20 bits, 2⁻²⁰ steps of [0, 1]) above the fragment's nearest point
//!    (its index on the page, 12 bits). 32 bits, not a 64-bit depth-and-id word, so that the
//!    one path runs on every device, the browser's too (WebGPU has no 64-bit atomics).
//! 2. **colours**: the same fragments find their depth among the slots and write their shaded
//!    colour and opacity there (`pack2x16float`); the others blend into the tail's two targets.
//! 3. **resolve**: a full-screen pass sorts each pixel's slots, composites them front to back
//!    and the tail behind them, and blends the result *over* the opaque picture already in the
//!    caller's target (premultiplied colour and coverage; a pixel without transparent fragments
//!    is left as it is).
//!
//! **A line counts once.** A strip folds over itself where a line bends within its width on
//! screen: one line's fragments overlap there, and blended twice they would be beads. Fragments
//! adjacent in depth order whose nearest points lie within 2 on the page are taken for one
//! line's and the nearest alone is composited. Two lines' fragments are taken for one only where
//! they are adjacent in depth and their points' indices agree within 2 modulo 2¹² (a line's end
//! and the next one's start, or 5 in 4096 by chance). The tail does not tell lines apart.
//!
//! A fragment behind the opaque G-buffer's depth (anatomy slices, surfaces, opaque lines) is
//! discarded by the shader before it writes anything. Each fragment's colour is the composite's
//! `color · (1 − strength · ao) + specular`, its AO the **object-space AO at its own point**
//! (the octant visibilities its points carry, [`crate::passes::volume_ao`]): the occlusion of
//! each layer by all the geometry, not by what happens to lie in front of it on screen. Without
//! object-space AO the transparent lines are lit but not occluded.
//!
//! Which lines are transparent ([`TransparencySettings`]): the selected ones at `alpha` where it
//! is below 1 (else they are drawn opaque into the G-buffer, with the method's screen-space AO),
//! and the ones the selection leaves out at `context_alpha` where it is above 0 — focus and
//! context: a bundle opaque with its own AO inside a faint whole brain.
//!
//! Memory: 12 bytes a slot ([`BYTES_PER_LAYER`]), K slots a guard-banded pixel, plus 10 bytes a
//! pixel for the tail: at 1280 × 1024 and K = 8, 126 MB for the slots.

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::lighting::LightingShape;
use crate::line_geometry::{LineGeometry, alternating_vertices, full_vertices};
use crate::passes::lines::LineRenderer;
use crate::passes::volume_ao::{VolumeAoUniform, table_buffer};
use crate::settings::TransparencySettings;
use crate::targets::{FrameTargets, Target};
use crate::timing::Span;

/// Bytes a slot of the K-buffer takes: the depth key (4) and the colour with its opacity (8).
pub const BYTES_PER_LAYER: u64 = 12;
/// The tail's premultiplied colour sum and opacity sum.
const ACCUM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The tail's transmittance, Π (1 − α).
const REVEAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

/// Keep in sync with `LayerUniform` in `shaders/transparency.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LayerUniform {
    /// Opacity of the selected lines in the layers; 0 where they are drawn opaque.
    pub alpha: f32,
    /// Opacity of the lines the selection leaves out; 0: hidden.
    pub context_alpha: f32,
    /// The composite's AO strength.
    pub strength: f32,
    /// Padding to WGSL's alignment.
    pub _pad0: u32,
    /// The guard-banded size.
    pub size: [u32; 2],
    /// The guard band.
    pub guard: [u32; 2],
}

/// The bytes of the K-buffer of `layers` slots for a guard-banded `size` (its colours: the
/// largest buffer, what a device's storage limit is checked against).
pub fn colour_bytes(size: (u32, u32), layers: u32) -> u64 {
    size.0 as u64 * size.1 as u64 * layers as u64 * 8
}

/// Whether the K-buffer of `settings` fits the device for a guard-banded `size`
/// ([`crate::Error::TooLarge`] naming the size where it does not).
pub fn fits(settings: &TransparencySettings, size: (u32, u32), limits: &wgpu::Limits) -> Result<(), crate::Error> {
    let what = format!("the K-buffer of {} layers", settings.layers);
    crate::method::fits_storage(&what, size, colour_bytes(size, settings.layers), limits)
}

/// Whether the resolve can blend over a target of `format` on `device` (an
/// [`crate::Error::Unsupported`] naming it where not: 32-bit floats blend only with
/// `FLOAT32_BLENDABLE`).
pub fn check_format(device: &wgpu::Device, format: wgpu::TextureFormat) -> Result<(), crate::Error> {
    let flags = format.guaranteed_format_features(device.features()).flags;
    if flags.contains(wgpu::TextureFormatFeatureFlags::BLENDABLE) {
        return Ok(());
    }
    Err(crate::Error::Unsupported(format!(
        "transparent lines blend over the composite's target, and {format:?} cannot be blended on this device \
         (Rgba16Float or Rgba8Unorm can)"
    )))
}

/// The K-buffer and the tail, for one size of targets.
struct Slots {
    size: (u32, u32),
    depths: wgpu::Buffer,
    colors: wgpu::Buffer,
    accum: wgpu::TextureView,
    reveal: wgpu::TextureView,
    /// Group 3 of the geometry passes and the resolve: the slots, the table, the opaque depth.
    buffers: wgpu::BindGroup,
    /// Group 0 of the resolve: the tail.
    tail: wgpu::BindGroup,
}

/// The transparent lines' passes (see the module documentation).
pub struct Transparency {
    layers: u32,
    octants: bool,
    slab: bool,
    shape: LightingShape,
    /// The depths and colours passes, over the full strip and over the alternating one.
    depths: [wgpu::RenderPipeline; 2],
    colors: [wgpu::RenderPipeline; 2],
    resolve: wgpu::RenderPipeline,
    buffers_layout: wgpu::BindGroupLayout,
    tail_layout: wgpu::BindGroupLayout,
    layer: wgpu::Buffer,
    volume: wgpu::Buffer,
    table: wgpu::Buffer,
    /// Group 2: the layer's and object-space AO's uniforms.
    uniforms: wgpu::BindGroup,
    slots: Option<Slots>,
}

impl Transparency {
    /// The passes for the lines `lines` draws (its group 0: the frame's uniform and lighting),
    /// blending over a picture of `format`: K = `layers` (in [`TransparencySettings::LAYERS`]),
    /// each fragment darkened by its object-space AO with `octants`, cut by the frame's slab with
    /// `slab`.
    pub fn new(
        device: &wgpu::Device,
        lines: &LineRenderer,
        layers: u32,
        octants: bool,
        slab: bool,
        format: wgpu::TextureFormat,
    ) -> Transparency {
        let bindings = lines.bindings();
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let uniforms_layout = binding::layout(device, "lineao::Transparency::uniforms", stages, &[Slot::Uniform; 2]);
        let buffers_layout = binding::layout(
            device,
            "lineao::Transparency::buffers",
            wgpu::ShaderStages::FRAGMENT,
            &[
                Slot::StorageReadWrite,
                Slot::StorageReadWrite,
                Slot::Storage,
                Slot::DepthTexture { multisampled: false },
            ],
        );
        let tail_layout =
            binding::layout(device, "lineao::Transparency::tail", wgpu::ShaderStages::FRAGMENT, &[Slot::Texture; 2]);
        let page = crate::line_geometry::page_layout(device);
        let module = crate::shader::module(device, "transparency.wgsl");
        let constants: Vec<(&str, f64)> =
            [("LAYERS", layers as f64), ("OCTANTS", octants as u32 as f64), ("SLAB", slab as u32 as f64)]
                .into_iter()
                .chain(bindings.shape.constants())
                .collect();
        let geometry_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lineao::Transparency::geometry"),
            bind_group_layouts: &[Some(&bindings.layout), Some(&page), Some(&uniforms_layout), Some(&buffers_layout)],
            immediate_size: 0,
        });
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        // reveal · (1 − α).
        let transmit = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::OneMinusSrc,
            operation: wgpu::BlendOperation::Add,
        };
        let tail_targets = |writes: wgpu::ColorWrites| {
            [
                Some(wgpu::ColorTargetState {
                    format: ACCUM_FORMAT,
                    blend: Some(wgpu::BlendState { color: add, alpha: add }),
                    write_mask: writes,
                }),
                Some(wgpu::ColorTargetState {
                    format: REVEAL_FORMAT,
                    blend: Some(wgpu::BlendState { color: transmit, alpha: transmit }),
                    write_mask: writes,
                }),
            ]
        };
        let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
        let geometry = |label, fragment, writes, alternating| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&geometry_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(if alternating { "vs_layer_alternating" } else { "vs_layer" }),
                    compilation_options: options.clone(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleStrip,
                    ..Default::default()
                },
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fragment),
                    compilation_options: options.clone(),
                    targets: &tail_targets(writes),
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        // The depths pass writes no target: the tail's are its attachments (a render pass needs
        // one), cleared there for the colours pass.
        let [depths, colors] = [
            ("lineao::Transparency::depths", "fs_depths", wgpu::ColorWrites::empty()),
            ("lineao::Transparency::colors", "fs_colors", wgpu::ColorWrites::ALL),
        ]
        .map(|(label, fragment, writes)| {
            [false, true].map(|alternating| geometry(label, fragment, writes, alternating))
        });
        let resolve_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lineao::Transparency::resolve"),
            bind_group_layouts: &[Some(&tail_layout), None, Some(&uniforms_layout), Some(&buffers_layout)],
            immediate_size: 0,
        });
        let resolve = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("lineao::Transparency::resolve"),
            layout: Some(&resolve_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_resolve"),
                compilation_options: options.clone(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_resolve"),
                compilation_options: options.clone(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let layer = binding::uniform_buffer::<LayerUniform>(device, "lineao::Transparency::layer");
        let volume = binding::uniform_buffer::<VolumeAoUniform>(device, "lineao::Transparency::volume");
        let uniforms = binding::group(
            device,
            "lineao::Transparency::uniforms",
            &uniforms_layout,
            &[layer.as_entire_binding(), volume.as_entire_binding()],
        );
        Transparency {
            layers,
            octants,
            slab,
            shape: bindings.shape,
            depths,
            colors,
            resolve,
            buffers_layout,
            tail_layout,
            layer,
            volume,
            table: table_buffer(device, "lineao::Transparency::table"),
            uniforms,
            slots: None,
        }
    }

    /// Whether it was made for these: K, octants, a slab, the lighting's shape.
    pub(crate) fn made_for(&self, layers: u32, octants: bool, slab: bool, shape: LightingShape) -> bool {
        (self.layers, self.octants, self.slab, self.shape) == (layers, octants, slab, shape)
    }

    /// (Re)allocates the K-buffer and the tail for `targets` (checked against the device by
    /// [`fits`] before).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        if self.slots.as_ref().is_some_and(|s| s.size == targets.size) {
            return;
        }
        let storage = |label, bytes| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let colour = colour_bytes(targets.size, self.layers);
        let depths = storage("lineao::Transparency::depths", colour / 2);
        let colors = storage("lineao::Transparency::colors", colour);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let texture = |label, format| Target::new(device, label, targets.size, format, usage).view;
        let accum = texture("lineao::Transparency::accum", ACCUM_FORMAT);
        let reveal = texture("lineao::Transparency::reveal", REVEAL_FORMAT);
        let buffers = binding::group(
            device,
            "lineao::Transparency::buffers",
            &self.buffers_layout,
            &[
                depths.as_entire_binding(),
                colors.as_entire_binding(),
                self.table.as_entire_binding(),
                wgpu::BindingResource::TextureView(&targets.depth.view),
            ],
        );
        let tail = binding::group(
            device,
            "lineao::Transparency::tail",
            &self.tail_layout,
            &[wgpu::BindingResource::TextureView(&accum), wgpu::BindingResource::TextureView(&reveal)],
        );
        self.slots = Some(Slots { size: targets.size, depths, colors, accum, reveal, buffers, tail });
    }

    /// Writes the frame's uniforms: the opacities of `settings`, the composite's AO `strength`
    /// and the sky of object-space AO.
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        view: &FrameView,
        settings: &TransparencySettings,
        strength: f32,
        sky: [f32; 8],
    ) {
        let (width, height) = view.banded_size();
        let uniform = LayerUniform {
            alpha: if settings.focus_transparent() { settings.alpha } else { 0.0 },
            context_alpha: settings.context_alpha,
            strength,
            _pad0: 0,
            size: [width, height],
            guard: [view.guard; 2],
        };
        queue.write_buffer(&self.layer, 0, bytemuck::bytes_of(&uniform));
        queue.write_buffer(&self.volume, 0, bytemuck::bytes_of(&VolumeAoUniform::new(view, sky)));
    }

    /// Records the three passes for `geometry` as `lines` draws it (its group 0 and strips,
    /// prepared for this frame), the resolve blending over `target`, which holds the opaque
    /// picture. Timed into `span` when given.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &LineGeometry,
        lines: &LineRenderer,
        target: &wgpu::TextureView,
        span: Option<Span>,
    ) {
        let Some(slots) = &self.slots else { return };
        let (first, last) = Span::split(span);
        encoder.clear_buffer(&slots.depths, 0, None);
        encoder.clear_buffer(&slots.colors, 0, None);
        for (label, pipelines, clear) in [
            ("lineao::Transparency::depths", &self.depths, true),
            ("lineao::Transparency::colors", &self.colors, false),
        ] {
            let attachment = |view, value: f64| {
                let load = if clear {
                    wgpu::LoadOp::Clear(wgpu::Color { r: value, g: value, b: value, a: value })
                } else {
                    wgpu::LoadOp::Load
                };
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
                })
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[attachment(&slots.accum, 0.0), attachment(&slots.reveal, 1.0)],
                depth_stencil_attachment: None,
                timestamp_writes: if clear { crate::timing::render_writes(first) } else { None },
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &lines.bindings().group, &[]);
            pass.set_bind_group(2, &self.uniforms, &[]);
            pass.set_bind_group(3, &slots.buffers, &[]);
            for page in geometry.pages() {
                // The strip the opaque lines take for this page, from afar the alternating one —
                // but the full one under object-space AO: over the alternating strip's triangles
                // (three points each) the octants interpolate otherwise than the opaque lines'
                // object-space AO does, measured 0.02 of a channel apart.
                let alternating = lines.page_alternates(page) && !self.octants;
                pass.set_pipeline(&pipelines[alternating as usize]);
                pass.set_bind_group(1, &page.group, &[]);
                for (class, range) in page.classes.iter().enumerate().filter(|(_, range)| !range.is_empty()) {
                    let vertices = if alternating { alternating_vertices(class) } else { full_vertices(class) };
                    for batch in geometry.draw_batches(range.clone()) {
                        pass.draw(0..vertices, batch);
                    }
                }
            }
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lineao::Transparency::resolve"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: crate::timing::render_writes(last),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &slots.tail, &[]);
        pass.set_bind_group(2, &self.uniforms, &[]);
        pass.set_bind_group(3, &slots.buffers, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        LayerUniform,
        "transparency.wgsl",
        "LayerUniform",
        [alpha, context_alpha, strength, size, guard]
    );
}
