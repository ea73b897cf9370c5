//! Every file in `../shared/data/` against what independent readers return for it
//! (`FACTS.txt`: nibabel 5.4.2 for .trk/.tck, plain numpy decoders for the rest; `[T]` = the
//! origin project's own tests assert it). Points to 1e-4 mm.

use std::path::PathBuf;

use lineao_tracts::{Compression, ErrorKind, Format, Tractogram, load};

fn data(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data").join(rel)
}

const NIBABEL: &str = "nipy+nibabel/nibabel/tests/data/";
const NIIVUE: &str = "niivue+niivue/packages/niivue/demos/images/";
const DIPY: &str = "dipy+dipy/dipy/data/files/";

struct Facts<'a> {
    file: String,
    format: Format,
    compression: Compression,
    n: usize,
    pts: usize,
    first: Option<[f32; 3]>,
    last: Option<[f32; 3]>,
    /// (first streamline's length, min, max)
    lengths: Option<(usize, usize, usize)>,
    vertex_fields: &'a [(&'a str, usize)],
    streamline_fields: &'a [(&'a str, usize)],
}

fn facts<'a>(file: String, format: Format, n: usize, pts: usize) -> Facts<'a> {
    Facts {
        file,
        format,
        compression: Compression::None,
        n,
        pts,
        first: None,
        last: None,
        lengths: None,
        vertex_fields: &[],
        streamline_fields: &[],
    }
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= 1e-4 * b[i].abs().max(1.0))
}

fn check(f: &Facts) -> Tractogram {
    let loaded = load(data(&f.file)).unwrap_or_else(|e| panic!("{e}"));
    let t = loaded.tractogram;
    assert_eq!(loaded.format, f.format, "{}", f.file);
    assert_eq!(loaded.compression, f.compression, "{}", f.file);
    assert_eq!((t.streamlines(), t.vertices()), (f.n, f.pts), "{}: counts", f.file);
    t.validate().unwrap();
    if let Some(first) = f.first {
        assert!(close(t.positions[0], first), "{}: first point {:?} vs {first:?}", f.file, t.positions[0]);
    }
    if let Some(last) = f.last {
        let got = *t.positions.last().unwrap();
        assert!(close(got, last), "{}: last point {got:?} vs {last:?}", f.file);
    }
    if let Some((first, min, max)) = f.lengths {
        let lens: Vec<usize> = (0..t.streamlines()).map(|i| t.streamline(i).len()).collect();
        assert_eq!(
            (lens[0], *lens.iter().min().unwrap(), *lens.iter().max().unwrap()),
            (first, min, max),
            "{}",
            f.file
        );
    }
    let names =
        |fields: &[lineao_tracts::Field]| fields.iter().map(|f| (f.name.clone(), f.columns)).collect::<Vec<_>>();
    let want = |w: &[(&str, usize)]| w.iter().map(|(n, c)| (n.to_string(), *c)).collect::<Vec<_>>();
    assert_eq!(names(&t.vertex_fields), want(f.vertex_fields), "{}: vertex fields", f.file);
    assert_eq!(names(&t.streamline_fields), want(f.streamline_fields), "{}: streamline fields", f.file);
    t
}

#[test]
fn nibabel_simple_files_in_every_byte_order() {
    // [T] 3 streamlines: [[0,1,2]], arange(6)→(2,3), arange(15)→(5,3).
    for (name, format) in
        [("simple.trk", Format::Trk), ("simple.tck", Format::Tck), ("simple_big_endian.tck", Format::Tck)]
    {
        let t = check(&Facts {
            first: Some([0.0, 1.0, 2.0]),
            last: Some([12.0, 13.0, 14.0]),
            lengths: Some((1, 1, 5)),
            ..facts(format!("{NIBABEL}{name}"), format, 3, 8)
        });
        assert_eq!(t.streamline(0), &[[0.0, 1.0, 2.0]], "{name}");
        assert_eq!(t.streamline(1), &[[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]], "{name}");
        assert_eq!(t.streamline(2)[4], [12.0, 13.0, 14.0], "{name}");
    }
}

