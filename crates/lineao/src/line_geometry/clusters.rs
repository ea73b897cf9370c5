//! Polylines as **clusters**, the form the GPU holds them in: each point once, 6 bytes.
//!
//! A polyline is cut at non-finite points into *runs* (≥ 2 finite points joined by segments),
//! and each run into clusters of at most [`CLUSTER_POINTS`] (24) consecutive points (never one: a
//! remainder of one point makes the cluster before it one shorter). A cluster's points are
//! quantized to 16 bits per axis on a grid of its own — origin the corner of its points' box,
//! step `scale` = the box's longest side / 65535 — so a decoded point lies within
//! `scale / 2 ≈ 7.6e-6` of the box's longest side of the input (plus the f32 rounding of
//! `origin + q · scale`). Points are stored in run order, `x | y << 16` in one word and `z`
//! in half a word; a cluster's record ([`ClusterRecord`], 32 bytes) holds its grid, its first
//! point and count, and whether its run goes on before and after it (and in which clusters).
//!
//! A cluster draws its own points *and the next cluster's first point*, so its strip ends
//! where the next one's begins: both decode that point with the next cluster's grid and get
//! the same bits — joins stay watertight. The vertex tangent of a point (the central
//! difference of its neighbours) reads across cluster borders the same way.
//!
//! The vertex shader *pulls* (`shaders/shared/clusters.wgsl`): instance = cluster, vertex =
//! a position along its strip, so no strip and no index buffer exist. A draw gives every
//! instance the same vertex count, so clusters are sorted by **size class** (the segments they
//! draw: ≤ 3, 6, 12, 24) and each class is drawn with its own count; vertices past a cluster's
//! end collapse onto its last one (zero-area triangles the rasterizer drops).
//!
//! **The alternating strip** (the module above has the tolerance argument) takes one side per
//! point but both sides of a cluster's ends and of its *bent* inner points — those farther than
//! the tolerance τ from the chord of their neighbours, or whose tangent turns more than 20°
//! from a neighbour's. A record holds its bent points as a mask; the vertex shader finds the
//! point of strip vertex v by a binary search over the mask's prefix counts. Within a size
//! class, records are sorted by how many of their points are bent, in five **bend classes**
//! (none, up to an eighth, a quarter, half, all of the class's segments), each drawn with the
//! vertex count its most bent cluster needs.

use std::ops::Range;

use glam::Vec3;

/// The most points of one cluster (the mask of its bent inner points fits in 24 bits of its
/// record).
pub const CLUSTER_POINTS: u32 = 24;

/// Segments of a piece, the unit the line cull tests and draws (`passes::cull`); as
/// `PIECE_SEGMENTS` in `shaders/shared/clusters.wgsl`.
pub const PIECE_SEGMENTS: u32 = 8;

/// Consecutive records of a page (close in space: they are sorted along a Morton curve within
/// their class) the cull tests as one box first; as `GROUP_CLUSTERS` in `shaders/cull.wgsl`.
pub const GROUP_CLUSTERS: usize = 16;

/// The size classes: a cluster of class `c` draws at most `c` segments.
pub(crate) const SIZE_CLASSES: [u32; 4] = [3, 6, 12, 24];

/// The bend classes of a size class of `s` segments: at most `BEND_CLASSES[i] · s / 8` bent
/// inner points (none, an eighth, a quarter, half, all).
pub(crate) const BEND_CLASSES: [u32; 5] = [0, 1, 2, 4, 8];

/// Draw ranges of a page: every bend class of every size class.
pub(crate) const DRAW_CLASSES: usize = SIZE_CLASSES.len() * BEND_CLASSES.len();

/// The bits of [`ClusterRecord::flags`]. Keep in sync with `shaders/shared/clusters.wgsl`.
pub(crate) mod flags {
    /// The cluster's own points (2..=24).
    pub const COUNT: u32 = 0x1f;
    /// Its run goes on before it: its first point's previous neighbour is `previous`'s last.
    pub const JOINS_PREVIOUS: u32 = 1 << 5;
    /// Its run goes on after it: it also draws `next`'s first point.
    pub const JOINS_NEXT: u32 = 1 << 6;
    /// Its streamline is selected out ([`crate::LineGeometry::set_selection`]): nothing of it
    /// is drawn, culled or occludes.
    pub const DESELECTED: u32 = 1 << 7;
    /// Bits 8–31: inner point k (1 ≤ k ≤ 24 of the strip) is bent at bit 7 + k.
    pub const BENT_SHIFT: u32 = 8;
}

