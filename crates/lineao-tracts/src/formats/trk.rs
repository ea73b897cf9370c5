//! TrackVis `.trk` (versions 1 and 2; 3 is read as 2).
//!
//! A 1000-byte header, then per streamline an `i32` point count, the points as
//! `(x, y, z, scalars…)` f32 records in *voxmm* (voxel index × voxel size, origin at the corner of
//! voxel 0), then the streamline's properties. The byte order is whichever makes `hdr_size` 1000.
//!
//! Points become RAS+ mm exactly as nibabel does it (`get_affine_trackvis_to_rasmm`):
//! divide by the voxel size, shift by −½ voxel (TrackVis puts voxel centres at +½), re-orient
//! from the header's `voxel_order` to the orientation of `vox_to_ras` (flipping an axis maps
//! i → dim − 1 − i), then apply `vox_to_ras`. An all-zero `vox_to_ras` (never recorded, as in
//! version 1 files) means identity; an empty `voxel_order` means LPS, TrackVis's default.
//!
//! Scalar and property names are 20-byte slots; `name\0N` in a slot means N columns under one
//! name (nibabel's convention), padding spaces and NULs are trimmed.

use std::io::{self, Write};

use crate::error::{Parse, bad};
use crate::input::{Endian, Reader, read_rest_as_points};
use crate::tractogram::{Field, IDENTITY, Tractogram, VoxelSpace, apply_affine, invert_affine};

pub(crate) const HEADER_SIZE: usize = 1000;
const NAME_SLOT: usize = 20;
const MAX_NAMES: usize = 10;

pub(crate) fn sniff(head: &[u8]) -> bool {
    head.starts_with(b"TRACK")
}

pub(crate) struct Header {
    pub(crate) endian: Endian,
    dims: [u32; 3],
    voxel_sizes: [f32; 3],
    scalars: Vec<(String, usize)>,
    n_scalars: usize,
    properties: Vec<(String, usize)>,
    n_properties: usize,
    vox_to_ras: [[f64; 4]; 4],
    voxel_order: String,
    pub(crate) n_count: u64,
}

pub(crate) fn parse_header(h: &[u8]) -> Parse<Header> {
    let endian = if Endian::Little.i32(&h[996..]) == HEADER_SIZE as i32 {
        Endian::Little
    } else if Endian::Big.i32(&h[996..]) == HEADER_SIZE as i32 {
        Endian::Big
    } else {
        return bad(996, format!("hdr_size 1000 in either byte order, found {}", Endian::Little.i32(&h[996..])));
    };
    let version = endian.i32(&h[992..]);
    if !(1..=3).contains(&version) {
        return bad(992, format!("version 1, 2 or 3, found {version}"));
    }
    let mut dims = [0u32; 3];
    for (a, d) in dims.iter_mut().enumerate() {
        let v = endian.i16(&h[6 + 2 * a..]);
        if v < 0 {
            return bad(6 + 2 * a as u64, format!("a non-negative dimension, found {v}"));
        }
        *d = v as u32;
    }
    let voxel_sizes: [f32; 3] = std::array::from_fn(|a| endian.f32(&h[12 + 4 * a..]));
    if let Some(a) = (0..3).find(|&a| !voxel_sizes[a].is_finite() || voxel_sizes[a] < 0.0) {
        return bad(12 + 4 * a as u64, format!("a finite, non-negative voxel size, found {}", voxel_sizes[a]));
    }
    let count = |at: usize, what: &str| -> Parse<usize> {
        let n = endian.i16(&h[at..]);
        if n < 0 { bad(at as u64, format!("a non-negative {what} count, found {n}")) } else { Ok(n as usize) }
    };
    let n_scalars = count(36, "n_scalars")?;
    let n_properties = count(238, "n_properties")?;
    let mut vox_to_ras = IDENTITY;
    if version >= 2 {
        for (r, row) in vox_to_ras.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = endian.f32(&h[440 + 4 * (4 * r + c)..]) as f64;
            }
        }
        // nibabel: a zero [3][3] means the matrix was never recorded; use identity.
        if vox_to_ras[3][3] == 0.0 {
            vox_to_ras = IDENTITY;
        }
        if vox_to_ras.iter().flatten().any(|v| !v.is_finite()) || invert_affine(&vox_to_ras).is_none() {
            return bad(440, "an invertible vox_to_ras matrix");
        }
    }
    let voxel_order: String =
        h[948..952].iter().take_while(|&&b| b != 0).map(|&b| (b as char).to_ascii_uppercase()).collect();
    let voxel_order = match voxel_order.trim() {
        "" => "LPS".to_string(),
        o => o.to_string(),
    };
    if axcodes(&voxel_order).is_none() {
        return bad(948, format!("a voxel_order of three axis letters (e.g. RAS, LPS), found '{voxel_order}'"));
    }
    let n_count = endian.i32(&h[988..]);
    if n_count < 0 {
        return bad(988, format!("a non-negative n_count, found {n_count}"));
    }
    Ok(Header {
        endian,
        dims,
        voxel_sizes,
        scalars: names(&h[38..238], n_scalars, "scalar"),
        n_scalars,
        properties: names(&h[240..440], n_properties, "property"),
        n_properties,
        vox_to_ras,
        voxel_order,
        n_count: n_count as u64,
    })
}

