//! Sample sets of Volumetric Obscurance (Loos & Sloan 2010, §4.5): N points in the unit disk,
//! each with the weight its line integral is scaled by, and N points in the unit ball for point
//! sampling (the kernel of [`crate::SsaoKernel::Sphere`]).
//!
//! The generator follows the paper: several Poisson-disk starting sets; a 1/d⁴ repulsion
//! between the points whose step grows while the error falls and shrinks (without applying it)
//! otherwise; periodically each point is pushed to the weighted centroid of its Voronoi region;
//! the regions come from a discrete Voronoi diagram of the disk (512² cells for the final
//! weights, 128² while optimising), weighted by the sphere's z extent 2√(1 − r²) over each cell,
//! because the disk is the orthographic projection of the sphere being integrated. The sphere
//! sets run the same optimisation in 3D on a 32³ diagram (the paper's 128³ costs 64× more per
//! step; a test measures the result on 128³ instead). The error is
//! the spread of the regions' volumes (the goal: every sample integrates an equal share) plus
//! each point's distance from its region's centroid. The best set of all starts wins.
//!
//! Weight A_i = V_i / (2 z_s,i): the volume V_i of sample i's Voronoi column divided by its own
//! chord length, so that A_i · |free ∩ allowed|_i estimates the free volume of that column and
//! Σ A_i · 2 z_s,i = 4π/3 exactly (the weights are normalized to it). For evenly sized regions
//! A_i is about the region's area, the Voronoi area of docs/reference.md "VO".
//!
//! [`VO_DISK_SAMPLES`] holds the disk tables for N ∈ {5, 7, 9, 12, 13, 16},
//! [`VO_SPHERE_SAMPLES`] the sphere tables for N ∈ {8, 12, 16, 24, 32}, written by
//! `cargo run --release --example gen_vo_samples`; a test regenerates them and compares.

#[cfg(feature = "reference")]
mod generate;
mod tables;

#[cfg(feature = "reference")]
pub use generate::{generate_vo_disk_samples, generate_vo_sphere_samples, sphere_volume_spread};
pub use tables::{VO_DISK_SAMPLES, VO_SPHERE_SAMPLES};

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

/// The sample counts with a checked-in sphere (point-sample) table.
pub const VO_SPHERE_SAMPLE_COUNTS: [u32; 5] = [8, 12, 16, 24, 32];

/// The checked-in sphere table for `n` points: (x, y, z) in the unit ball.
pub fn vo_sphere_samples(n: u32) -> Option<&'static [[f32; 3]]> {
    VO_SPHERE_SAMPLES.iter().find(|(count, _)| *count == n).map(|(_, table)| *table)
}

/// σ below which VO area sampling treats depth as a step (docs/reference.md): 1e-3 (far − near).
pub fn vo_sigma_floor(near: f32, far: f32) -> f32 {
    1e-3 * (far - near)
}

/// z_s = √(1 − x² − y²): half the chord at disk point (x, y) (the line pass keeps it in its table).
pub fn vo_chord_half(x: f32, y: f32) -> f32 {
    (1.0 - (x * x + y * y)).max(0.0).sqrt()
}
