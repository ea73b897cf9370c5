//! Wavefront OBJ polylines: `v x y z [w]` vertices and `l i j k …` line elements.
//!
//! Our own reader, because tobj turns `l` elements into faces that cannot be told apart from
//! polygons (and fans them under its GPU options); tobj stays our reader for OBJ *meshes*.
//! Indices are 1-based, negative ones count back from the last vertex, `i/t` takes the vertex
//! part. Consecutive `l` elements are chained into one polyline while each starts where the
//! previous ended (exporters often write a polyline as two-point segments). Faces are ignored; a
//! file without `l` elements is a `NoLines` error.

use crate::error::{ErrorKind, Parse, bad};
use crate::tractogram::Tractogram;

/// Text whose first keywords are OBJ's.
pub(crate) fn sniff(head: &[u8]) -> bool {
    let text = String::from_utf8_lossy(head);
    let mut keywords = text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#'));
    keywords.next().is_some_and(|l| {
        let k = l.split_whitespace().next().unwrap_or("");
        matches!(k, "v" | "vn" | "vt" | "o" | "g" | "l" | "f" | "mtllib" | "usemtl" | "s")
    })
}

pub(crate) fn read(b: &[u8]) -> Parse<Tractogram> {
    let mut vertices: Vec<[f32; 3]> = Vec::new();
    let mut polylines: Vec<Vec<u32>> = Vec::new();
    let mut faces = 0usize;
    let mut at = 0usize;
    for raw in b.split(|&c| c == b'\n') {
        let line_at = at as u64;
        at += raw.len() + 1;
        let line = String::from_utf8_lossy(raw);
        let line = line.split('#').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut p = [0f32; 3];
                for c in &mut p {
                    let w = words.next().unwrap_or("");
                    *c = w.parse().or_else(|_| bad(line_at, format!("three numbers after 'v', found '{line}'")))?;
                }
                vertices.push(p);
            }
            Some("l") => {
                let mut ids = Vec::new();
                for w in words {
                    let v = w.split('/').next().unwrap_or("");
                    let i: i64 =
                        v.parse().or_else(|_| bad(line_at, format!("vertex indices after 'l', found '{w}'")))?;
                    let n = vertices.len() as i64;
                    let index = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || !(0..n).contains(&index) {
                        return bad(line_at, format!("a vertex index between 1 and {n} (or −{n} and −1), found {i}"));
                    }
                    ids.push(index as u32);
                }
                if ids.len() < 2 {
                    return bad(line_at, "at least two vertices after 'l'");
                }
                match polylines.last_mut() {
                    Some(last) if last.last() == ids.first() => last.extend_from_slice(&ids[1..]),
                    _ => polylines.push(ids),
                }
            }
            Some("f") => faces += 1,
            _ => {}
        }
    }
    if polylines.is_empty() {
        return Err(ErrorKind::NoLines(format!(
            "OBJ with {} vertices and {faces} faces but no 'l' elements",
            vertices.len()
        )));
    }
    let mut t = Tractogram::new();
    for p in polylines {
        t.push(p.iter().map(|&i| vertices[i as usize]));
    }
    Ok(t)
}
