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

use crate::binding::{self, Slot};
use crate::settings::DebugView;
use crate::targets::{FrameTargets, LevelsUniform, Target};
use crate::timing::{self, Span};

/// Keep in sync with `CompositeUniform` in `shaders/composite.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CompositeUniform {
    pub levels: LevelsUniform,
    pub guard: [u32; 2],
    pub strength: f32,
    pub debug_view: u32,
    pub debug_level: u32,
    pub zoom_max: f32,
    /// 0: the screen-space AO, 1: object-space AO alone, 2: both, brightness multiplied,
    /// 3: both, the darker.
    pub combine: u32,
    pub _pad: u32,
}

/// Which occlusion the composite shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    Screen,
    Volume,
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

pub struct Composite {
    pipeline: wgpu::RenderPipeline,
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
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("lineao::Composite::pipeline"),
            layout: Some(&binding::pipeline_layout(device, "lineao::Composite::pipeline_layout", &layout)),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Composite {
            pipeline,
            layout,
            uniform: binding::uniform_buffer::<CompositeUniform>(device, "lineao::Composite::uniform"),
            group: None,
        }
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

    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        targets: &FrameTargets,
        strength: f32,
        debug_view: DebugView,
        zoom_max: f32,
        shown: Shown,
    ) {
        let (debug_view, debug_level) = debug_view.code();
        let uniform = CompositeUniform {
            levels: targets.levels_uniform(),
            guard: [targets.guard; 2],
            strength,
            debug_view,
            debug_level,
            zoom_max: zoom_max.max(1e-12),
            combine: shown.code(),
            _pad: 0,
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Draws the visible window into `target` (the visible size).
    /// Records the composite into `target`, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, target: &wgpu::TextureView, span: Option<Span>) {
        let Some(group) = &self.group else { return };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lineao::Composite"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timing::render_writes(span),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
    }
}
