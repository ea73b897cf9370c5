//! What the geometry passes share — [`LineRenderer`](crate::passes::lines::LineRenderer),
//! [`TubeRenderer`](crate::passes::tubes::TubeRenderer) and
//! [`MeshRenderer`](crate::passes::meshes::MeshRenderer) all write the G-buffer of docs/reference.md:
//! the per-frame uniform (`shaders/shared/geometry.wgsl`), the attachments in their order, and
//! a pipeline builder. The first writer of a frame clears the targets, the others draw over it.
//!
//! A host renderer that writes the ND and zoom maps from its own shaders includes
//! [`crate::shader::GBUFFER_WGSL`] (`shaders/shared/gbuffer.wgsl`).

use crate::camera::FrameView;
use crate::lighting::LightingShape;
use crate::settings::LineColor;
use crate::targets::{self, FrameTargets};
use crate::timing::{self, Span};

/// Keep in sync with `GeometryUniform` in `shaders/shared/geometry.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GeometryUniform {
    pub view: [[f32; 4]; 4],
    pub proj: [[f32; 4]; 4],
    pub inv_proj: [[f32; 4]; 4],
    pub constant_color: [f32; 4],
    pub viewport: [f32; 2],
    pub near: f32,
    pub far: f32,
    pub f_px: f32,
    pub zoom_unit: f32,
    pub line_width_px: f32,
    pub orthographic: u32,
    pub color_mode: u32,
    pub tube_radius: f32,
    /// NDC units per pixel: 2 / viewport (the lines' sideways offsets, without a division).
    pub ndc_per_px: [f32; 2],
    /// [`LineColor::Scalar`]: the scalar range mapped to the colormap's ends, and its table.
    pub scalar_range: [f32; 4],
    /// A [`crate::settings::Slab`] in eye space: (n, d), the signed distance dot(n, p) + d.
    pub slab_plane: [f32; 4],
    /// x: the slab's half thickness; negative without a slab.
    pub slab_half: [f32; 4],
    pub colormap: [[f32; 4]; crate::settings::COLORMAP_ENTRIES],
}

impl GeometryUniform {
    pub fn new(view: &FrameView, color: LineColor, line_width_px: f32, tube_radius: f32) -> GeometryUniform {
        let (w, h) = view.banded_size();
        let (color_mode, constant) = match color {
            LineColor::Tangent => (0, [0.0; 3]),
            LineColor::Constant(rgb) => (1, rgb),
            LineColor::Scalar { .. } => (2, [0.0; 3]),
            LineColor::Pieces => (3, [0.0; 3]),
        };
        let (scalar_range, colormap) = match color {
            LineColor::Scalar { colormap, range } => ([range[0], range[1], 0.0, 0.0], colormap.table()),
            _ => ([0.0, 1.0, 0.0, 0.0], [[0.0; 4]; crate::settings::COLORMAP_ENTRIES]),
        };
        GeometryUniform {
            view: view.view.to_cols_array_2d(),
            proj: view.proj.to_cols_array_2d(),
            inv_proj: view.proj.inverse().to_cols_array_2d(),
            constant_color: [constant[0], constant[1], constant[2], 1.0],
            viewport: [w as f32, h as f32],
            near: view.near,
            far: view.far,
            f_px: view.f_px,
            zoom_unit: view.zoom_unit,
            line_width_px,
            orthographic: view.orthographic as u32,
            color_mode,
            tube_radius,
            ndc_per_px: [2.0 / w as f32, 2.0 / h as f32],
            scalar_range,
            slab_plane: [0.0; 4],
            slab_half: [-1.0, 0.0, 0.0, 0.0],
            colormap,
        }
    }

    /// `self` cutting the lines to `slab` (as seen in `view`).
    pub fn with_slab(self, view: &FrameView, slab: Option<&crate::settings::Slab>) -> GeometryUniform {
        match slab {
            Some(slab) => {
                let (slab_plane, half) = slab.in_view(view);
                GeometryUniform { slab_plane, slab_half: [half, 0.0, 0.0, 0.0], ..self }
            }
            None => self,
        }
    }
}

