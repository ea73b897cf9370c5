//! Crytek SSAO and its 4 × 4 blur: closed forms on CPU-written G-buffers, and the GPU against
//! the CPU reference on rendered lines (docs/reference.md's policy, bound 2/N).

mod common;

use common::{cameras_for_polylines, flat_view, gpu, is_geometry, polylines, render};
use lineao::method::ssao::Ssao;
use lineao::method::ssao::blur::SsaoBlur;
use lineao::readback::{read_f32, write_target};
use lineao::reference::{self, Image, NdImage, SsaoParams, ViewParams};
use lineao::targets::{FrameTargets, Target};
use lineao::verify::{check_policy, compare};
use lineao::{AoMethod, ChainSettings, Gpu, SsaoKernel, SsaoSettings, noise};

/// Runs SSAO and its blur alone on a G-buffer written from the CPU; returns (raw, blurred).
fn ssao_on(gpu: &Gpu, nd0: &NdImage, settings: &SsaoSettings, guard: u32) -> (Image<f32>, Image<f32>, SsaoParams) {
    let (d, q) = (&gpu.device, &gpu.queue);
    let (w, h) = (nd0.width as u32 - 2 * guard, nd0.height as u32 - 2 * guard);
    let targets = FrameTargets::new(d, w, h, guard, 1);
    let raw = Target::ao(d, "test::ssao_raw", targets.size);
    write_target(q, &targets.nd[0], nd0);
    let view = flat_view(w, h, guard);
    let mut ssao = Ssao::new(d, settings);
    ssao.resize(d, &targets, &raw);
    ssao.prepare(q, &targets, &view, settings);
    let mut blur = SsaoBlur::new(d);
    blur.resize(d, &targets, &raw);
    let mut encoder = d.create_command_encoder(&Default::default());
    ssao.encode(&mut encoder, &targets, None);
    blur.encode(&mut encoder, &targets, None);
    q.submit([encoder.finish()]);
    let params = SsaoParams {
        view: ViewParams::of(&view),
        radius: settings.radius_world,
        range: settings.range_world,
        noise_origin: [guard as i32; 2],
    };
    (read_f32(d, q, &raw).unwrap(), read_f32(d, q, &targets.ao).unwrap(), params)
}

fn reflect(k: [f32; 3], r: [f32; 3]) -> [f32; 3] {
    let dot = r[0] * k[0] + r[1] * k[1] + r[2] * k[2];
    [k[0] - 2.0 * dot * r[0], k[1] - 2.0 * dot * r[1], k[2] - 2.0 * dot * r[2]]
}

#[test]
fn a_plane_facing_the_camera_is_occluded_by_exactly_the_samples_behind_it() {
    let gpu = gpu();
    for (kernel, points) in [
        (SsaoKernel::Crytek, noise::ssao_kernel(3, 16)),
        (SsaoKernel::Sphere, lineao::sample_sets::vo_sphere_samples(16).unwrap().to_vec()),
    ] {
        let settings = SsaoSettings { samples: 16, radius_world: 0.05, range_world: 1.0, noise_seed: 3, kernel };
        a_plane_facing_the_camera(&gpu, &settings, &points);
    }
}

fn a_plane_facing_the_camera(gpu: &Gpu, settings: &SsaoSettings, kernel: &[[f32; 3]]) {
    let (w, h, guard) = (40usize, 32usize, 4u32);
    let nd0 = Image::filled(w, h, [0.0, 0.0, 1.0, 0.5]);
    let (raw, blurred, params) = ssao_on(gpu, &nd0, settings, guard);
    let cpu = reference::ssao(&nd0, kernel, &noise::ssao_noise(3), &params);
    let tile = noise::ssao_noise(3);
    let mut checked = 0;
    for y in 0..h {
        for x in 0..w {
            let r = tile[(y as i32 - guard as i32).rem_euclid(4) as usize * 4
                + (x as i32 - guard as i32).rem_euclid(4) as usize];
            let rotated: Vec<[f32; 3]> = kernel.iter().map(|&k| reflect(k, r)).collect();
            // A sample is occluded iff it lies behind the plane (z_view further away).
            if rotated.iter().any(|k| k[2].abs() < 1e-3) {
                continue; // on the plane up to rounding: not a closed-form case
            }
            let expected = rotated.iter().filter(|k| k[2] < 0.0).count() as f32 / 16.0;
            assert_eq!(raw.get(x, y), expected, "{:?}: GPU at ({x}, {y})", settings.kernel);
            assert_eq!(cpu.get(x, y), expected, "{:?}: CPU at ({x}, {y})", settings.kernel);
            checked += 1;
        }
    }
    assert!(checked > w * h / 2, "only {checked} pixels had no sample on the plane");
    // Every 4 × 4 window holds each rotation once: away from the edges the blur is the mean over
    // the 16 rotations, the same number everywhere.
    let mean: f32 =
        (0..4).flat_map(|y| (0..4).map(move |x| (x, y))).map(|(x, y)| cpu.get(x + 8, y + 8)).sum::<f32>() / 16.0;
    for y in 2..h - 1 {
        for x in 2..w - 1 {
            assert!((blurred.get(x, y) - mean).abs() < 1e-6, "blur at ({x}, {y}): {} vs {mean}", blurred.get(x, y));
        }
    }
    assert!(mean > 0.3 && mean < 0.7, "about half the sphere lies behind a plane: {mean}");
}

