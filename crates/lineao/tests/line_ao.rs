//! LineAO and the ND pyramid: closed-form cases worked out here, the passes run alone on
//! G-buffers written from the CPU, and the GPU against the CPU reference on rendered lines.

mod common;

use common::{cameras_for_polylines, flat_view, gpu, is_geometry, line_ao_on, polylines, render};
use glam::Vec3;
use lineao::FrameView;
use lineao::lighting::{Light, Lighting};
use lineao::method::line_ao::sample_table;
use lineao::noise::noise_tile;
use lineao::reference::{self, Image, LineAoParams, NdImage};
use lineao::reference::{line_ao_flip_bound, line_ao_reference_flip_bound};
use lineao::verify::{check_policy, compare};
use lineao::{Camera, Projection};
use lineao::{ChainSettings, LineAoOuter, LineAoSettings, LineAoVariant};

fn settings(s_r: u32, r0_px: f32, light_attenuation: bool) -> ChainSettings {
    ChainSettings {
        line_ao: LineAoSettings { s_r, r0_px: Some(r0_px), light_attenuation, ..LineAoSettings::default() },
        ..ChainSettings::default()
    }
}

#[test]
fn delta_curve_and_depth_weight() {
    // δ(l) = (1 − l/s_r)² (Eq. 11): 1, 4/9, 1/9 for s_r = 3.
    for (j, expected) in [(0, 1.0), (1, 4.0 / 9.0), (2, 1.0 / 9.0)] {
        assert!((reference::delta(j, 3, 1.0) - expected).abs() < 1e-6);
        // The δ scale multiplies the whole curve.
        assert!((reference::delta(j, 3, 0.1) - 0.1 * expected).abs() < 1e-7);
    }
    let (d0, dj) = (1e-4, 4.0 / 9.0);
    assert_eq!(reference::depth_weight(0.5 * d0, dj, d0), 1.0);
    assert_eq!(reference::depth_weight(d0, dj, d0), 1.0); // continuous at δ0: 1 − h(0)
    assert!(reference::depth_weight(dj, dj, d0).abs() < 1e-6); // and at δ(l): 1 − h(1)
    assert!((reference::depth_weight(0.5 * (d0 + dj), dj, d0) - 0.5).abs() < 1e-6); // h(1/2) = 1/2
    assert_eq!(reference::depth_weight(dj + 1e-3, dj, d0), 0.0);
    // h(x) = 3x² − 2x³ at x = 1/4: 3/16 − 2/64 = 0.15625.
    assert!((reference::hermite(0.25) - 0.15625).abs() < 1e-7);
    let sweep: Vec<f32> = (0..=100).map(|k| reference::depth_weight(k as f32 / 200.0, dj, d0)).collect();
    assert!(sweep.windows(2).all(|w| w[1] <= w[0]), "g_depth must not increase with Δd");
}

#[test]
fn light_weight_closed_form() {
    let params = |dir: Vec3| LineAoParams {
        variant: LineAoVariant::Paper,
        outer: LineAoOuter::Full,
        reference_scale: [0.0; 2],
        s_r: 3,
        s_h: 32,
        r0_px: 3.0,
        r0_zoom: 0.0,
        delta0: 1e-4,
        delta_scale: 1.0,
        epsilon: 1e-6,
        light_attenuation: true,
        lights: vec![Light { dir, intensity: 1.0 }],
        kd: 0.3,
        ks: 0.4,
        shininess: 32.0,
        noise_origin: [0, 0],
    };
    let n = Vec3::Z;
    // Light, normal and ω aligned: BRDF = kd + ks = 0.7.
    assert!((reference::light_weight(&params(Vec3::Z), n, Vec3::Z) - 0.3).abs() < 1e-6);
    // ω ⊥ n: h at 45°, (n·h)^32 = 2^-16.
    let expected = 1.0 - (0.3 + 0.4 * 2f32.powi(-16));
    assert!((reference::light_weight(&params(Vec3::Z), n, Vec3::X) - expected).abs() < 1e-6);
    // Light behind the surface and ω opposite to it: nothing reflected.
    assert_eq!(reference::light_weight(&params(-Vec3::Z), n, Vec3::Z), 1.0);
    let off = LineAoParams { light_attenuation: false, ..params(Vec3::Z) };
    assert_eq!(reference::light_weight(&off, n, Vec3::Z), 1.0);
}

