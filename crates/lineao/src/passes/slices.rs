//! Anatomy slices: up to three planes through a scalar volume (a T1 image, an FA map), each
//! orthogonal to a world axis, drawn into the same G-buffer as the lines
//! (`shaders/slices.wgsl`), so that the lines' occlusion darkens a slice where fibres run close
//! to it and every method sees the slice as a surface: the contact cue that tells where the
//! fibres are in the head.
//!
//! A slice is a convex polygon in its plane: the rectangle of the world box of the volume's
//! voxel centres, or, where voxels without data are transparent, an outline around the voxels
//! with data near the plane ([`SliceVolume::outline`]: on the MNI template's default slices a
//! quarter fewer fragments than their rectangles, none of them shown). Each fragment maps its
//! world position to voxel coordinates through the inverse of the volume's affine (voxel indices → world, the convention of NIfTI and nibabel) and interpolates the
//! values trilinearly between the eight voxel centres around it — the numbers
//! `lineao_tracts::Volume::sample` gives on the CPU, which the tests compare. Fragments
//! outside the box of the voxel centres are discarded, so an oblique affine shows its true,
//! rotated outline. The value goes through a window (the ends of the colormap; by default the
//! 2nd and 98th percentiles of the volume's finite values) and a colormap, unlit: a slice is a
//! picture of the data, and the only darkening on it is the occlusion.
//!
//! Where the device filters f32 textures (`FLOAT32_FILTERABLE`: lavapipe, most desktop GPUs and
//! browsers) the volume lives in an `Rg32Float` 3-D texture, each voxel's value beside a 1 where
//! it holds data, so that one trilinear sample gives the value and the data's weight, in the
//! texture units (8 bytes a voxel); elsewhere in an `R32Float` one, and eight `textureLoad`s
//! give both (exact, and what every device can do; 4 bytes a voxel). On lavapipe the filtered
//! path draws the default frame's slices in about two thirds of the loads' time, and the packed
//! texel in three quarters of two samples' (an `R32Float` value and an `R8Unorm` mask, before);
//! on a GPU the texture units are what filtering is for. A
//! GPU filters with weights of 8 fractional bits or more: the sample is off by at most 1/512 of
//! the difference between neighbouring voxels, below a colormap's step. `tests/slices.rs`
//! checks both paths against the CPU's trilinear sample.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};

use crate::Error;
use crate::binding::{self, Slot};
use crate::camera::{Bounds, FrameView};
use crate::gbuffer::{self, GeometryBindings, GeometryUniform, Load, PipelineSpec};
use crate::lighting::{Lighting, LightingShape};
use crate::settings::{LineColor, SliceSettings};
use crate::targets::FrameTargets;
use crate::timing::Span;

/// A scalar volume on the GPU for [`SliceRenderer`].
pub struct SliceVolume {
    /// `Rg32Float` (the value, and 1 where the voxel holds data: finite, not 0) where the
    /// device filters f32 textures, else `R32Float` (the value).
    view: wgpu::TextureView,
    dims: [u32; 3],
    world_to_voxel: Mat4,
    /// The axis-aligned world box around the voxel centres.
    box_min: Vec3,
    box_max: Vec3,
    /// The world box around the voxels with data (finite, not 0) and half a voxel beyond; none
    /// without such voxels.
    data_box: Option<(Vec3, Vec3)>,
    voxel_to_world: Mat4,
    /// A bit a voxel (NIfTI's order, 64 a word): 1 where it holds data.
    data: Vec<u64>,
    percentiles: [f32; 2],
}