/// The names of `n` columns from ten 20-byte slots: `name\0K` covers K columns; columns without
/// a name get `{what}_{i}`.
fn names(slots: &[u8], n: usize, what: &str) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    let mut covered = 0;
    for slot in slots.chunks_exact(NAME_SLOT).take(MAX_NAMES) {
        if covered >= n {
            break;
        }
        let mut parts = slot.split(|&b| b == 0).filter(|p| !p.is_empty());
        let Some(name) = parts.next() else { break };
        let name = String::from_utf8_lossy(name).trim_end().to_string();
        let columns = parts
            .next()
            .and_then(|k| std::str::from_utf8(k).ok()?.trim().parse::<usize>().ok())
            .unwrap_or(1)
            .clamp(1, n - covered);
        out.push((name, columns));
        covered += columns;
    }
    for i in covered..n {
        out.push((format!("{what}_{i}"), 1));
    }
    out
}

/// Voxel axis codes → (world axis, sign) per voxel axis.
fn axcodes(order: &str) -> Option<[(usize, f64); 3]> {
    let b = order.as_bytes();
    if b.len() != 3 {
        return None;
    }
    let mut out = [(0, 1.0); 3];
    for (o, &c) in out.iter_mut().zip(b) {
        *o = match c {
            b'R' => (0, 1.0),
            b'L' => (0, -1.0),
            b'A' => (1, 1.0),
            b'P' => (1, -1.0),
            b'S' => (2, 1.0),
            b'I' => (2, -1.0),
            _ => return None,
        };
    }
    let mut seen = [false; 3];
    for (axis, _) in out {
        if std::mem::replace(&mut seen[axis], true) {
            return None;
        }
    }
    Some(out)
}

/// nibabel's `io_orientation` for a near-permutation affine: for each voxel axis the world axis
/// it points along most, chosen greedily by the largest normalised entry.
fn affine_orientation(m: &[[f64; 4]; 4]) -> [(usize, f64); 3] {
    let mut rs = [[0.0f64; 3]; 3];
    for c in 0..3 {
        let norm = (0..3).map(|r| m[r][c] * m[r][c]).sum::<f64>().sqrt().max(f64::MIN_POSITIVE);
        for r in 0..3 {
            rs[r][c] = m[r][c] / norm;
        }
    }
    let mut out = [(0, 1.0); 3];
    for _ in 0..3 {
        let (mut br, mut bc, mut best) = (0, 0, -1.0);
        for (r, row) in rs.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                if v.abs() > best {
                    (br, bc, best) = (r, c, v.abs());
                }
            }
        }
        out[bc] = (br, if rs[br][bc] < 0.0 { -1.0 } else { 1.0 });
        // This world axis and this voxel axis are taken.
        rs[br] = [0.0; 3];
        for row in rs.iter_mut() {
            row[bc] = 0.0;
        }
    }
    out
}