/// A flat fronto-parallel ND map with the given per-pixel depth.
fn nd_map(width: usize, height: usize, depth: impl Fn(usize, usize) -> f32) -> NdImage {
    Image::from_fn(width, height, |x, y| [0.0, 0.0, 1.0, depth(x, y)])
}

fn cpu_line_ao(levels: &[NdImage], zoom: &Image<f32>, s: &ChainSettings, view: &FrameView) -> Image<f32> {
    let ao = &s.line_ao;
    reference::line_ao(levels, zoom, &noise_tile(ao.noise_seed), &sample_table(ao), &LineAoParams::new(s, view))
}

/// The view `line_ao_on` uses for a CPU-written G-buffer of `levels[0]`'s size.
fn view_of(level0: &NdImage, guard: u32) -> FrameView {
    flat_view(level0.width as u32 - 2 * guard, level0.height as u32 - 2 * guard, guard)
}

#[test]
fn flat_region_is_unoccluded_even_with_rounding_noise() {
    let gpu = gpu();
    let s = settings(3, 6.0, true);
    // Depth noise below ε = 1e-6 (f32 rounding of a flat surface) must not occlude (docs/reference.md
    // departs from Eq. 8's Δd ≥ 0 for this reason).
    let nd0 = nd_map(64, 48, |x, y| 0.5 + if (x * 7 + y * 3) % 5 == 0 { 4e-7 } else { 0.0 });
    let zoom = Image::filled(64, 48, 4.0f32);
    let (levels, ao) = line_ao_on(&gpu, &nd0, &zoom, &s, 0);
    assert!(ao.data.iter().all(|&a| a == 0.0), "GPU occludes a flat region");
    assert!(
        cpu_line_ao(&levels, &zoom, &s, &view_of(&levels[0], 0)).data.iter().all(|&a| a == 0.0),
        "CPU occludes a flat region"
    );
}

/// Occlusion at pixel (x, y) of a step edge: the samples of hemisphere 0 that land at column
/// `edge` or beyond, each weighted by `weight` — counted here from the noise tables alone.
/// Pixels on the occluder's own side see only their own depth or farther: nothing.
fn step_edge_expected(x: usize, y: usize, edge: usize, r0: f32, s_h: u32, weight: f32) -> f32 {
    if x >= edge {
        return 0.0;
    }
    let (noise, samples) = (noise_tile(1), lineao::noise::sample_table(1, 1, s_h, |_| s_h));
    let r1 = Vec3::from_array(noise[(y % 64) * 64 + x % 64]);
    let hits = samples
        .iter()
        .map(|r2| {
            let r2 = Vec3::from_array(*r2);
            let omega = r1 - 2.0 * r2.dot(r1) * r2;
            if omega.z < 0.0 { -omega } else { omega }
        })
        .filter(|omega| (x as f32 + 0.5 + omega.x * r0).floor() >= edge as f32)
        .count();
    hits as f32 * weight / s_h as f32
}

#[test]
fn step_edge_occludes_a_known_fraction_of_samples() {
    let gpu = gpu();
    let (w, h, edge, r0) = (64usize, 16usize, 32usize, 6.0f32);
    let zoom = Image::filled(w, h, 4.0f32);
    // An occluder closer by Δ < δ0 weighs 1; by Δ = 0.3 it weighs 1 − h((Δ − δ0)/(1 − δ0)).
    let d0 = 1e-4f32;
    for (step, weight) in [(5e-5f32, 1.0f32), (0.3, 1.0 - reference::hermite((0.3 - d0) / (1.0 - d0)))] {
        let s = settings(1, r0, false);
        let nd0 = nd_map(w, h, |x, _| if x >= edge { 0.5 - step } else { 0.5 });
        let (levels, gpu_ao) = line_ao_on(&gpu, &nd0, &zoom, &s, 0);
        let cpu_ao = cpu_line_ao(&levels, &zoom, &s, &view_of(&levels[0], 0));
        let mut occluded_pixels = 0;
        for y in 0..h {
            for x in 0..w {
                let expected = step_edge_expected(x, y, edge, r0, 32, weight);
                assert!(
                    (cpu_ao.get(x, y) - expected).abs() < 1e-5,
                    "CPU at ({x}, {y}): {} vs {expected}",
                    cpu_ao.get(x, y)
                );
                // One sample may land on the other side of a texel border on the GPU (FMA).
                assert!((gpu_ao.get(x, y) - expected).abs() <= weight / 32.0 + 1e-5, "GPU at ({x}, {y})");
                if x + (r0 as usize) + 1 < edge {
                    assert_eq!(expected, 0.0, "only pixels within r0 left of the edge are occluded");
                }
                occluded_pixels += (expected > 0.0) as usize;
            }
        }
        assert!(occluded_pixels >= 4 * h, "{occluded_pixels}");
    }
}