impl SliceVolume {
    /// Uploads `values` (x fastest, then y, then z: NIfTI's order) of a `dims` volume whose
    /// voxel (i, j, k) centre lies at `voxel_to_world · (i, j, k, 1)`.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        dims: [u32; 3],
        values: &[f32],
        voxel_to_world: Mat4,
    ) -> Result<SliceVolume, Error> {
        let count = dims.iter().map(|&d| d as u64).product::<u64>();
        if count == 0 || count != values.len() as u64 {
            return Err(Error::InvalidGeometry(format!("{} values for a {dims:?} volume", values.len())));
        }
        let limit = device.limits().max_texture_dimension_3d;
        if dims.iter().any(|&d| d > limit) {
            let message = format!("a {dims:?} volume exceeds the device's 3-D textures of {limit} voxels a side");
            let value = dims.into_iter().max().unwrap_or(0) as u64;
            return Err(Error::TooLarge { limit: crate::Limit::TextureDimension3d, value, max: limit as u64, message });
        }
        let det = voxel_to_world.determinant();
        if !(det.is_finite() && det.abs() > 1e-12 && voxel_to_world.is_finite()) {
            return Err(Error::InvalidGeometry(format!("a singular voxel-to-world affine (determinant {det})")));
        }
        let texture = |format: wgpu::TextureFormat, dims: [u32; 3], texels: &[u8]| {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("lineao::SliceVolume"),
                size: wgpu::Extent3d { width: dims[0], height: dims[1], depth_or_array_layers: dims[2] },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            let row = format.block_copy_size(None).unwrap_or(1) * dims[0];
            let layout =
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(dims[1]) };
            queue.write_texture(texture.as_image_copy(), texels, layout, texture.size());
            texture.create_view(&Default::default())
        };
        // Where the slices sample it ([`SliceRenderer::new`]), the data's mark beside each value.
        let view = if device.features().contains(wgpu::Features::FLOAT32_FILTERABLE) {
            let texels: Vec<[f32; 2]> = values.iter().map(|&v| [v, has_data(v) as u32 as f32]).collect();
            texture(wgpu::TextureFormat::Rg32Float, dims, bytemuck::cast_slice(&texels))
        } else {
            texture(wgpu::TextureFormat::R32Float, dims, bytemuck::cast_slice(values))
        };
        let last = Vec3::new(dims[0] as f32 - 1.0, dims[1] as f32 - 1.0, dims[2] as f32 - 1.0);
        let (box_min, box_max) = world_box(voxel_to_world, Vec3::ZERO, last);
        // A point half a voxel or more beyond the last voxel with data on an axis draws nothing
        // (the voxels past it weigh at least half), so the data's voxels and half a voxel
        // around them (within the box) hold every fragment that a transparent slice keeps.
        let data_box = data_voxels(dims, values)
            .map(|(lo, hi)| world_box(voxel_to_world, (lo - 0.5).max(Vec3::ZERO), (hi + 0.5).min(last)));
        let mut data = vec![0u64; values.len().div_ceil(64)];
        for (n, _) in values.iter().enumerate().filter(|(_, v)| has_data(**v)) {
            data[n / 64] |= 1 << (n % 64);
        }
        Ok(SliceVolume {
            view,
            dims,
            world_to_voxel: voxel_to_world.inverse(),
            box_min,
            box_max,
            data_box,
            voxel_to_world,
            data,
            percentiles: percentiles(values, [0.02, 0.98]),
        })
    }

    /// The polygons the slices of `slices` are drawn as, [`OUTLINE_SIDES`] corners (u, w) an
    /// axis, two to a `vec4`, and whether each axis shows one: the rectangle of the voxel
    /// centres (its last corner repeated), or where voxels without data are transparent the
    /// [`SliceVolume::outline`].
    fn polygons(&self, slices: &SliceSettings) -> Polygons {
        let mut words = [[0.0; 4]; OUTLINE_WORDS];
        let mut shown = [false; 3];
        for (axis, p) in slices.positions.iter().enumerate() {
            let Some(p) = *p else { continue };
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let inside = (self.box_min[axis]..=self.box_max[axis]).contains(&p);
            let corners = match slices.opaque {
                _ if !inside => None,
                true => {
                    let (lo, hi) = (self.box_min, self.box_max);
                    let rectangle = [[lo[u], lo[w]], [hi[u], lo[w]], [hi[u], hi[w]], [lo[u], hi[w]]].map(Vec2::from);
                    Some(std::array::from_fn(|k| rectangle[k.min(3)]))
                }
                false => self.outline(axis, p),
            };
            let Some(corners) = corners else { continue };
            shown[axis] = true;
            for (k, pair) in corners.chunks_exact(2).enumerate() {
                words[axis * OUTLINE_SIDES / 2 + k] = [pair[0].x, pair[0].y, pair[1].x, pair[1].y];
            }
        }
        (words, shown)
    }

    /// A convex polygon in the plane `axis` = `p` (world) holding every point of it that a
    /// transparent slice shows: [`OUTLINE_SIDES`] corners (u, w), the plane's other two world
    /// axes in cyclic order; `None` where no voxel with data is near the plane.
    ///
    /// A fragment shows where the voxels with data weigh half or more of its trilinear sample,
    /// so one of the eight voxels around it, v, holds data, and it lies in the cube of voxel
    /// coordinates [v − 1, v + 1]³. The cubes that meet the plane are those of the voxels with
    /// |n · v − c| ≤ |n|₁, n · x = c being the plane in voxel coordinates, found a column at a
    /// time along the voxel axis that n leans on most (a few voxels a column). The polygon is
    /// the intersection of the half-planes, one a direction 360°/[`OUTLINE_SIDES`] apart (its
    /// four axis-aligned ones cut to the data's box), that hold every such cube's cut: the
    /// largest projection of a cube's centre plus the cube's own reach along the direction,
    /// with a little slack for f32 rounding.
    pub fn outline(&self, axis: usize, p: f32) -> Option<[Vec2; OUTLINE_SIDES]> {
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        let m = self.voxel_to_world;
        let row = |r: usize| Vec3::new(m.x_axis[r], m.y_axis[r], m.z_axis[r]);
        let (n, c) = (row(axis), p - m.w_axis[axis]);
        let (ru, rw) = (row(u), row(w));
        let reach = n.abs().element_sum();
        let directions: [Vec2; OUTLINE_SIDES] = std::array::from_fn(|k| {
            let angle = k as f32 * std::f32::consts::TAU / OUTLINE_SIDES as f32;
            Vec2::new(angle.cos(), angle.sin())
        });
        // Along voxel axis `a`, the column's voxels near the plane; `b`, `d` the others.
        let a = (0..3).max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs())).unwrap_or(0);
        let (b, d) = ((a + 1) % 3, (a + 2) % 3);
        let dims = self.dims.map(|d| d as usize);
        let mut support = [f32::NEG_INFINITY; OUTLINE_SIDES];
        for i_d in 0..dims[d] {
            for i_b in 0..dims[b] {
                let rest = n[b] * i_b as f32 + n[d] * i_d as f32;
                let (lo, hi) = ((c - rest - reach) / n[a], (c - rest + reach) / n[a]);
                let (lo, hi) = (lo.min(hi).ceil().max(0.0), lo.max(hi).floor().min(dims[a] as f32 - 1.0));
                if lo > hi {
                    continue;
                }
                for i_a in lo as usize..=hi as usize {
                    let mut v = [0usize; 3];
                    (v[a], v[b], v[d]) = (i_a, i_b, i_d);
                    let index = v[0] + dims[0] * (v[1] + dims[1] * v[2]);
                    if self.data[index / 64] & (1 << (index % 64)) == 0 {
                        continue;
                    }
                    let v = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
                    let q = Vec2::new(ru.dot(v) + m.w_axis[u], rw.dot(v) + m.w_axis[w]);
                    for (s, dir) in support.iter_mut().zip(&directions) {
                        *s = s.max(dir.dot(q));
                    }
                }
            }
        }
        if support[0] == f32::NEG_INFINITY {
            return None;
        }
        let (box_min, box_max) = self.data_box?;
        let extent = (self.box_max - self.box_min).max_element().max(1.0);
        for (k, (s, dir)) in support.iter_mut().zip(&directions).enumerate() {
            // The cube [−1, 1]³ of voxel coordinates reaches Σ |dir · (ru_i, rw_i)| along dir.
            *s += (0..3).map(|i| (dir.x * ru[i] + dir.y * rw[i]).abs()).sum::<f32>() + 1e-4 * extent;
            // No further than the box of the data (half a voxel beyond its last voxels: the
            // voxels past them weigh half or more), within the voxel centres' (beyond, cut).
            match k * 4 / OUTLINE_SIDES {
                _ if k % (OUTLINE_SIDES / 4) != 0 => {}
                0 => *s = s.min(box_max[u]),
                1 => *s = s.min(box_max[w]),
                2 => *s = s.min(-box_min[u]),
                _ => *s = s.min(-box_min[w]),
            }
        }
        // Corner k: where the sides of directions k and k + 1 meet.
        Some(std::array::from_fn(|k| {
            let (d0, d1) = (directions[k], directions[(k + 1) % OUTLINE_SIDES]);
            let (s0, s1) = (support[k], support[(k + 1) % OUTLINE_SIDES]);
            let det = d0.perp_dot(d1);
            Vec2::new(s0 * d1.y - s1 * d0.y, d0.x * s1 - d1.x * s0) / det
        }))
    }

    /// The 2nd and 98th percentiles of the finite values other than 0 (the default window: an
    /// MRI's background of zeros does not count; a constant volume gets [v, v + 1]).
    pub fn percentiles(&self) -> [f32; 2] {
        self.percentiles
    }

    /// The volume's size in voxels.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The world box around the voxel centres (min, max).
    pub fn world_box(&self) -> (Vec3, Vec3) {
        (self.box_min, self.box_max)
    }

    /// The bounding sphere of what `slices` shows of the volume: the box cut to the shown
    /// planes (a frame's bounds must hold it); `None` when no slice cuts the box.
    pub fn slice_bounds(&self, slices: &SliceSettings) -> Option<Bounds> {
        let mut points = Vec::new();
        for (axis, p) in slices.positions.iter().enumerate() {
            let Some(p) = *p else { continue };
            if !(self.box_min[axis]..=self.box_max[axis]).contains(&p) {
                continue;
            }
            for c in 0..8 {
                let corner =
                    Vec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), self.box_max, self.box_min);
                let mut q = corner;
                q[axis] = p;
                points.push(q.to_array());
            }
        }
        Bounds::of_points(&points)
    }
}

