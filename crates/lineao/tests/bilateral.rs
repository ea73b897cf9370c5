//! The bilateral blur: closed forms on a CPU-written G-buffer (a step of occlusion on one plane
//! blurs by the normalized Gaussian; across a depth edge nothing bleeds) and the GPU against
//! the CPU reference after every method on rendered lines.

mod common;

use common::{cameras_for_polylines, flat_view, gpu, polylines, render};
use lineao::passes::bilateral::Bilateral;
use lineao::readback::{read_f32, write_target};
use lineao::reference::{self, Image, ViewParams};
use lineao::targets::FrameTargets;
use lineao::verify::check_policy;
use lineao::{AoMethod, BilateralSettings, ChainSettings, Gpu};

/// Runs the blur alone over `ao` on the G-buffer `nd0` (no guard band); returns the GPU's
/// result and the CPU reference's.
fn blur_on(
    gpu: &Gpu,
    nd0: &Image<[f32; 4]>,
    ao: &Image<f32>,
    settings: &BilateralSettings,
) -> (Image<f32>, Image<f32>) {
    let (d, q) = (&gpu.device, &gpu.queue);
    let view = flat_view(nd0.width as u32, nd0.height as u32, 0);
    let targets = FrameTargets::new(d, view.width, view.height, 0, 1).with_blur(d);
    write_target(q, &targets.nd[0], nd0);
    write_target(q, &targets.ao, ao);
    let mut blur = Bilateral::new(d);
    blur.resize(d, &targets);
    blur.prepare(q, &view, settings, lineao::passes::bilateral::Region::All);
    let mut encoder = d.create_command_encoder(&Default::default());
    blur.encode(&mut encoder, &targets, None);
    q.submit([encoder.finish()]);
    let cpu = reference::bilateral(ao, nd0, &ViewParams::of(&view), settings);
    (read_f32(d, q, targets.ao_blurred.as_ref().unwrap()).unwrap(), cpu)
}

#[test]
fn a_step_on_one_plane_blurs_by_the_gaussian_and_nothing_crosses_a_depth_edge() {
    let gpu = gpu();
    let (w, h, edge) = (40usize, 12usize, 20usize);
    let settings = BilateralSettings { radius_px: 4, depth_sigma_world: 0.05 };
    let ao = Image::from_fn(w, h, |x, _| if x < edge { 1.0 } else { 0.0 });
    // One plane: the value at x is the share of the normalized Gaussian (σ = 2 px) left of the
    // edge, truncated at ±4 and at the image's border.
    let plane = Image::filled(w, h, [0.0, 0.0, 1.0, 0.5]);
    let (gpu_ao, cpu_ao) = blur_on(&gpu, &plane, &ao, &settings);
    let g = |k: i64| (-(k * k) as f64 / 8.0).exp();
    for x in 10..30 {
        let (left, all): (f64, f64) = (-4i64..=4)
            .map(|k| (x as i64 + k, g(k)))
            .filter(|&(s, _)| (0..w as i64).contains(&s))
            .fold((0.0, 0.0), |(l, a), (s, wk)| (l + if s < edge as i64 { wk } else { 0.0 }, a + wk));
        let expected = (left / all) as f32;
        for y in 0..h {
            assert!(
                (gpu_ao.get(x, y) - expected).abs() < 1e-5,
                "GPU at ({x}, {y}): {} vs {expected}",
                gpu_ao.get(x, y)
            );
            assert!(
                (cpu_ao.get(x, y) - expected).abs() < 1e-5,
                "CPU at ({x}, {y}): {} vs {expected}",
                cpu_ao.get(x, y)
            );
        }
    }
    // The right half 10 σ_z behind the left (in normalized depth of the view's range): no
    // occlusion bleeds over, none leaks back.
    let v = ViewParams::of(&flat_view(w as u32, h as u32, 0));
    let behind = 0.5 + 0.5 / (v.far - v.near);
    let step = Image::from_fn(w, h, |x, _| [0.0, 0.0, 1.0, if x < edge { 0.5 } else { behind }]);
    let (gpu_ao, cpu_ao) = blur_on(&gpu, &step, &ao, &settings);
    for y in 0..h {
        for x in 0..w {
            let expected = if x < edge { 1.0 } else { 0.0 };
            assert!((gpu_ao.get(x, y) - expected).abs() < 1e-6 && (cpu_ao.get(x, y) - expected).abs() < 1e-6);
        }
    }
}

#[test]
fn gpu_matches_cpu_reference_after_every_method() {
    let gpu = gpu();
    let (positions, offsets) = polylines(120, 0.3);
    let (perspective, ortho) = cameras_for_polylines();
    let blur = BilateralSettings { radius_px: 5, depth_sigma_world: 2.0 };
    for (method, cam) in [
        (AoMethod::LineAo, perspective),
        (AoMethod::Ssao, ortho),
        (AoMethod::VoLine, perspective),
        (AoMethod::VoArea, ortho),
    ] {
        let s = ChainSettings { method, blur: Some(blur.clone()), ..Default::default() };
        let frame = render(&gpu, &positions, &offsets, &cam, None, s, (200, 160));
        let cpu = reference::bilateral(&frame.ao, &frame.nd[0], &ViewParams::of(&frame.view), &blur);
        let stats =
            check_policy(&frame.ao_blurred, &cpu, &frame.nd[0], 1e-4).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        println!("{method:?}: {stats}");
        // It did blur, and what the composite shows is the blurred occlusion.
        let changed = frame.ao.data.iter().zip(&frame.ao_blurred.data).filter(|(a, b)| (*a - *b).abs() > 0.01).count();
        assert!(changed > 500, "{method:?}: only {changed} pixels changed");
    }
}
