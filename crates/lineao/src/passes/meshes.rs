//! Context surfaces: triangle meshes (a brain hull, a wing) rendered into the same G-buffer as
//! the lines or tubes, after them, so that surface and tracts occlude each other and LineAO, VO
//! and SSAO see both (`shaders/meshes.wgsl`). Phong lighting as for tubes; the interpolated
//! normal turned toward the eye (two-sided), no culling.

use crate::Error;
use crate::camera::{Bounds, FrameView};
use crate::gbuffer::{self, GeometryBindings, GeometryUniform, Load, PipelineSpec};
use crate::lighting::{Lighting, LightingShape};
use crate::settings::LineColor;
use crate::targets::FrameTargets;
use crate::timing::Span;

/// One vertex. Keep in sync with `MeshVertex` in `shaders/meshes.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MeshVertex {
    /// Position, world units.
    pub position: [f32; 3],
    /// Unit normal.
    pub normal: [f32; 3],
}

/// [`MeshVertex`] as the pipeline reads it.
const ATTRIBUTES: [wgpu::VertexAttribute; 2] = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];

/// An indexed triangle mesh on the GPU.
pub struct MeshGeometry {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
    /// Bounding sphere of the vertices.
    pub bounds: Option<Bounds>,
}

impl MeshGeometry {
    /// Uploads triangles `indices` (three per triangle) over `positions` with one unit `normals`
    /// entry per position (world units).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        indices: &[u32],
    ) -> Result<MeshGeometry, Error> {
        let bad = |what: String| Err(Error::InvalidGeometry(what));
        if normals.len() != positions.len() {
            return bad(format!("{} normals for {} positions", normals.len(), positions.len()));
        }
        if !indices.len().is_multiple_of(3) {
            return bad(format!("{} indices: not three per triangle", indices.len()));
        }
        if let Some(&i) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return bad(format!("index {i} of {} positions", positions.len()));
        }
        let vertices: Vec<MeshVertex> =
            positions.iter().zip(normals).map(|(&position, &normal)| MeshVertex { position, normal }).collect();
        let bytes = (vertices.len() * std::mem::size_of::<MeshVertex>()).max(indices.len() * 4) as u64;
        if bytes > device.limits().max_buffer_size {
            let max = device.limits().max_buffer_size;
            let message = format!("a mesh of {bytes} bytes exceeds the device's {max} byte buffers");
            return Err(Error::TooLarge { limit: crate::Limit::BufferSize, value: bytes, max, message });
        }
        let upload = |label, usage, contents: &[u8]| {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (contents.len() as u64).max(4),
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            queue.write_buffer(&buffer, 0, contents);
            buffer
        };
        Ok(MeshGeometry {
            vertices: upload(
                "lineao::MeshGeometry::vertices",
                wgpu::BufferUsages::VERTEX,
                bytemuck::cast_slice(&vertices),
            ),
            indices: upload("lineao::MeshGeometry::indices", wgpu::BufferUsages::INDEX, bytemuck::cast_slice(indices)),
            count: indices.len() as u32,
            bounds: Bounds::of_points(positions),
        })
    }
}

/// Renders [`MeshGeometry`] into the G-buffer of [`FrameTargets`].
pub struct MeshRenderer {
    pipeline: wgpu::RenderPipeline,
    octants: bool,
    bindings: GeometryBindings,
}

impl MeshRenderer {
    /// With `octants`, targets that have an `octants` texture get full visibility where a
    /// surface is ([`crate::passes::volume_ao`]: surfaces are not in the lines' volume). Its
    /// pipeline is compiled for lightings of `shape` ([`LightingShape::ANY`] for every one):
    /// each [`MeshRenderer::prepare`] must give one.
    pub fn new(device: &wgpu::Device, octants: bool, shape: LightingShape) -> MeshRenderer {
        let bindings = GeometryBindings::new(device, "lineao::MeshRenderer::bindings", shape);
        let module = crate::shader::module(device, "meshes.wgsl");
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<MeshVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &ATTRIBUTES,
        })];
        let pipeline = gbuffer::pipeline(
            device,
            &bindings,
            PipelineSpec {
                groups: &[],
                label: "lineao::MeshRenderer::pipeline",
                module: &module,
                vertex: "vs_mesh",
                fragment: if octants { "fs_mesh_octants" } else { "fs_mesh" },
                buffers: &buffers,
                topology: wgpu::PrimitiveTopology::TriangleList,
                octants,
                constants: &[],
            },
        );
        MeshRenderer { pipeline, octants, bindings }
    }

    /// Whether this renderer writes the `octants` target.
    pub fn writes_octants(&self) -> bool {
        self.octants
    }

    /// The lighting its pipelines are compiled for.
    pub fn lighting_shape(&self) -> LightingShape {
        self.bindings.shape
    }

    /// `color`: the surfaces' linear RGB.
    pub fn prepare(&self, queue: &wgpu::Queue, view: &FrameView, color: [f32; 3], lighting: &Lighting) {
        self.bindings.write(queue, &GeometryUniform::new(view, LineColor::Constant(color), 0.0, 0.0), lighting);
    }

    /// Draws `meshes` into the G-buffer, over earlier passes or clearing it first (`load`),
    /// timed into `span` when given.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        meshes: &[&MeshGeometry],
        load: Load,
        span: Option<Span>,
    ) {
        let octants = self.octants && targets.octants.is_some();
        let mut pass = gbuffer::begin(encoder, "lineao::MeshRenderer", targets, load, octants, span);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bindings.group, &[]);
        for mesh in meshes {
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..mesh.count, 0, 0..1);
        }
    }
}

#[cfg(test)]
#[test]
fn the_mesh_vertex_is_what_meshes_wgsl_reads() {
    crate::shader::assert_vertex_layout!(MeshVertex, "meshes.wgsl", "MeshVertex", ATTRIBUTES, [position, normal]);
}
