//! Composite (paper §3.3): the lit lines darkened by the occlusion, with the illuminated-lines
//! specular added on top (LineAO already stands for the diffuse and ambient part, so a
//! multiplicative specular would suppress too much), cropped from the guard-banded G-buffer into
//! the caller's target of any color format:
//!
//! ```text
//!   out = color · (1 − clamp(strength · ao, 0, 1)) + specular
//! ```
//!
//! With object-space AO ([`crate::passes::volume_ao`]) `ao` is that occlusion alone, or the
//! screen-space method's and it combined: brightness multiplied, 1 − (1 − a)(1 − b), or the
//! darker of the two, max(a, b) ([`crate::reference::combine_ao`]).
//!
//! Debug views show the AO alone, the normals, the depth, the zoom map or one pyramid level.
//! The CPU reference is [`crate::reference::composite`].
//!
//! As an overlay ([`Composite::set_overlay`], [`crate::OverlayAo`]) it draws only
//! the geometry's pixels into a host's frame: the background is discarded, so the host's colour
//! stays, and with the host's depth attachment each pixel writes the geometry's depth as the
//! host's projection puts it, tested against what the host drew before (so lines hide behind
//! the host's nearer surfaces) and kept for what it draws after:
//!
//! ```text
//!   z = −(near + nd.w · (far − near)),   depth = (P₂₂ z + P₂₃) / (P₃₂ z + P₃₃)
//! ```

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::seed_depth::OverlayDepth;
use crate::settings::DebugView;
use crate::targets::{FrameTargets, LevelsUniform, Target};
use crate::timing::{self, Span};

/// Keep in sync with `CompositeUniform` in `shaders/composite.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CompositeUniform {
    /// The pyramid's levels (for the level debug view).
    pub levels: LevelsUniform,
    /// The guard band on each side, x and y.
    pub guard: [u32; 2],
    /// The AO's strength.
    pub strength: f32,
    /// The debug view shown ([`crate::DebugView`]'s index).
    pub debug_view: u32,
    /// The pyramid level of the level debug view.
    pub debug_level: u32,
    /// The largest zoom, which the zoom debug view maps to white.
    pub zoom_max: f32,
    /// 0: the screen-space AO, 1: object-space AO alone, 2: both, brightness multiplied,
    /// 3: both, the darker.
    pub combine: u32,
    /// Padding to WGSL's 16-byte alignment.
    pub _pad: u32,
    /// The overlay depth's projection rows: depth = (x z + y) / (z z + w).
    pub host_depth_rows: [f32; 4],
    /// The near end of the depth range, as −z_view.
    pub near: f32,
    /// The far end of the depth range, as −z_view.
    pub far: f32,
    /// Padding to WGSL's 16-byte alignment.
    pub _pad1: [u32; 2],
}

/// The overlay pipeline and the depth it was made for.
struct Overlay {
    depth: Option<OverlayDepth>,
    pipeline: wgpu::RenderPipeline,
}

/// Which occlusion the composite shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// The screen-space method's occlusion.
    Screen,
    /// Object-space AO alone.
    Volume,
    /// Both, combined so.
    Both(crate::VoCombine),
}

impl Shown {
    fn code(self) -> u32 {
        match self {
            Shown::Screen => 0,
            Shown::Volume => 1,
            Shown::Both(crate::VoCombine::Product) => 2,
            Shown::Both(crate::VoCombine::Min) => 3,
        }
    }
}

/// The last pass: the colour darkened by the occlusion, the specular added, written to the target.
pub struct Composite {
    pipeline: wgpu::RenderPipeline,
    /// Made by [`Composite::set_overlay`].
    overlay: Option<Overlay>,
    format: wgpu::TextureFormat,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

impl Composite {
    /// A composite writing to targets of `format` (sRGB formats encode on write).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Composite {
        let mut slots = vec![Slot::Uniform, Slot::Texture, Slot::Texture, Slot::Texture, Slot::Texture, Slot::Texture];
        slots.extend([Slot::Texture; crate::MAX_LEVELS as usize]);
        let layout = binding::layout(device, "lineao::Composite::layout", wgpu::ShaderStages::FRAGMENT, &slots);
        let module = crate::shader::module(device, "composite.wgsl");
        let pipeline_layout = binding::pipeline_layout(device, "lineao::Composite::pipeline_layout", &layout);
        let pipeline = render_pipeline(device, &pipeline_layout, &module, format, "fs_main", None);
        Composite {
            pipeline,
            overlay: None,
            format,
            module,
            pipeline_layout,
            layout,
            uniform: binding::uniform_buffer::<CompositeUniform>(device, "lineao::Composite::uniform"),
            group: None,
        }
    }