#[test]
fn light_attenuation_scales_by_the_brdf() {
    let gpu = gpu();
    let (w, h) = (48usize, 16usize);
    let nd0 = nd_map(w, h, |x, _| if x >= 24 { 0.49995 } else { 0.5 });
    let zoom = Image::filled(w, h, 4.0f32);
    let off = settings(1, 6.0, false);
    // A purely diffuse light: g_light = 1 − kd · (n · L) = 1 − 0.3 · 0.8 for every sample.
    let lighting = Lighting {
        lights: vec![Light { dir: Vec3::new(0.0, 0.6, 0.8), intensity: 1.0 }],
        ks: 0.0,
        ..Lighting::default()
    };
    let on = ChainSettings { lighting, ..settings(1, 6.0, true) };
    let (levels, ao_off) = line_ao_on(&gpu, &nd0, &zoom, &off, 0);
    let (_, ao_on) = line_ao_on(&gpu, &nd0, &zoom, &on, 0);
    let cpu_on = cpu_line_ao(&levels, &zoom, &on, &view_of(&levels[0], 0));
    let mut occluded = 0;
    for i in 0..w * h {
        assert!((ao_on.data[i] - 0.76 * ao_off.data[i]).abs() < 1e-5, "GPU pixel {i}");
        assert!((cpu_on.data[i] - ao_on.data[i]).abs() < 1e-5, "CPU pixel {i}");
        occluded += (ao_off.data[i] > 0.0) as usize;
    }
    assert!(occluded > 0);
}