/// The group of the tiles' buffer `tiles`, or of a buffer of one tile (marks that nothing reads).
fn tiles_group(device: &wgpu::Device, layout: &wgpu::BindGroupLayout, tiles: Option<&wgpu::Buffer>) -> wgpu::BindGroup {
    let label = "lineao::SliceRenderer::tiles";
    let spare;
    let buffer = match tiles {
        Some(buffer) => buffer,
        None => {
            spare = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 4,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            });
            &spare
        }
    };
    binding::group(device, label, layout, &[buffer.as_entire_binding()])
}

/// The axis-aligned world box around the voxel-space box `lo..=hi` (its eight corners through
/// the affine).
fn world_box(voxel_to_world: Mat4, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
    let corners = (0..8).map(|c| {
        let corner = Vec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo);
        voxel_to_world.transform_point3(corner)
    });
    corners.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// Whether a voxel's value is data: finite and not 0.
fn has_data(v: f32) -> bool {
    v.is_finite() && v != 0.0
}

/// The voxel-index box (lowest, highest) of the voxels that hold data.
fn data_voxels(dims: [u32; 3], values: &[f32]) -> Option<(Vec3, Vec3)> {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for (row, voxels) in values.chunks_exact(dims[0] as usize).enumerate() {
        let Some(first) = voxels.iter().position(|&v| has_data(v)) else { continue };
        let last = voxels.iter().rposition(|&v| has_data(v)).unwrap_or(first);
        let (j, k) = ((row % dims[1] as usize) as f32, (row / dims[1] as usize) as f32);
        lo = lo.min(Vec3::new(first as f32, j, k));
        hi = hi.max(Vec3::new(last as f32, j, k));
    }
    (lo.x <= hi.x).then_some((lo, hi))
}

