//! Hand-built files for what the real data set lacks, and round trips through every writer.
//! The bytes here are written by the test itself, independently of our writers.

use std::io::Write;
use std::path::{Path, PathBuf};

use lineao_tracts::{Compression, ErrorKind, Field, Format, Group, Tractogram, VoxelSpace, load, save};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn zlib(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// Three streamlines of 2, 3 and 1 points with distinct coordinates.
fn sample() -> Tractogram {
    let mut t = Tractogram::new();
    t.push([[1.5, -2.0, 3.25], [4.0, 5.0, 6.0]]);
    t.push([[-7.0, 8.5, 9.0], [10.0, 11.0, -12.0], [13.0, 14.0, 15.0]]);
    t.push([[0.125, 0.25, 0.5]]);
    t
}

fn tck_bytes(datatype: &str, data_offset: usize, values: &[f64], width: usize, big: bool) -> Vec<u8> {
    let header = format!("mrtrix tracks    \ncount: 99\ndatatype: {datatype}\nfile: . {data_offset}\nEND\n");
    let mut b = header.into_bytes();
    b.resize(data_offset, 0);
    for &v in values {
        match (width, big) {
            (8, false) => b.extend_from_slice(&v.to_le_bytes()),
            (8, true) => b.extend_from_slice(&v.to_be_bytes()),
            (_, false) => b.extend_from_slice(&(v as f32).to_le_bytes()),
            (_, true) => b.extend_from_slice(&(v as f32).to_be_bytes()),
        }
    }
    b
}

/// Points of `sample()` with a NaN triplet after each streamline (one of them a non-canonical
/// NaN) and no Inf at the end.
fn tck_values() -> Vec<f64> {
    let t = sample();
    let mut v = Vec::new();
    for i in 0..t.streamlines() {
        for p in t.streamline(i) {
            v.extend(p.iter().map(|&c| c as f64));
        }
        let nan = if i == 1 { f64::from_bits(0xFFF8_0000_0000_0001) } else { f64::NAN };
        v.extend([nan; 3]);
    }
    v
}

#[test]
fn tck_float64_and_big_endian_with_a_seek_and_no_terminator() {
    let dir = tempfile::tempdir().unwrap();
    for (datatype, width, big) in
        [("Float64LE", 8, false), ("Float64BE", 8, true), ("Float32BE", 4, true), ("Float32LE", 4, false)]
    {
        let path = write(dir.path(), &format!("{datatype}.tck"), &tck_bytes(datatype, 200, &tck_values(), width, big));
        let loaded = load(&path).unwrap();
        assert_eq!(loaded.format, Format::Tck);
        assert_eq!(loaded.tractogram.offsets, sample().offsets, "{datatype}: count 99 in the header is ignored");
        assert_eq!(loaded.tractogram.positions, sample().positions, "{datatype}");
    }
    // An Inf of either sign ends the data; whatever follows is not read.
    let mut v = tck_values();
    v.extend([f64::NEG_INFINITY; 3]);
    v.extend([1.0, 2.0, 3.0]);
    let path = write(dir.path(), "inf.tck", &tck_bytes("Float32LE", 100, &v, 4, false));
    assert_eq!(load(&path).unwrap().tractogram, sample());
    // A data offset inside the header is an error at the header's end.
    let path = write(dir.path(), "early.tck", &tck_bytes("Float32LE", 100, &v, 4, false).replace_offset());
    let e = load(&path).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Format { .. }), "{e}");
}

trait ReplaceOffset {
    fn replace_offset(self) -> Vec<u8>;
}

impl ReplaceOffset for Vec<u8> {
    fn replace_offset(self) -> Vec<u8> {
        String::from_utf8_lossy(&self).replacen("file: . 100", "file: . 010", 1).into_bytes()
    }
}

#[test]
fn gzip_around_a_tck_named_bin_is_found_by_content() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "tracks.bin", &gzip(&tck_bytes("Float32LE", 64, &tck_values(), 4, false)));
    let loaded = load(&path).unwrap();
    assert_eq!((loaded.format, loaded.compression), (Format::Tck, Compression::Gzip));
    assert_eq!(loaded.tractogram, sample());
}

