//! The guard band (docs/reference.md, paper §3.4): AO at the viewport's edge must not fade. An edge
//! pixel's AO with the guard band must equal the AO of the same pixel when it sits in the middle
//! of a larger render of the same view (same focal length, pixel grid and noise phase).

mod common;

use common::{Frame, gpu, line_ao_on, render_geometry};
use glam::Vec3;
use lineao::LineGeometry;
use lineao::reference::Image;
use lineao::reference::line_ao_flip_bound;
use lineao::{Camera, Projection};
use lineao::{ChainSettings, Gpu, LineAoSettings};

/// Dense random-walk polylines filling a cube of side 100 around the origin.
fn dense_lines() -> (Vec<[f32; 3]>, Vec<u64>) {
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    let mut h = 1u32;
    let mut rand = || {
        h = lineao::noise::pcg_hash(h);
        h as f32 / u32::MAX as f32 - 0.5
    };
    for _ in 0..300 {
        let mut p = Vec3::new(100.0 * rand(), 100.0 * rand(), 100.0 * rand());
        let dir = Vec3::new(rand(), rand(), rand()).normalize_or(Vec3::X);
        for _ in 0..40 {
            positions.push(p.to_array());
            p += 1.5 * (dir + 0.5 * Vec3::new(rand(), rand(), rand()));
        }
        offsets.push(positions.len() as u64);
    }
    (positions, offsets)
}

/// Margin of the larger render on each side: a multiple of the 64-pixel noise tile and of the
/// pyramid's 2^(s_r−1), so noise and pyramid texels line up with the smaller render's.
const MARGIN: u32 = 64;

fn render(gpu: &Gpu, geometry: &LineGeometry, camera: Camera, settings: &ChainSettings, size: (u32, u32)) -> Frame {
    let bounds = geometry.bounds.unwrap();
    render_geometry(gpu, geometry, &camera, bounds, settings.clone(), size)
}

/// How the AO of the small render's visible pixels compares with the same pixels of the large
/// render, over the band of `band` pixels along the edge.
struct Edge {
    /// Worst |Δ| in the band.
    worst: f32,
    /// Fraction of the band within 1e-6 (equal up to f32 rounding) and within 1e-3.
    equal: f64,
    close: f64,
}

fn edge_band(small: &Frame, small_ao: &Image<f32>, large: &Frame, (w, h): (usize, usize), band: usize) -> Edge {
    let m = MARGIN as usize;
    let (mut worst, mut equal, mut close, mut count) = (0.0f32, 0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            if x >= band && y >= band && x + band < w && y + band < h {
                continue;
            }
            let d = (small_ao.get(x + small.guard, y + small.guard)
                - large.ao.get(x + m + large.guard, y + m + large.guard))
            .abs();
            worst = worst.max(d);
            equal += (d <= 1e-6) as usize;
            close += (d <= 1e-3) as usize;
            count += 1;
        }
    }
    Edge { worst, equal: equal as f64 / count as f64, close: close as f64 / count as f64 }
}

#[test]
fn edge_pixels_see_what_a_larger_render_sees() {
    let gpu = gpu();
    let (positions, offsets) = dense_lines();
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let (w, h) = (96u32, 80u32);
    let fov = 30.0f32;
    // The larger render: the same focal length in pixels over a larger image.
    let wide_fov = 2.0 * ((fov.to_radians() / 2.0).tan() * (h + 2 * MARGIN) as f32 / h as f32).atan().to_degrees();
    let camera = |fov_y_deg| Camera {
        eye: Vec3::new(10.0, -20.0, 170.0),
        target: Vec3::new(0.0, 0.0, 0.0),
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg },
    };
    // Variant `paper` only: the reference variant's radius grows without bound toward the far
    // plane (1/(1 − d)) and with the viewport (UV units), so no finite guard band makes it exact.
    for (s_r, line_width_px) in [(3, 2.0), (2, 5.0)] {
        let settings = ChainSettings {
            line_ao: LineAoSettings { s_r, ..Default::default() },
            line_width_px,
            ..Default::default()
        };
        let name = format!("s_r {s_r}, {line_width_px} px lines");
        let bound = line_ao_flip_bound(s_r, settings.line_ao.s_h);
        let size = (w as usize, h as usize);
        let small = render(&gpu, &geometry, camera(fov), &settings, (w, h));
        let large = render(&gpu, &geometry, camera(wide_fov), &settings, (w + 2 * MARGIN, h + 2 * MARGIN));
        let cap = settings.guard_max_px as usize;
        assert!(small.guard > 0 && small.guard < cap, "{name}: the guard band {} must not be capped", small.guard);
        let occluded = (0..w as usize).filter(|&x| small.ao.get(x + small.guard, small.guard) > 0.05).count();
        assert!(occluded > 10, "{name}: the top edge must be occluded somewhere ({occluded} px)");

        // End to end: two rasterizations of the same view differ in the last bits of depth (and
        // a rare pixel of coverage), which can flip a sample whose Δd sits at ε — docs/reference.md's
        // agreement policy.
        let e2e = edge_band(&small, &small.ao, &large, size, 8);
        println!(
            "{name}: guard {} px; edge band vs larger render: {:.2} % within 1e-3, worst {:.2e}",
            small.guard,
            100.0 * e2e.close,
            e2e.worst
        );
        assert!(e2e.close >= 0.995 && e2e.worst <= bound, "{name}: edge band differs: {:.4} {}", e2e.close, e2e.worst);

        // The same G-buffer: the larger render's ND and zoom maps cut to the smaller render's
        // guard-banded window, through the pyramid and LineAO alone. Only f32 rounding of the
        // absolute sample addresses may differ (a sample exactly on a texel border).
        let shift = MARGIN as usize + large.guard - small.guard;
        let (cw, ch) = (small.nd[0].width, small.nd[0].height);
        let nd0 = Image::from_fn(cw, ch, |x, y| large.nd[0].get(x + shift, y + shift));
        let zoom = Image::from_fn(cw, ch, |x, y| large.zoom.get(x + shift, y + shift));
        let (_, cut_ao) = line_ao_on(&gpu, &nd0, &zoom, &settings, small.guard as u32);
        let cut = edge_band(&small, &cut_ao, &large, size, 8);
        println!(
            "{name}: same G-buffer cut to the band: {:.2} % of the edge band equal, worst {:.2e}",
            100.0 * cut.equal,
            cut.worst
        );
        assert!(
            cut.equal >= 0.99 && cut.worst <= bound,
            "{name}: the band loses what samples read: {:.4} {}",
            cut.equal,
            cut.worst
        );

        // Without the guard band the edge differs: the comparison can tell.
        let unguarded = ChainSettings { guard_max_px: 0, ..settings.clone() };
        let bare = render(&gpu, &geometry, camera(fov), &unguarded, (w, h));
        assert_eq!(bare.guard, 0);
        let bare = edge_band(&bare, &bare.ao, &large, size, 8);
        println!("{name}: without a guard band: {:.2} % of the edge band within 1e-3", 100.0 * bare.close);
        assert!(bare.close < 0.9, "{name}: without a guard band the edge should differ: {:.4}", bare.close);
    }
}
