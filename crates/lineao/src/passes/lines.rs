//! Line renderer: polylines at a fixed pixel width, the way LineAO expects them ("the intrinsic
//! fixed line width on screen", paper §2–3). wgpu has no wide lines, so each polyline is one
//! triangle strip whose vertices the vertex shader pushes half a line width to either side of
//! the curve (see `shaders/lines.wgsl`).
//!
//! The strip buffer holds every point twice (left, right) with its tangent (central difference,
//! snorm16); the sign of tangent.w says the side. Consecutive polylines are joined by two
//! repeated vertices, which make zero-area triangles the rasterizer drops, so a whole tractogram
//! is one draw per buffer. Offsetting along the *vertex* tangent makes consecutive segments share
//! their join corners exactly: joins without gaps or overlaps. Polylines are split at
//! non-finite points. Tractograms larger than one buffer are split into chunks that overlap by
//! two vertices (every triangle of the strip lies in one chunk).
//!
//! Measured with `lineao bench` (1 M vertices, 1280 × 1024, lavapipe): the strip is 1.6× faster
//! than one instanced 4-vertex quad per segment, whose per-instance cost dominated.
//!
//! Per pixel it writes the G-buffer of CONTRACT.md: base color, the ND map (n = (T × C) × T
//! normalized, facing the eye; normalized linear depth), the zoom map, the illuminated-lines
//! specular and hardware depth.

use glam::Vec3;

use crate::Error;
use crate::binding::{self, Slot};
use crate::camera::{Bounds, FrameView};
use crate::lighting::{Lighting, LightingUniform};
use crate::settings::LineColor;
use crate::targets::{self, FrameTargets};
use crate::timing::{self, Span};

/// One vertex of the strip buffer. Keep in sync with `StripVertex` in `shaders/lines.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LinePoint {
    pub position: [f32; 3],
    /// Unit world-space tangent (xyz) as snorm16. w: the side, +1 left or −1 right as ±32767
    /// when a segment to the next point starts here (left vertices only), ±16384 otherwise.
    pub tangent: [i16; 4],
}

const SEGMENT_STARTS: i16 = 32767;
const NO_SEGMENT: i16 = 16384;

impl LinePoint {
    fn with_side(self, w: i16) -> LinePoint {
        LinePoint { tangent: [self.tangent[0], self.tangent[1], self.tangent[2], w], ..self }
    }
}

const POINT_SIZE: u64 = std::mem::size_of::<LinePoint>() as u64;

/// Default upper bound of one vertex buffer: below every adapter's buffer limit, and few
/// enough chunks for the paper's 11 M-vertex tractogram (440 MB of strip).
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

/// The points of one polyline with their tangents (central differences), w = 32767 where a
/// segment to the next point starts (both finite), appended to `out`.
fn polyline_points(line: &[[f32; 3]], out: &mut Vec<LinePoint>) {
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
        out.push(LinePoint {
            position: line[k],
            tangent: [
                snorm16(tangent.x),
                snorm16(tangent.y),
                snorm16(tangent.z),
                if starts_segment { SEGMENT_STARTS } else { 0 },
            ],
        });
    }
}

/// How [`LineGeometry`] is uploaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GeometryOptions {
    /// Upper bound of one vertex buffer in bytes (further capped by the device's limit).
    pub chunk_bytes: u64,
    /// Also upload the index buffers [`LineStyle::Native1px`] draws from (8 bytes per segment).
    pub native_lines: bool,
}

impl Default for GeometryOptions {
    fn default() -> Self {
        GeometryOptions { chunk_bytes: DEFAULT_CHUNK_BYTES, native_lines: false }
    }
}

/// One vertex buffer of the strip and, on request, the segments of native lines within it and
/// the vertices' attributes.
struct Chunk {
    vertices: wgpu::Buffer,
    count: u32,
    segments: Option<(wgpu::Buffer, u32)>,
    attributes: Option<wgpu::Buffer>,
}

/// Polylines uploaded to the GPU.
pub struct LineGeometry {
    chunks: Vec<Chunk>,
    /// Strip vertices per chunk at most (even).
    per_chunk: usize,
    /// Bounding sphere of the finite points; `None` when there are none.
    pub bounds: Option<Bounds>,
    pub vertices: usize,
    pub streamlines: usize,
}

