//! The line-density volume that object-space AO works on (occlusion sweeping, variance
//! occlusion maps): the tractogram voxelized over its bounds as *fractional occupancy*, the part
//! of each cubic voxel that the streamlines cover when swept with an occupancy radius r — the
//! union of one capsule (a cylinder of radius r with round caps) per segment.
//!
//! Each voxel carries a 4 × 4 × 4 grid of sub-sample points as the 64 bits of a `u64`; a segment
//! sets the bits of the points within r of it, so overlapping capsules are counted once (bits
//! are OR-ed) and the occupancy is the set bits over 64. The sub-samples form rows along x
//! through the whole volume; a capsule is convex, so it meets a row in one interval, found in
//! closed form (two balls and a cylinder), and sets its sub-samples as bit ranges. In
//! sub-sample units with each segment's constants precomputed, a row costs a few products and
//! a square root: a 1 M-vertex tractogram at 256³ is 76 M rows.
//!
//! The volume is cut into slabs of z layers, one per thread; every thread reads all segments
//! and keeps those whose bounding box reaches its slab, so no voxel has two writers and the
//! result does not depend on the thread count.

use glam::Vec3;

use super::VolumeGrid;
use crate::Error;

/// Sub-samples per voxel axis (4³ = 64 = the bits of a `u64`).
const SUB: usize = 4;

/// A density volume: occupancy over a grid of cubic voxels.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityVolume {
    /// The grid.
    pub grid: VolumeGrid,
    /// Occupancy in [0, 1] (multiples of 1/64 when voxelized), indexed by [`VolumeGrid::index`].
    pub occupancy: Vec<f32>,
    /// The occupancy radius r the streamlines were swept with, world units (0 for a volume
    /// that is not made of lines).
    pub radius: f32,
}

impl DensityVolume {
    /// Occupancy of voxel (x, y, z).
    pub fn get(&self, x: usize, y: usize, z: usize) -> f32 {
        self.occupancy[self.grid.index(x, y, z)]
    }

    /// The occupied volume Σ occupancy · voxel³, world units cubed.
    pub fn occupied_volume(&self) -> f64 {
        let cell = (self.grid.voxel as f64).powi(3);
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
    let r = options.occupancy_radius;
    if !(r.is_finite() && r > 0.0) {
        return Err(crate::Error::out_of_range("occupancy-radius", r, "> 0 world units"));
    }
    if !(8..=1024).contains(&options.resolution) {
        return Err(crate::Error::out_of_range("volume-resolution", options.resolution, "8..=1024 voxels"));
    }
    let segments = segments(positions, offsets)?;
    let (lo, hi) = segments
        .iter()
        .flat_map(|s| [s.a, s.b])
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
    if segments.is_empty() {
        return Err(Error::InvalidGeometry("no finite points to voxelize".into()));
    }
    let extent = (hi - lo + 2.0 * r).max_element();
    let voxel = extent / (options.resolution - 2) as f32;
    let origin = lo - r - voxel;
    // The longest axis is resolution − 2 voxels up to rounding, which must not add a voxel.
    let dims = ((hi - lo + 2.0 * r) / voxel - 1e-3).ceil().as_uvec3().max(glam::UVec3::ONE) + 2;
    let dims = [dims.x as usize, dims.y as usize, dims.z as usize];
    let grid = VolumeGrid { dims, origin, voxel };
    let rasterizer = Rasterizer { grid, r };

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
            let (rasterizer, segments) = (&rasterizer, &segments);
            scope.spawn(move || rasterizer.fill_slab(segments, k * per_slab, slab));
        }
    });
    let occupancy = masks.iter().map(|m| m.count_ones() as f32 / 64.0).collect();
    Ok(DensityVolume { grid, occupancy, radius: r })
}

/// A segment [a, b] of a streamline; its capsule is the cylinder, the ball at b and — where no
/// earlier segment ended at a — the ball at a (a polyline's joints are swept once).
#[derive(Clone, Copy)]
struct Piece {
    a: Vec3,
    b: Vec3,
    start_ball: bool,
}