/// The `quantiles` (in [0, 1]) of the finite `values` other than 0, from at most 2^20 of them
/// evenly spaced; [v, v + 1] where they coincide, [0, 1] without such values.
fn percentiles(values: &[f32], quantiles: [f32; 2]) -> [f32; 2] {
    let step = values.len().div_ceil(1 << 20).max(1);
    let mut finite: Vec<f32> = values.iter().step_by(step).copied().filter(|v| v.is_finite() && *v != 0.0).collect();
    if finite.is_empty() {
        return [0.0, 1.0];
    }
    let mut at = |q: f32| {
        let k = ((q * (finite.len() - 1) as f32).round() as usize).min(finite.len() - 1);
        *finite.select_nth_unstable_by(k, f32::total_cmp).1
    };
    let (lo, hi) = (at(quantiles[0]), at(quantiles[1]));
    if hi > lo { [lo, hi] } else { [lo, lo + 1.0] }
}

/// The corners of a slice's polygon ([`SliceVolume::outline`]; a number the WGSL shares:
/// `rust/constants.wgsl`).
pub use crate::shader::OUTLINE_SIDES;
/// The `vec4`s of the three axes' polygons in [`SliceUniform`].
const OUTLINE_WORDS: usize = 3 * OUTLINE_SIDES / 2;

