//! The ray tracer's scene on the GPU: the ground truth's BVH ([`crate::truth::bvh`]) flattened
//! into textures, built on the CPU and uploaded once per geometry.
//!
//! **View-independent.** A fixed-width line's volume depends on the view (its radius is the
//! line's half-width on screen, (w/2)·(−z_view)/f_px), a tube's on the settings (its radius).
//! So the tree is built over the bare axes — every segment a cone of radius 0 — and the traversal
//! grows each node's box by the largest radius inside it: for lines (w/2)·max(−z_view over the
//! box's corners, near)/f_px, a plane's maximum over a box being at a corner; for tubes the
//! largest tube radius. Camera moves and radius changes then need no rebuild, only new
//! geometry does.
//!
//! **Textures, not storage buffers.** Every word the traversal reads is a texel fetch. On a GPU
//! a node read through the texture unit costs what a buffer load does (Aila and Laine's 2009
//! GPU traversal fetches its nodes so). On lavapipe it is what decides the speed: llvmpipe
//! (Mesa 22.3) loads a storage buffer one SIMD lane at a time, in a loop with a branch per lane
//! and per 32-bit word, while a texel fetch of 16 bytes is one unrolled gather — and a BVH walk
//! is little else but such loads. Moving the scene from storage buffers into textures, with
//! the pass's specialized pipelines, made a one-ray frame 2.4–2.6× faster there.
//!
//! **Layout**: four textures, one per region (texel i of a region is its i-th element):
//!
//! | texture   | format       | texels                      | content                                              |
//! |-----------|--------------|-----------------------------|------------------------------------------------------|
//! | nodes     | `Rgba32Uint` | 2 per node                  | (min xyz (f32), first), (max xyz (f32), count): [`Node`] |
//! | vertices  | `Rgba32Uint` | 1 per vertex                | xyz (f32) and the tube radius (f32, ≤ 0 = the settings'): the lines' vertices, then every mesh's |
//! | words     | `R32Uint`    | 1 per primitive, then 1 per streamline + 1 | references (a segment's first vertex v, joining v and v + 1, or a triangle's index with bit 31), then each streamline's first vertex and the vertex count |
//! | triangles | `Rgba32Uint` | 1 per triangle              | vertex indices into `vertices`, and 0               |
//!
//! Leaves hold up to [`GPU_LEAF`] primitives, so there are about 0.34 nodes per segment: 16 B of
//! vertex + 4 B of reference + about 11 B of nodes, under 32 bytes per vertex
//! ([`RayScene::bytes_per_vertex`] says exactly, padding included; `lineao bench` prints it).
//!
//! **Addressing, and scenes larger than a texture.** Each texture is an array of square layers
//! 2^k texels wide: texel i lies at (i mod 2^k, ⌊i / 2^k⌋ mod 2^k) of layer ⌊i / 4^k⌋. k is the
//! least that holds the region in one layer (whose height is then only the rows it fills), up
//! to the adapter's largest 2D texture (8192 texels in wgpu's defaults: 67 M texels a layer);
//! past that more layers hold the rest, up to the adapter's `max_texture_array_layers`. A
//! region beyond that is [`Error::TooLarge`]. A texture binding so holds what several storage
//! bindings would (lavapipe's hold 128 MiB each, its largest texture array 32 GiB).

use std::sync::atomic::{AtomicU64, Ordering};

use glam::Vec3;
use wgpu::util::DeviceExt;

use crate::Error;
use crate::truth::bvh::{Bvh, Node, TRIANGLE_BIT};
use crate::truth::primitive::{RoundedCone, Triangle};

/// Most primitives in a leaf of the GPU tree.
pub const GPU_LEAF: usize = 8;

/// What the scene is made of: streamlines (as `Tractogram` holds them) and triangle meshes.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayGeometry<'a> {
    /// Line vertices, streamline `s` being `positions[offsets[s] .. offsets[s + 1]]`.
    pub positions: &'a [[f32; 3]],
    /// Each streamline's first point, and the end (CSR offsets).
    pub offsets: &'a [u64],
    /// Per-vertex tube radii (world units), where positive and finite; else the settings'.
    pub radii: Option<&'a [f32]>,
    /// Context surfaces: (positions, triangle indices).
    pub meshes: &'a [(&'a [[f32; 3]], &'a [u32])],
}

/// What the shader needs to know of the scene besides its textures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Regions {
    pub node_count: u32,
    /// Where the streamline starts begin in `words` (after the references).
    pub starts: u32,
    pub streamlines: u32,
    pub triangles: u32,
    /// Whether the vertices carry per-vertex tube radii.
    pub radii: bool,
}

/// One region as a texture array (see the module doc).
pub(crate) struct SceneTexture {
    pub(crate) view: wgpu::TextureView,
    /// log2 of the layers' width.
    pub(crate) shift: u32,
    layers: u32,
    bytes: u64,
}

