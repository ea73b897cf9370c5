//! Culling on the GPU (`passes::cull`): the culled lines draw the G-buffer drawing every line
//! (the full strip) draws — bit for bit, but where two fragments tie in depth and the order
//! decides — from outside, inside, close up, orthographic and after a camera cut, on the first
//! frame (nothing known visible) and the next (the early phase draws the last frame's pieces);
//! and the GPU's marks after each frame are the CPU reference's (`lineao::reference::cull`).

mod common;

use common::{gpu, is_geometry};
use glam::Vec3;
use lineao::lighting::LightingShape;
use lineao::passes::cull::{Culled, Frozen, LineCull};
use lineao::passes::lines::{LineRenderer, LineStyle, VertexAttributes};
use lineao::passes::tubes::TubeRenderer;
use lineao::reference::NdImage;
use lineao::targets::FrameTargets;
use lineao::{Bounds, Camera, ChainSettings, FrameView, LineGeometry, Projection};

const SIZE: (u32, u32) = (320, 240);
/// A guard band as the chain's methods want one (the pyramid covers it too).
const GUARD: u32 = 24;
const LINE_WIDTH: f32 = 3.0;
/// The tubes' radius where a point holds none (world units; the ball is 80 across).
const TUBE_RADIUS: f32 = 0.4;

/// `count` smooth streamlines of 150 points wandering through a ball of radius 40: a small
/// whole brain, many lines deep from every side.
fn ball(count: usize) -> (Vec<[f32; 3]>, Vec<u64>) {
    let mut state = 0x2545_f491_u64;
    let mut random = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 33) as f32 / (1u64 << 31) as f32) * 2.0 - 1.0
    };
    let (mut positions, mut offsets) = (Vec::new(), vec![0u64]);
    for _ in 0..count {
        let mut p = Vec3::new(random(), random(), random()) * 30.0;
        let mut d = Vec3::new(random(), random(), random()).normalize_or(Vec3::X);
        for _ in 0..150 {
            positions.push(p.to_array());
            d = (d + 0.15 * Vec3::new(random(), random(), random())).normalize_or(Vec3::X);
            // Turn back inside the ball.
            if (p + d).length() > 40.0 {
                d = (d - 0.5 * p.normalize()).normalize_or(Vec3::X);
            }
            p += d;
        }
        offsets.push(positions.len() as u64);
    }
    (positions, offsets)
}

/// `ball(count)` on the GPU, every line's full strip, and the culled lines (no levels of detail).
fn ball_lines(gpu: &lineao::Gpu, count: usize) -> (LineGeometry, LineRenderer, LineRenderer) {
    let d = &gpu.device;
    (
        ball_geometry(gpu, count),
        LineRenderer::with_style(d, LineStyle::FullStrip),
        LineRenderer::new(d).culled(d, false),
    )
}

/// The `ball` of `count` streamlines on the GPU.
fn ball_geometry(gpu: &lineao::Gpu, count: usize) -> LineGeometry {
    let (positions, offsets) = ball(count);
    LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap()
}