/// A TRX directory: float64 positions, uint32 N + 1 offsets, 2-column int16 dpv, uint8 dps,
/// groups with uint16 indices and a dpg entry; the header's counts are deliberately wrong.
fn trx_members() -> Vec<(String, Vec<u8>)> {
    let t = sample();
    let mut m = Vec::new();
    let header = r#"{"VOXEL_TO_RASMM": [[2,0,0,-10],[0,2,0,-20],[0,0,2,-30],[0,0,0,1]], "DIMENSIONS": [10, 20, 30], "NB_VERTICES": 1, "NB_STREAMLINES": 1}"#;
    m.push(("header.json".into(), header.as_bytes().to_vec()));
    m.push((
        "positions.3.float64".into(),
        t.positions.iter().flatten().flat_map(|&c| (c as f64).to_le_bytes()).collect(),
    ));
    m.push(("offsets.uint32".into(), t.offsets.iter().flat_map(|&o| (o as u32).to_le_bytes()).collect()));
    m.push(("dpv/color.2.int16".into(), (0..12i16).flat_map(|v| (v - 6).to_le_bytes()).collect()));
    m.push(("dps/label.uint8".into(), vec![7, 8, 9]));
    m.push(("groups/left.uint16".into(), [0u16, 2].iter().flat_map(|v| v.to_le_bytes()).collect()));
    m.push(("dpg/left/weight.float16".into(), half::f16::from_f32(0.5).to_le_bytes().to_vec()));
    m
}

fn check_trx(t: &Tractogram) {
    assert_eq!(t.positions, sample().positions);
    assert_eq!(t.offsets, sample().offsets);
    let color = t.vertex_field("color").unwrap();
    assert_eq!((color.columns, color.values[0], color.values[11]), (2, -6.0, 5.0));
    assert_eq!(t.streamline_field("label").unwrap().values, vec![7.0, 8.0, 9.0]);
    assert_eq!(t.groups.len(), 1);
    assert_eq!((t.groups[0].name.as_str(), &t.groups[0].streamlines[..]), ("left", &[0u32, 2][..]));
    assert_eq!(t.groups[0].data[0].values, vec![0.5]);
    let space = t.space.unwrap();
    assert_eq!((space.affine[1][3], space.dimensions), (-20.0, [10, 20, 30]));
}

