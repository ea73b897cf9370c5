//! `lineao info`, `convert` and `render FILE` on real files: docs/reference.md's JSON and exit codes.

use std::path::Path;

mod common;
use common::{lineao, scratch};

use serde_json::Value;

fn data(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data").join(rel).to_string_lossy().into_owned()
}

fn info(path: &str) -> Value {
    let out = lineao(&["info", "--json", path]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn info_json_is_the_contract() {
    let v = info(&data("niivue+niivue/packages/niivue/demos/images/colby.trk"));
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    let mut want = vec![
        "format",
        "compression",
        "streamlines",
        "vertices",
        "first_point",
        "last_point",
        "bounds",
        "vertex_fields",
        "streamline_fields",
        "groups",
        "affine",
        "dimensions",
        "voxel_sizes",
    ];
    want.sort();
    let mut keys = keys;
    keys.sort();
    assert_eq!(keys, want);
    assert_eq!((v["format"].as_str(), v["compression"].as_str()), (Some("trk"), Some("none")));
    assert_eq!((v["streamlines"].as_u64(), v["vertices"].as_u64()), (Some(2), Some(32)));
    assert_eq!(v["first_point"], serde_json::json!([191.5, -0.5, -0.5]));
    // Names with trailing spaces trimmed (the file pads `effect   `).
    assert_eq!(v["vertex_fields"], serde_json::json!({"effect": 1, "pval": 1, "pval_corr": 1}));
    assert_eq!(v["affine"][3], serde_json::json!([0.0, 0.0, 0.0, 1.0]));
    assert_eq!(v["dimensions"], serde_json::json!([192, 192, 55]));
    assert_eq!(v["voxel_sizes"], serde_json::json!([1.25, 1.25, 2.5]));
    let min = &v["bounds"]["min"];
    assert!(min[0].as_f64().unwrap() <= 81.9);

    let v = info(&data(
        "niivue+niivue/packages/niivue/demos/images/sub-01_ses-01_dwi_space-RASMM_model-probCSD_algo-AFQ_tractography.trx",
    ));
    assert_eq!((v["format"].as_str(), v["compression"].as_str()), (Some("trx"), Some("zip")));
    assert_eq!(v["groups"], serde_json::json!({"ARC_L": 486, "ARC_R": 22}));
    assert_eq!(v["voxel_sizes"], Value::Null, "TRX records only the affine");

    let v = info(&data("nipy+nibabel/nibabel/tests/data/empty.tck"));
    assert_eq!(
        (v["first_point"].clone(), v["bounds"].clone(), v["affine"].clone()),
        (Value::Null, Value::Null, Value::Null)
    );

    let v = info(&data("niivue+niivue/packages/niivue/demos/images/mni152.SLF1_R.tsf"));
    assert_eq!(
        (v["format"].as_str(), v["streamlines"].as_u64(), v["vertices"].as_u64()),
        (Some("tsf"), Some(13), Some(156))
    );
    assert_eq!(v["first_point"], Value::Null, "a .tsf's values have no points");

    let v = info(&data("niivue+niivue/packages/niivue/demos/images/stroke.trk.gz"));
    assert_eq!((v["format"].as_str(), v["compression"].as_str()), (Some("trk"), Some("gzip")));
}

#[test]
fn bad_files_exit_1_naming_the_file_and_bad_command_lines_exit_2() {
    for rel in [
        "niivue+niivue/packages/niivue/demos/images/issue1298.vtk",
        "nipy+nibabel/nibabel/tests/data/no_header_end.tck",
        "tee-ar-ex+trx-rs/tests/fixtures/tinytrack_malformed.tt.gz",
        "dipy+dipy/dipy/data/files/minimal_bundles.zip",
        "no/such/file.trk",
    ] {
        let path = data(rel);
        let out = lineao(&["info", "--json", &path]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{rel}: {err}");
        assert!(err.contains(Path::new(rel).file_name().unwrap().to_str().unwrap()), "{rel}: {err}");
        assert!(out.stdout.is_empty(), "{rel}");
    }
    assert_eq!(lineao(&["info"]).status.code(), Some(2));
    assert_eq!(lineao(&["convert", "only-one.trk"]).status.code(), Some(2));
    let out = lineao(&["convert", &data("nipy+nibabel/nibabel/tests/data/simple.trk"), "/tmp/out.vtk"]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn convert_round_trips_through_the_cli() {
    let dir = scratch("convert");
    let src = data("nipy+nibabel/nibabel/tests/data/complex_big_endian.trk");
    let before = info(&src);
    for ext in ["trx", "trk", "tck"] {
        let out_path = dir.join(format!("complex.{ext}")).to_string_lossy().into_owned();
        let out = lineao(&["convert", &src, &out_path]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{err}");
        let after = info(&out_path);
        assert_eq!(after["format"].as_str(), Some(ext));
        for key in ["streamlines", "vertices", "first_point", "last_point"] {
            assert_eq!(after[key], before[key], "{ext}: {key}");
        }
        if ext == "tck" {
            assert!(err.contains("left out: colors, fa, mean_colors"), "{err}");
        } else {
            assert_eq!(after["vertex_fields"], before["vertex_fields"], "{ext}");
            assert_eq!(after["streamline_fields"], before["streamline_fields"], "{ext}");
        }
    }
}

#[test]
fn render_a_real_file() {
    let dir = scratch("render-file");
    let png = dir.join("ifof.png").to_string_lossy().into_owned();
    let out = lineao(&[
        "render",
        &data("niivue+niivue/packages/niivue/demos/images/tract.IFOF_R.trk"),
        "--width",
        "160",
        "--height",
        "120",
        "-o",
        &png,
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("14 streamlines, 168 vertices"), "{err}");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let frame = reader.next_frame(&mut buf).unwrap();
    assert_eq!((frame.width, frame.height), (160, 120));
    // The lines are in view: some pixels differ from the white background.
    let drawn = buf[..frame.buffer_size()].chunks(4).filter(|p| p[0] < 250 || p[1] < 250 || p[2] < 250).count();
    assert!(drawn > 100, "{drawn} pixels drawn");
    // A value-only file cannot be rendered: a clear error.
    let out = lineao(&["render", &data("niivue+niivue/packages/niivue/demos/images/mni152.SLF1_R.tsf"), "-o", &png]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("values without points"));
}

/// `render --cull on` (the second frame of a view, culled on the GPU) draws the picture
/// `--cull off` draws, pixel for pixel, on a real tractogram (stroke.trk.gz, 2.5 M points) where
/// both draw the full strip — lines wider than 8 px, which the alternating strip is never used
/// for. At the default width they differ on line edges, not by the cull: every line is drawn
/// as the alternating strip where it stays within about half a pixel of the full one, the
/// culled pieces always as their part of the full strip; those pixels are counted and bounded.
#[test]
fn the_culled_picture_of_a_real_tractogram_is_the_picture_of_every_line() {
    let dir = scratch("cull-on-off");
    let file = data("niivue+niivue/packages/niivue/demos/images/stroke.trk.gz");
    let picture = |cull: &str, width: &str| {
        let output = dir.join(format!("{cull}-{width}.png"));
        let output = output.to_string_lossy().into_owned();
        let size = ["--width", "320", "--height", "256", "--method", "none", "--lod", "off"];
        let args = [&["render", file.as_str()][..], &size, &["--cull", cull, "--line-width", width, "-o", &output]];
        let out = lineao(&args.concat());
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        common::read_png(Path::new(&output)).1
    };
    assert!(picture("on", "9") == picture("off", "9"), "the culled full strips differ from every line's");
    let (culled, all) = (picture("on", "2"), picture("off", "2"));
    let differ = culled.chunks(4).zip(all.chunks(4)).filter(|(a, b)| a != b).count();
    println!("at 2 px, {differ} of {} pixels differ (the alternating strip's edges)", 320 * 256);
    assert!(differ * 50 <= 320 * 256, "{differ} pixels differ");
}
