//! Polylines on the GPU, apart from any renderer: [`LineGeometry`] holds them as **clusters**
//! ([`clusters`](self) module: every point once, 16 bits per axis on its cluster's grid, 6
//! bytes, and a 32-byte record per cluster of ≤ 32 points) that the line and tube renderers'
//! vertex shaders *pull* from storage buffers: no strip, no index buffer. A whole-brain
//! tractogram of 100 M points takes 0.7 GB where the strip of earlier versions took 4 GB.
//!
//! Clusters live in **pages**: one bind group each, of at most [`GeometryOptions::page_bytes`]
//! per buffer (and the device's binding limit), holding whole runs. A geometry grows by
//! [`LineGeometry::append`] — a file's streamlines chunk by chunk as they are read — and each
//! full page is uploaded at once; [`LineGeometry::flush`] uploads what is pending (so a viewer
//! draws what has arrived) and [`LineGeometry::finish`] also makes the bounds exact. Where
//! every cluster of a page is drawn, a CPU adapter draws it in batches of 256 k points
//! ([`LineGeometry::draw_batches`]), so a page's size is about bindings and uploads alone.
//!
//! **The alternating strip.** The full strip costs two vertices and two triangles per segment,
//! where the rasterizer's own lines cost one vertex and one line. The alternating strip takes
//! one side per point, left and right by turns (L0 R0 L1 R2 L3 R4 …, both sides at a strip's
//! ends): one vertex and one triangle per segment. Its left edge then runs from L1 to L3, past
//! where L2 would be: straight lines come out exact, a bend at point i moves the skipped edge
//! by about the distance δ_i of P_i from the chord P_(i−1) P_(i+1), and the turn of the tangents
//! shifts the offsets. So a point keeps both sides where δ_i exceeds a tolerance τ (world
//! units: [`GeometryOptions::tolerance`], by default a fixed share of the geometry's bounding
//! radius) or its tangent turns more than 20° from a neighbour's, and a frame uses the
//! alternating strip only where τ times the most pixels a world unit can cover in it is at most
//! a quarter pixel and lines are at most 8 px wide: every edge within about half a pixel of the
//! full strip's. Zoomed in closer, the full strip is drawn.

mod clusters;
#[cfg(feature = "reference")]
pub mod strip;

use std::ops::Range;

use glam::Vec3;

use crate::Error;
use crate::camera::Bounds;
pub use clusters::{CLUSTER_POINTS, ClusterRecord, GROUP_CLUSTERS, PIECE_SEGMENTS};
pub(crate) use clusters::{DRAW_CLASSES, alternating_vertices, class_segments, full_vertices};
use clusters::{PageAttributes, PageBuilder, PageData, RECORD_SIZE, RunMap};

/// Default upper bound of one page's largest buffer (its octant visibilities, 8 bytes a
/// point): 16 M points a page.
pub const DEFAULT_PAGE_BYTES: u64 = 128 << 20;

/// Points one draw of every cluster covers at most on a CPU adapter ([`LineGeometry::draw_batches`]):
/// lavapipe bins a draw's primitives before it rasterizes them, and a draw of 256 k points keeps
/// its points, records and bins in the caches.
const CPU_DRAW_BATCH_POINTS: u32 = 256 << 10;

/// `instances` in consecutive runs of at most `step` (at least one).
fn batches(instances: Range<u32>, step: u32) -> impl Iterator<Item = Range<u32>> {
    let step = step.max(1);
    instances.clone().step_by(step as usize).map(move |start| start..start.saturating_add(step).min(instances.end))
}

/// τ over the bounding radius: a view that shows the whole bounding sphere across 2 000 px
/// covers about 2 000 / (2 radius) px per world unit, so τ is about 0.12 px there.
const TOLERANCE_PER_RADIUS: f32 = 1.0 / 8192.0;
/// The alternating strip's budget: τ on screen, and the widest lines (a turn of 20° moves a
/// skipped offset by at most (1 − cos 20°) · width / 2 ≈ 0.24 px at 8 px).
pub(crate) const MAX_TOLERANCE_PX: f32 = 0.25;
pub(crate) const MAX_ALTERNATING_WIDTH_PX: f32 = 8.0;

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

/// A tube radius as the geometry stores it (f16, 0 where it is not positive and finite: the
/// chain's radius then): what the tube renderer draws for `radius`.
pub fn stored_radius(radius: f32) -> f32 {
    if radius.is_finite() && radius > 0.0 { half::f16::from_f32(radius).to_f32() } else { 0.0 }
}