/// Outside, inside, close up, orthographic, and a cut to the other side.
fn cameras() -> [(&'static str, Camera); 5] {
    let inside = Camera { eye: Vec3::new(2.0, 1.0, 3.0), target: Vec3::new(30.0, 5.0, -10.0), ..outside() };
    let close = Camera { eye: Vec3::new(10.0, 12.0, 40.0), target: Vec3::new(5.0, 5.0, 0.0), ..outside() };
    let orthographic = Camera { projection: Projection::Orthographic { height: 95.0 }, ..outside() };
    let cut = Camera { eye: Vec3::new(-110.0, -20.0, -40.0), ..outside() };
    [
        ("outside", outside()),
        ("inside", inside),
        ("close up", close),
        ("orthographic", orthographic),
        ("a camera cut", cut),
    ]
}

fn bounds() -> Bounds {
    Bounds { center: Vec3::ZERO, radius: 45.0 }
}

fn outside() -> Camera {
    Camera {
        eye: Vec3::new(30.0, 40.0, 120.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 45.0 },
    }
}

/// The G-buffer (color, ND, zoom, hardware depth) `renderer` draws of `geometry` for `camera`.
fn draw(gpu: &lineao::Gpu, renderer: &LineRenderer, geometry: &LineGeometry, camera: &Camera) -> [NdImage; 4] {
    draw_with(gpu, camera, |encoder, targets, view, s| {
        renderer.prepare(&gpu.queue, view, s.line_width_px, s.line_color, &s.lighting, None);
        renderer.encode(encoder, targets, geometry, lineao::passes::Load::Clear(s.background), None);
    })
}

/// The G-buffer `renderer` draws of `geometry` as tubes of radius `TUBE_RADIUS` (or the
/// points' own).
fn draw_tubes(gpu: &lineao::Gpu, renderer: &TubeRenderer, geometry: &LineGeometry, camera: &Camera) -> [NdImage; 4] {
    draw_with(gpu, camera, |encoder, targets, view, s| {
        renderer.prepare(&gpu.queue, view, TUBE_RADIUS, s.line_color, &s.lighting, None);
        renderer.encode(encoder, targets, geometry, lineao::passes::Load::Clear(s.background), None);
    })
}

/// The G-buffer `encode` draws for `camera` (the chain's default settings, 3 px lines).
fn draw_with(
    gpu: &lineao::Gpu,
    camera: &Camera,
    encode: impl Fn(&mut wgpu::CommandEncoder, &FrameTargets, &FrameView, &ChainSettings),
) -> [NdImage; 4] {
    let d = &gpu.device;
    let view = FrameView::new(camera, &bounds(), SIZE.0, SIZE.1, GUARD, 1.0);
    let targets = FrameTargets::new(d, SIZE.0, SIZE.1, GUARD, 1);
    let s = ChainSettings { line_width_px: LINE_WIDTH, ..ChainSettings::default() };
    let mut encoder = d.create_command_encoder(&Default::default());
    encode(&mut encoder, &targets, &view, &s);
    gpu.queue.submit([encoder.finish()]);
    common::read_gbuffer(gpu, &targets)
}

/// Checks that `culled` equals `all` bit for bit but at ties (same depth, another line's
/// values); returns (geometry pixels, ties).
fn same_gbuffer(all: &[NdImage; 4], culled: &[NdImage; 4], case: &str) -> (usize, usize) {
    let (mut geometry, mut ties) = (0, 0);
    for i in 0..all[0].data.len() {
        let depth = (all[3].data[i][0], culled[3].data[i][0]);
        assert_eq!(depth.0.to_bits(), depth.1.to_bits(), "{case}: depth differs at pixel {i}: {depth:?}");
        geometry += is_geometry(all[1].data[i]) as usize;
        let equal = (0..3).all(|t| all[t].data[i].map(f32::to_bits) == culled[t].data[i].map(f32::to_bits));
        ties += !equal as usize;
    }
    (geometry, ties)
}

/// Checks the GPU's marks after a frame against the CPU reference of the cull on the frame's
/// final depth (`depth`): every piece the reference finds visible or hidden with a hundredth of a
/// pixel and 1e-7 of depth to spare is marked so; the unsure ones are counted.
fn same_marks_as_the_cpu_reference(
    gpu: &lineao::Gpu,
    renderer: &LineRenderer,
    geometry: &LineGeometry,
    camera: &Camera,
    depth: &NdImage,
    case: &str,
) {
    use lineao::reference::cull::{CullView, Slack, Verdict, marks};
    let view = FrameView::new(camera, &bounds(), SIZE.0, SIZE.1, GUARD, 1.0);
    let depth = lineao::reference::Image {
        width: depth.width,
        height: depth.height,
        data: depth.data.iter().map(|d| d[0]).collect(),
    };
    let frame = CullView {
        view: view.view,
        proj: view.proj,
        size: view.banded_size(),
        line_width_px: LINE_WIDTH,
        tube_radius: None,
    };
    let pages = geometry.page_contents(&gpu.device, &gpu.queue).unwrap();
    let slack = Slack { px: 0.01, depth: 1e-7 };
    let expected = marks(&pages, &frame, &depth, slack);
    // Against nothing drawn, only what lies outside the view is hidden.
    let empty = lineao::reference::Image { data: vec![1.0; depth.data.len()], ..depth };
    let in_view = marks(&pages, &frame, &empty, slack);
    let got = renderer.cull().unwrap().cull().marks(&gpu.queue, geometry).unwrap();
    let (mut pieces, mut unsure, mut outside, mut said_outside) = (0, 0, 0, 0);
    for (page, ((expected, in_view), got)) in expected.iter().zip(&in_view).zip(&got).enumerate() {
        for (i, ((verdicts, in_view), &bits)) in expected.iter().zip(in_view).zip(got).enumerate() {
            for (p, verdict) in verdicts.iter().enumerate() {
                let marked = bits & (1 << p) != 0;
                let marked_outside = bits & (1 << (9 + p)) != 0;
                match verdict {
                    Verdict::Visible => assert!(marked, "{case}: page {page} cluster {i} piece {p} is visible"),
                    Verdict::Hidden => assert!(!marked, "{case}: page {page} cluster {i} piece {p} is hidden"),
                    Verdict::Unsure => unsure += 1,
                }
                pieces += (*verdict != Verdict::Hidden) as usize;
                // Why a hidden piece was left out: never "outside" for one in the view, nor
                // for one marked visible.
                let record = &pages[page].records[i];
                let exists = p * 8 + 1 < record.drawn() as usize && record.is_selected();
                if in_view[p] == Verdict::Visible || marked {
                    assert!(!marked_outside, "{case}: page {page} cluster {i} piece {p} is in the view");
                }
                if exists && in_view[p] == Verdict::Hidden {
                    outside += 1;
                    said_outside += marked_outside as usize;
                }
            }
        }
    }
    println!(
        "{case}: the CPU reference agrees on every sure piece; {unsure} unsure of {pieces} not hidden; \
         {said_outside} of the {outside} pieces outside the view marked so (the others' group hidden behind)"
    );
    assert!(unsure * 100 <= pieces.max(100), "{case}: {unsure} pieces unsure");
    assert!(said_outside * 2 >= outside, "{case}: {said_outside} of {outside} pieces outside the view marked so");
}

#[test]
fn culled_lines_draw_the_g_buffer_of_all_lines() {
    let gpu = gpu();
    let q = &gpu.queue;
    let (geometry, all, culled) = ball_lines(&gpu, 8000);
    let pieces = lineao::passes::cull::LineCull::pieces(&geometry);
    // The late test without each piece's capsule first (a GPU's default: no capsule made), then
    // with it (a CPU adapter's; made, and the radii found, on the first frame that tests them):
    // the same pictures and marks.
    for capsules in [false, true] {
        culled.cull().unwrap().cull().set_capsules(capsules);
        for (case, camera) in cameras() {
            let case = &format!("{case} (capsules {capsules})");
            let expected = draw(&gpu, &all, &geometry, &camera);
            // The first frame of a view (after the one before it), then the next.
            for frame in ["first", "second"] {
                let got = draw(&gpu, &culled, &geometry, &camera);
                let counts = culled.cull().unwrap().counts(q, &geometry).unwrap();
                assert_eq!(counts.segment_tested.is_some(), capsules, "{case}");
                let (early, late) = (counts.early, counts.late);
                let (covered, ties) = same_gbuffer(&expected, &got, case);
                println!(
                    "{case}, {frame} frame: drew {early} + {late} of {pieces} pieces ({:.1} %); {covered} geometry pixels, {ties} ties",
                    100.0 * (early + late) as f64 / pieces as f64
                );
                assert!(ties * 2000 <= covered, "{case}: {ties} of {covered} pixels differ at equal depth");
                if frame == "second" {
                    assert!(late * 100 <= early, "{case}: a still camera draws what the last frame found visible");
                }
                same_marks_as_the_cpu_reference(&gpu, &culled, &geometry, &camera, &got[3], case);
            }
        }
    }
    // From outside most of the ball is hidden: a second frame draws well under half of it.
    draw(&gpu, &culled, &geometry, &outside());
    draw(&gpu, &culled, &geometry, &outside());
    let counts = culled.cull().unwrap().counts(q, &geometry).unwrap();
    let (early, late) = (counts.early, counts.late);
    assert!((early + late) * 2 < pieces, "drew {early} + {late} of {pieces}");
}

/// A geometry's first culled frame knows nothing visible: it draws every piece of every
/// `SEED_STRIDE`-th cluster first and culls the rest against their depth, so from outside the
/// ball it draws well under half of the pieces — the G-buffer still every line's, bit for bit
/// but at ties (the test above) — where against an empty pyramid it drew them all.
#[test]
fn a_first_frame_culls_against_a_seed_of_its_own_lines() {
    let gpu = gpu();
    let (geometry, all, culled) = ball_lines(&gpu, 8000);
    let expected = draw(&gpu, &all, &geometry, &outside());
    let got = draw(&gpu, &culled, &geometry, &outside());
    let counts = culled.cull().unwrap().counts(&gpu.queue, &geometry).unwrap();
    let (early, late, pieces) = (counts.early, counts.late, counts.pieces);
    println!("first frame: drew {early} (the seed) + {late} of {pieces} pieces");
    let stride = lineao::passes::cull::SEED_STRIDE as u64;
    assert!(early * stride > pieces / 2 && early * stride < 2 * pieces, "the seed: {early} of {pieces}");
    assert!((early + late) * 2 < pieces, "drew {early} + {late} of {pieces}");
    let (covered, ties) = same_gbuffer(&expected, &got, "a seeded first frame");
    assert!(ties * 2000 <= covered, "{ties} of {covered} pixels differ at equal depth");
}

/// Over a host's depth seeded into the G-buffer (`passes::seed_depth`, what `OverlayAo` does
/// with a depth it can read: here a wall through the ball's centre), the culled lines draw the
/// G-buffer every line's full strip draws over it, bit for bit, first frame and second, leave
/// out the pieces behind the wall, and their marks are the CPU reference's on the final depth.
#[test]
fn culled_lines_over_a_seeded_depth_draw_the_g_buffer_of_all_lines() {
    use lineao::passes::seed_depth::SeedDepth;
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (geometry, all, culled) = ball_lines(&gpu, 4000);
    let seed = SeedDepth::new(d);
    let camera = outside();
    // The host: the same view, its depth a wall through the ball's centre.
    let view = FrameView::new(&camera, &bounds(), SIZE.0, SIZE.1, GUARD, 1.0);
    let host = lineao::OverlayDepth { format: wgpu::TextureFormat::Depth32Float, proj: view.proj };
    let wall = view.proj.project_point3(view.view.transform_point3(Vec3::ZERO)).z;
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
    let host_view = common::texture(&gpu, SIZE, host.format, usage, 1);
    let mut encoder = d.create_command_encoder(&Default::default());
    common::host_frame(&mut encoder, None, &host_view, wall);
    q.submit([encoder.finish()]);
    let draw_seeded = |renderer: &LineRenderer| {
        draw_with(&gpu, &camera, |encoder, targets, view, s| {
            seed.prepare(q, targets, view, &host);
            seed.encode(encoder, targets, &host_view);
            renderer.prepare(q, view, s.line_width_px, s.line_color, &s.lighting, None);
            renderer.encode(encoder, targets, &geometry, lineao::passes::Load::ClearOverDepth(s.background), None);
        })
    };
    let expected = draw_seeded(&all);
    let unseeded = draw(&gpu, &all, &geometry, &camera);
    // Where every line lies behind the wall the seeded G-buffer holds none; elsewhere the
    // front line is the one drawn without the seed.
    let mut behind = 0;
    for (i, (seeded, nd)) in expected[1].data.iter().zip(&unseeded[1].data).enumerate() {
        let depth = unseeded[3].data[i][0];
        if is_geometry(*nd) && depth > wall * (1.0 + 1e-5) {
            behind += 1;
            assert!(!is_geometry(*seeded), "a line behind the wall at pixel {i}");
        } else if depth < wall * (1.0 - 1e-5) {
            assert_eq!(seeded, nd, "the line in front of the wall at pixel {i}");
        }
    }
    let all_pixels = unseeded[1].data.iter().filter(|t| is_geometry(**t)).count();
    assert!(behind > 0, "no pixel with every line behind the wall");
    let mut drawn = Vec::new();
    for frame in ["first", "second"] {
        let got = draw_seeded(&culled);
        let counts = culled.cull().unwrap().counts(q, &geometry).unwrap();
        let (covered, ties) = same_gbuffer(&expected, &got, "seeded");
        println!("seeded, {frame} frame: {counts}; {covered} geometry pixels of {all_pixels} unseeded, {ties} ties");
        assert!(ties * 2000 <= covered, "{ties} of {covered} pixels differ at equal depth");
        same_marks_as_the_cpu_reference(&gpu, &culled, &geometry, &camera, &got[3], "seeded");
        drawn.push(counts.early + counts.late);
    }
    // The half behind the wall is left out even on the first frame (nothing drawn before).
    assert!(drawn[0] * 10 < LineCull::pieces(&geometry) * 7, "{drawn:?}");
}

/// The culled tubes draw the G-buffer of every tube, with radii of their own (the cull bounds
/// them by the page's largest) and the frame's.
#[test]
fn culled_tubes_draw_the_g_buffer_of_all_tubes() {
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = ball(1500);
    let mut geometry = LineGeometry::new(d, q, &positions, &offsets).unwrap();
    let all = TubeRenderer::new(d, false, LightingShape::ANY);
    let culled = TubeRenderer::new(d, false, LightingShape::ANY).culled(d, false);
    let pieces = lineao::passes::cull::LineCull::pieces(&geometry);
    // Radii along each streamline from 0.1 to 1.0, a third of them the frame's (none stored).
    let radii: Vec<f32> =
        (0..positions.len()).map(|i| if i % 3 == 0 { 0.0 } else { 0.1 + (i % 150) as f32 / 166.0 }).collect();
    for radius in ["the frame's radius", "their own radii"] {
        if radius == "their own radii" {
            geometry.set_attributes(d, q, &VertexAttributes { radius: Some(&radii), ..Default::default() }).unwrap();
        }
        // Each camera with the frame's radius; with their own, from outside and orthographic
        // (tubes cost on lavapipe: it shades hidden fragments too).
        let some = |case: &str| radius == "the frame's radius" || ["outside", "orthographic"].contains(&case);
        for (case, camera) in cameras().into_iter().filter(|(case, _)| some(case)) {
            let case = format!("tubes of {radius}, {case}");
            let expected = draw_tubes(&gpu, &all, &geometry, &camera);
            for frame in ["first", "second"] {
                let got = draw_tubes(&gpu, &culled, &geometry, &camera);
                let counts = culled.cull().unwrap().counts(q, &geometry).unwrap();
                let (early, late) = (counts.early, counts.late);
                let (covered, ties) = same_gbuffer(&expected, &got, &case);
                println!(
                    "{case}, {frame} frame: drew {early} + {late} of {pieces} pieces ({:.1} %); {covered} geometry pixels, {ties} ties",
                    100.0 * (early + late) as f64 / pieces as f64
                );
                // Two segments of a tube share their joint's sphere: seen end on, both hit it at
                // the same depth (0–0.1 % of the pixels, orthographic).
                assert!(ties * 200 <= covered, "{case}: {ties} of {covered} pixels differ at equal depth");
                // From outside most of the ball is hidden: a second frame draws under half.
                if case == "tubes of the frame's radius, outside" && frame == "second" {
                    assert!((early + late) * 2 < pieces, "{case}: drew {early} + {late} of {pieces}");
                }
            }
        }
    }
}

/// Checks the levels of detail the GPU chose for the visible pieces of the last frame against
/// the CPU reference's (`lineao::reference::cull::levels`, for tubes of `tube_radius`): the same
/// wherever no level's test lies within 1e-3 px of the bound; those are counted.
fn same_levels_as_the_cpu_reference(
    gpu: &lineao::Gpu,
    culled: &Culled,
    geometry: &LineGeometry,
    view: &FrameView,
    tube_radius: Option<f32>,
    case: &str,
) {
    use lineao::reference::cull::{CullView, levels};
    let frame =
        CullView { view: view.view, proj: view.proj, size: view.banded_size(), line_width_px: LINE_WIDTH, tube_radius };
    let pages = geometry.page_contents(&gpu.device, &gpu.queue).unwrap();
    let expected = levels(&pages, &frame, 1e-3);
    let got = culled.cull().marks(&gpu.queue, geometry).unwrap();
    let (mut visible, mut unsure, mut coarse) = (0, 0, 0);
    for (page, (expected, got)) in expected.iter().zip(&got).enumerate() {
        for (i, (levels, &bits)) in expected.iter().zip(got).enumerate() {
            for (p, level) in levels.iter().enumerate() {
                if bits & (1 << p) == 0 {
                    continue;
                }
                visible += 1;
                let chosen = (bits >> (3 + 2 * p)) & 3;
                coarse += (chosen > 0) as usize;
                match level {
                    Some(level) => assert_eq!(chosen, *level, "{case}: page {page} cluster {i} piece {p}"),
                    None => unsure += 1,
                }
            }
        }
    }
    println!(
        "{case}: the CPU reference's level for every sure piece of {visible} visible ({coarse} coarser); {unsure} unsure"
    );
    assert!(unsure * 100 <= visible.max(100), "{case}: {unsure} levels unsure");
    assert!(visible > 0, "{case}: nothing visible to check");
}

/// Culled lines or tubes (`draw` with `culled`'s cull, at levels of detail) against every line
/// or tube drawn whole (`all`), for each camera: the same pixels covered but a few at the
/// silhouette, and the front surface within half a pixel's width of the full one's at nearly
/// every pixel (elsewhere another line, shifted less than a pixel, is in front) — for lines in
/// depth, for tubes along the full surface's normal (a tube's solid lies within that distance
/// of the full one, and a surface shifted by δ along its normal n moves δ / |n · d| along the
/// ray d: without that factor 2 % of the pixels differ more, at the tubes' flanks); the levels
/// the CPU reference's; the first frame after a cut the full G-buffer.
fn levels_of_detail_stay_within_half_a_pixel(
    gpu: &lineao::Gpu,
    geometry: &LineGeometry,
    culled: &Culled,
    tube_radius: Option<f32>,
    all: impl Fn(&Camera) -> [NdImage; 4],
    draw: impl Fn(&Camera) -> [NdImage; 4],
) {
    let q = &gpu.queue;
    let shape = if tube_radius.is_some() { "tubes" } else { "lines" };
    let (width, height) = (SIZE.0 + 2 * GUARD, SIZE.1 + 2 * GUARD);
    for (case, camera) in cameras() {
        let case = format!("{shape}, {case}");
        let view = FrameView::new(&camera, &bounds(), SIZE.0, SIZE.1, GUARD, 1.0);
        assert_eq!(view.banded_size(), (width, height));
        let inverse = view.proj.inverse();
        // A depth difference at pixel i as the distance the surface moved along its normal.
        let along_normal = |i: usize, nd: [f32; 4]| {
            if tube_radius.is_none() {
                return 1.0;
            }
            let (x, y) = ((i as u32 % width) as f32 + 0.5, (i as u32 / width) as f32 + 0.5);
            let ndc = |z| Vec3::new(2.0 * x / width as f32 - 1.0, 1.0 - 2.0 * y / height as f32, z);
            let ray = (inverse.project_point3(ndc(1.0)) - inverse.project_point3(ndc(0.0))).normalize();
            Vec3::new(nd[0], nd[1], nd[2]).dot(ray).abs() / ray.z.abs()
        };
        let expected = all(&camera);
        // The first frame after a cut draws every piece whole (the levels were found for
        // another view); the second draws them at the levels found against this one.
        let first = draw(&camera);
        let counts = culled.counts(q, geometry).unwrap();
        assert_eq!(counts.coarse, 0, "{case}: the first frame after a cut draws every piece whole");
        same_gbuffer(&expected, &first, &case);
        let got = draw(&camera);
        let counts = culled.counts(q, geometry).unwrap();
        same_levels_as_the_cpu_reference(gpu, culled, geometry, &view, tube_radius, &case);
        let (mut covered, mut coverage, mut far, mut identical) = (0usize, 0usize, 0usize, 0usize);
        for i in 0..expected[0].data.len() {
            let (a, b) = (is_geometry(expected[1].data[i]), is_geometry(got[1].data[i]));
            covered += a as usize;
            coverage += (a != b) as usize;
            if !(a && b) {
                continue;
            }
            identical += (0..4).all(|t| expected[t].data[i] == got[t].data[i]) as usize;
            // Linear depth in world units, and half a pixel's width there.
            let z = |nd: [f32; 4]| view.near + nd[3] * (view.far - view.near);
            let (za, zb) = (z(expected[1].data[i]), z(got[1].data[i]));
            let px = if view.orthographic { view.f_px } else { view.f_px / za };
            let moved = (za - zb).abs() * along_normal(i, expected[1].data[i]);
            far += (moved > lineao::passes::cull::LOD_PIXELS / px) as usize;
        }
        let share = |n: usize| 100.0 * n as f64 / covered as f64;
        println!(
            "{case}: {:.1} % of {} pieces drawn coarser; of {covered} geometry pixels {:.2} % covered or not \
             otherwise, {:.2} % identical, {:.2} % moved beyond half a pixel",
            100.0 * counts.coarse as f64 / (counts.early + counts.late) as f64,
            counts.early + counts.late,
            share(coverage),
            share(identical),
            share(far),
        );
        assert!(coverage * 200 <= covered, "{case}: {coverage} of {covered} pixels covered otherwise");
        assert!(far * 50 <= covered, "{case}: {far} of {covered} pixels at another depth");
        if case.ends_with("outside") {
            assert!(counts.coarse * 2 >= counts.early + counts.late, "{case}: {counts}");
        }
    }
}

/// The culled lines at levels of detail (`passes::cull`'s `LOD_PIXELS`) against every line's
/// full strip.
#[test]
fn culled_lines_at_levels_of_detail_stay_within_half_a_pixel() {
    let gpu = gpu();
    let d = &gpu.device;
    let geometry = ball_geometry(&gpu, 8000);
    let all = LineRenderer::with_style(d, LineStyle::FullStrip);
    let lod = LineRenderer::new(d).culled(d, true);
    let (all, draw) = (|c: &Camera| draw(&gpu, &all, &geometry, c), |c: &Camera| draw(&gpu, &lod, &geometry, c));
    levels_of_detail_stay_within_half_a_pixel(&gpu, &geometry, lod.cull().unwrap(), None, all, draw);
}

/// The culled tubes at levels of detail against every tube (the rim's turn bounded by the
/// radius on screen).
#[test]
fn culled_tubes_at_levels_of_detail_stay_within_half_a_pixel() {
    let gpu = gpu();
    let d = &gpu.device;
    let geometry = ball_geometry(&gpu, 1500);
    let all = TubeRenderer::new(d, false, LightingShape::ANY);
    let lod = TubeRenderer::new(d, false, LightingShape::ANY).culled(d, true);
    let (all, draw) =
        (|c: &Camera| draw_tubes(&gpu, &all, &geometry, c), |c: &Camera| draw_tubes(&gpu, &lod, &geometry, c));
    levels_of_detail_stay_within_half_a_pixel(&gpu, &geometry, lod.cull().unwrap(), Some(TUBE_RADIUS), all, draw);
}

/// The chain's culled tubes follow its settings: levels of detail where asked, none with the
/// ray tracer (whose rays must find the tubes where its scene has them), and a change of
/// either rebuilds them.
#[test]
fn the_chain_draws_tubes_at_levels_of_detail_as_its_settings_say() {
    use lineao::{AoChain, AoMethod, TubeSettings};
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let geometry = ball_geometry(&gpu, 600);
    let tubes = Some(TubeSettings { radius_world: TUBE_RADIUS });
    let settings = |lod, method| ChainSettings { lod, method, tubes: tubes.clone(), ..ChainSettings::default() };
    let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, settings(true, AoMethod::None)).unwrap();
    chain.resize(SIZE.0, SIZE.1).unwrap();
    let output = lineao::targets::Target::output(d, "test::output", SIZE, common::OUTPUT_FORMAT);
    // Coarser pieces drawn in the second of two frames of one view.
    let coarse = |chain: &mut AoChain| {
        for _ in 0..2 {
            chain.prepare(d, q, &outside(), &bounds()).unwrap();
            let mut encoder = d.create_command_encoder(&Default::default());
            chain.encode(&mut encoder, &geometry, &output.view).unwrap();
            q.submit([encoder.finish()]);
        }
        chain.cull_counts(q, &geometry).unwrap().expect("culled tubes").coarse
    };
    assert!(coarse(&mut chain) > 0, "levels of detail on: no piece drawn coarser");
    chain.set_settings(d, settings(false, AoMethod::None)).unwrap();
    assert_eq!(coarse(&mut chain), 0, "levels of detail off");
    chain.set_settings(d, settings(true, AoMethod::None)).unwrap();
    assert!(coarse(&mut chain) > 0, "levels of detail on again");
    chain.set_settings(d, settings(true, AoMethod::RayTraced)).unwrap();
    assert_eq!(coarse(&mut chain), 0, "the ray tracer");
}