/// The G-buffer attachments a geometry pass writes, in `GBuffer`'s order (`geometry.wgsl`).
pub const GBUFFER_FORMATS: [wgpu::TextureFormat; 4] =
    [targets::COLOR_FORMAT, targets::ND_FORMAT, targets::ZOOM_FORMAT, targets::SPECULAR_FORMAT];

/// The two uniform buffers of a geometry pass (frame, lighting) and their bind group, and the
/// lighting its pipelines are compiled for ([`pipeline`]).
pub(crate) struct GeometryBindings {
    pub layout: wgpu::BindGroupLayout,
    pub frame: wgpu::Buffer,
    pub lighting: wgpu::Buffer,
    pub group: wgpu::BindGroup,
    pub shape: LightingShape,
}

impl GeometryBindings {
    pub fn new(device: &wgpu::Device, label: &str, shape: LightingShape) -> GeometryBindings {
        use crate::binding::{self, Slot};
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::Uniform],
        );
        let frame = binding::uniform_buffer::<GeometryUniform>(device, label);
        let lighting = binding::uniform_buffer::<crate::lighting::LightingUniform>(device, label);
        let group = binding::group(device, label, &layout, &[frame.as_entire_binding(), lighting.as_entire_binding()]);
        GeometryBindings { layout, frame, lighting, group, shape }
    }

    /// The frame's uniforms. `lighting` must fit the pipelines' shape, as the renderers'
    /// constructors promise their callers.
    pub fn write(&self, queue: &wgpu::Queue, frame: &GeometryUniform, lighting: &crate::lighting::Lighting) {
        debug_assert!(self.shape.fits(lighting), "{:?} drawn by pipelines made for {:?}", lighting, self.shape);
        queue.write_buffer(&self.frame, 0, bytemuck::bytes_of(frame));
        queue.write_buffer(&self.lighting, 0, bytemuck::bytes_of(&lighting.uniform()));
    }
}

/// What differs between the geometry pipelines.
pub(crate) struct PipelineSpec<'a> {
    pub label: &'a str,
    /// Bind groups after the frame's (group 0): the lines' and tubes' page of clusters.
    pub groups: &'a [&'a wgpu::BindGroupLayout],
    pub module: &'a wgpu::ShaderModule,
    pub vertex: &'a str,
    pub fragment: &'a str,
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    pub topology: wgpu::PrimitiveTopology,
    /// Also write the `octants` target (the fragment entry returns `GBufferOctants`).
    pub octants: bool,
    /// The module's `override` constants, for both stages.
    pub constants: &'a [(&'a str, f64)],
}

/// A render pipeline writing the G-buffer (depth test `Less`, depth written), compiled for the
/// lighting shape of `bindings`.
pub(crate) fn pipeline(device: &wgpu::Device, bindings: &GeometryBindings, spec: PipelineSpec) -> wgpu::RenderPipeline {
    pipeline_writing(device, bindings, spec, wgpu::CompareFunction::Less, wgpu::ColorWrites::ALL)
}

