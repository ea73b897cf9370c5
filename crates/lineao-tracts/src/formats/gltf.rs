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

pub(crate) fn sniff(head: &[u8]) -> bool {
    if head.starts_with(b"glTF") {
        return true;
    }
    let text = String::from_utf8_lossy(&head[..head.len().min(4096)]);
    text.trim_start().starts_with('{') && text.contains("\"asset\"")
}

pub(crate) fn read(bytes: &[u8], path: &Path, limit: u64) -> Parse<Tractogram> {
    let gltf = gltf::Gltf::from_slice(bytes).or_else(|e| bad(0, format!("a valid glTF document ({e})")))?;
    let dir = path.parent().unwrap_or(Path::new("."));
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
    let mut t = Tractogram::new();
    let mut triangles = 0usize;
    let roots: Vec<gltf::Node> = match gltf.document.default_scene().or_else(|| gltf.document.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => gltf.document.nodes().collect(),
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
        let Some(mesh) = node.mesh() else { continue };
        for prim in mesh.primitives() {
            use gltf::mesh::Mode;
            let mode = prim.mode();
            if !matches!(mode, Mode::Lines | Mode::LineLoop | Mode::LineStrip) {
                triangles += 1;
                continue;
            }
            let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let Some(positions) = reader.read_positions() else {
                return bad(0, format!("POSITION data for a line primitive of mesh {}", mesh.index()));
            };
            let points: Vec<[f32; 3]> =
                positions.map(|p| world.transform_point3(Vec3::from_array(p)).to_array()).collect();
            let ids: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..points.len() as u32).collect(),
            };
            if let Some(&i) = ids.iter().find(|&&i| i as usize >= points.len()) {
                return bad(0, format!("indices below {} in mesh {}, found {i}", points.len(), mesh.index()));
            }
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
    }
    if t.streamlines() == 0 {
        return Err(ErrorKind::NoLines(format!("glTF with {triangles} non-line primitives and no line primitive")));
    }
    Ok(t)
}
