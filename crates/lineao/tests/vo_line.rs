//! Volumetric Obscurance with line samples: the closed forms of the VO paper and CONTRACT.md
//! (a plane facing the camera is half obscured without the normal clamp and not at all with
//! it; a 90° crease leaves a quarter of the sphere free), and the GPU against the CPU reference
//! on rendered lines.

mod common;

use common::{cameras_for_polylines, flat_view, gpu, polylines, render};
use lineao::passes::vo_line::VoLine;
use lineao::reference::{self, Image, NdImage, ViewParams, VoParams, vo_line_sample};
use lineao::sample_sets::{VO_SAMPLE_COUNTS, vo_disk_samples};
use lineao::targets::FrameTargets;
use lineao::verify::{check_policy, read_f32, write_target};
use lineao::{AoMethod, ChainSettings, Gpu, VoSettings, noise};

/// Runs VO alone on a CPU-written G-buffer; returns the GPU's AO and the CPU reference's.
fn vo_on(gpu: &Gpu, nd0: &NdImage, zoom: &Image<f32>, settings: &VoSettings, guard: u32) -> (Image<f32>, Image<f32>) {
    let (d, q) = (&gpu.device, &gpu.queue);
    let (w, h) = (nd0.width as u32 - 2 * guard, nd0.height as u32 - 2 * guard);
    let targets = FrameTargets::new(d, w, h, guard, 1);
    write_target(q, &targets.nd[0], nd0);
    write_target(q, &targets.zoom, zoom);
    let view = flat_view(w, h, guard);
    let mut vo = VoLine::new(d, settings);
    vo.resize(d, &targets);
    vo.prepare(q, &targets, &view, settings);
    let mut encoder = d.create_command_encoder(&Default::default());
    vo.encode(&mut encoder, &targets, None);
    q.submit([encoder.finish()]);
    let params = VoParams {
        view: ViewParams::of(&view),
        radius: settings.radius_world,
        zoom_unit: 1.0,
        normal_clamp: settings.normal_clamp,
        thickness: settings.thickness_world,
        noise_origin: [guard as i32; 2],
    };
    let samples = vo_disk_samples(settings.samples).unwrap();
    let cpu = reference::vo_line(nd0, zoom, samples, &noise::vo_noise(settings.noise_seed), &params);
    (read_f32(d, q, &targets.ao).unwrap(), cpu)
}

#[test]
fn a_plane_facing_the_camera_is_half_obscured_and_not_at_all_with_the_normal_clamp() {
    let gpu = gpu();
    let nd0 = Image::filled(36, 28, [0.0, 0.0, 1.0, 0.5]);
    let zoom = Image::filled(36, 28, 3.0f32);
    for samples in VO_SAMPLE_COUNTS {
        for (clamp, expected) in [(false, 0.5f32), (true, 0.0)] {
            let settings = VoSettings { samples, radius_world: 2.0, normal_clamp: clamp, ..VoSettings::default() };
            let (gpu_ao, cpu_ao) = vo_on(&gpu, &nd0, &zoom, &settings, 4);
            for (g, c) in gpu_ao.data.iter().zip(&cpu_ao.data) {
                assert!((g - expected).abs() < 1e-6, "N = {samples}, clamp {clamp}: GPU {g}");
                assert!((c - expected).abs() < 1e-6, "N = {samples}, clamp {clamp}: CPU {c}");
            }
        }
    }
}

#[test]
fn line_integrals_of_the_chord() {
    // Fully free, fully occupied, half, and the thickness model's second free part.
    let up = [0.0, 0.0, 1.0];
    let z_s = (1.0f32 - 0.36).sqrt(); // s = (0.6, 0)
    assert_eq!(vo_line_sample([0.6, 0.0], 5.0, up, false, 0.0), (2.0 * z_s, 2.0 * z_s));
    assert_eq!(vo_line_sample([0.6, 0.0], -5.0, up, false, 0.0), (0.0, 2.0 * z_s));
    assert_eq!(vo_line_sample([0.6, 0.0], 0.0, up, false, 0.0), (z_s, 2.0 * z_s));
    let (free, allowed) = vo_line_sample([0.6, 0.0], 0.0, up, false, 0.3);
    assert!((free - (z_s + z_s - 0.3)).abs() < 1e-6 && allowed == 2.0 * z_s);
    // Normal clamp with a tilted normal: the plane's depth at s is (n_x s_x + n_y s_y) / n_z.
    let n = [0.6f32, 0.0, 0.8];
    let (free, allowed) = vo_line_sample([0.5, 0.0], 10.0, n, true, 0.0);
    let z = (1.0f32 - 0.25).sqrt();
    assert!((allowed - (0.3 / 0.8 + z)).abs() < 1e-6 && free == allowed);
}

