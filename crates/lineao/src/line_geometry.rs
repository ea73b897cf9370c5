//! Polylines on the GPU, apart from any renderer: the strip vertex format, the strip built from
//! polylines, its split into buffers, the alternating strip, and the attributes uploaded beside
//! it. [`LineGeometry`] remembers which strip vertex belongs to which point (as runs of points),
//! so attributes are given per point and nothing else.
//!
//! The strip buffer holds every point twice (left, right) with its tangent (central difference,
//! snorm16); the sign of tangent.w says the side, its magnitude [`flags`](VertexFlags).
//! Consecutive polylines are joined by two repeated vertices, which make zero-area triangles the
//! rasterizer drops, so a whole tractogram is one draw per buffer. Offsetting along the *vertex*
//! tangent makes consecutive segments share their join corners exactly: joins without gaps or
//! overlaps. Polylines are split at non-finite points. Tractograms larger than one buffer are
//! split into chunks that overlap by two vertices (every triangle of the strip lies in one
//! chunk), each padded with two copies of its last vertex, so the tube renderer can bind it a
//! second time two vertices ahead (the next point of every vertex) and still draw all of it.
//!
//! Measured with `lineao bench` (1 M vertices, 1280 × 1024, lavapipe): the strip is 1.6× faster
//! than one instanced 4-vertex quad per segment, whose per-instance cost dominated.
//!
//! **The alternating strip.** The full strip costs two vertices and two triangles per segment,
//! where the rasterizer's own lines cost one vertex and one line (`lineao bench`: 1.41×
//! `lines-native-1px`). An index strip over the same vertex buffer takes one side per point,
//! left and right by turns (L0 R0 L1 R2 L3 R4 …, both sides at a run's ends): one vertex and one
//! triangle per segment (1.10×). Its left edge then runs from L1 to L3, past where L2 would be:
//! straight lines come out exact, a bend at point i moves the skipped edge by about the distance
//! δ_i of P_i from the chord P_(i−1) P_(i+1), and the turn of the tangents shifts the offsets.
//! So a point keeps both sides where δ_i exceeds a tolerance τ (world units, a fixed share of
//! the geometry's bounding radius) or its tangent turns more than 20° from a neighbour's, and a
//! frame uses the alternating strip only where τ times the most pixels a world unit can cover in
//! it is at most a quarter pixel and lines are at most 8 px wide: every edge within about half a
//! pixel of the full strip's. Zoomed in closer, the full strip is drawn.

use glam::Vec3;

use crate::Error;
use crate::camera::Bounds;

/// One vertex of the strip buffer. Keep in sync with `StripVertex` in `shaders/lines.wgsl` and
/// `shaders/tubes.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LinePoint {
    pub position: [f32; 3],
    /// Unit world-space tangent (xyz) as snorm16. w: the side (+ left, − right) times
    /// [`FLAG_UNIT`] · (1 + [`VertexFlags`]).
    pub tangent: [i16; 4],
}

/// What a strip vertex's point is to its run of segments, as bits.
pub struct VertexFlags;

impl VertexFlags {
    /// A segment to the next point starts here.
    pub const SEGMENT: u16 = 1;
    /// The first point of a run (tubes extend their cap backward).
    pub const RUN_START: u16 = 2;
    /// The last point of a run (tubes extend their cap forward).
    pub const RUN_END: u16 = 4;
}

/// The step of tangent.w per flag value (snorm16: flags up to 7 fit below 32767).
pub const FLAG_UNIT: i16 = 4000;

impl LinePoint {
    fn encoded(self, left: bool, flags: u16) -> LinePoint {
        let w = FLAG_UNIT * (1 + flags as i16);
        LinePoint { tangent: [self.tangent[0], self.tangent[1], self.tangent[2], if left { w } else { -w }], ..self }
    }

    /// The side (+1 left, −1 right) and the flags of an encoded vertex.
    pub fn side_and_flags(&self) -> (i16, u16) {
        let w = self.tangent[3];
        (w.signum(), (w.unsigned_abs() / FLAG_UNIT as u16).saturating_sub(1))
    }
}

pub(crate) const POINT_SIZE: u64 = std::mem::size_of::<LinePoint>() as u64;

