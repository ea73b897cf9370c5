//! Anatomy slices on both of their paths: one filtered sample of the volume and of its data
//! mask where the device filters f32 textures (`FLOAT32_FILTERABLE`), eight `textureLoad`s
//! where it does not. Each path's picture of a synthetic volume (an oblique affine, zeros
//! around an ellipsoid of data, NaNs inside it) is checked against a CPU trilinear sample at
//! every slice pixel's unprojected world position, and the two paths against each other.

mod common;

use glam::{Mat4, Vec3, Vec4};
use lineao::readback::{read_f32, read_rgba};
use lineao::targets::Target;
use lineao::{AoChain, AoMethod, Camera, ChainSettings, Gpu, LineGeometry, SliceSettings, SliceVolume};

const DIMS: [usize; 3] = [37, 41, 29];
const WINDOW: [f32; 2] = [60.0, 170.0];

/// Voxel (i, j, k) → world: 1.5 mm voxels turned 10° about z, moved off the origin.
fn voxel_to_world() -> Mat4 {
    Mat4::from_translation(Vec3::new(-25.0, -30.0, -20.0))
        * Mat4::from_rotation_z(10f32.to_radians())
        * Mat4::from_scale(Vec3::splat(1.5))
}

/// Smooth values inside an ellipsoid, 0 outside it (no data), and a few NaNs.
fn values() -> Vec<f32> {
    let [nx, ny, nz] = DIMS;
    let mut values = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let (x, y, z) = (i as f32, j as f32, k as f32);
                let inside = ((x - 18.0) / 16.0).powi(2) + ((y - 20.0) / 18.0).powi(2) + ((z - 14.0) / 13.0).powi(2);
                let v = if inside > 1.0 {
                    0.0
                } else if (i * 7 + j * 3 + k) % 97 == 0 {
                    f32::NAN
                } else {
                    110.0 + 50.0 * (0.3 * x).sin() * (0.2 * y).cos() + z
                };
                values.push(v);
            }
        }
    }
    values
}

/// The trilinear sample between voxel centres at voxel coordinates `x` and the weight of its
/// voxels with data (finite, not 0): `shaders/slices.wgsl`'s `trilinear`, in f64.
fn trilinear(values: &[f32], x: Vec3) -> (f64, f64) {
    let last = [DIMS[0] - 1, DIMS[1] - 1, DIMS[2] - 1];
    let i0: [usize; 3] = std::array::from_fn(|a| (x[a].floor().max(0.0) as usize).min(last[a]));
    let f: [f64; 3] = std::array::from_fn(|a| (x[a] as f64 - i0[a] as f64).clamp(0.0, 1.0));
    let (mut value, mut data) = (0.0, 0.0);
    for corner in 0..8 {
        let pick = |a: usize| corner >> a & 1 == 1;
        let index: [usize; 3] = std::array::from_fn(|a| if pick(a) { (i0[a] + 1).min(last[a]) } else { i0[a] });
        let weight: f64 = (0..3).map(|a| if pick(a) { f[a] } else { 1.0 - f[a] }).product();
        let v = values[index[0] + DIMS[0] * (index[1] + DIMS[1] * index[2])] as f64;
        value += weight * v;
        if v.is_finite() && v != 0.0 {
            data += weight;
        }
    }
    (value, data)
}

/// `lineao`'s gray colormap through the window: 16 entries, linear between them.
fn gray(v: f64) -> f32 {
    let table = lineao::Colormap::Gray.table();
    let t = (((v as f32) - WINDOW[0]) / (WINDOW[1] - WINDOW[0])).clamp(0.0, 1.0) * 15.0;
    let k = (t as usize).min(14);
    table[k][0] + (table[k + 1][0] - table[k][0]) * (t - k as f32)
}