/// How [`LineGeometry`] is uploaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeometryOptions {
    /// Upper bound of a page's largest buffer in bytes, further capped by the device's buffer
    /// and storage-binding limits: how many points one bind group holds.
    pub page_bytes: u64,
    /// The most points of a cluster (3 to [`CLUSTER_POINTS`]).
    pub cluster_points: u32,
    /// How far (world units) a point may lie from the chord of its neighbours and still take
    /// one side in the alternating strip (τ; see the module documentation). `None`: a fixed
    /// share of the bounding radius — the geometry's for [`LineGeometry::with_options`], the
    /// box's so far for [`LineGeometry::append`], which then depends on how the chunks fall; a
    /// host that appends chunks and wants the same pixels however they fall sets it.
    pub tolerance: Option<f32>,
    /// Wait for the device after each page, so that each page's staging copy is freed before
    /// the next is made. It waits for whatever the device is doing, so a host's render loop
    /// leaves it off (the default: uploads never wait); a tool loading a huge file on its own
    /// device turns it on.
    pub bounded_staging: bool,
}

impl Default for GeometryOptions {
    fn default() -> Self {
        GeometryOptions {
            page_bytes: DEFAULT_PAGE_BYTES,
            cluster_points: CLUSTER_POINTS,
            tolerance: None,
            bounded_staging: false,
        }
    }
}

/// Per-vertex data drawn with the positions ([`LineGeometry::set_attributes`],
/// [`LineGeometry::append_with`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct VertexAttributes<'a> {
    /// Visibility of each octant of directions, in [0, 1], indexed as
    /// [`crate::volume::octant_signs`]: object-space AO ([`crate::volume`]), which
    /// [`crate::passes::volume_ao`] turns into occlusion with the pixel's normal. `None`: fully
    /// visible. Stored as unorm8 (8 bytes a point).
    pub octants: Option<&'a [[f32; 8]]>,
    /// Tube radius per vertex, world units (> 0; others take the chain's radius): tubes of
    /// varying thickness ([`crate::passes::tubes`]). Lines ignore it. Stored as f16 (2 bytes).
    pub radius: Option<&'a [f32]>,
    /// A scalar per vertex for [`crate::LineColor::Scalar`] (FA, curvature, …). `None`: 0.
    /// Stored as f32 (4 bytes).
    pub scalar: Option<&'a [f32]>,
}

impl VertexAttributes<'_> {
    fn is_empty(&self) -> bool {
        self.octants.is_none() && self.radius.is_none() && self.scalar.is_none()
    }

    /// Checks that every array has `vertices` entries.
    fn check(&self, vertices: usize) -> Result<(), Error> {
        let lengths = [
            ("octant visibilities", self.octants.map(<[_]>::len)),
            ("radii", self.radius.map(<[_]>::len)),
            ("scalars", self.scalar.map(<[_]>::len)),
        ];
        for (what, len) in lengths {
            if let Some(len) = len.filter(|&len| len != vertices) {
                return Err(Error::InvalidGeometry(format!("{len} {what} for {vertices} vertices")));
            }
        }
        Ok(())
    }

    /// The attributes of the points `runs` map (input vertex `run.input − base` of these
    /// arrays), in page order.
    fn gather(&self, runs: &[RunMap], base: u64) -> PageAttributes {
        let mut out = PageAttributes::holding(self);
        for run in runs {
            out.push_run(self, (run.input - base) as usize, run.len as usize);
        }
        out
    }
}

impl PageAttributes {
    /// Empty arrays for the attributes `a` has.
    fn holding(a: &VertexAttributes) -> PageAttributes {
        Self::with_arrays(a.octants.is_some(), a.scalar.is_some(), a.radius.is_some())
    }

    /// Empty arrays for the attributes this holds.
    fn emptied(&self) -> PageAttributes {
        Self::with_arrays(self.octants.is_some(), self.scalar.is_some(), self.radius.is_some())
    }

    fn with_arrays(octants: bool, scalar: bool, radius: bool) -> PageAttributes {
        PageAttributes { octants: octants.then(Vec::new), scalar: scalar.then(Vec::new), radius: radius.then(Vec::new) }
    }

    /// Appends the attributes of points `from..from + len` of `a` (as stored: unorm8 octants,
    /// f32 scalars, f16 radii, 0 where a radius is not positive and finite).
    fn push_run(&mut self, a: &VertexAttributes, from: usize, len: usize) {
        let unorm = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        let radius = |r: f32| if r.is_finite() && r > 0.0 { half::f16::from_f32(r).to_bits() } else { 0 };
        if let (Some(out), Some(octants)) = (&mut self.octants, a.octants) {
            out.extend(octants[from..from + len].iter().map(|o| o.map(unorm)));
        }
        if let (Some(out), Some(scalars)) = (&mut self.scalar, a.scalar) {
            out.extend_from_slice(&scalars[from..from + len]);
        }
        if let (Some(out), Some(radii)) = (&mut self.radius, a.radius) {
            out.extend(radii[from..from + len].iter().map(|&r| radius(r)));
        }
    }

    /// The largest radius it holds, as stored (0 where none).
    fn max_radius(&self) -> f32 {
        let radii = self.radius.iter().flatten();
        radii.map(|&bits| half::f16::from_bits(bits).to_f32()).fold(0.0, f32::max)
    }

