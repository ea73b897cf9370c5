//! Fast occlusion sweeping (Singh, Yuksel, House 2009; seed 000 §2, Eq. 3–8).
//!
//! Ambient occlusion A(P, N) = ∫ V(P, ω) g(N, ω) dω is split into the eight octants Ω_o of the
//! sphere (Eq. 3), and within an octant the visibility is taken as one constant V_o(P), so
//! A_o ≈ V_o(P) G_o(N) (Eq. 4) with the integrated geometry term G_o of
//! [`geometry_term`](super::geometry_term) (Eq. 5). V_o comes from the three neighbours on the
//! side the octant's light arrives from, each attenuated by its transmittance τ (Eq. 6):
//!
//! ```text
//!   V_o(P) = ⅓ [ V_o(P + σ_x h e_x) τ(P + σ_x h e_x) + V_o(P + σ_y h e_y) τ(…) + V_o(P + σ_z h e_z) τ(…) ]
//! ```
//!
//! (σ = the octant's signs), so one diagonal sweep from the octant's corner of the grid computes
//! V_o for every voxel, each voxel visited once: eight sweeps, linear time in the voxels.
//! Outside the grid V τ = 1 (an open sky).
//!
//! The paper's τ (Eq. 7) is the part of the voxel outside the surface, D/h + ½ clamped to
//! [0, 1] from the signed distance D — exactly 1 − coverage for a plane crossing the voxel. Our
//! density volume stores that coverage directly, so τ = 1 − occupancy, with no distance field
//! (only |D| < h/2 mattered). Translucent transmittance (Eq. 8) with an opacity α in (0, 1]
//! lets light through for α < 1: τ_α = 1 − α (1 − τ) = 1 − α · occupancy. The seed prints the
//! exponent form 1 − (1 − τ)^α, which for α < 1 *lowers* τ and never passes a full voxel —
//! the opposite of its text ("decreasing α values permit more light to penetrate", light
//! through the object from behind); the product form does what the text says.
//!
//! [`octant_visibility`] runs the sweeps on worker threads (one octant per thread at a time, so
//! each needs one field of f32) and samples every V_o trilinearly at the vertices' probes
//! ([`probe`]).

use glam::Vec3;

use super::density::DensityVolume;
use super::{OctantVisibility, VolumeGrid, check_tangents, octant_signs, probe};
use crate::Error;

/// Settings of the sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepSettings {
    /// Opacity α of the translucent transmittance (Eq. 8), in (0, 1]; 1 = the opaque τ of Eq. 7.
    pub alpha: f32,
    /// Worker threads; 0 = the machine's available parallelism.
    pub threads: usize,
}

impl Default for SweepSettings {
    fn default() -> Self {
        SweepSettings { alpha: 1.0, threads: 0 }
    }
}

impl SweepSettings {
    /// Its ranges, as [`Error::OutOfRange`].
    pub fn validate(&self) -> Result<(), Error> {
        if !(self.alpha > 0.0 && self.alpha <= 1.0) {
            return Err(Error::out_of_range("sweep-alpha", self.alpha, "(0, 1]"));
        }
        Ok(())
    }
}

/// The transmittance field τ_α = 1 − α · occupancy (Eq. 7–8).
pub fn transmittance(volume: &DensityVolume, alpha: f32) -> Vec<f32> {
    volume.occupancy.iter().map(|o| 1.0 - alpha * o).collect()
}

/// V_o over the whole grid for octant `o` (Eq. 6), given the transmittance field `tau`.
pub fn visibility_field(grid: &VolumeGrid, tau: &[f32], o: usize) -> Vec<f32> {
    let mut v = vec![0.0f32; grid.len()];
    sweep_into(grid, tau, o, &mut v);
    v
}

/// One diagonal sweep: visits the voxels from the octant's corner so each voxel's three
/// upwind neighbours are done before it.
fn sweep_into(grid: &VolumeGrid, tau: &[f32], o: usize, v: &mut [f32]) {
    let [nx, ny, nz] = grid.dims;
    let s = octant_signs(o);
    // Along an axis with σ > 0 the light comes from +: start at the top, neighbour at +1.
    let order = |n: usize, sign: f32| -> Box<dyn Iterator<Item = usize>> {
        if sign > 0.0 { Box::new((0..n).rev()) } else { Box::new(0..n) }
    };
    let upwind = |i: usize, n: usize, sign: f32| -> Option<usize> {
        if sign > 0.0 { (i + 1 < n).then_some(i + 1) } else { i.checked_sub(1) }
    };
    let third = 1.0 / 3.0;
    for z in order(nz, s.z) {
        let zn = upwind(z, nz, s.z);
        for y in order(ny, s.y) {
            let yn = upwind(y, ny, s.y);
            let row = grid.index(0, y, z);
            let row_y = yn.map(|yn| grid.index(0, yn, z));
            let row_z = zn.map(|zn| grid.index(0, y, zn));
            // V τ of the x neighbour, carried along the row (1 beyond the grid).
            let mut carried = 1.0f32;
            let mut visit = |x: usize| {
                let vt = |r: Option<usize>| r.map_or(1.0, |r| v[r + x] * tau[r + x]);
                let value = (carried + vt(row_y) + vt(row_z)) * third;
                v[row + x] = value;
                carried = value * tau[row + x];
            };
            if s.x > 0.0 {
                (0..nx).rev().for_each(&mut visit);
            } else {
                (0..nx).for_each(&mut visit);
            }
        }
    }
}

/// The eight octant visibilities of each vertex (`positions` with unit `tangents`), trilinear
/// in the V_o fields at the vertex's probes.
pub fn octant_visibility(
    volume: &DensityVolume,
    positions: &[[f32; 3]],
    tangents: &[Vec3],
    settings: &SweepSettings,
) -> Result<Vec<OctantVisibility>, Error> {
    settings.validate()?;
    check_tangents(positions, tangents)?;
    let grid = &volume.grid;
    let tau = transmittance(volume, settings.alpha);
    let threads = match settings.threads {
        0 => std::thread::available_parallelism().map_or(1, usize::from),
        n => n,
    }
    .clamp(1, 8);
    // One column of per-vertex values per octant; thread k sweeps octants k, k + threads, ….
    let mut columns: Vec<Vec<f32>> = vec![Vec::new(); 8];
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|k| {
                let tau = &tau;
                scope.spawn(move || {
                    let mut field = vec![0.0f32; grid.len()];
                    (k..8)
                        .step_by(threads)
                        .map(|o| {
                            sweep_into(grid, tau, o, &mut field);
                            let column = positions
                                .iter()
                                .zip(tangents)
                                .map(|(p, t)| grid.trilinear(&field, probe(volume, Vec3::from_array(*p), *t, o)))
                                .collect();
                            (o, column)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for handle in handles {
            for (o, column) in handle.join().expect("a sweep thread panicked") {
                columns[o] = column;
            }
        }
    });
    Ok((0..positions.len()).map(|i| std::array::from_fn(|o| columns[o][i])).collect())
}
