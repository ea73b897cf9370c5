//! Variance occlusion maps (Penner & Mitchell 2008, seed 002 §3.4, §4).
//!
//! Occlusion of a point is the fraction of a spherical region above it that lies inside the
//! surface. Instead of testing every voxel of the region, each voxel of a pyramid level carries
//! the first two moments M₁ = E\[x\], M₂ = E\[x²\] of the occupancy x over a Gaussian region around
//! it: the moments of the density volume, blurred by a separable Gaussian and halved in
//! resolution, level after level (§4.1: start at half resolution; the region's width doubles
//! per level). From μ = M₁ and σ² = M₂ − M₁², Chebyshev's one-sided inequality bounds the
//! fraction of the region at or above the iso-value t:
//!
//! ```text
//!   P(x ≥ t) ≤ σ² / (σ² + (t − μ)²)   for t > μ,   else 1
//! ```
//!
//! (the paper prints the inequality the other way round), exact for a two-valued region. The
//! occupancy is two-valued only where voxels are fine against the lines; partly covered voxels
//! make the distribution wider, and the iso-value that best matches rays cast through the same
//! grid is t = 0.35 (measured; the half-coverage iso-surface, t = 0.5, under-occludes by 0.18).
//!
//! Ambient occlusion (§4.3, Fig. 7) takes one region per level, its centre offset along the
//! normal (1.5 σ of its Gaussian) so the region lies mostly above the point, and keeps the
//! maximum. Soft shadows march toward the light, moving to coarser levels as the
//! distance grows ([`VarianceMaps::shadow`]). For lines, whose normal is view-dependent, the
//! per-vertex result is one occlusion per octant, with the octant's diagonal as the normal;
//! the renderer weights them by the geometry term like the sweep's.

use glam::{Vec2, Vec3};

use super::density::DensityVolume;
use super::{OctantVisibility, VolumeGrid, check_tangents, octant_signs, probe};
use crate::Error;

/// Settings of the maps and of their evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VarianceSettings {
    /// Pyramid levels, each one a region of twice the width (the paper: 3–4).
    pub levels: usize,
    /// The iso-value t: occupancy at or above it counts as occluder.
    pub iso: f32,
    /// How far each region's centre lies along the normal, in σ of its Gaussian.
    pub offset: f32,
    /// Worker threads; 0 = the machine's available parallelism.
    pub threads: usize,
}

impl Default for VarianceSettings {
    /// t = 0.35 and offset 1.5 σ: the least error against the Monte-Carlo reference on crossing
    /// bundles (mean |Δ| 0.048 of visibility; t ∈ 0.1–0.5 × offset 1–3 σ gave 0.048–0.18).
    fn default() -> Self {
        VarianceSettings { levels: 4, iso: 0.35, offset: 1.5, threads: 0 }
    }
}

impl VarianceSettings {
    /// Its ranges, as [`Error::OutOfRange`].
    pub fn validate(&self) -> Result<(), Error> {
        if !(1..=8).contains(&self.levels) {
            return Err(Error::out_of_range("VarianceOptions::levels", self.levels, "1..=8"));
        }
        if !(self.iso > 0.0 && self.iso <= 1.0) {
            return Err(Error::out_of_range("VarianceOptions::iso", self.iso, "(0, 1]"));
        }
        if !(self.offset.is_finite() && self.offset >= 0.0) {
            return Err(Error::out_of_range("VarianceOptions::offset", self.offset, "≥ 0 σ"));
        }
        Ok(())
    }
}

/// One level: moments over a grid, and the world σ of the Gaussian region each texel covers.
#[derive(Clone, Debug, PartialEq)]
pub struct MomentLevel {
    /// The level's grid.
    pub grid: VolumeGrid,
    /// (M₁, M₂) per texel, side by side so that a lookup reads both from one place.
    pub moments: Vec<Vec2>,
    /// The world σ of the Gaussian region a texel covers.
    pub sigma: f32,
}

/// The moment pyramid.
#[derive(Clone, Debug, PartialEq)]
pub struct VarianceMaps {
    /// The levels, finest first.
    pub levels: Vec<MomentLevel>,
    /// The density taken as the surface.
    pub iso: f32,
    /// The offset along the normal before sampling, world units.
    pub offset: f32,
}

