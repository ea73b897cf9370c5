//! Context surfaces: triangle meshes shown with the tracts (a brain hull, a wing) so that they
//! occlude and are occluded. OBJ faces through `tobj` (polygons triangulated), glTF TRIANGLES,
//! TRIANGLE_STRIP and TRIANGLE_FAN primitives of the node tree (node transforms applied, normals
//! by the inverse transpose); either may be gzip-wrapped. Normals come from the file where it
//! has them for every vertex, else from the faces (area-weighted, per vertex).
//!
//! OBJ `l` polylines are tracts, not surfaces ([`crate::load`] reads them): a file without faces
//! is an error here, as a file without lines is one there.

use std::io::Read;
use std::path::Path;

use glam::{Mat3, Mat4, Vec3};

use crate::error::{Error, Parse, bad};
use crate::formats::gltf;
use crate::input::{Limited, io_error};

/// An indexed triangle mesh in world space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions, world units.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Three per triangle, each below `positions.len()`.
    pub indices: Vec<u32>,
}

impl TriangleMesh {
    /// The number of triangles.
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }

    /// Appends `other`, its indices shifted.
    fn append(&mut self, other: TriangleMesh) {
        let base = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.normals.extend(other.normals);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }

    /// Area-weighted vertex normals from the faces (a vertex of no face or of degenerate faces
    /// only gets +z).
    pub fn face_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
        let mut sums = vec![Vec3::ZERO; positions.len()];
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from_array(positions[i as usize]));
            // The cross product's length is twice the area: larger faces weigh more.
            let n = (b - a).cross(c - a);
            for &i in t {
                sums[i as usize] += n;
            }
        }
        sums.into_iter().map(|n| n.normalize_or(Vec3::Z).to_array()).collect()
    }
}

/// Loads a triangle mesh from an OBJ or glTF/GLB file (gzip-wrapped or not; decompression stops
/// at 256 MiB or 64 × the file's size).
pub fn load_mesh(path: impl AsRef<Path>) -> Result<TriangleMesh, Error> {
    let path = path.as_ref();
    read_mesh(path).map_err(|kind| kind.at(path))
}

fn read_mesh(path: &Path) -> Parse<TriangleMesh> {
    let raw = std::fs::read(path)?;
    let limit = (256u64 << 20).max(raw.len() as u64 * 64);
    let bytes = if raw.starts_with(&[0x1f, 0x8b]) {
        let mut out = Vec::new();
        let decoder = flate2::read::MultiGzDecoder::new(&raw[..]);
        Limited { inner: decoder, left: limit, limit }
            .read_to_end(&mut out)
            .map_err(|e| io_error(e, out.len() as u64, "gzip data"))?;
        out
    } else {
        raw
    };
    let mesh = if gltf::sniff(&bytes) { read_gltf(&bytes, path.parent(), limit)? } else { read_obj(&bytes)? };
    if mesh.indices.is_empty() {
        return bad(0, "triangles (glTF TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN, or OBJ faces): a surface");
    }
    Ok(mesh)
}

fn read_obj(bytes: &[u8]) -> Parse<TriangleMesh> {
    let text = std::str::from_utf8(bytes).or_else(|e| bad(e.valid_up_to() as u64, "UTF-8 OBJ text"))?;
    if !text.lines().any(|l| l.trim_start().starts_with("f ")) {
        return bad(0, "OBJ faces ('f' lines): a surface (polylines are tracts: load them as such)");
    }
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    // Materials do not matter to a context surface; tobj must not look for .mtl files.
    let loaded = std::panic::catch_unwind(|| {
        tobj::load_obj_buf(&mut std::io::BufReader::new(bytes), &options, |_| Err(tobj::LoadError::OpenFileFailed))
    })
    .or_else(|_| bad(0, "an OBJ file tobj can parse"))?;
    let (models, _) = loaded.or_else(|e| bad(0, format!("valid OBJ ({e})")))?;
    let mut mesh = TriangleMesh::default();
    for model in models {
        let m = model.mesh;
        let positions: Vec<[f32; 3]> = m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        if let Some(&i) = m.indices.iter().find(|&&i| i as usize >= positions.len()) {
            return bad(0, format!("face indices below {} in object '{}', found {i}", positions.len(), model.name));
        }
        let normals = if m.normals.len() == m.positions.len() {
            m.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or(Vec3::Z).to_array()).collect()
        } else {
            TriangleMesh::face_normals(&positions, &m.indices)
        };
        mesh.append(TriangleMesh { positions, normals, indices: m.indices });
    }
    Ok(mesh)
}

fn read_gltf(bytes: &[u8], dir: Option<&Path>, limit: u64) -> Parse<TriangleMesh> {
    use ::gltf::mesh::Mode;
    let (document, buffers) = gltf::open(bytes, dir, limit)?;
    let mut mesh = TriangleMesh::default();
    gltf::walk(&document, |m, world: Mat4| {
        for prim in m.primitives() {
            let mode = prim.mode();
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                continue;
            }
            let (positions, ids) = gltf::primitive_vertices(&prim, m, world, &buffers)?;
            let indices: Vec<u32> = match mode {
                Mode::Triangles => ids.chunks_exact(3).flatten().copied().collect(),
                // Every other triangle of a strip is wound the other way round.
                Mode::TriangleStrip => (0..ids.len().saturating_sub(2))
                    .flat_map(|k| {
                        if k % 2 == 0 { [ids[k], ids[k + 1], ids[k + 2]] } else { [ids[k + 1], ids[k], ids[k + 2]] }
                    })
                    .collect(),
                _ => (1..ids.len().saturating_sub(1)).flat_map(|k| [ids[0], ids[k], ids[k + 1]]).collect(),
            };
            let normal = prim.get(&::gltf::Semantic::Normals);
            let normals = match normal {
                Some(accessor) if accessor.count() == positions.len() => {
                    use ::gltf::accessor::{DataType, Dimensions};
                    gltf::check_accessor(Some(&accessor), &buffers, &[DataType::F32], Dimensions::Vec3)?;
                    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
                    let to_world = Mat3::from_mat4(world).inverse().transpose();
                    let read = reader.read_normals().into_iter().flatten();
                    read.map(|n| (to_world * Vec3::from_array(n)).normalize_or(Vec3::Z).to_array()).collect()
                }
                _ => TriangleMesh::face_normals(&positions, &indices),
            };
            mesh.append(TriangleMesh { positions, normals, indices });
        }
        Ok(())
    })?;
    Ok(mesh)
}