#[test]
fn blur_skips_the_background_and_keeps_a_constant() {
    let gpu = gpu();
    let (w, h) = (24usize, 20usize);
    // A background hole in the middle; SSAO of a plane is not constant, so write the raw occlusion directly.
    let nd0 = Image::from_fn(w, h, |x, y| {
        if (10..14).contains(&x) && (8..12).contains(&y) { [0.0; 4] } else { [0.0, 0.0, 1.0, 0.5] }
    });
    let (d, q) = (&gpu.device, &gpu.queue);
    let targets = FrameTargets::new(d, w as u32, h as u32, 0, 1);
    let raw = Target::ao(d, "test::ssao_raw", targets.size);
    write_target(q, &targets.nd[0], &nd0);
    write_target(q, &raw, &Image::from_fn(w, h, |x, y| if is_geometry(nd0.get(x, y)) { 0.25f32 } else { 0.9 }));
    let mut blur = SsaoBlur::new(d);
    blur.resize(d, &targets, &raw);
    let mut encoder = d.create_command_encoder(&Default::default());
    blur.encode(&mut encoder, &targets, None);
    q.submit([encoder.finish()]);
    let out = read_f32(d, q, &targets.ao).unwrap();
    for y in 0..h {
        for x in 0..w {
            let expected = if is_geometry(nd0.get(x, y)) { 0.25 } else { 0.0 };
            assert_eq!(out.get(x, y), expected, "({x}, {y})");
        }
    }
}

#[test]
fn gpu_matches_cpu_reference_on_rendered_lines() {
    let gpu = gpu();
    let (positions, offsets) = polylines(120, 0.3);
    let (perspective, ortho) = cameras_for_polylines();
    for (name, cam, samples, kernel) in [
        ("perspective, 16", perspective, 16, SsaoKernel::Crytek),
        ("orthographic, 12", ortho, 12, SsaoKernel::Crytek),
        ("perspective, 32", perspective, 32, SsaoKernel::Crytek),
        ("perspective, sphere set 12", perspective, 12, SsaoKernel::Sphere),
    ] {
        let ssao = SsaoSettings { samples, radius_world: 4.0, range_world: 6.0, noise_seed: 1, kernel };
        let s = ChainSettings { method: AoMethod::Ssao, ssao: ssao.clone(), ..Default::default() };
        let frame = render(&gpu, &positions, &offsets, &cam, None, s, (240, 180));
        assert!(frame.guard > 0, "{name}: the sphere reaches past the edge");
        let params = SsaoParams {
            view: ViewParams::of(&frame.view),
            radius: ssao.radius_world,
            range: ssao.range_world,
            noise_origin: [frame.guard as i32; 2],
        };
        let points = match kernel {
            SsaoKernel::Crytek => noise::ssao_kernel(1, samples),
            SsaoKernel::Sphere => lineao::sample_sets::vo_sphere_samples(samples).unwrap().to_vec(),
        };
        let cpu = reference::ssao(&frame.nd[0], &points, &noise::ssao_noise(1), &params);
        let stats = check_policy(&frame.ao_raw, &cpu, &frame.nd[0], 2.0 / samples as f32)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name}: {stats}");
        let occluded = frame.ao_raw.data.iter().filter(|&&a| a > 0.05).count();
        assert!(occluded > 1000, "{name}: only {occluded} occluded pixels");
        // The blur on exactly the GPU's raw SSAO.
        let blurred = reference::ssao_blur(&frame.nd[0], &frame.ao_raw);
        let stats = compare(&frame.ao, &blurred, 1e-5, |_, _| true);
        assert!(stats.fraction_within == 1.0, "{name}: blur {stats}");
    }
}
