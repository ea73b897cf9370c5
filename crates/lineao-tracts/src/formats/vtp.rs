//! VTK XML PolyData (`.vtp`): `<VTKFile type="PolyData">` with `Points`, `Lines`
//! (`connectivity` + end `offsets`), `PointData` and `CellData` arrays.
//!
//! Arrays come as `format="ascii"` text, `format="binary"` base64, or `format="appended"` into an
//! `<AppendedData>` block (`encoding="raw"` bytes or `"base64"`). Binary arrays carry a header of
//! `header_type` words (UInt32 unless the file says UInt64): the byte count, or with
//! `compressor="vtkZLibDataCompressor"` the block count, block size, last block size and each
//! block's compressed size, followed by zlib blocks. VTK base64-encodes the header and the data
//! separately (padding may sit between them), older writers encode them together: both read.
//! Raw appended data is not UTF-8, so it is cut off before the XML is parsed.

use std::io::Read;

use base64::Engine;
use base64::engine::general_purpose::STANDARD;

use crate::error::{ErrorKind, Parse, bad};
use crate::input::{Limited, io_error};
use crate::tractogram::{Field, Tractogram};

pub(crate) fn sniff(head: &[u8]) -> bool {
    let text = String::from_utf8_lossy(&head[..head.len().min(512)]);
    text.trim_start().starts_with('<') && text.contains("<VTKFile")
}

struct Layout<'a> {
    little: bool,
    wide_header: bool,
    compressed: bool,
    appended: Option<(&'a [u8], bool)>, // (bytes after '_', base64?)
    limit: u64,
}

