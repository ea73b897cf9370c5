//! TRX (tee-ar-ex): a zip archive (stored or deflated) or a plain directory of raw arrays.
//!
//! `header.json` (`VOXEL_TO_RASMM`, `DIMENSIONS`, `NB_VERTICES`, `NB_STREAMLINES`),
//! `positions.3.<dtype>`, `offsets.<dtype>`, and optional `dpv/`, `dps/`, `groups/`,
//! `dpg/<group>/` members named `NAME[.COLUMNS].<dtype>`, all little-endian. Every dtype reads,
//! float16 included. We trust the arrays over the header: `offsets` holds N + 1 entries (its last
//! equals the vertex count) or, in older files, only N, and the header's counts may be stale.
//! Members are found relative to `header.json`, so an archive made by zipping a folder works too.

use std::cell::RefCell;
use std::fs::File;
use std::io::{self, Read, Seek, Write};
use std::path::Path;
use std::rc::Rc;

use crate::error::{ErrorKind, Parse, bad};
use crate::input::{Limited, Reader, advise_huge_pages, io_error};
use crate::tractogram::{Field, Group, IDENTITY, Tractogram, VoxelSpace};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dtype {
    I8,
    I16,
    I32,
    I64,
    U8,
    U16,
    U32,
    U64,
    F16,
    F32,
    F64,
}

impl Dtype {
    fn parse(s: &str) -> Option<Dtype> {
        Some(match s {
            "int8" => Dtype::I8,
            "int16" => Dtype::I16,
            "int32" => Dtype::I32,
            "int64" => Dtype::I64,
            "uint8" | "bit" | "bool" => Dtype::U8,
            "uint16" => Dtype::U16,
            "uint32" => Dtype::U32,
            "uint64" => Dtype::U64,
            "float16" => Dtype::F16,
            "float32" => Dtype::F32,
            "float64" => Dtype::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Dtype::I8 | Dtype::U8 => 1,
            Dtype::I16 | Dtype::U16 | Dtype::F16 => 2,
            Dtype::I32 | Dtype::U32 | Dtype::F32 => 4,
            Dtype::I64 | Dtype::U64 | Dtype::F64 => 8,
        }
    }

    /// One little-endian value as f64 (exact for every integer a TRX offset can hold in practice).
    fn get(self, b: &[u8]) -> f64 {
        match self {
            Dtype::I8 => b[0] as i8 as f64,
            Dtype::U8 => b[0] as f64,
            Dtype::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Dtype::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Dtype::F16 => half::f16::from_le_bytes([b[0], b[1]]).to_f64(),
            Dtype::I32 => i32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            Dtype::U32 => u32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            Dtype::F32 => f32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            Dtype::I64 => i64::from_le_bytes(b[..8].try_into().unwrap()) as f64,
            Dtype::U64 => u64::from_le_bytes(b[..8].try_into().unwrap()) as f64,
            Dtype::F64 => f64::from_le_bytes(b[..8].try_into().unwrap()),
        }
    }

    /// Unsigned integer value, exact to 64 bits; `None` for floats and negatives.
    fn get_index(self, b: &[u8]) -> Option<u64> {
        match self {
            Dtype::U8 => Some(b[0] as u64),
            Dtype::U16 => Some(u16::from_le_bytes([b[0], b[1]]) as u64),
            Dtype::U32 => Some(u32::from_le_bytes(b[..4].try_into().unwrap()) as u64),
            Dtype::U64 => Some(u64::from_le_bytes(b[..8].try_into().unwrap())),
            Dtype::I8 | Dtype::I16 | Dtype::I32 | Dtype::I64 => {
                let v = self.get(b);
                (v >= 0.0).then_some(v as u64)
            }
            Dtype::F16 | Dtype::F32 | Dtype::F64 => None,
        }
    }
}

/// A member name split into `NAME`, columns and dtype: `a.b.3.float32` → (`a.b`, 3, f32).
fn split_name(file: &str) -> Option<(&str, usize, Dtype)> {
    let (rest, dtype) = file.rsplit_once('.')?;
    let dtype = Dtype::parse(dtype)?;
    match rest.rsplit_once('.') {
        Some((name, cols)) if !cols.is_empty() && cols.bytes().all(|b| b.is_ascii_digit()) => {
            Some((name, cols.parse().ok().filter(|&c| c > 0)?, dtype))
        }
        _ => Some((rest, 1, dtype)),
    }
}

/// Where members come from.
trait Members {
    /// Paths relative to the archive root, `/`-separated, files only.
    fn names(&self) -> Vec<String>;
    /// A reader for one member and its size, if known and trustworthy.
    fn open(&mut self, name: &str) -> Parse<(Box<dyn Read + '_>, Option<u64>)>;
    /// Reads an uncompressed member's bytes straight into `out` (its exact size), bypassing
    /// the zip reader's buffering and CRC pass (TRX readers map these bytes directly; so do we,
    /// in effect). False when the member is compressed.
    fn read_stored(&mut self, name: &str, out: &mut [u8]) -> Parse<bool>;
}

/// One reader shared by the zip index and our direct reads of stored members.
struct Shared<R>(Rc<RefCell<R>>);

impl<R: Read> Read for Shared<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.0.borrow_mut().read(buf)
    }
}