/// The scene on the GPU (see the module doc).
pub struct RayScene {
    pub(crate) nodes: SceneTexture,
    pub(crate) vertices: SceneTexture,
    pub(crate) words: SceneTexture,
    pub(crate) triangles: SceneTexture,
    pub(crate) regions: Regions,
    /// The largest per-vertex tube radius (0 without).
    pub(crate) max_vertex_radius: f32,
    /// Changes with every upload: what tells the progressive tracer to start again.
    pub(crate) generation: u64,
    vertex_count: usize,
    longest_side: f32,
}

static GENERATION: AtomicU64 = AtomicU64::new(1);

impl RayScene {
    /// Builds the tree over `geometry` on all cores and uploads it, in textures as wide as the
    /// device allows.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, geometry: &RayGeometry) -> Result<RayScene, Error> {
        let widest = device.limits().max_texture_dimension_2d.max(2);
        Self::with_max_width(device, queue, geometry, 1 << widest.ilog2())
    }

    /// [`RayScene::new`] with layers at most `max_width` texels wide (a power of two ≥ 2): how
    /// tests spread a small scene over many layers.
    pub fn with_max_width(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        geometry: &RayGeometry,
        max_width: u32,
    ) -> Result<RayScene, Error> {
        if !max_width.is_power_of_two() || max_width < 2 {
            return Err(Error::out_of_range("RayScene::max_width", max_width, "a power of two ≥ 2"));
        }
        let limits = Limits { max_width, max_layers: device.limits().max_texture_array_layers };
        let vertex_count = geometry.positions.len() + geometry.meshes.iter().map(|m| m.0.len()).sum::<usize>();
        // Before building the tree: a vertex is a texel, a segment up to two.
        let capacity = limits.texels();
        if vertex_count >= TRIANGLE_BIT as usize || 2 * vertex_count as u64 > capacity {
            return Err(too_large("vertices", vertex_count as u64, 2 * vertex_count as u64, &limits));
        }
        let points = geometry.positions.iter().chain(geometry.meshes.iter().flat_map(|m| m.0.iter()));
        let longest_side = crate::camera::Bounds::corners_of(points).map_or(0.0, |(lo, hi)| (hi - lo).max_element());
        let flat = flatten(geometry);
        Ok(RayScene {
            nodes: upload(device, queue, "nodes", flat.nodes, 4, &limits)?,
            vertices: upload(device, queue, "vertices", flat.vertices, 4, &limits)?,
            words: upload(device, queue, "words", flat.words, 1, &limits)?,
            triangles: upload(device, queue, "triangles", flat.triangles, 4, &limits)?,
            regions: flat.regions,
            max_vertex_radius: flat.max_vertex_radius,
            generation: GENERATION.fetch_add(1, Ordering::Relaxed),
            vertex_count,
            longest_side,
        })
    }

    /// The longest side of the axis-aligned box around its finite vertices (lines' and
    /// meshes'), world units: what a reach given as a share of the scene is a share of
    /// ([`crate::RayTracedSettings::distance_share`]).
    pub fn longest_side(&self) -> f32 {
        self.longest_side
    }

    /// Its textures in binding order: nodes, vertices, words, triangles.
    pub(crate) fn textures(&self) -> [&SceneTexture; 4] {
        [&self.nodes, &self.vertices, &self.words, &self.triangles]
    }

    /// Bytes on the GPU, the textures' padding included.
    pub fn bytes(&self) -> u64 {
        self.textures().iter().map(|t| t.bytes).sum()
    }

    /// GPU bytes per vertex (lines and meshes).
    pub fn bytes_per_vertex(&self) -> f64 {
        self.bytes() as f64 / self.vertex_count.max(1) as f64
    }

    /// A number no other scene of this process has: what tells a renderer holding scenes that
    /// the geometry changed.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The layers of its largest texture (1 unless a region outgrows one layer).
    pub fn layers(&self) -> u32 {
        self.textures().iter().map(|t| t.layers).max().unwrap_or(1)
    }

    /// Whether there is nothing to hit.
    pub fn is_empty(&self) -> bool {
        self.regions.node_count == 0
    }
}

/// How large the scene's textures may be.
struct Limits {
    max_width: u32,
    max_layers: u32,
}

impl Limits {
    /// Texels a texture holds.
    fn texels(&self) -> u64 {
        (self.max_width as u64).pow(2) * self.max_layers as u64
    }
}

/// `count` `what` need `texels` texels, more than the textures hold.
fn too_large(what: &str, count: u64, texels: u64, limits: &Limits) -> Error {
    let message = format!(
        "the ray tracer's scene has {count} {what}, more than a texture of this adapter holds: {} layers of \
         {w} × {w} texels (max_texture_array_layers, max_texture_dimension_2d), {} texels",
        limits.max_layers,
        limits.texels(),
        w = limits.max_width,
    );
    Error::TooLarge { limit: crate::Limit::TextureArrayTexels, value: texels, max: limits.texels(), message }
}