/// One cluster on the GPU. Keep in sync with `Cluster` in `shaders/shared/clusters.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ClusterRecord {
    /// The grid's origin: the corner of the cluster's box (world units).
    pub origin: [f32; 3],
    /// World units per quantization step (0 when all its points coincide).
    pub scale: f32,
    /// Its first point in the page's point arrays.
    pub first: u32,
    /// Point count and flags (the bits of `flags`: a run's start and end, selected out).
    pub flags: u32,
    /// The cluster holding the run's point before `first` (with `JOINS_PREVIOUS`).
    pub previous: u32,
    /// The cluster holding the run's point after its last (with `JOINS_NEXT`).
    pub next: u32,
}

impl ClusterRecord {
    /// Its points (at most [`CLUSTER_POINTS`](super::CLUSTER_POINTS)).
    pub fn count(&self) -> u32 {
        self.flags & flags::COUNT
    }

    /// The points its strip draws: its own and, when the run goes on, the next cluster's first.
    pub fn drawn(&self) -> u32 {
        self.count() + (self.flags & flags::JOINS_NEXT != 0) as u32
    }

    /// Whether its streamline is selected ([`crate::LineGeometry::set_selection`]).
    pub fn is_selected(&self) -> bool {
        self.flags & flags::DESELECTED == 0
    }

    /// How many of its inner points are bent (take both sides in the alternating strip).
    pub fn bent(&self) -> u32 {
        (self.flags >> flags::BENT_SHIFT).count_ones()
    }

    /// Vertices of its alternating strip: one a point, both sides of its ends and bent points.
    pub fn alternating_vertices(&self) -> u32 {
        self.drawn() + 2 + self.bent()
    }

    /// A quantized point back in world units, as the shaders compute it.
    pub fn decode(&self, q: [u16; 3]) -> [f32; 3] {
        std::array::from_fn(|a| (q[a] as f32).mul_add(self.scale, self.origin[a]))
    }
}

pub(crate) const RECORD_SIZE: u64 = std::mem::size_of::<ClusterRecord>() as u64;

/// A run of input points stored in a page: input vertex `input..input + len` is page point
/// `first..first + len` (which input vertices a page holds, for per-vertex attributes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct RunMap {
    pub input: u64,
    /// The polyline it is part of (its index among every polyline appended).
    pub streamline: u32,
    pub first: u32,
    pub len: u32,
}

/// The class of a cluster that draws `segments` segments: the smallest size class that holds
/// them.
fn size_class(segments: u32) -> usize {
    SIZE_CLASSES.iter().position(|&c| segments <= c).expect("clusters draw at most CLUSTER_POINTS segments")
}

/// The draw class of a record: its size class's bend class.
fn draw_class(record: &ClusterRecord) -> usize {
    let size = size_class(record.drawn() - 1);
    let bent = record.bent();
    let bend = BEND_CLASSES.iter().position(|&b| bent * 8 <= b * SIZE_CLASSES[size]).expect("at most all points");
    size * BEND_CLASSES.len() + bend
}

/// The alternating strip's vertex count of draw class `class` (its most bent cluster's).
pub(crate) fn alternating_vertices(class: usize) -> u32 {
    let segments = SIZE_CLASSES[class / BEND_CLASSES.len()];
    let bent = (BEND_CLASSES[class % BEND_CLASSES.len()] * segments / 8).min(segments - 1);
    segments + 3 + bent
}

/// The full strip's vertex count of draw class `class`.
pub(crate) fn full_vertices(class: usize) -> u32 {
    2 * (SIZE_CLASSES[class / BEND_CLASSES.len()] + 1)
}

/// The segments a cluster of draw class `class` draws at most.
pub(crate) fn class_segments(class: usize) -> u32 {
    SIZE_CLASSES[class / BEND_CLASSES.len()]
}

