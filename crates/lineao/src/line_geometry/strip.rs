//! The strip lineao drew before clusters, kept as the baseline the compact path is tested and
//! measured against (feature `reference`): every point twice (left, right) in a vertex buffer
//! with its tangent as snorm16, 20 bytes a vertex, 40 a point; consecutive polylines joined by
//! two repeated vertices (zero-area triangles), the whole geometry one draw per buffer; and the
//! alternating index strip over it (one side per point where a point stays within the
//! tolerance of its neighbours' chord and turns its tangent by at most 20°, both sides at a
//! run's ends), 4 more bytes a point. `lineao bench` times it as `lines-strip`; the tests hold
//! the clusters' G-buffer against its.

use glam::Vec3;

use super::clusters::{deviation, runs, vertex_tangent};
use super::{MAX_ALTERNATING_WIDTH_PX, MAX_TOLERANCE_PX, validate_offsets};
use crate::Error;
use crate::camera::{Bounds, FrameView};
use crate::gbuffer::{self, GeometryBindings, GeometryUniform, Load, PipelineSpec};
use crate::lighting::LightingShape;
use crate::settings::ChainSettings;
use crate::targets::FrameTargets;
use crate::timing::Span;

/// One vertex of the strip. Keep in sync with `StripVertex` in `shaders/strip.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
struct StripVertex {
    position: [f32; 3],
    /// Unit world-space tangent (xyz) as snorm16; w: the side, +1 left, −1 right (snorm16).
    tangent: [i16; 4],
}

const VERTEX_SIZE: u64 = std::mem::size_of::<StripVertex>() as u64;
/// [`StripVertex`] as the pipeline reads it.
const ATTRIBUTES: [wgpu::VertexAttribute; 2] = wgpu::vertex_attr_array![0 => Float32x3, 1 => Snorm16x4];
/// τ over the bounding radius: a view that shows the whole bounding sphere across 2 000 px
/// covers about 2 000 / (2 radius) px per world unit, so τ is about 0.12 px there.
const TOLERANCE_PER_RADIUS: f32 = 1.0 / 8192.0;
/// Ends an index strip; the next index starts a new one.
const RESTART: u32 = u32::MAX;