/// Default upper bound of one vertex buffer: below every adapter's buffer limit, and few
/// enough chunks for the paper's 11 M-vertex tractogram (440 MB of strip).
pub const DEFAULT_CHUNK_BYTES: u64 = 128 << 20;

fn snorm16(v: f32) -> i16 {
    (v.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

/// Checks that `offsets` (N + 1 entries, first 0, non-decreasing, last = vertex count) describe
/// polylines over `vertices` points.
pub fn validate_offsets(offsets: &[u64], vertices: usize) -> Result<(), Error> {
    let bad = |what: String| Err(Error::InvalidGeometry(what));
    match (offsets.first(), offsets.last()) {
        (None, _) => return bad("offsets must have N + 1 entries, got none".into()),
        (Some(&first), _) if first != 0 => return bad(format!("offsets must start at 0, got {first}")),
        (_, Some(&last)) if last != vertices as u64 => {
            return bad(format!("offsets must end at the vertex count {vertices}, got {last}"));
        }
        _ => {}
    }
    if let Some(i) = offsets.windows(2).position(|w| w[1] < w[0]) {
        return bad(format!("offsets decrease at streamline {i}: {} then {}", offsets[i], offsets[i + 1]));
    }
    Ok(())
}

/// The points of one polyline with their tangents (central differences), w = 1 where a segment
/// to the next point starts (both finite), appended to `out` (not yet encoded).
fn polyline_points(line: &[[f32; 3]], out: &mut Vec<LinePoint>) {
    let at = |k: usize| Vec3::from_array(line[k]);
    for k in 0..line.len() {
        let prev = at(k.saturating_sub(1));
        let next = at((k + 1).min(line.len() - 1));
        let tangent = [next - prev, next - at(k), at(k) - prev]
            .into_iter()
            .map(|t| t.normalize_or_zero())
            .find(|t| t != &Vec3::ZERO && t.is_finite())
            .unwrap_or(Vec3::X);
        let starts_segment = k + 1 < line.len() && at(k).is_finite() && at(k + 1).is_finite();
        out.push(LinePoint {
            position: line[k],
            tangent: [snorm16(tangent.x), snorm16(tangent.y), snorm16(tangent.z), starts_segment as i16],
        });
    }
}

/// How [`LineGeometry`] is uploaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GeometryOptions {
    /// Upper bound of one vertex buffer in bytes (further capped by the device's limit).
    pub chunk_bytes: u64,
    /// Also upload the index buffers [`LineStyle::Native1px`](crate::passes::lines::LineStyle::Native1px) draws from (8 bytes per segment).
    pub native_lines: bool,
    /// Wait for the device after each chunk, so that each chunk's staging copy is freed before
    /// the next is made: 11 M vertices peak at 1.4 GB instead of 2.1 GB. It waits for whatever
    /// the device is doing, so a host's render loop leaves it off (the default: uploads never
    /// wait); a tool loading a huge file on its own device turns it on.
    pub bounded_staging: bool,
}

impl Default for GeometryOptions {
    fn default() -> Self {
        GeometryOptions { chunk_bytes: DEFAULT_CHUNK_BYTES, native_lines: false, bounded_staging: false }
    }
}

/// After a chunk's upload: submit its writes and wait for the device
/// ([`GeometryOptions::bounded_staging`]), or leave the writes to the caller's next submission
/// and only let the device reclaim what it has finished. (No submission either: on lavapipe a
/// submission waits for the frame before it, measured by the test
/// `prepare_encode_and_upload_do_not_wait_for_the_device`.)
fn settle(device: &wgpu::Device, queue: &wgpu::Queue, bounded_staging: bool) -> Result<(), Error> {
    let poll = if bounded_staging {
        queue.submit([]);
        wgpu::PollType::wait_indefinitely()
    } else {
        wgpu::PollType::Poll
    };
    device.poll(poll).map(|_| ()).map_err(|e| Error::Gpu(e.to_string()))
}

/// One vertex buffer of the strip and, on request, the segments of native lines within it and
/// the vertices' attributes.
pub(crate) struct Chunk {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) count: u32,
    pub(crate) segments: Option<(wgpu::Buffer, u32)>,
    /// The alternating strip's indices into `vertices` (see the module documentation).
    pub(crate) alternating: (wgpu::Buffer, u32),
    pub(crate) attributes: Option<wgpu::Buffer>,
}

