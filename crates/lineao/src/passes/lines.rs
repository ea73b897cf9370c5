//! Line renderer: polylines at a fixed pixel width, the way LineAO expects them ("the intrinsic
//! fixed line width on screen", paper §2–3). wgpu has no wide lines, so each polyline is one
//! triangle strip whose vertices the vertex shader pushes half a line width to either side of
//! the curve (see `shaders/lines.wgsl`).
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
//!
//! Per pixel it writes the G-buffer of CONTRACT.md: base color, the ND map (n = (T × C) × T
//! normalized, facing the eye; normalized linear depth), the zoom map, the illuminated-lines
//! specular and hardware depth.

use std::sync::atomic::{AtomicU32, Ordering};

use glam::Vec3;

use crate::Error;
use crate::camera::{Bounds, FrameView};
use crate::gbuffer::{self, GeometryBindings, GeometryUniform, Load, PipelineSpec};
use crate::lighting::Lighting;
use crate::settings::LineColor;
use crate::targets::FrameTargets;
use crate::timing::Span;

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
    /// Also upload the index buffers [`LineStyle::Native1px`] draws from (8 bytes per segment).
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
struct Chunk {
    vertices: wgpu::Buffer,
    count: u32,
    segments: Option<(wgpu::Buffer, u32)>,
    /// The alternating strip's indices into `vertices` (see the module documentation).
    alternating: (wgpu::Buffer, u32),
    attributes: Option<wgpu::Buffer>,
}

/// Polylines uploaded to the GPU.
pub struct LineGeometry {
    chunks: Vec<Chunk>,
    /// Strip vertices per chunk at most (even).
    per_chunk: usize,
    /// How far (world units) a point may lie from the chord of its neighbours and still have
    /// one side in the alternating strip.
    tolerance: f32,
    /// Bounding sphere of the finite points; `None` when there are none.
    pub bounds: Option<Bounds>,
    pub vertices: usize,
    pub streamlines: usize,
    /// [`GeometryOptions::bounded_staging`], for later attribute uploads too.
    bounded_staging: bool,
}

