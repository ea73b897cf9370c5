//! The ray tracer's scene on the GPU: the ground truth's BVH ([`crate::truth::bvh`]) flattened
//! into storage buffers, built on the CPU and uploaded once per geometry.
//!
//! **View-independent.** A fixed-width line's volume depends on the view (its radius is the
//! line's half-width on screen, (w/2)·(−z_view)/f_px), a tube's on the settings (its radius).
//! So the tree is built over the bare axes — every segment a cone of radius 0 — and the traversal
//! grows each node's box by the largest radius inside it: for lines (w/2)·max(−z_view over the
//! box's corners, near)/f_px, a plane's maximum over a box being at a corner; for tubes the
//! largest tube radius. Camera moves and radius changes then need no rebuild, only new
//! geometry does.
//!
//! **Layout**: one array of 32-bit words, regions in this order (offsets in words):
//!
//! | region    | words                  | content                                                     |
//! |-----------|------------------------|-------------------------------------------------------------|
//! | nodes     | 8 per node             | min xyz (f32), first, max xyz (f32), count: [`Node`]       |
//! | refs      | 1 per primitive        | a segment's first vertex v (joins v, v + 1), or a triangle's index with bit 31 |
//! | positions | 3 per vertex           | the lines' vertices, then every mesh's (f32)                |
//! | radii     | 1 per line vertex      | per-vertex tube radii, ≤ 0 = the settings' (only when given) |
//! | starts    | 1 per streamline, + 1  | each streamline's first vertex, then the vertex count       |
//! | triangles | 3 per triangle         | vertex indices into `positions`                              |
//!
//! Leaves hold up to [`GPU_LEAF`] primitives, so there are about 0.3 nodes per segment:
//! 12 B of position + 4 B of reference + about 10 B of nodes + 4 B of radius where tubes have
//! per-vertex radii, under 32 bytes per vertex ([`RayScene::bytes_per_vertex`] says exactly;
//! `lineao bench` prints it).
//!
//! **Split over bindings.** A storage binding holds at most the adapter's
//! `max_storage_buffer_binding_size` (128 MiB on lavapipe, 11 M segments need more), so the
//! words are cut into chunks of 2^k words, each its own buffer and binding, up to
//! [`MAX_CHUNKS`]; the shader reads word i from chunk i ≫ k. A scene beyond that is
//! [`Error::TooLarge`].

use std::sync::atomic::{AtomicU64, Ordering};

use glam::Vec3;
use wgpu::util::DeviceExt;

use crate::Error;
use crate::truth::bvh::{Bvh, Node, TRIANGLE_BIT};
use crate::truth::{RoundedCone, Triangle};

/// Most primitives in a leaf of the GPU tree.
pub const GPU_LEAF: usize = 8;
/// Most bindings the words are split over (with the pass's uniform, G-buffer, `ao` and
/// accumulation buffer, within wgpu's default 8 storage buffers per stage).
pub const MAX_CHUNKS: usize = 6;

/// What the scene is made of: streamlines (as `Tractogram` holds them) and triangle meshes.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayGeometry<'a> {
    /// Line vertices, streamline `s` being `positions[offsets[s] .. offsets[s + 1]]`.
    pub positions: &'a [[f32; 3]],
    pub offsets: &'a [u64],
    /// Per-vertex tube radii (world units), where positive and finite; else the settings'.
    pub radii: Option<&'a [f32]>,
    /// Context surfaces: (positions, triangle indices).
    pub meshes: &'a [(&'a [[f32; 3]], &'a [u32])],
}

/// Word offsets of the regions, as the shader's uniform takes them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Regions {
    pub nodes: u32,
    pub node_count: u32,
    pub refs: u32,
    pub positions: u32,
    /// `u32::MAX` when there are no per-vertex radii.
    pub radii: u32,
    pub starts: u32,
    pub streamlines: u32,
    pub triangles: u32,
}