#[test]
fn a_right_angled_crease_leaves_a_quarter_of_the_sphere_free() {
    // The exact integral: a V of two planes at ±45° (d_r = −|x|) leaves the 90° wedge in front
    // free. Integrated over a fine grid of line samples it is 1/4 of the volume ...
    let (mut free, mut allowed) = (0.0f64, 0.0f64);
    let n = 400;
    for j in 0..n {
        for i in 0..n {
            let s = [-1.0 + (i as f32 + 0.5) * 2.0 / n as f32, -1.0 + (j as f32 + 0.5) * 2.0 / n as f32];
            if s[0] * s[0] + s[1] * s[1] < 1.0 {
                let (f, a) = vo_line_sample(s, -s[0].abs(), [0.0, 0.0, 1.0], false, 0.0);
                free += f as f64;
                allowed += a as f64;
            }
        }
    }
    assert!((free / allowed - 0.25).abs() < 2e-3, "{}", free / allowed);
    // ... and every sample set estimates it, on the GPU as on the CPU, from a crease in a G-buffer.
    let gpu = gpu();
    let (w, h, guard, z_px) = (48usize, 24usize, 4u32, 6.0f32);
    let view = flat_view(w as u32 - 8, h as u32 - 8, guard);
    let v = ViewParams::of(&view);
    let centre = 24.0;
    let nd0 = Image::from_fn(w, h, |x, _| {
        let depth = 10.0 - ((x as f32 + 0.5) - centre).abs() / z_px;
        [0.0, 0.0, 1.0, (depth - v.near) / (v.far - v.near)]
    });
    let zoom = Image::filled(w, h, z_px);
    for samples in VO_SAMPLE_COUNTS {
        let settings = VoSettings { samples, radius_world: 1.5, normal_clamp: false, ..VoSettings::default() };
        let (gpu_ao, cpu_ao) = vo_on(&gpu, &nd0, &zoom, &settings, guard);
        for y in 8..16 {
            for x in [23usize, 24] {
                assert!((gpu_ao.get(x, y) - cpu_ao.get(x, y)).abs() < 1e-5, "N = {samples} at ({x}, {y})");
                assert!((cpu_ao.get(x, y) - 0.75).abs() < 0.12, "N = {samples}: {} at the crease", cpu_ao.get(x, y));
            }
        }
    }
}

#[test]
fn gpu_matches_cpu_reference_on_rendered_lines() {
    let gpu = gpu();
    let (positions, offsets) = polylines(120, 0.3);
    let (perspective, ortho) = cameras_for_polylines();
    let cases = [
        ("perspective, 9, clamp", perspective, VoSettings { radius_world: 4.0, ..VoSettings::default() }),
        (
            "perspective, 5, no clamp",
            perspective,
            VoSettings { samples: 5, radius_world: 4.0, normal_clamp: false, ..VoSettings::default() },
        ),
        (
            "orthographic, 16, thickness",
            ortho,
            VoSettings { samples: 16, radius_world: 4.0, thickness_world: 1.0, ..VoSettings::default() },
        ),
    ];
    for (name, cam, vo) in cases {
        let s = ChainSettings { method: AoMethod::VoLine, vo: vo.clone(), ..Default::default() };
        let frame = render(&gpu, &positions, &offsets, &cam, None, s, (240, 180));
        let params = VoParams {
            view: ViewParams::of(&frame.view),
            radius: vo.radius_world,
            zoom_unit: 1.0,
            normal_clamp: vo.normal_clamp,
            thickness: vo.thickness_world,
            noise_origin: [frame.guard as i32; 2],
        };
        let samples = vo_disk_samples(vo.samples).unwrap();
        let cpu = reference::vo_line(&frame.nd[0], &frame.zoom, samples, &noise::vo_noise(1), &params);
        let stats = check_policy(&frame.ao, &cpu, &frame.nd[0], 2.0 / vo.samples as f32)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name}: {stats}");
        let occluded = frame.ao.data.iter().filter(|&&a| a > 0.05).count();
        assert!(occluded > 1000, "{name}: only {occluded} obscured pixels");
    }
}

#[test]
fn the_checked_in_sample_sets_are_what_the_generator_writes() {
    for n in VO_SAMPLE_COUNTS {
        let generated = lineao::sample_sets::generate_vo_disk_samples(n);
        let table = vo_disk_samples(n).unwrap();
        assert_eq!(generated.len(), n as usize);
        for (g, t) in generated.iter().zip(table) {
            assert!((0..3).all(|k| (g[k] - t[k]).abs() <= 1e-6 * t[k].abs().max(1.0)), "N = {n}: {g:?} vs {t:?}");
        }
        // Inside the disk, weights positive, Σ A_i · 2 z_s = the unit sphere's volume.
        let volume: f32 = table.iter().map(|s| s[2] * 2.0 * (1.0 - s[0] * s[0] - s[1] * s[1]).sqrt()).sum();
        assert!((volume - 4.0 / 3.0 * std::f32::consts::PI).abs() < 1e-4, "N = {n}: {volume}");
        assert!(table.iter().all(|s| s[0].hypot(s[1]) < 1.0 && s[2] > 0.0));
    }
}