/// The strip vertices of polylines `positions[offsets[i]..offsets[i + 1]]` (see the module
/// documentation), streamed to `emit` with the index of the point each one comes from; memory
/// beyond the longest polyline is never held.
fn strip_vertices(positions: &[[f32; 3]], offsets: &[u64], mut emit: impl FnMut(LinePoint, usize)) {
    let mut points = Vec::new();
    let mut previous: Option<(LinePoint, usize)> = None;
    for range in offsets.windows(2) {
        let first = range[0] as usize;
        points.clear();
        polyline_points(&positions[first..range[1] as usize], &mut points);
        // Runs of points joined by segments (w = 32767 on all but a run's last point).
        let mut start = 0;
        while start < points.len() {
            let end = points[start..]
                .iter()
                .position(|p| p.tangent[3] != SEGMENT_STARTS)
                .map_or(points.len(), |k| start + k + 1);
            let run = &points[start..end];
            if run.len() >= 2 {
                if let Some((last, index)) = previous {
                    emit(last, index);
                    emit(run[0].with_side(NO_SEGMENT), first + start);
                }
                for (k, p) in run.iter().enumerate() {
                    emit(p.with_side(if k + 1 < run.len() { SEGMENT_STARTS } else { NO_SEGMENT }), first + start + k);
                    emit(p.with_side(-NO_SEGMENT), first + start + k);
                }
                previous = Some((run[run.len() - 1].with_side(-NO_SEGMENT), first + end - 1));
            }
            start = end;
        }
    }
}

/// Splits a stream of strip vertices into chunks of at most `per_chunk` (even) that overlap by
/// two vertices, so every triangle lies in one chunk; the vertex and attribute streams of one
/// geometry split identically.
struct Chunker<T> {
    per_chunk: usize,
    current: Vec<T>,
}

impl<T: Copy> Chunker<T> {
    fn new(per_chunk: usize, expected: usize) -> Chunker<T> {
        Chunker { per_chunk, current: Vec::with_capacity(per_chunk.min(expected)) }
    }

    fn push(&mut self, value: T, flush: &mut impl FnMut(&[T])) {
        if self.current.len() == self.per_chunk {
            flush(&self.current);
            self.current.drain(..self.per_chunk - 2);
        }
        self.current.push(value);
    }

    /// The last chunk, if it holds a triangle.
    fn finish(self, flush: &mut impl FnMut(&[T])) {
        if self.current.len() >= 3 {
            flush(&self.current);
        }
    }
}

/// Per-vertex data uploaded beside the positions ([`LineGeometry::set_attributes`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct VertexAttributes<'a> {
    /// Visibility of each octant of directions, in [0, 1], indexed as
    /// [`crate::volume::octant_signs`]: object-space AO ([`crate::volume`]), which
    /// [`crate::passes::volume_ao`] turns into occlusion with the pixel's normal. `None`: fully
    /// visible.
    pub octants: Option<&'a [[f32; 8]]>,
}

/// One strip vertex's attributes. Keep in sync with `Attributes` in `shaders/lines.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LineAttributes {
    /// The eight octant visibilities as unorm8.
    pub octants: [u8; 8],
}

const ATTRIBUTE_SIZE: u64 = std::mem::size_of::<LineAttributes>() as u64;

