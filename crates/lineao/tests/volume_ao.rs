//! Object-space AO over a density volume: the geometry term in closed form, the analytic cases
//! of the issue (closed shell, flat slab, bundle against an isolated line), and both methods
//! against the Monte-Carlo reference.

use std::f32::consts::PI;

use glam::Vec3;
use lineao::volume::density::{DensityOptions, DensityVolume, voxelize};
use lineao::volume::geometry_term::{self, GeometryTable, TABLE_SIZE};
use lineao::volume::sweep::{self, SweepSettings};
use lineao::volume::variance::{self, VarianceMaps, VarianceSettings};
use lineao::volume::{ScalarForm, Sky, VolumeGrid, monte_carlo, octant_signs, scalar_visibility, vertex_tangents};

fn random_unit(k: u32) -> Vec3 {
    Vec3::from_array(lineao::noise::unit_vector(7, 3, k))
}

#[test]
fn the_geometry_term_sums_to_pi_and_matches_quadrature() {
    for k in 0..200 {
        let n = random_unit(k);
        let g = geometry_term::octant_integrals(n);
        let sum: f32 = g.iter().sum();
        assert!((sum - PI).abs() < 1e-4, "{n}: Σ G = {sum}");
        for (o, &g) in g.iter().enumerate() {
            let s = octant_signs(o);
            // An octant wholly above the horizon: ∫ N·ω dω = N · (π/4) σ.
            if (0..3).all(|a| n[a] * s[a] >= 0.0) {
                assert!((g - PI / 4.0 * n.dot(s)).abs() < 1e-5, "{n} octant {o}: {g}");
            }
            assert!(g >= 0.0);
        }
    }
    // Midpoint quadrature over (z, φ) in every octant, for a few normals.
    let steps = 400;
    for n in [Vec3::new(0.3, -0.5, 0.81).normalize(), Vec3::new(-0.9, 0.1, -0.2).normalize(), Vec3::Z] {
        for o in 0..8 {
            let s = octant_signs(o);
            let mut sum = 0.0f64;
            for i in 0..steps {
                for j in 0..steps {
                    let z = (i as f64 + 0.5) / steps as f64;
                    let phi = 0.5 * std::f64::consts::PI * (j as f64 + 0.5) / steps as f64;
                    let r = (1.0 - z * z).sqrt();
                    let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32) * s;
                    sum += n.dot(w).max(0.0) as f64;
                }
            }
            let quadrature = sum * (std::f64::consts::PI / 2.0) / (steps * steps) as f64;
            let closed = geometry_term::octant_integral(o, n) as f64;
            assert!((quadrature - closed).abs() < 2e-3, "{n} octant {o}: {closed} vs {quadrature}");
        }
    }
}

#[test]
fn the_lookup_tables_stay_close_to_the_closed_form() {
    let normals = GeometryTable::normals(TABLE_SIZE);
    let tangents = GeometryTable::around_tangent(TABLE_SIZE);
    let (mut worst_n, mut worst_t) = (0.0f32, 0.0f32);
    for k in 0..2000 {
        let n = random_unit(k);
        let exact = geometry_term::octant_integrals(n);
        let table = normals.lookup(n);
        worst_n = (0..8).map(|o| (exact[o] - table[o]).abs()).fold(worst_n, f32::max);
        let exact = geometry_term::around_tangent(n, 256);
        let table = tangents.lookup(n);
        worst_t = (0..8).map(|o| (exact[o] - table[o]).abs()).fold(worst_t, f32::max);
    }
    println!("table error: normals {worst_n:.5}, tangents {worst_t:.5} (π = 3.14159)");
    assert!(worst_n < 0.01 * PI && worst_t < 0.01 * PI, "{worst_n} {worst_t}");
}

/// An empty grid of n³ voxels of edge 1 from the origin.
fn empty(n: usize) -> DensityVolume {
    let grid = VolumeGrid { dims: [n; 3], origin: Vec3::ZERO, voxel: 1.0 };
    DensityVolume { grid, occupancy: vec![0.0; grid.len()], radius: 0.0 }
}

fn fill(volume: &mut DensityVolume, inside: impl Fn(usize, usize, usize) -> bool) {
    let [nx, ny, nz] = volume.grid.dims;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                if inside(x, y, z) {
                    let i = volume.grid.index(x, y, z);
                    volume.occupancy[i] = 1.0;
                }
            }
        }
    }
}

