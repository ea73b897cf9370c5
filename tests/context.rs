//! Tractograms in context: anatomy slices show the volume where nibabel's affine puts it, and a
//! slab leaves no line outside it. Each test renders through the session (`lineao render`'s
//! path), reads the G-buffer back and checks it against numbers computed apart from the GPU:
//! the CPU volume's trilinear sample (`lineao_tracts::Volume`, itself checked against
//! nibabel and scipy in the Python tests) at each pixel's unprojected world position.

use std::path::Path;

use glam::{Mat4, Vec3, Vec4};
use lineao::readback::{read_f32, read_rgba, read_texture};
use lineao_session::args::RenderArgs;
use lineao_session::render::Session;

fn images(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/niivue+niivue/packages/niivue/demos/images")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// `render FILE` with `keywords`, one frame: the session and the chain that drew it.
fn render(file: &str, keywords: serde_json::Value) -> (Session, lineao::AoChain) {
    let serde_json::Value::Object(map) = keywords else { panic!("keywords are an object") };
    let mut args = RenderArgs::from_keywords(map).unwrap();
    args.file = Some(file.into());
    let mut session = Session::open(&args).unwrap();
    let mut chains = Vec::new();
    session.compose(&args, &mut chains).unwrap();
    (session, chains.pop().unwrap())
}

/// The world position of every pixel with geometry: (x, y, world, pixel index) from the depth
/// buffer through the inverse of the frame's projection and view.
fn geometry_points(session: &Session, chain: &lineao::AoChain) -> Vec<(usize, Vec3)> {
    let gpu = &session.gpu;
    let targets = chain.targets().unwrap();
    let view = chain.frame_view().unwrap();
    let depth = read_texture(&gpu.device, &gpu.queue, &targets.depth.texture).unwrap().to_f32();
    let (w, h) = (targets.depth.texture.width() as usize, targets.depth.texture.height() as usize);
    let to_world: Mat4 = view.view.inverse() * view.proj.inverse();
    let mut points = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let d = depth[y * w + x];
            if d >= 1.0 {
                continue;
            }
            let ndc =
                Vec4::new((x as f32 + 0.5) / w as f32 * 2.0 - 1.0, 1.0 - (y as f32 + 0.5) / h as f32 * 2.0, d, 1.0);
            let p = to_world * ndc;
            points.push((y * w + x, p.truncate() / p.w));
        }
    }
    points
}

#[test]
fn a_slice_shows_the_volume_where_its_affine_puts_it() {
    // The T1 template (a plain affine) cut coronally, and the z-map whose affine flips x cut
    // sagittally, each seen from its slice's side; opaque, their zeros too.
    for (name, slices, axis, at, eye) in [
        ("MNI152_2009_template.nii.gz", "-,-18,-", 1, -18.0, "60,-260,40"),
        ("strokez.nii.gz", "20,-,-", 0, 20.0, "260,-40,40"),
    ] {
        let path = images(name);
        let keywords = serde_json::json!({
            "volume": path, "slices": slices, "method": "none", "width": 320, "height": 256,
            "eye": eye, "target": "0,-18,10", "up": "0,0,1", "opaque_slices": true,
        });
        let (session, chain) = render(&images("stroke.trk.gz"), keywords);
        let volume = lineao_tracts::Volume::load(&path).unwrap();
        let window = session.anatomy.as_ref().expect("the volume loads").percentiles();
        let table = lineao::Colormap::Gray.table();
        // The shader's colormap: 16 entries, linear between them.
        let gray = |v: f32| {
            let t = ((v - window[0]) / (window[1] - window[0])).clamp(0.0, 1.0) * 15.0;
            let k = (t as usize).min(14);
            table[k][0] + (table[k + 1][0] - table[k][0]) * (t - k as f32)
        };
        let gpu = &session.gpu;
        let color = read_texture(&gpu.device, &gpu.queue, &chain.targets().unwrap().color.texture).unwrap().to_vec4();
        let (mut on_slice, mut off, mut worst) = (0, 0, 0.0f32);
        for (i, p) in geometry_points(&session, &chain) {
            // The slice's pixels (the lines in front of it lie off its plane).
            if (p[axis] - at).abs() > 0.05 {
                continue;
            }
            let value = volume.sample(p.to_array());
            if value.is_nan() {
                continue;
            }
            on_slice += 1;
            let error = (color[i][0] - gray(value)).abs();
            worst = worst.max(error);
            // Half floats hold 11 bits; a value gradient across the depth's rounding adds a little.
            if error > 4e-3 {
                off += 1;
            }
        }
        assert!(on_slice > 15_000, "{name}: only {on_slice} slice pixels");
        assert!(
            off * 1000 <= on_slice,
            "{name}: {off} of {on_slice} slice pixels differ from the CPU's sample (worst {worst})"
        );
    }
}

