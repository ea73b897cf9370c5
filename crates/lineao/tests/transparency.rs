//! Transparent lines against a CPU composite of independently rendered fragments: each line is
//! rendered alone and opaque through the chain (its colour, specular and depth read back per
//! pixel), the CPU sorts every pixel's fragments by depth and composites them front to back —
//! exact where a pixel holds at most K of them, within the tail's bound beyond — and the chain's
//! transparent frame of all lines must match. Focus + context: the selected lines opaque with
//! the context's fragments in front of them composited over, those behind them hidden.

mod common;

use common::gpu;
use lineao::passes::lines::GeometryOptions;
use lineao::readback::{read_f32, read_rgba};
use lineao::reference::{Image, NdImage};
use lineao::targets::Target;
use lineao::wgpu;
use lineao::{
    AoChain, AoMethod, Bounds, Camera, ChainSettings, Error, Gpu, LineGeometry, TransparencySettings, VolumeAoSettings,
};

const SIZE: (u32, u32) = (72, 64);
/// The composite's target: blendable everywhere (Rgba32Float is only with a feature), its
/// halves read back exactly.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The background, which the lines are composited over.
const BACKGROUND: [f32; 3] = [0.9, 0.85, 0.8];
/// The K-buffer's colours and the target are half floats: 2⁻¹¹ relative, under 1/1000 of a
/// channel ≤ 1.5, summed over a few layers.
const TOLERANCE: f32 = 4e-3;

/// A polyline.
type Line = Vec<[f32; 3]>;

/// Straight lines crossing one another in a small region at different depths, of `POINTS`
/// points each (one colour along a line; straight, no line covers a pixel twice).
fn segments() -> Vec<Line> {
    const POINTS: usize = 8;
    (0..10)
        .map(|i| {
            let a = i as f32 * 0.61;
            let (s, c) = a.sin_cos();
            let z = -0.8 + 0.17 * i as f32;
            let centre = glam::Vec3::new(0.07 * (i % 3) as f32 - 0.07, 0.05 * (i % 4) as f32 - 0.08, z);
            let half = glam::Vec3::new(c, s, -0.3 * s);
            (0..POINTS).map(|k| (centre + half * (2.0 * k as f32 / (POINTS - 1) as f32 - 1.0)).to_array()).collect()
        })
        .collect()
}

/// A zigzag of sharp bends, its segments short against its width on screen: its strip folds
/// over itself at every bend.
fn zigzag() -> Line {
    (0..17).map(|k| [-1.2 + 0.15 * k as f32, if k % 2 == 0 { -0.15 } else { 0.15 }, 0.05 * k as f32 - 0.4]).collect()
}

fn camera() -> (Camera, Bounds) {
    let camera = Camera {
        eye: glam::Vec3::new(0.0, 0.0, 4.0),
        target: glam::Vec3::ZERO,
        up: glam::Vec3::Y,
        projection: lineao::Projection::Perspective { fov_y_deg: 40.0 },
    };
    (camera, Bounds { center: glam::Vec3::ZERO, radius: 1.6 })
}

/// Plain lit lines (no occlusion) over the background, wide enough to overlap.
fn plain() -> ChainSettings {
    ChainSettings { method: AoMethod::None, background: BACKGROUND, line_width_px: 5.0, ..ChainSettings::default() }
}

/// The lines on the GPU, each point with octant visibilities that vary with its position
/// (object-space AO's attribute: the same for a line drawn alone or with the others).
fn geometry(gpu: &Gpu, lines: &[Line]) -> LineGeometry {
    let positions: Vec<[f32; 3]> = lines.iter().flatten().copied().collect();
    let offsets: Vec<u64> = std::iter::once(0)
        .chain(lines.iter().scan(0, |end, line| {
            *end += line.len() as u64;
            Some(*end)
        }))
        .collect();
    // One tolerance for the alternating strip whatever the lines' bounds: a line's strip is
    // then the same drawn alone or with the others.
    let options = GeometryOptions { tolerance: Some(0.002), ..Default::default() };
    let mut geometry = LineGeometry::with_options(&gpu.device, &gpu.queue, &positions, &offsets, options).unwrap();
    let visibility = |p: &[f32; 3], o: usize| 0.5 + 0.45 * (3.0 * p[0] + 2.0 * p[1] + p[2] + o as f32).sin();
    let octants: Vec<[f32; 8]> = positions.iter().map(|p| std::array::from_fn(|o| visibility(p, o))).collect();
    let attributes = lineao::passes::lines::VertexAttributes { octants: Some(&octants), ..Default::default() };
    geometry.set_attributes(&gpu.device, &gpu.queue, &attributes).unwrap();
    geometry
}

