//! The Monte-Carlo reference for object-space AO: rays cast from each vertex through the same
//! occupancy grid, by which the sweep's and the variance maps' approximations are judged.
//!
//! A ray's transmittance is Π_k (1 − occupancy(p_k))^(Δs / h) over steps of Δs = h/4 from the
//! vertex to the grid's edge (h the voxel edge, nearest-voxel occupancy): occupancy read as the
//! probability that a voxel-long path is blocked, so a path through a fully covered voxel is
//! dark, through an empty one clear. V_o is the mean transmittance of stratified directions,
//! uniform over octant o's solid angle — the quantity the sweep's V_o approximates.

use glam::Vec3;

use super::density::DensityVolume;
use super::{OctantVisibility, octant_signs, probe};
use crate::noise;

/// Mean transmittance over `rays` (a square number of strata is used: ⌈√rays⌉²) directions per
/// octant, per vertex (`positions` with unit `tangents`), cast from the vertex's probes as the
/// sweep reads them; `seed` jitters the strata.
pub fn octant_visibility(
    volume: &DensityVolume,
    positions: &[[f32; 3]],
    tangents: &[Vec3],
    rays: u32,
    seed: u32,
) -> Vec<OctantVisibility> {
    let side = (rays as f32).sqrt().ceil().max(1.0) as u32;
    positions
        .iter()
        .zip(tangents)
        .enumerate()
        .map(|(i, (p, t))| {
            std::array::from_fn(|o| {
                let p = probe(volume, Vec3::from_array(*p), *t, o);
                let signs = octant_signs(o);
                let mut sum = 0.0;
                for k in 0..side * side {
                    // Uniform on the sphere: z = 2u − 1, φ = 2πv; folded into the octant.
                    let index = (i as u32).wrapping_mul(8 * side * side) + (o as u32) * side * side + k;
                    let u = ((k % side) as f32 + noise::uniform(seed, 0, index)) / side as f32;
                    let v = ((k / side) as f32 + noise::uniform(seed, 1, index)) / side as f32;
                    let z = u;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    let phi = 0.5 * std::f32::consts::PI * v;
                    let d = Vec3::new(r * phi.cos(), r * phi.sin(), z) * signs;
                    sum += transmittance(volume, p, d);
                }
                sum / (side * side) as f32
            })
        })
        .collect()
}

/// Transmittance along the ray from `p` in unit direction `d` to the grid's edge.
pub fn transmittance(volume: &DensityVolume, p: Vec3, d: Vec3) -> f32 {
    let grid = &volume.grid;
    let step = 0.25;
    let mut log_t = 0.0f32;
    let mut s = 0.5 * step;
    loop {
        let q = (p + d * (s * grid.voxel) - grid.origin) / grid.voxel;
        if q.cmplt(Vec3::ZERO).any()
            || q.x >= grid.dims[0] as f32
            || q.y >= grid.dims[1] as f32
            || q.z >= grid.dims[2] as f32
        {
            break;
        }
        let o = volume.get(q.x as usize, q.y as usize, q.z as usize);
        if o >= 1.0 {
            return 0.0;
        }
        log_t += step * (1.0 - o).ln();
        s += step;
    }
    log_t.exp()
}