#[test]
fn parallel_lines_occlude_within_r0_only() {
    let gpu = gpu();
    let cam = Camera {
        eye: Vec3::new(0.0, 0.0, 100.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Orthographic { height: 100.0 },
    };
    // Orthographic, 1 px per unit. The front line is 2 units closer (Δd = 0.02 of the depth range).
    let r0 = 8.0;
    for (gap, occludes) in [(5.0f32, true), (30.0, false)] {
        let back = [[-40.0, 0.0, 0.0], [40.0, 0.0, 0.0]];
        let front = [[-40.0, gap, 2.0], [40.0, gap, 2.0]];
        let positions = [back, front].concat();
        let bounds = lineao::Bounds { center: Vec3::ZERO, radius: 50.0 };
        let s = settings(1, r0, false);
        let frame = render(&gpu, &positions, &[0, 2, 4], &cam, Some(bounds), s.clone(), (100, 100));
        let g = frame.guard;
        let row = |y: f32| (50.0 - y) as usize + g - 1..=(50.0 - y) as usize + g;
        let back_ao: f32 =
            (20 + g..80 + g).flat_map(|x| row(0.0).map(move |y| (x, y))).map(|(x, y)| frame.ao.get(x, y)).sum();
        let front_ao: f32 =
            (20 + g..80 + g).flat_map(|x| row(gap).map(move |y| (x, y))).map(|(x, y)| frame.ao.get(x, y)).sum();
        assert_eq!(front_ao, 0.0, "nothing is in front of the front line");
        assert_eq!(back_ao > 0.0, occludes, "gap {gap} px, r0 {r0} px: back line AO sum {back_ao}");
        let cpu = cpu_line_ao(&frame.nd, &frame.zoom, &s, &frame.view);
        check_policy(&frame.ao, &cpu, &frame.nd[0], line_ao_flip_bound(1, 32)).unwrap();
    }
}

#[test]
fn gpu_matches_cpu_reference_on_rendered_lines() {
    let gpu = gpu();
    let (positions, offsets) = polylines(120, 0.3);
    let (perspective, ortho) = cameras_for_polylines();
    let cases = [
        ("perspective, light", perspective, ChainSettings::default()),
        (
            "perspective, no light",
            perspective,
            ChainSettings {
                line_ao: LineAoSettings { light_attenuation: false, ..Default::default() },
                ..Default::default()
            },
        ),
        ("orthographic, wide lines", ortho, ChainSettings { line_width_px: 4.0, ..Default::default() }),
        (
            // The light count is compiled into the pipeline: two lights, and none at all.
            "perspective, two lights",
            perspective,
            ChainSettings {
                lighting: Lighting {
                    lights: vec![
                        Light { dir: Vec3::new(-0.4, 0.6, 0.7), intensity: 0.7 },
                        Light { dir: Vec3::new(0.5, -0.2, 0.8), intensity: 0.6 },
                    ],
                    ..Lighting::default()
                },
                ..Default::default()
            },
        ),
        (
            "perspective, no lights",
            perspective,
            ChainSettings { lighting: Lighting { lights: vec![], ..Lighting::default() }, ..Default::default() },
        ),
        (
            // The δ scale reaches the shader: occluders beyond 0.05 in depth stop counting.
            "perspective, δ scale 0.05",
            perspective,
            ChainSettings { line_ao: LineAoSettings { delta_scale: 0.05, ..Default::default() }, ..Default::default() },
        ),
    ];
    for (name, cam, s) in cases {
        let frame = render(&gpu, &positions, &offsets, &cam, None, s.clone(), (240, 180));
        assert!(frame.guard > 0);
        // The pyramid from the GPU's own level 0.
        let cpu_levels = reference::nd_pyramid(frame.nd[0].clone(), s.line_ao.s_r);
        for (j, (g, c)) in frame.nd.iter().zip(&cpu_levels).enumerate().skip(1) {
            for channel in 0..4 {
                let a = Image { width: g.width, height: g.height, data: g.data.iter().map(|t| t[channel]).collect() };
                let b = Image { width: c.width, height: c.height, data: c.data.iter().map(|t| t[channel]).collect() };
                let stats = compare(&a, &b, 1e-5, |_, _| true);
                assert!(
                    stats.fraction_within > 0.999 && stats.worst < 1e-3,
                    "{name}: level {j} channel {channel}: {stats}"
                );
            }
        }
        // LineAO on exactly the GPU's pyramid and zoom.
        let cpu = cpu_line_ao(&frame.nd, &frame.zoom, &s, &frame.view);
        let stats = check_policy(&frame.ao, &cpu, &frame.nd[0], line_ao_flip_bound(3, 32))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name}: {stats}");
        if s.line_ao.delta_scale != 1.0 {
            // The case can fail: with the paper's δ the reference differs on many pixels.
            let paper =
                ChainSettings { line_ao: LineAoSettings { delta_scale: 1.0, ..s.line_ao.clone() }, ..s.clone() };
            let unscaled = cpu_line_ao(&frame.nd, &frame.zoom, &paper, &frame.view);
            let differing = unscaled.data.iter().zip(&cpu.data).filter(|(a, b)| (*a - *b).abs() > 0.02).count();
            assert!(differing > 500, "{name}: δ scale changes only {differing} pixels");
        }
        let occluded = frame.ao.data.iter().filter(|&&a| a > 0.05).count();
        assert!(occluded > 500, "{name}: only {occluded} occluded pixels");
        // The composite over the visible window.
        let expected = reference::composite(&frame.color, &frame.specular, &frame.ao, frame.guard, s.strength);
        for (i, (out, exp)) in frame.output.data.iter().zip(&expected.data).enumerate() {
            for c in 0..3 {
                assert!((out[c] - exp[c]).abs() < 1e-5, "{name}: composite pixel {i}: {out:?} vs {exp:?}");
            }
        }
        assert!(frame.nd[0].data.iter().filter(|t| is_geometry(**t)).count() > 2000);
    }
}