/// Uploads `data` (`texel_words` words a texel) as a texture array of square layers, padded
/// in place to whole rows and layers.
fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    region: &str,
    mut data: Vec<u32>,
    texel_words: usize,
    limits: &Limits,
) -> Result<SceneTexture, Error> {
    let texels = (data.len() / texel_words).max(1) as u64;
    if texels > limits.texels() {
        return Err(too_large(&format!("texels of {region}"), texels, texels, limits));
    }
    // The least width whose square layer holds every texel, within the limit.
    let mut shift = 0;
    while (1u64 << (2 * shift)) < texels && (1u32 << shift) < limits.max_width {
        shift += 1;
    }
    let width = 1u64 << shift;
    let layers = texels.div_ceil(width * width);
    let rows = if layers == 1 { texels.div_ceil(width) } else { width };
    data.resize((width * rows * layers) as usize * texel_words, 0);
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some(&format!("lineao::RayScene::{region}")),
            size: wgpu::Extent3d { width: width as u32, height: rows as u32, depth_or_array_layers: layers as u32 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: if texel_words == 4 { wgpu::TextureFormat::Rgba32Uint } else { wgpu::TextureFormat::R32Uint },
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&data),
    );
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    Ok(SceneTexture { view, shift, layers: layers as u32, bytes: data.len() as u64 * 4 })
}

/// The regions' words (see the module doc).
struct Flat {
    nodes: Vec<u32>,
    vertices: Vec<u32>,
    words: Vec<u32>,
    triangles: Vec<u32>,
    regions: Regions,
    max_vertex_radius: f32,
}

fn flatten(geometry: &RayGeometry) -> Flat {
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
            triangle_vertices.extend(t.iter().map(|&i| base + i).chain([0]));
        }
        base += mesh_positions.len() as u32;
    }
    let bvh = Bvh::build_with_leaves(cones, triangles, GPU_LEAF);
    let mut max_vertex_radius = 0.0f32;
    let radius = |v: usize| {
        let r = geometry.radii.and_then(|radii| radii.get(v)).copied().unwrap_or(0.0);
        if r > 0.0 && r.is_finite() { r } else { 0.0 }
    };
    let mut vertices = Vec::with_capacity(4 * base as usize);
    for (v, p) in positions.iter().enumerate() {
        let r = radius(v);
        max_vertex_radius = max_vertex_radius.max(r);
        vertices.extend([p[0], p[1], p[2], r].map(f32::to_bits));
    }
    for (mesh_positions, _) in geometry.meshes {
        vertices.extend(mesh_positions.iter().flat_map(|p| [p[0], p[1], p[2], 0.0].map(f32::to_bits)));
    }
    let mut words: Vec<u32> =
        bvh.refs.iter().map(|&r| if r & TRIANGLE_BIT != 0 { r } else { first_vertex[r as usize] }).collect();
    let streamlines = geometry.offsets.len().saturating_sub(1);
    let regions = Regions {
        node_count: bvh.nodes.len() as u32,
        starts: words.len() as u32,
        streamlines: streamlines as u32,
        triangles: (triangle_vertices.len() / 4) as u32,
        radii: geometry.radii.is_some(),
    };
    words.extend(geometry.offsets.iter().map(|&o| o.min(positions.len() as u64) as u32));
    Flat {
        nodes: bytemuck::cast_slice::<Node, u32>(&bvh.nodes).to_vec(),
        vertices,
        words,
        triangles: triangle_vertices,
        regions,
        max_vertex_radius,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_hold_what_the_module_doc_says() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [f32::NAN, 0.0, 0.0]];
        let offsets = [0, 3, 5];
        let radii = [0.5, -1.0, f32::INFINITY, 0.25];
        let mesh_positions = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let indices = [0, 1, 2, 0, 1, 7];
        let meshes = [(&mesh_positions[..], &indices[..])];
        let geometry = RayGeometry { positions: &positions, offsets: &offsets, radii: Some(&radii), meshes: &meshes };
        let flat = flatten(&geometry);
        let r = flat.regions;
        // Two finite segments (0–1, 1–2; 3–4 has a NaN end) and one valid triangle.
        let refs = &flat.words[..r.starts as usize];
        let mut sorted = refs.to_vec();
        sorted.sort();
        assert_eq!(sorted, vec![0, 1, TRIANGLE_BIT]);
        assert_eq!(&flat.words[r.starts as usize..], &[0, 3, 5]);
        assert_eq!((r.streamlines, r.triangles, r.radii), (2, 1, true));
        // Vertex 1: x = 1, and its radius −1 reads as none (0); vertex 3's 0.25 is kept.
        assert_eq!(flat.vertices[4..8], [1.0f32, 0.0, 0.0, 0.0].map(f32::to_bits));
        assert_eq!(f32::from_bits(flat.vertices[4 * 3 + 3]), 0.25);
        assert_eq!((f32::from_bits(flat.vertices[3]), f32::from_bits(flat.vertices[4 * 2 + 3])), (0.5, 0.0));
        assert_eq!(flat.max_vertex_radius, 0.5);
        // 5 line vertices, then the mesh's 3; the triangle's vertices follow the line vertices.
        assert_eq!(flat.vertices.len(), 4 * 8);
        assert_eq!(flat.triangles, [5, 6, 7, 0]);
        assert_eq!(flat.nodes.len(), 8 * r.node_count as usize);
    }
}