impl LineGeometry {
    /// Uploads polylines `positions[offsets[i]..offsets[i + 1]]` (world units). Waits for the
    /// queue after each buffer so that its staging memory is freed before the next one is made:
    /// peak memory is the strip plus one buffer, not twice the strip.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
    ) -> Result<LineGeometry, Error> {
        Self::with_options(device, queue, positions, offsets, GeometryOptions::default())
    }

    pub fn with_options(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
        options: GeometryOptions,
    ) -> Result<LineGeometry, Error> {
        validate_offsets(offsets, positions.len())?;
        let limit = options.chunk_bytes.min(device.limits().max_buffer_size);
        // Even, so that every chunk starts at an even strip position: a triangle then keeps the
        // vertex order (and so the exact interpolation) it has in one long strip. The attribute
        // stream splits at the same vertices, so its buffers must fit the same count.
        let per_chunk = (limit / POINT_SIZE).max(4) as usize & !1;
        let mut chunks = Vec::new();
        let mut failed = None;
        let mut upload = |vertices: &[LinePoint]| {
            let chunk = Chunk {
                vertices: upload_buffer(
                    device,
                    queue,
                    "lineao::LineGeometry::strip",
                    wgpu::BufferUsages::VERTEX,
                    vertices,
                ),
                count: vertices.len() as u32,
                segments: options.native_lines.then(|| native_segments(device, queue, vertices)),
                attributes: None,
            };
            if let Err(e) = device.poll(wgpu::PollType::wait_indefinitely()) {
                failed.get_or_insert(Error::Gpu(e.to_string()));
            }
            chunks.push(chunk);
        };
        let mut chunker = Chunker::new(per_chunk, 2 * positions.len() + 2 * offsets.len());
        strip_vertices(positions, offsets, |v, _| chunker.push(v, &mut upload));
        chunker.finish(&mut upload);
        if let Some(error) = failed {
            return Err(error);
        }
        Ok(LineGeometry {
            chunks,
            per_chunk,
            bounds: Bounds::of_points(positions),
            vertices: positions.len(),
            streamlines: offsets.len() - 1,
        })
    }

    /// Uploads per-vertex `attributes` for the polylines this geometry was made from (the same
    /// `positions` and `offsets`), replacing earlier ones: object-space AO computed after the
    /// upload, or recomputed with other settings, needs no new strip.
    pub fn set_attributes(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
        attributes: &VertexAttributes,
    ) -> Result<(), Error> {
        validate_offsets(offsets, positions.len())?;
        if positions.len() != self.vertices || offsets.len() != self.streamlines + 1 {
            return Err(Error::InvalidGeometry(format!(
                "attributes for {} vertices in {} streamlines, but the geometry has {} in {}",
                positions.len(),
                offsets.len() - 1,
                self.vertices,
                self.streamlines
            )));
        }
        if let Some(octants) = attributes.octants
            && octants.len() != positions.len()
        {
            return Err(Error::InvalidGeometry(format!(
                "{} octant visibilities for {} vertices",
                octants.len(),
                positions.len()
            )));
        }
        let unorm = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        let of = |i: usize| LineAttributes { octants: attributes.octants.map_or([255; 8], |o| o[i].map(unorm)) };
        let mut buffers = Vec::with_capacity(self.chunks.len());
        let mut upload = |values: &[LineAttributes]| {
            buffers.push(upload_buffer(
                device,
                queue,
                "lineao::LineGeometry::attributes",
                wgpu::BufferUsages::VERTEX,
                values,
            ));
        };
        // Buffers of the same vertex count as the strip's, at most the strip's bytes.
        let mut chunker = Chunker::new(self.per_chunk, 2 * positions.len() + 2 * offsets.len());
        strip_vertices(positions, offsets, |_, i| chunker.push(of(i), &mut upload));
        chunker.finish(&mut upload);
        if buffers.len() != self.chunks.len() {
            return Err(Error::InvalidGeometry("the polylines differ from the geometry's".into()));
        }
        for (chunk, buffer) in self.chunks.iter_mut().zip(buffers) {
            chunk.attributes = Some(buffer);
        }
        device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(e.to_string()))?;
        Ok(())
    }

    /// Whether [`LineGeometry::set_attributes`] gave every chunk attributes.
    pub fn has_attributes(&self) -> bool {
        self.chunks.iter().all(|c| c.attributes.is_some())
    }

    /// Number of vertex buffers the strip was split into.
    pub fn chunk_count(&self) -> usize {
        self.chunks.len()
    }
}

/// Index pairs (left vertex of a point, left vertex of the next) of the segments that lie
/// within `vertices`: a segment across a chunk border is in the next chunk, which repeats the
/// last two vertices.
fn native_segments(device: &wgpu::Device, queue: &wgpu::Queue, vertices: &[LinePoint]) -> (wgpu::Buffer, u32) {
    let indices: Vec<u32> = (0..vertices.len().saturating_sub(2))
        .filter(|&i| vertices[i].tangent[3] == SEGMENT_STARTS)
        .flat_map(|i| [i as u32, i as u32 + 2])
        .collect();
    let contents = if indices.is_empty() { &[0u32, 0][..] } else { &indices };
    let buffer = upload_buffer(device, queue, "lineao::LineGeometry::segments", wgpu::BufferUsages::INDEX, contents);
    (buffer, indices.len() as u32)
}

/// A buffer of `usage` holding `contents`, written through the queue and submitted.
fn upload_buffer<T: bytemuck::Pod>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    usage: wgpu::BufferUsages,
    contents: &[T],
) -> wgpu::Buffer {
    let bytes: &[u8] = bytemuck::cast_slice(contents);
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.len() as u64,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&buffer, 0, bytes);
    queue.submit([]);
    buffer
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
    /// The rasterizer's native 1-pixel lines (an indexed `LineList` over the same vertices),
    /// ignoring the line width: the cheapest way to put segments on screen, and the baseline
    /// `lineao bench` measures quads against. Needs geometry uploaded with
    /// [`GeometryOptions::native_lines`]; without it nothing is drawn.
    Native1px,
}

/// Renders [`LineGeometry`] into the G-buffer of [`FrameTargets`].
pub struct LineRenderer {
    style: LineStyle,
    pipeline: wgpu::RenderPipeline,
    /// Writing `octants` too: from the geometry's attributes, and fully visible for geometry
    /// without them.
    octants: Option<OctantPipelines>,
    uniform: wgpu::Buffer,
    lighting: wgpu::Buffer,
    group: wgpu::BindGroup,
}

struct OctantPipelines {
    attributes: wgpu::RenderPipeline,
    visible: wgpu::RenderPipeline,
}