/// Polylines uploaded to the GPU.
pub struct LineGeometry {
    pub(crate) chunks: Vec<Chunk>,
    /// Strip vertices per chunk at most (even).
    per_chunk: usize,
    /// How far (world units) a point may lie from the chord of its neighbours and still have
    /// one side in the alternating strip.
    pub(crate) tolerance: f32,
    /// Bounding sphere of the finite points; `None` when there are none.
    pub bounds: Option<Bounds>,
    pub vertices: usize,
    pub streamlines: usize,
    /// [`GeometryOptions::bounded_staging`], for later attribute uploads too.
    bounded_staging: bool,
    /// The strip's runs of points (first point, count), in strip order: which strip vertex
    /// belongs to which point, 8 bytes per run (about one per streamline).
    runs: Vec<Run>,
}

/// Points `first..first + len` of the geometry's positions, joined by segments: one run of the
/// strip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Run {
    first: u32,
    len: u32,
}

/// The point of each strip vertex, in strip order, from the runs alone: what
/// [`strip_vertices`] emits as its second argument.
fn strip_points(runs: &[Run], mut emit: impl FnMut(usize)) {
    let mut previous = None;
    for run in runs {
        let (first, len) = (run.first as usize, run.len as usize);
        if let Some(last) = previous {
            emit(last);
            emit(first);
        }
        for k in first..first + len {
            emit(k);
            emit(k);
        }
        previous = Some(first + len - 1);
    }
}

/// The strip vertices of polylines `positions[offsets[i]..offsets[i + 1]]` (see the module
/// documentation), streamed to `emit` with the index of the point each one comes from; memory
/// beyond the longest polyline is never held. Returns the runs ([`strip_points`]).
fn strip_vertices(positions: &[[f32; 3]], offsets: &[u64], mut emit: impl FnMut(LinePoint, usize)) -> Vec<Run> {
    let mut runs = Vec::new();
    let mut points = Vec::new();
    let mut previous: Option<(LinePoint, usize)> = None;
    for range in offsets.windows(2) {
        let first = range[0] as usize;
        points.clear();
        polyline_points(&positions[first..range[1] as usize], &mut points);
        // Runs of points joined by segments (w = 1 on all but a run's last point).
        let mut start = 0;
        while start < points.len() {
            let end = points[start..].iter().position(|p| p.tangent[3] == 0).map_or(points.len(), |k| start + k + 1);
            let run = &points[start..end];
            if run.len() >= 2 {
                let encode = |k: usize, left: bool| {
                    let mut flags = 0;
                    if k + 1 < run.len() {
                        flags |= VertexFlags::SEGMENT;
                    }
                    if k == 0 {
                        flags |= VertexFlags::RUN_START;
                    }
                    if k + 1 == run.len() {
                        flags |= VertexFlags::RUN_END;
                    }
                    run[k].encoded(left, flags)
                };
                // Two repeated vertices join this run to the previous one: zero-area triangles.
                if let Some((last, index)) = previous {
                    emit(last, index);
                    emit(encode(0, true), first + start);
                }
                for k in 0..run.len() {
                    emit(encode(k, true), first + start + k);
                    emit(encode(k, false), first + start + k);
                }
                previous = Some((encode(run.len() - 1, false), first + end - 1));
                runs.push(Run { first: (first + start) as u32, len: run.len() as u32 });
            }
            start = end;
        }
    }
    runs
}

/// Splits a stream of strip vertices into chunks of at most `per_chunk` (even) that overlap by
/// two vertices, so every triangle lies in one chunk; the vertex and attribute streams of one
/// geometry split identically.
struct Chunker<T> {
    per_chunk: usize,
    current: Vec<T>,
}

impl<T: Copy> Chunker<T> {
    fn new(per_chunk: usize, expected: usize) -> Chunker<T> {
        Chunker { per_chunk, current: Vec::with_capacity(per_chunk.min(expected)) }
    }

    fn push(&mut self, value: T, flush: &mut impl FnMut(&[T])) {
        if self.current.len() == self.per_chunk {
            flush(&self.current);
            self.current.drain(..self.per_chunk - 2);
        }
        self.current.push(value);
    }

    /// The last chunk, if it holds a triangle.
    fn finish(self, flush: &mut impl FnMut(&[T])) {
        if self.current.len() >= 3 {
            flush(&self.current);
        }
    }
}