/// The unit vertex tangent of run point `k`: the central difference of its neighbours, else
/// the one-sided ones, else +x (a run of coincident points).
pub(crate) fn vertex_tangent(run: &[[f32; 3]], k: usize) -> Vec3 {
    let at = |i: usize| Vec3::from_array(run[i]);
    let prev = at(k.saturating_sub(1));
    let next = at((k + 1).min(run.len() - 1));
    [next - prev, next - at(k), at(k) - prev]
        .into_iter()
        .map(|t| t.normalize_or_zero())
        .find(|t| t != &Vec3::ZERO && t.is_finite())
        .unwrap_or(Vec3::X)
}

/// The cosine of the largest turn between neighbouring tangents a straight cluster allows (20°).
pub(crate) const MAX_TURN_COS: f32 = 0.9397;

/// How far run point `k` (0 < k < len − 1) lies from the chord of its neighbours (world
/// units): what skipping one of its sides moves an edge by; infinite where its tangent turns
/// more than 20° from a neighbour's.
pub(crate) fn deviation(run: &[[f32; 3]], tangents: &[Vec3], k: usize) -> f32 {
    if tangents[k].dot(tangents[k - 1]) < MAX_TURN_COS || tangents[k].dot(tangents[k + 1]) < MAX_TURN_COS {
        return f32::INFINITY;
    }
    let (a, p, b) = (Vec3::from_array(run[k - 1]), Vec3::from_array(run[k]), Vec3::from_array(run[k + 1]));
    let chord = b - a;
    let t =
        if chord.length_squared() > 0.0 { ((p - a).dot(chord) / chord.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    p.distance(a + t * chord)
}

/// The sizes of the clusters a run of `len` ≥ 2 points is cut into: `per` (≥ 3) each, the last
/// the rest, and never one point (a rest of one makes the last two clusters `per` − 1 and 2).
pub(crate) fn cluster_sizes(len: usize, per: usize) -> impl Iterator<Item = usize> {
    let per = per.max(3);
    let whole = len / per;
    let rest = len % per;
    let (whole, last) = match (whole, rest) {
        (0, _) => (0, len),
        (w, 1) => (w - 1, per + 1),
        (w, r) => (w, r),
    };
    // `last` may exceed `per` by one (per + 1 points): split it into per − 1 and 2.
    let tail: Vec<usize> = match last {
        0 => vec![],
        l if l > per => vec![per - 1, 2],
        l => vec![l],
    };
    std::iter::repeat_n(per, whole).chain(tail)
}

/// Per-vertex attributes of one page in its point order, as the GPU reads them.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct PageAttributes {
    /// Eight octant visibilities per point as unorm8 (object-space AO).
    pub octants: Option<Vec<[u8; 8]>>,
    /// The colormap's scalar.
    pub scalar: Option<Vec<f32>>,
    /// Tube radii as f16 bits (0: the chain's radius).
    pub radius: Option<Vec<u16>>,
}

/// One page's clusters on the CPU, before upload: points appended run by run.
#[derive(Default)]
pub(crate) struct PageBuilder {
    pub xy: Vec<u32>,
    pub z: Vec<u16>,
    pub records: Vec<ClusterRecord>,
    /// Per record, the box of the input points its strip draws (its own and the next
    /// cluster's first).
    pub boxes: Vec<(Vec3, Vec3)>,
    pub runs: Vec<RunMap>,
    /// Per record, its run's polyline.
    pub streamlines: Vec<u32>,
    /// The largest tolerance a point of this page was judged bent with.
    pub tolerance: f32,
    /// The box of its input points (min, max).
    pub corners: Option<(Vec3, Vec3)>,
    tangents: Vec<Vec3>,
}

impl PageBuilder {
    pub fn points(&self) -> usize {
        self.xy.len()
    }

    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// Appends a run of ≥ 2 finite points (input vertex `input` first), cut into clusters of at
    /// most `per_cluster` points, its points bent beyond `tolerance` (world units) marked.
    pub fn add_run(&mut self, run: &[[f32; 3]], input: u64, streamline: u32, per_cluster: usize, tolerance: f32) {
        debug_assert!(run.len() >= 2 && run.iter().all(|p| p.iter().all(|c| c.is_finite())));
        let page_first = self.xy.len() as u32;
        self.runs.push(RunMap { input, streamline, first: page_first, len: run.len() as u32 });
        self.tangents.clear();
        self.tangents.extend((0..run.len()).map(|k| vertex_tangent(run, k)));
        self.tolerance = self.tolerance.max(tolerance);
        let (mut lo, mut hi) = self.corners.unwrap_or((Vec3::INFINITY, Vec3::NEG_INFINITY));
        let first_record = self.records.len() as u32;
        let mut start = 0;
        let sizes: Vec<usize> = cluster_sizes(run.len(), per_cluster).collect();
        for (i, &count) in sizes.iter().enumerate() {
            let points = &run[start..start + count];
            let (min, max) = points.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                let p = Vec3::from_array(*p);
                (lo.min(p), hi.max(p))
            });
            (lo, hi) = (lo.min(min), hi.max(max));
            let longest = (max - min).max_element();
            let scale = longest / 65535.0;
            // f64: the step and the rounding stay exact whatever the magnitudes.
            let inverse = if scale > 0.0 { 1.0 / scale as f64 } else { 0.0 };
            for p in points {
                let q: [u16; 3] = std::array::from_fn(|a| {
                    ((p[a] as f64 - min[a] as f64) * inverse).round().clamp(0.0, 65535.0) as u16
                });
                self.xy.push(q[0] as u32 | (q[1] as u32) << 16);
                self.z.push(q[2]);
            }
            let joins_next = i + 1 < sizes.len();
            let drawn = count + joins_next as usize;
            // Inner points of the strip: run points start + 1 ..= start + drawn − 2, the k-th
            // at bit 7 + k.
            let bent = (1..drawn - 1)
                .filter(|&k| deviation(run, &self.tangents, start + k) > tolerance)
                .fold(0u32, |mask, k| mask | 1 << (flags::BENT_SHIFT + k as u32 - 1));
            let index = first_record + i as u32;
            let mut bits = count as u32 | bent;
            if i > 0 {
                bits |= flags::JOINS_PREVIOUS;
            }
            if joins_next {
                bits |= flags::JOINS_NEXT;
            }
            // The box of what its strip draws: its points and the next cluster's first.
            let joined = run.get(start + count).filter(|_| joins_next).map(|p| Vec3::from_array(*p));
            self.boxes.push(joined.map_or((min, max), |p| (min.min(p), max.max(p))));
            self.streamlines.push(streamline);
            self.records.push(ClusterRecord {
                origin: min.to_array(),
                scale,
                first: page_first + start as u32,
                flags: bits,
                previous: index.wrapping_sub(1),
                next: index + 1,
            });
            start += count;
        }
        self.corners = Some((lo, hi));
    }

    /// The page's arrays as uploaded: points packed (`z` two to a word), records sorted into
    /// their draw classes (their `previous`/`next` renumbered), and each class's range.
    pub fn finish(self) -> PageData {
        let mut order: Vec<u32> = (0..self.records.len() as u32).collect();
        // Within a class along a Morton curve, so that a group of consecutive records is a
        // small region of space (the cull tests groups first).
        let (lo, hi) = self.corners.unwrap_or((Vec3::ZERO, Vec3::ONE));
        let cell = 1023.0 / (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
        let morton = |(a, b): (Vec3, Vec3)| {
            let q = (((a + b) * 0.5 - lo) * cell).clamp(Vec3::ZERO, Vec3::splat(1023.0)).as_uvec3();
            (0..10).fold(0u32, |code, bit| {
                code | ((q.x >> bit) & 1) << (3 * bit)
                    | ((q.y >> bit) & 1) << (3 * bit + 1)
                    | ((q.z >> bit) & 1) << (3 * bit + 2)
            })
        };
        order.sort_by_key(|&i| (draw_class(&self.records[i as usize]), morton(self.boxes[i as usize])));
        let mut new_index = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            new_index[old as usize] = new as u32;
        }
        let records: Vec<ClusterRecord> = order
            .iter()
            .map(|&old| {
                let mut r = self.records[old as usize];
                if r.flags & flags::JOINS_PREVIOUS != 0 {
                    r.previous = new_index[r.previous as usize];
                } else {
                    r.previous = u32::MAX;
                }
                if r.flags & flags::JOINS_NEXT != 0 {
                    r.next = new_index[r.next as usize];
                } else {
                    r.next = u32::MAX;
                }
                r
            })
            .collect();
        let mut classes: [Range<u32>; DRAW_CLASSES] = Default::default();
        for (class, range) in classes.iter_mut().enumerate() {
            let start = records.partition_point(|r| draw_class(r) < class) as u32;
            let end = records.partition_point(|r| draw_class(r) <= class) as u32;
            *range = start..end;
        }
        let z = self.z.chunks(2).map(|pair| pair[0] as u32 | (*pair.get(1).unwrap_or(&0) as u32) << 16).collect();
        let groups = order
            .chunks(GROUP_CLUSTERS)
            .map(|members| {
                let (lo, hi) = members.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &old| {
                    let r = &self.records[old as usize];
                    // A decoded point lies within half a step of its input (on its own grid,
                    // or the next cluster's for the joined point), and f32's rounding of it.
                    let next = (r.flags & flags::JOINS_NEXT != 0).then(|| self.records[r.next as usize].scale);
                    let step = Vec3::splat(r.scale.max(next.unwrap_or(0.0)));
                    let (a, b) = self.boxes[old as usize];
                    (lo.min(a - step), hi.max(b + step))
                });
                let ulps = |v: Vec3| v.abs() * (4.0 * f32::EPSILON);
                let (lo, hi) = (lo - ulps(lo), hi + ulps(hi));
                [lo.x, lo.y, lo.z, 0.0, hi.x, hi.y, hi.z, 0.0]
            })
            .collect();
        let streamlines = order.iter().map(|&old| self.streamlines[old as usize]).collect();
        PageData { xy: self.xy, z, records, groups, classes, runs: self.runs, streamlines, tolerance: self.tolerance }
    }
}