/// Taps of the per-level Gaussian (σ = one texel of the level): weights for offsets −3..=3.
fn gaussian_taps() -> [f32; 7] {
    let w: [f32; 7] = std::array::from_fn(|k| (-0.5 * (k as f32 - 3.0).powi(2)).exp());
    let sum: f32 = w.iter().sum();
    w.map(|w| w / sum)
}

impl VarianceMaps {
    /// Builds the pyramid from a density volume.
    pub fn new(volume: &DensityVolume, settings: &VarianceSettings) -> Result<VarianceMaps, Error> {
        settings.validate()?;
        let threads = match settings.threads {
            0 => std::thread::available_parallelism().map_or(1, usize::from),
            n => n,
        };
        // The variance of the regions' Gaussians, world units², accumulated through the steps.
        let mut variance = 0.0f32;
        let mut levels: Vec<MomentLevel> = Vec::with_capacity(settings.levels);
        for _ in 0..settings.levels {
            // A 2 × 2 × 2 box adds (h/2)² per axis, the blur (2h)² — h the finer spacing.
            let (fine_voxel, (grid, box_mean)) = match levels.last() {
                None => (volume.grid.voxel, halve(&volume.grid, &volume.occupancy, |x| Vec2::new(x, x * x), threads)),
                Some(fine) => (fine.grid.voxel, halve(&fine.grid, &fine.moments, |m| m, threads)),
            };
            let moments = blur(&grid, box_mean, threads);
            variance += (0.5 * fine_voxel).powi(2) + grid.voxel.powi(2);
            levels.push(MomentLevel { grid, moments, sigma: variance.sqrt() });
        }
        Ok(VarianceMaps { levels, iso: settings.iso, offset: settings.offset })
    }

    /// Chebyshev's bound on the occluding fraction of level `l`'s region centred at `c`.
    pub fn region_occlusion(&self, l: usize, c: Vec3) -> f32 {
        let level = &self.levels[l];
        let m = level.grid.trilinear(&level.moments, c);
        chebyshev(m.x, m.y, self.iso)
    }

    /// Occlusion at `p` with unit normal `n`: the largest over the levels' regions, each
    /// centred `offset` σ along the normal.
    pub fn occlusion(&self, p: Vec3, n: Vec3) -> f32 {
        // Every level shares the origin: level l's texel coordinates of p + n · offset · σ_l are
        // (p − origin) / h_l + n · offset · σ_l / h_l − ½, one division per probe at most.
        let from_origin = p - self.levels[0].grid.origin;
        let mut occlusion = 0.0f32;
        for level in &self.levels {
            let inverse = 1.0 / level.grid.voxel;
            let q = from_origin * inverse + n * (self.offset * level.sigma * inverse) - 0.5;
            let m = level.grid.trilinear_texel(q).sample(&level.moments);
            occlusion = occlusion.max(chebyshev(m.x, m.y, self.iso));
        }
        occlusion
    }

    /// Transmittance toward a light in direction `l` (unit): regions marched from `p` until
    /// the grid ends, the level growing with log₂ of the distance (§4.3: an area light's
    /// penumbra widens with distance), each step one σ of its level; 1 − the largest occlusion.
    pub fn shadow(&self, p: Vec3, l: Vec3) -> f32 {
        let first = 2.0 * self.levels[0].sigma;
        let mut occlusion = 0.0f32;
        let mut distance = first;
        loop {
            let c = p + l * distance;
            if !self.levels[0].grid.contains(c) {
                break;
            }
            let level = ((distance / first).log2().floor().max(0.0) as usize).min(self.levels.len() - 1);
            occlusion = occlusion.max(self.region_occlusion(level, c));
            distance += self.levels[level].sigma;
        }
        1.0 - occlusion
    }