impl<R: Seek> Seek for Shared<R> {
    fn seek(&mut self, pos: io::SeekFrom) -> io::Result<u64> {
        self.0.borrow_mut().seek(pos)
    }
}

struct Zip<R> {
    archive: zip::ZipArchive<Shared<R>>,
    raw: Rc<RefCell<R>>,
    /// Inflated bytes left for the whole archive (bomb guard).
    budget: u64,
    limit: u64,
    file_len: u64,
}

impl<R: Read + Seek> Members for Zip<R> {
    fn names(&self) -> Vec<String> {
        self.archive.file_names().filter(|n| !n.ends_with('/')).map(str::to_string).collect()
    }

    fn open(&mut self, name: &str) -> Parse<(Box<dyn Read + '_>, Option<u64>)> {
        let file_len = self.file_len;
        let entry = self.archive.by_name(name).map_err(|e| zip_error(e, name))?;
        // A stored member's size is bounded by the file it sits in; a deflated member's is not.
        let stored = entry.compression() == zip::CompressionMethod::Stored;
        let size = (stored && entry.size() <= file_len).then_some(entry.size());
        let budget = self.budget;
        self.budget = self.budget.saturating_sub(entry.size());
        Ok((Box::new(Limited { inner: entry, left: budget, limit: self.limit }), size))
    }

    fn read_stored(&mut self, name: &str, out: &mut [u8]) -> Parse<bool> {
        let entry = self.archive.by_name(name).map_err(|e| zip_error(e, name))?;
        let (Some(start), zip::CompressionMethod::Stored) = (entry.data_start(), entry.compression()) else {
            return Ok(false);
        };
        if entry.size() != out.len() as u64 {
            return Ok(false);
        }
        drop(entry);
        let mut raw = self.raw.borrow_mut();
        raw.seek(io::SeekFrom::Start(start))?;
        raw.read_exact(out).map_err(|e| io_error(e, start, &format!("the {} bytes of '{name}'", out.len())))?;
        Ok(true)
    }
}

fn zip_error(e: zip::result::ZipError, what: &str) -> ErrorKind {
    match e {
        zip::result::ZipError::Io(e) => io_error(e, 0, what),
        other => ErrorKind::Format { offset: 0, expected: format!("a readable zip member '{what}' ({other})") },
    }
}

struct Directory<'a> {
    root: &'a Path,
}