/// Per-vertex data uploaded beside the positions ([`LineGeometry::set_attributes`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct VertexAttributes<'a> {
    /// Visibility of each octant of directions, in [0, 1], indexed as
    /// [`crate::volume::octant_signs`]: object-space AO ([`crate::volume`]), which
    /// [`crate::passes::volume_ao`] turns into occlusion with the pixel's normal. `None`: fully
    /// visible.
    pub octants: Option<&'a [[f32; 8]]>,
    /// Tube radius per vertex, world units (> 0; others take the chain's radius): tubes of
    /// varying thickness ([`crate::passes::tubes`]). Lines ignore it.
    pub radius: Option<&'a [f32]>,
    /// A scalar per vertex for [`crate::LineColor::Scalar`] (FA, curvature, …). `None`: 0.
    pub scalar: Option<&'a [f32]>,
}

/// One strip vertex's attributes. Keep in sync with `Attributes` in `shaders/lines.wgsl` and
/// `shaders/tubes.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LineAttributes {
    /// The eight octant visibilities as unorm8.
    pub octants: [u8; 8],
    /// Tube radius, world units; 0 = the chain's.
    pub radius: f32,
    /// The colormap's scalar.
    pub scalar: f32,
}

pub(crate) const ATTRIBUTE_SIZE: u64 = std::mem::size_of::<LineAttributes>() as u64;

impl LineGeometry {
    /// Uploads polylines `positions[offsets[i]..offsets[i + 1]]` (world units) without waiting
    /// for the device: the buffers are written through the queue and usable by the next
    /// submission. For a huge file on a device of its own, [`GeometryOptions::bounded_staging`]
    /// waits after each buffer instead, so that peak memory is the strip plus one buffer, not
    /// twice the strip.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
    ) -> Result<LineGeometry, Error> {
        Self::with_options(device, queue, positions, offsets, GeometryOptions::default())
    }

    pub fn with_options(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
        options: GeometryOptions,
    ) -> Result<LineGeometry, Error> {
        validate_offsets(offsets, positions.len())?;
        let limit = options.chunk_bytes.min(device.limits().max_buffer_size);
        // Even, so that every chunk starts at an even strip position: a triangle then keeps the
        // vertex order (and so the exact interpolation) it has in one long strip. Two vertices
        // of padding follow. The attribute stream splits at the same vertices, so its buffers
        // must fit the same count.
        let per_chunk = (limit / POINT_SIZE).saturating_sub(2).max(4) as usize & !1;
        let bounds = Bounds::of_points(positions);
        let tolerance = bounds.map_or(0.0, |b| b.radius * TOLERANCE_PER_RADIUS);
        let mut chunks = Vec::new();
        let mut failed = None;
        let mut upload = |vertices: &[LinePoint]| {
            let chunk = Chunk {
                vertices: upload_padded(device, queue, "lineao::LineGeometry::strip", vertices),
                count: vertices.len() as u32,
                segments: options.native_lines.then(|| native_segments(device, queue, vertices)),
                alternating: alternating_buffer(device, queue, vertices, tolerance),
                attributes: None,
            };
            if let Err(e) = settle(device, queue, options.bounded_staging) {
                failed.get_or_insert(e);
            }
            chunks.push(chunk);
        };
        let mut chunker = Chunker::new(per_chunk, 2 * positions.len() + 2 * offsets.len());
        let runs = strip_vertices(positions, offsets, |v, _| chunker.push(v, &mut upload));
        chunker.finish(&mut upload);
        if let Some(error) = failed {
            return Err(error);
        }
        Ok(LineGeometry {
            chunks,
            per_chunk,
            tolerance,
            bounds,
            vertices: positions.len(),
            streamlines: offsets.len() - 1,
            bounded_staging: options.bounded_staging,
            runs,
        })
    }

    /// Uploads per-vertex `attributes` (one entry per point the geometry was made from),
    /// replacing earlier ones: object-space AO computed after the upload, or recomputed with
    /// other settings, needs no new strip, and the caller need not keep the polylines.
    pub fn set_attributes(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        attributes: &VertexAttributes,
    ) -> Result<(), Error> {
        let lengths = [
            ("octant visibilities", attributes.octants.map(<[_]>::len)),
            ("radii", attributes.radius.map(<[_]>::len)),
            ("scalars", attributes.scalar.map(<[_]>::len)),
        ];
        for (what, len) in lengths {
            if let Some(len) = len.filter(|&len| len != self.vertices) {
                return Err(Error::InvalidGeometry(format!("{len} {what} for {} vertices", self.vertices)));
            }
        }
        let unorm = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        let radius = |r: f32| if r.is_finite() && r > 0.0 { r } else { 0.0 };
        let of = |i: usize| LineAttributes {
            octants: attributes.octants.map_or([255; 8], |o| o[i].map(unorm)),
            radius: attributes.radius.map_or(0.0, |r| radius(r[i])),
            scalar: attributes.scalar.map_or(0.0, |s| s[i]),
        };
        let mut buffers = Vec::with_capacity(self.chunks.len());
        let mut upload = |values: &[LineAttributes]| {
            buffers.push(upload_padded(device, queue, "lineao::LineGeometry::attributes", values))
        };
        // Buffers of the same vertex count as the strip's, at most the strip's bytes.
        let mut chunker = Chunker::new(self.per_chunk, 2 * self.vertices + 2 * self.runs.len());
        strip_points(&self.runs, |i| chunker.push(of(i), &mut upload));
        chunker.finish(&mut upload);
        debug_assert_eq!(buffers.len(), self.chunks.len(), "the runs give the strip's chunks");
        for (chunk, buffer) in self.chunks.iter_mut().zip(buffers) {
            chunk.attributes = Some(buffer);
        }
        settle(device, queue, self.bounded_staging)
    }

    /// Each chunk's strip buffer (padded), its vertex count and its attribute buffer.
    pub(crate) fn chunk_buffers(&self) -> impl Iterator<Item = (&wgpu::Buffer, u32, Option<&wgpu::Buffer>)> {
        self.chunks.iter().map(|c| (&c.vertices, c.count, c.attributes.as_ref()))
    }

    /// Whether [`LineGeometry::set_attributes`] gave every chunk attributes.
    pub fn has_attributes(&self) -> bool {
        self.chunks.iter().all(|c| c.attributes.is_some())
    }

    /// Number of vertex buffers the strip was split into.
    pub fn chunk_count(&self) -> usize {
        self.chunks.len()
    }
}