    /// Which arrays it holds, as the shaders' `attributes` bits.
    fn flags(&self) -> u32 {
        self.octants.is_some() as u32 | (self.scalar.is_some() as u32) << 1 | (self.radius.is_some() as u32) << 2
    }
}

/// A page's uniform. Keep in sync with `ClusterPage` in `shaders/shared/clusters.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct PageUniform {
    pub attributes: u32,
    /// The largest tube radius its points hold (0 where none), for the tube cull's bound.
    pub max_radius: f32,
    pub _pad: [u32; 2],
}

impl PageUniform {
    fn of(attributes: &PageAttributes) -> PageUniform {
        PageUniform { attributes: attributes.flags(), max_radius: attributes.max_radius(), _pad: [0; 2] }
    }
}

/// The bind group layout of a page (group 1 of the line and tube pipelines): the points, the
/// records, the three attribute arrays, the page's uniform and the boxes of its groups of clusters.
pub(crate) fn page_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    use crate::binding::Slot::{Storage, Uniform};
    let visibility = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE;
    crate::binding::layout(
        device,
        "lineao::LineGeometry::page",
        visibility,
        &[Storage, Storage, Storage, Storage, Storage, Storage, Uniform, Storage],
    )
}

/// One page of clusters on the GPU.
pub(crate) struct Page {
    pub group: wgpu::BindGroup,
    /// The records of each draw class (size and bend class).
    pub classes: [Range<u32>; DRAW_CLASSES],
    /// The largest tolerance τ its bent points were marked with (world units).
    pub tolerance: f32,
    pub records: u32,
    /// Pieces of eight segments its clusters' strips have (the culled lines' unit).
    pub pieces: u64,
    /// Its culling state for lines and tubes, each at levels of detail or not (each marks what
    /// it found visible, and at which level), made on its first culled frame.
    pub cull: [std::sync::OnceLock<crate::passes::cull::page::PageCull>; 4],
    points: u32,
    runs: Vec<RunMap>,
    /// Per record, its polyline (for [`LineGeometry::set_selection`]).
    streamlines: Vec<u32>,
    pub xy: wgpu::Buffer,
    pub z: wgpu::Buffer,
    pub clusters: wgpu::Buffer,
    /// Per group of consecutive clusters, the box of their points (the cull's first test).
    pub groups: wgpu::Buffer,
    attributes: [Option<wgpu::Buffer>; 3],
    pub uniform: wgpu::Buffer,
}

impl Page {
    /// Bytes of its buffers.
    fn bytes(&self) -> u64 {
        let attributes: u64 = self.attributes.iter().flatten().map(wgpu::Buffer::size).sum();
        let cull: u64 = self.cull.iter().filter_map(|c| c.get()).map(crate::passes::cull::page::PageCull::bytes).sum();
        let own = self.xy.size() + self.z.size() + self.clusters.size() + self.groups.size();
        // (`streamlines` is on the CPU.)
        own + attributes + self.uniform.size() + cull
    }
}

/// Polylines uploaded to the GPU as clusters (see the module documentation).
pub struct LineGeometry {
    pages: Vec<Page>,
    /// Runs appended since the last page was uploaded.
    pending: PageBuilder,
    /// Their attributes, when the chunks carried them.
    pending_attributes: Option<PageAttributes>,
    layout: wgpu::BindGroupLayout,
    /// Bound where a page holds no attribute array (bindings are never empty).
    placeholder: wgpu::Buffer,
    options: GeometryOptions,
    /// Points and records a page holds at most (the options and the device's limits).
    page_points: usize,
    page_records: usize,
    /// Clusters one draw of every cluster covers at most ([`LineGeometry::draw_batches`]).
    draw_batch: u32,
    /// The box of every finite point appended.
    corners: Option<(Vec3, Vec3)>,
    /// Input vertices appended so far.
    pub vertices: usize,
    /// Streamlines appended so far.
    pub streamlines: usize,
    /// Of those, the ones drawn ([`LineGeometry::set_selection`]).
    selected: usize,
    /// Bounding sphere of the finite points; `None` when there are none. Exact for a geometry
    /// made whole ([`LineGeometry::new`]) or finished ([`LineGeometry::finish`]); while a
    /// geometry is appended to, the sphere around the box of what arrived.
    pub bounds: Option<Bounds>,
}

