//! VTK legacy PolyData (`# vtk DataFile Version 2.0–5.1`), ASCII or binary (binary is big-endian).
//!
//! `POINTS n type`, then the cells: before 5.0 `LINES n size` with `size` integers
//! `k i₀ … iₖ₋₁` per cell; from 5.0 `LINES n_offsets n_conn` followed by `OFFSETS type` and
//! `CONNECTIVITY type` arrays. Each line cell becomes a streamline whose points are looked up
//! through the connectivity. `POINT_DATA`/`CELL_DATA` `SCALARS`, `VECTORS`, `NORMALS`,
//! `COLOR_SCALARS` and `FIELD` arrays are kept as data (cell data of the line cells only);
//! `METADATA` blocks are skipped. A file with points but no line cells (a polygon mesh) is a
//! `NoLines` error, never a tractogram made of polygon edges.

use crate::error::{ErrorKind, Parse, bad};
use crate::tractogram::{Field, Tractogram};

pub(crate) fn sniff(head: &[u8]) -> bool {
    head.starts_with(b"# vtk DataFile")
}

/// A cursor over the whole file: words for the ASCII parts, raw bytes for binary arrays.
struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
    binary: bool,
}

impl<'a> Cursor<'a> {
    fn skip_space(&mut self) {
        while self.at < self.b.len() && self.b[self.at].is_ascii_whitespace() {
            self.at += 1;
        }
    }

    fn word(&mut self) -> Option<&'a str> {
        self.skip_space();
        let start = self.at;
        while self.at < self.b.len() && !self.b[self.at].is_ascii_whitespace() {
            self.at += 1;
        }
        (self.at > start).then(|| std::str::from_utf8(&self.b[start..self.at]).unwrap_or("?"))
    }

    fn need(&mut self, expected: &str) -> Parse<&'a str> {
        self.skip_space();
        let at = self.at as u64;
        self.word().map_or_else(|| bad(at, expected.to_string()), Ok)
    }

    fn number<T: std::str::FromStr>(&mut self, expected: &str) -> Parse<T> {
        self.skip_space();
        let at = self.at as u64;
        let w = self.need(expected)?;
        w.parse().or_else(|_| bad(at, format!("{expected}, found '{}'", w.chars().take(30).collect::<String>())))
    }

    fn rest_of_line(&mut self) -> &'a str {
        let start = self.at;
        while self.at < self.b.len() && self.b[self.at] != b'\n' {
            self.at += 1;
        }
        let line = std::str::from_utf8(&self.b[start..self.at]).unwrap_or("");
        self.at = (self.at + 1).min(self.b.len());
        line
    }

    /// `count` values of VTK type `ty` as f64 (ASCII words or big-endian binary).
    fn values(&mut self, ty: &str, count: usize, what: &str) -> Parse<Vec<f64>> {
        let size = match ty.to_ascii_lowercase().as_str() {
            "char" | "unsigned_char" | "vtktypeint8" | "vtktypeuint8" => 1,
            "short" | "unsigned_short" | "vtktypeint16" | "vtktypeuint16" => 2,
            "int" | "unsigned_int" | "float" | "vtktypeint32" | "vtktypeuint32" | "vtktypefloat32" => 4,
            "long" | "unsigned_long" | "double" | "vtkidtype" | "vtktypeint64" | "vtktypeuint64" | "vtktypefloat64" => {
                8
            }
            other => return bad(self.at as u64, format!("a VTK data type for {what}, found '{other}'")),
        };
        if !self.binary {
            // Each value needs at least two bytes of text: bound the allocation by the file.
            let mut out = Vec::with_capacity(count.min((self.b.len() - self.at) / 2 + 1));
            for _ in 0..count {
                out.push(self.number::<f64>(&format!("{count} {ty} values for {what}"))?);
            }
            return Ok(out);
        }
        // Binary data starts after the keyword line's newline.
        let start = self.at;
        let Some(end) = count.checked_mul(size).and_then(|n| n.checked_add(start)).filter(|&e| e <= self.b.len())
        else {
            return bad(
                start as u64,
                format!("{count} binary {ty} values for {what} ({} bytes left)", self.b.len() - start),
            );
        };
        let lower = ty.to_ascii_lowercase();
        let signed = !lower.starts_with("unsigned") && !lower.contains("uint");
        let float = lower.contains("float") || lower == "double";
        let out = self.b[start..end]
            .chunks_exact(size)
            .map(|c| match (size, float, signed) {
                (4, true, _) => f32::from_be_bytes(c.try_into().unwrap()) as f64,
                (8, true, _) => f64::from_be_bytes(c.try_into().unwrap()),
                (1, _, true) => c[0] as i8 as f64,
                (1, _, false) => c[0] as f64,
                (2, _, true) => i16::from_be_bytes(c.try_into().unwrap()) as f64,
                (2, _, false) => u16::from_be_bytes(c.try_into().unwrap()) as f64,
                (4, _, true) => i32::from_be_bytes(c.try_into().unwrap()) as f64,
                (4, _, false) => u32::from_be_bytes(c.try_into().unwrap()) as f64,
                (_, _, true) => i64::from_be_bytes(c.try_into().unwrap()) as f64,
                (_, _, false) => u64::from_be_bytes(c.try_into().unwrap()) as f64,
            })
            .collect();
        self.at = end;
        Ok(out)
    }

    /// After a binary block: the next keyword line may follow directly or after a newline.
    fn at_end(&mut self) -> bool {
        self.skip_space();
        self.at >= self.b.len()
    }
}

