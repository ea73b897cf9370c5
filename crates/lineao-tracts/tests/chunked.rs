//! Chunked loading (`load_chunked`, `ChunkDecoder`) against the whole-file loader: every real
//! file of `../shared/data` gives exactly the same points, fields and counts in chunks of any
//! size, however its bytes are pushed; a file cut short is the same error, raised after every
//! whole chunk before it was handed over once.

use std::ops::ControlFlow;
use std::path::PathBuf;

use lineao_tracts::{ChunkDecoder, ErrorKind, LoadOptions, Tractogram, load_chunked, load_from_bytes};

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// Every tractography file of the shared data set (what the whole-file loader reads).
fn real_files() -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![data_dir()];
    while let Some(dir) = dirs.pop() {
        for e in std::fs::read_dir(&dir).unwrap().flatten() {
            let p = e.path();
            if lineao_tracts::load(&p).is_ok() {
                out.push(p);
            } else if p.is_dir() {
                dirs.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The chunks joined into one tractogram (fields appended, offsets shifted), with the chunk
/// sizes seen.
#[derive(Default)]
struct Joined {
    t: Tractogram,
    chunks: Vec<usize>,
}

impl Joined {
    fn add(&mut self, chunk: Tractogram) {
        let base = self.t.offsets.last().copied().unwrap_or(0);
        if self.t.offsets.is_empty() {
            self.t.offsets.push(0);
            self.t.vertex_fields = chunk.vertex_fields.iter().map(empty).collect();
            self.t.streamline_fields = chunk.streamline_fields.iter().map(empty).collect();
        }
        self.chunks.push(chunk.offsets.last().copied().unwrap_or(0) as usize);
        self.t.positions.extend_from_slice(&chunk.positions);
        self.t.offsets.extend(chunk.offsets[1..].iter().map(|o| o + base));
        for (into, from) in self.t.vertex_fields.iter_mut().zip(&chunk.vertex_fields) {
            into.values.extend_from_slice(&from.values);
        }
        for (into, from) in self.t.streamline_fields.iter_mut().zip(&chunk.streamline_fields) {
            into.values.extend_from_slice(&from.values);
        }
    }
}

fn empty(f: &lineao_tracts::Field) -> lineao_tracts::Field {
    lineao_tracts::Field { name: f.name.clone(), columns: f.columns, values: Vec::new() }
}

/// Pushes `bytes` into a decoder in pieces of `piece` bytes.
fn pushed(
    bytes: &[u8],
    name: &str,
    piece: usize,
    chunk_vertices: usize,
) -> (Result<lineao_tracts::Streamed, lineao_tracts::Error>, Joined) {
    let mut joined = Joined::default();
    let mut sink = |chunk: Tractogram| {
        joined.add(chunk);
        ControlFlow::Continue(())
    };
    let options = LoadOptions::default();
    let mut decoder = ChunkDecoder::new(name, &options, Some(bytes.len() as u64), chunk_vertices, &mut sink);
    for part in bytes.chunks(piece.max(1)) {
        if let Err(e) = decoder.push(part) {
            drop(decoder);
            return (Err(e), joined);
        }
    }
    let result = decoder.finish();
    (result, joined)
}

fn same(whole: &Tractogram, joined: &Tractogram, what: &str) {
    assert_eq!(joined.positions, whole.positions, "{what}: points");
    let offsets = if whole.offsets.len() <= 1 { vec![0] } else { whole.offsets.clone() };
    let joined_offsets = if joined.offsets.is_empty() { vec![0] } else { joined.offsets.clone() };
    assert_eq!(joined_offsets, offsets, "{what}: offsets");
    let values = |fields: &[lineao_tracts::Field]| {
        fields
            .iter()
            .map(|f| (f.name.clone(), f.columns, f.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>()))
            .collect::<Vec<_>>()
    };
    if whole.streamlines() > 0 {
        assert_eq!(values(&joined.vertex_fields), values(&whole.vertex_fields), "{what}: vertex fields");
        assert_eq!(values(&joined.streamline_fields), values(&whole.streamline_fields), "{what}: streamline fields");
    }
}

#[test]
fn every_real_file_in_chunks_is_the_whole_file() {
    let files = real_files();
    assert!(files.len() >= 12, "the shared data set is there: {}", files.len());
    for path in files {
        let whole = lineao_tracts::load(&path).unwrap();
        let name = path.display().to_string();
        for chunk_vertices in [1, 1000, usize::MAX] {
            let mut joined = Joined::default();
            let streamed = load_chunked(&path, &LoadOptions::default(), chunk_vertices, None, &mut |chunk| {
                joined.add(chunk);
                ControlFlow::Continue(())
            })
            .unwrap_or_else(|e| panic!("{e}"));
            let what = format!("{name} in chunks of {chunk_vertices}");
            same(&whole.tractogram, &joined.t, &what);
            assert_eq!(streamed.format, Some(whole.format), "{what}");
            assert_eq!(streamed.compression, Some(whole.compression), "{what}");
            assert_eq!(streamed.streamlines as usize, whole.tractogram.streamlines(), "{what}");
            assert_eq!(streamed.space, whole.tractogram.space, "{what}");
            assert_eq!(streamed.groups, whole.tractogram.groups, "{what}");
            // Chunks hold whole streamlines, fewer than `chunk_vertices` and the longest.
            let t = &whole.tractogram;
            let longest = (0..t.streamlines()).map(|i| t.offsets[i + 1] - t.offsets[i]).max().unwrap_or(0);
            let bound = chunk_vertices.saturating_add(longest as usize);
            assert!(joined.chunks.iter().all(|&n| n < bound), "{what}: {:?}", joined.chunks.iter().max());
        }
        // Bytes pushed a few at a time (a record split between pushes waits for its rest),
        // against the bytes loaded whole (a glTF's external buffers are not in its bytes).
        if !path.is_dir() {
            let bytes = std::fs::read(&path).unwrap();
            let from_bytes = load_from_bytes(&bytes, &name, &LoadOptions::default());
            for piece in [7, 4096] {
                let (result, joined) = pushed(&bytes, &name, piece, 333);
                let what = format!("{name} pushed {piece} bytes at a time");
                match &from_bytes {
                    Ok(loaded) => {
                        result.unwrap_or_else(|e| panic!("{what}: {e}"));
                        same(&loaded.tractogram, &joined.t, &what);
                    }
                    Err(e) => assert_eq!(result.unwrap_err().to_string(), e.to_string(), "{what}"),
                }
            }
        }
    }
}

/// A .tck and a .trk (plain and gzip) made here, large enough for many chunks.
fn synthetic() -> Vec<(String, Vec<u8>)> {
    let mut t = Tractogram::new();
    for i in 0..400 {
        let n = 3 + (i * 7) % 50;
        t.push((0..n).map(|k| [i as f32, k as f32 * 0.5, (i * k) as f32 * 0.01]));
    }
    let dir = tempfile::tempdir().unwrap();
    let mut out = Vec::new();
    for ext in ["tck", "trk"] {
        let path = dir.path().join(format!("synthetic.{ext}"));
        lineao_tracts::save(&t, &path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        out.push((format!("synthetic.{ext}.gz"), gzip(&bytes)));
        out.push((format!("synthetic.{ext}"), bytes));
    }
    out
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

#[test]
fn a_file_cut_short_is_the_whole_loaders_error_after_the_chunks_before_it() {
    for (name, bytes) in synthetic() {
        let whole = load_from_bytes(&bytes, &name, &LoadOptions::default()).unwrap().tractogram;
        let gz = name.ends_with(".gz");
        let mut errors = 0;
        let step = (bytes.len() / 97).max(1);
        // (A gzip stream cut in its last bytes — the end of its deflate data, its 8-byte
        // trailer — has given all its data: whether the whole-file loader's decompressor
        // complains depends on the byte; the chunked decoder takes it as the end.)
        let end = if gz { bytes.len() - 16 } else { bytes.len() };
        for cut in (0..end).step_by(step).chain([end - 1, end - 5]) {
            let cut_bytes = &bytes[..cut];
            let expected = load_from_bytes(cut_bytes, &name, &LoadOptions::default());
            let (got, joined) = pushed(cut_bytes, &name, 1 << 12, 500);
            match (expected, got) {
                (Ok(t), Ok(_)) => same(&t.tractogram, &joined.t, &format!("{name} cut at {cut}")),
                (Err(e), Err(g)) => {
                    errors += 1;
                    let (e, g) = (e.kind, g.kind);
                    assert_eq!(e.offset(), g.offset(), "{name} cut at {cut}: {e} / {g}");
                    if let (ErrorKind::Format { expected: a, .. }, ErrorKind::Format { expected: b, .. }) = (&e, &g) {
                        // Plain files: the same words too (gzip: the decompressor's own).
                        if !gz {
                            assert_eq!(a, b, "{name} cut at {cut}");
                        }
                    } else {
                        assert_eq!(e.to_string(), g.to_string(), "{name} cut at {cut}");
                    }
                    // What was handed over before the error are whole streamlines of the file,
                    // each once and in order.
                    let n = joined.t.streamlines();
                    assert!(n <= whole.streamlines(), "{name} cut at {cut}");
                    let prefix = whole.offsets[n] as usize;
                    assert_eq!(joined.t.positions, whole.positions[..prefix], "{name} cut at {cut}");
                }
                (e, g) => {
                    panic!("{name} ({} bytes) cut at {cut}: whole {:?}, chunked {:?}", bytes.len(), e.err(), g.err())
                }
            }
        }
        assert!(errors > 50, "{name}: {errors} cuts were errors");
    }
}

#[test]
fn cancelling_stops_the_load() {
    let (name, bytes) = synthetic().remove(1);
    let mut seen = 0;
    let mut sink = |_: Tractogram| {
        seen += 1;
        ControlFlow::Break(())
    };
    let mut decoder = ChunkDecoder::new(&name, &LoadOptions::default(), None, 100, &mut sink);
    let result = decoder.push(&bytes).and_then(|()| decoder.finish().map(drop));
    assert!(matches!(result.unwrap_err().kind, ErrorKind::Cancelled));
    assert_eq!(seen, 1);
}