#[test]
fn a_vertex_inside_a_closed_shell_is_fully_occluded() {
    let mut volume = empty(32);
    // A hollow cube: voxels 8..24 on each axis, walls one voxel thick.
    fill(&mut volume, |x, y, z| {
        let inside = |c: usize| (8..24).contains(&c);
        inside(x) && inside(y) && inside(z) && [x, y, z].iter().any(|&c| c == 8 || c == 23)
    });
    let centre = [[16.0, 16.0, 16.0], [10.2, 21.7, 12.5]];
    let v = sweep::octant_visibility(&volume, &centre, &[Vec3::X; 2], &SweepSettings::default()).unwrap();
    assert!(v.iter().flatten().all(|&v| v == 0.0), "{v:?}");
    let mc = monte_carlo::octant_visibility(&volume, &centre, &[Vec3::X; 2], 64, 1);
    assert!(mc.iter().flatten().all(|&v| v == 0.0), "{mc:?}");
    // Outside the shell, the sky is open on the far side.
    let outside =
        sweep::octant_visibility(&volume, &[[4.0, 16.0, 16.0]], &[Vec3::Z], &SweepSettings::default()).unwrap()[0];
    assert!(outside.iter().cloned().fold(0.0, f32::max) > 0.9, "{outside:?}");
}

#[test]
fn a_point_on_a_large_slab_facing_away_is_lit_and_sees_half_the_sky_without_the_term() {
    // An occupied slab z < 20 of a 96 × 96 × 48 grid; the point one voxel above its top.
    let grid = VolumeGrid { dims: [96, 96, 48], origin: Vec3::ZERO, voxel: 1.0 };
    let mut volume = DensityVolume { grid, occupancy: vec![0.0; grid.len()], radius: 0.0 };
    fill(&mut volume, |_, _, z| z < 20);
    let p = [[48.0, 48.0, 21.0]];
    let v = sweep::octant_visibility(&volume, &p, &[Vec3::ZERO], &SweepSettings::default()).unwrap()[0];
    let up = geometry_term::octant_integrals(Vec3::Z);
    let lit = geometry_term::weighted_visibility(&v, &up, &[1.0; 8]);
    let without = scalar_visibility(&[v], &[Vec3::X], ScalarForm::NoGeometryTerm, &Sky::Uniform)[0];
    println!("slab: with G {lit:.6}, without {without:.6}, octants {v:?}");
    assert!((lit - 1.0).abs() < 1e-4, "{lit}");
    assert!((without - 0.5).abs() < 1e-4, "{without}");
    // The Monte-Carlo reference agrees octant by octant (but for a grazing ray or two that
    // leaves the finite slab's grid sideways).
    let mc = monte_carlo::octant_visibility(&volume, &p, &[Vec3::ZERO], 64, 1)[0];
    for o in 0..8 {
        let expected = if octant_signs(o).z > 0.0 { 1.0 } else { 0.0 };
        assert!((mc[o] - expected).abs() < 0.05 && (v[o] - expected).abs() < 1e-4, "octant {o}: {mc:?} {v:?}");
    }
    // A cloudy sky (the four octants above) changes nothing for this normal.
    let cloudy = geometry_term::weighted_visibility(&v, &up, &Sky::Cloudy.weights());
    assert!((cloudy - lit).abs() < 1e-6);
}

#[test]
fn translucency_lets_light_through() {
    let mut volume = empty(40);
    fill(&mut volume, |_, _, z| z == 30);
    let below = [[20.0, 20.0, 25.0]];
    let top = |volume: &DensityVolume, alpha: f32| {
        let v = sweep::octant_visibility(volume, &below, &[Vec3::X], &SweepSettings { alpha, threads: 1 }).unwrap()[0];
        v[0]
    };
    // An opaque plate blocks the octants above (but for light entering sideways under it, at
    // the grid's edge); with α = 0.25 each voxel passes 1 − α = 0.75.
    let (opaque, translucent) = (top(&volume, 1.0), top(&volume, 0.25));
    println!("full plate above: V = {opaque:.4} (α = 1), {translucent:.4} (α = 0.25)");
    assert!(opaque < 0.01 && translucent > 0.5, "{opaque} {translucent}");
    // Light from behind a thin plate, for a point on its far side, grows as α falls.
    let steps: Vec<f32> = [1.0, 0.75, 0.5, 0.25].iter().map(|&a| top(&volume, a)).collect();
    assert!(steps.windows(2).all(|w| w[0] < w[1]), "{steps:?}");
    assert!(SweepSettings { alpha: 0.0, threads: 0 }.validate().is_err());
}