/// Keep in sync with `SliceUniform` in `shaders/slices.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct SliceUniform {
    world_to_voxel: [[f32; 4]; 4],
    /// xyz: where each axis's slice lies (world units).
    positions: [f32; 4],
    /// xyz: 1 where the axis has a slice; w: 1 where voxels without data are transparent.
    shown: [u32; 4],
    /// xyz: the last voxel index on each axis.
    last_voxel: [f32; 4],
    /// Each axis's polygon in its plane: OUTLINE_SIDES corners (u, w), two a `vec4`.
    outline: [[f32; 4]; OUTLINE_WORDS],
}

/// Draws a [`SliceVolume`]'s slices into the G-buffer of [`FrameTargets`], marking the tiles
/// they fall in ([`FrameTargets::slice_tiles`]).
pub struct SliceRenderer {
    pipeline: wgpu::RenderPipeline,
    octants: bool,
    bindings: GeometryBindings,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    /// The volume and its bind group, once set.
    volume: Option<(Arc<SliceVolume>, wgpu::BindGroup)>,
    /// The tiles' buffer (the targets', or one of a single tile where they have none) and its
    /// group, visible to the fragments alone.
    tiles_layout: wgpu::BindGroupLayout,
    tiles: wgpu::BindGroup,
    /// Trilinear, clamped to the edge: the volume's, where the device filters f32.
    sampler: wgpu::Sampler,
    /// The last polygons drawn and what they were drawn for (forgotten with the volume): they
    /// change when a slice moves.
    polygons: std::sync::Mutex<Option<(PolygonsOf, Polygons)>>,
}

/// What a volume's slices' polygons depend on: the positions' bits, and whether opaque.
type PolygonsOf = ([Option<u32>; 3], bool);

/// The three axes' polygons as the uniform holds them, and which axes show one.
type Polygons = ([[f32; 4]; OUTLINE_WORDS], [bool; 3]);