/// The chain's output of `geometry` with `settings` (composited into `FORMAT`), and its
/// G-buffer depth.
fn render(gpu: &Gpu, geometry: &LineGeometry, settings: ChainSettings) -> (NdImage, Image<f32>) {
    let (camera, bounds) = camera();
    let mut chain = AoChain::new(&gpu.device, FORMAT, settings).unwrap();
    chain.resize(SIZE.0, SIZE.1).unwrap();
    chain.prepare(&gpu.device, &gpu.queue, &camera, &bounds).unwrap();
    let output = Target::output(&gpu.device, "test::output", SIZE, FORMAT);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, geometry, &output.view).unwrap();
    gpu.queue.submit([encoder.finish()]);
    let targets = chain.targets().unwrap();
    assert_eq!(targets.guard, 0, "lines without a method need no guard band");
    let depth = read_f32(&gpu.device, &gpu.queue, &targets.depth).unwrap();
    (read_rgba(&gpu.device, &gpu.queue, &output).unwrap(), depth)
}

/// A pixel's fragment: depth, colour.
type Fragment = (f32, [f32; 3]);

/// Each line's fragments, rendered alone and opaque with `settings`: per pixel, (depth, colour)
/// where it covers it.
fn fragments(gpu: &Gpu, lines: &[Line], settings: &ChainSettings) -> Vec<Vec<Fragment>> {
    let mut per_pixel = vec![Vec::new(); (SIZE.0 * SIZE.1) as usize];
    for line in lines {
        let (output, depth) = render(gpu, &geometry(gpu, std::slice::from_ref(line)), settings.clone());
        for (i, fragments) in per_pixel.iter_mut().enumerate() {
            let (x, y) = (i % SIZE.0 as usize, i / SIZE.0 as usize);
            let d = depth.get(x, y);
            if d < 1.0 {
                let c = output.get(x, y);
                fragments.push((d, [c[0], c[1], c[2]]));
            }
        }
    }
    per_pixel
}

/// The front-to-back composite of `fragments` at `alpha` over `behind`, the K nearest exact and
/// the rest as the tail's bound says: (colour, the bound of its error).
fn composite(fragments: &[Fragment], alpha: f32, layers: usize, behind: [f32; 3]) -> ([f32; 3], f32) {
    let mut sorted = fragments.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut rgb = [0.0f32; 3];
    let mut transmittance = 1.0;
    let mut at_k = 1.0;
    for (i, (_, c)) in sorted.iter().enumerate() {
        if i == layers {
            at_k = transmittance;
        }
        for k in 0..3 {
            rgb[k] += transmittance * alpha * c[k];
        }
        transmittance *= 1.0 - alpha;
    }
    let tail_coverage =
        if sorted.len() > layers { 1.0 - (1.0 - alpha).powi((sorted.len() - layers) as i32) } else { 0.0 };
    let out = [0, 1, 2].map(|k| rgb[k] + transmittance * behind[k]);
    // The tail's colour, true and approximate, lies between its fragments' extremes: the
    // difference is at most their range times its coverage.
    let range = sorted.iter().skip(layers).flat_map(|(_, c)| c.iter().copied()).fold(0.0f32, f32::max);
    (out, at_k * tail_coverage * range)
}

/// Renders `lines` transparent at `alpha` with K = `layers` (over `settings`) and checks every
/// pixel against the composite of the lines' fragments rendered alone and opaque.
fn check_against_fragments(settings: ChainSettings, alpha: f32, layers: u32) {
    let gpu = gpu();
    let lines = segments();
    let per_pixel = fragments(&gpu, &lines, &settings);
    let deepest = per_pixel.iter().map(Vec::len).max().unwrap();
    let all = geometry(&gpu, &lines);
    let transparency = Some(TransparencySettings { alpha, context_alpha: 0.0, layers });
    let (output, _) = render(&gpu, &all, ChainSettings { transparency, ..settings });
    let (mut exact, mut beyond, mut worst_exact, mut worst_beyond) = (0, 0, 0.0f32, 0.0f32);
    for (i, fragments) in per_pixel.iter().enumerate() {
        let (x, y) = (i % SIZE.0 as usize, i / SIZE.0 as usize);
        let (expected, bound) = composite(fragments, alpha, layers as usize, BACKGROUND);
        let got = output.get(x, y);
        let error = (0..3).map(|k| (got[k] - expected[k]).abs()).fold(0.0, f32::max);
        if fragments.len() <= layers as usize {
            exact += 1;
            worst_exact = worst_exact.max(error);
            assert!(error <= TOLERANCE, "({x}, {y}), {} fragments: {got:?} vs {expected:?}", fragments.len());
        } else {
            beyond += 1;
            worst_beyond = worst_beyond.max(error - bound);
            assert!(
                error <= bound + TOLERANCE,
                "({x}, {y}), {} fragments: {got:?} vs {expected:?}, bound {bound}",
                fragments.len()
            );
        }
    }
    println!(
        "{exact} pixels of ≤ K = {layers} fragments: worst {worst_exact:.5}; {beyond} of more (up to {deepest}): \
         worst over the bound {worst_beyond:.5}"
    );
    assert!(beyond > 50 && deepest > 2 * layers as usize, "the scene must pile fragments past K: {beyond}, {deepest}");
    assert!(per_pixel.iter().filter(|f| f.len() >= 2).count() > 200, "lines must overlap");
}