impl Members for Directory<'_> {
    fn names(&self) -> Vec<String> {
        fn walk(dir: &Path, prefix: &str, out: &mut Vec<String>) {
            let Ok(entries) = std::fs::read_dir(dir) else { return };
            for e in entries.flatten() {
                let name = format!("{prefix}{}", e.file_name().to_string_lossy());
                if e.file_type().is_ok_and(|t| t.is_dir()) {
                    walk(&e.path(), &format!("{name}/"), out);
                } else {
                    out.push(name);
                }
            }
        }
        let mut out = Vec::new();
        walk(self.root, "", &mut out);
        out
    }

    fn open(&mut self, name: &str) -> Parse<(Box<dyn Read + '_>, Option<u64>)> {
        let f = File::open(self.root.join(name))?;
        let size = f.metadata()?.len();
        Ok((Box::new(f), Some(size)))
    }

    fn read_stored(&mut self, name: &str, out: &mut [u8]) -> Parse<bool> {
        let mut f = File::open(self.root.join(name))?;
        if f.metadata()?.len() != out.len() as u64 {
            return Ok(false);
        }
        f.read_exact(out).map_err(|e| io_error(e, 0, name))?;
        Ok(true)
    }
}

pub(crate) fn sniff(head: &[u8]) -> bool {
    head.starts_with(b"PK\x03\x04") || head.starts_with(b"PK\x05\x06")
}

/// Reads a zipped TRX.
pub(crate) fn read_zip(file: impl Read + Seek, file_len: u64, limit: u64) -> Parse<Tractogram> {
    let raw = Rc::new(RefCell::new(file));
    let archive = zip::ZipArchive::new(Shared(raw.clone())).map_err(|e| zip_error(e, "the zip directory"))?;
    read(&mut Zip { archive, raw, budget: limit, limit, file_len })
}

/// Reads a TRX directory.
pub(crate) fn read_dir(root: &Path) -> Parse<Tractogram> {
    read(&mut Directory { root })
}