impl SliceRenderer {
    /// With `octants`, targets that have an `octants` texture get full visibility where a
    /// slice is (slices are not in the lines' volume, [`crate::passes::volume_ao`]).
    pub fn new(device: &wgpu::Device, octants: bool) -> SliceRenderer {
        let label = "lineao::SliceRenderer";
        // Unlit: every lighting is the same to it.
        let bindings = GeometryBindings::new(device, label, LightingShape::ANY);
        let filtered = device.features().contains(wgpu::Features::FLOAT32_FILTERABLE);
        let volume = if filtered { Slot::FilterableTexture3d } else { Slot::Texture3d };
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            &[volume, Slot::Uniform, Slot::Sampler],
        );
        let module = crate::shader::module(device, "slices.wgsl");
        let tiles_layout = binding::layout(device, label, wgpu::ShaderStages::FRAGMENT, &[Slot::StorageReadWrite]);
        let pipeline = gbuffer::pipeline(
            device,
            &bindings,
            PipelineSpec {
                groups: &[&layout, &tiles_layout],
                label,
                module: &module,
                vertex: "vs_slice",
                fragment: match (filtered, octants) {
                    (true, false) => "fs_slice_filtered",
                    (true, true) => "fs_slice_filtered_octants",
                    (false, false) => "fs_slice",
                    (false, true) => "fs_slice_octants",
                },
                buffers: &[],
                topology: wgpu::PrimitiveTopology::TriangleList,
                octants,
                constants: &[],
            },
        );
        let uniform = binding::uniform_buffer::<SliceUniform>(device, label);
        let tiles = tiles_group(device, &tiles_layout, None);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some(label),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        SliceRenderer {
            pipeline,
            octants,
            bindings,
            layout,
            uniform,
            volume: None,
            tiles_layout,
            tiles,
            sampler,
            polygons: Default::default(),
        }
    }

    /// Marks the slices' tiles in `targets`' buffer (none without the blur's targets).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        self.tiles = tiles_group(device, &self.tiles_layout, targets.slice_tiles.as_ref());
    }

    /// Whether this renderer writes the `octants` target.
    pub fn writes_octants(&self) -> bool {
        self.octants
    }

    /// The volume the slices cut, or none (nothing is drawn).
    pub fn set_volume(&mut self, device: &wgpu::Device, volume: Option<Arc<SliceVolume>>) {
        *self.polygons.get_mut().unwrap_or_else(std::sync::PoisonError::into_inner) = None;
        self.volume = volume.map(|volume| {
            let group = binding::group(
                device,
                "lineao::SliceRenderer::volume",
                &self.layout,
                &[
                    wgpu::BindingResource::TextureView(&volume.view),
                    self.uniform.as_entire_binding(),
                    wgpu::BindingResource::Sampler(&self.sampler),
                ],
            );
            (volume, group)
        });
    }

    /// Whether a volume is set.
    pub fn has_volume(&self) -> bool {
        self.volume.is_some()
    }

    /// Writes this frame's uniform.
    pub fn prepare(&self, queue: &wgpu::Queue, view: &FrameView, slices: &SliceSettings, lighting: &Lighting) {
        let Some((volume, _)) = &self.volume else { return };
        let range = slices.window.unwrap_or(volume.percentiles);
        let color = LineColor::Scalar { colormap: slices.colormap, range };
        self.bindings.write(queue, &GeometryUniform::new(view, color, 0.0, 0.0), lighting);
        let [x, y, z] = slices.positions;
        let of = (slices.positions.map(|p| p.map(f32::to_bits)), slices.opaque);
        let mut last = self.polygons.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let (outline, shown) = match &*last {
            Some((drawn, polygons)) if *drawn == of => *polygons,
            _ => last.insert((of, volume.polygons(slices))).1,
        };
        let uniform = SliceUniform {
            world_to_voxel: volume.world_to_voxel.to_cols_array_2d(),
            positions: [x.unwrap_or(0.0), y.unwrap_or(0.0), z.unwrap_or(0.0), 0.0],
            shown: [shown[0] as u32, shown[1] as u32, shown[2] as u32, !slices.opaque as u32],
            last_voxel: [volume.dims[0], volume.dims[1], volume.dims[2], 1].map(|d| d as f32 - 1.0),
            outline,
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Draws the slices over the G-buffer (or clearing it first: `load`), timed into `span`.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, load: Load, span: Option<Span>) {
        let Some((_, group)) = &self.volume else { return };
        if let Some(tiles) = &targets.slice_tiles {
            encoder.clear_buffer(tiles, 0, None);
        }
        let octants = self.octants && targets.octants.is_some();
        let mut pass = gbuffer::begin(encoder, "lineao::SliceRenderer", targets, load, octants, span);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bindings.group, &[]);
        pass.set_bind_group(1, group, &[]);
        pass.set_bind_group(2, &self.tiles, &[]);
        // One polygon an axis: a fan of OUTLINE_SIDES − 2 triangles.
        pass.draw(0..3 * (OUTLINE_SIDES as u32 - 2), 0..3);
    }
}

#[cfg(test)]
mod tests {
    use super::percentiles;

    #[test]
    fn the_uniform_matches_its_wgsl_struct() {
        crate::shader::assert_wgsl_layout!(
            super::SliceUniform,
            "slices.wgsl",
            "SliceUniform",
            [world_to_voxel, positions, shown, last_voxel, outline]
        );
    }

    #[test]
    fn percentiles_skip_zeros_and_non_finite_values_and_widen_a_constant_volume() {
        let values: Vec<f32> = (1..=101).map(|v| v as f32).chain([f32::NAN, f32::INFINITY, 0.0, 0.0]).collect();
        assert_eq!(percentiles(&values, [0.02, 0.98]), [3.0, 99.0]);
        assert_eq!(percentiles(&[3.0; 10], [0.02, 0.98]), [3.0, 4.0]);
        assert_eq!(percentiles(&[f32::NAN], [0.02, 0.98]), [0.0, 1.0]);
    }
}