pub(crate) fn read(bytes: &[u8], limit: u64) -> Parse<Tractogram> {
    // Cut raw appended data out before parsing the XML.
    let (xml_bytes, appended) = match find(bytes, b"<AppendedData") {
        Some(start) => {
            let open_end = find(&bytes[start..], b">").map(|i| start + i + 1).ok_or(ErrorKind::Format {
                offset: start as u64,
                expected: "the end of the <AppendedData> tag".into(),
            })?;
            let tag = String::from_utf8_lossy(&bytes[start..open_end]).to_string();
            let Some(underscore) = bytes[open_end..].iter().position(|&b| b == b'_') else {
                return bad(open_end as u64, "'_' that starts the appended data");
            };
            let data_start = open_end + underscore + 1;
            let data_end = rfind(bytes, b"</AppendedData>").filter(|&e| e >= data_start).unwrap_or(bytes.len());
            let mut xml = bytes[..start].to_vec();
            xml.extend_from_slice(b"</VTKFile>");
            (xml, Some((data_start, data_end, tag.contains("base64"))))
        }
        None => (bytes.to_vec(), None),
    };
    let text = std::str::from_utf8(&xml_bytes).or_else(|e| bad(e.valid_up_to() as u64, "UTF-8 XML"))?;
    let doc = roxmltree::Document::parse(text).map_err(|e| ErrorKind::Format {
        offset: text_offset(text, e.pos()),
        expected: format!("well-formed XML ({e})"),
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "VTKFile" || root.attribute("type") != Some("PolyData") {
        return bad(0, format!("<VTKFile type=\"PolyData\">, found type {:?}", root.attribute("type")));
    }
    let layout = Layout {
        little: root.attribute("byte_order") != Some("BigEndian"),
        wide_header: root.attribute("header_type") == Some("UInt64"),
        compressed: match root.attribute("compressor") {
            None | Some("") => false,
            Some("vtkZLibDataCompressor") => true,
            Some(other) => return bad(0, format!("no compressor or vtkZLibDataCompressor, found {other}")),
        },
        appended: appended.map(|(s, e, b64)| (&bytes[s..e], b64)),
        limit,
    };
    fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
        node.children().find(|n| n.has_tag_name(name))
    }
    let Some(piece) = child(root, "PolyData").and_then(|p| child(p, "Piece")) else {
        return bad(0, "<PolyData><Piece>");
    };
    let count = |name: &str| piece.attribute(name).and_then(|v| v.parse::<usize>().ok()).unwrap_or(0);
    let n_verts = count("NumberOfVerts");
    let arrays = |section: &str| {
        child(piece, section)
            .map(|s| s.children().filter(|n| n.has_tag_name("DataArray")).collect::<Vec<_>>())
            .unwrap_or_default()
    };
    let points_node = arrays("Points").into_iter().next();
    let points: Vec<[f32; 3]> = match points_node {
        Some(node) => {
            let (values, columns) = data_array(node, &layout, text)?;
            if columns != 3 {
                return bad(node_offset(node, text), "Points with NumberOfComponents=\"3\"");
            }
            values.chunks_exact(3).map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]).collect()
        }
        None => Vec::new(),
    };
    let lines = arrays("Lines");
    let named = |name: &str| lines.iter().find(|n| n.attribute("Name") == Some(name));
    let (Some(conn), Some(offs)) = (named("connectivity"), named("offsets")) else {
        return Err(ErrorKind::NoLines(format!(
            "VTK XML PolyData with {} points, {} polygons and no Lines",
            points.len(),
            count("NumberOfPolys")
        )));
    };
    let as_index = |node: &roxmltree::Node, v: f64| -> Parse<u64> {
        if v >= 0.0 && v.fract() == 0.0 {
            Ok(v as u64)
        } else {
            bad(node_offset(*node, text), format!("non-negative indices, found {v}"))
        }
    };
    let connectivity: Vec<u64> =
        data_array(*conn, &layout, text)?.0.into_iter().map(|v| as_index(conn, v)).collect::<Parse<_>>()?;
    let mut offsets = vec![0u64];
    for v in data_array(*offs, &layout, text)?.0 {
        let o = as_index(offs, v)?;
        if o < *offsets.last().unwrap() || o as usize > connectivity.len() {
            return bad(node_offset(*offs, text), format!("non-decreasing line offsets up to {}", connectivity.len()));
        }
        offsets.push(o);
    }
    if *offsets.last().unwrap() as usize != connectivity.len() {
        return bad(node_offset(*offs, text), format!("line offsets ending at {}", connectivity.len()));
    }
    if offsets.len() == 1 {
        return Err(ErrorKind::NoLines("VTK XML PolyData with an empty Lines section".into()));
    }
    if let Some(&i) = connectivity.iter().find(|&&i| i as usize >= points.len()) {
        return bad(node_offset(*conn, text), format!("point indices below {}, found {i}", points.len()));
    }
    let n_lines = offsets.len() - 1;
    let mut t = Tractogram {
        positions: connectivity.iter().map(|&i| points[i as usize]).collect(),
        offsets,
        ..Tractogram::default()
    };
    for node in arrays("PointData") {
        let (values, columns) = data_array(node, &layout, text)?;
        if values.len() == points.len() * columns {
            let values = connectivity
                .iter()
                .flat_map(|&i| &values[i as usize * columns..(i as usize + 1) * columns])
                .map(|&v| v as f32)
                .collect();
            t.vertex_fields.push(Field { name: node.attribute("Name").unwrap_or("").to_string(), columns, values });
        }
    }
    for node in arrays("CellData") {
        let (values, columns) = data_array(node, &layout, text)?;
        let first = if values.len() == n_lines * columns { 0 } else { n_verts };
        if let Some(v) = values.get(first * columns..(first + n_lines) * columns) {
            let values = v.iter().map(|&v| v as f32).collect();
            t.streamline_fields.push(Field { name: node.attribute("Name").unwrap_or("").to_string(), columns, values });
        }
    }
    Ok(t)
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

fn rfind(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).rposition(|w| w == needle)
}

fn text_offset(text: &str, pos: roxmltree::TextPos) -> u64 {
    text.split_inclusive('\n').take(pos.row as usize - 1).map(str::len).sum::<usize>() as u64 + pos.col as u64 - 1
}