/// The depth-aware upsampling of `outer = level`: a constant stays constant, a smooth ramp is
/// interpolated bilinearly, and nothing crosses a depth step of more than τ.
#[test]
fn outer_upsampling_is_bilinear_within_a_surface_and_stops_at_depth_steps() {
    let constant = Image::filled(5, 4, [0.25f32, 0.5]);
    let ramp = Image::from_fn(5, 4, |x, _| [x as f32 * 0.1, 0.5]);
    let step = Image::from_fn(5, 4, |x, _| if x < 2 { [1.0f32, 0.3] } else { [0.0, 0.6] });
    for y in 0..8 {
        for x in 0..10 {
            assert_eq!(reference::upsample_outer(&constant, [10, 8], x, y), 0.25);
            // Texel centres sit at full-resolution x = 2t + 0.5: between them the ramp is linear.
            let expected = ((x as f32 - 0.5) / 2.0).clamp(0.0, 4.0) * 0.1;
            assert!((reference::upsample_outer(&ramp, [10, 8], x, y) - expected).abs() < 1e-6, "({x}, {y})");
            let side = if x < 4 { 1.0 } else { 0.0 };
            assert_eq!(reference::upsample_outer(&step, [10, 8], x, y), side, "({x}, {y})");
        }
    }
    const { assert!(reference::OUTER_DEPTH_TOLERANCE < 0.3) };
}

/// `outer = level` on rendered lines: the GPU's level passes and depth-aware upsampling against
/// the CPU reference, under the same policy as `outer = full`; and what it changes: the level
/// image is the full one subsampled, so the result differs from `full` by noise, less than
/// `full` differs from itself under another noise seed, and not on average.
#[test]
fn outer_level_matches_the_cpu_reference_and_stays_near_full() {
    let gpu = gpu();
    let (positions, offsets) = polylines(120, 0.3);
    let (perspective, ortho) = cameras_for_polylines();
    let with = |outer, noise_seed| ChainSettings {
        line_ao: LineAoSettings { outer, noise_seed, ..Default::default() },
        ..Default::default()
    };
    for (name, cam) in [("perspective", perspective), ("orthographic", ortho)] {
        let s = with(LineAoOuter::Level, 1);
        let frame = render(&gpu, &positions, &offsets, &cam, None, s.clone(), (240, 180));
        let cpu = cpu_line_ao(&frame.nd, &frame.zoom, &s, &frame.view);
        let stats = check_policy(&frame.ao, &cpu, &frame.nd[0], line_ao_flip_bound(3, 32))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name}, outer = level: {stats}");

        let full = render(&gpu, &positions, &offsets, &cam, None, with(LineAoOuter::Full, 1), (240, 180));
        let reseeded = render(&gpu, &positions, &offsets, &cam, None, with(LineAoOuter::Full, 2), (240, 180));
        let geometry = |x: usize, y: usize| is_geometry(frame.nd[0].get(x, y));
        let level_vs_full = compare(&frame.ao, &full.ao, 0.0, geometry);
        let seed_vs_seed = compare(&reseeded.ao, &full.ao, 0.0, geometry);
        let mean = |ao: &Image<f32>| {
            let values: Vec<f32> = (0..ao.height)
                .flat_map(|y| (0..ao.width).map(move |x| (x, y)))
                .filter(|&(x, y)| geometry(x, y))
                .map(|(x, y)| ao.get(x, y))
                .collect();
            values.iter().sum::<f32>() / values.len() as f32
        };
        let bias = mean(&frame.ao) - mean(&full.ao);
        println!(
            "{name}: mean |level − full| {:.4}, mean |full(seed 2) − full| {:.4}, mean(level) − mean(full) {bias:+.4}",
            level_vs_full.mean_abs, seed_vs_seed.mean_abs
        );
        assert!(level_vs_full.mean_abs < seed_vs_seed.mean_abs, "{name}");
        assert!(bias.abs() <= 0.02, "{name}: {bias}");
    }
}