/// [`pipeline`] with the depth test `compare` and the G-buffer's channels `writes` (a pass that
/// resolves a visibility buffer: every pixel's nearest fragment known, or its depth alone).
pub(crate) fn pipeline_writing(
    device: &wgpu::Device,
    bindings: &GeometryBindings,
    spec: PipelineSpec,
    compare: wgpu::CompareFunction,
    writes: wgpu::ColorWrites,
) -> wgpu::RenderPipeline {
    let layout = &bindings.layout;
    let constants: Vec<_> = spec.constants.iter().copied().chain(bindings.shape.constants()).collect();
    let color_target = |format| Some(wgpu::ColorTargetState { format, blend: None, write_mask: writes });
    let mut color_targets: Vec<_> = GBUFFER_FORMATS.iter().map(|&format| color_target(format)).collect();
    if spec.octants {
        color_targets.push(color_target(targets::OCTANTS_FORMAT));
    }
    let groups: Vec<Option<&wgpu::BindGroupLayout>> =
        std::iter::once(layout).chain(spec.groups.iter().copied()).map(Some).collect();
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(spec.label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(spec.label),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: spec.module,
            entry_point: Some(spec.vertex),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            buffers: spec.buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: spec.topology,
            // Index strips end at u32::MAX (the earlier strip's alternating strip).
            strip_index_format: (spec.topology == wgpu::PrimitiveTopology::TriangleStrip)
                .then_some(wgpu::IndexFormat::Uint32),
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: targets::DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: spec.module,
            entry_point: Some(spec.fragment),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            targets: &color_targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// How a geometry pass starts on the G-buffer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Load {
    /// The frame's first writer: color to this background (linear RGB), ND to background, zoom,
    /// specular and octants to 0, depth to 1.
    Clear([f32; 3]),
    /// The frame's first writer over a depth already written (a host's:
    /// [`crate::passes::seed_depth`]): the colors cleared as [`Load::Clear`] does, the depth kept.
    ClearOverDepth([f32; 3]),
    /// Draw over what earlier passes wrote.
    Keep,
}

/// Clears the G-buffer of `targets` to `background` ([`Load::Clear`]'s values): what a frame
/// without opaque geometry starts from.
pub fn clear(encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, background: [f32; 3]) {
    let load = Load::Clear(background);
    drop(begin(encoder, "lineao::gbuffer::clear", targets, load, targets.octants.is_some(), None));
}

/// Begins a render pass over the G-buffer of `targets` (with `octants` when asked and present).
pub(crate) fn begin<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    targets: &FrameTargets,
    load: Load,
    octants: bool,
    span: Option<Span>,
) -> wgpu::RenderPass<'e> {
    let ops = |clear: [f64; 4]| wgpu::Operations {
        load: match load {
            Load::Clear(_) | Load::ClearOverDepth(_) => {
                wgpu::LoadOp::Clear(wgpu::Color { r: clear[0], g: clear[1], b: clear[2], a: clear[3] })
            }
            Load::Keep => wgpu::LoadOp::Load,
        },
        store: wgpu::StoreOp::Store,
    };
    let attachment = |view, clear| {
        Some(wgpu::RenderPassColorAttachment { view, depth_slice: None, resolve_target: None, ops: ops(clear) })
    };
    let [r, g, b] = match load {
        Load::Clear(background) | Load::ClearOverDepth(background) => background.map(f64::from),
        Load::Keep => [0.0; 3],
    };
    let mut color_attachments = vec![
        attachment(&targets.color.view, [r, g, b, 1.0]),
        attachment(&targets.nd[0].view, [0.0, 0.0, 0.0, 1.0]),
        attachment(&targets.zoom.view, [0.0; 4]),
        attachment(&targets.specular.view, [0.0; 4]),
    ];
    if let (true, Some(target)) = (octants, &targets.octants) {
        color_attachments.push(attachment(&target.view, [0.0; 4]));
    }
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &color_attachments,
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &targets.depth.view,
            depth_ops: Some(wgpu::Operations {
                load: match load {
                    Load::Clear(_) => wgpu::LoadOp::Clear(1.0),
                    Load::ClearOverDepth(_) | Load::Keep => wgpu::LoadOp::Load,
                },
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: timing::render_writes(span),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        GeometryUniform,
        "shared/geometry.wgsl",
        "GeometryUniform",
        [
            view,
            proj,
            inv_proj,
            constant_color,
            viewport,
            near,
            far,
            f_px,
            zoom_unit,
            line_width_px,
            orthographic,
            color_mode,
            tube_radius,
            ndc_per_px,
            scalar_range,
            slab_plane,
            slab_half,
            colormap
        ]
    );
}
