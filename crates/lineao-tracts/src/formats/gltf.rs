//! glTF 2.0 line primitives (`.gltf` with external or `data:` buffers, or binary `.glb`), read
//! through the `gltf` crate.
//!
//! Every LINES, LINE_LOOP and LINE_STRIP primitive of the default scene's node tree (all root
//! nodes when there is no scene) becomes streamlines in world space (node transforms applied).
//! LINE_STRIP is one polyline; LINE_LOOP repeats its first vertex at the end; LINES segments are
//! chained into one polyline while each segment starts where the previous ended. Triangle and
//! point primitives are not lines: a file with no line primitive is a `NoLines` error.

use std::path::Path;

use base64::Engine;
use glam::{Mat4, Vec3};

use crate::error::{ErrorKind, Parse, bad};
use crate::tractogram::Tractogram;

/// Checks what the gltf crate (1.4) trusts before it validates, both found by our fuzzer: a GLB
/// header length below 12 (an integer underflow, a panic with overflow checks), and
/// `accessors[POSITION]` indexed before the index is checked.
fn precheck(bytes: &[u8]) -> Parse<()> {
    let json = if bytes.starts_with(b"glTF") {
        let word = |at: usize| bytes.get(at..at + 4).map_or(0, |b| u32::from_le_bytes(b.try_into().unwrap()) as usize);
        if !(20..=bytes.len()).contains(&word(8)) {
            return bad(8, format!("a GLB length between 20 and the file's {} bytes, found {}", bytes.len(), word(8)));
        }
        let Some(json) = bytes.get(20..20usize.saturating_add(word(12))) else {
            return bad(12, "a GLB JSON chunk inside the file");
        };
        json
    } else {
        bytes
    };
    let doc = serde_json::from_slice::<serde_json::Value>(json)
        .or_else(|e| bad(e.column() as u64, format!("glTF JSON (line {}: {e})", e.line())))?;
    let accessors = doc.get("accessors").and_then(|a| a.as_array()).map_or(0, Vec::len) as u64;
    let meshes = doc.get("meshes").and_then(|m| m.as_array()).into_iter().flatten();
    for prim in meshes.filter_map(|m| m.get("primitives")?.as_array()).flatten() {
        let attributes = prim.get("attributes").and_then(|a| a.as_object()).into_iter().flat_map(|a| a.values());
        for index in attributes.chain(prim.get("indices")) {
            if index.as_u64().is_none_or(|i| i >= accessors) {
                return bad(0, format!("primitive accessor indices below {accessors}, found {index}"));
            }
        }
    }
    Ok(())
}

pub(crate) fn sniff(head: &[u8]) -> bool {
    if head.starts_with(b"glTF") {
        return true;
    }
    let text = String::from_utf8_lossy(&head[..head.len().min(4096)]);
    text.trim_start().starts_with('{') && text.contains("\"asset\"")
}

/// A parsed glTF document with its buffers loaded. `dir` is where external buffer files are
/// looked up; `None` (bytes in memory) refuses them.
pub(crate) fn open(bytes: &[u8], dir: Option<&Path>, limit: u64) -> Parse<(gltf::Document, Vec<Vec<u8>>)> {
    precheck(bytes)?;
    // The gltf crate has panicked on malformed input its validation should reject (found by our
    // fuzzer, see `precheck`); a panic there must not take the caller down.
    let parsed = std::panic::catch_unwind(|| gltf::Gltf::from_slice(bytes))
        .or_else(|_| bad(0, "a glTF document the gltf crate can validate"))?;
    let gltf = parsed.or_else(|e| bad(0, format!("a valid glTF document ({e})")))?;
    let mut buffers = Vec::new();
    for buffer in gltf.document.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or(ErrorKind::Format { offset: 0, expected: "the GLB binary chunk the buffer refers to".into() })?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let Some((_, payload)) = uri.split_once(";base64,") else {
                    return bad(0, "a base64 data: URI for the buffer");
                };
                base64::engine::general_purpose::STANDARD
                    .decode(payload)
                    .or_else(|e| bad(0, format!("base64 in the buffer's data: URI ({e})")))?
            }
            gltf::buffer::Source::Uri(uri) => {
                let Some(dir) = dir else {
                    return Err(ErrorKind::Unsupported(format!(
                        "the external buffer '{uri}' of a glTF read from memory"
                    )));
                };
                let file = dir.join(uri);
                let len = std::fs::metadata(&file).map_err(|e| ErrorKind::Format {
                    offset: 0,
                    expected: format!("the buffer file '{}' ({e})", file.display()),
                })?;
                if len.len() > limit {
                    return Err(ErrorKind::TooLarge { offset: 0, limit });
                }
                std::fs::read(&file)?
            }
        };
        if data.len() < buffer.length() {
            return bad(0, format!("buffer {} of {} bytes, found {}", buffer.index(), buffer.length(), data.len()));
        }
        buffers.push(data);
    }
    Ok((gltf.document, buffers))
}