/// Straight streamlines along z at the given (x, y), 0.5 mm steps over 40 mm.
fn streamlines(columns: &[(f32, f32)]) -> (Vec<[f32; 3]>, Vec<u64>) {
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    for &(x, y) in columns {
        positions.extend((0..=80).map(|k| [x, y, k as f32 * 0.5]));
        offsets.push(positions.len() as u64);
    }
    (positions, offsets)
}

#[test]
fn vertices_in_a_dense_bundle_are_more_occluded_than_an_isolated_line() {
    // A 12 × 12 bundle at 1.2 mm spacing, and one line 30 mm away; radius 0.5 mm.
    let mut columns: Vec<(f32, f32)> = (0..144).map(|k| ((k % 12) as f32 * 1.2, (k / 12) as f32 * 1.2)).collect();
    columns.push((40.0, 6.6));
    let (positions, offsets) = streamlines(&columns);
    let options = DensityOptions { resolution: 128, occupancy_radius: 0.5, threads: 0 };
    let volume = voxelize(&positions, &offsets, &options).unwrap();
    // Middle vertices (z = 20) of the bundle's central line and of the isolated line.
    let pick = |(x, y): (f32, f32)| [x, y, 20.0];
    let probes = [pick((6.0, 6.0)), pick((40.0, 6.6))];
    let tangents = [Vec3::Z; 2];
    let sweep = sweep::octant_visibility(&volume, &probes, &tangents, &SweepSettings::default()).unwrap();
    let maps = VarianceMaps::new(&volume, &VarianceSettings::default()).unwrap();
    let variance = maps.octant_visibility(&volume, &probes, &tangents, 0).unwrap();
    let mc = monte_carlo::octant_visibility(&volume, &probes, &tangents, 256, 3);
    for (name, v) in [("sweep", &sweep), ("variance", &variance), ("monte carlo", &mc)] {
        let vis = scalar_visibility(v, &tangents, ScalarForm::AroundTangent, &Sky::Uniform);
        let (bundle, isolated) = (1.0 - vis[0], 1.0 - vis[1]);
        println!("{name}: ao in the bundle {bundle:.3}, isolated {isolated:.3}, ratio {:.1}", bundle / isolated);
        assert!(bundle > 0.5 && bundle > 3.0 * isolated, "{name}: {bundle} vs {isolated}");
    }
}

/// Crossing bundles of wavy streamlines: a tractogram-like test volume.
fn crossing_bundles() -> (Vec<[f32; 3]>, Vec<u64>) {
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    for b in 0..3 {
        let axis = [Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.6).normalize()][b];
        let (u, w) = axis.any_orthonormal_pair();
        for k in 0..60u32 {
            let spread = if b == 2 { 2.0 } else { 6.0 };
            let offset = (u * (lineao::noise::uniform(5, b as u32, k) - 0.5)
                + w * (lineao::noise::uniform(6, b as u32, k) - 0.5))
                * 2.0
                * spread;
            for s in 0..=100 {
                let t = (s as f32 - 50.0) * 0.4;
                let wave = u * (0.8 * (t * 0.3 + k as f32).sin());
                positions.push((offset + axis * t + wave).to_array());
            }
            offsets.push(positions.len() as u64);
        }
    }
    (positions, offsets)
}

#[test]
fn both_methods_against_the_monte_carlo_reference() {
    let (positions, offsets) = crossing_bundles();
    let volume =
        voxelize(&positions, &offsets, &DensityOptions { resolution: 64, occupancy_radius: 0.5, threads: 0 }).unwrap();
    // Every 37th vertex.
    let probes: Vec<[f32; 3]> = positions.iter().step_by(37).copied().collect();
    let tangents: Vec<Vec3> = vertex_tangents(&positions, &offsets).into_iter().step_by(37).collect();
    let mc = monte_carlo::octant_visibility(&volume, &probes, &tangents, 144, 9);
    let sweep = sweep::octant_visibility(&volume, &probes, &tangents, &SweepSettings::default()).unwrap();
    let maps = VarianceMaps::new(&volume, &VarianceSettings::default()).unwrap();
    let variance = maps.octant_visibility(&volume, &probes, &tangents, 0).unwrap();
    let reference = scalar_visibility(&mc, &tangents, ScalarForm::AroundTangent, &Sky::Uniform);
    for (name, v, mean_bound, correlation_bound) in [("sweep", &sweep, 0.04, 0.95), ("variance", &variance, 0.07, 0.88)]
    {
        let ours = scalar_visibility(v, &tangents, ScalarForm::AroundTangent, &Sky::Uniform);
        let stats = Stats::new(&ours, &reference);
        println!(
            "{name} vs Monte Carlo ({} vertices): mean |Δ| {:.3}, bias {:+.3}, max |Δ| {:.3}, correlation {:.3}; \
             per octant mean |Δ| {:.3}",
            probes.len(),
            stats.mean_abs,
            stats.bias,
            stats.max_abs,
            stats.correlation,
            Stats::new(&v.concat(), &mc.concat()).mean_abs
        );
        assert!(stats.mean_abs < mean_bound && stats.correlation > correlation_bound, "{name}: {stats:?}");
    }
}