/// Cells as (offsets, connectivity), the same in both layouts.
struct Cells {
    offsets: Vec<u64>,
    connectivity: Vec<u64>,
}

fn cells(c: &mut Cursor, version: f32, what: &str) -> Parse<Cells> {
    let at = c.at as u64;
    let n: usize = c.number(&format!("the number of {what} cells"))?;
    let size: usize = c.number(&format!("the size of the {what} cell list"))?;
    c.rest_of_line();
    let index = |v: f64, at: usize| -> Parse<u64> {
        if v >= 0.0 && v.fract() == 0.0 {
            Ok(v as u64)
        } else {
            bad(at as u64, format!("a non-negative index, found {v}"))
        }
    };
    if version >= 5.0 {
        // n = number of offsets (cells + 1), size = connectivity length.
        let mut read = |key: &str, count: usize| -> Parse<Vec<u64>> {
            let kat = c.at as u64;
            let k = c.need(key)?;
            if !k.eq_ignore_ascii_case(key) {
                return bad(kat, format!("{key}, found '{k}'"));
            }
            let ty = c.need("a data type")?;
            c.rest_of_line();
            let start = c.at;
            c.values(ty, count, key)?.into_iter().map(|v| index(v, start)).collect()
        };
        let offsets = read("OFFSETS", n)?;
        let connectivity = read("CONNECTIVITY", size)?;
        let ok = offsets.first().is_none_or(|&o| o == 0)
            && offsets.windows(2).all(|w| w[0] <= w[1])
            && offsets.last().is_none_or(|&o| o as usize == connectivity.len());
        if !ok {
            return bad(at, format!("{what} offsets from 0, non-decreasing, ending at {}", connectivity.len()));
        }
        let offsets = if offsets.is_empty() { vec![0] } else { offsets };
        return Ok(Cells { offsets, connectivity });
    }
    let start = c.at;
    let raw = c.values("int", size, what)?;
    let mut offsets = vec![0u64];
    let mut connectivity = Vec::with_capacity(raw.len());
    let mut i = 0;
    for _ in 0..n {
        let Some(&k) = raw.get(i) else {
            return bad(start as u64, format!("{n} {what} cells in {size} integers"));
        };
        let k = index(k, start)? as usize;
        let Some(ids) = raw.get(i + 1..i + 1 + k) else {
            return bad(start as u64, format!("{k} point indices in {what} cell"));
        };
        for &v in ids {
            connectivity.push(index(v, start)?);
        }
        offsets.push(connectivity.len() as u64);
        i += 1 + k;
    }
    Ok(Cells { offsets, connectivity })
}

