//! Bad input: every truncation point and thousands of byte mutations of real and synthetic files
//! must give `Ok` or a typed error, never a panic; decompression bombs stop at the limit;
//! lying headers run into the end of the file, not into the allocator.

use std::io::Write;
use std::path::PathBuf;

use lineao_tracts::{ErrorKind, LoadOptions, load_from_bytes};

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// Every file of the shared data set up to 64 KiB, plus the fuzz seeds (the fuzz corpus itself
/// is for `cargo fuzz`; replaying it here would cost minutes).
fn corpus() -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let fuzz = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let regressions = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
    let mut dirs = vec![data_dir(), fuzz.join("seeds"), regressions];
    while let Some(dir) = dirs.pop() {
        for e in std::fs::read_dir(&dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                dirs.push(p);
            } else if e.metadata().unwrap().len() <= 64 << 10 && !p.extension().is_some_and(|x| x == "md" || x == "txt")
            {
                out.push((p.file_name().unwrap().to_string_lossy().to_string(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// xorshift64*: deterministic mutations without a dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn options() -> LoadOptions {
    LoadOptions { max_inflated_bytes: Some(64 << 20) }
}

#[test]
fn inputs_the_fuzzer_crashed_on_are_errors_now() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
    for f in std::fs::read_dir(dir).unwrap().flatten() {
        let e = lineao_tracts::load(f.path()).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Format { .. }), "{e}");
    }
}

#[test]
fn the_fuzz_seeds_are_valid_files_of_their_format() {
    let seeds = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    for dir in std::fs::read_dir(&seeds).unwrap().flatten() {
        let target = dir.file_name().to_string_lossy().to_string();
        for f in std::fs::read_dir(dir.path()).unwrap().flatten() {
            if target == "nifti" {
                let volume = lineao_tracts::Volume::load(f.path()).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(volume.dims, [2, 3, 2], "{}", f.path().display());
                continue;
            }
            let loaded = lineao_tracts::load(f.path()).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(loaded.format.name(), target, "{}", f.path().display());
            assert!(loaded.tractogram.streamlines() > 0, "{}", f.path().display());
        }
    }
}

#[test]
fn every_truncation_is_an_error_or_a_shorter_file_never_a_panic() {
    let corpus = corpus();
    assert!(corpus.len() >= 25, "the corpus is there: {}", corpus.len());
    for (name, bytes) in &corpus {
        // All cut points near the start (headers), then 64 spread over the rest.
        let step = (bytes.len() / 64).max(1);
        let cuts = (0..bytes.len().min(1100)).chain((1100..bytes.len()).step_by(step));
        for cut in cuts {
            if let Err(e) = load_from_bytes(&bytes[..cut], name, &options()) {
                assert!(e.to_string().starts_with(name.as_str()), "the error names the file: {e}");
            }
        }
    }
}

#[test]
fn random_byte_mutations_never_panic() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for (name, bytes) in corpus() {
        for _ in 0..200 {
            let mut b = bytes.clone();
            for _ in 0..1 + rng.below(8) {
                let i = rng.below(b.len());
                match rng.below(4) {
                    0 => b[i] = rng.next() as u8,
                    1 => b[i] ^= 1 << rng.below(8),
                    // Extreme values where counts and sizes live.
                    2 => b[i] = [0x00, 0x7F, 0x80, 0xFF][rng.below(4)],
                    _ => {
                        let j = (i + 4).min(b.len());
                        b[i..j].fill(0xFF);
                    }
                }
            }
            let _ = load_from_bytes(&b, &name, &options());
        }
    }
}

#[test]
fn volumes_cut_short_or_mutated_are_errors_never_panics() {
    // The NIfTI-1 and NIfTI-2 seeds of the `nifti` fuzz target, either byte order: every cut
    // point, and 500 mutations each, read as the anatomy would be.
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/nifti");
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    let mut read = 0;
    for f in std::fs::read_dir(dir).unwrap().flatten() {
        let bytes = std::fs::read(f.path()).unwrap();
        for cut in 0..bytes.len() {
            let _ = lineao_tracts::Volume::from_bytes(&bytes[..cut], 1 << 20);
        }
        for _ in 0..500 {
            let mut b = bytes.clone();
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(b.len());
                b[i] = [0x00, 0x7F, 0x80, 0xFF, rng.next() as u8][rng.below(5)];
            }
            read += lineao_tracts::Volume::from_bytes(&b, 1 << 20).is_ok() as usize;
        }
    }
    assert!(read > 0, "some mutations still read as volumes");
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