#[test]
fn complex_trk_keeps_scalars_and_properties_in_both_byte_orders() {
    for name in ["complex.trk", "complex_big_endian.trk"] {
        let t = check(&Facts {
            first: Some([0.0, 1.0, 2.0]),
            last: Some([12.0, 13.0, 14.0]),
            lengths: Some((1, 1, 5)),
            vertex_fields: &[("colors", 3), ("fa", 1)],
            streamline_fields: &[("mean_colors", 3), ("mean_curvature", 1), ("mean_torsion", 1)],
            ..facts(format!("{NIBABEL}{name}"), Format::Trk, 3, 8)
        });
        // nibabel's test data: colors of streamline 0 are (1, 0, 0), fa 0.2, mean_curvature 1.11.
        let colors = t.vertex_field("colors").unwrap();
        assert_eq!(&colors.values[..3], &[1.0, 0.0, 0.0], "{name}");
        assert!((t.vertex_field("fa").unwrap().values[0] - 0.2).abs() < 1e-6, "{name}");
        assert!((t.streamline_field("mean_curvature").unwrap().values[0] - 1.11).abs() < 1e-5, "{name}");
    }
}

#[test]
fn standard_trk_lps_trk_and_tck_give_the_same_points() {
    // [T] the same 120 streamlines in world space; the .trk files differ in voxel order and size.
    let files = [("standard.trk", Format::Trk), ("standard.LPS.trk", Format::Trk), ("standard.tck", Format::Tck)];
    let all: Vec<Tractogram> = files
        .iter()
        .map(|(name, format)| {
            check(&Facts {
                first: Some([-0.5, -1.5, 1.0]),
                last: Some([3.5, 13.5, 11.0]),
                lengths: Some((3, 3, 3)),
                ..facts(format!("{NIBABEL}{name}"), *format, 120, 360)
            })
        })
        .collect();
    for t in &all[1..] {
        assert_eq!(t.offsets, all[0].offsets);
        for (a, b) in t.positions.iter().zip(&all[0].positions) {
            assert!(close(*a, *b), "{a:?} vs {b:?}");
        }
    }
    let space = all[1].space.unwrap();
    assert_eq!(space.dimensions, [4, 5, 7]);
    assert_eq!(space.voxel_sizes, Some([1.0, 3.0, 2.0]));
    assert_eq!(all[2].space, None, "a .tck records no voxel grid");
}

#[test]
fn empty_files_are_valid_and_empty() {
    for (name, format) in [("empty.trk", Format::Trk), ("empty.tck", Format::Tck)] {
        let t = check(&facts(format!("{NIBABEL}{name}"), format, 0, 0));
        assert_eq!(t.bounds(), None);
    }
}

#[test]
fn tck_header_quirks() {
    // [T] count says 615000: one streamline of 108 points, MATLAB NaN bits, −Inf terminator.
    check(&Facts {
        first: Some([-0.1301, -0.4523, 7.4381]),
        last: Some([-0.9685, -19.0761, 14.5566]),
        lengths: Some((108, 108, 108)),
        ..facts(format!("{NIBABEL}matlab_nan.tck"), Format::Tck, 1, 108)
    });
    // [T] repeated keys and a command_history over several lines.
    check(&Facts {
        lengths: Some((253, 253, 253)),
        ..facts(format!("{NIBABEL}multiline_header_field.tck"), Format::Tck, 1, 253)
    });
}