/// The streamlines of (`positions`, `offsets`) that `keep` marks.
fn subset(positions: &[[f32; 3]], offsets: &[u64], keep: &[bool]) -> (Vec<[f32; 3]>, Vec<u64>) {
    let (mut kept, mut kept_offsets) = (Vec::new(), vec![0u64]);
    for (w, _) in offsets.windows(2).zip(keep).filter(|(_, kept)| **kept) {
        kept.extend_from_slice(&positions[w[0] as usize..w[1] as usize]);
        kept_offsets.push(kept.len() as u64);
    }
    (kept, kept_offsets)
}

#[test]
fn a_selection_draws_what_the_selected_streamlines_alone_draw() {
    use lineao::passes::lines::GeometryOptions;
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = ball(600);
    // One tolerance for both, so that each cluster takes the same strip in both.
    let options = GeometryOptions { tolerance: Some(0.02), cluster_points: 16, ..GeometryOptions::default() };
    let keep: Vec<bool> = (0..600).map(|i| i % 3 != 1).collect();
    let mut masked = LineGeometry::with_options(d, q, &positions, &offsets, options).unwrap();
    masked.set_selection(d, q, Some(&keep)).unwrap();
    assert_eq!((masked.streamlines, masked.selected()), (600, 400));
    let (kept, kept_offsets) = subset(&positions, &offsets, &keep);
    let alone = LineGeometry::with_options(d, q, &kept, &kept_offsets, options).unwrap();
    let camera = outside();
    // Drawn whole, culled (the second frame draws what the first found), and as tubes.
    let lines = |culled: bool| if culled { LineRenderer::new(d).culled(d, false) } else { LineRenderer::new(d) };
    for culled in [false, true] {
        let (a, b) = (lines(culled), lines(culled));
        let frames = 1 + culled as usize;
        let expected = (0..frames).map(|_| draw(&gpu, &a, &alone, &camera)).last().unwrap();
        let got = (0..frames).map(|_| draw(&gpu, &b, &masked, &camera)).last().unwrap();
        let (covered, ties) = same_gbuffer(&expected, &got, if culled { "culled lines" } else { "lines" });
        assert!(covered > 5_000 && ties * 1000 <= covered, "{ties} ties of {covered}");
        if culled {
            same_marks_as_the_cpu_reference(&gpu, &b, &masked, &camera, &got[3], "culled lines");
        }
    }
    let (a, b) = (TubeRenderer::new(d, false, LightingShape::ANY), TubeRenderer::new(d, false, LightingShape::ANY));
    let (expected, got) = (draw_tubes(&gpu, &a, &alone, &camera), draw_tubes(&gpu, &b, &masked, &camera));
    let (covered, ties) = same_gbuffer(&expected, &got, "tubes");
    assert!(covered > 5_000 && ties * 1000 <= covered, "{ties} ties of {covered}");
    // Nothing selected draws nothing; no selection draws every streamline again.
    masked.set_selection(d, q, Some(&[false; 600])).unwrap();
    let empty = draw(&gpu, &lines(false), &masked, &camera);
    assert!(!empty[1].data.iter().any(|&nd| is_geometry(nd)));
    masked.set_selection(d, q, None).unwrap();
    assert_eq!(masked.selected(), 600);
    let everything = LineGeometry::with_options(d, q, &positions, &offsets, options).unwrap();
    let (covered, ties) = same_gbuffer(
        &draw(&gpu, &lines(false), &everything, &camera),
        &draw(&gpu, &lines(false), &masked, &camera),
        "all",
    );
    assert!(ties * 1000 <= covered);
    // A selection of the wrong length is refused.
    assert!(masked.set_selection(d, q, Some(&[true; 3])).is_err());
}