/// The voxmm → RAS+ affine of a header (nibabel's `get_affine_trackvis_to_rasmm`).
fn voxmm_to_ras(h: &Header) -> [[f64; 4]; 4] {
    let mut scale_shift = IDENTITY;
    for (a, row) in scale_shift.iter_mut().take(3).enumerate() {
        let size = if h.voxel_sizes[a] > 0.0 { h.voxel_sizes[a] as f64 } else { 1.0 };
        row[a] = 1.0 / size;
        row[3] = -0.5;
    }
    // Re-orientation between the header's voxel order and the affine's, literally as nibabel
    // composes `inv_ornt_aff(ornt_transform(header, affine), dims)`: for header axis i and the
    // affine's axis j along the same world axis, out[i] = ±v[j], plus dims[i] − 1 when flipped.
    let header = axcodes(&h.voxel_order).expect("checked in parse_header");
    let affine = affine_orientation(&h.vox_to_ras);
    let mut reorient = [[0.0f64; 4]; 4];
    reorient[3][3] = 1.0;
    for (i, &(world, sign)) in header.iter().enumerate() {
        let j = affine.iter().position(|&(w, _)| w == world).unwrap_or(i);
        let flip = sign * affine[j].1;
        reorient[i][j] = flip;
        if flip < 0.0 {
            reorient[i][3] = h.dims[i] as f64 - 1.0;
        }
    }
    mul(&h.vox_to_ras, &mul(&reorient, &scale_shift))
}

fn mul(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..4).map(|k| a[r][k] * b[k][c]).sum()))
}

pub(crate) fn read(r: &mut Reader, size_hint: Option<u64>) -> Parse<Tractogram> {
    let h = parse_header(r.take(HEADER_SIZE, "a 1000-byte TrackVis header")?)?;
    let mut t = Tractogram::new();
    let (mut scalar_fields, mut property_fields) = h.fields();
    let mut decoder = Decoder::new(&h);
    match size_hint {
        // A plain file: read the body into the points' storage and decode in place (a point's
        // 12 bytes never overtake the 4 + 12 n bytes of its streamline's record).
        Some(len) => {
            let (mut points, got) = read_rest_as_points(r, len)?;
            let bytes = bytemuck::cast_slice_mut::<[f32; 3], u8>(&mut points);
            let mut at = 0usize;
            let mut kept = 0usize;
            while (h.n_count == 0 || (t.streamlines() as u64) < h.n_count) && at < got {
                let offset = (HEADER_SIZE + at) as u64;
                let Some(n) = bytes.get(at..(at + 4).min(got)).filter(|b| b.len() == 4).map(|b| h.endian.i32(b)) else {
                    return bad(offset, "a streamline's point count (4 bytes)");
                };
                let need = decoder.record_bytes(n, offset)?;
                if need > got - at - 4 {
                    return bad(offset + 4, format!("{n} points of {} bytes and the properties", decoder.record));
                }
                at += 4;
                if decoder.n_scalars == 0 {
                    kept = decoder.points_in_place(bytes, at, n as usize, kept);
                } else {
                    for p in 0..n as usize {
                        let s = at + p * decoder.record;
                        let xyz: [u8; 12] = bytes[s..s + 12].try_into().unwrap();
                        decoder.scalars(&bytes[s + 12..s + decoder.record], &mut scalar_fields);
                        let point = decoder.point(&xyz);
                        bytes[12 * kept..12 * kept + 12].copy_from_slice(bytemuck::bytes_of(&point));
                        kept += 1;
                    }
                }
                at += n as usize * decoder.record;
                decoder.properties(&bytes[at..], &mut property_fields);
                at += 4 * h.n_properties;
                t.offsets.push(kept as u64);
            }
            points.truncate(kept);
            points.shrink_to_fit();
            t.positions = points;
        }
        // A stream (gzip): the same records, piece by piece.
        None => {
            while (h.n_count == 0 || (t.streamlines() as u64) < h.n_count) && !r.at_end()? {
                let offset = r.offset();
                let n = h.endian.i32(r.take(4, "a streamline's point count")?);
                decoder.record_bytes(n, offset)?;
                let mut left = n as usize;
                let per_piece = (Reader::CHUNK / decoder.record).max(1);
                while left > 0 {
                    let k = left.min(per_piece);
                    let piece = r.take(k * decoder.record, &format!("{n} points of {} bytes", decoder.record))?;
                    for p in piece.chunks_exact(decoder.record) {
                        decoder.scalars(&p[12..], &mut scalar_fields);
                        t.positions.push(decoder.point(p[..12].try_into().unwrap()));
                    }
                    left -= k;
                }
                let properties = r.take(4 * h.n_properties, "the streamline's properties")?;
                decoder.properties(properties, &mut property_fields);
                t.offsets.push(t.positions.len() as u64);
            }
        }
    }
    t.vertex_fields = scalar_fields;
    t.streamline_fields = property_fields;
    t.space = Some(h.space());
    Ok(t)
}