/// The axial slice at z = −1 seen from above: each pixel showing the slice, with its colour's
/// red and its world position (unprojected from the depth).
fn slice_pixels(gpu: &Gpu) -> Vec<(usize, f32, Vec3)> {
    let (width, height) = (240u32, 200u32);
    let settings = ChainSettings {
        method: AoMethod::None,
        slices: Some(SliceSettings { positions: [None, None, Some(-1.0)], window: Some(WINDOW), ..Default::default() }),
        ..ChainSettings::default()
    };
    let volume =
        SliceVolume::new(&gpu.device, &gpu.queue, DIMS.map(|d| d as u32), &values(), voxel_to_world()).unwrap();
    let bounds = volume.slice_bounds(settings.slices.as_ref().unwrap()).unwrap();
    // One line far outside the view: the frame's lines.
    let geometry =
        LineGeometry::new(&gpu.device, &gpu.queue, &[[500.0, 500.0, 500.0], [501.0, 500.0, 500.0]], &[0, 2]).unwrap();
    let mut chain = AoChain::new(&gpu.device, common::OUTPUT_FORMAT, settings).unwrap();
    chain.set_slice_volume(&gpu.device, Some(std::sync::Arc::new(volume)));
    chain.resize(width, height).unwrap();
    let camera = Camera {
        eye: bounds.center + Vec3::new(8.0, -20.0, 110.0),
        target: bounds.center,
        up: Vec3::Y,
        projection: lineao::Projection::Perspective { fov_y_deg: 40.0 },
    };
    let view = chain.prepare(&gpu.device, &gpu.queue, &camera, &bounds).unwrap();
    let output = Target::output(&gpu.device, "test::output", (width, height), common::OUTPUT_FORMAT);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &geometry, &output.view).unwrap();
    gpu.queue.submit([encoder.finish()]);
    let targets = chain.targets().unwrap();
    let color = read_rgba(&gpu.device, &gpu.queue, &targets.color).unwrap();
    let depth = read_f32(&gpu.device, &gpu.queue, &targets.depth).unwrap();
    let to_world = view.view.inverse() * view.proj.inverse();
    let (w, h) = (depth.width, depth.height);
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (c, d) = (color.get(x, y), depth.get(x, y));
            if d >= 1.0 || c[3] != 0.0 {
                continue;
            }
            let ndc =
                Vec4::new((x as f32 + 0.5) / w as f32 * 2.0 - 1.0, 1.0 - (y as f32 + 0.5) / h as f32 * 2.0, d, 1.0);
            let p = to_world * ndc;
            pixels.push((y * w + x, c[0], p.truncate() / p.w));
        }
    }
    pixels
}

/// Every slice pixel of `pixels` shows the CPU's sample where its data weigh half or more:
/// returns how many pixels differ by more than 4e-3 (the colour target's half floats, and the
/// depth's rounding across the values' gradient), and the least data weight among them.
fn against_cpu(pixels: &[(usize, f32, Vec3)]) -> (usize, f64) {
    let values = values();
    let to_voxel = voxel_to_world().inverse();
    let (mut off, mut least) = (0, f64::MAX);
    for &(_, red, p) in pixels {
        let (value, data) = trilinear(&values, to_voxel.transform_point3(p));
        least = least.min(data);
        let error = if value.is_nan() { (red - 0.5).abs() } else { (red - gray(value)).abs() };
        if error > 4e-3 {
            off += 1;
        }
    }
    (off, least)
}