#[test]
fn broken_tck_headers_are_rejected_with_a_header_error() {
    for name in ["no_magic_number.tck", "no_header_end.tck", "no_header_end_eof.tck"] {
        let e = load(data(&format!("{NIBABEL}{name}"))).expect_err(name);
        assert!(e.path.ends_with(name));
        let msg = e.to_string();
        assert!(msg.contains(name), "{msg}");
        let ErrorKind::Format { offset, expected } = &e.kind else { panic!("{name}: {e:?}") };
        if name == "no_magic_number.tck" {
            assert_eq!(*offset, 0);
            assert!(expected.contains("magic line") && expected.contains("count: 0000"), "{msg}");
        } else {
            assert!(expected.contains("END"), "{name}: {msg}");
        }
    }
}

#[test]
fn dipy_and_niivue_trk() {
    check(&Facts {
        first: Some([-80.0, -120.0, -60.0]),
        last: Some([-64.0, -108.0, -60.0]),
        lengths: Some((4, 2, 8)),
        ..facts(format!("{DIPY}EuDX_small_25.trk"), Format::Trk, 60, 228)
    });
    check(&Facts {
        first: Some([92.2969, 115.4608, 66.9255]),
        last: Some([105.8003, 85.1808, 85.0565]),
        lengths: Some((79, 30, 91)),
        ..facts(format!("{DIPY}tracks300.trk"), Format::Trk, 300, 14576)
    });
    let t = check(&Facts {
        first: Some([20.9003, 65.2577, 8.1323]),
        last: Some([26.2585, -87.4261, -7.5085]),
        lengths: Some((12, 12, 12)),
        ..facts(format!("{NIIVUE}tract.IFOF_R.trk"), Format::Trk, 14, 168)
    });
    assert_eq!(t.space.unwrap().affine[0][3], -78.0);
    assert_eq!(t.space.unwrap().dimensions, [157, 189, 136]);
}

#[test]
fn colby_trk_zero_matrix_is_identity_and_padded_names_are_trimmed() {
    let t = check(&Facts {
        first: Some([191.5, -0.5, -0.5]),
        last: Some([81.8155, 83.7775, 49.2112]),
        lengths: Some((2, 2, 30)),
        vertex_fields: &[("effect", 1), ("pval", 1), ("pval_corr", 1)],
        ..facts(format!("{NIIVUE}colby.trk"), Format::Trk, 2, 32)
    });
    assert_eq!(t.space.unwrap().affine, lineao_tracts::IDENTITY);
    assert_eq!(t.space.unwrap().voxel_sizes, Some([1.25, 1.25, 2.5]));
}

#[test]
fn gzip_wrapped_trk() {
    let t = check(&Facts {
        compression: Compression::Gzip,
        first: Some([63.7966, -41.4548, 2.3185]),
        last: Some([-64.2489, -12.3755, 1.8408]),
        lengths: Some((4, 3, 41)),
        ..facts(format!("{NIIVUE}stroke.trk.gz"), Format::Trk, 36763, 237468)
    });
    assert_eq!(t.space.unwrap().affine[0], [-1.0, 0.0, 0.0, 90.0]);
}

#[test]
fn niivue_tck_and_its_tsf() {
    let tck = check(&Facts {
        first: Some([2.2857, 42.1839, 54.8273]),
        last: Some([4.8187, -48.8316, 62.0556]),
        lengths: Some((12, 12, 12)),
        ..facts(format!("{NIIVUE}tract.SLF1_R.tck"), Format::Tck, 13, 156)
    });
    // The .tsf: one value per vertex of that .tck, NaN between streamlines, no Inf at the end.
    let tsf = check(&Facts {
        vertex_fields: &[("tsf", 1)],
        ..facts(format!("{NIIVUE}mni152.SLF1_R.tsf"), Format::Tsf, 13, 156)
    });
    assert!(!tsf.has_points());
    assert_eq!(tsf.offsets, tck.offsets, "the scalars line up with the streamlines they belong to");
    assert!(tsf.vertex_fields[0].values.iter().all(|v| v.is_finite()));
}

