//! Line renderer: polylines at a fixed pixel width, the way LineAO expects them ("the intrinsic
//! fixed line width on screen", paper §2–3). wgpu has no wide lines, so each segment is an
//! instanced 4-vertex quad expanded in the vertex shader (see `shaders/lines.wgsl`).
//!
//! The point buffer holds each vertex once with its tangent (central difference, snorm16) and a
//! flag telling whether a segment starts there. It is bound twice, the second binding one point
//! further on, so instance k is the segment (k, k + 1). Tractograms larger than one buffer are
//! split into chunks that overlap by one point.
//!
//! Per pixel it writes the G-buffer of CONTRACT.md: base color, the ND map (n = (T × C) × T
//! normalized, facing the eye; normalized linear depth), the zoom map, the illuminated-lines
//! specular and hardware depth.

use glam::Vec3;
use wgpu::util::DeviceExt;

use crate::Error;
use crate::binding::{self, Slot};
use crate::camera::{Bounds, FrameView};
use crate::lighting::{Lighting, LightingUniform};
use crate::settings::LineColor;
use crate::targets::{self, FrameTargets};
use crate::timing::{self, Span};

/// One vertex of the point buffer. Keep in sync with `SegmentIn` in `shaders/lines.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LinePoint {
    pub position: [f32; 3],
    /// Unit world-space tangent (xyz) as snorm16; w = 32767 when a segment starts here.
    pub tangent: [i16; 4],
}

const POINT_SIZE: u64 = std::mem::size_of::<LinePoint>() as u64;

/// Default upper bound of one vertex buffer: below every adapter's buffer limit that can hold
/// the paper's 11 M-vertex tractogram in a handful of chunks.
pub const DEFAULT_CHUNK_BYTES: u64 = 128 << 20;

fn snorm16(v: f32) -> i16 {
    (v.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

/// Checks that `offsets` (N + 1 entries, first 0, non-decreasing, last = vertex count) describe
/// polylines over `vertices` points.
pub fn validate_offsets(offsets: &[u64], vertices: usize) -> Result<(), Error> {
    let bad = |what: String| Err(Error::InvalidGeometry(what));
    match (offsets.first(), offsets.last()) {
        (None, _) => return bad("offsets must have N + 1 entries, got none".into()),
        (Some(&first), _) if first != 0 => return bad(format!("offsets must start at 0, got {first}")),
        (_, Some(&last)) if last != vertices as u64 => {
            return bad(format!("offsets must end at the vertex count {vertices}, got {last}"));
        }
        _ => {}
    }
    if let Some(i) = offsets.windows(2).position(|w| w[1] < w[0]) {
        return bad(format!("offsets decrease at streamline {i}: {} then {}", offsets[i], offsets[i + 1]));
    }
    Ok(())
}

/// The point buffer contents for polylines `positions[offsets[i]..offsets[i + 1]]`.
pub fn line_points(positions: &[[f32; 3]], offsets: &[u64]) -> Result<Vec<LinePoint>, Error> {
    validate_offsets(offsets, positions.len())?;
    let mut points = Vec::with_capacity(positions.len());
    for range in offsets.windows(2) {
        let line = &positions[range[0] as usize..range[1] as usize];
        let at = |k: usize| Vec3::from_array(line[k]);
        for k in 0..line.len() {
            let prev = at(k.saturating_sub(1));
            let next = at((k + 1).min(line.len() - 1));
            let tangent = [next - prev, next - at(k), at(k) - prev]
                .into_iter()
                .map(|t| t.normalize_or_zero())
                .find(|t| t != &Vec3::ZERO && t.is_finite())
                .unwrap_or(Vec3::X);
            let starts_segment = k + 1 < line.len() && at(k).is_finite() && at(k + 1).is_finite();
            points.push(LinePoint {
                position: line[k],
                tangent: [
                    snorm16(tangent.x),
                    snorm16(tangent.y),
                    snorm16(tangent.z),
                    if starts_segment { 32767 } else { 0 },
                ],
            });
        }
    }
    Ok(points)
}

/// Polylines uploaded to the GPU.
pub struct LineGeometry {
    chunks: Vec<(wgpu::Buffer, u32)>,
    /// Bounding sphere of the finite points; `None` when there are none.
    pub bounds: Option<Bounds>,
    pub vertices: usize,
    pub streamlines: usize,
}

impl LineGeometry {
    /// Uploads polylines `positions[offsets[i]..offsets[i + 1]]` (world units).
    pub fn new(device: &wgpu::Device, positions: &[[f32; 3]], offsets: &[u64]) -> Result<LineGeometry, Error> {
        Self::with_chunk_bytes(device, positions, offsets, DEFAULT_CHUNK_BYTES.min(device.limits().max_buffer_size))
    }

    /// As [`LineGeometry::new`], with vertex buffers of at most `chunk_bytes` each.
    pub fn with_chunk_bytes(
        device: &wgpu::Device,
        positions: &[[f32; 3]],
        offsets: &[u64],
        chunk_bytes: u64,
    ) -> Result<LineGeometry, Error> {
        let points = line_points(positions, offsets)?;
        let per_chunk = (chunk_bytes / POINT_SIZE).max(2) as usize;
        let mut chunks = Vec::new();
        let mut start = 0;
        while start + 1 < points.len() {
            let end = (start + per_chunk).min(points.len());
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("lineao::LineGeometry::points"),
                contents: bytemuck::cast_slice(&points[start..end]),
                usage: wgpu::BufferUsages::VERTEX,
            });
            chunks.push((buffer, (end - start) as u32));
            start = end - 1;
        }
        Ok(LineGeometry {
            chunks,
            bounds: Bounds::of_points(positions),
            vertices: positions.len(),
            streamlines: offsets.len() - 1,
        })
    }

    /// Number of vertex buffers the points were split into.
    pub fn chunk_count(&self) -> usize {
        self.chunks.len()
    }
}