/// A finished page's arrays ([`PageBuilder::finish`]).
pub(crate) struct PageData {
    pub xy: Vec<u32>,
    pub z: Vec<u32>,
    pub records: Vec<ClusterRecord>,
    /// Per group of [`GROUP_CLUSTERS`] consecutive records, the box (min, 0, max, 0) of
    /// every point their strips draw, as decoded.
    pub groups: Vec<[f32; 8]>,
    pub classes: [Range<u32>; DRAW_CLASSES],
    pub runs: Vec<RunMap>,
    /// Per record, its polyline.
    pub streamlines: Vec<u32>,
    pub tolerance: f32,
}

#[cfg(test)]
impl PageData {
    /// The quantized point `i` of the page.
    pub fn quantized(&self, i: u32) -> [u16; 3] {
        let w = self.xy[i as usize];
        let z = self.z[i as usize / 2] >> (16 * (i % 2));
        [w as u16, (w >> 16) as u16, z as u16]
    }

    /// Every point decoded, in page order (what the shaders draw).
    pub fn decoded(&self) -> Vec<[f32; 3]> {
        let mut out = vec![[0.0; 3]; self.xy.len()];
        for r in &self.records {
            for i in r.first..r.first + r.count() {
                out[i as usize] = r.decode(self.quantized(i));
            }
        }
        out
    }
}