    /// Makes the composite ready to draw as an overlay ([`Composite::encode_overlay`]), with or
    /// without the host's depth; the pipeline is rebuilt only when the depth's format or
    /// direction changes, so a new projection each frame is cheap. Takes effect at the next
    /// `prepare`.
    pub fn set_overlay(&mut self, device: &wgpu::Device, depth: Option<OverlayDepth>) {
        let key = |d: &Option<OverlayDepth>| d.map(|d| (d.format, d.reversed()));
        if let Some(overlay) = &mut self.overlay
            && key(&overlay.depth) == key(&depth)
        {
            overlay.depth = depth;
            return;
        }
        let stencil = depth.map(|d| wgpu::DepthStencilState {
            format: d.format,
            depth_write_enabled: Some(true),
            depth_compare: Some(if d.reversed() {
                wgpu::CompareFunction::GreaterEqual
            } else {
                wgpu::CompareFunction::LessEqual
            }),
            stencil: Default::default(),
            bias: Default::default(),
        });
        let entry = if depth.is_some() { "fs_overlay_depth" } else { "fs_overlay" };
        let pipeline = render_pipeline(device, &self.pipeline_layout, &self.module, self.format, entry, stencil);
        self.overlay = Some(Overlay { depth, pipeline });
    }

    /// The overlay's depth, if [`Composite::set_overlay`] asked for one.
    pub fn overlay_depth(&self) -> Option<Option<OverlayDepth>> {
        self.overlay.as_ref().map(|o| o.depth)
    }

    /// Shows `ao` (`targets.ao`, or `targets.ao_blurred` after the bilateral blur) and, where
    /// the targets have it, `targets.volume_ao`.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets, ao: &Target) {
        let volume = targets.volume_ao.as_ref().unwrap_or(ao);
        let mut resources = vec![
            self.uniform.as_entire_binding(),
            wgpu::BindingResource::TextureView(&targets.color.view),
            wgpu::BindingResource::TextureView(&targets.specular.view),
            wgpu::BindingResource::TextureView(&ao.view),
            wgpu::BindingResource::TextureView(&targets.zoom.view),
            wgpu::BindingResource::TextureView(&volume.view),
        ];
        resources.extend(targets.level_views().into_iter().map(wgpu::BindingResource::TextureView));
        self.group = Some(binding::group(device, "lineao::Composite::group", &self.layout, &resources));
    }

    /// Writes this frame's uniform.
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        targets: &FrameTargets,
        view: &FrameView,
        strength: f32,
        debug_view: DebugView,
        shown: Shown,
    ) {
        let rows = self.overlay.as_ref().and_then(|o| o.depth).map_or([0.0, 0.0, 0.0, 1.0], |d| d.rows());
        let (debug_view, debug_level) = debug_view.code();
        let uniform = CompositeUniform {
            levels: targets.levels_uniform(),
            guard: [targets.guard; 2],
            strength,
            debug_view,
            debug_level,
            zoom_max: view.zoom_max().max(1e-12),
            combine: shown.code(),
            _pad: 0,
            host_depth_rows: rows,
            near: view.near,
            far: view.far,
            _pad1: [0; 2],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the composite into `target` (the visible size), timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, target: &wgpu::TextureView, span: Option<Span>) {
        let load = wgpu::LoadOp::Clear(wgpu::Color::BLACK);
        self.record(encoder, &self.pipeline, (target, load), None, span);
    }

    /// Records the overlay (after [`Composite::set_overlay`]) into the host's `target` and, when
    /// the overlay has depth, its `depth`: both loaded, so the host's frame stays.
    pub fn encode_overlay(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        depth: Option<&wgpu::TextureView>,
        span: Option<Span>,
    ) {
        let Some(overlay) = &self.overlay else { return };
        self.record(encoder, &overlay.pipeline, (target, wgpu::LoadOp::Load), depth, span);
    }

    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::RenderPipeline,
        (target, load): (&wgpu::TextureView, wgpu::LoadOp<wgpu::Color>),
        depth: Option<&wgpu::TextureView>,
        span: Option<Span>,
    ) {
        let Some(group) = &self.group else { return };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lineao::Composite"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: depth.map(|view| wgpu::RenderPassDepthStencilAttachment {
                view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: timing::render_writes(span),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// The composite's full-screen pipeline with fragment entry point `entry`.
fn render_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
    entry: &str,
    depth_stencil: Option<wgpu::DepthStencilState>,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("lineao::Composite::pipeline"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        CompositeUniform,
        "composite.wgsl",
        "CompositeUniform",
        [levels, guard, strength, debug_view, debug_level, zoom_max, combine, host_depth_rows, near, far]
    );
}