/// Variant `reference` on a step edge, counted from the noise tables alone: the authors'
/// ω = ±reflect(R2, R1), the first radius 1.5 · base, every hit weighing
/// 1.5 · (1 − smoothstep(1e−5, 1, Δ)), normalized by the samples that stay on the texture.
#[test]
fn reference_variant_on_a_step_edge() {
    let gpu = gpu();
    let (w, h, edge) = (64usize, 16usize, 32usize);
    let step = 0.2f32;
    let s = ChainSettings {
        line_ao: LineAoSettings {
            variant: LineAoVariant::Reference,
            s_r: 1,
            light_attenuation: false,
            // flat_view(64, 16): z_fit = 8 px per unit, so base = 4 · z / 8 / (1 − d) = 4 px along x
            // at z = 4, d = 0.5; along y a quarter of that (the authors' UV radius is anisotropic).
            reference_radius_px: 4.0,
            ..LineAoSettings::default()
        },
        ..ChainSettings::default()
    };
    let nd0 = nd_map(w, h, |x, _| if x >= edge { 0.5 - step } else { 0.5 });
    let zoom = Image::filled(w, h, 4.0f32);
    let (levels, gpu_ao) = line_ao_on(&gpu, &nd0, &zoom, &s, 0);
    assert_eq!(levels.len(), 1, "the reference variant needs no pyramid");
    let cpu_ao = cpu_line_ao(&levels, &zoom, &s, &view_of(&levels[0], 0));
    let (noise, samples) = (noise_tile(1), lineao::noise::sample_table(1, 1, 32, |_| 32));
    let weight = 1.5 * (1.0 - reference::hermite((step - 1e-5) / (1.0 - 1e-5)));
    let (base_x, base_y) = (1.5 * 4.0, 1.5 * 1.0);
    for y in 0..h {
        for x in 0..w {
            let r1 = Vec3::from_array(noise[(y % 64) * 64 + x % 64]);
            let (mut used, mut hits) = (0, 0);
            for r2 in &samples {
                let r2 = Vec3::from_array(*r2);
                let omega = r2 - 2.0 * r1.dot(r2) * r1;
                let ray = if omega.z > 0.0 { omega } else { -omega };
                let (at_x, at_y) = (x as f32 + 0.5 + ray.x * base_x, y as f32 + 0.5 - ray.y * base_y);
                if (0.0..=w as f32).contains(&at_x) && (0.0..=h as f32).contains(&at_y) {
                    used += 1;
                    hits += (x < edge && at_x.floor() >= edge as f32) as u32;
                }
            }
            let expected = weight * hits as f32 / used as f32;
            assert!(
                (cpu_ao.get(x, y) - expected).abs() < 1e-5,
                "CPU at ({x}, {y}): {} vs {expected}",
                cpu_ao.get(x, y)
            );
            let bound = weight / used as f32 + 1e-5;
            assert!((gpu_ao.get(x, y) - expected).abs() <= bound, "GPU at ({x}, {y}): {}", gpu_ao.get(x, y));
        }
    }
    assert!(cpu_ao.data.iter().any(|&a| a > 0.1), "the step must occlude");
}

#[test]
fn reference_variant_matches_its_cpu_reference_on_rendered_lines() {
    let gpu = gpu();
    let (positions, offsets) = polylines(120, 0.3);
    let (perspective, ortho) = cameras_for_polylines();
    let reference = |light_attenuation| LineAoSettings {
        variant: LineAoVariant::Reference,
        light_attenuation,
        ..LineAoSettings::default()
    };
    let cases = [
        // The authors' brain-lines strength: the composite's clamp(2.5 · ao) is their
        // clamp(1 − 2.5/s_r · Σ occ_l).
        (
            "perspective, light",
            perspective,
            ChainSettings { line_ao: reference(true), strength: 2.5, guard_max_px: 32, ..Default::default() },
        ),
        (
            "orthographic, no light",
            ortho,
            ChainSettings { line_ao: reference(false), guard_max_px: 32, ..Default::default() },
        ),
    ];
    for (name, cam, s) in cases {
        let frame = render(&gpu, &positions, &offsets, &cam, None, s.clone(), (240, 180));
        assert_eq!((frame.nd.len(), frame.guard), (1, 32), "{name}: no pyramid, the guard band is the cap");
        let cpu = cpu_line_ao(&frame.nd, &frame.zoom, &s, &frame.view);
        let stats = check_policy(&frame.ao, &cpu, &frame.nd[0], line_ao_reference_flip_bound(32))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("reference variant, {name}: {stats}");
        assert!(frame.ao.data.iter().filter(|&&a| a > 0.05).count() > 500, "{name}: too little occlusion");
        let expected = reference::composite(&frame.color, &frame.specular, &frame.ao, frame.guard, s.strength);
        for (out, exp) in frame.output.data.iter().zip(&expected.data) {
            assert!((0..3).all(|c| (out[c] - exp[c]).abs() < 1e-5), "{name}: composite {out:?} vs {exp:?}");
        }
    }
}