/// Every segment with finite ends; a one-point streamline as a zero-length segment.
fn segments(positions: &[[f32; 3]], offsets: &[u64]) -> Result<Vec<Piece>, Error> {
    let mut out: Vec<Piece> = Vec::new();
    let mut push = |a: Vec3, b: Vec3, first: bool| {
        let start_ball = first || out.last().is_none_or(|previous| previous.b != a);
        out.push(Piece { a, b, start_ball });
    };
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
            [p] if finite(p) => push(Vec3::from_array(*p), Vec3::from_array(*p), true),
            _ => {
                let pairs = points.windows(2).filter(|w| finite(&w[0]) && finite(&w[1]));
                for (i, w) in pairs.enumerate() {
                    push(Vec3::from_array(w[0]), Vec3::from_array(w[1]), i == 0);
                }
            }
        }
    }
    Ok(out)
}

/// The grid and the occupancy radius.
struct Rasterizer {
    grid: VolumeGrid,
    r: f32,
}

impl Rasterizer {
    /// Sets the sub-sample bits of the z layers `z0..` that `slab` holds. Coordinates are in
    /// sub-sample units (sub-sample g of an axis at g exactly), so a row's interval [lo, hi]
    /// holds the sub-samples ⌈lo⌉..=⌊hi⌋.
    fn fill_slab(&self, segments: &[Piece], z0: usize, slab: &mut [u64]) {
        let VolumeGrid { dims: [nx, ny, _], .. } = self.grid;
        let z1 = z0 + slab.len() / (nx * ny);
        let (x_end, y_end, z_lo, z_hi) = ((nx * SUB) as i32, (ny * SUB) as i32, (z0 * SUB) as i32, (z1 * SUB) as i32);
        for piece in segments {
            let capsule = Capsule::new(
                self.to_sub(piece.a),
                self.to_sub(piece.b),
                self.r * SUB as f32 / self.grid.voxel,
                piece.start_ball,
            );
            let (lo, hi) = capsule.z_range();
            for gz in ceil(lo).max(z_lo)..=floor(hi).min(z_hi - 1) {
                let plane = capsule.plane(gz as f32);
                let Some((y_lo, y_hi)) = plane.y_range else { continue };
                let layer = nx * ny * (gz as usize / SUB - z0);
                let z_bits = SUB * SUB * (gz as usize % SUB);
                for gy in ceil(y_lo).max(0)..=floor(y_hi).min(y_end - 1) {
                    let Some((x0, x1)) = capsule.row(&plane, gy as f32) else { continue };
                    let (g0, g1) = (ceil(x0).max(0), floor(x1).min(x_end - 1));
                    if g0 > g1 {
                        continue;
                    }
                    let (g0, g1) = (g0 as usize, g1 as usize);
                    let bits = SUB * (gy as usize % SUB) + z_bits;
                    let row = layer + nx * (gy as usize / SUB);
                    for x in g0 / SUB..=g1 / SUB {
                        let i0 = g0.max(x * SUB) - x * SUB;
                        let i1 = g1.min(x * SUB + SUB - 1) - x * SUB;
                        slab[row + x] |= ((1u64 << (i1 - i0 + 1)) - 1) << (i0 + bits);
                    }
                }
            }
        }
    }

    /// World position → sub-sample coordinates: sub-sample g of an axis sits at
    /// origin + (g + ½) · voxel / 4.
    fn to_sub(&self, p: Vec3) -> Vec3 {
        (p - self.grid.origin) * (SUB as f32 / self.grid.voxel) - 0.5
    }
}

/// ⌊x⌋ and ⌈x⌉ as integers, saturating (x86-64's baseline has no rounding instruction, and
/// `f32::floor` is a libm call there).
fn floor(x: f32) -> i32 {
    let t = x as i32;
    if t as f32 > x { t - 1 } else { t }
}

fn ceil(x: f32) -> i32 {
    -floor(-x)
}

/// The capsule of a segment [a, b] with radius r (all in sub-sample units), with what every
/// row intersection needs precomputed: a row costs a few products and one square root per
/// part it meets, no division.
struct Capsule {
    a: Vec3,
    b: Vec3,
    start_ball: bool,
    /// Unit direction of the segment (zero for a point) and its length.
    u: Vec3,
    length: f32,
    r_sq: f32,
    /// 1 − u.x², the x² coefficient of the infinite cylinder's quadratic, and its inverse.
    qa: f32,
    inv_qa: f32,
    inv_ux: f32,
    inv_dz: f32,
}

/// The capsule's section by the plane z = g: what its rows share.
struct Plane {
    /// z − a.z, z − b.z, (z − a.z) u.z.
    dza: f32,
    dzb: f32,
    along_z: f32,
    /// The y range of the section, if the plane meets the capsule.
    y_range: Option<(f32, f32)>,
}

