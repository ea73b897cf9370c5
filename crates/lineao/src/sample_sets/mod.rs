//! Sample sets of Volumetric Obscurance (Loos & Sloan 2010, §4.5): N points in the unit disk,
//! each with the weight its line integral is scaled by.
//!
//! The generator follows the paper: several Poisson-disk starting sets; a 1/d⁴ repulsion
//! between the points whose step grows while the error falls and shrinks (without applying it)
//! otherwise; periodically each point is pushed to the weighted centroid of its Voronoi region;
//! the regions come from a discrete Voronoi diagram of the disk (512² cells for the final
//! weights, 128² while optimising), weighted by the sphere's z extent 2√(1 − r²) over each cell,
//! because the disk is the orthographic projection of the sphere being integrated. The error is
//! the spread of the regions' volumes (the goal: every sample integrates an equal share) plus
//! each point's distance from its region's centroid. The best set of all starts wins.
//!
//! Weight A_i = V_i / (2 z_s,i): the volume V_i of sample i's Voronoi column divided by its own
//! chord length, so that A_i · |free ∩ allowed|_i estimates the free volume of that column and
//! Σ A_i · 2 z_s,i = 4π/3 exactly (the weights are normalized to it). For evenly sized regions
//! A_i is about the region's area, CONTRACT.md's "Voronoi area".
//!
//! [`VO_DISK_SAMPLES`] holds the tables for N ∈ {5, 7, 9, 12, 13, 16}, written by
//! `cargo run --release --example gen_vo_samples`; a test regenerates them and compares.

mod tables;

pub use tables::VO_DISK_SAMPLES;

use crate::noise;

/// The sample counts with a checked-in table.
pub const VO_SAMPLE_COUNTS: [u32; 6] = [5, 7, 9, 12, 13, 16];

/// The checked-in table for `n` samples: (x, y, A_i).
pub fn vo_disk_samples(n: u32) -> Option<&'static [[f32; 3]]> {
    VO_DISK_SAMPLES.iter().find(|(count, _)| *count == n).map(|(_, table)| *table)
}

/// The sample counts of area sampling (§4.2): one sample (the whole disk) or a line set.
pub const VO_AREA_SAMPLE_COUNTS: [u32; 7] = [1, 5, 7, 9, 12, 13, 16];

/// (x, y, A_i) of area sampling with `n` samples: the line table, or for n = 1 the disk's
/// centre weighted as the whole sphere (A · 2 z_s = 4π/3).
pub fn vo_area_samples(n: u32) -> Option<Vec<[f32; 3]>> {
    match n {
        1 => Some(vec![[0.0, 0.0, 2.0 * std::f32::consts::PI / 3.0]]),
        _ => vo_disk_samples(n).map(<[_]>::to_vec),
    }
}

/// Level-of-detail offset of each area sample, ½ log2(π A_i / Σ A): the footprint of sample i
/// covers the fraction A_i / Σ A of the disk, π r² A_i / Σ A pixels for a sphere of r pixels,
/// so its side is 2^(log2 r + offset_i) pixels (the paper's precomputed logs, §4.2).
pub fn vo_area_lod_offsets(samples: &[[f32; 3]]) -> Vec<f32> {
    let total: f32 = samples.iter().map(|s| s[2]).sum();
    samples.iter().map(|s| 0.5 * (std::f32::consts::PI * s[2] / total).log2()).collect()
}

const STREAM: u32 = 7;

/// Centres of the cells of a `res`² grid over [−1, 1]² that fall inside the unit disk, with
/// the z extent 2√(1 − r²) of each as its weight.
fn disk_cells(res: usize) -> Vec<([f64; 2], f64)> {
    let mut cells = Vec::new();
    for j in 0..res {
        for i in 0..res {
            let x = -1.0 + (i as f64 + 0.5) * 2.0 / res as f64;
            let y = -1.0 + (j as f64 + 0.5) * 2.0 / res as f64;
            let r2 = x * x + y * y;
            if r2 < 1.0 {
                cells.push(([x, y], 2.0 * (1.0 - r2).sqrt()));
            }
        }
    }
    cells
}

/// Each sample's Voronoi column volume and weighted centroid, from a discrete diagram.
fn voronoi(points: &[[f64; 2]], cells: &[([f64; 2], f64)]) -> (Vec<f64>, Vec<[f64; 2]>) {
    let mut volume = vec![0.0; points.len()];
    let mut centroid = vec![[0.0; 2]; points.len()];
    for (c, w) in cells {
        let nearest = (0..points.len())
            .min_by(|&a, &b| {
                let d = |p: [f64; 2]| (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2);
                d(points[a]).total_cmp(&d(points[b]))
            })
            .expect("at least one point");
        volume[nearest] += w;
        centroid[nearest][0] += w * c[0];
        centroid[nearest][1] += w * c[1];
    }
    for (c, v) in centroid.iter_mut().zip(&volume) {
        if *v > 0.0 {
            *c = [c[0] / v, c[1] / v];
        }
    }
    (volume, centroid)
}