/// Visits every mesh of the default scene's node tree (all root nodes when there is no scene)
/// with its node's world transform.
pub(crate) fn walk(document: &gltf::Document, mut visit: impl FnMut(&gltf::Mesh, Mat4) -> Parse<()>) -> Parse<()> {
    let roots: Vec<gltf::Node> = match document.default_scene().or_else(|| document.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => document.nodes().collect(),
    };
    let mut stack: Vec<(gltf::Node, Mat4)> = roots.into_iter().map(|n| (n, Mat4::IDENTITY)).collect();
    let mut visited = 0usize;
    while let Some((node, parent)) = stack.pop() {
        visited += 1;
        if visited > 1 << 20 {
            return bad(0, "a node tree without cycles");
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        for child in node.children() {
            stack.push((child, world));
        }
        if let Some(mesh) = node.mesh() {
            visit(&mesh, world)?;
        }
    }
    Ok(())
}

/// A primitive's positions in world space and its vertex indices (0..n without an index
/// accessor), every index checked against the positions.
pub(crate) fn primitive_vertices(
    prim: &gltf::Primitive,
    mesh: &gltf::Mesh,
    world: Mat4,
    buffers: &[Vec<u8>],
) -> Parse<(Vec<[f32; 3]>, Vec<u32>)> {
    use gltf::accessor::{DataType as D, Dimensions};
    // The gltf crate's readers panic on accessors its validation lets through (wrong component
    // types, views past the buffer): check what we read.
    check_accessor(prim.get(&gltf::Semantic::Positions).as_ref(), buffers, &[D::F32], Dimensions::Vec3)?;
    if prim.indices().is_some() {
        check_accessor(prim.indices().as_ref(), buffers, &[D::U8, D::U16, D::U32], Dimensions::Scalar)?;
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let Some(positions) = reader.read_positions() else {
        return bad(0, format!("POSITION data for a primitive of mesh {}", mesh.index()));
    };
    let points: Vec<[f32; 3]> = positions.map(|p| world.transform_point3(Vec3::from_array(p)).to_array()).collect();
    let ids: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..points.len() as u32).collect(),
    };
    if let Some(&i) = ids.iter().find(|&&i| i as usize >= points.len()) {
        return bad(0, format!("indices below {} in mesh {}, found {i}", points.len(), mesh.index()));
    }
    Ok((points, ids))
}

pub(crate) fn read(bytes: &[u8], dir: Option<&Path>, limit: u64) -> Parse<Tractogram> {
    let (document, buffers) = open(bytes, dir, limit)?;
    let mut t = Tractogram::new();
    let mut triangles = 0usize;
    walk(&document, |mesh, world| {
        for prim in mesh.primitives() {
            use gltf::mesh::Mode;
            let mode = prim.mode();
            if !matches!(mode, Mode::Lines | Mode::LineLoop | Mode::LineStrip) {
                triangles += 1;
                continue;
            }
            let (points, ids) = primitive_vertices(&prim, mesh, world, &buffers)?;
            match mode {
                Mode::LineStrip => t.push(ids.iter().map(|&i| points[i as usize])),
                Mode::LineLoop => t.push(ids.iter().chain(ids.first()).map(|&i| points[i as usize])),
                _ => {
                    let mut polylines: Vec<Vec<u32>> = Vec::new();
                    for seg in ids.chunks_exact(2) {
                        match polylines.last_mut() {
                            Some(last) if last.last() == Some(&seg[0]) => last.push(seg[1]),
                            _ => polylines.push(seg.to_vec()),
                        }
                    }
                    for p in polylines {
                        t.push(p.iter().map(|&i| points[i as usize]));
                    }
                }
            }
        }
        Ok(())
    })?;
    if t.streamlines() == 0 {
        return Err(ErrorKind::NoLines(format!("glTF with {triangles} non-line primitives and no line primitive")));
    }
    Ok(t)
}

/// An accessor we read must exist, have the expected type and lie inside its buffer.
pub(crate) fn check_accessor(
    accessor: Option<&gltf::Accessor>,
    buffers: &[Vec<u8>],
    types: &[gltf::accessor::DataType],
    dims: gltf::accessor::Dimensions,
) -> Parse<()> {
    let Some(a) = accessor else { return bad(0, "a POSITION accessor on every primitive read") };
    if !types.contains(&a.data_type()) || a.dimensions() != dims {
        return bad(
            0,
            format!(
                "accessor {} of type {types:?} {dims:?}, found {:?} {:?}",
                a.index(),
                a.data_type(),
                a.dimensions()
            ),
        );
    }
    let Some(view) = a.view() else { return bad(0, format!("a buffer view for accessor {}", a.index())) };
    let element = a.size();
    let stride = view.stride().unwrap_or(element);
    let end = (a.count() as u64).checked_sub(1).map_or(0, |n| n * stride as u64 + element as u64);
    let start = view.offset() as u64 + a.offset() as u64;
    let buffer_len = buffers.get(view.buffer().index()).map_or(0, Vec::len) as u64;
    if a.offset() as u64 + end > view.length() as u64
        || start + end > buffer_len
        || view.offset() as u64 + view.length() as u64 > buffer_len
    {
        return bad(0, format!("accessor {} inside its view and buffer ({buffer_len} bytes)", a.index()));
    }
    Ok(())
}