/// Index pairs (left vertex of a point, left vertex of the next) of the segments that lie
/// within `vertices`: a segment across a chunk border is in the next chunk, which repeats the
/// last two vertices. (A join's repeated left vertex also says SEGMENT, but two vertices on
/// lies a right vertex, not its point's next left one.)
fn native_segments(device: &wgpu::Device, queue: &wgpu::Queue, vertices: &[LinePoint]) -> (wgpu::Buffer, u32) {
    let starts = |i: usize| {
        let ((side, flags), (next_side, _)) = (vertices[i].side_and_flags(), vertices[i + 2].side_and_flags());
        side > 0 && flags & VertexFlags::SEGMENT != 0 && next_side > 0
    };
    let indices: Vec<u32> =
        (0..vertices.len().saturating_sub(2)).filter(|&i| starts(i)).flat_map(|i| [i as u32, i as u32 + 2]).collect();
    index_buffer(device, queue, "lineao::LineGeometry::segments", &indices)
}

/// An index buffer of `indices` (one unused index when there are none: buffers are never
/// empty) and their count.
fn index_buffer(device: &wgpu::Device, queue: &wgpu::Queue, label: &str, indices: &[u32]) -> (wgpu::Buffer, u32) {
    let contents = if indices.is_empty() { &[0][..] } else { indices };
    (upload_buffer(device, queue, label, wgpu::BufferUsages::INDEX, contents), indices.len() as u32)
}

/// τ over the bounding radius: a view that shows the whole bounding sphere across 2 000 px
/// covers about 2 000 / (2 radius) px per world unit, so τ is about 0.12 px there.
const TOLERANCE_PER_RADIUS: f32 = 1.0 / 8192.0;
/// The cosine of the largest turn between neighbouring tangents that keeps one side (20°).
const MAX_TURN_COS: f32 = 0.9397;
/// The alternating strip's budget: τ on screen, and the widest lines (a turn of 20° moves a
/// skipped offset by at most (1 − cos 20°) · width / 2 ≈ 0.24 px at 8 px).
pub(crate) const MAX_TOLERANCE_PX: f32 = 0.25;
pub(crate) const MAX_ALTERNATING_WIDTH_PX: f32 = 8.0;
/// Ends an index strip; the next index starts a new one.
const RESTART: u32 = u32::MAX;