impl Header {
    pub(crate) fn space(&self) -> VoxelSpace {
        VoxelSpace { affine: self.vox_to_ras, dimensions: self.dims, voxel_sizes: Some(self.voxel_sizes) }
    }

    /// Empty fields for the scalars (per vertex) and properties (per streamline).
    pub(crate) fn fields(&self) -> (Vec<Field>, Vec<Field>) {
        let empty = |names: &[(String, usize)]| {
            names.iter().map(|(n, c)| Field { name: n.clone(), columns: *c, values: Vec::new() }).collect()
        };
        (empty(&self.scalars), empty(&self.properties))
    }
}

/// Turns point records into RAS+ points (and scalar rows), property records into rows.
pub(crate) struct Decoder {
    endian: Endian,
    to_ras: [[f32; 4]; 3],
    /// Bytes of one point record.
    pub(crate) record: usize,
    n_scalars: usize,
    pub(crate) n_properties: usize,
    row: Vec<f32>,
}

impl Decoder {
    pub(crate) fn new(h: &Header) -> Decoder {
        let m = voxmm_to_ras(h);
        Decoder {
            endian: h.endian,
            // f32 like nibabel's float32 points; the affine itself was composed in f64.
            to_ras: std::array::from_fn(|r| std::array::from_fn(|c| m[r][c] as f32)),
            record: 4 * (3 + h.n_scalars),
            n_scalars: h.n_scalars,
            n_properties: h.n_properties,
            row: vec![0.0; h.n_scalars.max(h.n_properties)],
        }
    }

    /// Bytes a streamline of `n` points needs after its count; rejects negative counts.
    pub(crate) fn record_bytes(&self, n: i32, offset: u64) -> Parse<usize> {
        if n < 0 {
            return bad(offset, format!("a non-negative point count, found {n}"));
        }
        Ok((n as usize).saturating_mul(self.record).saturating_add(4 * self.n_properties))
    }