#[test]
fn a_selection_changed_between_culled_frames_draws_at_once() {
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = ball(600);
    // Appended in three chunks, as a file streams in.
    let mut geometry = LineGeometry::empty(d, Default::default()).unwrap();
    for first in (0..600).step_by(200) {
        let (a, b) = (offsets[first], offsets[first + 200]);
        let local: Vec<u64> = offsets[first..=first + 200].iter().map(|o| o - a).collect();
        geometry.append(d, q, &positions[a as usize..b as usize], &local).unwrap();
    }
    geometry.finish(d, q).unwrap();
    for lod in [false, true] {
        let culled = LineRenderer::new(d).culled(d, lod);
        geometry.set_selection(d, q, None).unwrap();
        draw(&gpu, &culled, &geometry, &outside());
        let before = draw(&gpu, &culled, &geometry, &outside());
        assert!(before[1].data.iter().any(|&nd| is_geometry(nd)));
        geometry.set_selection(d, q, Some(&[false; 600])).unwrap();
        let after = draw(&gpu, &culled, &geometry, &outside());
        let left = after[1].data.iter().filter(|&&nd| is_geometry(nd)).count();
        assert_eq!(left, 0, "lod {lod}: {left} pixels of streamlines selected out");
    }
}

/// `DebugView::Frozen`'s cull: frozen after the frames of one view, a frame from another draws
/// exactly the pieces found visible for the first — the early phase alone, no late pieces, the
/// marks untouched — and so leaves the pixels the culled pieces would have covered empty; thawed,
/// the next frame is again every line's G-buffer.
#[test]
fn a_frozen_cull_draws_the_pieces_it_found_for_the_view_before() {
    let gpu = gpu();
    let q = &gpu.queue;
    let (geometry, all, culled) = ball_lines(&gpu, 4000);
    let cull = culled.cull().unwrap().cull();
    let (from, to) = (outside(), cameras()[4].1);
    draw(&gpu, &culled, &geometry, &from);
    draw(&gpu, &culled, &geometry, &from);
    let marks = cull.marks(q, &geometry).unwrap();
    let visible: u64 =
        marks.iter().flatten().map(|m| (m & lineao::passes::cull::MARK_VISIBLE).count_ones() as u64).sum();
    cull.set_frozen(Frozen::Visible);
    let frozen = draw(&gpu, &culled, &geometry, &to);
    let counts = cull.counts(q, &geometry).unwrap();
    assert_eq!((counts.early, counts.late), (visible, 0), "{counts}");
    assert_eq!(cull.marks(q, &geometry).unwrap(), marks, "a frozen frame marks nothing");
    let expected = draw(&gpu, &all, &geometry, &to);
    let covered = |g: &[NdImage; 4]| g[1].data.iter().filter(|t| is_geometry(**t)).count();
    let (shown, whole) = (covered(&frozen), covered(&expected));
    println!("frozen: {visible} pieces of {} drawn from the other side, {shown} of {whole} pixels", counts.pieces);
    assert!(shown > 0 && shown * 10 < whole * 9, "{shown} of {whole} pixels: the other side's front is missing");
    cull.set_frozen(Frozen::No);
    draw(&gpu, &culled, &geometry, &to);
    let thawed = draw(&gpu, &culled, &geometry, &to);
    same_gbuffer(&expected, &thawed, "thawed");
}