fn read(m: &mut dyn Members) -> Parse<Tractogram> {
    let names = m.names();
    let Some(header_name) = names.iter().find(|n| *n == "header.json" || n.ends_with("/header.json")) else {
        let shown: Vec<&str> = names.iter().take(4).map(String::as_str).collect();
        let more = if names.len() > 4 { format!(" and {} more", names.len() - 4) } else { String::new() };
        return Err(ErrorKind::UnknownFormat(format!(
            "a zip or directory without a TRX header.json; it holds {}{more}",
            shown.join(", ")
        )));
    };
    let prefix = header_name.strip_suffix("header.json").unwrap().to_string();
    let members: Vec<String> = names.iter().filter_map(|n| n.strip_prefix(&prefix)).map(str::to_string).collect();
    let full = |rel: &str| format!("{prefix}{rel}");

    let header = read_member(m, &full("header.json"), 1 << 20)?;
    let header: serde_json::Value = serde_json::from_slice(&header)
        .map_err(|e| ErrorKind::Format { offset: e.column() as u64, expected: format!("JSON in header.json ({e})") })?;
    let space = voxel_space(&header)?;

    let find = |stem: &str| members.iter().find(|n| split_name(n).is_some_and(|(name, ..)| name == stem));
    let Some(positions_name) = find("positions") else {
        return bad(0, "a positions.3.<dtype> member in the TRX");
    };
    let (_, cols, dtype) = split_name(positions_name).unwrap();
    if cols != 3 {
        return bad(0, format!("positions with 3 columns, found {cols} in '{positions_name}'"));
    }
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let (_, size) = m.open(&full(positions_name))?;
    // A stored member's size is bounded by the file; reserve it (untouched pages cost nothing).
    positions.reserve(size.unwrap_or(0) as usize / (3 * dtype.size()));
    // Stored float32: the member's bytes are the points (little-endian), read straight in.
    let direct = dtype == Dtype::F32 && size.is_some_and(|s| s % 12 == 0) && {
        // vec! of zeros is calloc: fresh pages, no memset, so huge pages can still back them.
        positions = vec![[0.0; 3]; size.unwrap() as usize / 12];
        advise_huge_pages(bytemuck::cast_slice_mut(&mut positions));
        let done = m.read_stored(&full(positions_name), bytemuck::cast_slice_mut(&mut positions))?;
        if !done {
            positions.clear();
        }
        done
    };
    if direct {
        #[cfg(target_endian = "big")]
        for c in positions.iter_mut().flatten() {
            *c = f32::from_bits(c.to_bits().swap_bytes());
        }
    } else if dtype == Dtype::F32 {
        // The common case, decoded without going through f64 rows.
        let f = |b: &[u8]| f32::from_le_bytes(b[..4].try_into().unwrap());
        raw_values(m, &full(positions_name), 12, |b| positions.push([f(b), f(&b[4..]), f(&b[8..])]))?;
    } else {
        array(m, &full(positions_name), dtype, 3, |row| positions.push([row[0] as f32, row[1] as f32, row[2] as f32]))?;
    }
    let vertices = positions.len() as u64;

    let offsets = match find("offsets") {
        Some(name) => {
            let (_, _, dtype) = split_name(name).unwrap();
            let mut raw = Vec::new();
            raw_values(m, &full(name), dtype.size(), |b| raw.push(dtype.get_index(b)))?;
            to_offsets(raw, vertices, name)?
        }
        None if vertices == 0 => vec![0],
        None => return bad(0, "an offsets.<dtype> member in the TRX"),
    };
    let mut t = Tractogram { positions, offsets, space, ..Tractogram::default() };
    let n = t.streamlines();

    for rel in &members {
        let Some((dir, file)) = rel.rsplit_once('/') else { continue };
        let Some((name, columns, dtype)) = split_name(file) else { continue };
        let name = name.trim_end().to_string();
        match dir {
            "dpv" | "dps" => {
                let rows = if dir == "dpv" { t.vertices() } else { n };
                let values = field(m, &full(rel), dtype, columns, rows, rel)?;
                let f = Field { name, columns, values };
                if dir == "dpv" { t.vertex_fields.push(f) } else { t.streamline_fields.push(f) }
            }
            "groups" => {
                let mut streamlines = Vec::new();
                let mut bad_index = None;
                raw_values(m, &full(rel), dtype.size(), |b| match dtype.get_index(b) {
                    Some(i) if i < n as u64 => streamlines.push(i as u32),
                    other => bad_index = bad_index.or(Some(other)),
                })?;
                if let Some(i) = bad_index {
                    return bad(0, format!("streamline indices below {n} in '{rel}', found {i:?}"));
                }
                t.groups.push(Group { name, streamlines, data: Vec::new() });
            }
            _ => {}
        }
    }
    // dpg/<group>/<name>: attach after every group is known.
    for rel in &members {
        let mut parts = rel.splitn(3, '/');
        let (Some("dpg"), Some(group), Some(file)) = (parts.next(), parts.next(), parts.next()) else { continue };
        let Some((name, columns, dtype)) = split_name(file) else { continue };
        let mut values = Vec::new();
        array(m, &full(rel), dtype, columns, |row| values.extend(row.iter().map(|&v| v as f32)))?;
        let field = Field { name: name.trim_end().to_string(), columns, values };
        match t.groups.iter_mut().find(|g| g.name == group) {
            Some(g) => g.data.push(field),
            None => t.groups.push(Group { name: group.to_string(), streamlines: Vec::new(), data: vec![field] }),
        }
    }
    t.vertex_fields.sort_by(|a, b| a.name.cmp(&b.name));
    t.streamline_fields.sort_by(|a, b| a.name.cmp(&b.name));
    t.groups.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(t)
}

fn voxel_space(header: &serde_json::Value) -> Parse<Option<VoxelSpace>> {
    let Some(m) = header.get("VOXEL_TO_RASMM") else { return Ok(None) };
    let mut affine = IDENTITY;
    let rows = m.as_array().filter(|r| r.len() == 4);
    for (r, row) in rows.into_iter().flatten().enumerate() {
        let row = row.as_array().filter(|c| c.len() == 4);
        for (c, v) in row.into_iter().flatten().enumerate() {
            affine[r][c] = v.as_f64().unwrap_or(f64::NAN);
        }
    }
    if affine.iter().flatten().any(|v| !v.is_finite()) || m.as_array().is_none_or(|r| r.len() != 4) {
        return bad(0, "VOXEL_TO_RASMM as 4 rows of 4 numbers in header.json");
    }
    let dims = header.get("DIMENSIONS").and_then(|d| d.as_array()).filter(|d| d.len() == 3);
    let dimensions = match dims {
        Some(d) => {
            let v: Vec<u32> = d.iter().filter_map(|x| x.as_u64()).map(|x| x.min(u32::MAX as u64) as u32).collect();
            if v.len() != 3 {
                return bad(0, "DIMENSIONS as 3 non-negative integers in header.json");
            }
            [v[0], v[1], v[2]]
        }
        None => [0; 3],
    };
    Ok(Some(VoxelSpace { affine, dimensions, voxel_sizes: None }))
}