#[test]
fn chain_reports_gpu_time_per_pass() {
    let gpu = gpu();
    let (positions, offsets) = polylines(40, 0.7);
    let geometry = lineao::LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let (camera, _) = cameras_for_polylines();
    let has_timestamps = gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
    let variants = [(LineAoVariant::Paper, 4), (LineAoVariant::Reference, 3)];
    for (variant, passes) in variants {
        let s = ChainSettings { line_ao: LineAoSettings { variant, ..Default::default() }, ..Default::default() };
        let mut chain = lineao::AoChain::new(&gpu.device, common::OUTPUT_FORMAT, s).unwrap();
        assert_eq!(chain.set_timing(&gpu.device, &gpu.queue, true), has_timestamps);
        chain.resize(64, 48).unwrap();
        chain.prepare(&gpu.device, &gpu.queue, &camera, &geometry.bounds.unwrap()).unwrap();
        let output = lineao::targets::Target::output(&gpu.device, "test::output", (64, 48), common::OUTPUT_FORMAT);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        chain.encode(&mut encoder, &geometry, &output.view).unwrap();
        gpu.queue.submit([encoder.finish()]);
        let Some(times) = chain.pass_times(&gpu.device, true).unwrap() else {
            assert!(!has_timestamps);
            continue;
        };
        let names: Vec<_> = times.iter().map(|t| t.name).collect();
        assert_eq!(names.len(), passes, "{variant:?}: {names:?}");
        assert!(times.iter().all(|t| t.ms > 0.0 && t.ms < 10_000.0), "{variant:?}: {times:?}");
    }
}

/// The polled timings never wait: right after a submission they may say "not yet" (`None`),
/// and asking on, frame after frame, they return the times of a finished frame — with the
/// same spans as the blocking read.
#[test]
fn pass_times_can_be_polled_without_waiting() {
    let gpu = gpu();
    let (positions, offsets) = polylines(40, 0.7);
    let geometry = lineao::LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let (camera, _) = cameras_for_polylines();
    let mut chain = lineao::AoChain::new(&gpu.device, common::OUTPUT_FORMAT, ChainSettings::default()).unwrap();
    let timed = chain.set_timing(&gpu.device, &gpu.queue, true);
    if !gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
        // An adapter without timestamp queries (not lavapipe) has no timer: timing stays off and
        // polling says so at once.
        assert!(!timed);
        assert_eq!(chain.pass_times(&gpu.device, false).unwrap(), None);
        return;
    }
    assert!(timed);
    assert_eq!(chain.pass_times(&gpu.device, false).unwrap(), None, "nothing was submitted yet");
    chain.resize(64, 48).unwrap();
    let output = lineao::targets::Target::output(&gpu.device, "test::output", (64, 48), common::OUTPUT_FORMAT);
    let mut polled = None;
    for _ in 0..1000 {
        chain.prepare(&gpu.device, &gpu.queue, &camera, &geometry.bounds.unwrap()).unwrap();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        chain.encode(&mut encoder, &geometry, &output.view).unwrap();
        gpu.queue.submit([encoder.finish()]);
        if let Some(times) = chain.pass_times(&gpu.device, false).unwrap() {
            polled = Some(times);
            break;
        }
    }
    let polled = polled.expect("a finished frame's times within 1000 frames");
    // The next frame is timed again, and the blocking read waits for it.
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &geometry, &output.view).unwrap();
    gpu.queue.submit([encoder.finish()]);
    let blocking = chain.pass_times(&gpu.device, true).unwrap().unwrap();
    let names = |t: &[lineao::timing::PassTime]| t.iter().map(|t| t.name).collect::<Vec<_>>();
    assert_eq!(names(&polled), names(&blocking));
    assert_eq!(names(&polled), ["lines", "nd-pyramid", "lineao", "composite"]);
    assert!(polled.iter().all(|t| t.ms > 0.0 && t.ms < 10_000.0), "{polled:?}");
}
