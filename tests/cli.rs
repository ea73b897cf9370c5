//! `lineao render` end to end: exit codes, the PNG, and `--dump` read back the way an outside
//! tool would, recomputing LineAO from the dumped files alone.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::{lineao, lineao_command, scratch};

use lineao::lighting::Light;
use lineao::reference::{self, Image, LineAoParams, SsaoParams, ViewParams, VoParams};
use lineao::reference::{line_ao_flip_bound, line_ao_reference_flip_bound};
use lineao::verify::check_policy;
use lineao::{LineAoOuter, LineAoVariant};
use serde_json::Value;

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn exit_codes() {
    assert_eq!(lineao(&["--help"]).status.code(), Some(0));
    assert_eq!(lineao(&["render", "--help"]).status.code(), Some(0));
    for bad in [
        &["render", "--no-such-flag"][..],
        &["render", "--scene", "brain"],
        &["render", "--method", "magic"],
        &["render", "--width", "0"],
        &["render", "--eye", "1,2"],
        &["render", "--debug-view", "level:x"],
        &["frobnicate"],
    ] {
        let out = lineao(bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {}", stderr(&out));
    }
    // A reach as a share of the scene: in (0 %, 100 %], a number.
    for (bad, reason) in [
        (&["score", "--ao-distance", "0%"][..], "(0 %, 100 %]"),
        (&["score", "--ao-distance", "120%"], "(0 %, 100 %]"),
        (&["render", "--ao-distance", "x%"], "a share such as 20%"),
        (&["score", "--bundle-distance=-5%"], "(0 %, 100 %]"),
        (&["score", "--ao-distance=-2"], "must be > 0 world units"),
        // Library ranges the command line knows: a bad command line, and the option named.
        (&["render", "--s-h", "0"], "--s-h"),
        // A described setting's range (`lineao::method::setting`), whichever method is shown.
        (&["render", "--s-r", "9"], "--s-r must be in 1..=5, got 9"),
        (&["render", "--method", "vo-line", "--ssao-samples", "40"], "--ssao-samples must be in 8..=32"),
        (&["render", "--method", "ssao", "--vo-samples", "6"], "--vo-samples must be 5, 7, 9, 12, 13 or 16, got 6"),
        (&["render", "--delta-scale", "0"], "(0, 1]"),
        (&["render", "--method", "vo-line", "--radius", "0"], "--radius"),
        (&["render", "--method", "vo-line", "--vo-radius", "0"], "--vo-radius"),
        (&["render", "--ssao-radius=-1"], "--ssao-radius"),
        // Settings as JSON are checked against their types, the key named.
        (
            &["render", "--settings", r#"{"ssao": {"sample": 12}}"#],
            "ssao.sample: unknown field `sample`, expected one of `samples`",
        ),
        (&["render", "--settings", r#"{"line_ao": {"s_r": "two"}}"#], "line_ao.s_r: invalid type"),
        (&["render", "--settings", r#"{"method": "ssao"}"#], "--method"),
        (&["render", "--settings", "/nonexistent/settings.json"], "/nonexistent/settings.json"),
    ] {
        let out = lineao(bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(reason), "{bad:?}: {}", stderr(&out));
    }
    let dir = scratch("exit_codes");
    let png = dir.join("x.png");
    let png = png.to_str().unwrap();
    for (bad, needle) in [
        (&["render", "--line-width", "0", "-o", png][..], "--line-width must be in (0, 256] px, got 0"),
        (
            &["render", "--debug-view", "level:3", "-o", png],
            "--debug-view must be a level of the pyramid's: level:0 to level:1, got level:3",
        ),
        (&["render", "--eye", "0,0,0", "--target", "0,0,0", "-o", png], "coincide"),
        (&["render", "--method", "ssao", "--ssao-kernel", "sphere", "--samples", "10", "-o", png], "sphere kernel"),
        (
            &["render", "--variant", "reference", "--outer", "level", "-o", png],
            "--outer does not go with --variant: outer = level applies",
        ),
        (&["render", "--surface", "/nonexistent/hull.obj", "-o", png], "/nonexistent/hull.obj"),
        (
            &["render", "--geometry", "tubes", "--tube-radius=-1", "-o", png],
            "--tube-radius must be > 0 world units, got -1",
        ),
        (
            &["render", "--vertices", "2000", "--width", "64", "--height", "64", "-o", "/nonexistent/dir/x.png"],
            "/nonexistent/dir/x.png",
        ),
    ] {
        let out = lineao(bad);
        assert_eq!(out.status.code(), Some(1), "{bad:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{bad:?}: {}", stderr(&out));
    }
    // A selection's error is said once (it was twice: its own words and its source's).
    let out = lineao(&["render", "--vertices", "2000", "--field", "nope,0,1", "-o", png]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert_eq!(stderr(&out).matches("no per-streamline field 'nope'").count(), 1, "{}", stderr(&out));
}

/// `--timed-frames` prints each pass's median, `--timings-against` the cost of a change of
/// settings measured frame for frame, and the picture written is the picture's own.
#[test]
fn timings_over_frames_and_against_other_settings() {
    let dir = scratch("timings");
    let (timed, plain) = (dir.join("timed.png"), dir.join("plain.png"));
    let size = ["--vertices", "3000", "--width", "96", "--height", "64"];
    let against = r#"{"strength": 0.5, "slices": null}"#;
    let timing = ["--timings", "--timed-frames", "3", "--timings-against", against, "-o", timed.to_str().unwrap()];
    let out = lineao(&[&["render"][..], &size, &timing].concat());
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("(GPU, median of 3 frames)"), "{text}");
    assert!(text.contains(r#"against {"slices":null,"strength":0.5}: lines"#), "{text}");
    assert!(text.contains("the picture's frame"), "{text}");
    assert_eq!(lineao(&[&["render"][..], &size, &["-o", plain.to_str().unwrap()]].concat()).status.code(), Some(0));
    assert!(std::fs::read(&timed).unwrap() == std::fs::read(&plain).unwrap(), "the timed picture differs");
    // Without --timings the comparison is a bad command line.
    assert_eq!(lineao(&["render", "--timings-against", against]).status.code(), Some(2));
}

/// A single picture of a whole brain is culled where `--cull` is not given: its first frame
/// seeds the cull (every 8th cluster drawn, the rest culled against their depth), and it is the
/// picture drawing every line with the full strip makes (`--cull on --lod off`, settled), byte
/// for byte; `--timings` says what was chosen. Below the threshold every line is drawn, as
/// `--cull off` draws it.
#[test]
fn a_single_picture_of_a_whole_brain_is_culled_where_that_is_cheaper() {
    let dir = scratch("cull-auto");
    let picture = |vertices: &str, cull: &[&str], name: &str| {
        let path = dir.join(name);
        let size = ["--scene", "wholebrain", "--vertices", vertices, "--width", "128", "--height", "96"];
        let args = [&["render"][..], &size, &["--method", "none", "-o", path.to_str().unwrap()], cull].concat();
        let out = lineao(&args);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        (std::fs::read(&path).unwrap(), stderr(&out))
    };
    let whole_brain = "8100000";
    // Timed over three frames: the picture is the first one's still.
    let (chosen, said) = picture(whole_brain, &["--timings", "--timed-frames", "3"], "chosen.png");
    assert!(said.contains("cull on (8037714 points; culled from 8000000)"), "{said}");
    assert!(said.contains("cull: drew"), "the culled frame reports what it drew: {said}");
    let (full_strip, _) = picture(whole_brain, &["--cull", "on", "--lod", "off"], "full-strip.png");
    assert!(chosen == full_strip, "the culled single picture differs from the full strip's");
    let (small, said) = picture("400000", &["--timings"], "small.png");
    assert!(said.contains("cull off (") && !said.contains("cull: drew"), "{said}");
    assert!(small == picture("400000", &["--cull", "off"], "off.png").0, "below the threshold every line is drawn");
}

fn read_npy(path: &Path) -> (Vec<u64>, Vec<f32>) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    let shape = npy.shape().to_vec();
    (shape, npy.into_vec::<f32>().unwrap())
}

fn vec3(v: &Value) -> [f32; 3] {
    let a: Vec<f32> = v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect();
    [a[0], a[1], a[2]]
}

#[test]
fn render_and_dump_let_an_outside_tool_recompute_lineao() {
    recompute_from_dump("paper", "full", "lines");
}

#[test]
fn render_and_dump_let_an_outside_tool_recompute_the_reference_variant() {
    recompute_from_dump("reference", "full", "lines");
}

#[test]
fn render_and_dump_let_an_outside_tool_recompute_lineao_with_outer_level() {
    recompute_from_dump("paper", "level", "lines");
}

#[test]
fn render_and_dump_let_an_outside_tool_recompute_lineao_on_tubes() {
    recompute_from_dump("paper", "full", "tubes");
}

/// `lineao render` at 200 × 150 on 60 000 vertices with `extra` options and `--dump`; returns
/// the PNG's and the dump folder's paths.
fn render_with_dump(name: &str, extra: &[&str]) -> (PathBuf, PathBuf) {
    let dir = scratch(name);
    let (png, dump) = (dir.join("out.png"), dir.join("dump"));
    let mut args = vec!["render", "--vertices", "60000", "--width", "200", "--height", "150"];
    args.extend(extra);
    args.extend(["-o", png.to_str().unwrap(), "--dump", dump.to_str().unwrap()]);
    let out = lineao(&args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    (png, dump)
}

/// Renders with `--variant variant --dump` as `geometry` (lines or tubes), then recomputes LineAO
/// from the dumped files and `params.json` alone, as an outside implementation would (for tubes
/// with docs/reference.md's r0(P) = 1.5 · z(P) · t_s / zoom_unit, t_s = 2 × `tube_radius_world`).
fn recompute_from_dump(variant: &str, outer: &str, geometry: &str) {
    let (png, dump) = render_with_dump(
        &format!("dump-{variant}-{outer}-{geometry}"),
        &[
            "--scene",
            "spiral",
            "--variant",
            variant,
            "--outer",
            outer,
            "--guard-max",
            "48",
            "--geometry",
            geometry,
            "--tube-radius",
            "0.6",
        ],
    );

    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (200, 150));

    let params: Value = serde_json::from_str(&std::fs::read_to_string(dump.join("params.json")).unwrap()).unwrap();
    let variant_keys: &[&str] = match variant {
        "paper" => &["r0_px", "delta0", "delta_scale", "epsilon", "kd", "ks", "shininess"],
        _ => &["reference_radius_px", "zoom_fit"],
    };
    let geometry_key = if geometry == "tubes" { "tube_radius_world" } else { "line_width_px" };
    assert_eq!(params["geometry"], geometry);
    let common = [
        geometry_key,
        "method",
        "variant",
        "geometry",
        "s_r",
        "s_h",
        "strength",
        "light_attenuation",
        "lights",
        "zoom_unit",
        "guard_px",
        "noise_seed",
        "outer",
        "depth_near",
        "depth_far",
        "width",
        "height",
        "camera",
    ];
    for key in common.iter().chain(variant_keys) {
        assert!(params.get(key).is_some(), "params.json lacks {key}");
    }
    assert_eq!(params["variant"], variant);
    assert_eq!(params["outer"], outer);
    assert_eq!(
        params.get("outer_depth_tolerance").and_then(Value::as_f64).map(|t| t as f32),
        match outer {
            "level" => Some(lineao::reference::OUTER_DEPTH_TOLERANCE),
            _ => None,
        }
    );
    assert_eq!(params["method"], "lineao");
    assert_eq!((params["width"].as_u64(), params["height"].as_u64()), (Some(200), Some(150)));
    assert!(params["camera"]["fov_y_deg"].is_number());
    let guard = params["guard_px"].as_u64().unwrap();
    let s_r = params["s_r"].as_u64().unwrap() as u32;
    let s_h = params["s_h"].as_u64().unwrap() as u32;
    assert!(guard > 0 && guard.is_multiple_of(1 << (s_r - 1)));
    let (w, h) = (200 + 2 * guard, 150 + 2 * guard);

    let mut levels = Vec::new();
    let (mut lw, mut lh) = (w, h);
    let pyramid_levels = if variant == "paper" { s_r } else { 1 };
    for j in 0..pyramid_levels {
        let (shape, data) = read_npy(&dump.join(format!("nd_{j}.npy")));
        assert_eq!(shape, [lh, lw, 4], "nd_{j}.npy");
        levels.push(Image {
            width: lw as usize,
            height: lh as usize,
            data: data.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect(),
        });
        (lw, lh) = (lw.div_ceil(2), lh.div_ceil(2));
    }
    let (shape, zoom) = read_npy(&dump.join("zoom.npy"));
    assert_eq!(shape, [h, w]);
    let (shape, ao) = read_npy(&dump.join("ao.npy"));
    assert_eq!(shape, [h, w]);
    let (shape, noise) = read_npy(&dump.join("noise.npy"));
    assert_eq!(shape, [64, 64, 3]);
    let (shape, samples) = read_npy(&dump.join("samples.npy"));
    assert_eq!(shape, [s_r as u64, s_h as u64, 3]);

    let lights = params["lights"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| Light { dir: vec3(&l["dir"]).into(), intensity: l["intensity"].as_f64().unwrap() as f32 })
        .collect();
    let get = |k: &str| params.get(k).and_then(Value::as_f64).unwrap_or(0.0) as f32;
    let reference_scale = if variant == "paper" {
        [0.0; 2]
    } else {
        let (vw, vh) = (get("width"), get("height"));
        let k = get("reference_radius_px") / get("zoom_fit") / vw.max(vh);
        [k * vw, k * vh]
    };
    let p = LineAoParams {
        variant: if variant == "paper" { LineAoVariant::Paper } else { LineAoVariant::Reference },
        outer: if outer == "level" { LineAoOuter::Level } else { LineAoOuter::Full },
        reference_scale,
        s_r,
        s_h,
        r0_px: get("r0_px"),
        r0_zoom: 1.5 * 2.0 * get("tube_radius_world") / get("zoom_unit"),
        delta0: get("delta0"),
        delta_scale: get("delta_scale"),
        epsilon: get("epsilon"),
        light_attenuation: params["light_attenuation"].as_bool().unwrap(),
        lights,
        kd: get("kd"),
        ks: get("ks"),
        shininess: get("shininess"),
        noise_origin: [guard as i32; 2],
    };
    let triples = |v: &[f32]| v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect::<Vec<_>>();
    let zoom = Image { width: w as usize, height: h as usize, data: zoom };
    let gpu_ao = Image { width: w as usize, height: h as usize, data: ao };
    let cpu_ao = reference::line_ao(&levels, &zoom, &triples(&noise), &triples(&samples), &p);
    let bound = if variant == "paper" { line_ao_flip_bound(s_r, s_h) } else { line_ao_reference_flip_bound(s_h) };
    let stats = check_policy(&gpu_ao, &cpu_ao, &levels[0], bound).unwrap();
    println!("{variant}, outer = {outer}, {geometry}, recomputed from the dump: {stats}");
    assert!(gpu_ao.data.iter().filter(|&&a| a > 0.1).count() > 1000);
}

/// The bench's passes timed on the CPU (docs/reference.md's and `select`).
const CPU_PASSES: [&str; 7] =
    ["density-256", "sweep-256", "variance-volume-256", "bvh-build-1m", "raytraced-cpu-64", "bvh-upload", "select"];

/// `lineao bench --json` on a small scene with `extra` options; the report.
fn bench_report(extra: &[&str]) -> Value {
    let mut args = vec!["bench", "--json", "--vertices", "3000"];
    args.extend(extra);
    let out = lineao(&args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

#[test]
fn bench_json_is_the_contract() {
    let report = bench_report(&["--width", "96", "--height", "64", "--frames", "3", "--warmup", "1"]);
    for key in ["adapter", "backend", "width", "height", "scene", "vertices", "frames", "timestamps", "passes"] {
        assert!(report.get(key).is_some(), "bench JSON lacks {key}");
    }
    assert_eq!((report["width"].as_u64(), report["height"].as_u64()), (Some(96), Some(64)));
    assert_eq!((report["scene"].as_str(), report["frames"].as_u64()), (Some("bundles"), Some(3)));
    assert!(report["vertices"].as_u64().unwrap() > 1000);
    let on = if report["timestamps"] == true { "gpu" } else { "cpu" };
    let passes = report["passes"].as_array().unwrap();
    let names: Vec<&str> = passes.iter().map(|p| p["name"].as_str().unwrap()).collect();
    // Every pass of docs/reference.md, and the test build's `toy` (the registry's methods list
    // theirs); in the bench's order, its own passes first.
    let mut sorted = names.clone();
    sorted.sort_unstable();
    let mut expected = [
        "lines",
        "lines-native-1px",
        "lines-full-strip",
        "lines-strip",
        "nd-pyramid",
        "lines-all",
        "lines-culled",
        "lines-culled-exact",
        "lines-compute",
        "cull",
        "lineao",
        "lineao-tap-floor",
        "composite",
        "lineao-chain",
        "lineao-level",
        "lineao-chain-level",
        "ssao-12",
        "ssao-16-chain",
        "vo-line-5",
        "vo-area-1",
        "bilateral",
        "tubes",
        "tubes-culled",
        "tubes-culled-exact",
        "nd-from-depth",
        "lines-transparent",
        "raytraced-1spp",
        "raytraced-start-1spp",
        "ray-denoise",
        "toy",
    ]
    .into_iter()
    .chain(CPU_PASSES)
    .collect::<Vec<_>>();
    expected.sort_unstable();
    assert_eq!(sorted, expected);
    assert_eq!(names[..5], ["lines", "lines-native-1px", "lines-full-strip", "lines-strip", "nd-pyramid"]);
    // The line geometry's bytes a vertex on the GPU: the clusters' and the earlier strip's.
    let (clusters, strip) =
        (report["gpu_bytes_per_vertex"].as_f64().unwrap(), report["strip_bytes_per_vertex"].as_f64().unwrap());
    assert!(clusters <= 8.0 && strip > 40.0, "{clusters} and {strip} bytes a vertex");
    // The culled lines' last frame: a share of the pieces, in a share of the clusters.
    let (pieces, culled) = (report["visible_pieces"].as_f64().unwrap(), report["visible_clusters"].as_f64().unwrap());
    assert!(
        0.0 < pieces && pieces <= 1.0 && 0.0 < culled && culled <= 1.0,
        "{pieces} of the pieces in {culled} of the clusters"
    );
    for p in passes {
        let cpu_pass = CPU_PASSES.contains(&p["name"].as_str().unwrap());
        assert_eq!(p["on"], if cpu_pass { "cpu" } else { on });
        let ms = |k: &str| p[k].as_f64().unwrap();
        assert!(0.0 <= ms("ms_min") && ms("ms_min") <= ms("ms_median") && ms("ms_median") <= ms("ms_max"), "{p}");
        assert!(ms("ms_max") < 60_000.0, "{p}");
    }
    assert_eq!(lineao(&["bench", "--frames", "0"]).status.code(), Some(2));
    assert_eq!(lineao(&["bench", "--passes", "lines,warp-drive"]).status.code(), Some(2));
    let out = lineao(&["bench", "--fov", "180", "--passes", "lines"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("--fov must be in (0, 180) degrees, got 180"), "{}", stderr(&out));

    // The CPU fallback (adapters without timestamp queries), on a subset of the passes.
    let report = bench_report(&[
        "--no-timestamps",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--passes",
        "lines,lineao",
        "--fov",
        "15",
    ]);
    assert_eq!(report["timestamps"], false);
    let passes = report["passes"].as_array().unwrap();
    assert_eq!(passes.iter().map(|p| p["name"].as_str().unwrap()).collect::<Vec<_>>(), ["lines", "lineao"]);
    assert!(passes.iter().all(|p| p["on"] == "cpu" && p["ms_median"].as_f64().unwrap() > 0.0));
}

/// `--method ssao --dump`: Crytek SSAO recomputed from the dumped files and `params.json` alone
/// (the projection from the camera's field of view and the image height, as an outside tool
/// would), against the dumped raw `ao.npy`.
#[test]
fn render_and_dump_let_an_outside_tool_recompute_ssao() {
    let extra = ["--scene", "vortex", "--method", "ssao", "--samples", "12", "--radius", "3"];
    let (_, dump) = render_with_dump("dump-ssao", &extra);
    let params: Value = serde_json::from_str(&std::fs::read_to_string(dump.join("params.json")).unwrap()).unwrap();
    assert_eq!(params["method"], "ssao");
    assert_eq!(
        (params["samples"].as_u64(), params["radius_world"].as_f64(), params["ssao_range"].as_f64()),
        (Some(12), Some(3.0), Some(3.0))
    );
    assert_eq!(params["ssao_kernel"], "crytek");
    assert!(params.get("s_r").is_none(), "LineAO keys are omitted for SSAO");
    let f = |k: &str| params[k].as_f64().unwrap() as f32;
    let guard = params["guard_px"].as_u64().unwrap() as usize;
    let (w, h) = (
        params["width"].as_u64().unwrap() as usize + 2 * guard,
        params["height"].as_u64().unwrap() as usize + 2 * guard,
    );
    let f_px = match params["camera"]["fov_y_deg"].as_f64() {
        Some(fov) => f("height") / (2.0 * ((fov as f32).to_radians() * 0.5).tan()),
        None => f("height") / params["camera"]["ortho_height"].as_f64().unwrap() as f32,
    };
    let view = ViewParams {
        near: f("depth_near"),
        far: f("depth_far"),
        f_px,
        orthographic: params["camera"]["fov_y_deg"].is_null(),
        center: [w as f32 * 0.5, h as f32 * 0.5],
    };
    let (shape, nd) = read_npy(&dump.join("nd_0.npy"));
    assert_eq!(shape, [h as u64, w as u64, 4]);
    let nd0 = Image { width: w, height: h, data: nd.chunks_exact(4).map(|t| [t[0], t[1], t[2], t[3]]).collect() };
    let (_, ao) = read_npy(&dump.join("ao.npy"));
    let ao = Image { width: w, height: h, data: ao };
    let (kshape, kernel) = read_npy(&dump.join("ssao_kernel.npy"));
    assert_eq!(kshape, [12, 3]);
    let (nshape, tile) = read_npy(&dump.join("ssao_noise.npy"));
    assert_eq!(nshape, [4, 4, 3]);
    let triples = |v: &[f32]| v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect::<Vec<_>>();
    let p = SsaoParams { view, radius: f("radius_world"), range: f("ssao_range"), noise_origin: [guard as i32; 2] };
    let cpu = reference::ssao(&nd0, &triples(&kernel), &triples(&tile), &p);
    let stats = check_policy(&ao, &cpu, &nd0, 2.0 / 12.0).unwrap_or_else(|e| panic!("{e}"));
    println!("ssao from --dump: {stats}");
    assert!(ao.data.iter().filter(|&&a| a > 0.05).count() > 200, "SSAO occludes something");
}

/// `--method vo-line|vo-area --dump`: VO recomputed from the dumped files and `params.json`
/// alone (area sampling from the dumped moments pyramid, which is checked against `nd_0.npy`).
#[test]
fn render_and_dump_let_an_outside_tool_recompute_vo() {
    let runs: [(&str, &[&str]); 2] = [
        ("vo-line", &["--samples", "7", "--thickness", "1", "--radius2", "6", "--combine", "min"]),
        ("vo-area", &["--samples", "5", "--no-normal-clamp"]),
    ];
    for (method, options) in runs {
        let mut extra = vec!["--scene", "spiral", "--method", method, "--radius", "3"];
        extra.extend(options);
        let (_, dump) = render_with_dump(&format!("dump-{method}"), &extra);
        let params: Value = serde_json::from_str(&std::fs::read_to_string(dump.join("params.json")).unwrap()).unwrap();
        assert_eq!(params["method"], method);
        let n = params["samples"].as_u64().unwrap() as usize;
        let f = |k: &str| params[k].as_f64().unwrap() as f32;
        let guard = params["guard_px"].as_u64().unwrap() as usize;
        let (w, h) = (
            params["width"].as_u64().unwrap() as usize + 2 * guard,
            params["height"].as_u64().unwrap() as usize + 2 * guard,
        );
        let fov = params["camera"]["fov_y_deg"].as_f64().unwrap() as f32;
        let view = ViewParams {
            near: f("depth_near"),
            far: f("depth_far"),
            f_px: f("height") / (2.0 * (fov.to_radians() * 0.5).tan()),
            orthographic: false,
            center: [w as f32 * 0.5, h as f32 * 0.5],
        };
        let (_, nd) = read_npy(&dump.join("nd_0.npy"));
        let nd0 = Image { width: w, height: h, data: nd.chunks_exact(4).map(|t| [t[0], t[1], t[2], t[3]]).collect() };
        let zoom = Image { width: w, height: h, data: read_npy(&dump.join("zoom.npy")).1 };
        let ao = Image { width: w, height: h, data: read_npy(&dump.join("ao.npy")).1 };
        let (sshape, samples) = read_npy(&dump.join("vo_samples.npy"));
        assert_eq!(sshape, [n as u64, 3]);
        let (nshape, tile) = read_npy(&dump.join("vo_noise.npy"));
        assert_eq!(nshape, [4, 4, 2]);
        let samples: Vec<[f32; 3]> = samples.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let tile: Vec<[f32; 2]> = tile.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        let p = VoParams {
            view,
            radius: f("radius_world"),
            radius2: params["radius2_world"].as_f64().map(|r| r as f32),
            combine: match params["combine"].as_str() {
                Some("min") => lineao::VoCombine::Min,
                None | Some("product") => lineao::VoCombine::Product,
                Some(other) => panic!("combine {other}"),
            },
            zoom_unit: f("zoom_unit"),
            normal_clamp: params["normal_clamp"].as_bool().unwrap(),
            thickness: f("thickness"),
            noise_origin: [guard as i32; 2],
        };
        let (cpu, bound) = if method == "vo-line" {
            assert_eq!((p.radius2, p.combine), (Some(6.0), lineao::VoCombine::Min));
            (reference::vo_line(&nd0, &zoom, &samples, &tile, &p), 2.0 / n as f32)
        } else {
            let moments: Vec<_> = (0..)
                .map(|l| dump.join(format!("moments_{l}.npy")))
                .take_while(|path| path.exists())
                .map(|path| {
                    let (shape, data) = read_npy(&path);
                    let (height, width) = (shape[0] as usize, shape[1] as usize);
                    Image { width, height, data: data.chunks_exact(2).map(|c| [c[0], c[1]]).collect() }
                })
                .collect();
            assert_eq!(moments.last().map(|m| (m.width, m.height)), Some((1, 1)));
            let z = view.linear_depth(nd0.get(40, 30)[3]);
            let m = moments[0].get(40, 30);
            assert!((m[0] - z).abs() <= 1e-5 * z && (m[1] - z * z).abs() <= 1e-5 * z * z, "{m:?} vs {z}");
            let lod = lineao::sample_sets::vo_area_lod_offsets(&samples);
            (reference::vo_area(&nd0, &zoom, &moments, &samples, &lod, &tile, &p), 1e-2)
        };
        let stats = check_policy(&ao, &cpu, &nd0, bound).unwrap_or_else(|e| panic!("{method}: {e}"));
        println!("{method} from --dump: {stats}");
        assert!(ao.data.iter().filter(|&&a| a > 0.05).count() > 200, "{method} obscures something");
    }
}

/// `--compare` and `--grid` write one labelled image of the right size; `--dump` with several
/// methods writes one folder per method; a wrong pair is a command-line error.
#[test]
fn compare_and_grid_write_one_image() {
    let dir = scratch("compare-grid");
    for (name, extra, size) in
        [("compare", &["--compare", "vo-area,lineao"][..], (90, 60)), ("grid", &["--grid"][..], (270, 180))]
    {
        let png = dir.join(format!("{name}.png"));
        let dump = dir.join(format!("{name}-dump"));
        let mut args = vec!["render", "--vertices", "5000", "--width", "90", "--height", "60", "-o"];
        args.extend([png.to_str().unwrap(), "--dump", dump.to_str().unwrap()]);
        args.extend(extra);
        let output = lineao(&args);
        assert!(output.status.success(), "{name}: {}", stderr(&output));
        let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
        let info = decoder.read_info().unwrap();
        assert_eq!((info.info().width, info.info().height), size, "{name}");
        let folders = if name == "compare" {
            vec!["vo-area", "lineao"]
        } else {
            vec![
                "none",
                "lineao",
                "lineao-reference",
                "vo-line",
                "vo-area",
                "ssao",
                "sweep",
                "variance-volume",
                "lineao+sweep",
            ]
        };
        for folder in folders {
            let params = std::fs::read_to_string(dump.join(folder).join("params.json")).unwrap();
            assert!(params.contains("\"method\""), "{name}: {folder}");
        }
    }
    for bad in ["lineao", "lineao,ssao,vo-line", "lineao,magic", "ssao, ssao", "sweep,none+sweep", "sweep+lineao,ssao"]
    {
        let output = lineao(&["render", "--compare", bad, "-o", dir.join("x.png").to_str().unwrap()]);
        assert_eq!(output.status.code(), Some(2), "--compare {bad}: {}", stderr(&output));
    }
}

#[test]
fn an_adapter_that_cannot_run_the_passes_is_a_clear_error() {
    // wgpu's GL backend (llvmpipe through EGL) renders no Rgba32Float: exit 1 with what it lacks
    // (or, where no GL driver is installed, that there is no adapter), never a panic.
    let out = lineao_command()
        .env("WGPU_BACKEND", "gl")
        .args(["render", "--scene", "spiral", "--vertices", "2000", "--width", "64", "--height", "48", "-o"])
        .arg(scratch("gl").join("x.png"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("lineao: error:") && !stderr.contains("internal error"), "{stderr}");
    assert!(stderr.contains("cannot run lineao") || stderr.contains("no GPU adapter"), "{stderr}");
}

/// Object-space AO from `--dump` alone: `volume_ao.npy` recomputed per pixel from `octants.npy`,
/// `nd_0.npy`, `geometry_term.npy` and params.json's `sky` and `view_to_world`, as an outside
/// tool would; `ao.npy` is that occlusion for a volume method alone.
#[test]
fn render_and_dump_let_an_outside_tool_recompute_object_space_ao() {
    use lineao::volume::geometry_term::GeometryTable;
    for (name, extra) in [
        ("sweep", &["--method", "sweep", "--sky", "cloudy"][..]),
        ("variance", &["--method", "lineao+variance-volume", "--volume-combine", "min", "--volume-resolution", "64"]),
        ("tangent", &["--method", "sweep", "--volume-normal", "tangent", "--scene", "vortex"]),
    ] {
        let (_, dump) = render_with_dump(&format!("dump-volume-{name}"), extra);
        let params: Value = serde_json::from_str(&std::fs::read_to_string(dump.join("params.json")).unwrap()).unwrap();
        let (shape, octants) = read_npy(&dump.join("octants.npy"));
        let (h, w) = (shape[0] as usize, shape[1] as usize);
        assert_eq!(shape[2], 8);
        let (_, nd0) = read_npy(&dump.join("nd_0.npy"));
        let (table_shape, table) = read_npy(&dump.join("geometry_term.npy"));
        let (_, volume_ao) = read_npy(&dump.join("volume_ao.npy"));
        let size = table_shape[0] as usize;
        let table = GeometryTable { size, values: table.chunks(8).map(|c| c.try_into().unwrap()).collect() };
        let rows: Vec<[f32; 3]> = params["view_to_world"].as_array().unwrap().iter().map(vec3).collect();
        let to_world = glam::Mat3::from_cols_array_2d(&[rows[0], rows[1], rows[2]]).transpose();
        let sky: Vec<f32> = params["sky"].as_array().unwrap().iter().map(|w| w.as_f64().unwrap() as f32).collect();
        let sky: [f32; 8] = sky.try_into().unwrap();
        let (mut worst, mut geometry) = (0.0f32, 0);
        for i in 0..w * h {
            let n = glam::Vec3::new(nd0[4 * i], nd0[4 * i + 1], nd0[4 * i + 2]);
            let expected = if n == glam::Vec3::ZERO {
                0.0
            } else {
                geometry += 1;
                let v: [f32; 8] = octants[8 * i..8 * i + 8].try_into().unwrap();
                1.0 - lineao::volume::geometry_term::weighted_visibility(&v, &table.lookup(to_world * n), &sky)
            };
            worst = worst.max((expected - volume_ao[i]).abs());
        }
        println!("{name}: {geometry} geometry pixels, worst |Δ| {worst:.2e} recomputed from the dump");
        assert!(geometry > 1000 && worst < 1e-5, "{name}: {worst}");
        assert!(volume_ao.iter().filter(|&&a| a > 0.2).count() > 100, "{name}: something is occluded");
        let (_, ao) = read_npy(&dump.join("ao.npy"));
        match name {
            "variance" => {
                assert_eq!(
                    (params["method"].as_str(), params["volume_combine"].as_str()),
                    (Some("lineao+variance-volume"), Some("min"))
                );
                assert!(params["variance"]["levels"].as_u64().is_some() && ao != volume_ao);
            }
            _ => {
                assert_eq!(params["method"], "sweep");
                assert_eq!(ao, volume_ao);
            }
        }
        if name == "sweep" {
            // Cloudy: the lower octants are dark (the built-in scenes' up is +y).
            assert_eq!(sky.iter().sum::<f32>(), 4.0);
        }
        if name == "tangent" {
            // View-independent: one value in all eight octants, the sky applied already.
            assert!(octants.chunks(8).all(|v| v.iter().all(|&x| x == v[0])) && sky == [1.0; 8]);
        }
    }
    let out = lineao(&["render", "--method", "sweep", "--sweep-alpha", "0", "-o", "/tmp/lineao-never.png"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("--sweep-alpha must be in (0, 1], got 0"), "{}", stderr(&out));
}

/// `--surface` with the shared glTF sample's triangles, and `--geometry tubes`: one image each.
#[test]
fn surfaces_and_tubes_render() {
    let dir = scratch("surfaces-tubes");
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/KhronosGroup+glTF-Sample-Models/2.0/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf");
    for (name, extra) in [
        ("surface", vec!["--surface", mesh.to_str().unwrap(), "--surface-color", "0.9,0.7,0.5"]),
        ("tubes", vec!["--geometry", "tubes", "--tube-radius", "0.8", "--method", "vo-line"]),
    ] {
        let png = dir.join(format!("{name}.png"));
        let mut args = vec!["render", "--scene", "spiral", "--vertices", "5000", "--width", "96", "--height", "72"];
        args.extend(extra);
        args.extend(["-o", png.to_str().unwrap()]);
        let out = lineao(&args);
        assert_eq!(out.status.code(), Some(0), "{name}: {}", stderr(&out));
        assert!(std::fs::metadata(&png).unwrap().len() > 100);
    }
}

/// The ray-traced truth's command-line checks: bad values exit 2 with the reason.
#[test]
fn truth_options_are_checked() {
    for (bad, needle) in [
        (&["render", "--method", "raytraced", "--rays", "0"][..], "rays"),
        (&["render", "--method", "raytraced", "--ao-distance=-1"], "must be > 0 world units, or a share"),
        (&["render", "--method", "raytraced", "--ao-distance", "nan"], "must be > 0 world units"),
        (&["render", "--method", "raytraced", "--ao-distance", "inf"], "must be > 0 world units"),
        (&["score", "--ao-distance", "0"], "must be > 0 world units"),
        (&["score", "--methods", "magic"], "unknown method"),
        (&["render", "--preset", "fancy"], "unknown preset"),
        (&["render", "--delta-scale", "x"], "invalid value"),
        // The library's own names, listed from it (lineao::Named).
        (&["render", "--variant", "authors"], "[possible values: paper, reference]"),
        (&["render", "--colormap", "jet"], "[possible values: viridis, gray, coolwarm, categories]"),
        (&["render", "--ao-falloff", "cubic"], "[possible values: none, linear]"),
    ] {
        let out = lineao(bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{bad:?}: {}", stderr(&out));
    }
}

/// A lone, gently curved polyline facing the camera occludes nothing: its own segment and its
/// neighbours never occlude its surface, and no origin is buried. (A sharp zigzag does occlude
/// itself: segment k + 2 is another part of the line, a few millimetres away.) On the CPU with
/// the truth's dump, and on the GPU.
#[test]
fn a_lone_line_has_no_truth_ao() {
    for cpu in [true, false] {
        lone_line(cpu);
    }
}

fn lone_line(cpu: bool) {
    let dir = scratch("lone_line");
    let mut tracts = lineao_tracts::Tractogram::new();
    tracts.positions = (0..40).map(|i| [i as f32 * 1.5, (i as f32 * 0.35).sin() * 0.8, 0.0]).collect();
    tracts.offsets = vec![0, 40];
    let file = dir.join("curve.tck");
    lineao_tracts::save(&tracts, &file).unwrap();
    let dump = dir.join(if cpu { "dump-cpu" } else { "dump-gpu" });
    let out = lineao(&[
        "render",
        file.to_str().unwrap(),
        "--method",
        "raytraced",
        if cpu { "--cpu" } else { "--ray-seed=1" },
        "--rays",
        "64",
        "--line-width",
        "4",
        "--eye",
        "29,0,70",
        "--target",
        "29,0,0",
        "--up",
        "0,1,0",
        "--width",
        "160",
        "--height",
        "120",
        "-o",
        dir.join("x.png").to_str().unwrap(),
        "--dump",
        dump.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let (shape, ao) = read_npy(&dump.join("ao.npy"));
    let (_, nd) = read_npy(&dump.join("nd_0.npy"));
    assert_eq!(shape, [120, 160]);
    let geometry = nd.chunks(4).filter(|t| t[..3] != [0.0; 3]).count();
    assert!(geometry > 200, "{geometry} line pixels");
    let worst = ao.iter().cloned().fold(0.0f32, f32::max);
    assert_eq!(worst, 0.0, "a lone line occludes itself");
    let params: Value = serde_json::from_str(&std::fs::read_to_string(dump.join("params.json")).unwrap()).unwrap();
    assert_eq!(params["method"], "raytraced");
    assert_eq!(params["rays"], 64);
    assert_eq!(params["ao_distance_world"], 2.0);
    assert_eq!(params["ao_falloff"], "none");
    assert_eq!(params["ray_seed"], 1);
    assert_eq!(params["buried_share"], 0.0);
    assert!(dump.join("ao_stderr.npy").exists());
}

/// The truth's dump traced on the GPU equals the CPU's: the same rays give the same AO and the
/// same standard error per pixel, and the same keys.
#[test]
fn the_gpu_dump_of_the_truth_is_the_cpu_dump() {
    let dir = scratch("truth_dumps");
    let dump = |cpu: bool| {
        let to = dir.join(if cpu { "cpu" } else { "gpu" });
        let mut args = vec!["render", "--vertices", "20000", "--method", "raytraced", "--rays", "12"];
        args.extend(["--width", "160", "--height", "128", "--ao-falloff", "linear"]);
        let png = dir.join("x.png");
        args.extend(["-o", png.to_str().unwrap(), "--dump", to.to_str().unwrap()]);
        if cpu {
            args.push("--cpu");
        }
        let out = lineao(&args);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let params: Value = serde_json::from_str(&std::fs::read_to_string(to.join("params.json")).unwrap()).unwrap();
        (read_npy(&to.join("ao.npy")).1, read_npy(&to.join("ao_stderr.npy")).1, params)
    };
    let ((gpu_ao, gpu_err, gpu), (cpu_ao, cpu_err, cpu)) = (dump(false), dump(true));
    for key in ["rays", "ao_distance_world", "ao_falloff", "ray_seed", "ray_epsilon_world", "guard_px"] {
        assert_eq!(gpu[key], cpu[key], "{key}");
    }
    let (gpu_buried, cpu_buried) = (gpu["buried_share"].as_f64().unwrap(), cpu["buried_share"].as_f64().unwrap());
    assert!((gpu_buried - cpu_buried).abs() < 1e-3, "{gpu_buried} vs {cpu_buried}");
    // Linear falloff: each ray adds 1 − t/R, f32 against f64 (the GPU tests' tolerance).
    let close = |a: &[f32], b: &[f32]| a.iter().zip(b).filter(|(x, y)| (*x - *y).abs() < 1e-3).count();
    let (pixels, occluded) = (gpu_ao.len(), cpu_ao.iter().filter(|&&v| v > 0.0).count());
    assert!(occluded > 1000, "{occluded} occluded pixels");
    assert!(close(&gpu_ao, &cpu_ao) * 1000 >= pixels * 999, "AO");
    assert!(close(&gpu_err, &cpu_err) * 1000 >= pixels * 999, "standard error");
    assert!(cpu_err.iter().any(|&e| e > 0.01), "a standard error to compare");
}

/// `score` on a built-in scene: the truth traced again with another seed agrees with the truth
/// better than any screen-space method; the JSON carries every method; the truth is deterministic
/// for a seed (two runs, the same numbers).
#[test]
fn score_ranks_the_truth_first() {
    let dir = scratch("score");
    let grid = dir.join("grid.png");
    let args = [
        "score",
        "--vertices",
        "30000",
        "--width",
        "200",
        "--height",
        "160",
        "--rays",
        "64",
        "--json",
        "-o",
        grid.to_str().unwrap(),
    ];
    let out = lineao(&args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let methods = report["methods"].as_array().unwrap();
    let mut names: Vec<&str> = methods.iter().map(|m| m["method"].as_str().unwrap()).collect();
    // The test build's registry has the toy method (feature `toy-method`), scored after SSAO.
    names.retain(|name| *name != "toy");
    assert_eq!(names, ["lineao", "lineao-reference", "vo-line", "vo-area", "ssao", "raytraced"]);
    let correlation =
        |name: &str| methods.iter().find(|m| m["method"] == name).unwrap()["correlation"].as_f64().unwrap();
    let truth = correlation("raytraced");
    assert!(truth > 0.9, "the truth against itself: {truth}");
    for name in &names[..5] {
        assert!(correlation(name) < truth, "{name}: {} vs the truth's {truth}", correlation(name));
    }
    for m in methods {
        for key in ["bias", "mean_abs", "rmse", "ssim", "scale", "image_ssim", "pixels", "mean", "truth_mean"] {
            assert!(m[key].is_number(), "{key} of {}", m["method"]);
        }
        assert!(
            m["scaled"]["rmse"].as_f64().unwrap() <= m["rmse"].as_f64().unwrap() + 1e-9 || m["method"] == "raytraced"
        );
    }
    assert!(report["buried_share"].as_f64().unwrap() < 0.2);
    // Legibility of every method, `none` and both truths' pictures; the bundle-scale truth.
    for m in methods {
        let l = &m["legibility"];
        for key in ["l_local", "l_bundle", "l_global", "l_mean", "mean_darkening", "near_black"] {
            assert!(l[key].is_number(), "legibility {key} of {}", m["method"]);
        }
        assert!(m["bundle"]["correlation"].is_number());
    }
    let pictures = report["pictures"].as_array().unwrap();
    let picture = |name: &str| &pictures.iter().find(|p| p["picture"] == name).unwrap()["legibility"];
    assert_eq!(picture("none")["l_mean"].as_f64(), Some(0.0), "no AO, nothing legible");
    assert_eq!(picture("none")["mean_darkening"].as_f64(), Some(0.0));
    // Darker is deeper in the truth's own picture, at every scale.
    for key in ["l_local", "l_bundle", "l_global"] {
        assert!(
            picture("bundle-truth")[key].as_f64().unwrap() > 0.05,
            "bundle truth {key}: {}",
            picture("bundle-truth")
        );
    }
    let bundle = &report["bundle_truth"];
    assert_eq!((bundle["ao_distance"].as_str(), bundle["ao_falloff"].as_str()), (Some("20%"), Some("linear")));
    // 20 % of the bundles scene's longest side (its bounds, tens of mm).
    let reach = bundle["ao_distance_world"].as_f64().unwrap();
    assert!(reach > 10.0 && reach < 100.0, "{reach}");
    assert!(bundle["mean"].as_f64().unwrap() > report["truth_mean"].as_f64().unwrap(), "the bundle reach sees more");
    // A row of three tiles per method (and the toy's).
    assert_eq!(common::read_png(&grid).0, (3 * 200, 7 * 160));
    let again = lineao(&args);
    let again: Value = serde_json::from_slice(&again.stdout).unwrap();
    assert_eq!(report["methods"][0]["truth_mean"], again["methods"][0]["truth_mean"]);
}

/// VO is scored against the share of the ball it samples: the half ball where it clamps to the
/// normal's side, the whole ball where the flag or the `--settings` JSON turns that off.
#[test]
fn score_takes_vos_ball_from_the_settings_vo_renders_with() {
    let truth = |extra: &[&str]| {
        let mut args = vec!["score", "--vertices", "2000", "--width", "40", "--height", "32", "--rays", "4"];
        args.extend(["--methods", "vo-line", "--json"]);
        args.extend(extra);
        let out = lineao(&args);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let report: Value = serde_json::from_slice(&out.stdout).unwrap();
        report["methods"][0]["truth"].as_str().unwrap().to_string()
    };
    assert_eq!(truth(&[]), "vo-half");
    assert_eq!(truth(&["--no-normal-clamp"]), "vo-whole");
    assert_eq!(truth(&["--settings", r#"{"vo": {"normal_clamp": false}}"#]), "vo-whole");
}

/// A frame with fewer than 100 geometry pixels has no legibility, said with the reason, not 0.
#[test]
fn legibility_of_a_tiny_frame_is_absent_with_the_reason() {
    let out = lineao(&[
        "score",
        "--vertices",
        "2000",
        "--width",
        "12",
        "--height",
        "8",
        "--rays",
        "4",
        "--methods",
        "lineao",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let absent = report["methods"][0]["legibility"]["absent"].as_str().unwrap_or_else(|| panic!("{report}"));
    assert!(absent.contains("fewer than the 100"), "{absent}");
}

#[test]
fn score_without_geometry_in_view_says_so() {
    let out = lineao(&[
        "score",
        "--vertices",
        "2000",
        "--width",
        "64",
        "--height",
        "48",
        "--eye",
        "0,0,500",
        "--target",
        "0,0,1000",
        "--up",
        "0,1,0",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("no geometry in view"), "{}", stderr(&out));
}

/// A method made by the registry alone (`toy`: a folder and one line in lineao's `registry!`,
/// compiled into the tests' build by the feature `toy-method`) is listed by every part of the
/// command line that lists methods: `render --help` with its help, the bench's passes (timed),
/// `score`'s rows; and it renders. (Python's `methods()`: test_render.py.)
#[test]
fn a_method_of_the_registry_alone_is_listed_everywhere() {
    let help = lineao(&["render", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains("- toy:") && help.contains("the registry's test"), "{help}");
    let score_help = lineao(&["score", "--help"]);
    assert!(String::from_utf8_lossy(&score_help.stdout).contains("- toy:"));

    let small = ["--vertices", "2000", "--width", "64", "--height", "48"];
    let bench =
        lineao(&[&["bench", "--passes", "toy", "--frames", "1", "--warmup", "0", "--json"][..], &small].concat());
    assert_eq!(bench.status.code(), Some(0), "{}", stderr(&bench));
    let report: Value = serde_json::from_slice(&bench.stdout).unwrap();
    assert_eq!(report["passes"][0]["name"], "toy", "{report}");
    assert!(report["passes"][0]["ms_median"].as_f64().unwrap() >= 0.0);
    // An unknown pass is refused with the registry's passes listed, the toy's among them.
    let unknown = lineao(&["bench", "--passes", "gtao"]);
    assert_eq!(unknown.status.code(), Some(2));
    assert!(stderr(&unknown).contains("toy"), "{}", stderr(&unknown));

    let score = lineao(&[&["score", "--methods", "lineao,toy", "--rays", "4", "--json"][..], &small].concat());
    assert_eq!(score.status.code(), Some(0), "{}", stderr(&score));
    let report: Value = serde_json::from_slice(&score.stdout).unwrap();
    let rows: Vec<&str> = report["methods"].as_array().unwrap().iter().map(|m| m["method"].as_str().unwrap()).collect();
    assert_eq!(rows, ["lineao", "toy"]);

    let dir = scratch("toy");
    let png = dir.join("toy.png");
    let render = lineao(&[&["render", "--method", "toy", "-o", png.to_str().unwrap()][..], &small].concat());
    assert_eq!(render.status.code(), Some(0), "{}", stderr(&render));
}

/// The toy's two settings, described in its folder alone (`lineao::method::setting`): flags in
/// `render --help` under its heading with unit, range and default; values that reach its pass
/// (the dump's `ao.npy`) and `params.json` (`flags`); `--settings` JSON under its registry line's key; a
/// value out of range refused by flag, from the command line and from the JSON. (Python's
/// keywords: test_render.py; the viewer's controls and the page's URL keys: their tests.)
#[test]
fn a_methods_settings_are_flags_from_their_description() {
    let help = lineao(&["render", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    let toy = &help[help.find("\ntoy:").expect("the toy's heading")..];
    assert!(toy.contains("--toy-radius <ZOOM UNITS>"), "{toy}");
    assert!(toy.contains("(in [0.25, 4] zoom units)") && toy.contains("[default: 1]"), "{toy}");
    assert!(toy.contains("--toy-invert") && toy.contains("one minus that occlusion"), "{toy}");

    let small = ["--vertices", "2000", "--width", "64", "--height", "48", "--method", "toy"];
    let dump = scratch("toy-settings");
    let given = ["--toy-radius", "1.5", "--toy-invert", "--dump", dump.to_str().unwrap()];
    let render = lineao(&[&["render", "-o", dump.join("toy.png").to_str().unwrap()][..], &small, &given].concat());
    assert_eq!(render.status.code(), Some(0), "{}", stderr(&render));
    let params: Value = serde_json::from_str(&std::fs::read_to_string(dump.join("params.json")).unwrap()).unwrap();
    let flags = &params["flags"];
    assert_eq!((flags["toy_radius"].as_f64(), flags["toy_invert"].as_bool()), (Some(1.5), Some(true)), "{params}");
    let (_, ao) = read_npy(&dump.join("ao.npy"));
    assert!(ao.iter().all(|&a| a == 0.0 || a == 1.0 - 0.25 * 1.5), "the toy's occlusion or the background");
    assert!(ao.contains(&0.625));

    let json = lineao(
        &[
            &["render", "--settings", r#"{"toy": {"radius_zoom": 2}}"#, "-o"][..],
            &[dump.join("j.png").to_str().unwrap()],
            &small[..],
        ]
        .concat(),
    );
    assert_eq!(json.status.code(), Some(0), "{}", stderr(&json));
    for refused in [
        lineao(&[&["render", "--toy-radius", "9"][..], &small].concat()),
        lineao(&[&["render", "--settings", r#"{"toy": {"radius_zoom": 9}}"#][..], &small].concat()),
    ] {
        assert_ne!(refused.status.code(), Some(0));
        assert!(
            stderr(&refused).contains("--toy-radius must be in [0.25, 4] zoom units, got 9"),
            "{}",
            stderr(&refused)
        );
    }
}

/// No source file names the toy outside its folder and its registry line (tests — files under
/// `tests/`, a module `tests.rs`, a file's `#[cfg(test)]` module —, test scripts and the feature's lines in the
/// manifests aside): a method owns everything about itself.
#[test]
fn only_its_folder_and_its_registry_line_name_the_toy() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut named = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let skipped = ["target", "tests", "node_modules", ".git", "toy", "docs", "browser"];
            if path.is_dir() {
                if !skipped.contains(&name.as_str()) && !name.starts_with('.') {
                    stack.push(path);
                }
                continue;
            }
            let source = ["rs", "wgsl", "py", "js", "html"].iter().any(|e| name.ends_with(&format!(".{e}")));
            let source = source && name != "tests.rs";
            if !source {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            // A file's own tests (its `#[cfg(test)]` module, at its end) are tests.
            let source_lines = text.lines().take_while(|l| l.trim() != "#[cfg(test)]");
            for (k, line) in source_lines.enumerate() {
                // The registry's line and the module's declaration, each under the feature.
                let registry = line.contains("Toy => toy { toy: ToySettings }")
                    || line.trim() == "pub mod toy;"
                    || line.contains(r#"feature = "toy-method""#)
                    || line.contains("(feature `toy-method`");
                if line.to_lowercase().contains("toy") && !registry {
                    named.push(format!("{}:{}: {}", path.strip_prefix(root).unwrap().display(), k + 1, line.trim()));
                }
            }
        }
    }
    assert!(named.is_empty(), "the toy is named outside its folder:\n{}", named.join("\n"));
}

/// `--turntable N`: a PNG a frame, their cameras, and an animated PNG of them that an outside
/// reader (the `png` crate's APNG decoder) finds N frames of in; frame k is what `render`
/// draws from frame k's camera, read from the cameras' file.
#[test]
fn a_turntable_writes_its_frames_cameras_and_movie() {
    let dir = scratch("turntable");
    let output = dir.join("spin.png");
    let size = ["--vertices", "30000", "--width", "96", "--height", "64"];
    let mut argv = vec!["render", "--turntable", "3", "--fps", "12", "-o", output.to_str().unwrap()];
    argv.extend(size);
    let out = lineao(&argv);
    assert!(out.status.success(), "{}", stderr(&out));
    let cameras: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("spin.json")).unwrap()).unwrap();
    assert_eq!((cameras["frames"].as_u64(), cameras["fps"].as_u64()), (Some(3), Some(12)));
    // The movie, frame by frame, against the PNGs.
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(dir.join("spin.apng")).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let control = reader.info().animation_control.expect("an animated PNG");
    assert_eq!((control.num_frames, control.num_plays), (3, 0));
    for k in 0..3 {
        let mut frame = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut frame).unwrap();
        assert_eq!((info.width, info.height), (96, 64));
        let ((w, h), png) = common::read_png(&dir.join(format!("spin-00{k}.png")));
        assert_eq!(((w, h), &png[..]), ((96, 64), &frame[..info.buffer_size()]), "frame {k}");
    }
    // Frame 1 again, by `render` from its camera.
    let camera = &cameras["cameras"][1];
    assert_eq!(camera["file"], "spin-001.png");
    let vec3 = |key: &str| {
        let v: Vec<String> = camera[key].as_array().unwrap().iter().map(|c| c.to_string()).collect();
        v.join(",")
    };
    let (eye, target, up) = (vec3("eye"), vec3("target"), vec3("up"));
    let single = dir.join("single.png");
    let mut argv = vec!["render", "--eye", &eye, "--target", &target, "--up", &up, "-o", single.to_str().unwrap()];
    argv.extend(size);
    let out = lineao(&argv);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(common::read_png(&single), common::read_png(&dir.join("spin-001.png")));
    assert_ne!(common::read_png(&single), common::read_png(&dir.join("spin-000.png")), "the frames turn");
}

/// Figures and movies refuse what they cannot do, naming the flag; a movie that cannot be
/// written loses no frame.
#[test]
fn figures_and_movies_refuse_bad_input() {
    for (bad, said) in [
        (&["render", "--turntable", "0"][..], "--turntable"),
        (&["render", "--turntable=-3"], "--turntable"),
        (&["render", "--fps", "30"], "--turntable"),
        (&["render", "--views", "left,sideways"], "'sideways' is not a view"),
        (&["render", "--views", "left", "--grid"], "--grid"),
        (&["render", "--tile", "100"], "a multiple of 64"),
        (&["render", "--width", "70000"], "--width"),
    ] {
        let out = lineao(bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(said), "{bad:?}: {}", stderr(&out));
    }
    let dir = scratch("movie-refused");
    let output = dir.join("spin.png");
    let tiny = ["--vertices", "3000", "--width", "32", "--height", "32", "-o", output.to_str().unwrap()];
    let run = |extra: &[&str]| {
        let mut argv = vec!["render", "--turntable", "2"];
        argv.extend(extra);
        argv.extend(tiny);
        lineao(&argv)
    };
    let out = run(&["--movie", "spin.avi"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("--movie spin.avi"), "{}", stderr(&out));
    let ffmpeg = std::process::Command::new("ffmpeg").arg("-version").output().is_ok_and(|o| o.status.success());
    if !ffmpeg {
        let out = run(&["--movie", "spin.mp4"]);
        assert_eq!(out.status.code(), Some(1));
        assert!(stderr(&out).contains("--movie spin.mp4") && stderr(&out).contains("ffmpeg"), "{}", stderr(&out));
        assert!(!dir.join("spin-000.png").exists(), "refused before anything is rendered");
    }
    let unwritable = dir.join("no-such-folder").join("spin.apng");
    let out = run(&["--movie", unwritable.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("the 2 PNG frames are written"), "{}", stderr(&out));
    assert!(dir.join("spin-000.png").exists() && dir.join("spin-001.png").exists());
    assert!(lineao(&["score", "--views", "left"]).status.code() != Some(0), "score refuses --views");
}

/// `--orbit AZIMUTH,ELEVATION,ZOOM` places the camera as the viewer's and the page's links do;
/// given twice or more with --turntable, the keyframes of a camera path whose first and last
/// frames are the pictures of the first and last keyframes.
#[test]
fn orbit_keyframes_make_a_camera_path() {
    let dir = scratch("keyframes");
    let size = ["--vertices", "30000", "--width", "96", "--height", "64"];
    let render = |extra: &[&str], output: &Path| {
        let mut argv = vec!["render", "-o", output.to_str().unwrap()];
        argv.extend(extra);
        argv.extend(size);
        let out = lineao(&argv);
        assert!(out.status.success(), "{extra:?}: {}", stderr(&out));
    };
    render(
        &["--turntable", "4", "--orbit", "0,10,1", "--orbit=-60,30,0.8", "--orbit", "90,-20,1.2"],
        &dir.join("path.png"),
    );
    render(&["--orbit", "0,10,1"], &dir.join("first.png"));
    render(&["--orbit=90,-20,1.2"], &dir.join("last.png"));
    assert_eq!(common::read_png(&dir.join("path-000.png")), common::read_png(&dir.join("first.png")));
    assert_eq!(common::read_png(&dir.join("path-003.png")), common::read_png(&dir.join("last.png")));
    assert_ne!(common::read_png(&dir.join("path-001.png")), common::read_png(&dir.join("first.png")));
    let cameras: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("path.json")).unwrap()).unwrap();
    assert_eq!(cameras["keyframes"].as_array().map(Vec::len), Some(3));
    let out = lineao(&["render", "--orbit", "0,10,1", "--eye", "1,2,3"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("--orbit"), "{}", stderr(&out));
    let out = lineao(&["render", "--orbit", "0,95,1"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}