    /// Per vertex (`positions` with unit `tangents`), 1 − occlusion at each octant's probe of
    /// `volume` with the octant's diagonal as the normal.
    pub fn octant_visibility(
        &self,
        volume: &DensityVolume,
        positions: &[[f32; 3]],
        tangents: &[Vec3],
        threads: usize,
    ) -> Result<Vec<OctantVisibility>, Error> {
        check_tangents(positions, tangents)?;
        let threads = match threads {
            0 => std::thread::available_parallelism().map_or(1, usize::from),
            n => n,
        }
        .max(1);
        let normals: [Vec3; 8] = std::array::from_fn(|o| octant_signs(o).normalize());
        let mut out = vec![[0.0f32; 8]; positions.len()];
        let chunk = positions.len().div_ceil(threads).max(1);
        std::thread::scope(|scope| {
            for ((points, tangents), out) in
                positions.chunks(chunk).zip(tangents.chunks(chunk)).zip(out.chunks_mut(chunk))
            {
                scope.spawn(move || {
                    for ((p, t), v) in points.iter().zip(tangents).zip(out) {
                        let p = Vec3::from_array(*p);
                        *v = std::array::from_fn(|o| 1.0 - self.occlusion(probe(volume, p, *t, o), normals[o]));
                    }
                });
            }
        });
        Ok(out)
    }
}

/// P(x ≥ t) ≤ σ² / (σ² + (t − μ)²) for t > μ, else 1.
pub fn chebyshev(m1: f32, m2: f32, t: f32) -> f32 {
    if t <= m1 {
        return 1.0;
    }
    let variance = (m2 - m1 * m1).max(0.0);
    let gap = t - m1;
    if variance == 0.0 { 0.0 } else { variance / (variance + gap * gap) }
}

/// A 2 × 2 × 2 box average of `moments(field)` to half the resolution (odd sizes padded with
/// empty voxels), in z-slabs of the coarse grid, one per thread.
fn halve<T: Copy + Sync>(
    grid: &VolumeGrid,
    field: &[T],
    moments: impl Fn(T) -> Vec2 + Sync,
    threads: usize,
) -> (VolumeGrid, Vec<Vec2>) {
    let dims = grid.dims.map(|n| n.div_ceil(2));
    let coarse = VolumeGrid { dims, origin: grid.origin, voxel: 2.0 * grid.voxel };
    let mut out = vec![Vec2::ZERO; coarse.len()];
    let layer = dims[0] * dims[1];
    let per = dims[2].div_ceil(threads.clamp(1, dims[2]));
    std::thread::scope(|scope| {
        for (k, slab) in out.chunks_mut(layer * per).enumerate() {
            let moments = &moments;
            scope.spawn(move || {
                for z in (2 * k * per..grid.dims[2]).take(2 * slab.len() / layer) {
                    for y in 0..grid.dims[1] {
                        let (row, coarse_row) = (grid.index(0, y, z), layer * (z / 2 - k * per) + dims[0] * (y / 2));
                        for x in 0..grid.dims[0] {
                            slab[coarse_row + x / 2] += moments(field[row + x]) * 0.125;
                        }
                    }
                }
            });
        }
    });
    (coarse, out)
}

/// The separable Gaussian (σ = one texel, 7 taps, empty beyond the grid) along x, y and z,
/// each axis in z-slabs of output, one per thread.
fn blur(grid: &VolumeGrid, mut field: Vec<Vec2>, threads: usize) -> Vec<Vec2> {
    let taps = gaussian_taps();
    let [nx, ny, nz] = grid.dims;
    let layer = nx * ny;
    let per = nz.div_ceil(threads.clamp(1, nz));
    let mut scratch = vec![Vec2::ZERO; field.len()];
    for (axis, stride) in [1, nx, layer].into_iter().enumerate() {
        let (source, n) = (&field, grid.dims[axis]);
        std::thread::scope(|scope| {
            for (k, out) in scratch.chunks_mut(layer * per).enumerate() {
                scope.spawn(move || {
                    for (i, value) in out.iter_mut().enumerate() {
                        let index = k * per * layer + i;
                        *value = convolve(source, index, (index / stride) % n, n, stride, &taps);
                    }
                });
            }
        });
        std::mem::swap(&mut field, &mut scratch);
    }
    field
}

/// One output of a 1D convolution along a stride; taps beyond the line read zero.
fn convolve(source: &[Vec2], index: usize, coordinate: usize, n: usize, stride: usize, taps: &[f32; 7]) -> Vec2 {
    let mut sum = Vec2::ZERO;
    for (k, w) in taps.iter().enumerate() {
        let c = coordinate as isize + k as isize - 3;
        if c >= 0 && (c as usize) < n {
            sum += *w * source[(index as isize + (k as isize - 3) * stride as isize) as usize];
        }
    }
    sum
}