#[derive(Debug)]
struct Stats {
    mean_abs: f32,
    bias: f32,
    max_abs: f32,
    correlation: f32,
}

impl Stats {
    fn new(a: &[f32], b: &[f32]) -> Stats {
        let n = a.len() as f32;
        let diff: Vec<f32> = a.iter().zip(b).map(|(a, b)| a - b).collect();
        let (ma, mb) = (a.iter().sum::<f32>() / n, b.iter().sum::<f32>() / n);
        let cov: f32 = a.iter().zip(b).map(|(a, b)| (a - ma) * (b - mb)).sum();
        let va: f32 = a.iter().map(|a| (a - ma).powi(2)).sum();
        let vb: f32 = b.iter().map(|b| (b - mb).powi(2)).sum();
        Stats {
            mean_abs: diff.iter().map(|d| d.abs()).sum::<f32>() / n,
            bias: diff.iter().sum::<f32>() / n,
            max_abs: diff.iter().map(|d| d.abs()).fold(0.0, f32::max),
            correlation: cov / (va * vb).sqrt(),
        }
    }
}

#[test]
fn the_sweep_does_not_depend_on_the_thread_count() {
    let (positions, offsets) = crossing_bundles();
    let volume =
        voxelize(&positions, &offsets, &DensityOptions { resolution: 48, occupancy_radius: 0.5, threads: 0 }).unwrap();
    let tangents = vertex_tangents(&positions, &offsets);
    let one =
        sweep::octant_visibility(&volume, &positions, &tangents, &SweepSettings { alpha: 1.0, threads: 1 }).unwrap();
    let three =
        sweep::octant_visibility(&volume, &positions, &tangents, &SweepSettings { alpha: 1.0, threads: 3 }).unwrap();
    assert_eq!(one, three);
}

#[test]
fn chebyshev_is_exact_for_two_values_and_soft_shadows_fall_behind_occluders() {
    // Two-valued regions: a fraction p at 1, the rest at 0 → μ = p, E[x²] = p, bound = p at t = 1.
    for p in [0.1f32, 0.3, 0.7] {
        assert!((variance::chebyshev(p, p, 1.0) - p).abs() < 1e-6);
    }
    assert_eq!(variance::chebyshev(0.6, 0.4, 0.5), 1.0);
    // A block at z = 36..48 over the middle of the grid: below it, toward +z, is shadow.
    let mut volume = empty(64);
    fill(&mut volume, |x, y, z| (20..44).contains(&x) && (20..44).contains(&y) && (36..48).contains(&z));
    let maps = VarianceMaps::new(&volume, &VarianceSettings::default()).unwrap();
    let under = maps.shadow(Vec3::new(32.0, 32.0, 20.0), Vec3::Z);
    let beside = maps.shadow(Vec3::new(6.0, 6.0, 20.0), Vec3::Z);
    println!("shadow transmittance under the plate {under:.3}, beside it {beside:.3}");
    assert!(under < 0.3 && beside > 0.8, "{under} {beside}");
    // Inside a solid block everything is occluded.
    let mut solid = empty(48);
    fill(&mut solid, |x, y, z| [x, y, z].iter().all(|c| (8..40).contains(c)));
    let maps = VarianceMaps::new(&solid, &VarianceSettings::default()).unwrap();
    let inside = maps.octant_visibility(&solid, &[[24.0, 24.0, 24.0]], &[Vec3::X], 1).unwrap();
    assert!(inside[0].iter().all(|&v| v == 0.0), "{inside:?}");
}