#[test]
fn trx_files() {
    // colby.trx: float16 positions, N offsets (older TRX), dpv names with spaces.
    let t = check(&Facts {
        compression: Compression::Zip,
        first: Some([191.5, -0.5, -0.5]),
        last: Some([81.8125, 83.75, 49.21875]),
        lengths: Some((2, 2, 30)),
        vertex_fields: &[("effect", 1), ("pval", 1), ("pval_corr", 1)],
        ..facts(format!("{NIIVUE}colby.trx"), Format::Trx, 2, 32)
    });
    let effect = t.vertex_field("effect").unwrap();
    assert!((effect.values[0] + 0.1).abs() < 1e-6 && (effect.values[2] - 0.016921213).abs() < 1e-6);
    // dpsv.trx: header says 459 streamlines, arrays hold 460.
    let t = check(&Facts {
        compression: Compression::Zip,
        first: Some([-24.25, -22.09375, -26.90625]),
        last: Some([3.96875, -73.5625, 42.09375]),
        lengths: Some((208, 126, 233)),
        vertex_fields: &[("z", 1)],
        streamline_fields: &[("DataSetID", 1)],
        ..facts(format!("{NIIVUE}dpsv.trx"), Format::Trx, 460, 95865)
    });
    assert_eq!(&t.vertex_field("z").unwrap().values[..3], &[-26.90625, -26.5625, -25.96875]);
    assert_eq!(t.space.unwrap().affine[0], [0.5, 0.0, 0.0, -78.5]);
    // N + 1 offsets and two groups.
    let t = check(&Facts {
        compression: Compression::Zip,
        first: Some([14.2115, 32.4821, 46.7170]),
        last: Some([-55.1477, -57.2192, 5.0831]),
        lengths: Some((322, 118, 488)),
        ..facts(
            format!("{NIIVUE}sub-01_ses-01_dwi_space-RASMM_model-probCSD_algo-AFQ_tractography.trx"),
            Format::Trx,
            508,
            141447,
        )
    });
    let groups: Vec<(&str, usize, &[u32])> =
        t.groups.iter().map(|g| (g.name.as_str(), g.streamlines.len(), &g.streamlines[..3])).collect();
    assert_eq!(groups, vec![("ARC_L", 486, &[22u32, 23, 24][..]), ("ARC_R", 22, &[0u32, 1, 2][..])]);
}

#[test]
fn vtk_legacy_binary_lines_and_a_polygon_mesh_rejected() {
    check(&Facts {
        first: Some([56.2770, 18.1123, 9.2624]),
        lengths: Some((12, 12, 12)),
        ..facts(format!("{NIIVUE}tract.FAT_R.vtk"), Format::Vtk, 5, 60)
    });
    let e = load(data(&format!("{NIIVUE}issue1298.vtk"))).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::NoLines(_)), "{e}");
}

#[test]
fn vtp_with_zlib_compressed_base64_arrays() {
    check(&Facts {
        first: Some([-11.5828, 6.6583, -39.6741]),
        ..facts("SlicerDMRI+whitematteranalysis/tests/test_atlas_results/atlas1.vtp".into(), Format::Vtp, 500, 177405)
    });
    let t = load(data("SlicerDMRI+whitematteranalysis/tests/test_atlas_results/atlas1.vtp")).unwrap().tractogram;
    assert_eq!(t.streamline(0).len(), 239);
}

