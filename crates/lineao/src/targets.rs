//! The size-dependent textures of a frame: the G-buffer (color, ND map, zoom map, specular,
//! hardware depth), the ND pyramid and the AO result. One owner, rebuilt by `resize`, so passes
//! never allocate per frame.
//!
//! | texture   | format        | content                                                    |
//! |-----------|---------------|------------------------------------------------------------|
//! | color     | Rgba16Float   | linear base color of the lines; background color elsewhere |
//! | `nd[j]`   | Rgba32Float   | level j: view-space normal (xyz), normalized depth (w)     |
//! | zoom      | R32Float      | z(P): pixels per `zoom_unit` at P; 0 on background          |
//! | specular  | R32Float      | illuminated-lines specular, added in the composite         |
//! | depth     | Depth32Float  | hardware depth                                             |
//! | ao        | R32Float      | occlusion of the chosen method, 0 = none                   |
//! | ao_blurred| R32Float      | `ao` after the bilateral blur (via `ao_blur_tmp`; blur only)|
//! | octants   | Rg32Uint      | object-space AO: the lines' octant visibilities, unorm8 × 8 |
//! | volume_ao | R32Float      | object-space AO with the pixel's normal (`volume_ao` pass) |
//!
//! All at the guard-banded size; level j is ⌈W_{j−1}/2⌉ × ⌈H_{j−1}/2⌉ (docs/reference.md).
//! Object-space AO adds `octants` and `volume_ao` ([`FrameTargets::with_volume`]). What one
//! method alone reads and writes on the way to `ao` is that method's own (SSAO's occlusion
//! before its blur, VO area's moments pyramid, LineAO's `outer = level` targets: see
//! [`crate::method`]), allocated by its stage at the targets' size.

/// Half floats: plenty for a color, and with it the G-buffer a geometry pass writes is 32 bytes
/// per pixel, WebGPU's default `max_color_attachment_bytes_per_sample`, so the chain runs on a
/// host's device opened with default limits (object-space AO's octants need 40).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The ND map's format: n.xyz, d.
pub const ND_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The zoom map's format.
pub const ZOOM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// The specular term's format.
pub const SPECULAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// The hardware depth's format.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The occlusion's format.
pub const AO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// The eight octant visibilities of object-space AO per pixel, `pack4x8unorm` of octants 0–3
/// and 4–7.
pub const OCTANTS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;

/// A texture with its default view.
pub struct Target {
    /// The texture.
    pub texture: wgpu::Texture,
    /// A view of all of it.
    pub view: wgpu::TextureView,
}

impl Target {
    /// A texture of `size` and `format` with `usage`, and its view.
    pub fn new(
        device: &wgpu::Device,
        label: &str,
        (width, height): (u32, u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> Target {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        Target { texture, view }
    }

    /// An offscreen texture to composite into and read back (PNG output, tests, examples).
    pub fn output(device: &wgpu::Device, label: &str, size: (u32, u32), format: wgpu::TextureFormat) -> Target {
        Target::new(device, label, size, format, wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC)
    }

    /// An occlusion (R32Float) that compute passes write and later ones read, copied for
    /// readback and written by hosts and tests.
    pub fn ao(device: &wgpu::Device, label: &str, size: (u32, u32)) -> Target {
        Target::new(device, label, size, AO_FORMAT, AO_USAGE)
    }

    /// Its size in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.texture.width(), self.texture.height())
    }
}

/// Sizes of the pyramid levels for a level-0 size (each level ⌈previous/2⌉).
pub fn level_sizes((width, height): (u32, u32), levels: u32) -> Vec<(u32, u32)> {
    std::iter::successors(Some((width, height)), |&(w, h)| Some((w.div_ceil(2), h.div_ceil(2))))
        .take(levels as usize)
        .collect()
}

/// Keep in sync with `Levels` in `shaders/shared/nd.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LevelsUniform {
    /// Per level: its size over level 0's (x, y).
    pub scale: [[f32; 4]; 5],
    /// Per level: its size in texels (x, y).
    pub size: [[u32; 4]; 5],
}

/// How the AO targets are used: written by compute passes, read by later ones, copied for
/// readback and written by hosts and tests.
const AO_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::STORAGE_BINDING
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC)
    .union(wgpu::TextureUsages::COPY_DST);

/// The side in pixels of the tiles in which [`FrameTargets::slice_tiles`] marks the slices:
/// the bilateral blur's workgroup (a number the WGSL shares: `rust/constants.wgsl`).
pub use crate::shader::SLICE_TILE;

/// Tiles of [`SLICE_TILE`] pixels a side across and down a target of `size`.
pub fn tile_grid(size: (u32, u32)) -> (u32, u32) {
    (size.0.div_ceil(SLICE_TILE), size.1.div_ceil(SLICE_TILE))
}

/// Every size-dependent texture of the chain.
pub struct FrameTargets {
    /// Guard-banded size.
    pub size: (u32, u32),
    /// Guard band in pixels on each side.
    pub guard: u32,
    /// The base colour.
    pub color: Target,
    /// The ND pyramid; `nd[0]` is the ND map the geometry writes.
    pub nd: Vec<Target>,
    /// The zoom map.
    pub zoom: Target,
    /// The specular term the composite adds.
    pub specular: Target,
    /// The hardware depth.
    pub depth: Target,
    /// What the composite shows: the method's occlusion, after its blur if it has one.
    pub ao: Target,
    /// The bilateral blur's horizontal half, and its result.
    pub ao_blur_tmp: Option<Target>,
    /// The bilateral blur's result.
    pub ao_blurred: Option<Target>,
    /// With the blur: a `u32` per 8 × 8 tile ([`SLICE_TILE`], row-major), not 0 where an anatomy
    /// slice's fragment fell (`passes::slices` writes it, `passes::bilateral` reads it).
    pub slice_tiles: Option<wgpu::Buffer>,
    /// Object-space AO: the geometry's octant visibilities per pixel, and the occlusion the
    /// `volume_ao` pass makes of them.
    pub octants: Option<Target>,
    /// Object-space AO's occlusion.
    pub volume_ao: Option<Target>,
}