mod common;

use common::{Frame, cameras_for_polylines, gpu, is_geometry, polylines, polylines_with_octants, render_geometry};
use lineao::Camera;
use lineao::LineGeometry;
use lineao::passes::lines::{GeometryOptions, VertexAttributes};
use lineao::passes::volume_ao::view_to_world;
use lineao::reference::{self, Image};
use lineao::verify::compare;
use lineao::{AoMethod, ChainSettings, VoCombine, VolumeAoSettings};

/// A chain frame with object-space AO (the geometry's attributes), every target read back.
fn render_volume(
    gpu: &lineao::Gpu,
    geometry: &LineGeometry,
    camera: &Camera,
    settings: ChainSettings,
    size: (u32, u32),
) -> Frame {
    let frame = render_geometry(gpu, geometry, camera, geometry.bounds.unwrap(), settings, size);
    assert!(frame.octants.is_some() && frame.volume_ao.is_some(), "object-space AO is on");
    frame
}

/// Polylines with octant visibilities from the sweep over their own density volume.
fn swept_polylines(gpu: &lineao::Gpu, options: GeometryOptions) -> (LineGeometry, Vec<[f32; 8]>) {
    let (positions, offsets) = polylines(40, 0.3);
    let volume =
        voxelize(&positions, &offsets, &DensityOptions { resolution: 48, occupancy_radius: 1.5, threads: 0 }).unwrap();
    let tangents = vertex_tangents(&positions, &offsets);
    let octants = sweep::octant_visibility(&volume, &positions, &tangents, &SweepSettings::default()).unwrap();
    let mut geometry = LineGeometry::with_options(&gpu.device, &gpu.queue, &positions, &offsets, options).unwrap();
    let attributes = VertexAttributes { octants: Some(&octants), ..Default::default() };
    geometry.set_attributes(&gpu.device, &gpu.queue, &attributes).unwrap();
    (geometry, octants)
}

#[test]
fn the_gpu_agrees_with_the_cpu_reference_on_rendered_lines() {
    let gpu = gpu();
    let (geometry, octants) = swept_polylines(&gpu, GeometryOptions::default());
    let table = GeometryTable::normals(TABLE_SIZE);
    let (perspective, orthographic) = cameras_for_polylines();
    for (name, camera, sky, method, combine) in [
        ("perspective, open sky, alone", perspective, Sky::Uniform, AoMethod::None, VoCombine::Product),
        ("orthographic, cloudy, alone", orthographic, Sky::Cloudy, AoMethod::None, VoCombine::Product),
        ("perspective, with LineAO, product", perspective, Sky::Uniform, AoMethod::LineAo, VoCombine::Product),
        ("perspective, with SSAO, darker", perspective, Sky::Cloudy, AoMethod::Ssao, VoCombine::Min),
    ] {
        let settings = ChainSettings {
            method,
            volume: Some(VolumeAoSettings { sky: sky.weights(), combine }),
            ..ChainSettings::default()
        };
        let f = render_volume(&gpu, &geometry, &camera, settings.clone(), (200, 150));
        let (volume_ao, octants) = (f.volume_ao.as_ref().unwrap(), f.octants.as_ref().unwrap());
        let cpu = reference::volume_ao(&f.nd[0], octants, &table, view_to_world(&f.view), sky.weights());
        let stats = compare(volume_ao, &cpu, 1e-4, |_, _| true);
        println!("{name}: {stats}");
        assert!(stats.worst < 1e-4, "{name}: {stats}");
        // The octants come from the geometry: some pixels dark, some lit.
        let geometry_pixels: Vec<f32> =
            (0..f.nd[0].data.len()).filter(|&i| is_geometry(f.nd[0].data[i])).map(|i| volume_ao.data[i]).collect();
        let dark = geometry_pixels.iter().filter(|&&a| a > 0.3).count();
        assert!(dark > 50 && dark < geometry_pixels.len() - 50, "{name}: {dark} of {}", geometry_pixels.len());
        // The composite shows it alone or combined with the method's.
        let volume = |x, y| (method != AoMethod::None).then(|| (volume_ao.get(x, y), combine));
        let shown = Image::from_fn(f.ao.width, f.ao.height, |x, y| match method {
            AoMethod::None => volume_ao.get(x, y),
            _ => reference::combine_ao(f.ao.get(x, y), volume(x, y)),
        });
        let expected = reference::composite(&f.color, &f.specular, &shown, f.guard, settings.strength);
        let worst = expected
            .data
            .iter()
            .zip(&f.output.data)
            .map(|(e, o)| (0..3).map(|c| (e[c] - o[c]).abs()).fold(0.0, f32::max))
            .fold(0.0, f32::max);
        assert!(worst < 1e-5, "{name}: composite differs by {worst}");
    }
    assert_eq!(octants.len(), geometry.vertices);
}

