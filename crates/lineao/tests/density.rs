//! The line-density volume: occupied volumes against the capsule's closed form, whole voxels
//! inside and outside the radius, independence of the thread count, and bad input.

use lineao::volume::density::{DensityOptions, voxelize};

fn options(resolution: usize, occupancy_radius: f32, threads: usize) -> DensityOptions {
    DensityOptions { resolution, occupancy_radius, threads }
}

#[test]
fn a_straight_streamline_occupies_its_capsule() {
    // A line of length 60 along x in 30 segments, radius 3: πr²L + 4/3 πr³.
    let positions: Vec<[f32; 3]> = (0..=30).map(|i| [i as f32 * 2.0, 0.3, -0.2]).collect();
    let (r, length) = (3.0f64, 60.0f64);
    let exact = std::f64::consts::PI * r * r * length + 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    for resolution in [64, 128] {
        let volume = voxelize(&positions, &[0, 31], &options(resolution, r as f32, 0)).unwrap();
        let measured = volume.occupied_volume();
        println!("{resolution}: {measured:.1} vs {exact:.1} ({:+.2} %)", 100.0 * (measured / exact - 1.0));
        assert!((measured / exact - 1.0).abs() < 0.02, "{resolution}: {measured} vs {exact}");
        assert_eq!(volume.grid.dims[0], resolution);
        // Voxels whose centre lies within r − h are full, beyond r + h empty, nothing outside [0, 1].
        let h = 0.5 * 3f32.sqrt() * volume.grid.voxel;
        for z in 0..volume.grid.dims[2] {
            for y in 0..volume.grid.dims[1] {
                for x in 0..volume.grid.dims[0] {
                    let c = volume.grid.centre(x, y, z);
                    let d = (c.y - 0.3).hypot(c.z + 0.2).max(if c.x < 0.0 { -c.x } else { (c.x - 60.0).max(0.0) });
                    let o = volume.get(x, y, z);
                    if c.x >= 0.0 && c.x <= 60.0 && d <= 3.0 - h {
                        assert_eq!(o, 1.0, "({x}, {y}, {z})");
                    }
                    if d >= 3.0 + h {
                        assert_eq!(o, 0.0, "({x}, {y}, {z})");
                    }
                    assert!((0.0..=1.0).contains(&o));
                }
            }
        }
    }
}

#[test]
fn a_single_point_is_a_ball_and_overlaps_count_once() {
    let r = 5.0f64;
    let ball = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let one = voxelize(&[[1.0, 2.0, 3.0]], &[0, 1], &options(96, r as f32, 0)).unwrap();
    assert!((one.occupied_volume() / ball - 1.0).abs() < 0.02, "{}", one.occupied_volume());
    // The same point twice (two streamlines) and a zero-length segment: still one ball.
    let twice =
        voxelize(&[[1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [1.0, 2.0, 3.0]], &[0, 1, 3], &options(96, r as f32, 0)).unwrap();
    assert_eq!(twice.occupancy, one.occupancy);
}

#[test]
fn the_result_does_not_depend_on_the_thread_count() {
    // Crossing helices: segments reach across slab borders in every direction.
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    for k in 0..6 {
        for i in 0..200 {
            let t = i as f32 * 0.1;
            let phase = k as f32;
            positions.push([10.0 * (t + phase).cos(), 10.0 * (t + phase).sin(), t * 3.0 - 30.0]);
        }
        offsets.push(positions.len() as u64);
    }
    let single = voxelize(&positions, &offsets, &options(64, 1.5, 1)).unwrap();
    for threads in [2, 3, 7, 64] {
        let many = voxelize(&positions, &offsets, &options(64, 1.5, threads)).unwrap();
        assert_eq!(many, single, "{threads} threads");
    }
    assert!(single.occupancy.iter().filter(|&&o| o > 0.0).count() > 1000);
}

#[test]
fn bad_input_is_a_clear_error() {
    let line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    for (positions, offsets, opts, needle) in [
        (&line[..], &[0u64, 2][..], options(64, 0.0, 0), "--occupancy-radius must be > 0 world units"),
        (&line, &[0, 2], options(64, f32::NAN, 0), "--occupancy-radius must be > 0 world units"),
        (&line, &[0, 2], options(4, 1.0, 0), "resolution"),
        (&line, &[0, 3], options(64, 1.0, 0), "streamline 0"),
        (&[], &[0], options(64, 1.0, 0), "no finite points"),
        (&[[f32::NAN, 0.0, 0.0]], &[0, 1], options(64, 1.0, 0), "no finite points"),
    ] {
        let error = voxelize(positions, offsets, &opts).unwrap_err().to_string();
        assert!(error.contains(needle), "{error}");
    }
}

/// Distance from `p` to the segment [a, b].
fn segment_distance(p: glam::Vec3, a: glam::Vec3, b: glam::Vec3) -> f32 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    p.distance(a + t * ab)
}