fn node_offset(node: roxmltree::Node, _text: &str) -> u64 {
    node.range().start as u64
}

/// One `<DataArray>` as f64 values and its number of components.
fn data_array(node: roxmltree::Node, layout: &Layout, text: &str) -> Parse<(Vec<f64>, usize)> {
    let at = node_offset(node, text);
    let columns = node.attribute("NumberOfComponents").and_then(|v| v.parse().ok()).unwrap_or(1usize).max(1);
    let ty = node.attribute("type").unwrap_or("Float32");
    let size = match ty {
        "Int8" | "UInt8" => 1,
        "Int16" | "UInt16" => 2,
        "Int32" | "UInt32" | "Float32" => 4,
        "Int64" | "UInt64" | "Float64" => 8,
        other => return bad(at, format!("a DataArray type such as Float32 or Int64, found '{other}'")),
    };
    let format = node.attribute("format").unwrap_or("ascii");
    let bytes = match format {
        "ascii" => {
            let values = node.text().unwrap_or("").split_ascii_whitespace().map(|w| {
                w.parse::<f64>().or_else(|_| bad(at, format!("{ty} numbers in an ascii DataArray, found '{w}'")))
            });
            return Ok((values.collect::<Parse<_>>()?, columns));
        }
        "binary" => block(Source::Base64(node.text().unwrap_or("").trim().as_bytes()), layout, at)?,
        "appended" => {
            let Some((data, b64)) = layout.appended else {
                return bad(at, "an <AppendedData> block for format=\"appended\"");
            };
            let offset = node.attribute("offset").and_then(|v| v.parse::<usize>().ok()).unwrap_or(0);
            let Some(rest) = data.get(offset..) else {
                return bad(at, format!("an appended offset inside the {} bytes of data, found {offset}", data.len()));
            };
            block(if b64 { Source::Base64(rest) } else { Source::Raw(rest) }, layout, at)?
        }
        other => return bad(at, format!("format ascii, binary or appended, found '{other}'")),
    };
    if bytes.len() % size != 0 {
        return bad(at, format!("whole {size}-byte {ty} values"));
    }
    let le = layout.little;
    let values = bytes
        .chunks_exact(size)
        .map(|c| {
            let mut a = [0u8; 8];
            a[..size].copy_from_slice(c);
            if !le {
                a[..size].reverse();
            }
            match ty {
                "Int8" => a[0] as i8 as f64,
                "UInt8" => a[0] as f64,
                "Int16" => i16::from_le_bytes([a[0], a[1]]) as f64,
                "UInt16" => u16::from_le_bytes([a[0], a[1]]) as f64,
                "Int32" => i32::from_le_bytes(a[..4].try_into().unwrap()) as f64,
                "UInt32" => u32::from_le_bytes(a[..4].try_into().unwrap()) as f64,
                "Float32" => f32::from_le_bytes(a[..4].try_into().unwrap()) as f64,
                "Int64" => i64::from_le_bytes(a) as f64,
                "UInt64" => u64::from_le_bytes(a) as f64,
                _ => f64::from_le_bytes(a),
            }
        })
        .collect();
    Ok((values, columns))
}