impl FrameTargets {
    /// Targets for a visible `width` × `height` window with a `guard` band and `levels` pyramid
    /// levels (≥ 1).
    pub fn new(device: &wgpu::Device, width: u32, height: u32, guard: u32, levels: u32) -> FrameTargets {
        use wgpu::TextureUsages as U;
        let size = (width + 2 * guard, height + 2 * guard);
        // COPY_DST lets a host (or a test) write a G-buffer of its own into the targets, storage
        // the pass that derives it from a host's depth.
        let attachment = U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC | U::COPY_DST;
        let gbuffer = attachment | U::STORAGE_BINDING;
        let level_usage = U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC;
        let sizes = level_sizes(size, levels.max(1));
        let nd = sizes
            .iter()
            .enumerate()
            .map(|(j, &level)| {
                let usage = if j == 0 { gbuffer } else { level_usage };
                Target::new(device, &format!("lineao::FrameTargets::nd[{j}]"), level, ND_FORMAT, usage)
            })
            .collect();
        FrameTargets {
            size,
            guard,
            color: Target::new(device, "lineao::FrameTargets::color", size, COLOR_FORMAT, gbuffer),
            nd,
            zoom: Target::new(device, "lineao::FrameTargets::zoom", size, ZOOM_FORMAT, gbuffer),
            specular: Target::new(device, "lineao::FrameTargets::specular", size, SPECULAR_FORMAT, gbuffer),
            depth: Target::new(device, "lineao::FrameTargets::depth", size, DEPTH_FORMAT, attachment),
            ao: Target::ao(device, "lineao::FrameTargets::ao", size),
            ao_blur_tmp: None,
            ao_blurred: None,
            slice_tiles: None,
            octants: None,
            volume_ao: None,
        }
    }

    /// These targets with the two of object-space AO (`octants`, `volume_ao`).
    pub fn with_volume(mut self, device: &wgpu::Device) -> FrameTargets {
        use wgpu::TextureUsages as U;
        let attachment = U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC | U::COPY_DST;
        let storage = U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC | U::COPY_DST;
        self.octants =
            Some(Target::new(device, "lineao::FrameTargets::octants", self.size, OCTANTS_FORMAT, attachment));
        self.volume_ao = Some(Target::new(device, "lineao::FrameTargets::volume_ao", self.size, AO_FORMAT, storage));
        self
    }

    /// These targets with the bilateral blur's two (`ao_blur_tmp`, `ao_blurred`) and the slices' tiles.
    pub fn with_blur(mut self, device: &wgpu::Device) -> FrameTargets {
        self.ao_blur_tmp = Some(Target::ao(device, "lineao::FrameTargets::ao_blur_tmp", self.size));
        self.ao_blurred = Some(Target::ao(device, "lineao::FrameTargets::ao_blurred", self.size));
        self.slice_tiles = Some(device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lineao::FrameTargets::slice_tiles"),
            size: 4 * self.tile_count() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
        self
    }

    /// Tiles of [`SLICE_TILE`] pixels a side across and down the guard-banded size.
    pub fn tiles(&self) -> (u32, u32) {
        tile_grid(self.size)
    }

    /// How many tiles [`FrameTargets::tiles`] makes.
    pub fn tile_count(&self) -> u32 {
        let (x, y) = self.tiles();
        x * y
    }

    /// What the composite shows: `ao_blurred` when the blur's targets exist, else `ao`.
    pub fn shown(&self) -> &Target {
        self.ao_blurred.as_ref().unwrap_or(&self.ao)
    }

    /// Visible size (without the guard band).
    pub fn visible_size(&self) -> (u32, u32) {
        (self.size.0 - 2 * self.guard, self.size.1 - 2 * self.guard)
    }

    /// Per-level (size_j / size_0, size_j) as the shaders' uniforms carry them, padded to
    /// [`crate::MAX_LEVELS`] with the last level.
    pub fn levels_uniform(&self) -> LevelsUniform {
        let (w0, h0) = self.size;
        let mut scale = [[0.0; 4]; 5];
        let mut size = [[0; 4]; 5];
        for k in 0..crate::MAX_LEVELS as usize {
            let (w, h) = self.nd[k.min(self.nd.len() - 1)].size();
            scale[k] = [w as f32 / w0 as f32, h as f32 / h0 as f32, 0.0, 0.0];
            size[k] = [w, h, 0, 0];
        }
        LevelsUniform { scale, size }
    }

    /// Views of the pyramid levels padded to [`crate::MAX_LEVELS`] with the last level, for the
    /// shaders' fixed bindings.
    pub fn level_views(&self) -> Vec<&wgpu::TextureView> {
        (0..crate::MAX_LEVELS as usize).map(|k| &self.nd[k.min(self.nd.len() - 1)].view).collect()
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(LevelsUniform, "shared/nd.wgsl", "Levels", [scale, size]);
}