#[test]
fn gzip_bomb_stops_at_the_limit() {
    // A valid .tck header followed by 60 MiB of zeros (valid points!) compresses ~1000:1.
    let mut raw = b"mrtrix tracks\ndatatype: Float32LE\nfile: . 64\nEND\n".to_vec();
    raw.resize(64 + 12 * (5 << 20), 0);
    let bomb = gzip(&raw);
    assert!(bomb.len() < 200 << 10);
    let small = LoadOptions { max_inflated_bytes: Some(4 << 20) };
    let e = load_from_bytes(&bomb, "bomb.tck.gz", &small).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooLarge { limit, .. } if limit == 4 << 20), "{e}");
    // The default limit scales with the file: 64 × 65 KiB is under 256 MiB, so it holds here.
    let ok = load_from_bytes(&bomb, "bomb.tck.gz", &LoadOptions::default()).unwrap();
    assert_eq!(ok.tractogram.vertices(), 5 << 20);
}

#[test]
fn zip_bomb_member_stops_at_the_limit() {
    let mut buf = std::io::Cursor::new(Vec::new());
    let mut zip = zip::ZipWriter::new(&mut buf);
    let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("header.json", opts).unwrap();
    zip.write_all(br#"{"NB_VERTICES": 1, "NB_STREAMLINES": 1}"#).unwrap();
    zip.start_file("positions.3.float32", opts).unwrap();
    zip.write_all(&vec![0u8; 48 << 20]).unwrap();
    zip.start_file("offsets.uint64", opts).unwrap();
    zip.write_all(&0u64.to_le_bytes()).unwrap();
    zip.finish().unwrap();
    let small = LoadOptions { max_inflated_bytes: Some(1 << 20) };
    let e = load_from_bytes(buf.get_ref(), "bomb.trx", &small).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooLarge { .. }), "{e}");
}

#[test]
fn vtp_zlib_header_claiming_a_terabyte_is_refused_before_allocating() {
    use base64::Engine;
    let b = base64::engine::general_purpose::STANDARD;
    // One block of 2^40 bytes whose compressed size is 8.
    let header: Vec<u8> = [1u32, 0, 0, 8].iter().flat_map(|w| w.to_le_bytes()).collect();
    let mut header = header;
    header[4..8].copy_from_slice(&(1u32 << 31).to_le_bytes());
    header[8..12].copy_from_slice(&(1u32 << 31).to_le_bytes());
    let xml = format!(
        r#"<VTKFile type="PolyData" compressor="vtkZLibDataCompressor"><PolyData><Piece><Points><DataArray type="Float32" NumberOfComponents="3" format="binary">{}{}</DataArray></Points></Piece></PolyData></VTKFile>"#,
        b.encode(&header),
        b.encode([0u8; 8])
    );
    let e =
        load_from_bytes(xml.as_bytes(), "bomb.vtp", &LoadOptions { max_inflated_bytes: Some(1 << 30) }).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooLarge { .. }), "{e}");
}

#[test]
fn lying_counts_hit_the_end_of_the_file() {
    // TrackVis: a streamline claiming 2^31 − 1 points in a 1004-byte file.
    let mut trk = std::fs::read(data_dir().join("nipy+nibabel/nibabel/tests/data/empty.trk")).unwrap();
    trk[988..992].copy_from_slice(&i32::MAX.to_le_bytes());
    trk.extend_from_slice(&i32::MAX.to_le_bytes());
    let e = load_from_bytes(&trk, "liar.trk", &options()).unwrap_err();
    let ErrorKind::Format { offset, expected } = &e.kind else { panic!("{e}") };
    assert_eq!(*offset, 1004, "{e}");
    assert!(expected.contains("points"), "{e}");
    // MRtrix: a data offset far past the end.
    let tck = b"mrtrix tracks\ndatatype: Float32LE\nfile: . 999999999999\nEND\n";
    let e = load_from_bytes(tck, "far.tck", &options()).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Format { .. }), "{e}");
    // VTK: POINTS claiming 10^15 points.
    let vtk = b"# vtk DataFile Version 3.0\nx\nBINARY\nDATASET POLYDATA\nPOINTS 1000000000000000 float\n\0\0\0\0";
    let e = load_from_bytes(vtk, "liar.vtk", &options()).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Format { offset, .. } if offset > 0), "{e}");
}

#[test]
fn errors_name_file_offset_and_expectation() {
    let bytes = std::fs::read(data_dir().join("nipy+nibabel/nibabel/tests/data/simple.trk")).unwrap();
    let mut bad = bytes.clone();
    bad[992..996].copy_from_slice(&7i32.to_le_bytes());
    let e = load_from_bytes(&bad, "v7.trk", &options()).unwrap_err();
    assert_eq!(e.to_string(), "v7.trk: at byte 992: expected version 1, 2 or 3, found 7");
    let e = load_from_bytes(&bytes[..1010], "cut.trk", &options()).unwrap_err();
    assert!(e.to_string().starts_with("cut.trk: at byte 1004: expected"), "{e}");
}