/// `DebugView::Culled`'s cull: frozen after the frames of one view, a frame from another draws
/// every piece — every line's G-buffer depth bit for bit — in the colors of the pieces' debug
/// view: blue where drawn, purple where left out behind what was drawn, light gray where
/// outside the view; the marks untouched.
#[test]
fn a_frozen_cull_shows_why_it_left_each_piece_out() {
    let gpu = gpu();
    let q = &gpu.queue;
    let (geometry, all, culled) = ball_lines(&gpu, 4000);
    let cull = culled.cull().unwrap().cull();
    let draw_pieces = |camera: &Camera| {
        draw_with(&gpu, camera, |encoder, targets, view, s| {
            culled.prepare(q, view, s.line_width_px, lineao::LineColor::Pieces, &s.lighting, None);
            culled.encode(encoder, targets, &geometry, lineao::passes::Load::Clear(s.background), None);
        })
    };
    // Close up, most of the ball lies outside the view; seen from the other side, its back.
    let cameras = cameras();
    for (from, to, hue) in [(&cameras[2].1, outside(), Hue::Gray), (&outside(), cameras[4].1, Hue::Purple)] {
        cull.set_frozen(Frozen::No);
        draw_pieces(from);
        draw_pieces(from);
        let marks = cull.marks(q, &geometry).unwrap();
        cull.set_frozen(Frozen::All);
        let shown = draw_pieces(&to);
        let counts = cull.counts(q, &geometry).unwrap();
        assert_eq!((counts.early, counts.late), (counts.pieces, 0), "{counts}");
        assert_eq!(cull.marks(q, &geometry).unwrap(), marks, "a frozen frame marks nothing");
        let expected = draw(&gpu, &all, &geometry, &to);
        let mut hues = [0usize; 4];
        for i in 0..expected[3].data.len() {
            let depth = (expected[3].data[i][0], shown[3].data[i][0]);
            assert_eq!(depth.0.to_bits(), depth.1.to_bits(), "depth differs at pixel {i}: {depth:?}");
            if is_geometry(shown[1].data[i]) {
                hues[hue_of(shown[0].data[i]) as usize] += 1;
            }
        }
        println!("frozen, every piece: {hues:?} pixels blue, purple, gray, other");
        assert_eq!(hues[Hue::Other as usize], 0);
        assert!(hues[Hue::Blue as usize] > 0 && hues[hue as usize] > hues.iter().sum::<usize>() / 4, "{hues:?}");
    }
}