#[test]
fn transparent_lines_match_the_depth_sorted_composite_of_their_fragments() {
    check_against_fragments(plain(), 0.4, 3);
}

/// Each fragment darkened by the object-space AO at its own point: the opaque chain's
/// per-pixel object-space AO of each line alone (method none: the composite shows it) is the
/// reference's colour.
#[test]
fn transparent_lines_are_darkened_by_their_own_object_space_ao() {
    let settings = ChainSettings { volume: Some(VolumeAoSettings::default()), strength: 0.9, ..plain() };
    check_against_fragments(settings, 0.3, 4);
}

/// A line counts once where its own pieces overlap: every pixel of a transparent zigzag is its
/// one nearest fragment over the background, the joins too (blended twice there, they would
/// be darker beads).
#[test]
fn a_bent_line_is_blended_once_at_its_joins() {
    let gpu = gpu();
    let line = zigzag();
    let settings = ChainSettings { line_width_px: 12.0, ..plain() };
    let per_pixel = fragments(&gpu, std::slice::from_ref(&line), &settings);
    let alpha = 0.5;
    let transparency = Some(TransparencySettings { alpha, ..Default::default() });
    let (output, _) = render(&gpu, &geometry(&gpu, &[line]), ChainSettings { transparency, ..settings });
    let mut covered = 0;
    for (i, fragments) in per_pixel.iter().enumerate() {
        let (x, y) = (i % SIZE.0 as usize, i / SIZE.0 as usize);
        covered += fragments.len();
        let (expected, _) = composite(fragments, alpha, 8, BACKGROUND);
        let got = output.get(x, y);
        let error = (0..3).map(|k| (got[k] - expected[k]).abs()).fold(0.0, f32::max);
        assert!(error <= TOLERANCE, "({x}, {y}): {got:?} vs {expected:?}: blended twice?");
    }
    assert!(covered > 500, "{covered} pixels");
}

#[test]
fn context_lines_composite_over_the_opaque_focus_and_hide_behind_it() {
    let gpu = gpu();
    let lines = segments();
    let selected: Vec<bool> = (0..lines.len()).map(|i| i % 3 == 0).collect();
    let focus: Vec<_> = lines.iter().zip(&selected).filter(|(_, s)| **s).map(|(l, _)| l.clone()).collect();
    let context: Vec<_> = lines.iter().zip(&selected).filter(|(_, s)| !**s).map(|(l, _)| l.clone()).collect();
    // The opaque picture: the focus alone, with its depth.
    let (opaque, opaque_depth) = render(&gpu, &geometry(&gpu, &focus), plain());
    let per_pixel = fragments(&gpu, &context, &plain());
    let mut all = geometry(&gpu, &lines);
    all.set_selection(&gpu.device, &gpu.queue, Some(&selected)).unwrap();
    let context_alpha = 0.5;
    let settings =
        ChainSettings { transparency: Some(TransparencySettings { alpha: 1.0, context_alpha, layers: 16 }), ..plain() };
    let (output, _) = render(&gpu, &all, settings.clone());
    let (mut hidden, mut over) = (0, 0);
    for (i, fragments) in per_pixel.iter().enumerate() {
        let (x, y) = (i % SIZE.0 as usize, i / SIZE.0 as usize);
        let d = opaque_depth.get(x, y);
        let in_front: Vec<Fragment> = fragments.iter().copied().filter(|f| f.0 < d).collect();
        hidden += fragments.len() - in_front.len();
        over += (d < 1.0 && !in_front.is_empty()) as usize;
        let o = opaque.get(x, y);
        let (expected, bound) = composite(&in_front, context_alpha, 16, [o[0], o[1], o[2]]);
        assert_eq!(bound, 0.0, "K = 16 holds every fragment here");
        let got = output.get(x, y);
        let error = (0..3).map(|k| (got[k] - expected[k]).abs()).fold(0.0, f32::max);
        assert!(error <= TOLERANCE, "({x}, {y}): {got:?} vs {expected:?}");
    }
    assert!(hidden > 20 && over > 20, "context both behind and in front of the focus: {hidden}, {over}");
    // Hidden context (0) is today's picture of the selection; all selected, there is no context.
    let hide = ChainSettings {
        transparency: Some(TransparencySettings { context_alpha: 0.0, ..Default::default() }),
        ..plain()
    };
    assert_same(&render(&gpu, &all, hide).0, &render(&gpu, &all, plain()).0, "the focus alone");
    all.set_selection(&gpu.device, &gpu.queue, None).unwrap();
    let (everything, _) = render(&gpu, &all, plain());
    assert_same(&render(&gpu, &all, settings).0, &everything, "no line left for the context");
}

