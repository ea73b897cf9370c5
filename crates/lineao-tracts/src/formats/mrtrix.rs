//! MRtrix `.tck` (track points) and `.tsf` (track scalar file).
//!
//! A text header — the magic line `mrtrix tracks` (or `mrtrix track scalars`), then `key: value`
//! lines, then `END` — followed at `file: . OFFSET` by raw triplets (tck) or single values (tsf)
//! of `datatype` Float32/Float64, LE/BE. A NaN (any NaN bit pattern: MATLAB writes 0xFFC00000)
//! ends a streamline; an Inf of either sign ends the data. Writers in the wild leave out the final
//! Inf or the count (`count` is unreliable), so we trust only the data: the end of the file ends
//! the last streamline too. Keys may repeat (`command_history` over several lines): their values
//! are joined with a newline, as nibabel and MRtrix do.

use std::io::{self, Write};

use crate::error::{Parse, bad};
use crate::input::{Endian, Reader, read_rest_as_points};
use crate::tractogram::{Field, Tractogram};

/// The header: keys in file order, repeated keys joined by `\n`.
#[derive(Clone, Debug, Default)]
pub struct Header {
    /// The header's `key: value` lines, in file order (a key may repeat).
    pub fields: Vec<(String, String)>,
    /// Whether the file holds track scalars (`.tsf`) rather than tracks (`.tck`).
    pub scalars: bool,
}

impl Header {
    /// The first value of `key`, if the header has it.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.fields.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }
}

const MAGIC_TRACKS: &str = "mrtrix tracks";
const MAGIC_SCALARS: &str = "mrtrix track scalars";
const MAX_HEADER_LINE: usize = 1 << 16;

/// True when `head` starts like a tck (false) or tsf (true) file.
pub(crate) fn sniff(head: &[u8]) -> Option<bool> {
    let first = head.split(|&b| b == b'\n').next()?;
    let first = std::str::from_utf8(first).ok()?.trim_end();
    match first {
        MAGIC_TRACKS => Some(false),
        MAGIC_SCALARS => Some(true),
        _ => None,
    }
}

pub(crate) fn read_header(r: &mut Reader) -> Parse<Header> {
    let magic_at = r.offset();
    let magic = r.line(MAX_HEADER_LINE, "the magic line 'mrtrix tracks'")?.unwrap_or_default();
    let magic = String::from_utf8_lossy(magic);
    let scalars = match magic.trim_end() {
        MAGIC_TRACKS => false,
        MAGIC_SCALARS => true,
        other => {
            let shown: String = other.chars().take(40).collect();
            return bad(magic_at, format!("the magic line 'mrtrix tracks' or 'mrtrix track scalars', found '{shown}'"));
        }
    };
    let mut header = Header { fields: Vec::new(), scalars };
    let mut last_key: Option<String> = None;
    loop {
        let at = r.offset();
        let Some(line) = r.line(MAX_HEADER_LINE, "a header line")? else {
            return bad(at, "the header's END line");
        };
        let line = String::from_utf8_lossy(line);
        let line = line.trim();
        if line == "END" {
            return Ok(header);
        }
        if line.is_empty() {
            continue;
        }
        let Some((key, value)) = line.split_once(':') else {
            // A line without a key continues the previous key's value (multi-line fields).
            match header.fields.iter_mut().find(|(k, _)| Some(k) == last_key.as_ref()) {
                Some((_, v)) => {
                    v.push('\n');
                    v.push_str(line);
                    continue;
                }
                None => {
                    return bad(
                        at,
                        format!("'key: value' or END, found '{}'", line.chars().take(40).collect::<String>()),
                    );
                }
            }
        };
        let (key, value) = (key.trim().to_string(), value.trim().to_string());
        last_key = Some(key.clone());
        match header.fields.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => {
                v.push('\n');
                v.push_str(&value);
            }
            None => header.fields.push((key, value)),
        }
    }
}