/// The alternating strip over a chunk's strip `vertices` (see the module documentation): per
/// run of segments, both sides of its first point, then one side per point by turns, both sides
/// where the point lies more than `tolerance` from the chord of its neighbours or its tangent
/// turns more than 20° from theirs, both sides of its last point; runs separated by restarts.
/// Points are the pairs at even positions (left, right); a pair that starts on the right side is
/// the join between two polylines.
pub(crate) fn alternating_strip(vertices: &[LinePoint], tolerance: f32) -> Vec<u32> {
    let points = vertices.len() / 2;
    let is_point = |k: usize| vertices[2 * k].side_and_flags().0 > 0;
    let continues = |k: usize| vertices[2 * k].side_and_flags().1 & VertexFlags::SEGMENT != 0;
    let position = |k: usize| Vec3::from_array(vertices[2 * k].position);
    // Unit tangents as snorm16 (their rounding, 3e-5, is far below the turn's threshold).
    let tangent = |k: usize| {
        let [x, y, z, _] = vertices[2 * k].tangent;
        Vec3::new(x as f32, y as f32, z as f32) / 32767.0
    };
    let bends = |k: usize| {
        let (a, p, b) = (position(k - 1), position(k), position(k + 1));
        let chord = b - a;
        let t = if chord.length_squared() > 0.0 {
            ((p - a).dot(chord) / chord.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let t_k = tangent(k);
        p.distance(a + t * chord) > tolerance
            || t_k.dot(tangent(k - 1)) < MAX_TURN_COS
            || t_k.dot(tangent(k + 1)) < MAX_TURN_COS
    };
    let mut out = Vec::with_capacity(points + points / 8);
    let mut k = 0;
    while k < points {
        if !is_point(k) {
            k += 1;
            continue;
        }
        let first = k;
        while k + 1 < points && continues(k) && is_point(k + 1) {
            k += 1;
        }
        let last = k;
        k += 1;
        if last == first {
            continue;
        }
        if !out.is_empty() {
            out.push(RESTART);
        }
        // Sides by turns: after both sides of a point the same side comes next.
        let mut left = true;
        let mut side = |point: usize, out: &mut Vec<u32>| {
            out.push((2 * point + !left as usize) as u32);
            left = !left;
        };
        for point in first..=last {
            side(point, &mut out);
            if point == first || point == last || bends(point) {
                side(point, &mut out);
            }
        }
    }
    out
}

/// The index buffer of [`alternating_strip`] and its length.
fn alternating_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    vertices: &[LinePoint],
    tolerance: f32,
) -> (wgpu::Buffer, u32) {
    index_buffer(device, queue, "lineao::LineGeometry::alternating", &alternating_strip(vertices, tolerance))
}

/// A vertex buffer of `values` and two more copies of the last (see the module documentation).
fn upload_padded<T: bytemuck::Pod>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    values: &[T],
) -> wgpu::Buffer {
    let last = *values.last().expect("a chunk holds a triangle");
    let padded: Vec<T> = values.iter().copied().chain([last, last]).collect();
    upload_buffer(device, queue, label, wgpu::BufferUsages::VERTEX, &padded)
}

/// A buffer of `usage` holding `contents`, written through the queue (visible to the next
/// submission).
fn upload_buffer<T: bytemuck::Pod>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    usage: wgpu::BufferUsages,
    contents: &[T],
) -> wgpu::Buffer {
    let bytes: &[u8] = bytemuck::cast_slice(contents);
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.len() as u64,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&buffer, 0, bytes);
    buffer
}

/// The strip's vertex layout (slot 0; `shader_location`s 0, 1).
pub(crate) const STRIP_ATTRIBUTES: [wgpu::VertexAttribute; 2] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Snorm16x4];

pub(crate) fn strip_layout(attributes: &[wgpu::VertexAttribute]) -> wgpu::VertexBufferLayout<'_> {
    wgpu::VertexBufferLayout { array_stride: POINT_SIZE, step_mode: wgpu::VertexStepMode::Vertex, attributes }
}