/// Keep in sync with `LineUniform` in `shaders/lines.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LineUniform {
    pub view: [[f32; 4]; 4],
    pub proj: [[f32; 4]; 4],
    pub constant_color: [f32; 4],
    pub viewport: [f32; 2],
    pub near: f32,
    pub far: f32,
    pub f_px: f32,
    pub zoom_unit: f32,
    pub line_width_px: f32,
    pub orthographic: u32,
    pub color_mode: u32,
    pub _pad: [u32; 3],
}

/// How segments are rasterized.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineStyle {
    /// Screen-aligned quads of the chain's line width (the paper's fixed-width lines).
    #[default]
    Quads,
    /// The rasterizer's native 1-pixel lines (`LineList`), ignoring the line width: the cheapest
    /// way to put segments on screen, and the baseline `lineao bench` measures quads against.
    Native1px,
}

/// Renders [`LineGeometry`] into the G-buffer of [`FrameTargets`].
pub struct LineRenderer {
    style: LineStyle,
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    lighting: wgpu::Buffer,
    group: wgpu::BindGroup,
}

impl LineRenderer {
    /// The renderer of fixed-width lines.
    pub fn new(device: &wgpu::Device) -> LineRenderer {
        Self::with_style(device, LineStyle::Quads)
    }

    pub fn with_style(device: &wgpu::Device, style: LineStyle) -> LineRenderer {
        let layout = binding::layout(
            device,
            "lineao::LineRenderer::layout",
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            &[Slot::Uniform, Slot::Uniform],
        );
        let uniform = binding::uniform_buffer::<LineUniform>(device, "lineao::LineRenderer::uniform");
        let lighting = binding::uniform_buffer::<LightingUniform>(device, "lineao::LineRenderer::lighting");
        let group = binding::group(
            device,
            "lineao::LineRenderer::group",
            &layout,
            &[uniform.as_entire_binding(), lighting.as_entire_binding()],
        );
        let module = crate::shader::module(device, "lines.wgsl");
        let attributes = [
            wgpu::vertex_attr_array![0 => Float32x3, 1 => Snorm16x4],
            wgpu::vertex_attr_array![2 => Float32x3, 3 => Snorm16x4],
        ];
        let buffers = attributes.each_ref().map(|attributes| {
            Some(wgpu::VertexBufferLayout {
                array_stride: POINT_SIZE,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes,
            })
        });
        let target = |format| Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("lineao::LineRenderer::pipeline"),
            layout: Some(&binding::pipeline_layout(device, "lineao::LineRenderer::pipeline_layout", &layout)),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(match style {
                    LineStyle::Quads => "vs_main",
                    LineStyle::Native1px => "vs_native",
                }),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology: match style {
                    LineStyle::Quads => wgpu::PrimitiveTopology::TriangleStrip,
                    LineStyle::Native1px => wgpu::PrimitiveTopology::LineList,
                },
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: targets::DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[
                    target(targets::COLOR_FORMAT),
                    target(targets::ND_FORMAT),
                    target(targets::ZOOM_FORMAT),
                    target(targets::SPECULAR_FORMAT),
                ],
            }),
            multiview_mask: None,
            cache: None,
        });
        LineRenderer { style, pipeline, uniform, lighting, group }
    }

    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        view: &FrameView,
        line_width_px: f32,
        color: LineColor,
        lighting: &Lighting,
    ) {
        let (w, h) = view.banded_size();
        let (color_mode, constant) = match color {
            LineColor::Tangent => (0, [0.0; 3]),
            LineColor::Constant(rgb) => (1, rgb),
        };
        let uniform = LineUniform {
            view: view.view.to_cols_array_2d(),
            proj: view.proj.to_cols_array_2d(),
            constant_color: [constant[0], constant[1], constant[2], 1.0],
            viewport: [w as f32, h as f32],
            near: view.near,
            far: view.far,
            f_px: view.f_px,
            zoom_unit: view.zoom_unit,
            line_width_px,
            orthographic: view.orthographic as u32,
            color_mode,
            _pad: [0; 3],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        queue.write_buffer(&self.lighting, 0, bytemuck::bytes_of(&lighting.uniform()));
    }

    /// Clears the G-buffer (color to `background`, ND to background, zoom and specular to 0,
    /// depth to 1) and draws `geometry`, timed into `span` when given.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        background: [f32; 3],
        span: Option<Span>,
    ) {
        let clear = |r: f64, g: f64, b: f64, a: f64| wgpu::Operations {
            load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a }),
            store: wgpu::StoreOp::Store,
        };
        let attachment =
            |view, ops| Some(wgpu::RenderPassColorAttachment { view, depth_slice: None, resolve_target: None, ops });
        let [r, g, b] = background.map(f64::from);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lineao::LineRenderer"),
            color_attachments: &[
                attachment(&targets.color.view, clear(r, g, b, 1.0)),
                attachment(&targets.nd[0].view, clear(0.0, 0.0, 0.0, 1.0)),
                attachment(&targets.zoom.view, clear(0.0, 0.0, 0.0, 0.0)),
                attachment(&targets.specular.view, clear(0.0, 0.0, 0.0, 0.0)),
            ],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.depth.view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: timing::render_writes(span),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        let corners = match self.style {
            LineStyle::Quads => 4,
            LineStyle::Native1px => 2,
        };
        for (buffer, points) in &geometry.chunks {
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.set_vertex_buffer(1, buffer.slice(POINT_SIZE..));
            pass.draw(0..corners, 0..points - 1);
        }
    }
}