/// `datatype` → (bytes per value, byte order).
pub(crate) fn datatype(header: &Header, at: u64) -> Parse<(usize, Endian)> {
    match header.get("datatype").map(str::trim) {
        Some("Float32LE") => Ok((4, Endian::Little)),
        Some("Float32BE") => Ok((4, Endian::Big)),
        Some("Float64LE") => Ok((8, Endian::Little)),
        Some("Float64BE") => Ok((8, Endian::Big)),
        Some(other) => bad(at, format!("datatype Float32LE, Float32BE, Float64LE or Float64BE, found '{other}'")),
        None => bad(at, "a 'datatype' key in the header"),
    }
}

/// Reads a `.tck` or `.tsf` from the magic line on.
pub(crate) fn read(r: &mut Reader, size_hint: Option<u64>) -> Parse<(Tractogram, bool)> {
    let header = read_header(r)?;
    let header_end = r.offset();
    let (width, endian) = datatype(&header, header_end)?;
    // `file: . OFFSET`: the data may start anywhere after the header; seek, don't assume.
    let data_at = data_offset(&header, header_end)?;
    r.skip(data_at - header_end, "the padding before the data offset")?;

    let layout = (width, header.scalars);
    let mut t = Tractogram::new();
    let mut values = Vec::new();
    match (size_hint, header.scalars) {
        // A plain .tck: read the data into the points' storage and decode it in place.
        (Some(len), false) => {
            let data_at = r.offset();
            let (mut points, got) = read_rest_as_points(r, len)?;
            let bytes = bytemuck::cast_slice_mut::<[f32; 3], u8>(&mut points);
            let kept = match (width, endian) {
                (4, Endian::Little) => {
                    in_place(bytes, got, data_at, 4, &mut t.offsets, |b| f32::from_le_bytes(b[..4].try_into().unwrap()))
                }
                (4, Endian::Big) => {
                    in_place(bytes, got, data_at, 4, &mut t.offsets, |b| f32::from_be_bytes(b[..4].try_into().unwrap()))
                }
                (_, Endian::Little) => in_place(bytes, got, data_at, 8, &mut t.offsets, |b| {
                    f64::from_le_bytes(b[..8].try_into().unwrap()) as f32
                }),
                (_, Endian::Big) => in_place(bytes, got, data_at, 8, &mut t.offsets, |b| {
                    f64::from_be_bytes(b[..8].try_into().unwrap()) as f32
                }),
            }?;
            points.truncate(kept);
            points.shrink_to_fit();
            t.positions = points;
        }
        _ => match (width, endian) {
            (4, Endian::Little) => {
                stream(r, layout, &mut t, &mut values, |b| f32::from_le_bytes(b[..4].try_into().unwrap()))
            }
            (4, Endian::Big) => {
                stream(r, layout, &mut t, &mut values, |b| f32::from_be_bytes(b[..4].try_into().unwrap()))
            }
            (_, Endian::Little) => {
                stream(r, layout, &mut t, &mut values, |b| f64::from_le_bytes(b[..8].try_into().unwrap()) as f32)
            }
            (_, Endian::Big) => {
                stream(r, layout, &mut t, &mut values, |b| f64::from_be_bytes(b[..8].try_into().unwrap()) as f32)
            }
        }?,
    }
    if header.scalars {
        t.vertex_fields.push(Field { name: "tsf".into(), columns: 1, values });
    }
    Ok((t, header.scalars))
}

/// What a file that ends inside an element of `element` bytes lacks.
pub(crate) fn truncated_element(element: usize, scalars: bool) -> String {
    let what = if scalars { "element" } else { "point" };
    format!("a whole {element}-byte {what} (the file ends inside one)")
}

/// The `file: . OFFSET` of a header ending at `header_end`: where the data starts.
pub(crate) fn data_offset(header: &Header, header_end: u64) -> Parse<u64> {
    match header.get("file") {
        None => Ok(header_end),
        Some(file) => {
            let mut parts = file.split_whitespace();
            let (Some("."), Some(offset), None) = (parts.next(), parts.next(), parts.next()) else {
                return bad(header_end, format!("'file: . OFFSET' (data in this file), found 'file: {file}'"));
            };
            let Ok(offset) = offset.parse::<u64>() else {
                return bad(header_end, format!("a byte offset after 'file: .', found '{offset}'"));
            };
            if offset < header_end {
                return bad(
                    header_end,
                    format!("a data offset at or after the header's end ({header_end}), found {offset}"),
                );
            }
            Ok(offset)
        }
    }
}

