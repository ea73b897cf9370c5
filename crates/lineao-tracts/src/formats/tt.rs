//! DSI Studio "tiny track" `.tt.gz`: a gzip-wrapped MATLAB v4 file.
//!
//! Records are `(type, rows, cols, imag, name_len)` as little-endian i32, the name with its NUL,
//! then `rows × cols` values (type 10·P: P = 0 f64, 1 f32, 2 i32, 3 i16, 4 u16, 5 u8).
//! `dimension` (i32 × 3), `voxel_size` (f32 × 3), `trans_to_mni` (f32 × 16, a row-major
//! voxel → MNI affine) and `track` (u8) are what we use; `cluster` (u16 per track) becomes groups.
//! `track` holds, per streamline, a u32 count of coordinates (3 per point), the first point as
//! 3 × i32, then `count − 3` i8 deltas, each relative to the coordinate three places before; all
//! in 1/32 voxel. Points in RAS+ mm are `trans_to_mni · (coordinate / 32)`.

use crate::error::{Parse, bad};
use crate::tractogram::{Group, IDENTITY, Tractogram, VoxelSpace, apply_affine};

struct Record<'a> {
    name: &'a str,
    precision: u32,
    count: usize,
    data: &'a [u8],
    at: u64,
}

/// True when `head` starts like a MATLAB v4 record with a short ASCII name.
pub(crate) fn sniff(head: &[u8]) -> bool {
    if head.len() < 24 {
        return false;
    }
    let word = |i: usize| i32::from_le_bytes(head[4 * i..4 * i + 4].try_into().unwrap());
    let (ty, imag, name_len) = (word(0), word(3), word(4));
    (0..=52).contains(&ty)
        && imag == 0
        && (2..=64).contains(&name_len)
        && head
            .get(20..20 + name_len as usize)
            .is_some_and(|n| n[..n.len() - 1].iter().all(|b| b.is_ascii_graphic()) && n[n.len() - 1] == 0)
}

fn records(b: &[u8]) -> Parse<Vec<Record<'_>>> {
    let mut out = Vec::new();
    let mut at = 0usize;
    while at < b.len() {
        let Some(h) = b.get(at..at + 20) else { return bad(at as u64, "a 20-byte MATLAB v4 record header") };
        let word = |i: usize| i32::from_le_bytes(h[4 * i..4 * i + 4].try_into().unwrap());
        let (ty, rows, cols, imag, name_len) = (word(0), word(1), word(2), word(3), word(4));
        if !(0..=52).contains(&ty)
            || ty / 100 != 0
            || rows < 0
            || cols < 0
            || imag != 0
            || !(1..=4096).contains(&name_len)
        {
            return bad(at as u64, format!("a little-endian real MATLAB v4 record, found type {ty}, {rows}×{cols}"));
        }
        let precision = (ty / 10 % 10) as u32;
        let size = [8usize, 4, 4, 2, 2, 1].get(precision as usize).copied();
        let Some(size) = size else { return bad(at as u64, format!("a MATLAB v4 precision 0–5, found {precision}")) };
        let name_at = at + 20;
        let Some(name) = b.get(name_at..name_at + name_len as usize) else {
            return bad(name_at as u64, "the record's name");
        };
        let name = std::str::from_utf8(name.split(|&c| c == 0).next().unwrap_or(&[])).unwrap_or("?");
        let data_at = name_at + name_len as usize;
        let count = rows as usize * cols as usize;
        let Some(data) = count.checked_mul(size).and_then(|n| b.get(data_at..data_at + n)) else {
            return bad(
                data_at as u64,
                format!("{count} values of {size} bytes for '{name}' ({} bytes left)", b.len() - data_at),
            );
        };
        out.push(Record { name, precision, count, data, at: data_at as u64 });
        at = data_at + data.len();
    }
    Ok(out)
}