#[derive(Clone, Copy)]
enum Hue {
    Blue,
    Purple,
    Gray,
    Other,
}

/// Which of the pieces' debug colors a lit G-buffer color is (lighting scales its channels
/// alike).
fn hue_of(color: [f32; 4]) -> Hue {
    let [r, g, b, _] = color;
    let most = r.max(g).max(b);
    if most - r.min(g).min(b) < 0.02 * most {
        Hue::Gray
    } else if b > g && g > r {
        Hue::Blue
    } else if b > r && r > 2.0 * g {
        Hue::Purple
    } else {
        Hue::Other
    }
}

/// How a frame rasterized in compute differs from the hardware's.
#[derive(Debug, Default)]
struct RasterDifferences {
    /// Geometry pixels of the hardware's frame.
    covered: usize,
    /// Pixels covered by one and not the other.
    coverage: usize,
    /// Pixels covered by both whose depths differ in their bits, and by more than 1e-5.
    depth_bits: usize,
    depth: usize,
    /// Where the depths agree within 1e-5: the pixels whose ND map or color differ by more than
    /// 2e-3, and the largest difference of the others.
    attributes: usize,
    largest: f32,
}

fn raster_differences(hardware: &[NdImage; 4], compute: &[NdImage; 4]) -> RasterDifferences {
    let mut d = RasterDifferences::default();
    let largest = |a: [f32; 4], b: [f32; 4]| (0..4).map(|k| (a[k] - b[k]).abs()).fold(0.0f32, f32::max);
    for i in 0..hardware[0].data.len() {
        let (a, b) = (is_geometry(hardware[1].data[i]), is_geometry(compute[1].data[i]));
        d.covered += a as usize;
        if a != b {
            d.coverage += 1;
            continue;
        }
        let (x, y) = (hardware[3].data[i][0], compute[3].data[i][0]);
        d.depth_bits += (x.to_bits() != y.to_bits()) as usize;
        if (x - y).abs() > 1e-5 {
            d.depth += 1;
        } else if a {
            let differs =
                largest(hardware[1].data[i], compute[1].data[i]).max(largest(hardware[0].data[i], compute[0].data[i]));
            if differs > 2e-3 {
                d.attributes += 1;
            } else {
                d.largest = d.largest.max(differs);
            }
        }
    }
    d
}