fn snorm16(v: f32) -> i16 {
    (v.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

/// Polylines as the earlier strip, in one vertex buffer and one index buffer.
pub struct StripGeometry {
    vertices: wgpu::Buffer,
    count: u32,
    alternating: wgpu::Buffer,
    indices: u32,
    tolerance: f32,
    /// The box of its points.
    pub bounds: Option<Bounds>,
}

impl StripGeometry {
    /// The strip of polylines `positions[offsets[i]..offsets[i + 1]]`, cut at non-finite points.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
    ) -> Result<StripGeometry, Error> {
        use wgpu::util::DeviceExt;
        validate_offsets(offsets, positions.len())?;
        let bounds = Bounds::of_points(positions);
        // A point keeps both sides where it lies farther than τ, a fixed share of the
        // bounding radius, from its neighbours' chord (or turns sharply).
        let tolerance = bounds.map_or(0.0, |b| b.radius * TOLERANCE_PER_RADIUS);
        let mut vertices: Vec<StripVertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        for (_, run) in runs(positions, offsets) {
            let tangents: Vec<Vec3> = (0..run.len()).map(|k| vertex_tangent(run, k)).collect();
            let vertex = |k: usize, side: i16| {
                let t = tangents[k];
                StripVertex { position: run[k], tangent: [snorm16(t.x), snorm16(t.y), snorm16(t.z), side * 32767] }
            };
            // Two repeated vertices join this run to the previous one: zero-area triangles.
            if let Some(&last) = vertices.last() {
                vertices.push(last);
                vertices.push(vertex(0, 1));
            }
            let first = vertices.len() as u32;
            for k in 0..run.len() {
                vertices.push(vertex(k, 1));
                vertices.push(vertex(k, -1));
            }
            if !indices.is_empty() {
                indices.push(RESTART);
            }
            // Sides by turns: after both sides of a point the same side comes next.
            let mut left = true;
            let mut side = |k: usize, out: &mut Vec<u32>| {
                out.push(first + 2 * k as u32 + !left as u32);
                left = !left;
            };
            for k in 0..run.len() {
                side(k, &mut indices);
                if k == 0 || k + 1 == run.len() || deviation(run, &tangents, k) > tolerance {
                    side(k, &mut indices);
                }
            }
        }
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let padded = |bytes: &[u8]| if bytes.is_empty() { vec![0u8; 4] } else { bytes.to_vec() };
        let _ = queue;
        Ok(StripGeometry {
            vertices: buffer(
                "lineao::StripGeometry::vertices",
                &padded(bytemuck::cast_slice(&vertices)),
                wgpu::BufferUsages::VERTEX,
            ),
            count: vertices.len() as u32,
            alternating: buffer(
                "lineao::StripGeometry::alternating",
                &padded(bytemuck::cast_slice(&indices)),
                wgpu::BufferUsages::INDEX,
            ),
            indices: indices.len() as u32,
            tolerance,
            bounds,
        })
    }

    /// Bytes of its buffers.
    pub fn gpu_bytes(&self) -> u64 {
        self.vertices.size() + self.alternating.size()
    }
}

/// Draws a [`StripGeometry`] into the G-buffer: the line renderer of earlier versions.
pub struct StripRenderer {
    pipeline: wgpu::RenderPipeline,
    bindings: GeometryBindings,
    /// The frame's most pixels per world unit where the alternating strip may be drawn.
    px_per_world: f32,
    /// Always the full strip (as [`crate::passes::lines::LineStyle::FullStrip`]).
    full: bool,
}

impl StripRenderer {
    /// The renderer of earlier versions: the alternating strip where it stays within half a
    /// pixel of the full one, or with `full` always the full strip.
    /// Compiled for lightings of `shape`, as [`crate::passes::lines::LineRenderer::with_slab`].
    pub fn new(device: &wgpu::Device, full: bool, shape: LightingShape) -> StripRenderer {
        let bindings = GeometryBindings::new(device, "lineao::StripRenderer::bindings", shape);
        let module = crate::shader::module(device, "strip.wgsl");
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: VERTEX_SIZE,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &ATTRIBUTES,
        })];
        let pipeline = gbuffer::pipeline(
            device,
            &bindings,
            PipelineSpec {
                label: "lineao::StripRenderer::pipeline",
                groups: &[],
                module: &module,
                vertex: "vs_strip",
                fragment: "fs_main",
                buffers: &buffers,
                topology: wgpu::PrimitiveTopology::TriangleStrip,
                octants: false,
                constants: &[],
            },
        );
        StripRenderer { pipeline, bindings, px_per_world: f32::INFINITY, full }
    }

    /// Writes this frame's uniform.
    pub fn prepare(&mut self, queue: &wgpu::Queue, view: &FrameView, settings: &ChainSettings) {
        let uniform = GeometryUniform::new(view, settings.line_color, settings.line_width_px, 0.0);
        self.bindings.write(queue, &uniform, &settings.lighting);
        self.px_per_world = if settings.line_width_px <= MAX_ALTERNATING_WIDTH_PX {
            crate::passes::lines::max_px_per_world(view)
        } else {
            f32::INFINITY
        };
    }

    /// Draws `geometry`, as the alternating strip where that stays within half a pixel.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &StripGeometry,
        load: Load,
        span: Option<Span>,
    ) {
        let mut pass = gbuffer::begin(encoder, "lineao::StripRenderer", targets, load, false, span);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bindings.group, &[]);
        pass.set_vertex_buffer(0, geometry.vertices.slice(..));
        if !self.full && geometry.tolerance * self.px_per_world <= MAX_TOLERANCE_PX {
            pass.set_index_buffer(geometry.alternating.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..geometry.indices, 0, 0..1);
        } else {
            pass.draw(0..geometry.count, 0..1);
        }
    }
}

#[cfg(test)]
#[test]
fn the_strip_vertex_is_what_strip_wgsl_reads() {
    crate::shader::assert_vertex_layout!(StripVertex, "strip.wgsl", "StripVertex", ATTRIBUTES, [position, tangent]);
}