/// Decodes the triplets in `bytes[..got]` in place (point w goes to bytes 12w..12w + 12, never
/// ahead of the triplet being read) until an Inf or the end; returns the number of points.
/// `data_at` is the file offset of `bytes[0]`, for errors.
fn in_place(
    bytes: &mut [u8],
    got: usize,
    data_at: u64,
    width: usize,
    offsets: &mut Vec<u64>,
    decode: impl Fn(&[u8]) -> f32,
) -> Parse<usize> {
    let element = 3 * width;
    let mut kept = 0usize;
    let mut at = 0usize;
    while at + element <= got {
        let e = &bytes[at..at + element];
        let x = decode(e);
        if x.is_nan() {
            offsets.push(kept as u64);
        } else if x.is_infinite() {
            at = got; // the terminator: ignore whatever follows
            break;
        } else {
            let p = [x, decode(&e[width..]), decode(&e[2 * width..])];
            bytes[12 * kept..12 * kept + 12].copy_from_slice(bytemuck::bytes_of(&p));
            kept += 1;
        }
        at += element;
    }
    if at < got {
        return bad(data_at + at as u64, truncated_element(element, false));
    }
    if *offsets.last().unwrap() != kept as u64 {
        offsets.push(kept as u64);
    }
    Ok(kept)
}

/// Decodes elements until an Inf or the end of the file. Monomorphised per datatype so the
/// inner loop is a plain load, compare and push.
fn stream(
    r: &mut Reader,
    (width, scalars): (usize, bool),
    t: &mut Tractogram,
    values: &mut Vec<f32>,
    decode: impl Fn(&[u8]) -> f32,
) -> Parse<()> {
    let element = if scalars { width } else { 3 * width };
    let per_piece = Reader::CHUNK / element * element;
    let mut count = 0u64;
    'data: loop {
        let piece_at = r.offset();
        let piece = r.take_up_to(per_piece)?;
        if piece.is_empty() {
            break;
        }
        if piece.len() % element != 0 {
            let at = piece_at + (piece.len() / element * element) as u64;
            return bad(at, truncated_element(element, scalars));
        }
        for e in piece.chunks_exact(element) {
            let x = decode(e);
            if x.is_nan() {
                t.offsets.push(count);
            } else if x.is_infinite() {
                break 'data;
            } else {
                if scalars {
                    values.push(x);
                } else {
                    t.positions.push([x, decode(&e[width..]), decode(&e[2 * width..])]);
                }
                count += 1;
            }
        }
    }
    // A missing NaN before the Inf, or a missing Inf: the data still ends the last streamline.
    if *t.offsets.last().unwrap() != count {
        t.offsets.push(count);
    }
    Ok(())
}

/// Writes a `.tck` (Float32LE): header, points, a NaN triplet after each streamline, an Inf
/// triplet at the end.
pub fn write_tck(t: &Tractogram, out: &mut dyn Write) -> io::Result<()> {
    write_header(out, MAGIC_TRACKS, t.streamlines())?;
    let mut buf = Vec::with_capacity(1 << 20);
    for i in 0..t.streamlines() {
        for p in t.streamline(i) {
            for c in p {
                buf.extend_from_slice(&c.to_le_bytes());
            }
            if buf.len() >= 1 << 20 {
                out.write_all(&buf)?;
                buf.clear();
            }
        }
        buf.extend_from_slice(&[f32::NAN.to_le_bytes(); 3].concat());
    }
    buf.extend_from_slice(&[f32::INFINITY.to_le_bytes(); 3].concat());
    out.write_all(&buf)
}

fn write_header(out: &mut dyn Write, magic: &str, count: usize) -> io::Result<()> {
    let body = format!("{magic}\ncount: {count:010}\ndatatype: Float32LE\nfile: . ");
    // The offset names itself: pick the smallest that holds the header, its own digits and END.
    let mut offset = body.len() + "\nEND\n".len() + 1;
    while body.len() + offset.to_string().len() + "\nEND\n".len() > offset {
        offset += 1;
    }
    let text = format!("{body}{offset}\nEND\n");
    out.write_all(text.as_bytes())?;
    out.write_all(&vec![0u8; offset - text.len()])
}