/// `a` and `b` within [`TOLERANCE`]: a line geometry's first frame on lavapipe differs from
/// its next ones by a few half-float steps in a few pixels, transparency or not.
fn assert_same(a: &NdImage, b: &NdImage, what: &str) {
    let close = |p: [f32; 4], q: [f32; 4]| (0..4).all(|k| (p[k] - q[k]).abs() <= TOLERANCE);
    let differ: Vec<usize> = (0..a.data.len()).filter(|&i| !close(a.data[i], b.data[i])).collect();
    if let Some(&i) = differ.first() {
        let (x, y) = (i % a.width, i / a.width);
        panic!("{what}: {} pixels differ, first ({x}, {y}): {:?} vs {:?}", differ.len(), a.data[i], b.data[i]);
    }
}

#[test]
fn bad_transparency_is_an_error_naming_the_setting() {
    let gpu = gpu();
    let cases = [
        (TransparencySettings { alpha: 0.0, ..Default::default() }, "alpha"),
        (TransparencySettings { alpha: 1.5, ..Default::default() }, "alpha"),
        (TransparencySettings { alpha: f32::NAN, ..Default::default() }, "alpha"),
        (TransparencySettings { context_alpha: -0.1, ..Default::default() }, "context-alpha"),
        (TransparencySettings { alpha: 0.5, layers: 0, ..Default::default() }, "layers"),
        (TransparencySettings { alpha: 0.5, layers: 17, ..Default::default() }, "layers"),
    ];
    for (transparency, name) in cases {
        let settings = ChainSettings { transparency: Some(transparency.clone()), ..plain() };
        match AoChain::new(&gpu.device, FORMAT, settings) {
            Err(Error::OutOfRange { setting, .. }) => assert_eq!(setting, name, "{transparency:?}"),
            other => panic!("{transparency:?}: {:?}", other.err()),
        }
    }
    let tubes = ChainSettings {
        transparency: Some(TransparencySettings { alpha: 0.5, ..Default::default() }),
        tubes: Some(lineao::TubeSettings { radius_world: 0.1 }),
        ..plain()
    };
    let refused = AoChain::new(&gpu.device, FORMAT, tubes).err();
    assert!(matches!(refused, Some(Error::Conflict { setting: "alpha", with: "geometry", .. })), "{refused:?}");
    // A K-buffer past the device's storage is refused by size, not by wgpu's panic.
    let transparency = Some(TransparencySettings { alpha: 0.5, layers: 16, ..Default::default() });
    let mut chain = AoChain::new(&gpu.device, FORMAT, ChainSettings { transparency, ..plain() }).unwrap();
    let guard = plain().guard_max_px;
    let side = 8192.min(gpu.device.limits().max_texture_dimension_2d - 2 * guard);
    let banded = (side + 2 * guard) as u64;
    let limits = gpu.device.limits();
    let fits = banded * banded * 16 * 8 <= limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    match chain.resize(side, side) {
        Ok(()) => assert!(fits),
        Err(Error::TooLarge { message, .. }) => assert!(!fits && message.contains("K-buffer"), "{message}"),
        Err(other) => panic!("{other:?}"),
    }
}

#[test]
fn a_target_that_cannot_blend_is_refused_by_name() {
    let gpu = gpu();
    let transparency = Some(TransparencySettings { alpha: 0.5, ..Default::default() });
    let settings = ChainSettings { transparency, ..plain() };
    // 32-bit floats blend only with the device's feature, which lineao asks for where offered.
    let blendable = gpu.device.features().contains(wgpu::Features::FLOAT32_BLENDABLE);
    match AoChain::new(&gpu.device, wgpu::TextureFormat::Rgba32Float, settings.clone()) {
        Ok(_) => assert!(blendable),
        Err(Error::Unsupported(message)) => assert!(!blendable && message.contains("Rgba32Float"), "{message}"),
        Err(other) => panic!("{other:?}"),
    }
    // Made without transparency, a chain takes settings that ask for it where its target can
    // blend, and refuses them (keeping its own) where not.
    let mut chain = AoChain::new(&gpu.device, wgpu::TextureFormat::Rgba32Float, plain()).unwrap();
    match chain.set_settings(&gpu.device, settings.clone()) {
        Ok(()) => assert!(blendable && chain.settings() == &settings),
        Err(Error::Unsupported(_)) => assert!(!blendable && chain.settings() == &plain()),
        Err(other) => panic!("{other:?}"),
    }
}