/// Raw offsets → N + 1 checked offsets. N entries (older files) get the vertex count appended.
fn to_offsets(raw: Vec<Option<u64>>, vertices: u64, name: &str) -> Parse<Vec<u64>> {
    let mut offsets = Vec::with_capacity(raw.len() + 1);
    for (i, v) in raw.into_iter().enumerate() {
        match v {
            Some(v) if v <= vertices && offsets.last().is_none_or(|&l| v >= l) && (i > 0 || v == 0) => offsets.push(v),
            other => {
                return bad(
                    0,
                    format!("in '{name}' entry {i}: non-decreasing offsets from 0 up to {vertices}, found {other:?}"),
                );
            }
        }
    }
    // N + 1 form ends at the vertex count; N form does not (unless its last streamline is empty,
    // which the two forms cannot tell apart: we read it as N + 1, as trx-python does).
    if offsets.last() != Some(&vertices) || offsets.is_empty() {
        offsets.push(vertices);
    }
    Ok(offsets)
}

fn read_member(m: &mut dyn Members, name: &str, max: u64) -> Parse<Vec<u8>> {
    let (r, _) = m.open(name)?;
    let mut out = Vec::new();
    r.take(max + 1).read_to_end(&mut out).map_err(|e| io_error(e, 0, name))?;
    if out.len() as u64 > max {
        return bad(max, format!("'{name}' of at most {max} bytes"));
    }
    Ok(out)
}

/// Streams one member's elements (each `dtype.size()` bytes) to `each`.
fn raw_values(m: &mut dyn Members, name: &str, size: usize, mut each: impl FnMut(&[u8])) -> Parse<()> {
    let (inner, _) = m.open(name)?;
    let mut r = Reader::new(inner);
    loop {
        let at = r.offset();
        let piece = r.take_up_to(Reader::CHUNK / size * size).map_err(|e| member(e, name))?;
        if piece.is_empty() {
            return Ok(());
        }
        if piece.len() % size != 0 {
            return bad(at + piece.len() as u64, format!("in '{name}': whole {size}-byte values"));
        }
        piece.chunks_exact(size).for_each(&mut each);
    }
}

/// Streams rows of `columns` values (as f64) to `each`.
fn array(m: &mut dyn Members, name: &str, dtype: Dtype, columns: usize, mut each: impl FnMut(&[f64])) -> Parse<()> {
    let mut row = Vec::with_capacity(columns.min(1 << 16));
    raw_values(m, name, dtype.size(), |b| {
        row.push(dtype.get(b));
        if row.len() == columns {
            each(&row);
            row.clear();
        }
    })?;
    if !row.is_empty() {
        return bad(0, format!("in '{name}': whole rows of {columns} values"));
    }
    Ok(())
}

fn field(m: &mut dyn Members, name: &str, dtype: Dtype, columns: usize, rows: usize, rel: &str) -> Parse<Vec<f32>> {
    let mut values = Vec::new();
    array(m, name, dtype, columns, |row| values.extend(row.iter().map(|&v| v as f32)))?;
    if values.len() != rows * columns {
        return bad(0, format!("'{rel}' with {rows} rows of {columns}, found {} values", values.len()));
    }
    Ok(values)
}

/// Names the member in a format error.
fn member(e: ErrorKind, name: &str) -> ErrorKind {
    match e {
        ErrorKind::Format { offset, expected } => {
            ErrorKind::Format { offset, expected: format!("in '{name}': {expected}") }
        }
        other => other,
    }
}