/// The scene on the GPU (see the module doc).
pub struct RayScene {
    pub(crate) chunks: Vec<wgpu::Buffer>,
    /// log2 of the words per chunk.
    pub(crate) chunk_shift: u32,
    pub(crate) regions: Regions,
    /// The largest per-vertex tube radius (0 without).
    pub(crate) max_vertex_radius: f32,
    /// Changes with every upload: what tells the progressive tracer to start again.
    pub(crate) generation: u64,
    vertices: usize,
    bytes: u64,
}

static GENERATION: AtomicU64 = AtomicU64::new(1);

impl RayScene {
    /// Builds the tree over `geometry` on all cores and uploads it, split over as many bindings
    /// as the device's limits need.
    pub fn new(device: &wgpu::Device, geometry: &RayGeometry) -> Result<RayScene, Error> {
        let limits = device.limits();
        let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        // The largest power of two of words a binding holds.
        let chunk_words = 1u64 << (63 - (binding / 4).max(1).leading_zeros());
        Self::with_chunk_words(device, geometry, chunk_words)
    }

    /// [`RayScene::new`] with chunks of `chunk_words` words (a power of two): how tests split a
    /// small scene over several bindings.
    pub fn with_chunk_words(
        device: &wgpu::Device,
        geometry: &RayGeometry,
        chunk_words: u64,
    ) -> Result<RayScene, Error> {
        if !chunk_words.is_power_of_two() || chunk_words < 64 {
            return Err(Error::Usage(format!("chunk_words must be a power of two ≥ 64, got {chunk_words}")));
        }
        let vertices = geometry.positions.len() + geometry.meshes.iter().map(|m| m.0.len()).sum::<usize>();
        let estimate = 4 * (vertices as u64) * 8;
        let capacity = MAX_CHUNKS as u64 * chunk_words * 4;
        if vertices >= TRIANGLE_BIT as usize || estimate > 2 * capacity {
            return Err(too_large(vertices, estimate, capacity));
        }
        let (words, regions, max_vertex_radius) = flatten(geometry);
        let bytes = words.len() as u64 * 4;
        if bytes > capacity {
            return Err(too_large(vertices, bytes, capacity));
        }
        let chunks = words
            .chunks(chunk_words as usize)
            .enumerate()
            .map(|(i, chunk)| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("lineao::RayScene[{i}]")),
                    contents: bytemuck::cast_slice(chunk),
                    usage: wgpu::BufferUsages::STORAGE,
                })
            })
            .collect::<Vec<_>>();
        let chunks = if chunks.is_empty() {
            vec![device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("lineao::RayScene[empty]"),
                contents: &[0; 32],
                usage: wgpu::BufferUsages::STORAGE,
            })]
        } else {
            chunks
        };
        Ok(RayScene {
            chunks,
            chunk_shift: chunk_words.trailing_zeros(),
            regions,
            max_vertex_radius,
            generation: GENERATION.fetch_add(1, Ordering::Relaxed),
            vertices,
            bytes,
        })
    }

    /// Bytes on the GPU.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// GPU bytes per vertex (lines and meshes).
    pub fn bytes_per_vertex(&self) -> f64 {
        self.bytes as f64 / self.vertices.max(1) as f64
    }

    /// A number no other scene of this process has: what tells a renderer holding scenes that
    /// the geometry changed.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The buffers the words are split over.
    pub fn chunk_count(&self) -> usize {
        self.chunks.len()
    }

    /// Whether there is nothing to hit.
    pub fn is_empty(&self) -> bool {
        self.regions.node_count == 0
    }
}

fn too_large(vertices: usize, bytes: u64, capacity: u64) -> Error {
    Error::TooLarge(format!(
        "the ray tracer's scene of {vertices} vertices needs {bytes} bytes on the GPU, more than the {capacity} bytes \
         of {MAX_CHUNKS} storage bindings this adapter allows"
    ))
}