pub(crate) fn attribute_layout(attributes: &[wgpu::VertexAttribute]) -> wgpu::VertexBufferLayout<'_> {
    wgpu::VertexBufferLayout { array_stride: ATTRIBUTE_SIZE, step_mode: wgpu::VertexStepMode::Vertex, attributes }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The strip vertices of `polylines`.
    fn strip(polylines: &[&[[f32; 3]]]) -> Vec<LinePoint> {
        let positions: Vec<[f32; 3]> = polylines.iter().flat_map(|line| line.iter().copied()).collect();
        let mut offsets = vec![0u64];
        for line in polylines {
            offsets.push(offsets.last().unwrap() + line.len() as u64);
        }
        let mut vertices = Vec::new();
        strip_vertices(&positions, &offsets, |v, _| vertices.push(v));
        vertices
    }

    /// The runs alone give every strip vertex's point, as building the strip does: across
    /// polylines, runs split at non-finite points, single points and empty polylines.
    #[test]
    fn runs_give_each_strip_vertex_its_point() {
        let nan = f32::NAN;
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.5, 0.0], // a polyline of 3
            [5.0, 5.0, 5.0], // a lone point: no run
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [nan, 0.0, 0.0],
            [3.0, 1.0, 0.0],
            [4.0, 1.0, 0.0],
            [5.0, 2.0, 0.0],
            [9.0, 9.0, 9.0],
            [9.0, 9.0, 8.0],
        ];
        let offsets = [0u64, 3, 4, 4, 10, 12];
        let mut from_positions = Vec::new();
        let runs = strip_vertices(&positions, &offsets, |_, i| from_positions.push(i));
        let mut from_runs = Vec::new();
        strip_points(&runs, |i| from_runs.push(i));
        assert_eq!(from_runs, from_positions);
        assert_eq!(runs.len(), 4, "{runs:?}");
        assert!(from_positions.len() > 2 * 10);
    }

    #[test]
    fn a_straight_run_takes_one_side_per_point_by_turns() {
        let line: Vec<[f32; 3]> = (0..5).map(|i| [i as f32, 0.0, 0.0]).collect();
        // L0 R0 | L1 R2 L3 | R4 L4 (L_k = 2k, R_k = 2k + 1): one triangle per segment and one more.
        assert_eq!(alternating_strip(&strip(&[&line]), 1e-3), [0, 1, 2, 5, 6, 9, 8]);
    }

    #[test]
    fn bends_keep_both_sides_and_polylines_restart() {
        // A right angle at point 2, then a second polyline: the join's two vertices (10 and 11)
        // are skipped, and the runs are separate strips.
        let bent = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [2.0, 2.0, 0.0]];
        let straight = [[0.0, 5.0, 0.0], [1.0, 5.0, 0.0], [2.0, 5.0, 0.0]];
        let vertices = strip(&[&bent, &straight]);
        assert_eq!(vertices.len(), 2 * 8 + 2);
        let indices = alternating_strip(&vertices, 1e-3);
        // The corner and its neighbours (their tangents turn 45°) keep both sides: the full strip.
        assert_eq!(&indices[..11], [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, RESTART]);
        assert_eq!(&indices[11..], [12, 13, 14, 17, 16]);
        // A gentle bend within the tolerance keeps one side.
        let gentle = [[0.0, 0.0, 0.0], [1.0, 0.001, 0.0], [2.0, 0.0, 0.0]];
        assert_eq!(alternating_strip(&strip(&[&gentle]), 1e-2), [0, 1, 2, 5, 4]);
        assert_eq!(alternating_strip(&strip(&[&gentle]), 1e-4), [0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn runs_split_at_non_finite_points_and_single_points_draw_nothing() {
        let line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [3.0, 0.0, 0.0], [4.0, 0.0, 0.0]];
        let vertices = strip(&[&line]);
        let indices = alternating_strip(&vertices, 1e-3);
        assert_eq!(indices.iter().filter(|&&i| i == RESTART).count(), 1);
        assert!(indices.iter().all(|&i| i == RESTART || (i as usize) < vertices.len()));
        assert!(alternating_strip(&strip(&[&[[0.0; 3]]]), 1e-3).is_empty());
    }
}