/// The G-buffer attachments the line pipelines write, in `fs_main`'s order.
const GBUFFER_FORMATS: [wgpu::TextureFormat; 4] =
    [targets::COLOR_FORMAT, targets::ND_FORMAT, targets::ZOOM_FORMAT, targets::SPECULAR_FORMAT];

impl LineRenderer {
    /// The renderer of fixed-width lines.
    pub fn new(device: &wgpu::Device) -> LineRenderer {
        Self::with_style(device, LineStyle::Quads)
    }

    pub fn with_style(device: &wgpu::Device, style: LineStyle) -> LineRenderer {
        Self::with_outputs(device, style, false)
    }

    /// With `octants`, targets that have an `octants` texture also get the geometry's
    /// per-vertex octant visibilities, interpolated ([`crate::passes::volume_ao`]); quads only.
    pub fn with_outputs(device: &wgpu::Device, style: LineStyle, octants: bool) -> LineRenderer {
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
        let pipeline_layout = binding::pipeline_layout(device, "lineao::LineRenderer::pipeline_layout", &layout);
        let point_attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Snorm16x4];
        let octant_attributes = wgpu::vertex_attr_array![2 => Unorm8x4, 3 => Unorm8x4];
        let points = wgpu::VertexBufferLayout {
            array_stride: POINT_SIZE,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &point_attributes,
        };
        let with_attributes = [
            Some(points.clone()),
            Some(wgpu::VertexBufferLayout {
                array_stride: ATTRIBUTE_SIZE,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &octant_attributes,
            }),
        ];
        let topology = match style {
            LineStyle::Quads => wgpu::PrimitiveTopology::TriangleStrip,
            LineStyle::Native1px => wgpu::PrimitiveTopology::LineList,
        };
        let create = |label: &str, vertex: &str, fragment: &str, buffers: &[Option<wgpu::VertexBufferLayout>]| {
            let mut targets: Vec<_> = GBUFFER_FORMATS.iter().map(|&format| color_target(format)).collect();
            if fragment == "fs_octants" {
                targets.push(color_target(targets::OCTANTS_FORMAT));
            }
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vertex),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState { topology, ..Default::default() },
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
                    entry_point: Some(fragment),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let vertex = match style {
            LineStyle::Quads => "vs_main",
            LineStyle::Native1px => "vs_native",
        };
        let pipeline = create("lineao::LineRenderer::pipeline", vertex, "fs_main", &[Some(points.clone())]);
        let octants = (octants && style == LineStyle::Quads).then(|| OctantPipelines {
            attributes: create("lineao::LineRenderer::octants", "vs_octants", "fs_octants", &with_attributes),
            visible: create("lineao::LineRenderer::visible", "vs_visible", "fs_octants", &[Some(points.clone())]),
        });
        LineRenderer { style, pipeline, octants, uniform, lighting, group }
    }

    /// Whether this renderer writes the `octants` target.
    pub fn writes_octants(&self) -> bool {
        self.octants.is_some()
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
        // The octants too when both the pipelines and the target exist.
        let octants = self.octants.as_ref().zip(targets.octants.as_ref());
        let mut color_attachments = vec![
            attachment(&targets.color.view, clear(r, g, b, 1.0)),
            attachment(&targets.nd[0].view, clear(0.0, 0.0, 0.0, 1.0)),
            attachment(&targets.zoom.view, clear(0.0, 0.0, 0.0, 0.0)),
            attachment(&targets.specular.view, clear(0.0, 0.0, 0.0, 0.0)),
        ];
        if let Some((_, target)) = octants {
            color_attachments.push(attachment(&target.view, clear(0.0, 0.0, 0.0, 0.0)));
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lineao::LineRenderer"),
            color_attachments: &color_attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.depth.view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: timing::render_writes(span),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let pipeline = match octants {
            Some((pipelines, _)) if geometry.has_attributes() => &pipelines.attributes,
            Some((pipelines, _)) => &pipelines.visible,
            None => &self.pipeline,
        };
        let attributes = octants.is_some() && geometry.has_attributes();
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        for chunk in &geometry.chunks {
            pass.set_vertex_buffer(0, chunk.vertices.slice(..));
            if let (true, Some(buffer)) = (attributes, &chunk.attributes) {
                pass.set_vertex_buffer(1, buffer.slice(..));
            }
            match (self.style, &chunk.segments) {
                (LineStyle::Quads, _) => pass.draw(0..chunk.count, 0..1),
                (LineStyle::Native1px, Some((indices, count))) => {
                    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..*count, 0, 0..1);
                }
                (LineStyle::Native1px, None) => {}
            }
        }
    }
}

fn color_target(format: wgpu::TextureFormat) -> Option<wgpu::ColorTargetState> {
    Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
}
