//! The line-density volume that object-space AO works on (occlusion sweeping, variance
//! occlusion maps): the tractogram voxelized over its bounds as *fractional occupancy*, the part
//! of each cubic voxel that the streamlines cover when swept with an occupancy radius r — the
//! union of one capsule (a cylinder of radius r with round caps) per segment.
//!
//! Each voxel carries a 4 × 4 × 4 grid of sub-sample points as the 64 bits of a `u64`; a segment
//! sets the bits of the points within r of it, so overlapping capsules are counted once (bits
//! are OR-ed) and the occupancy is the set bits over 64. Most voxels need no sub-samples: the
//! distance d from the voxel's centre to the segment decides them whole when d ≤ r − h (inside)
//! or d ≥ r + h (outside), h = √3/2 · voxel the half diagonal.
//!
//! The volume is cut into slabs of z layers, one per thread; every thread reads all segments
//! and keeps those whose bounding box reaches its slab, so no voxel has two writers and the
//! result does not depend on the thread count.

use glam::Vec3;

use crate::Error;

/// Sub-samples per voxel axis (4³ = 64 = the bits of a `u64`).
const SUB: usize = 4;

/// A density volume: `dims` voxels of edge `voxel` from the corner `origin`, x fastest.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityVolume {
    pub dims: [usize; 3],
    /// World position of the corner of voxel (0, 0, 0).
    pub origin: Vec3,
    /// Edge length of the cubic voxels, world units.
    pub voxel: f32,
    /// Occupancy in [0, 1] (multiples of 1/64), index `x + dims[0] * (y + dims[1] * z)`.
    pub occupancy: Vec<f32>,
}

impl DensityVolume {
    /// Occupancy of voxel (x, y, z).
    pub fn get(&self, x: usize, y: usize, z: usize) -> f32 {
        self.occupancy[x + self.dims[0] * (y + self.dims[1] * z)]
    }

    /// World position of the centre of voxel (x, y, z).
    pub fn centre(&self, x: usize, y: usize, z: usize) -> Vec3 {
        self.origin + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * self.voxel
    }

    /// The occupied volume Σ occupancy · voxel³, world units cubed.
    pub fn occupied_volume(&self) -> f64 {
        let cell = (self.voxel as f64).powi(3);
        self.occupancy.iter().map(|&o| o as f64 * cell).sum()
    }
}

/// How to voxelize.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DensityOptions {
    /// Voxels along the longest axis of the bounds (8..=1024; the range is 64–256).
    pub resolution: usize,
    /// Occupancy radius r in world units (mm for tractograms).
    pub occupancy_radius: f32,
    /// Worker threads; 0 = the machine's available parallelism.
    pub threads: usize,
}

impl Default for DensityOptions {
    fn default() -> Self {
        DensityOptions { resolution: 128, occupancy_radius: 0.5, threads: 0 }
    }
}

/// Voxelizes streamlines (`positions`, split by `offsets` as in `lineao_tracts::Tractogram`)
/// over their bounds grown by the occupancy radius and one voxel, so the outermost layer of
/// voxels is empty. Segments with a non-finite end are skipped; a one-point streamline is a
/// ball.
pub fn voxelize(positions: &[[f32; 3]], offsets: &[u64], options: &DensityOptions) -> Result<DensityVolume, Error> {
    let bad = |what: String| Err(Error::InvalidSettings(what));
    let r = options.occupancy_radius;
    if !(r.is_finite() && r > 0.0) {
        return bad(format!("the occupancy radius must be > 0 world units, got {r}"));
    }
    if !(8..=1024).contains(&options.resolution) {
        return bad(format!("the density resolution must be in 8..=1024 voxels, got {}", options.resolution));
    }
    let segments = segments(positions, offsets)?;
    let (lo, hi) = segments
        .iter()
        .flat_map(|s| s.iter())
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    if segments.is_empty() {
        return Err(Error::InvalidGeometry("no finite points to voxelize".into()));
    }
    let extent = (hi - lo + 2.0 * r).max_element();
    let voxel = extent / (options.resolution - 2) as f32;
    let origin = lo - r - voxel;
    // The longest axis is resolution − 2 voxels up to rounding, which must not add a voxel.
    let dims = ((hi - lo + 2.0 * r) / voxel - 1e-3).ceil().as_uvec3().max(glam::UVec3::ONE) + 2;
    let dims = [dims.x as usize, dims.y as usize, dims.z as usize];
    let grid = Grid { dims, origin, voxel, r };

    let threads = match options.threads {
        0 => std::thread::available_parallelism().map_or(1, usize::from),
        n => n,
    }
    .min(dims[2]);
    let layer = dims[0] * dims[1];
    let mut masks = vec![0u64; layer * dims[2]];
    let per_slab = dims[2].div_ceil(threads);
    std::thread::scope(|scope| {
        for (k, slab) in masks.chunks_mut(layer * per_slab).enumerate() {
            let (grid, segments) = (&grid, &segments);
            scope.spawn(move || grid.fill_slab(segments, k * per_slab, slab));
        }
    });
    let occupancy = masks.iter().map(|m| m.count_ones() as f32 / 64.0).collect();
    Ok(DensityVolume { dims, origin, voxel, occupancy })
}