    /// voxmm → RAS+ for one point record's first 12 bytes.
    #[inline(always)]
    pub(crate) fn point(&self, p: &[u8; 12]) -> [f32; 3] {
        let word = |i: usize| {
            let w = u32::from_le_bytes([p[4 * i], p[4 * i + 1], p[4 * i + 2], p[4 * i + 3]]);
            f32::from_bits(if self.endian == Endian::Big { w.swap_bytes() } else { w })
        };
        let v = [word(0), word(1), word(2)];
        let m = &self.to_ras;
        std::array::from_fn(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2] + m[r][3])
    }

    /// `n` bare points (no scalars) from `bytes[at..]` to points `kept..` of the same buffer; the
    /// tight loop of the common case, with the matrix in registers and the diagonal case (no
    /// rotation: every TrackVis voxel order with an axis-aligned vox_to_ras) apart.
    fn points_in_place(&self, bytes: &mut [u8], at: usize, n: usize, mut kept: usize) -> usize {
        let m = self.to_ras;
        let big = self.endian == Endian::Big;
        let diagonal = (0..3).all(|r| (0..3).all(|c| r == c || m[r][c] == 0.0));
        let (scale, shift) = ([m[0][0], m[1][1], m[2][2]], [m[0][3], m[1][3], m[2][3]]);
        for p in 0..n {
            let s = at + 12 * p;
            let raw: [u8; 12] = bytes[s..s + 12].try_into().unwrap();
            let mut v: [f32; 3] = bytemuck::cast(raw);
            if big {
                v = v.map(|x| f32::from_bits(x.to_bits().swap_bytes()));
            }
            let w: [f32; 3] = if diagonal {
                std::array::from_fn(|a| v[a] * scale[a] + shift[a])
            } else {
                std::array::from_fn(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2] + m[r][3])
            };
            bytes[12 * kept..12 * kept + 12].copy_from_slice(bytemuck::bytes_of(&w));
            kept += 1;
        }
        kept
    }

    /// The scalars that follow a point's coordinates, appended to `fields`.
    pub(crate) fn scalars(&mut self, p: &[u8], fields: &mut [Field]) {
        if self.n_scalars > 0 {
            for (s, x) in self.row[..self.n_scalars].iter_mut().enumerate() {
                *x = self.endian.f32(&p[4 * s..]);
            }
            split_row(&self.row[..self.n_scalars], fields);
        }
    }

    /// A streamline's properties, appended to `fields`.
    pub(crate) fn properties(&mut self, p: &[u8], fields: &mut [Field]) {
        if self.n_properties > 0 {
            for (s, x) in self.row[..self.n_properties].iter_mut().enumerate() {
                *x = self.endian.f32(&p[4 * s..]);
            }
            split_row(&self.row[..self.n_properties], fields);
        }
    }
}

/// Appends one row of values to the fields that share it, in order.
fn split_row(row: &[f32], fields: &mut [Field]) {
    let mut at = 0;
    for f in fields {
        f.values.extend_from_slice(&row[at..at + f.columns]);
        at += f.columns;
    }
}