/// The strip vertices of polylines `positions[offsets[i]..offsets[i + 1]]` (see the module
/// documentation), streamed to `emit` with the index of the point each one comes from; memory
/// beyond the longest polyline is never held.
fn strip_vertices(positions: &[[f32; 3]], offsets: &[u64], mut emit: impl FnMut(LinePoint, usize)) {
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
            }
            start = end;
        }
    }
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
        strip_vertices(positions, offsets, |v, _| chunker.push(v, &mut upload));
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
        })
    }

    /// Uploads per-vertex `attributes` for the polylines this geometry was made from (the same
    /// `positions` and `offsets`), replacing earlier ones: object-space AO computed after the
    /// upload, or recomputed with other settings, needs no new strip.
    pub fn set_attributes(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
        attributes: &VertexAttributes,
    ) -> Result<(), Error> {
        validate_offsets(offsets, positions.len())?;
        if positions.len() != self.vertices || offsets.len() != self.streamlines + 1 {
            return Err(Error::InvalidGeometry(format!(
                "attributes for {} vertices in {} streamlines, but the geometry has {} in {}",
                positions.len(),
                offsets.len() - 1,
                self.vertices,
                self.streamlines
            )));
        }
        let lengths = [
            ("octant visibilities", attributes.octants.map(<[_]>::len)),
            ("radii", attributes.radius.map(<[_]>::len)),
            ("scalars", attributes.scalar.map(<[_]>::len)),
        ];
        for (what, len) in lengths {
            if let Some(len) = len.filter(|&len| len != positions.len()) {
                return Err(Error::InvalidGeometry(format!("{len} {what} for {} vertices", positions.len())));
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
        let mut chunker = Chunker::new(self.per_chunk, 2 * positions.len() + 2 * offsets.len());
        strip_vertices(positions, offsets, |_, i| chunker.push(of(i), &mut upload));
        chunker.finish(&mut upload);
        if buffers.len() != self.chunks.len() {
            return Err(Error::InvalidGeometry("the polylines differ from the geometry's".into()));
        }
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
const MAX_TOLERANCE_PX: f32 = 0.25;
const MAX_ALTERNATING_WIDTH_PX: f32 = 8.0;
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

/// The most pixels one world unit can cover in `view` (at the near end of its depth range,
/// off axis up to the viewport's corners): the Jacobian of (f x / z, f y / z) has norm at most
/// f / z · √(1 + (x² + y²) / z²).
fn max_px_per_world(view: &FrameView) -> f32 {
    if view.orthographic {
        return view.f_px;
    }
    let guard = 2.0 * view.guard as f32;
    let half_diagonal = 0.5 * (view.width as f32 + guard).hypot(view.height as f32 + guard) / view.f_px;
    view.f_px / view.near * (1.0 + half_diagonal * half_diagonal).sqrt()
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

/// How segments are rasterized.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineStyle {
    /// Screen-aligned quads of the chain's line width (the paper's fixed-width lines), from the
    /// alternating strip where it stays within about half a pixel of the full one (see the
    /// module documentation), else the full strip.
    #[default]
    Quads,
    /// Quads always from the full strip: both sides of every point.
    FullStrip,
    /// The rasterizer's native 1-pixel lines (an indexed `LineList` over the same vertices),
    /// ignoring the line width: the cheapest way to put segments on screen, and the baseline
    /// `lineao bench` measures quads against. Needs geometry uploaded with
    /// [`GeometryOptions::native_lines`]; without it nothing is drawn.
    Native1px,
}

/// Renders [`LineGeometry`] into the G-buffer of [`FrameTargets`].
pub struct LineRenderer {
    style: LineStyle,
    pipeline: wgpu::RenderPipeline,
    /// With the geometry's attributes (the scalar's color), quads only.
    attributes: Option<wgpu::RenderPipeline>,
    /// Writing `octants` too: from the geometry's attributes, and fully visible for geometry
    /// without them.
    octants: Option<OctantPipelines>,
    bindings: GeometryBindings,
    /// The frame's [`max_px_per_world`] (f32 bits) when the alternating strip may be drawn
    /// (∞ otherwise), from [`LineRenderer::prepare`].
    px_per_world: AtomicU32,
}

/// The pipelines of a geometry pass that also writes the `octants` target.
pub(crate) struct OctantPipelines {
    pub attributes: wgpu::RenderPipeline,
    pub visible: wgpu::RenderPipeline,
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

impl LineRenderer {
    /// The renderer of fixed-width lines.
    pub fn new(device: &wgpu::Device) -> LineRenderer {
        Self::with_style(device, LineStyle::Quads)
    }

    pub fn with_style(device: &wgpu::Device, style: LineStyle) -> LineRenderer {
        Self::with_outputs(device, style, false)
    }

    /// With `octants`, targets that have an `octants` texture also get the geometry's
    /// per-vertex octant visibilities, interpolated ([`crate::passes::volume_ao`]); quads only.
    pub fn with_outputs(device: &wgpu::Device, style: LineStyle, octants: bool) -> LineRenderer {
        let bindings = GeometryBindings::new(device, "lineao::LineRenderer::bindings");
        let module = crate::shader::module(device, "lines.wgsl");
        // Octants at 0 and 4, the scalar at 12 (the tubes' radius at 8 is skipped).
        let octant_attributes = [
            wgpu::VertexAttribute { format: wgpu::VertexFormat::Unorm8x4, offset: 0, shader_location: 2 },
            wgpu::VertexAttribute { format: wgpu::VertexFormat::Unorm8x4, offset: 4, shader_location: 3 },
            wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32, offset: 12, shader_location: 5 },
        ];
        let strip = [Some(strip_layout(&STRIP_ATTRIBUTES))];
        let with_attributes = [Some(strip_layout(&STRIP_ATTRIBUTES)), Some(attribute_layout(&octant_attributes))];
        let topology = match style {
            LineStyle::Quads | LineStyle::FullStrip => wgpu::PrimitiveTopology::TriangleStrip,
            LineStyle::Native1px => wgpu::PrimitiveTopology::LineList,
        };
        let create = |label, vertex, fragment, buffers| {
            let octants = fragment == "fs_octants";
            gbuffer::pipeline(
                device,
                &bindings.layout,
                PipelineSpec { label, module: &module, vertex, fragment, buffers, topology, octants },
            )
        };
        let vertex = match style {
            LineStyle::Quads | LineStyle::FullStrip => "vs_main",
            LineStyle::Native1px => "vs_native",
        };
        let pipeline = create("lineao::LineRenderer::pipeline", vertex, "fs_main", &strip);
        let quads = style != LineStyle::Native1px;
        let attributes =
            quads.then(|| create("lineao::LineRenderer::attributes", "vs_attributes", "fs_main", &with_attributes));
        let octants = (octants && quads).then(|| OctantPipelines {
            attributes: create("lineao::LineRenderer::octants", "vs_octants", "fs_octants", &with_attributes),
            visible: create("lineao::LineRenderer::visible", "vs_visible", "fs_octants", &strip),
        });
        LineRenderer {
            style,
            pipeline,
            attributes,
            octants,
            bindings,
            px_per_world: AtomicU32::new(f32::INFINITY.to_bits()),
        }
    }

    /// Whether this renderer writes the `octants` target.
    pub fn writes_octants(&self) -> bool {
        self.octants.is_some()
    }

    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        view: &FrameView,
        line_width_px: f32,
        color: LineColor,
        lighting: &Lighting,
    ) {
        self.bindings.write(queue, &GeometryUniform::new(view, color, line_width_px, 0.0), lighting);
        let scale = if line_width_px <= MAX_ALTERNATING_WIDTH_PX { max_px_per_world(view) } else { f32::INFINITY };
        self.px_per_world.store(scale.to_bits(), Ordering::Relaxed);
    }

    /// Whether [`LineRenderer::encode`] draws `geometry` from the alternating strip in the frame
    /// of the last [`LineRenderer::prepare`].
    pub fn alternates(&self, geometry: &LineGeometry) -> bool {
        let scale = f32::from_bits(self.px_per_world.load(Ordering::Relaxed));
        self.style == LineStyle::Quads && geometry.tolerance * scale <= MAX_TOLERANCE_PX
    }

    /// Draws `geometry` into the G-buffer, clearing it first or over earlier passes (`load`),
    /// timed into `span` when given.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        load: Load,
        span: Option<Span>,
    ) {
        // The octants too when both the pipelines and the target exist.
        let octants = self.octants.as_ref().filter(|_| targets.octants.is_some());
        let mut pass = gbuffer::begin(encoder, "lineao::LineRenderer", targets, load, octants.is_some(), span);
        let attributes = geometry.has_attributes() && (octants.is_some() || self.attributes.is_some());
        pass.set_pipeline(match (octants, &self.attributes) {
            (Some(pipelines), _) if attributes => &pipelines.attributes,
            (Some(pipelines), _) => &pipelines.visible,
            (None, Some(pipeline)) if attributes => pipeline,
            _ => &self.pipeline,
        });
        pass.set_bind_group(0, &self.bindings.group, &[]);
        let alternates = self.alternates(geometry);
        for chunk in &geometry.chunks {
            pass.set_vertex_buffer(0, chunk.vertices.slice(..));
            if let (true, Some(buffer)) = (attributes, &chunk.attributes) {
                pass.set_vertex_buffer(1, buffer.slice(..));
            }
            match (self.style, &chunk.segments) {
                (LineStyle::Quads, _) if alternates => {
                    let (indices, count) = &chunk.alternating;
                    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..*count, 0, 0..1);
                }
                (LineStyle::Quads | LineStyle::FullStrip, _) => pass.draw(0..chunk.count, 0..1),
                (LineStyle::Native1px, Some((indices, count))) => {
                    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..*count, 0, 0..1);
                }
                (LineStyle::Native1px, None) => {}
            }
        }
    }
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