pub(crate) fn read(b: &[u8]) -> Parse<Tractogram> {
    let mut c = Cursor { b, at: 0, binary: false };
    let first = c.rest_of_line();
    let version: f32 = first.rsplit(' ').next().and_then(|v| v.trim().parse().ok()).unwrap_or(3.0);
    // The title line; writers such as MRtrix's tckconvert may leave it out, the version line
    // then being followed directly by ASCII or BINARY (a title that reads "ASCII" is told apart
    // by the format line after it).
    let is_format = |line: &str| ["ASCII", "BINARY"].iter().any(|f| line.trim().eq_ignore_ascii_case(f));
    let title_at = c.at;
    let title = c.rest_of_line();
    let after_title = c.at;
    let next = c.rest_of_line();
    c.at = if is_format(title) && !is_format(next) { title_at } else { after_title };
    let fmt_at = c.at as u64;
    c.binary = match c.need("ASCII or BINARY")?.to_ascii_uppercase().as_str() {
        "ASCII" => false,
        "BINARY" => true,
        other => return bad(fmt_at, format!("ASCII or BINARY, found '{other}'")),
    };
    let ds_at = c.at as u64;
    let (kw, ty) = (c.need("DATASET")?, c.need("a dataset type")?);
    if !kw.eq_ignore_ascii_case("DATASET") || !ty.eq_ignore_ascii_case("POLYDATA") {
        return bad(ds_at, format!("DATASET POLYDATA, found '{kw} {ty}'"));
    }
    let mut points: Vec<[f32; 3]> = Vec::new();
    let mut lines: Option<Cells> = None;
    let mut cells_before_lines = 0usize; // VERTICES come before LINES in CELL_DATA order
    let mut other_cells = 0usize;
    let mut vertex_fields = Vec::new();
    let mut streamline_fields = Vec::new();
    let mut attach: Option<(bool, usize)> = None; // (point data?, count)
    while !c.at_end() {
        let at = c.at as u64;
        let key = c.need("a keyword")?.to_ascii_uppercase();
        match key.as_str() {
            "POINTS" => {
                let n: usize = c.number("the number of points")?;
                let ty = c.need("the points' data type")?;
                c.rest_of_line();
                let v = c.values(ty, n.saturating_mul(3), "POINTS")?;
                points = v.chunks_exact(3).map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]).collect();
            }
            "LINES" => lines = Some(cells(&mut c, version, "LINES")?),
            "VERTICES" | "POLYGONS" | "TRIANGLE_STRIPS" => {
                let cs = cells(&mut c, version, &key)?;
                let count = cs.offsets.len() - 1;
                if key == "VERTICES" {
                    cells_before_lines += count;
                } else {
                    other_cells += count;
                }
            }
            "METADATA" => {
                // Ends at the first empty line.
                c.rest_of_line();
                while c.at < c.b.len() && !c.rest_of_line().trim().is_empty() {}
            }
            "POINT_DATA" | "CELL_DATA" => {
                let n: usize = c.number("the number of data tuples")?;
                attach = Some((key == "POINT_DATA", n));
            }
            "SCALARS" | "VECTORS" | "NORMALS" | "COLOR_SCALARS" | "TEXTURE_COORDINATES" | "TENSORS" => {
                let Some((point, n)) = attach else {
                    return bad(at, format!("POINT_DATA or CELL_DATA before {key}"));
                };
                let name = c.need("the array's name")?.to_string();
                let line = c.rest_of_line();
                let mut words = line.split_whitespace();
                let (ty, columns) = match key.as_str() {
                    "SCALARS" => {
                        (words.next().unwrap_or("float"), words.next().and_then(|w| w.parse().ok()).unwrap_or(1))
                    }
                    "COLOR_SCALARS" => ("unsigned_char", line.trim().parse().unwrap_or(1)),
                    "TEXTURE_COORDINATES" => {
                        let d = words.next().and_then(|w| w.parse().ok()).unwrap_or(2);
                        (words.next().unwrap_or("float"), d)
                    }
                    "TENSORS" => (words.next().unwrap_or("float"), 9),
                    _ => (words.next().unwrap_or("float"), 3),
                };
                let ty = if key == "COLOR_SCALARS" && !c.binary { "float" } else { ty };
                if key == "SCALARS" {
                    let save = c.at;
                    if c.word().is_some_and(|w| w.eq_ignore_ascii_case("LOOKUP_TABLE")) {
                        c.rest_of_line();
                    } else {
                        c.at = save;
                    }
                }
                let values = c.values(ty, n.saturating_mul(columns), &name)?;
                let f = Field { name, columns, values: values.into_iter().map(|v| v as f32).collect() };
                if point { vertex_fields.push(f) } else { streamline_fields.push((f, n)) }
            }
            "LOOKUP_TABLE" => {
                let _name = c.need("the table's name")?;
                let n: usize = c.number("the table's size")?;
                c.rest_of_line();
                let ty = if c.binary { "unsigned_char" } else { "float" };
                c.values(ty, n.saturating_mul(4), "LOOKUP_TABLE")?;
            }
            "FIELD" => {
                let _name = c.need("the field data's name")?;
                let arrays: usize = c.number("the number of field arrays")?;
                for _ in 0..arrays {
                    let name = c.need("the field array's name")?.to_string();
                    let columns: usize = c.number("the field array's components")?;
                    let tuples: usize = c.number("the field array's tuples")?;
                    let ty = c.need("the field array's type")?;
                    c.rest_of_line();
                    let values = c.values(ty, columns.saturating_mul(tuples), &name)?;
                    let f = Field { name, columns, values: values.into_iter().map(|v| v as f32).collect() };
                    match attach {
                        Some((true, _)) => vertex_fields.push(f),
                        Some((false, _)) => streamline_fields.push((f, tuples)),
                        None => {} // dataset-level field data (e.g. a timestamp): not per line
                    }
                }
            }
            other => {
                return bad(
                    at,
                    format!("a VTK PolyData keyword, found '{}'", other.chars().take(30).collect::<String>()),
                );
            }
        }
    }
    // No lines at all (a tractogram of zero streamlines, as a converter writes it): empty. A
    // file of polygons or strips without lines is a surface, not a tractogram.
    if other_cells == 0 && lines.as_ref().is_none_or(|l| l.offsets.len() <= 1) {
        return Ok(Tractogram::new());
    }
    let Some(lines) = lines.filter(|l| l.offsets.len() > 1) else {
        return Err(ErrorKind::NoLines(format!(
            "VTK PolyData with {} points and {other_cells} polygon/strip cells but no LINES",
            points.len()
        )));
    };
    // Points are looked up through the connectivity; point data follows them.
    if let Some(&i) = lines.connectivity.iter().find(|&&i| i as usize >= points.len()) {
        return bad(0, format!("LINES point indices below {}, found {i}", points.len()));
    }
    let positions = lines.connectivity.iter().map(|&i| points[i as usize]).collect();
    let vertex_fields = vertex_fields
        .into_iter()
        .filter(|f| f.values.len() == points.len() * f.columns)
        .map(|f| Field {
            values: lines
                .connectivity
                .iter()
                .flat_map(|&i| &f.values[i as usize * f.columns..(i as usize + 1) * f.columns])
                .copied()
                .collect(),
            ..f
        })
        .collect();
    let n_lines = lines.offsets.len() - 1;
    let streamline_fields = streamline_fields
        .into_iter()
        .filter_map(|(f, tuples)| {
            let first = if tuples == n_lines { 0 } else { cells_before_lines };
            let values = f.values.get(first * f.columns..(first + n_lines) * f.columns)?.to_vec();
            Some(Field { values, ..f })
        })
        .collect();
    Ok(Tractogram { positions, offsets: lines.offsets, vertex_fields, streamline_fields, ..Tractogram::default() })
}