enum Source<'a> {
    Raw(&'a [u8]),
    Base64(&'a [u8]),
}

/// Decodes base64 `chars` (whitespace allowed) into bytes.
fn b64(chars: &[u8], at: u64) -> Parse<Vec<u8>> {
    let clean: Vec<u8> = chars.iter().copied().filter(|b| !b.is_ascii_whitespace()).collect();
    STANDARD.decode(&clean).or_else(|e| bad(at, format!("base64 data ({e})")))
}

/// The bytes of one binary array: header, then raw or zlib-compressed blocks.
fn block(src: Source, layout: &Layout, at: u64) -> Parse<Vec<u8>> {
    let word = if layout.wide_header { 8 } else { 4 };
    let get = |b: &[u8], i: usize| -> u64 {
        let mut a = [0u8; 8];
        a[..word].copy_from_slice(&b[i * word..(i + 1) * word]);
        if !layout.little {
            a[..word].reverse();
        }
        u64::from_le_bytes(a)
    };
    // First word: the byte count, or the number of compressed blocks.
    let chars_for = |n: usize| n.div_ceil(3) * 4;
    let base64_chars: Vec<u8>;
    let src = match src {
        Source::Base64(s) => {
            base64_chars = s.iter().copied().filter(|b| !b.is_ascii_whitespace()).collect();
            Source::Base64(&base64_chars)
        }
        raw => raw,
    };
    let head = |n: usize| -> Parse<Vec<u8>> {
        match &src {
            Source::Raw(r) => {
                r.get(..n).map(<[u8]>::to_vec).map_or_else(|| bad(at, format!("a {n}-byte array header")), Ok)
            }
            Source::Base64(s) => {
                let Some(chars) = s.get(..chars_for(n)) else { return bad(at, format!("a {n}-byte array header")) };
                let mut b = b64(chars, at)?;
                if b.len() < n {
                    return bad(at, format!("a {n}-byte array header"));
                }
                b.truncate(n);
                Ok(b)
            }
        }
    };
    let first = get(&head(word)?, 0);
    let header_words = if layout.compressed { 3 + first as usize } else { 1 };
    let header_bytes = header_words
        .checked_mul(word)
        .filter(|&n| n <= 1 << 30)
        .ok_or(ErrorKind::Format { offset: at, expected: format!("a sane block count, found {first}") })?;
    let available = match &src {
        Source::Raw(r) => r.len(),
        Source::Base64(s) => s.len() / 4 * 3,
    };
    if header_bytes > available {
        return bad(at, format!("a {header_bytes}-byte array header ({available} bytes left)"));
    }
    let header = head(header_bytes)?;
    let data_len: u64 = if layout.compressed { (3..header_words).map(|i| get(&header, i)).sum() } else { first };
    let data_len = usize::try_from(data_len).ok().filter(|&n| n <= available).ok_or(ErrorKind::Format {
        offset: at,
        expected: format!("an array of at most {available} bytes, header says {data_len}"),
    })?;
    let data = match &src {
        Source::Raw(r) => r[header_bytes..header_bytes + data_len].to_vec(),
        Source::Base64(s) => {
            let hc = chars_for(header_bytes);
            let separate = header_bytes % 3 == 0 || s.get(hc - 1) == Some(&b'=');
            if separate {
                let Some(chars) = s.get(hc..hc + chars_for(data_len)) else {
                    return bad(at, format!("{data_len} bytes of base64 data"));
                };
                b64(chars, at)?
            } else {
                let Some(chars) = s.get(..chars_for(header_bytes + data_len)) else {
                    return bad(at, format!("{data_len} bytes of base64 data"));
                };
                b64(chars, at)?.split_off(header_bytes)
            }
        }
    };
    if data.len() < data_len {
        return bad(at, format!("{data_len} bytes of array data, found {}", data.len()));
    }
    if !layout.compressed {
        return Ok(data);
    }
    let (blocks, block_size, last) = (first, get(&header, 1), get(&header, 2));
    let total = if blocks == 0 { 0 } else { (blocks - 1) * block_size + if last == 0 { block_size } else { last } };
    if total > layout.limit {
        return Err(ErrorKind::TooLarge { offset: at, limit: layout.limit });
    }
    let mut out = Vec::new();
    let mut pos = 0usize;
    for i in 0..blocks as usize {
        let c = get(&header, 3 + i) as usize;
        let z = flate2::read::ZlibDecoder::new(&data[pos..pos + c]);
        Limited { inner: z, left: layout.limit - out.len() as u64, limit: layout.limit }
            .read_to_end(&mut out)
            .map_err(|e| io_error(e, at, "a zlib block"))?;
        pos += c;
    }
    if out.len() as u64 != total {
        return bad(at, format!("{total} bytes from the zlib blocks, found {}", out.len()));
    }
    Ok(out)
}
