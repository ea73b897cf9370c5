//! The size-dependent textures of a frame: the G-buffer (color, ND map, zoom map, specular,
//! hardware depth), the ND pyramid and the AO result. One owner, rebuilt by `resize`, so passes
//! never allocate per frame.
//!
//! | texture   | format        | content                                                    |
//! |-----------|---------------|------------------------------------------------------------|
//! | color     | Rgba32Float   | linear base color of the lines; background color elsewhere |
//! | `nd[j]`   | Rgba32Float   | level j: view-space normal (xyz), normalized depth (w)     |
//! | zoom      | R32Float      | z(P): pixels per `zoom_unit` at P; 0 on background          |
//! | specular  | R32Float      | illuminated-lines specular, added in the composite         |
//! | depth     | Depth32Float  | hardware depth                                             |
//! | ao        | R32Float      | raw occlusion of the chosen method, 0 = none               |
//!
//! All at the guard-banded size; level j is ⌈W_{j−1}/2⌉ × ⌈H_{j−1}/2⌉ (CONTRACT.md).

pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const ND_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const ZOOM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
pub const SPECULAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub const AO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// A texture with its default view.
pub struct Target {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl Target {
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
    pub scale: [[f32; 4]; 5],
    pub size: [[u32; 4]; 5],
}

/// Every size-dependent texture of the chain.
pub struct FrameTargets {
    /// Guard-banded size.
    pub size: (u32, u32),
    /// Guard band in pixels on each side.
    pub guard: u32,
    pub color: Target,
    /// The ND pyramid; `nd[0]` is the ND map the geometry writes.
    pub nd: Vec<Target>,
    pub zoom: Target,
    pub specular: Target,
    pub depth: Target,
    /// What the composite shows: the method's occlusion, after its blur if it has one.
    pub ao: Target,
    /// A method's occlusion before its blur (SSAO); the blur writes `ao`.
    pub ao_raw: Target,
}

impl FrameTargets {
    /// Targets for a visible `width` × `height` window with a `guard` band and `levels` pyramid
    /// levels (≥ 1).
    pub fn new(device: &wgpu::Device, width: u32, height: u32, guard: u32, levels: u32) -> FrameTargets {
        use wgpu::TextureUsages as U;
        let size = (width + 2 * guard, height + 2 * guard);
        // COPY_DST lets a host (or a test) write a G-buffer of its own into the targets.
        let attachment = U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC | U::COPY_DST;
        let ao_usage = U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC | U::COPY_DST;
        let nd = level_sizes(size, levels.max(1))
            .into_iter()
            .enumerate()
            .map(|(j, level)| {
                let usage = if j == 0 { attachment } else { U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC };
                Target::new(device, &format!("lineao::FrameTargets::nd[{j}]"), level, ND_FORMAT, usage)
            })
            .collect();
        FrameTargets {
            size,
            guard,
            color: Target::new(device, "lineao::FrameTargets::color", size, COLOR_FORMAT, attachment),
            nd,
            zoom: Target::new(device, "lineao::FrameTargets::zoom", size, ZOOM_FORMAT, attachment),
            specular: Target::new(device, "lineao::FrameTargets::specular", size, SPECULAR_FORMAT, attachment),
            depth: Target::new(device, "lineao::FrameTargets::depth", size, DEPTH_FORMAT, attachment),
            ao: Target::new(device, "lineao::FrameTargets::ao", size, AO_FORMAT, ao_usage),
            ao_raw: Target::new(device, "lineao::FrameTargets::ao_raw", size, AO_FORMAT, ao_usage),
        }
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