#[test]
fn trx_directory_and_deflated_zip_with_a_folder_prefix() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("bundle.trx");
    for (name, bytes) in trx_members() {
        let p = root.join(&name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    let loaded = load(&root).unwrap();
    assert_eq!((loaded.format, loaded.compression), (Format::Trx, Compression::None));
    check_trx(&loaded.tractogram);

    // The same members deflated, inside a folder, in a zip with N-entry offsets.
    let path = dir.path().join("zipped.trx");
    let mut zip = zip::ZipWriter::new(std::fs::File::create(&path).unwrap());
    let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for (name, mut bytes) in trx_members() {
        if name == "offsets.uint32" {
            bytes.truncate(bytes.len() - 4);
        }
        zip.start_file(format!("bundle/{name}"), opts).unwrap();
        zip.write_all(&bytes).unwrap();
    }
    zip.finish().unwrap();
    let loaded = load(&path).unwrap();
    assert_eq!((loaded.format, loaded.compression), (Format::Trx, Compression::Zip));
    check_trx(&loaded.tractogram);
}

#[test]
fn vtk_51_ascii_lines_with_point_and_cell_data() {
    // Points are used out of order and twice; one VERTICES cell precedes the lines in CELL_DATA.
    let text = "# vtk DataFile Version 5.1\nsynthetic\nASCII\nDATASET POLYDATA\n\
        POINTS 4 float\n0 0 0  1 0 0  2 0 0\n3 0 0\n\
        METADATA\nINFORMATION 0\n\n\
        VERTICES 2 1\nOFFSETS vtktypeint64\n0 1\nCONNECTIVITY vtktypeint64\n0\n\
        LINES 3 5\nOFFSETS vtktypeint64\n0 2 5\nCONNECTIVITY vtktypeint64\n3 2 0 1 3\n\
        POINT_DATA 4\nSCALARS fa float 1\nLOOKUP_TABLE default\n0.5 0.6 0.7 0.8\n\
        CELL_DATA 3\nFIELD FieldData 1\nlabel 1 3 int\n100 200 300\n";
    let dir = tempfile::tempdir().unwrap();
    let t = load(write(dir.path(), "lines51.vtk", text.as_bytes())).unwrap().tractogram;
    assert_eq!(t.offsets, vec![0, 2, 5]);
    assert_eq!(t.positions, vec![[3.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [3.0, 0.0, 0.0]]);
    assert_eq!(t.vertex_field("fa").unwrap().values, vec![0.8, 0.7, 0.5, 0.6, 0.8]);
    assert_eq!(t.streamline_field("label").unwrap().values, vec![200.0, 300.0], "the VERTICES cell's value is skipped");

    // The same lines in the old `LINES n size` layout.
    let old = "# vtk DataFile Version 3.0\nold\nASCII\nDATASET POLYDATA\nPOINTS 4 double\n0 0 0 1 0 0 2 0 0 3 0 0\n\
        LINES 2 7\n2 3 2\n3 0 1 3\n";
    let t2 = load(write(dir.path(), "old.vtk", old.as_bytes())).unwrap().tractogram;
    assert_eq!((t2.offsets.clone(), t2.positions.clone()), (t.offsets.clone(), t.positions.clone()));

    // Without a title line (the version line straight followed by ASCII, as MRtrix's
    // tckconvert may write it), and with a title that reads "ASCII".
    let untitled = old.replacen("old\n", "", 1);
    let t3 = load(write(dir.path(), "untitled.vtk", untitled.as_bytes())).unwrap().tractogram;
    assert_eq!((&t3.offsets, &t3.positions), (&t.offsets, &t.positions));
    let ascii_title = old.replacen("old\n", "ASCII\n", 1);
    let t4 = load(write(dir.path(), "ascii_title.vtk", ascii_title.as_bytes())).unwrap().tractogram;
    assert_eq!((&t4.offsets, &t4.positions), (&t.offsets, &t.positions));
}

/// Zero streamlines, as a converter writes them (no title, no points, no lines; or empty LINES):
/// an empty tractogram, not an error — while a surface without lines stays an error.
#[test]
fn vtk_with_zero_lines_is_an_empty_tractogram() {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in [
        ("bare.vtk", "# vtk DataFile Version 3.0\nASCII\nDATASET POLYDATA\nPOINTS 0 float\n"),
        ("empty_lines.vtk", "# vtk DataFile Version 3.0\nempty\nASCII\nDATASET POLYDATA\nPOINTS 0 float\nLINES 0 0\n"),
        ("binary.vtk", "# vtk DataFile Version 4.2\nBINARY\nDATASET POLYDATA\nPOINTS 0 float\n\nLINES 0 0\n"),
    ] {
        let t = load(write(dir.path(), name, text.as_bytes())).unwrap_or_else(|e| panic!("{name}: {e}")).tractogram;
        assert_eq!((t.streamlines(), t.positions.len()), (0, 0), "{name}");
    }
    let surface = "# vtk DataFile Version 3.0\ns\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\n\
        POLYGONS 1 4\n3 0 1 2\n";
    let e = load(write(dir.path(), "surface.vtk", surface.as_bytes())).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::NoLines(_)), "{e}");
}