/// A slice is transparent where the voxels without data (0 or NaN) weigh half its sample: over
/// the T1 template, whose values outside the brain are 0 and inside at least 1, every pixel of
/// the slice samples above 0 (data weighing at least half), while `opaque_slices` also shows
/// the zeros around the brain; both show the same values where both show the slice (within
/// half-float rounding: their quads differ).
#[test]
fn a_slice_is_transparent_where_its_volume_holds_no_data() {
    let path = images("MNI152_2009_template.nii.gz");
    let volume = lineao_tracts::Volume::load(&path).unwrap();
    let slice_samples = |opaque: bool| {
        let keywords = serde_json::json!({
            "volume": path, "slices": "-,-18,-", "method": "none", "width": 320, "height": 256,
            "eye": "60,-260,40", "target": "0,-18,10", "up": "0,0,1", "opaque_slices": opaque,
        });
        let (session, chain) = render(&images("stroke.trk.gz"), keywords);
        let gpu = &session.gpu;
        let color = read_texture(&gpu.device, &gpu.queue, &chain.targets().unwrap().color.texture).unwrap().to_vec4();
        let mut samples = std::collections::HashMap::new();
        for (i, p) in geometry_points(&session, &chain) {
            // The slices' pixels, marked by the colour's alpha (the lines write 1).
            if color[i][3] == 0.0 {
                assert!((p.y + 18.0).abs() < 0.05, "a slice pixel off the plane: {p}");
                samples.insert(i, (volume.sample(p.to_array()), color[i][0]));
            }
        }
        samples
    };
    let (clear, opaque) = (slice_samples(false), slice_samples(true));
    let zeros = |s: &std::collections::HashMap<usize, (f32, f32)>| s.values().filter(|(v, _)| *v == 0.0).count();
    println!(
        "slice pixels: {} transparent where no data, {} opaque ({} of them zeros)",
        clear.len(),
        opaque.len(),
        zeros(&opaque)
    );
    assert!(clear.len() > 3_000, "only {} slice pixels", clear.len());
    assert!(clear.values().all(|(v, _)| *v > 0.0), "a transparent slice shows a sample of 0");
    assert!(zeros(&opaque) > 5_000, "the opaque slice shows {} zeros", zeros(&opaque));
    assert!(clear.iter().all(|(i, (_, c))| opaque.get(i).is_some_and(|(_, o)| (o - c).abs() < 2e-3)));
}

/// Over the slices the chain's bilateral blur smooths their pixels alone: the occlusion shown
/// equals the CPU reference blurring the raw occlusion where the colour's alpha marks a slice,
/// and every other pixel (the lines) keeps its raw occlusion exactly.
#[test]
fn the_blur_smooths_the_slices_and_leaves_the_lines_occlusion() {
    let keywords = serde_json::json!({
        "volume": images("MNI152_2009_template.nii.gz"), "slices": "0,-18,10", "width": 320, "height": 256,
    });
    let (session, chain) = render(&images("stroke.trk.gz"), keywords);
    let (d, q) = (&session.gpu.device, &session.gpu.queue);
    let targets = chain.targets().unwrap();
    let (w, h) = (targets.size.0 as usize, targets.size.1 as usize);
    let ao = read_f32(d, q, &targets.ao).unwrap();
    let shown = read_f32(d, q, targets.ao_blurred.as_ref().expect("the blur's targets")).unwrap();
    let nd0 = read_rgba(d, q, &targets.nd[0]).unwrap();
    let color = read_rgba(d, q, &targets.color).unwrap();
    let slice = |x: usize, y: usize| color.get(x, y)[3] == 0.0;
    let (blur, slices_only) = chain.settings().bilateral().expect("a blur over the slices");
    assert!(slices_only);
    let view = lineao::reference::ViewParams::of(chain.frame_view().unwrap());
    let cpu = lineao::reference::bilateral_where(&ao, &nd0, &view, &blur, &slice);
    let stats = lineao::verify::check_policy(&shown, &cpu, &nd0, 1e-4).unwrap();
    let slices = (0..w * h).filter(|&i| slice(i % w, i / w)).count();
    let changed = (0..w * h).filter(|&i| (shown.data[i] - ao.data[i]).abs() > 1e-3).count();
    let kept = (0..w * h).filter(|&i| !slice(i % w, i / w)).all(|i| shown.data[i] == ao.data[i]);
    println!("{stats}; {slices} slice pixels, {changed} pixels changed");
    assert!(kept, "a pixel that is no slice changed its occlusion");
    assert!(slices > 3_000 && changed > 1_000, "{slices} slice pixels, {changed} changed");
}