#[test]
fn the_filtered_and_the_loaded_slice_show_the_cpu_s_trilinear_sample() {
    let filtering = common::gpu();
    let mut descriptor = Gpu::device_descriptor(&filtering.adapter);
    descriptor.required_features.remove(wgpu::Features::FLOAT32_FILTERABLE);
    let (device, queue) = pollster::block_on(filtering.adapter.request_device(&descriptor)).unwrap();
    let loading = Gpu::new(filtering.instance.clone(), filtering.adapter.clone(), device, queue);
    let filters = filtering.device.features().contains(wgpu::Features::FLOAT32_FILTERABLE);
    // Lavapipe (CI) filters f32: there both paths are drawn, not the loading one twice.
    let adapter = filtering.adapter.get_info().name;
    assert!(filters || !adapter.contains("llvmpipe"), "{adapter} offers no FLOAT32_FILTERABLE");
    let (filtered, loaded) = (slice_pixels(&filtering), slice_pixels(&loading));
    let ((filtered_off, filtered_least), (loaded_off, loaded_least)) = (against_cpu(&filtered), against_cpu(&loaded));
    let indices = |pixels: &[(usize, f32, Vec3)]| pixels.iter().map(|p| p.0).collect::<std::collections::BTreeSet<_>>();
    let only_one = indices(&filtered).symmetric_difference(&indices(&loaded)).count();
    println!(
        "filtered (device filters f32: {filters}): {} pixels, {filtered_off} off the CPU, least data weight \
         {filtered_least:.3}; loaded: {} pixels, {loaded_off} off, least {loaded_least:.3}; shown by one only: {only_one}",
        filtered.len(),
        loaded.len()
    );
    for (pixels, off, least) in [(&filtered, filtered_off, filtered_least), (&loaded, loaded_off, loaded_least)] {
        assert!(pixels.len() > 10_000, "only {} slice pixels", pixels.len());
        assert!(off * 1000 <= pixels.len(), "{off} of {} pixels differ from the CPU's sample", pixels.len());
        // The threshold of half, give or take the filter's weights and the depth's rounding.
        assert!(least > 0.45, "a pixel whose data weigh {least} shows the slice");
    }
    // Both paths cut the same outline, up to pixels whose data weigh half within rounding.
    assert!(only_one * 200 <= filtered.len(), "{only_one} pixels shown by one path only");
}

/// A transparent slice's polygon ([`SliceVolume::outline`]) holds every point of its plane whose
/// data weigh half or more (the CPU's trilinear weight on a grid of a tenth of a voxel), for
/// the oblique volume and for it mirrored in x (a flipped affine, as strokez.nii.gz has), on
/// each axis at several positions; and it is tighter than the rectangle it replaces.
#[test]
fn a_slices_outline_holds_every_point_that_shows() {
    let gpu = common::gpu();
    let values = values();
    for voxel_to_world in [voxel_to_world(), Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)) * voxel_to_world()] {
        let volume =
            SliceVolume::new(&gpu.device, &gpu.queue, DIMS.map(|d| d as u32), &values, voxel_to_world).unwrap();
        let to_voxel = voxel_to_world.inverse();
        let (lo, hi) = volume.world_box();
        let (mut shown, mut polygon_area, mut rectangle_area) = (0usize, 0.0f64, 0.0f64);
        for axis in 0..3 {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            for t in [0.2f32, 0.35, 0.5, 0.65, 0.8] {
                let p = lo[axis] + t * (hi[axis] - lo[axis]);
                let corners = volume.outline(axis, p).expect("data near the plane");
                // Inside: on the inner side of every edge (the corners run counter-clockwise).
                let inside = |q: glam::Vec2| {
                    (0..corners.len()).all(|k| {
                        let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
                        (b - a).perp_dot(q - a) >= -1e-4
                    })
                };
                let step = 0.15;
                let (nu, nw) = (((hi[u] - lo[u]) / step) as usize, ((hi[w] - lo[w]) / step) as usize);
                for iu in 0..=nu {
                    for iw in 0..=nw {
                        let q = glam::Vec2::new(lo[u] + iu as f32 * step, lo[w] + iw as f32 * step);
                        let mut world = Vec3::ZERO;
                        (world[axis], world[u], world[w]) = (p, q.x, q.y);
                        let (_, data) = trilinear(&values, to_voxel.transform_point3(world));
                        if data >= 0.5 {
                            shown += 1;
                            assert!(
                                inside(q),
                                "axis {axis} at {p}: {world} shows (data {data:.3}) outside {corners:?}"
                            );
                        }
                    }
                }
                let area: f32 = (0..corners.len()).map(|k| corners[k].perp_dot(corners[(k + 1) % corners.len()])).sum();
                polygon_area += 0.5 * area as f64;
                rectangle_area += ((hi[u] - lo[u]) * (hi[w] - lo[w])) as f64;
            }
        }
        assert!(shown > 100_000, "{shown} points shown");
        println!("outlines: {:.0} % of the rectangles' area", 100.0 * polygon_area / rectangle_area);
        assert!(polygon_area < 0.9 * rectangle_area, "{polygon_area} of {rectangle_area}");
    }
}