/// How far a set is from the goal: the relative spread of the column volumes, plus the mean
/// distance of each point from its region's weighted centroid in units of the point spacing
/// (equal volumes alone are met by pie slices with every point on the rim, where a line sample
/// has no chord; the centroid term is what the paper's boundary charge and centroid pushes
/// enforce).
fn error(points: &[[f64; 2]], cells: &[([f64; 2], f64)]) -> f64 {
    let (volume, centroid) = voronoi(points, cells);
    let n = volume.len() as f64;
    let mean = volume.iter().sum::<f64>() / n;
    let spread = (volume.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt() / mean;
    let spacing = 1.0 / n.sqrt();
    let off_centre = points.iter().zip(&centroid).map(|(p, c)| (p[0] - c[0]).hypot(p[1] - c[1])).sum::<f64>() / n;
    spread + off_centre / spacing
}

/// Poisson-disk dart throwing in the unit disk (minimum distance relaxed until n fit).
fn poisson(n: u32, start: u32) -> Vec<[f64; 2]> {
    let mut radius = 1.6 / (n as f64).sqrt();
    let mut index = 0u32;
    loop {
        let mut points: Vec<[f64; 2]> = Vec::new();
        for _ in 0..2000 {
            let u = noise::uniform(start, STREAM, index) as f64;
            let v = noise::uniform(start, STREAM, index + 1) as f64;
            index += 2;
            let (r, phi) = (u.sqrt(), std::f64::consts::TAU * v);
            let p = [r * phi.cos(), r * phi.sin()];
            if points.iter().all(|q| (q[0] - p[0]).hypot(q[1] - p[1]) >= radius) {
                points.push(p);
                if points.len() == n as usize {
                    return points;
                }
            }
        }
        radius *= 0.9;
    }
}

/// One repulsion step of size `step`: 1/d⁴ forces, points kept inside the disk.
fn repel(points: &[[f64; 2]], step: f64) -> Vec<[f64; 2]> {
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut f = [0.0; 2];
            for (j, q) in points.iter().enumerate() {
                if i != j {
                    let d = [p[0] - q[0], p[1] - q[1]];
                    let len = d[0].hypot(d[1]).max(1e-9);
                    let scale = 1.0 / len.powi(5); // |F| = 1/d⁴ along d/|d|
                    f = [f[0] + d[0] * scale, f[1] + d[1] * scale];
                }
            }
            let norm = f[0].hypot(f[1]).max(1e-12);
            let moved = [p[0] + step * f[0] / norm, p[1] + step * f[1] / norm];
            let r = moved[0].hypot(moved[1]);
            if r > 0.999 { [moved[0] * 0.999 / r, moved[1] * 0.999 / r] } else { moved }
        })
        .collect()
}

/// Generates the N-sample set: (x, y, A_i).
pub fn generate_vo_disk_samples(n: u32) -> Vec<[f32; 3]> {
    let coarse = disk_cells(128);
    let mut best: Option<(f64, Vec<[f64; 2]>)> = None;
    for start in 0..12 {
        let mut points = poisson(n, start);
        let mut err = error(&points, &coarse);
        let mut step = 0.05;
        for iteration in 0..60 {
            let candidate = if iteration % 10 == 9 {
                voronoi(&points, &coarse).1 // the periodic push to the weighted centroids
            } else {
                repel(&points, step)
            };
            let candidate_err = error(&candidate, &coarse);
            if candidate_err < err {
                (points, err) = (candidate, candidate_err);
                step *= 1.2;
            } else {
                step *= 0.5;
            }
        }
        if best.as_ref().is_none_or(|(e, _)| err < *e) {
            best = Some((err, points));
        }
    }
    let (_, points) = best.expect("at least one start");
    let (volume, _) = voronoi(&points, &disk_cells(512));
    let chord = |p: [f64; 2]| 2.0 * (1.0 - p[0] * p[0] - p[1] * p[1]).max(0.0).sqrt();
    let raw: Vec<f64> = points.iter().zip(&volume).map(|(p, v)| v / chord(*p)).collect();
    let total: f64 = points.iter().zip(&raw).map(|(p, a)| a * chord(*p)).sum();
    let normalize = 4.0 / 3.0 * std::f64::consts::PI / total;
    points.iter().zip(raw).map(|(p, a)| [p[0] as f32, p[1] as f32, (a * normalize) as f32]).collect()
}