/// Writes a version 2 `.trk`, little-endian. Points go to voxmm through the inverse of the
/// reader's affine, with `voxel_order` taken from the affine so no re-orientation is needed.
/// Fields that TrackVis cannot hold (more than ten names, names over 18 bytes) are left out and
/// their names returned.
pub fn write(t: &Tractogram, out: &mut dyn Write) -> io::Result<Vec<String>> {
    let space = t.space.unwrap_or(VoxelSpace { affine: IDENTITY, dimensions: [1, 1, 1], voxel_sizes: None });
    let mut voxel_sizes = space.voxel_sizes.unwrap_or_else(|| {
        std::array::from_fn(|c| (0..3).map(|r| space.affine[r][c].powi(2)).sum::<f64>().sqrt() as f32)
    });
    for v in &mut voxel_sizes {
        if !(v.is_finite() && *v > 0.0) {
            *v = 1.0;
        }
    }
    let order: String = affine_orientation(&space.affine)
        .iter()
        .map(|&(w, s)| match (w, s > 0.0) {
            (0, true) => 'R',
            (0, false) => 'L',
            (1, true) => 'A',
            (1, false) => 'P',
            (2, true) => 'S',
            _ => 'I',
        })
        .collect();
    let mut dropped = Vec::new();
    let mut pick = |fields: &[Field]| -> Vec<Field> {
        let mut kept = Vec::new();
        for f in fields {
            let name_ok = !f.name.is_empty() && f.name.len() <= NAME_SLOT - 2 && !f.name.contains('\0');
            if kept.len() < MAX_NAMES && name_ok && f.columns <= 9 {
                kept.push(f.clone());
            } else {
                dropped.push(f.name.clone());
            }
        }
        kept
    };
    let scalars = pick(&t.vertex_fields);
    let properties = pick(&t.streamline_fields);
    let n_scalars: usize = scalars.iter().map(|f| f.columns).sum();
    let n_properties: usize = properties.iter().map(|f| f.columns).sum();

    let mut h = vec![0u8; HEADER_SIZE];
    h[..6].copy_from_slice(b"TRACK\0");
    for a in 0..3 {
        let d = space.dimensions[a].min(i16::MAX as u32) as i16;
        h[6 + 2 * a..8 + 2 * a].copy_from_slice(&d.to_le_bytes());
        h[12 + 4 * a..16 + 4 * a].copy_from_slice(&voxel_sizes[a].to_le_bytes());
    }
    let put_names = |h: &mut [u8], at: usize, fields: &[Field]| {
        for (i, f) in fields.iter().enumerate() {
            let slot = &mut h[at + NAME_SLOT * i..at + NAME_SLOT * (i + 1)];
            slot[..f.name.len()].copy_from_slice(f.name.as_bytes());
            if f.columns > 1 {
                slot[f.name.len() + 1] = b'0' + f.columns as u8;
            }
        }
    };
    h[36..38].copy_from_slice(&(n_scalars as i16).to_le_bytes());
    put_names(&mut h, 38, &scalars);
    h[238..240].copy_from_slice(&(n_properties as i16).to_le_bytes());
    put_names(&mut h, 240, &properties);
    for r in 0..4 {
        for c in 0..4 {
            h[440 + 4 * (4 * r + c)..444 + 4 * (4 * r + c)].copy_from_slice(&(space.affine[r][c] as f32).to_le_bytes());
        }
    }
    h[948..951].copy_from_slice(order.as_bytes());
    h[988..992].copy_from_slice(&(t.streamlines().min(i32::MAX as usize) as i32).to_le_bytes());
    h[992..996].copy_from_slice(&2i32.to_le_bytes());
    h[996..1000].copy_from_slice(&(HEADER_SIZE as i32).to_le_bytes());
    out.write_all(&h)?;

    let header = Header {
        endian: Endian::Little,
        dims: space.dimensions,
        voxel_sizes,
        scalars: Vec::new(),
        n_scalars,
        properties: Vec::new(),
        n_properties,
        vox_to_ras: space.affine,
        voxel_order: order,
        n_count: 0,
    };
    let from_ras = invert_affine(&voxmm_to_ras(&header))
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the tractogram's affine is not invertible"))?;
    let mut buf = Vec::with_capacity(1 << 20);
    for i in 0..t.streamlines() {
        let (a, b) = (t.offsets[i] as usize, t.offsets[i + 1] as usize);
        buf.extend_from_slice(&((b - a) as i32).to_le_bytes());
        for v in a..b {
            let p = t.positions[v];
            let q = apply_affine(&from_ras, [p[0] as f64, p[1] as f64, p[2] as f64]);
            for c in q {
                buf.extend_from_slice(&(c as f32).to_le_bytes());
            }
            for f in &scalars {
                for x in &f.values[v * f.columns..(v + 1) * f.columns] {
                    buf.extend_from_slice(&x.to_le_bytes());
                }
            }
        }
        for f in &properties {
            for x in &f.values[i * f.columns..(i + 1) * f.columns] {
                buf.extend_from_slice(&x.to_le_bytes());
            }
        }
        if buf.len() >= 1 << 20 {
            out.write_all(&buf)?;
            buf.clear();
        }
    }
    out.write_all(&buf)?;
    Ok(dropped)
}