/// A VTP whose arrays are appended: raw zlib blocks behind UInt64 headers, or base64.
fn vtp(appended_raw: bool) -> Vec<u8> {
    let points: Vec<u8> =
        [0f32, 0., 0., 1., 0., 0., 2., 0., 0., 3., 1., 0.].iter().flat_map(|v| v.to_le_bytes()).collect();
    let conn: Vec<u8> = [0i64, 1, 2, 3, 1].iter().flat_map(|v| v.to_le_bytes()).collect();
    let offs: Vec<u8> = [3i64, 5].iter().flat_map(|v| v.to_le_bytes()).collect();
    let fa: Vec<u8> = [0.1f32, 0.2, 0.3, 0.4].iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut data = Vec::new();
    let mut offsets = Vec::new();
    for raw in [&points, &conn, &offs, &fa] {
        offsets.push(data.len());
        if appended_raw {
            // One zlib block: [1, block size, last size, compressed size] as UInt64.
            let z = zlib(raw);
            for w in [1u64, raw.len() as u64, raw.len() as u64, z.len() as u64] {
                data.extend_from_slice(&w.to_le_bytes());
            }
            data.extend_from_slice(&z);
        } else {
            // Uncompressed, UInt32 byte count and data base64-encoded separately.
            use base64::Engine;
            let b = base64::engine::general_purpose::STANDARD;
            data.extend_from_slice(b.encode((raw.len() as u32).to_le_bytes()).as_bytes());
            data.extend_from_slice(b.encode(raw).as_bytes());
        }
    }
    let (header, encoding) = if appended_raw {
        (r#" header_type="UInt64" compressor="vtkZLibDataCompressor""#, "raw")
    } else {
        ("", "base64")
    };
    let arr = |ty: &str, name: &str, comps: usize, i: usize| {
        format!(
            r#"<DataArray type="{ty}" Name="{name}" NumberOfComponents="{comps}" format="appended" offset="{}"/>"#,
            offsets[i]
        )
    };
    let xml = format!(
        r#"<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian"{header}>
  <PolyData><Piece NumberOfPoints="4" NumberOfLines="2">
    <PointData>{}</PointData>
    <Points>{}</Points>
    <Lines>{}{}</Lines>
  </Piece></PolyData>
  <AppendedData encoding="{encoding}">
   _"#,
        arr("Float32", "fa", 1, 3),
        arr("Float32", "Points", 3, 0),
        arr("Int64", "connectivity", 1, 1),
        arr("Int64", "offsets", 1, 2),
    );
    let mut b = xml.into_bytes();
    b.extend_from_slice(&data);
    b.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
    b
}

#[test]
fn vtp_appended_raw_zlib_and_base64() {
    let dir = tempfile::tempdir().unwrap();
    for raw in [true, false] {
        let t = load(write(dir.path(), &format!("a{raw}.vtp"), &vtp(raw))).unwrap().tractogram;
        assert_eq!(t.offsets, vec![0, 3, 5], "raw: {raw}");
        assert_eq!(t.positions[3], [3.0, 1.0, 0.0]);
        assert_eq!(t.positions[4], [1.0, 0.0, 0.0]);
        assert_eq!(t.vertex_field("fa").unwrap().values, vec![0.1, 0.2, 0.3, 0.4, 0.2]);
    }
}

/// Fields and a voxel grid that every writer must carry (TrackVis: names ≤ 18 bytes).
fn rich() -> Tractogram {
    let mut t = sample();
    t.vertex_fields.push(Field { name: "fa".into(), columns: 1, values: (0..6).map(|i| i as f32 * 0.1).collect() });
    t.vertex_fields.push(Field { name: "rgb".into(), columns: 3, values: (0..18).map(|i| i as f32).collect() });
    t.streamline_fields.push(Field { name: "len".into(), columns: 1, values: vec![2.0, 3.0, 1.0] });
    t.space = Some(VoxelSpace {
        affine: [[-1.25, 0.0, 0.0, 90.0], [0.0, 1.25, 0.0, -126.0], [0.0, 0.0, 2.5, -72.0], [0.0, 0.0, 0.0, 1.0]],
        dimensions: [145, 174, 73],
        voxel_sizes: Some([1.25, 1.25, 2.5]),
    });
    t
}

fn assert_points_close(a: &Tractogram, b: &Tractogram, what: &str) {
    assert_eq!(a.offsets, b.offsets, "{what}");
    for (p, q) in a.positions.iter().zip(&b.positions) {
        assert!((0..3).all(|i| (p[i] - q[i]).abs() < 1e-4), "{what}: {p:?} vs {q:?}");
    }
}

#[test]
fn round_trips_through_every_writer() {
    let dir = tempfile::tempdir().unwrap();
    let t = rich();
    // .trx keeps everything.
    let p = dir.path().join("rt.trx");
    assert!(save(&t, &p).unwrap().is_empty());
    let back = load(&p).unwrap().tractogram;
    assert_points_close(&back, &t, "trx");
    assert_eq!(back.vertex_fields, t.vertex_fields);
    assert_eq!(back.streamline_fields, t.streamline_fields);
    assert_eq!(back.space.unwrap().affine, t.space.unwrap().affine);
    // .trk keeps fields and the grid (an LAS grid: the writer's voxel order makes the flip exact).
    let p = dir.path().join("rt.trk");
    assert!(save(&t, &p).unwrap().is_empty());
    let back = load(&p).unwrap().tractogram;
    assert_points_close(&back, &t, "trk");
    assert_eq!(back.vertex_fields, t.vertex_fields);
    assert_eq!(back.streamline_fields, t.streamline_fields);
    assert_eq!(back.space.unwrap().dimensions, t.space.unwrap().dimensions);
    // .tck holds only points and says which fields it left out.
    let p = dir.path().join("rt.tck");
    assert_eq!(save(&t, &p).unwrap(), vec!["fa", "rgb", "len"]);
    assert_eq!(load(&p).unwrap().tractogram.positions, t.positions, "tck is exact f32");
    // And groups survive TRX.
    let mut g = sample();
    g.groups.push(Group { name: "CST_L".into(), streamlines: vec![1, 2], data: Vec::new() });
    let p = dir.path().join("groups.trx");
    save(&g, &p).unwrap();
    assert_eq!(load(&p).unwrap().tractogram.groups, g.groups);
    // Real files through all three writers.
    let real = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/nipy+nibabel/nibabel/tests/data/standard.LPS.trk");
    let t = load(real).unwrap().tractogram;
    for ext in ["trk", "tck", "trx"] {
        let p = dir.path().join(format!("standard.{ext}"));
        save(&t, &p).unwrap();
        assert_points_close(&load(&p).unwrap().tractogram, &t, ext);
    }
}

#[test]
fn empty_tractograms_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["trk", "tck", "trx"] {
        let p = dir.path().join(format!("empty.{ext}"));
        save(&Tractogram::new(), &p).unwrap();
        let back = load(&p).unwrap().tractogram;
        assert_eq!((back.streamlines(), back.vertices()), (0, 0), "{ext}");
    }
}