/// The slices are drawn first (three quads), so the lines behind them fail the depth test and
/// the cull leaves their pieces out: over the template's three opaque slices it draws under 3/4 of the
/// pieces it draws without them. The culled picture differs from every line drawn no more than
/// it does without the slices: the culled pieces are full strips where drawing everything takes
/// the alternating strip (within half a pixel, `tests/lines.rs`); a line the slices' depth
/// culled wrongly would add pixels.
#[test]
fn the_cull_leaves_out_the_lines_behind_the_slices() {
    let frame = |slices: bool, cull: bool| {
        let mut keywords =
            serde_json::json!({"method": "none", "width": 320, "height": 256, "cull": cull, "lod": false});
        if slices {
            keywords["volume"] = images("MNI152_2009_template.nii.gz").into();
            keywords["slices"] = "0,-18,10".into();
            keywords["opaque_slices"] = true.into();
        }
        let (session, chain) = render(&images("stroke.trk.gz"), keywords);
        let counts = chain.cull_counts(&session.gpu.queue, &session.lines.geometry).unwrap();
        let drawn = counts.map(|c| (c.early + c.late) as f64 / c.pieces as f64);
        let (d, q) = (&session.gpu.device, &session.gpu.queue);
        let targets = chain.targets().unwrap();
        let depth = read_texture(d, q, &targets.depth.texture).unwrap().to_f32();
        let color = read_texture(d, q, &targets.color.texture).unwrap().to_vec4();
        (drawn, depth, color)
    };
    let differing = |a: &(Option<f64>, Vec<f32>, Vec<[f32; 4]>), b: &(Option<f64>, Vec<f32>, Vec<[f32; 4]>)| {
        (0..a.1.len()).filter(|&i| a.1[i] != b.1[i] || a.2[i] != b.2[i]).count()
    };
    let (bare, bare_whole) = (frame(false, true), frame(false, false));
    let (sliced, sliced_whole) = (frame(true, true), frame(true, false));
    let (bare_drawn, sliced_drawn) = (bare.0.expect("culled"), sliced.0.expect("culled"));
    assert!(bare_whole.0.is_none() && sliced_whole.0.is_none(), "--cull off draws every line");
    let (bare_differ, sliced_differ) = (differing(&bare, &bare_whole), differing(&sliced, &sliced_whole));
    println!(
        "pieces drawn: {:.1} % without the slices, {:.1} % with them; pixels unlike every line drawn: {bare_differ}, \
         {sliced_differ}",
        100.0 * bare_drawn,
        100.0 * sliced_drawn
    );
    assert!(sliced_drawn < 0.75 * bare_drawn, "{sliced_drawn} against {bare_drawn}");
    assert!(sliced_differ <= bare_differ, "{sliced_differ} pixels against {bare_differ}");
    assert!(sliced.1.iter().filter(|&&d| d < 1.0).count() > 40_000);
}

#[test]
fn a_slab_leaves_no_line_outside_it() {
    let (center, thickness) = (16.0, 12.0);
    let keywords = serde_json::json!({
        "slab": format!("z,{center},{thickness}"), "method": "none", "width": 320, "height": 256,
    });
    let (session, chain) = render(&images("stroke.trk.gz"), keywords);
    let view = *chain.frame_view().unwrap();
    let points = geometry_points(&session, &chain);
    assert!(points.len() > 2_000, "only {} line pixels", points.len());
    for (_, p) in points {
        // A line's pixels lie within half its width (2 px) of its centre, whose depth they carry.
        let px_world = -view.view.transform_point3(p).z / view.f_px;
        let slack = 1.5 * px_world + 1e-3;
        assert!((p.z - center).abs() <= 0.5 * thickness + slack, "a line pixel at z = {} outside the slab", p.z);
    }
    // A slab beside the data leaves nothing.
    let (session, chain) = render(&images("stroke.trk.gz"), serde_json::json!({"slab": "x,500,2", "method": "none"}));
    assert!(geometry_points(&session, &chain).is_empty());
}

#[test]
fn groups_colour_their_streamlines_a_colour_each() {
    // pyAFQ's arcuate bundles: 486 streamlines in ARC_L, 22 in ARC_R (FACTS.txt).
    let afq = images("sub-01_ses-01_dwi_space-RASMM_model-probCSD_algo-AFQ_tractography.trx");
    let table = lineao::Colormap::Categories.table();
    let colours = |keywords: serde_json::Value| {
        let (session, chain) = render(&afq, keywords);
        let gpu = &session.gpu;
        let color = read_texture(&gpu.device, &gpu.queue, &chain.targets().unwrap().color.texture).unwrap().to_vec4();
        let mut counts = [0usize; 3];
        for (i, _) in geometry_points(&session, &chain) {
            let c = color[i];
            let near = |k: usize| (0..3).all(|a| (c[a] - table[k][a]).abs() < 2e-3);
            counts[if near(0) {
                0
            } else if near(1) {
                1
            } else {
                2
            }] += 1;
        }
        counts
    };
    let base = serde_json::json!({"color": "groups", "method": "none", "width": 320, "height": 256});
    let [left, right, other] = colours(base.clone());
    assert!(left > 10 * right && right > 50 && other == 0, "ARC_L {left}, ARC_R {right}, else {other} pixels");
    // ARC_R alone: its colour only.
    let mut only_right = base;
    only_right["groups"] = "ARC_R".into();
    let [left, right, other] = colours(only_right);
    assert!(left == 0 && right > 50 && other == 0, "ARC_L {left}, ARC_R {right}, else {other} pixels");
}