impl LineGeometry {
    /// Uploads polylines `positions[offsets[i]..offsets[i + 1]]` (world units) without waiting
    /// for the device: the buffers are written through the queue and usable by the next
    /// submission.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
    ) -> Result<LineGeometry, Error> {
        Self::with_options(device, queue, positions, offsets, GeometryOptions::default())
    }

    /// [`LineGeometry::new`] with explicit upload options.
    pub fn with_options(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
        options: GeometryOptions,
    ) -> Result<LineGeometry, Error> {
        validate_offsets(offsets, positions.len())?;
        let mut geometry = Self::empty(device, options)?;
        // The exact sphere first: it sets the strips' tolerance as a stream's box would.
        let bounds = Bounds::of_points(positions);
        geometry.corners = Bounds::corners_of(positions);
        geometry.append_runs(device, queue, positions, offsets, &VertexAttributes::default(), bounds)?;
        geometry.flush(device, queue)?;
        geometry.bounds = bounds;
        Ok(geometry)
    }

    /// A geometry without polylines, to [`append`](LineGeometry::append) to.
    pub fn empty(device: &wgpu::Device, options: GeometryOptions) -> Result<LineGeometry, Error> {
        if !(3..=CLUSTER_POINTS).contains(&options.cluster_points) {
            return Err(Error::InvalidGeometry(format!(
                "cluster_points must be 3 to {CLUSTER_POINTS}, got {}",
                options.cluster_points
            )));
        }
        let limits = device.limits();
        let cap = options.page_bytes.min(limits.max_buffer_size).min(limits.max_storage_buffer_binding_size);
        // The widest per-point array is the octants' (8 bytes).
        let page_points = (cap / 8).max(64) as usize;
        let page_records = (cap / RECORD_SIZE).max(64) as usize;
        let placeholder = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lineao::LineGeometry::placeholder"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(LineGeometry {
            pages: Vec::new(),
            pending: PageBuilder::default(),
            pending_attributes: None,
            layout: page_layout(device),
            placeholder,
            options,
            page_points,
            page_records,
            draw_batch: match device.adapter_info().device_type {
                wgpu::DeviceType::Cpu => CPU_DRAW_BATCH_POINTS / options.cluster_points,
                _ => u32::MAX,
            },
            corners: None,
            vertices: 0,
            streamlines: 0,
            selected: 0,
            bounds: None,
        })
    }

    /// A draw of the clusters `instances` of a page split into the draws a renderer makes of
    /// them: one on a GPU, runs of 256 k points on a CPU adapter. At 50 M points in pages of 4 M
    /// (lavapipe): drawing every line took 20.3 s a frame in one draw a page, 15.6 s in batches,
    /// as in pages of 256 k points — whose per-page dispatches cost the culled frame a second.
    pub(crate) fn draw_batches(&self, instances: Range<u32>) -> impl Iterator<Item = Range<u32>> {
        batches(instances, self.draw_batch)
    }

    /// Appends whole polylines `positions[offsets[i]..offsets[i + 1]]` (a chunk of a file, in
    /// order); full pages are uploaded as they fill. What has not filled a page yet is drawn
    /// after [`LineGeometry::flush`].
    pub fn append(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
    ) -> Result<(), Error> {
        self.append_with(device, queue, positions, offsets, &VertexAttributes::default())
    }

    /// [`LineGeometry::append`] with the chunk's per-vertex attributes (one entry per point of
    /// the chunk). Every chunk of a geometry carries the same attributes, or none.
    pub fn append_with(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
        attributes: &VertexAttributes,
    ) -> Result<(), Error> {
        validate_offsets(offsets, positions.len())?;
        attributes.check(positions.len())?;
        let held = self.pending_attributes.as_ref().map_or(0, PageAttributes::flags);
        if self.vertices > 0 && held != PageAttributes::holding(attributes).flags() {
            return Err(Error::InvalidGeometry(
                "every chunk appended to a geometry carries the same attributes".to_string(),
            ));
        }
        if let Some((lo, hi)) = Bounds::corners_of(positions) {
            let (a, b) = self.corners.unwrap_or((lo, hi));
            self.corners = Some((a.min(lo), b.max(hi)));
        }
        // Until `finish`: the sphere around the box (which also gives the strips' tolerance).
        let sphere = self
            .corners
            .map(|(lo, hi)| Bounds { center: (lo + hi) * 0.5, radius: ((hi - lo).length() * 0.5).max(1e-6) });
        self.append_runs(device, queue, positions, offsets, attributes, sphere)?;
        self.bounds = sphere;
        Ok(())
    }

    /// Cuts the polylines into runs and adds them to the pending page, uploading it whenever
    /// it is full; `bounds` sets the strips' tolerance unless the options do.
    fn append_runs(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        offsets: &[u64],
        attributes: &VertexAttributes,
        bounds: Option<Bounds>,
    ) -> Result<(), Error> {
        let tolerance =
            self.options.tolerance.unwrap_or_else(|| bounds.map_or(0.0, |b| b.radius * TOLERANCE_PER_RADIUS));
        let per_cluster = self.options.cluster_points as usize;
        let base = self.vertices as u64;
        if self.vertices == 0 && !attributes.is_empty() {
            self.pending_attributes = Some(PageAttributes::holding(attributes));
        }
        let first_streamline = self.streamlines;
        for (input, run) in clusters::runs(positions, offsets) {
            // The polyline holding input vertex `input` (the last offset at or before it).
            let streamline = first_streamline + offsets.partition_point(|&o| o <= input) - 1;
            let records = clusters::cluster_sizes(run.len(), per_cluster).count();
            if self.pending.points() + run.len() > self.page_points
                || self.pending.records.len() + records > self.page_records
            {
                self.flush(device, queue)?;
            }
            if run.len() > self.page_points {
                let message = format!(
                    "a polyline of {} points exceeds a page of {} points (GeometryOptions::page_bytes)",
                    run.len(),
                    self.page_points
                );
                let (value, max) = (run.len() as u64, self.page_points as u64);
                return Err(Error::TooLarge { limit: crate::Limit::PagePoints, value, max, message });
            }
            self.pending.add_run(run, base + input, streamline as u32, per_cluster, tolerance);
            if let Some(pending) = &mut self.pending_attributes {
                pending.push_run(attributes, input as usize, run.len());
            }
        }
        self.vertices += positions.len();
        self.streamlines += offsets.len() - 1;
        self.selected += offsets.len() - 1;
        Ok(())
    }

    /// Uploads the runs appended since the last page as a page of their own, so the next frame
    /// draws them.
    pub fn flush(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<(), Error> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let data = std::mem::take(&mut self.pending).finish();
        // A later page's attributes start empty with the same arrays.
        let attributes = match &mut self.pending_attributes {
            Some(pending) => {
                let emptied = pending.emptied();
                std::mem::replace(pending, emptied)
            }
            None => PageAttributes::default(),
        };
        let page = self.upload(device, queue, data, attributes)?;
        self.pages.push(page);
        settle(device, queue, self.options.bounded_staging)
    }

    /// Flushes, and makes [`LineGeometry::bounds`] the exact sphere around the points as
    /// drawn (the box's centre, the farthest point's distance, found on the GPU). Waits for
    /// the device; [`LineGeometry::finish_async`] awaits it.
    pub fn finish(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<(), Error> {
        pollster::block_on(self.finish_async(device, queue))
    }

    /// [`LineGeometry::finish`] as a future.
    pub async fn finish_async(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<(), Error> {
        self.flush(device, queue)?;
        let Some((lo, hi)) = self.corners else {
            self.bounds = None;
            return Ok(());
        };
        let center = (lo + hi) * 0.5;
        let radius = compute::distance(device, queue, &self.pages, center).await?;
        self.bounds = Some(Bounds { center, radius: radius.max(1e-6) });
        Ok(())
    }

    /// One page's buffers and bind group.
    fn upload(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        data: PageData,
        attributes: PageAttributes,
    ) -> Result<Page, Error> {
        let points = data.xy.len() as u32;
        let page_uniform = PageUniform::of(&attributes);
        let buffer = |label: &str, bytes: &[u8]| storage_buffer(device, queue, label, bytes);
        let xy = buffer("lineao::LineGeometry::xy", bytemuck::cast_slice(&data.xy))?;
        let z = buffer("lineao::LineGeometry::z", bytemuck::cast_slice(&data.z))?;
        let clusters = buffer("lineao::LineGeometry::clusters", bytemuck::cast_slice(&data.records))?;
        let groups = buffer("lineao::LineGeometry::groups", bytemuck::cast_slice(&data.groups))?;
        let attributes = self.attribute_buffers(device, queue, attributes)?;
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lineao::LineGeometry::page"),
            size: std::mem::size_of::<PageUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&uniform, 0, bytemuck::bytes_of(&page_uniform));
        Ok(Page {
            group: self.bind_group(device, [&xy, &z, &clusters, &groups], &attributes, &uniform),
            classes: data.classes,
            tolerance: data.tolerance,
            records: data.records.len() as u32,
            pieces: data.records.iter().map(|r| r.drawn().saturating_sub(1).div_ceil(PIECE_SEGMENTS) as u64).sum(),
            cull: Default::default(),
            points,
            runs: data.runs,
            streamlines: data.streamlines,
            xy,
            z,
            clusters,
            groups,
            attributes,
            uniform,
        })
    }

    fn attribute_buffers(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        attributes: PageAttributes,
    ) -> Result<[Option<wgpu::Buffer>; 3], Error> {
        let buffer = |label, bytes: &[u8]| storage_buffer(device, queue, label, bytes).map(Some);
        let octants = match &attributes.octants {
            Some(values) => buffer("lineao::LineGeometry::octants", bytemuck::cast_slice(values))?,
            None => None,
        };
        let scalars = match &attributes.scalar {
            Some(values) => buffer("lineao::LineGeometry::scalars", bytemuck::cast_slice(values))?,
            None => None,
        };
        let radii = match &attributes.radius {
            Some(values) => {
                let mut pairs: Vec<u16> = values.clone();
                pairs.resize(values.len().next_multiple_of(2), 0);
                buffer("lineao::LineGeometry::radii", bytemuck::cast_slice(&pairs))?
            }
            None => None,
        };
        Ok([octants, scalars, radii])
    }

    /// `page`'s scalars as its bind group holds them (a placeholder where it has none).
    pub(crate) fn scalars<'a>(&'a self, page: &'a Page) -> &'a wgpu::Buffer {
        page.attributes[1].as_ref().unwrap_or(&self.placeholder)
    }

    fn bind_group(
        &self,
        device: &wgpu::Device,
        [xy, z, clusters, groups]: [&wgpu::Buffer; 4],
        attributes: &[Option<wgpu::Buffer>; 3],
        uniform: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let [octants, scalars, radii] = attributes;
        crate::binding::group(
            device,
            "lineao::LineGeometry::page",
            &self.layout,
            &[
                xy.as_entire_binding(),
                z.as_entire_binding(),
                clusters.as_entire_binding(),
                octants.as_ref().unwrap_or(&self.placeholder).as_entire_binding(),
                scalars.as_ref().unwrap_or(&self.placeholder).as_entire_binding(),
                radii.as_ref().unwrap_or(&self.placeholder).as_entire_binding(),
                uniform.as_entire_binding(),
                groups.as_entire_binding(),
            ],
        )
    }

    /// Uploads per-vertex `attributes` (one entry per point appended), replacing earlier ones:
    /// object-space AO computed after the upload, or recomputed with other settings, needs no
    /// new geometry, and the caller need not keep the polylines. Flushes first.
    pub fn set_attributes(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        attributes: &VertexAttributes,
    ) -> Result<(), Error> {
        attributes.check(self.vertices)?;
        self.flush(device, queue)?;
        for i in 0..self.pages.len() {
            let page = &self.pages[i];
            let gathered = attributes.gather(&page.runs, 0);
            let page_uniform = PageUniform::of(&gathered);
            let buffers = self.attribute_buffers(device, queue, gathered)?;
            let page = &self.pages[i];
            let group =
                self.bind_group(device, [&page.xy, &page.z, &page.clusters, &page.groups], &buffers, &page.uniform);
            queue.write_buffer(&page.uniform, 0, bytemuck::bytes_of(&page_uniform));
            let page = &mut self.pages[i];
            page.attributes = buffers;
            page.group = group;
        }
        settle(device, queue, self.options.bounded_staging)
    }

    /// Draws only the polylines `selected` marks (one entry per polyline appended; `None`:
    /// all of them): the others are neither drawn, culled nor occlude, in every pass — but the
    /// transparent context's ([`crate::TransparencySettings::context_alpha`]). Nothing
    /// is uploaded again but a bit per cluster, which a compute pass writes into the cluster
    /// records; polylines appended later are selected. Flushes first.
    pub fn set_selection(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        selected: Option<&[bool]>,
    ) -> Result<(), Error> {
        if let Some(selected) = selected
            && selected.len() != self.streamlines
        {
            return Err(Error::InvalidGeometry(format!(
                "a selection of {} polylines for a geometry of {}",
                selected.len(),
                self.streamlines
            )));
        }
        self.flush(device, queue)?;
        let pass = compute::Select::new(device);
        for page in &self.pages {
            let mut words = vec![0u32; page.streamlines.len().div_ceil(32).max(1)];
            if let Some(selected) = selected {
                for (i, &s) in page.streamlines.iter().enumerate() {
                    words[i / 32] |= (!selected[s as usize] as u32) << (i % 32);
                }
            }
            pass.run(device, queue, page, &words);
        }
        self.selected = selected.map_or(self.streamlines, |s| s.iter().filter(|&&k| k).count());
        settle(device, queue, self.options.bounded_staging)
    }

    /// The polylines drawn: all of them but those [`LineGeometry::set_selection`] left out.
    pub fn selected(&self) -> usize {
        self.selected
    }

    /// The corners (min, max) of the box around every finite point appended.
    pub fn corners(&self) -> Option<(Vec3, Vec3)> {
        self.corners
    }

    /// Whether every page holds per-vertex attributes.
    pub fn has_attributes(&self) -> bool {
        self.pages.iter().all(|p| p.attributes.iter().any(Option::is_some))
    }

    /// The uploaded pages.
    pub(crate) fn pages(&self) -> &[Page] {
        &self.pages
    }

    /// Number of pages (bind groups) uploaded.
    pub fn page_count(&self) -> usize {
        self.pages.len()
    }

    /// Clusters uploaded.
    pub fn clusters(&self) -> usize {
        self.pages.iter().map(|p| p.records as usize).sum()
    }

    /// Points uploaded (the finite points of runs of two or more).
    pub fn points(&self) -> usize {
        self.pages.iter().map(|p| p.points as usize).sum()
    }

    /// Bytes of the GPU buffers that hold the uploaded pages.
    pub fn gpu_bytes(&self) -> u64 {
        self.pages.iter().map(Page::bytes).sum()
    }

    /// Each page's points decoded as the shaders draw them (read back from the GPU), in page
    /// order, with the input vertex of each: what the tests hold against the input.
    #[cfg(feature = "reference")]
    pub fn decoded_points(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<(u64, [f32; 3])>, Error> {
        let mut out = Vec::with_capacity(self.points());
        for page in &self.pages {
            let decoded = compute::decode(device, queue, page)?;
            for run in &page.runs {
                for k in 0..run.len {
                    out.push((run.input + k as u64, decoded[(run.first + k) as usize]));
                }
            }
        }
        Ok(out)
    }

    /// Each page's cluster records, points (page order) and group boxes (min, max) as the GPU
    /// holds them, read back: what the cull's CPU reference tests ([`crate::reference::cull`]).
    #[cfg(feature = "reference")]
    pub fn page_contents(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<PageContents>, Error> {
        let read = |buffer| pollster::block_on(crate::readback::read_buffer_async(device, queue, buffer));
        self.pages
            .iter()
            .map(|page| {
                let records: Vec<ClusterRecord> =
                    bytemuck::cast_slice(&read(&page.clusters)?)[..page.records as usize].to_vec();
                let groups = bytemuck::cast_slice::<u8, [f32; 8]>(&read(&page.groups)?)
                    .iter()
                    .map(|g| (Vec3::new(g[0], g[1], g[2]), Vec3::new(g[4], g[5], g[6])))
                    .collect();
                Ok(PageContents { records, points: compute::decode(device, queue, page)?, groups })
            })
            .collect()
    }
}

/// One page as the GPU holds it ([`LineGeometry::page_contents`]), what the cull's CPU
/// reference tests ([`crate::reference::cull`]).
#[cfg(feature = "reference")]
pub struct PageContents {
    /// Its clusters' records.
    pub records: Vec<ClusterRecord>,
    /// Every point decoded on its cluster's grid, in page order.
    pub points: Vec<[f32; 3]>,
    /// Per group of GROUP_CLUSTERS (16) consecutive records, its box (min, max).
    pub groups: Vec<(Vec3, Vec3)>,
}

/// A storage buffer holding `bytes` (words; at least one), written through the queue; an allocation
/// over the device's limits is [`Error::TooLarge`] naming both.
fn storage_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    bytes: &[u8],
) -> Result<wgpu::Buffer, Error> {
    let size = (bytes.len() as u64).max(4).next_multiple_of(4);
    let limits = device.limits();
    let limit = limits.max_buffer_size.min(limits.max_storage_buffer_binding_size);
    if size > limit {
        let message = format!("{label}: {size} bytes, over the device's largest storage buffer ({limit} bytes)");
        return Err(Error::TooLarge { limit: crate::Limit::StorageBuffer, value: size, max: limit, message });
    }
    let buffer = crate::gpu::allocating(device, label, size, || {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    })?;
    // Every array here is of 4-byte words (radii are padded to pairs).
    debug_assert!(bytes.len().is_multiple_of(4));
    if !bytes.is_empty() {
        queue.write_buffer(&buffer, 0, bytes);
    }
    Ok(buffer)
}

/// After a page's upload: submit its writes and wait for the device
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

/// The compute passes over a page's clusters: the farthest point from a centre (the exact
/// bounding sphere of [`LineGeometry::finish`]), the selection written into the records
/// ([`LineGeometry::set_selection`]) and, for the tests, every point decoded
/// (`shaders/line_geometry.wgsl`).
mod compute {
    use super::Page;
    use crate::Error;
    use glam::Vec3;

    /// Workgroups along x at most (WebGPU's guaranteed 65 535): more clusters go on along y.
    const ROW: u32 = 32_768;

    #[repr(C)]
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    struct Params {
        center: [f32; 3],
        clusters: u32,
    }

    struct Pass {
        pipeline: wgpu::ComputePipeline,
        layout: wgpu::BindGroupLayout,
    }

    fn pass(device: &wgpu::Device, entry: &str) -> Pass {
        use crate::binding::Slot;
        let layout = crate::binding::layout(
            device,
            "lineao::LineGeometry::compute",
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::StorageReadWrite],
        );
        let pages = super::page_layout(device);
        let module = crate::shader::module(device, "line_geometry.wgsl");
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lineao::LineGeometry::compute"),
            bind_group_layouts: &[Some(&layout), Some(&pages)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("lineao::LineGeometry::compute"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        });
        Pass { pipeline, layout }
    }

    /// Runs `entry` over every cluster of `page` with `output` bound.
    fn run(device: &wgpu::Device, queue: &wgpu::Queue, pass: &Pass, page: &Page, center: Vec3, output: &wgpu::Buffer) {
        use wgpu::util::DeviceExt;
        let params = Params { center: center.to_array(), clusters: page.records };
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lineao::LineGeometry::compute"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let group = crate::binding::group(
            device,
            "lineao::LineGeometry::compute",
            &pass.layout,
            &[uniform.as_entire_binding(), output.as_entire_binding()],
        );
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::LineGeometry") });
        {
            let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
            cpass.set_pipeline(&pass.pipeline);
            cpass.set_bind_group(0, &group, &[]);
            cpass.set_bind_group(1, &page.group, &[]);
            let rows = page.records.div_ceil(ROW);
            cpass.dispatch_workgroups(page.records.min(ROW), rows, 1);
        }
        queue.submit([encoder.finish()]);
    }

    /// The pass that writes a selection into a page's records (`select_clusters`).
    pub struct Select {
        pipeline: wgpu::ComputePipeline,
        layout: wgpu::BindGroupLayout,
    }

    impl Select {
        const LABEL: &str = "lineao::LineGeometry::select";

        pub fn new(device: &wgpu::Device) -> Select {
            use crate::binding::Slot;
            let slots = [Slot::Uniform, Slot::StorageReadWrite, Slot::Storage];
            let layout = crate::binding::layout(device, Self::LABEL, wgpu::ShaderStages::COMPUTE, &slots);
            let pipeline = crate::binding::compute_pipeline(
                device,
                Self::LABEL,
                &layout,
                "line_geometry.wgsl",
                "select_clusters",
                &[],
            );
            Select { pipeline, layout }
        }

        /// Marks the records of `page` whose bit in `deselected` is set (record i: word i / 32,
        /// bit i % 32) with `flags::DESELECTED` and clears the others'.
        pub fn run(&self, device: &wgpu::Device, queue: &wgpu::Queue, page: &Page, deselected: &[u32]) {
            use wgpu::util::DeviceExt;
            let label = Some(Self::LABEL);
            let params = Params { center: [0.0; 3], clusters: page.records };
            let init = |contents: &[u8], usage| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label, contents, usage })
            };
            let uniform = init(bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
            let mask = init(bytemuck::cast_slice(deselected), wgpu::BufferUsages::STORAGE);
            let resources = [uniform.as_entire_binding(), page.clusters.as_entire_binding(), mask.as_entire_binding()];
            let group = crate::binding::group(device, Self::LABEL, &self.layout, &resources);
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label });
            {
                let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
                cpass.set_pipeline(&self.pipeline);
                cpass.set_bind_group(0, &group, &[]);
                let groups = page.records.div_ceil(64);
                cpass.dispatch_workgroups(groups.min(ROW), groups.div_ceil(ROW), 1);
            }
            queue.submit([encoder.finish()]);
        }
    }

    /// The largest distance from `center` of any point of `pages`.
    pub async fn distance(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        pages: &[Page],
        center: Vec3,
    ) -> Result<f32, Error> {
        if pages.is_empty() {
            return Ok(0.0);
        }
        let pass = pass(device, "farthest_point");
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lineao::LineGeometry::farthest"),
            size: 4,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&output, 0, &[0; 4]);
        for page in pages {
            run(device, queue, &pass, page, center, &output);
        }
        let bytes = crate::readback::read_buffer_async(device, queue, &output).await?;
        let squared = f32::from_bits(u32::from_le_bytes(bytes[..4].try_into().expect("4 bytes")));
        Ok(squared.sqrt())
    }

    /// Every point of `page` decoded on the GPU, in page order.
    #[cfg(feature = "reference")]
    pub fn decode(device: &wgpu::Device, queue: &wgpu::Queue, page: &Page) -> Result<Vec<[f32; 3]>, Error> {
        let pass = pass(device, "decode_points");
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lineao::LineGeometry::decoded"),
            size: 16 * page.points.max(1) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        run(device, queue, &pass, page, Vec3::ZERO, &output);
        let bytes = pollster::block_on(crate::readback::read_buffer_async(device, queue, &output))?;
        let points: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        Ok(points.iter().take(page.points as usize).map(|p| [p[0], p[1], p[2]]).collect())
    }
}

#[cfg(test)]
#[test]
fn records_and_the_page_uniform_match_their_wgsl_structs() {
    crate::shader::assert_wgsl_layout!(
        ClusterRecord,
        "shared/clusters.wgsl",
        "Cluster",
        [origin, scale, first, flags, previous, next]
    );
    crate::shader::assert_wgsl_layout!(PageUniform, "shared/clusters.wgsl", "ClusterPage", [attributes, max_radius]);
}

#[cfg(test)]
#[test]
fn draw_batches_cover_each_instance_once_in_order() {
    for (range, step) in [(0..0, 5), (3..4, 5), (0..10, 5), (7..30, 4), (0..10, 1), (5..9, 0), (0..u32::MAX, u32::MAX)]
    {
        let runs: Vec<Range<u32>> = batches(range.clone(), step).collect();
        let mut next = range.start;
        for run in &runs {
            assert_eq!(run.start, next, "{range:?} by {step}: {runs:?}");
            assert!(!run.is_empty() && run.len() <= step.max(1) as usize, "{range:?} by {step}: {runs:?}");
            next = run.end;
        }
        assert_eq!(next, range.end, "{range:?} by {step}: {runs:?}");
    }
}