#[test]
fn a_constant_visibility_gives_the_hemisphere_sky_in_closed_form() {
    // Every vertex sees c of each octant: with an open sky ao = 1 − c for every normal; with only
    // the upper four octants lit (a cloudy day) the cosine lobe's share of the upper hemisphere,
    // (1 + n_z)/2 in world space, so ao = 1 − c (1 + n_z)/2 — through the view-to-world
    // rotation, the octahedral table and the sky weights.
    let gpu = gpu();
    let c = 153.0 / 255.0;
    let geometry = polylines_with_octants(&gpu, 30, 1.1, c);
    let (camera, _) = cameras_for_polylines();
    for sky in [Sky::Uniform, Sky::Cloudy] {
        let settings = ChainSettings {
            method: AoMethod::None,
            volume: Some(VolumeAoSettings { sky: sky.weights(), ..Default::default() }),
            ..ChainSettings::default()
        };
        let f = render_volume(&gpu, &geometry, &camera, settings, (160, 120));
        let (volume_ao, octants) = (f.volume_ao.as_ref().unwrap(), f.octants.as_ref().unwrap());
        let to_world = view_to_world(&f.view);
        let (mut worst, mut pixels) = (0.0f32, 0);
        for (i, nd) in f.nd[0].data.iter().enumerate() {
            if !is_geometry(*nd) {
                assert_eq!(volume_ao.data[i], 0.0);
                continue;
            }
            assert_eq!(reference::unpack_octants(octants.data[i]), [c; 8]);
            let n = (to_world * Vec3::new(nd[0], nd[1], nd[2])).normalize();
            let expected = match sky {
                Sky::Cloudy => 1.0 - c * (1.0 + n.z) / 2.0,
                _ => 1.0 - c,
            };
            worst = worst.max((volume_ao.data[i] - expected).abs());
            pixels += 1;
        }
        println!("{sky:?}: {pixels} pixels, worst |Δ| {worst:.2e} against the closed form");
        // The table's bilinear error (below 1 % of π per octant) bounds the cloudy case.
        assert!(pixels > 500 && worst < if sky == Sky::Uniform { 1e-5 } else { 0.015 }, "{sky:?}: {worst}");
    }
}

#[test]
fn attributes_split_with_the_strip_and_bad_attributes_are_errors() {
    let gpu = gpu();
    let (whole, _) = swept_polylines(&gpu, GeometryOptions::default());
    // 40 polylines of 60 points in pages of 120 points.
    let (chunked, _) = swept_polylines(&gpu, GeometryOptions { page_bytes: 120 * 8, ..Default::default() });
    assert!(chunked.page_count() == 20 && whole.page_count() == 1, "{} pages", chunked.page_count());
    let (camera, _) = cameras_for_polylines();
    let settings =
        ChainSettings { method: AoMethod::None, volume: Some(Default::default()), ..ChainSettings::default() };
    let a = render_volume(&gpu, &whole, &camera, settings.clone(), (120, 90));
    let b = render_volume(&gpu, &chunked, &camera, settings.clone(), (120, 90));
    assert_eq!(a.octants, b.octants);
    assert_eq!(a.volume_ao, b.volume_ao);
    // Geometry without attributes renders fully visible.
    let (positions, offsets) = polylines(40, 0.3);
    let mut plain = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let c = render_volume(&gpu, &plain, &camera, settings, (120, 90));
    assert!(
        c.nd[0]
            .data
            .iter()
            .zip(&c.volume_ao.as_ref().unwrap().data)
            .all(|(nd, &ao)| !is_geometry(*nd) || ao.abs() < 1e-6)
    );
    // Wrong lengths are errors naming what differs.
    let short = vec![[1.0; 8]; positions.len() - 1];
    let error = plain
        .set_attributes(&gpu.device, &gpu.queue, &VertexAttributes { octants: Some(&short), ..Default::default() })
        .unwrap_err()
        .to_string();
    assert!(error.contains("octant visibilities"), "{error}");
}