/// Every segment with finite ends; a one-point streamline as a zero-length segment.
fn segments(positions: &[[f32; 3]], offsets: &[u64]) -> Result<Vec<[Vec3; 2]>, Error> {
    let mut out = Vec::new();
    for (k, pair) in offsets.windows(2).enumerate() {
        let (start, end) = (pair[0] as usize, pair[1] as usize);
        if start > end || end > positions.len() {
            return Err(Error::InvalidGeometry(format!(
                "streamline {k} spans points {start}..{end} of {}",
                positions.len()
            )));
        }
        let points = &positions[start..end];
        let finite = |p: &[f32; 3]| p.iter().all(|c| c.is_finite());
        match points {
            [p] if finite(p) => out.push([Vec3::from_array(*p); 2]),
            _ => out.extend(
                points
                    .windows(2)
                    .filter(|w| finite(&w[0]) && finite(&w[1]))
                    .map(|w| [Vec3::from_array(w[0]), Vec3::from_array(w[1])]),
            ),
        }
    }
    Ok(out)
}

struct Grid {
    dims: [usize; 3],
    origin: Vec3,
    voxel: f32,
    r: f32,
}

/// A segment [a, a + ab] prepared for many distance queries.
#[derive(Clone, Copy)]
struct Segment {
    a: Vec3,
    ab: Vec3,
    inv_len_sq: f32,
}

impl Segment {
    fn new([a, b]: [Vec3; 2]) -> Segment {
        let ab = b - a;
        let len_sq = ab.length_squared();
        Segment { a, ab, inv_len_sq: if len_sq > 0.0 { 1.0 / len_sq } else { 0.0 } }
    }

    /// Squared distance from `p` to the segment.
    fn distance_sq(&self, p: Vec3) -> f32 {
        let ap = p - self.a;
        let t = (ap.dot(self.ab) * self.inv_len_sq).clamp(0.0, 1.0);
        (ap - t * self.ab).length_squared()
    }
}

impl Grid {
    /// Sets the sub-sample bits of the z layers `z0..` that `slab` holds.
    fn fill_slab(&self, segments: &[[Vec3; 2]], z0: usize, slab: &mut [u64]) {
        let [nx, ny, _] = self.dims;
        let z1 = z0 + slab.len() / (nx * ny);
        let r = self.r;
        let half_diagonal = 0.5 * 3f32.sqrt() * self.voxel;
        let (inner, outer) = ((r - half_diagonal).max(0.0), r + half_diagonal);
        let (inner_sq, outer_sq, r_sq) = (inner * inner, outer * outer, r * r);
        for &ends in segments {
            let segment = Segment::new(ends);
            let (segment_lo, segment_hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
            // The voxels the capsule's bounding box touches, within this slab.
            let lo = ((segment_lo - r - self.origin) / self.voxel).floor();
            let hi = ((segment_hi + r - self.origin) / self.voxel).floor();
            let range = |axis: usize, from: usize, to: usize| {
                let a = (lo[axis].max(0.0) as usize).max(from);
                let b = ((hi[axis].max(-1.0) + 1.0) as usize).min(to);
                a..b
            };
            for z in range(2, z0, z1) {
                for y in range(1, 0, ny) {
                    for x in range(0, 0, nx) {
                        let corner = self.origin + Vec3::new(x as f32, y as f32, z as f32) * self.voxel;
                        let d_sq = segment.distance_sq(corner + 0.5 * self.voxel);
                        let mask = &mut slab[x + nx * (y + ny * (z - z0))];
                        if d_sq >= outer_sq || *mask == u64::MAX {
                            continue;
                        }
                        if d_sq <= inner_sq && inner > 0.0 {
                            *mask = u64::MAX;
                            continue;
                        }
                        for bit in 0..SUB * SUB * SUB {
                            let (i, j, k) = (bit % SUB, (bit / SUB) % SUB, bit / (SUB * SUB));
                            let at = Vec3::new(i as f32, j as f32, k as f32) + 0.5;
                            if segment.distance_sq(corner + at * (self.voxel / SUB as f32)) <= r_sq {
                                *mask |= 1 << bit;
                            }
                        }
                    }
                }
            }
        }
    }
}