/// The words of the scene, their regions, and the largest per-vertex radius.
fn flatten(geometry: &RayGeometry) -> (Vec<u32>, Regions, f32) {
    let positions = geometry.positions;
    // Bare axes (radius 0), with the vertex each segment starts at.
    let mut cones = Vec::with_capacity(positions.len());
    let mut first_vertex = Vec::with_capacity(positions.len());
    for (s, range) in geometry.offsets.windows(2).enumerate() {
        let (start, end) = (range[0] as usize, (range[1] as usize).min(positions.len()));
        for v in start..end.saturating_sub(1) {
            let (a, b) = (Vec3::from(positions[v]), Vec3::from(positions[v + 1]));
            if a.is_finite() && b.is_finite() {
                cones.push(RoundedCone { a, b, ra: 0.0, rb: 0.0, streamline: s as u32, segment: (v - start) as u32 });
                first_vertex.push(v as u32);
            }
        }
    }
    let mut triangles = Vec::new();
    let mut triangle_vertices: Vec<u32> = Vec::new();
    let mut base = positions.len() as u32;
    for (mesh_positions, indices) in geometry.meshes {
        for t in indices.chunks_exact(3) {
            let Some(v) = t.iter().map(|&i| mesh_positions.get(i as usize)).collect::<Option<Vec<_>>>() else {
                continue;
            };
            triangles.push(Triangle { v: [v[0], v[1], v[2]].map(|p| Vec3::from(*p)) });
            triangle_vertices.extend(t.iter().map(|&i| base + i));
        }
        base += mesh_positions.len() as u32;
    }
    let bvh = Bvh::build_with_leaves(cones, triangles, GPU_LEAF);
    let mut words: Vec<u32> = Vec::new();
    let mut regions = Regions { nodes: 0, node_count: bvh.nodes.len() as u32, ..Regions::default() };
    words.extend_from_slice(bytemuck::cast_slice::<Node, u32>(&bvh.nodes));
    regions.refs = words.len() as u32;
    words.extend(bvh.refs.iter().map(|&r| if r & TRIANGLE_BIT != 0 { r } else { first_vertex[r as usize] }));
    regions.positions = words.len() as u32;
    words.extend_from_slice(bytemuck::cast_slice(positions));
    for (mesh_positions, _) in geometry.meshes {
        words.extend_from_slice(bytemuck::cast_slice(mesh_positions));
    }
    let mut max_vertex_radius = 0.0f32;
    regions.radii = match geometry.radii {
        Some(radii) => {
            let at = words.len() as u32;
            words.extend((0..positions.len()).map(|v| {
                let r = radii.get(v).copied().unwrap_or(0.0);
                let r = if r > 0.0 && r.is_finite() { r } else { 0.0 };
                max_vertex_radius = max_vertex_radius.max(r);
                r.to_bits()
            }));
            at
        }
        None => u32::MAX,
    };
    regions.starts = words.len() as u32;
    let streamlines = geometry.offsets.len().saturating_sub(1);
    regions.streamlines = streamlines as u32;
    words.extend(geometry.offsets.iter().map(|&o| o.min(positions.len() as u64) as u32));
    regions.triangles = words.len() as u32;
    words.extend_from_slice(&triangle_vertices);
    (words, regions, max_vertex_radius)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_hold_what_the_module_doc_says() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [f32::NAN, 0.0, 0.0]];
        let offsets = [0, 3, 5];
        let mesh_positions = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let indices = [0, 1, 2, 0, 1, 7];
        let meshes = [(&mesh_positions[..], &indices[..])];
        let geometry = RayGeometry { positions: &positions, offsets: &offsets, radii: None, meshes: &meshes };
        let (words, r, _) = flatten(&geometry);
        // Two finite segments (0–1, 1–2; 3–4 has a NaN end) and one valid triangle.
        let refs = &words[r.refs as usize..r.positions as usize];
        let mut sorted = refs.to_vec();
        sorted.sort();
        assert_eq!(sorted, vec![0, 1, TRIANGLE_BIT]);
        assert_eq!(f32::from_bits(words[r.positions as usize + 3]), 1.0);
        assert_eq!(r.radii, u32::MAX);
        assert_eq!(&words[r.starts as usize..r.triangles as usize], &[0, 3, 5]);
        // The triangle's vertices follow the 5 line vertices.
        assert_eq!(&words[r.triangles as usize..], &[5, 6, 7]);
    }
}