impl Record<'_> {
    fn values(&self) -> Vec<f64> {
        let size = self.data.len() / self.count.max(1);
        self.data
            .chunks_exact(size.max(1))
            .map(|c| match self.precision {
                0 => f64::from_le_bytes(c.try_into().unwrap()),
                1 => f32::from_le_bytes(c.try_into().unwrap()) as f64,
                2 => i32::from_le_bytes(c.try_into().unwrap()) as f64,
                3 => i16::from_le_bytes(c.try_into().unwrap()) as f64,
                4 => u16::from_le_bytes(c.try_into().unwrap()) as f64,
                _ => c[0] as f64,
            })
            .collect()
    }
}

pub(crate) fn read(b: &[u8]) -> Parse<Tractogram> {
    let recs = records(b)?;
    let get = |name: &str, len: usize| -> Parse<Option<Vec<f64>>> {
        match recs.iter().find(|r| r.name == name) {
            None => Ok(None),
            Some(r) if r.count == len => Ok(Some(r.values())),
            Some(r) => bad(r.at, format!("{len} values in '{name}', found {}", r.count)),
        }
    };
    let Some(dims) = get("dimension", 3)? else { return bad(0, "a 'dimension' record") };
    let voxel_sizes = get("voxel_size", 3)?.unwrap_or(vec![1.0; 3]);
    let affine = match get("trans_to_mni", 16)? {
        Some(m) => std::array::from_fn(|r| std::array::from_fn(|c| m[4 * r + c])),
        None => {
            let mut m = IDENTITY;
            (0..3).for_each(|a| m[a][a] = voxel_sizes[a]);
            m
        }
    };
    let Some(track) = recs.iter().find(|r| r.name == "track") else { return bad(0, "a 'track' record") };
    if track.precision != 5 {
        return bad(track.at, "'track' as uint8");
    }
    let mut t = Tractogram::new();
    let d = track.data;
    let mut at = 0usize;
    let mut coords: Vec<i32> = Vec::new();
    while at < d.len() {
        let here = track.at + at as u64;
        let Some(h) = d.get(at..at + 16) else { return bad(here, "a 16-byte track header (count and first point)") };
        let count = u32::from_le_bytes(h[..4].try_into().unwrap()) as usize;
        if count < 3 || !count.is_multiple_of(3) {
            return bad(here, format!("a coordinate count that is a positive multiple of 3, found {count}"));
        }
        let Some(deltas) = d.get(at + 16..at + 16 + (count - 3)) else {
            return bad(here + 16, format!("{} delta bytes ({} left)", count - 3, d.len() - at - 16));
        };
        coords.clear();
        coords.extend((0..3).map(|i| i32::from_le_bytes(h[4 + 4 * i..8 + 4 * i].try_into().unwrap())));
        for &delta in deltas {
            coords.push(coords[coords.len() - 3].wrapping_add(delta as i8 as i32));
        }
        t.push(coords.chunks_exact(3).map(|c| {
            let v = [c[0] as f64 / 32.0, c[1] as f64 / 32.0, c[2] as f64 / 32.0];
            let w = apply_affine(&affine, v);
            [w[0] as f32, w[1] as f32, w[2] as f32]
        }));
        at += 16 + count - 3;
    }
    if let Some(cluster) = recs.iter().find(|r| r.name == "cluster") {
        if cluster.count != t.streamlines() {
            return bad(cluster.at, format!("one cluster id per track ({}), found {}", t.streamlines(), cluster.count));
        }
        let ids = cluster.values();
        let mut distinct: Vec<u32> = ids.iter().map(|&v| v as u32).collect();
        distinct.sort_unstable();
        distinct.dedup();
        for id in distinct {
            let streamlines = (0..ids.len() as u32).filter(|&i| ids[i as usize] as u32 == id).collect();
            t.groups.push(Group { name: format!("cluster_{id}"), streamlines, data: Vec::new() });
        }
    }
    let dimensions = std::array::from_fn(|a| dims[a].max(0.0) as u32);
    let voxel_sizes = Some(std::array::from_fn(|a| voxel_sizes[a] as f32));
    t.space = Some(VoxelSpace { affine, dimensions, voxel_sizes });
    Ok(t)
}