#[test]
fn every_voxel_counts_the_sub_samples_within_the_radius() {
    // Random polylines in every direction (some segments along an axis, some of zero length):
    // each voxel's occupancy is the share of its 4 × 4 × 4 sub-samples (at (i + ½)/4 of the
    // voxel) within r of some segment, counted by brute force; a sub-sample within 1e-4 r of
    // the surface may go either way (rounding).
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut offsets = vec![0u64];
    let random = |k: u32, axis: u32| lineao::noise::uniform(11, axis, k);
    for line in 0..12u32 {
        let mut p = glam::Vec3::new(random(line, 0), random(line, 1), random(line, 2)) * 20.0;
        for step in 0..8u32 {
            positions.push(p.to_array());
            let k = line * 8 + step;
            let mut d = glam::Vec3::new(random(k, 3), random(k, 4), random(k, 5)) - 0.5;
            match k % 5 {
                0 => d = glam::Vec3::new(d.x, 0.0, 0.0),
                1 => d = glam::Vec3::new(0.0, d.y, d.z),
                2 => d = glam::Vec3::ZERO,
                _ => {}
            }
            p += d * 6.0;
        }
        offsets.push(positions.len() as u64);
    }
    let r = 1.3f32;
    let volume = voxelize(&positions, &offsets, &options(40, r, 0)).unwrap();
    let segments: Vec<(glam::Vec3, glam::Vec3)> = offsets
        .windows(2)
        .flat_map(|w| (w[0] as usize + 1..w[1] as usize).map(|i| (positions[i - 1].into(), positions[i].into())))
        .collect();
    let grid = volume.grid;
    let (mut ambiguous, mut checked) = (0, 0);
    for z in 0..grid.dims[2] {
        for y in 0..grid.dims[1] {
            for x in 0..grid.dims[0] {
                let (mut inside, mut unsure) = (0, 0);
                for s in 0..64 {
                    let sub = glam::Vec3::new((s % 4) as f32, (s / 4 % 4) as f32, (s / 16) as f32) + 0.5;
                    let p = grid.origin + (glam::Vec3::new(x as f32, y as f32, z as f32) + sub / 4.0) * grid.voxel;
                    let d = segments.iter().map(|&(a, b)| segment_distance(p, a, b)).fold(f32::INFINITY, f32::min);
                    if (d - r).abs() < 1e-4 * r {
                        unsure += 1;
                    } else if d < r {
                        inside += 1;
                    }
                }
                let count = (volume.get(x, y, z) * 64.0).round() as i32;
                assert!(
                    (inside..=inside + unsure).contains(&count),
                    "voxel ({x}, {y}, {z}): {count} of 64 set, brute force {inside} (+{unsure} on the surface)"
                );
                ambiguous += unsure;
                checked += 1;
            }
        }
    }
    println!("{checked} voxels agree; {ambiguous} sub-samples on the surface");
}