/// The runs of polylines `positions[offsets[i]..offsets[i + 1]]`: maximal stretches of ≥ 2
/// consecutive finite points, with the input index of their first point, in order.
pub(crate) fn runs<'a>(positions: &'a [[f32; 3]], offsets: &'a [u64]) -> impl Iterator<Item = (u64, &'a [[f32; 3]])> {
    offsets.windows(2).flat_map(move |w| {
        let (first, last) = (w[0] as usize, w[1] as usize);
        let line = &positions[first..last];
        line.split(|p| !p.iter().all(|c| c.is_finite()))
            .filter(|run| run.len() >= 2)
            .map(move |run| ((first + (run.as_ptr() as usize - line.as_ptr() as usize) / 12) as u64, run))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn build(polylines: &[Vec<[f32; 3]>], per: usize) -> PageData {
        let tolerance = 1e-3;
        let mut page = PageBuilder::default();
        let mut input = 0u64;
        for line in polylines {
            page.add_run(line, input, 0, per, tolerance);
            input += line.len() as u64;
        }
        page.finish()
    }

    #[test]
    fn runs_never_leave_a_single_point_cluster() {
        for len in 2..200 {
            for per in [3, 4, 8, 16, 32] {
                let sizes: Vec<usize> = cluster_sizes(len, per).collect();
                assert_eq!(sizes.iter().sum::<usize>(), len, "len {len} per {per}");
                assert!(sizes.iter().all(|&s| (2..=per).contains(&s)), "len {len} per {per}: {sizes:?}");
            }
        }
    }

    #[test]
    fn runs_split_at_non_finite_points_and_drop_single_points() {
        let nan = f32::NAN;
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [nan, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [5.0, 0.0, 0.0], // first polyline ends
            [7.0, 7.0, 7.0], // a lone point
            [9.0, 9.0, 9.0],
            [f32::INFINITY, 0.0, 0.0],
        ];
        let found: Vec<(u64, usize)> = runs(&positions, &[0, 6, 7, 9]).map(|(i, r)| (i, r.len())).collect();
        assert_eq!(found, [(0, 2), (3, 3)]);
    }

    #[test]
    fn decoded_points_lie_within_their_clusters_bound() {
        // A helix of 1 000 points at three scales: 1 µm, 1 mm and 1 km across, the first at
        // the origin (where f32 resolves a micrometre), the others far from it.
        for (size, at) in [(1e-3f32, 0.0f32), (1.0, 250.0), (1e6, -3e6)] {
            let line: Vec<[f32; 3]> = (0..1000)
                .map(|i| {
                    let s = i as f32 / 999.0;
                    let a = s * 40.0;
                    [at + size * a.cos(), at + size * a.sin(), at + size * (2.0 * s - 1.0)]
                })
                .collect();
            let page = build(std::slice::from_ref(&line), 24);
            let decoded = page.decoded();
            for r in &page.records {
                let own = &line[r.first as usize..(r.first + r.count()) as usize];
                let (lo, hi) = own.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(Vec3::from_array(*p)), hi.max(Vec3::from_array(*p)))
                });
                let extent = (hi - lo).max_element();
                for (i, p) in own.iter().enumerate() {
                    let d = Vec3::from_array(decoded[r.first as usize + i]);
                    let error = (d - Vec3::from_array(*p)).abs().max_element();
                    // Half a step, and f32's rounding of a coordinate of this magnitude.
                    let ulp = Vec3::from_array(*p).abs().max_element() * f32::EPSILON;
                    assert!(error <= 1e-4 * extent + ulp, "size {size}: error {error:e} of extent {extent:e}");
                }
            }
        }
    }

    #[test]
    fn records_sort_into_classes_and_keep_their_neighbours() {
        // Runs of 70 (24 + 24 + 22), 3 and 25 (23 + 2) points, a zigzag among them.
        let line = |n: usize, zig: bool| -> Vec<[f32; 3]> {
            (0..n).map(|i| [i as f32, if zig && i % 2 == 1 { 1.0 } else { 0.0 }, 0.0]).collect()
        };
        let page = build(&[line(70, false), line(3, false), line(25, true)], 24);
        assert_eq!(page.records.len(), 3 + 1 + 2);
        for (class, range) in page.classes.iter().enumerate() {
            for r in &page.records[range.start as usize..range.end as usize] {
                assert_eq!(draw_class(r), class);
            }
            for r in &page.records[range.start as usize..range.end as usize] {
                assert!(r.alternating_vertices() <= alternating_vertices(class), "{r:?} in class {class}");
                assert!(2 * r.drawn() <= full_vertices(class), "{r:?} in class {class}");
            }
        }
        // Following `next` from each run's first cluster visits its points in order.
        let decoded = page.decoded();
        for (first, len) in [(0u32, 70u32), (70, 3), (73, 25)] {
            let mut c = page.records.iter().position(|r| r.first == first).unwrap();
            let mut seen = 0;
            loop {
                let r = page.records[c];
                assert_eq!(r.first, first + seen);
                seen += r.count();
                if r.flags & flags::JOINS_NEXT == 0 {
                    break;
                }
                assert_eq!(page.records[r.next as usize].previous as usize, c);
                c = r.next as usize;
            }
            assert_eq!(seen, len);
        }
        // The straight runs' clusters have no bent point; every inner point of the zigzag's is.
        for r in &page.records {
            let inner = r.drawn() - 2;
            assert_eq!(r.bent(), if r.first < 73 { 0 } else { inner }, "{r:?}");
        }
        // The 3-point run's middle point, 1 of its 2 units across: within half a step.
        assert!((decoded[71][0] - 1.0).abs() <= 2.0 / 65535.0 && decoded[71][1] == 0.0, "{:?}", decoded[71]);
    }
}