/// The culled lines rasterized in compute (`passes::raster`) draw the G-buffer the hardware
/// draws of the same pieces, at full detail and at levels of detail: the same pixels covered
/// (the coverage rule: a line a pixel wider, or a triangle of the strip missing, would differ on
/// thousands), the same depths within 1e-5 and the same ND map and colors there. The hardware
/// clips a quad that crosses the eye plane, the prototype leaves it out: from inside the ball
/// and close up the nearest fragment then differs on some pixels, which are counted, not bounded.
#[test]
fn lines_rasterized_in_compute_draw_the_hardware_g_buffer() {
    let gpu = gpu();
    let d = &gpu.device;
    // A geometry each: each page keeps its cull's marks (and levels), so that the two draw the
    // same frames of the same sequence.
    let (geometry, same) = (ball_geometry(&gpu, 8000), ball_geometry(&gpu, 8000));
    for lod in [false, true] {
        let hardware = LineRenderer::new(d).culled(d, lod);
        let compute = LineRenderer::new(d).culled(d, lod).rasterized_in_compute(d);
        assert_eq!(compute.raster_note(), None, "lavapipe has 64-bit atomics");
        for (case, camera) in cameras() {
            for frame in ["first", "second"] {
                let expected = draw(&gpu, &hardware, &geometry, &camera);
                let got = draw(&gpu, &compute, &same, &camera);
                let diff = raster_differences(&expected, &got);
                println!("{case} (levels of detail {lod}), {frame} frame: {diff:?}");
                let case = format!("{case}, levels of detail {lod}, {frame} frame");
                assert!(diff.coverage * 1000 <= diff.covered, "{case}: coverage differs at {}", diff.coverage);
                let crosses_the_eye_plane = camera.eye.length() < 60.0;
                if !crosses_the_eye_plane {
                    assert!(diff.depth * 1000 <= diff.covered, "{case}: depth differs at {}", diff.depth);
                    assert!(diff.attributes * 1000 <= diff.covered, "{case}: {diff:?}");
                }
            }
        }
    }
}