/// Writes a TRX zip with stored (uncompressed) members: float32 positions and fields, uint64
/// N + 1 offsets, uint32 groups.
pub fn write<W: Write + Seek>(t: &Tractogram, out: W) -> io::Result<()> {
    let mut zip = zip::ZipWriter::new(out);
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .large_file(t.positions.len() as u64 * 12 >= u32::MAX as u64);
    let space = t.space.unwrap_or(VoxelSpace { affine: IDENTITY, dimensions: [1, 1, 1], voxel_sizes: None });
    let header = serde_json::json!({
        "VOXEL_TO_RASMM": space.affine,
        "DIMENSIONS": space.dimensions,
        "NB_VERTICES": t.vertices(),
        "NB_STREAMLINES": t.streamlines(),
    });
    let zerr = |e: zip::result::ZipError| io::Error::other(e);
    zip.start_file("header.json", opts).map_err(zerr)?;
    zip.write_all(header.to_string().as_bytes())?;
    let put = |zip: &mut zip::ZipWriter<W>, name: String, bytes: &mut dyn Iterator<Item = [u8; 4]>| -> io::Result<()> {
        zip.start_file(name, opts).map_err(zerr)?;
        let mut buf = Vec::with_capacity(1 << 20);
        for b in bytes {
            buf.extend_from_slice(&b);
            if buf.len() >= 1 << 20 {
                zip.write_all(&buf)?;
                buf.clear();
            }
        }
        zip.write_all(&buf)
    };
    put(&mut zip, "positions.3.float32".into(), &mut t.positions.iter().flatten().map(|v| v.to_le_bytes()))?;
    zip.start_file("offsets.uint64", opts).map_err(zerr)?;
    for chunk in t.offsets.chunks(1 << 17) {
        let bytes: Vec<u8> = chunk.iter().flat_map(|o| o.to_le_bytes()).collect();
        zip.write_all(&bytes)?;
    }
    let fname = |dir: &str, f: &Field| match f.columns {
        1 => format!("{dir}/{}.float32", f.name),
        c => format!("{dir}/{}.{c}.float32", f.name),
    };
    for f in &t.vertex_fields {
        put(&mut zip, fname("dpv", f), &mut f.values.iter().map(|v| v.to_le_bytes()))?;
    }
    for f in &t.streamline_fields {
        put(&mut zip, fname("dps", f), &mut f.values.iter().map(|v| v.to_le_bytes()))?;
    }
    for g in &t.groups {
        put(&mut zip, format!("groups/{}.uint32", g.name), &mut g.streamlines.iter().map(|v| v.to_le_bytes()))?;
        for f in &g.data {
            put(&mut zip, fname(&format!("dpg/{}", g.name), f), &mut f.values.iter().map(|v| v.to_le_bytes()))?;
        }
    }
    zip.finish().map_err(zerr)?;
    Ok(())
}

/// Used by the loader to decide between file and directory.
pub(crate) fn is_trx_dir(path: &Path) -> bool {
    path.is_dir() && path.join("header.json").is_file()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn member_names_split_from_the_right() {
        assert_eq!(split_name("positions.3.float16"), Some(("positions", 3, Dtype::F16)));
        assert_eq!(split_name("effect   .float32"), Some(("effect   ", 1, Dtype::F32)));
        assert_eq!(split_name("a.b.4.uint8"), Some(("a.b", 4, Dtype::U8)));
        assert_eq!(split_name("x.0.float32"), None);
        assert_eq!(split_name("x.float128"), None);
    }

    #[test]
    fn offsets_of_either_length() {
        let some = |v: &[u64]| v.iter().map(|&x| Some(x)).collect::<Vec<_>>();
        assert_eq!(to_offsets(some(&[0, 2, 5]), 9, "o").unwrap(), vec![0, 2, 5, 9]);
        assert_eq!(to_offsets(some(&[0, 2, 5, 9]), 9, "o").unwrap(), vec![0, 2, 5, 9]);
        assert!(to_offsets(some(&[0, 5, 2]), 9, "o").is_err());
        assert!(to_offsets(some(&[1, 5]), 9, "o").is_err());
        assert!(to_offsets(some(&[0, 10]), 9, "o").is_err());
    }
}