impl Capsule {
    fn new(a: Vec3, b: Vec3, r: f32, start_ball: bool) -> Capsule {
        let length = a.distance(b);
        let u = if length > 0.0 { (b - a) / length } else { Vec3::ZERO };
        let qa = 1.0 - u.x * u.x;
        let dz = b.z - a.z;
        Capsule { a, b, start_ball, u, length, r_sq: r * r, qa, inv_qa: 1.0 / qa, inv_ux: 1.0 / u.x, inv_dz: 1.0 / dz }
    }

    fn z_range(&self) -> (f32, f32) {
        let r = self.r_sq.sqrt();
        (self.a.z.min(self.b.z) - r, self.a.z.max(self.b.z) + r)
    }

    /// The plane at `z`. Its y range: the segment's points within r of the plane
    /// (|a.z + t (b − a).z − z| ≤ r, t ∈ [0, 1]) widened by r.
    fn plane(&self, z: f32) -> Plane {
        let r = self.r_sq.sqrt();
        let (dz, dy) = (self.b.z - self.a.z, self.b.y - self.a.y);
        let (dza, dzb) = (z - self.a.z, z - self.b.z);
        let t = if dz.abs() > 1e-12 {
            let (t0, t1) = ((dza - r) * self.inv_dz, (dza + r) * self.inv_dz);
            Some((t0.min(t1).max(0.0), t0.max(t1).min(1.0)))
        } else {
            (dza.abs() <= r).then_some((0.0, 1.0))
        };
        let y_range = t.filter(|(t0, t1)| t0 <= t1).map(|(t0, t1)| {
            let (y0, y1) = (self.a.y + t0 * dy, self.a.y + t1 * dy);
            (y0.min(y1) - r, y0.max(y1) + r)
        });
        Plane { dza, dzb, along_z: dza * self.u.z, y_range }
    }

    /// The x interval in which the row {(x, y, plane's z)} lies within the capsule: the union
    /// of the cylinder's interval (an infinite cylinder's quadratic cut by the slab
    /// 0 ≤ (p − a)·u ≤ length) and the end balls' (the capsule is convex: one interval).
    fn row(&self, plane: &Plane, y: f32) -> Option<(f32, f32)> {
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        let mut ball = |c: Vec3, dz: f32| {
            let rest = self.r_sq - (y - c.y) * (y - c.y) - dz * dz;
            if rest >= 0.0 {
                let half = rest.sqrt();
                lo = lo.min(c.x - half);
                hi = hi.max(c.x + half);
            }
        };
        ball(self.b, plane.dzb);
        if self.start_ball {
            ball(self.a, plane.dza);
        }
        if self.length > 0.0
            && let Some((x0, x1)) = self.cylinder(plane, y - self.a.y)
        {
            lo = lo.min(x0);
            hi = hi.max(x1);
        }
        (lo <= hi).then_some((lo, hi))
    }

    /// With ξ = x − a.x: (p − a)·u = ξ u.x + m, |p − a|² = ξ² + ρ², and the squared distance to
    /// the axis is qa ξ² − 2 u.x m ξ + ρ² − m².
    fn cylinder(&self, plane: &Plane, dya: f32) -> Option<(f32, f32)> {
        let u = self.u;
        let m = dya * u.y + plane.along_z;
        let rho_sq = dya * dya + plane.dza * plane.dza;
        let qc = rho_sq - m * m - self.r_sq;
        let (mut x0, mut x1) = if self.qa > 1e-6 {
            let h = u.x * u.x * m * m - self.qa * qc;
            if h < 0.0 {
                return None;
            }
            let s = h.sqrt();
            ((u.x * m - s) * self.inv_qa, (u.x * m + s) * self.inv_qa)
        } else if qc <= 0.0 {
            (f32::NEG_INFINITY, f32::INFINITY)
        } else {
            return None;
        };
        // The slab 0 ≤ ξ u.x + m ≤ length.
        if u.x.abs() > 1e-12 {
            let (t0, t1) = (-m * self.inv_ux, (self.length - m) * self.inv_ux);
            x0 = x0.max(t0.min(t1));
            x1 = x1.min(t0.max(t1));
        } else if !(0.0..=self.length).contains(&m) {
            return None;
        }
        (x0 <= x1).then_some((self.a.x + x0, self.a.x + x1))
    }
}