#[test]
fn dsi_studio_tiny_tracks() {
    // [T] 9 streamlines, dims (157, 189, 136), trans_to_mni rows [−1,0,0,78], [0,−1,0,76], [0,0,1,−50].
    let t = check(&Facts {
        compression: Compression::Gzip,
        first: Some([-43.9375, 24.15625, 22.96875]),
        ..facts("tee-ar-ex+trx-rs/tests/fixtures/tinytrack_small.tt.gz".into(), Format::Tt, 9, 2120)
    });
    let space = t.space.unwrap();
    assert_eq!(space.dimensions, [157, 189, 136]);
    assert_eq!(space.affine[0], [-1.0, 0.0, 0.0, 78.0]);
    assert_eq!(space.affine[1], [0.0, -1.0, 0.0, 76.0]);
    assert_eq!(space.affine[2], [0.0, 0.0, 1.0, -50.0]);
    assert_eq!(t.streamline(0).len(), 265);
    let mean_x = t.positions.iter().map(|p| p[0] as f64).sum::<f64>() / t.vertices() as f64;
    assert!((mean_x - -9.294).abs() < 1e-3, "{mean_x}");
    let clusters: Vec<(&str, usize)> = t.groups.iter().map(|g| (g.name.as_str(), g.streamlines.len())).collect();
    assert_eq!(clusters, vec![("cluster_0", 3), ("cluster_1", 3), ("cluster_2", 3)]);

    let t = check(&Facts {
        compression: Compression::Gzip,
        first: Some([18.5938, 44.4062, 42.5]),
        ..facts(format!("{NIIVUE}TR_S_R.tt.gz"), Format::Tt, 1159, 143324)
    });
    assert_eq!(t.streamline(0).len(), 141);
    let mean_x = t.positions.iter().map(|p| p[0] as f64).sum::<f64>() / t.vertices() as f64;
    assert!((mean_x - 25.018).abs() < 1e-3, "{mean_x}");

    // [T] must be rejected: the last track's deltas run past the end of the record.
    let e = load(data("tee-ar-ex+trx-rs/tests/fixtures/tinytrack_malformed.tt.gz")).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Format { .. }), "{e}");
}

#[test]
fn obj_segments_chain_into_one_polyline() {
    // [T] `l` elements with indices [0,1,1,2,2,0] as segments: each starts where the last ended.
    let t = check(&facts("Twinklebear+tobj/obj/lines.obj".into(), Format::Obj, 1, 4));
    assert_eq!(t.streamline(0), &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]);
}

#[test]
fn gltf_line_modes_with_node_transforms() {
    // MeshPrimitiveModes: LINES indices 0-1, 0-2, …, 0-6 (six separate segments: none starts
    // where the last ended), LINE_LOOP 0..6 (+ the first again), LINE_STRIP 0..6; triangles and
    // points skipped. Each mesh sits at its node's translation.
    let t = check(&facts(
        "KhronosGroup+glTF-Sample-Models/2.0/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf".into(),
        Format::Gltf,
        8,
        27,
    ));
    let lens: Vec<usize> = (0..8).map(|i| t.streamline(i).len()).collect();
    let mut sorted = lens.clone();
    sorted.sort();
    assert_eq!(sorted, vec![2, 2, 2, 2, 2, 2, 7, 8]);
    let looped = (0..8).find(|&i| t.streamline(i).len() == 8).unwrap();
    let s = t.streamline(looped);
    assert_eq!(s[0], s[7], "LINE_LOOP closes on its first vertex");
    assert!(close(s[0], [0.0, 0.0, 0.0]), "LINE_LOOP node at the origin: {:?}", s[0]);
    let strip = (0..8).find(|&i| t.streamline(i).len() == 7).unwrap();
    assert!(close(t.streamline(strip)[3], [2.0, 1.0, 0.0]), "LINE_STRIP node translated by (2, 0, 0)");
    let segment = (0..8).find(|&i| t.streamline(i).len() == 2).unwrap();
    assert!(close(t.streamline(segment)[0], [-2.0, 0.0, 0.0]), "LINES node translated by (−2, 0, 0)");
}

#[test]
fn a_zip_of_trk_files_is_not_a_trx() {
    let e = load(data(&format!("{DIPY}minimal_bundles.zip"))).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::UnknownFormat(_)), "{e}");
    assert!(e.to_string().contains("AF_L.trk"), "the message says what the zip holds: {e}");
}