#[test]
fn unwritable_formats_and_value_only_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let e = save(&sample(), dir.path().join("x.vtk")).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Unsupported(_)), "{e}");
    let mut tsf = Tractogram::new();
    tsf.offsets = vec![0, 2];
    tsf.vertex_fields.push(Field { name: "tsf".into(), columns: 1, values: vec![1.0, 2.0] });
    assert!(matches!(save(&tsf, dir.path().join("x.tck")).unwrap_err().kind, ErrorKind::Unsupported(_)));
    assert!(!dir.path().join("x.tck").exists(), "nothing half-written");
}

/// 500 000 vertices (several progress reports) as .tck, .trk and .trx in `dir`.
fn big_files(dir: &Path) -> Vec<PathBuf> {
    let mut t = Tractogram::new();
    for i in 0..5000 {
        t.push((0..100).map(|k| [i as f32, k as f32, 0.5]));
    }
    ["tck", "trk", "trx"]
        .iter()
        .map(|ext| {
            let p = dir.join(format!("big.{ext}"));
            save(&t, &p).unwrap();
            p
        })
        .collect()
}

#[test]
fn progress_reports_bytes_of_the_file_up_to_its_size() {
    let dir = tempfile::tempdir().unwrap();
    for p in big_files(dir.path()) {
        let ext = p.extension().unwrap().to_string_lossy().to_string();
        let len = std::fs::metadata(&p).unwrap().len();
        let mut seen = Vec::new();
        let mut report = |p: lineao_tracts::Progress| {
            seen.push(p);
            std::ops::ControlFlow::Continue(())
        };
        let loaded = lineao_tracts::load_with(&p, &lineao_tracts::LoadOptions::default(), Some(&mut report)).unwrap();
        assert_eq!(loaded.tractogram.vertices(), 500_000);
        assert!(seen.len() >= 2, "{ext}: {} reports for {len} bytes", seen.len());
        assert!(seen.iter().all(|p| p.total == Some(len) && p.bytes <= len), "{ext}");
        assert!(seen.windows(2).all(|w| w[0].bytes <= w[1].bytes), "{ext}: only forward");
        // A zip's members are most of it; its directory and local headers are read by the zip
        // crate in small pieces.
        assert!(seen.last().unwrap().bytes as f64 >= 0.99 * len as f64, "{ext}: {:?} of {len}", seen.last());
    }
}

#[test]
fn a_progress_callback_cancels_the_load_after_its_first_report() {
    let dir = tempfile::tempdir().unwrap();
    for p in big_files(dir.path()) {
        let ext = p.extension().unwrap().to_string_lossy().to_string();
        let mut reports = 0;
        let mut cancel = |_: lineao_tracts::Progress| {
            reports += 1;
            std::ops::ControlFlow::Break(())
        };
        let error =
            lineao_tracts::load_with(&p, &lineao_tracts::LoadOptions::default(), Some(&mut cancel)).unwrap_err();
        assert!(matches!(error.kind, lineao_tracts::ErrorKind::Cancelled), "{ext}: {error}");
        assert_eq!(reports, 1, "{ext}: nothing read after the callback said stop");
        assert!(error.to_string().contains("cancelled"), "{error}");
    }
}
