//! The moments pyramid of VO area sampling (Loos & Sloan §4.2; docs/reference.md "VO area").
//!
//! Area sampling needs the distribution of depth over a sample's footprint, at any footprint
//! size. As in variance shadow maps, the first two moments M₁ = E\[z\] and M₂ = E\[z²\] of depth
//! filter linearly: level l holds them over a footprint of about 2^l pixels, and a trilinear
//! read gives the mean μ = M₁ and the variance σ² = M₂ − M₁² of any footprint. Level 0 is the
//! linear depth z = −z_view (world units) of each pixel and its square, the background at the
//! far plane; each further level is the binomial 5 × 5 of the one below at half resolution
//! (`moments.wgsl`) — a Gaussian, as the paper recommends for its mip-map, so that
//! large footprints read smoothly. Everything in f32 (M₂ − M₁² cancels in f16). The levels
//! have mip-chain sizes, ⌊W/2^l⌋ down to 1, in one storage buffer ([`Moments`]). The CPU
//! reference is [`crate::reference::moments_pyramid`].

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_size;
use crate::shader::{Constant, Library};
use crate::targets::FrameTargets;
use crate::timing::{self, Span};
use crate::view_params::ViewParams;
use crate::view_params::ViewUniform;

/// Levels the moments pyramid can have (`moments_layout.wgsl`): enough for 32768² pixels.
pub const MAX_MOMENT_LEVELS: usize = 16;

/// The pyramid's WGSL and the number it shares with Rust (`moments_layout.wgsl`, which `vo_area.wgsl` imports too, reads it).
pub(crate) const LIBRARY: Library = Library {
    files: &[
        ("moments.wgsl", include_str!("moments.wgsl")),
        ("moments_layout.wgsl", include_str!("moments_layout.wgsl")),
    ],
    constants: &[("MAX_MOMENT_LEVELS", Constant::U32(MAX_MOMENT_LEVELS as u32))],
};

/// One level of [`Moments`]: `width` × `height` texels from element `offset`, row-major.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MomentsLevel {
    /// Its first element in the buffer.
    pub offset: u32,
    /// Its width in texels.
    pub width: u32,
    /// Its height in texels.
    pub height: u32,
}

/// VO area sampling's pyramid of depth moments ([`MomentsPyramid`] writes it): every level in one
/// storage buffer of `vec2<f32>` (E\[z\], E\[z²\]), and the layout as a uniform
/// (`array<vec4<u32>, 16>` of (offset, width, height, 0)).
pub struct Moments {
    /// Every level's (E[z], E[z²]).
    pub buffer: wgpu::Buffer,
    /// Where each level lies in `buffer`.
    pub levels: Vec<MomentsLevel>,
    /// The layout as a uniform.
    pub layout: wgpu::Buffer,
}

impl Moments {
    /// The pyramid read back as the CPU reference takes it: (E\[z\], E\[z²\]) per level.
    #[cfg(feature = "reference")]
    pub fn read(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<crate::reference::MomentsImage>, crate::Error> {
        let all: Vec<[f32; 2]> =
            bytemuck::pod_collect_to_vec(&crate::readback::read_buffer(device, queue, &self.buffer)?);
        let level = |l: &MomentsLevel| {
            let (start, width, height) = (l.offset as usize, l.width as usize, l.height as usize);
            crate::image::Image { width, height, data: all[start..start + width * height].to_vec() }
        };
        Ok(self.levels.iter().map(level).collect())
    }

    /// Level l is ⌊W_{l−1}/2⌋ × ⌊H_{l−1}/2⌋ (at least 1) down to 1 × 1, as a mip chain.
    pub fn levels((width, height): (u32, u32)) -> Vec<MomentsLevel> {
        let mut levels = vec![MomentsLevel { offset: 0, width, height }];
        while let Some(&last) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            levels.push(MomentsLevel {
                offset: last.offset + last.width * last.height,
                width: (last.width / 2).max(1),
                height: (last.height / 2).max(1),
            });
        }
        levels
    }

    /// Bytes of the buffer for a `size` pyramid.
    pub fn bytes(size: (u32, u32)) -> u64 {
        let last = *Moments::levels(size).last().expect("level 0 exists");
        (last.offset as u64 + (last.width * last.height) as u64) * 8
    }

    /// The buffers for a guard-banded `size`.
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> Moments {
        use wgpu::util::DeviceExt;
        let levels = Moments::levels(size);
        let mut rects = [[0u32; 4]; MAX_MOMENT_LEVELS];
        for (rect, l) in rects.iter_mut().zip(&levels) {
            *rect = [l.offset, l.width, l.height, 0];
        }
        Moments {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lineao::Moments"),
                size: Moments::bytes(size),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            layout: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("lineao::Moments::layout"),
                contents: bytemuck::cast_slice(&rects),
                usage: wgpu::BufferUsages::UNIFORM,
            }),
            levels,
        }
    }
}

/// Whether VO area's moments pyramid for a guard-banded `size` fits the device's storage
/// buffers (the method's entry in the registry's size check).
pub(crate) fn fits(size: (u32, u32), limits: &wgpu::Limits) -> Result<(), crate::Error> {
    crate::method::fits_storage("VO area's moments pyramid", size, Moments::bytes(size), limits)
}

/// The pass that writes [`Moments`] from `nd[0]`; it owns the pyramid, sized by `resize`.
pub struct MomentsPyramid {
    level0: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    /// Per level: the bind group that writes it (with its own level-index uniform), its size.
    groups: Vec<(wgpu::BindGroup, (u32, u32))>,
    moments: Option<Moments>,
}

impl MomentsPyramid {
    /// The passes that build the pyramid.
    pub fn new(device: &wgpu::Device) -> MomentsPyramid {
        let label = "lineao::MomentsPyramid";
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::Uniform, Slot::Uniform, Slot::Texture, Slot::StorageReadWrite],
        );
        let pipeline =
            |entry| binding::compute_pipeline(device, label, &layout, LIBRARY.source("moments.wgsl"), entry, &[]);
        MomentsPyramid {
            level0: pipeline("level0"),
            downsample: pipeline("downsample"),
            uniform: binding::uniform_buffer::<ViewUniform>(device, label),
            layout,
            groups: Vec::new(),
            moments: None,
        }
    }

    /// Allocates the pyramid for `targets`' size and binds it: reads `nd[0]`, writes every
    /// level. The caller checks the size against the device's storage-buffer limits
    /// ([`Moments::bytes`]; the chain does, through the registry).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let moments = Moments::new(device, targets.size);
        self.groups = (0..moments.levels.len()).map(|l| self.level_group(device, targets, &moments, l)).collect();
        self.moments = Some(moments);
    }

    /// The pyramid, once sized.
    pub fn moments(&self) -> Option<&Moments> {
        self.moments.as_ref()
    }

    fn level_group(
        &self,
        device: &wgpu::Device,
        targets: &FrameTargets,
        moments: &Moments,
        l: usize,
    ) -> (wgpu::BindGroup, (u32, u32)) {
        use wgpu::util::DeviceExt;
        let index = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lineao::MomentsPyramid::level"),
            contents: bytemuck::cast_slice(&[l as u32, 0, 0, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let group = binding::group(
            device,
            &format!("lineao::MomentsPyramid[{l}]"),
            &self.layout,
            &[
                self.uniform.as_entire_binding(),
                moments.layout.as_entire_binding(),
                index.as_entire_binding(),
                wgpu::BindingResource::TextureView(&targets.nd[0].view),
                moments.buffer.as_entire_binding(),
            ],
        );
        (group, (moments.levels[l].width, moments.levels[l].height))
    }

    /// Writes this frame's view.
    pub fn prepare(&self, queue: &wgpu::Queue, view: &FrameView) {
        let uniform: ViewUniform = ViewParams::of(view).into();
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records every level, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, span: Option<Span>) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lineao::MomentsPyramid"),
            timestamp_writes: timing::compute_writes(span),
        });
        for (l, (group, size)) in self.groups.iter().enumerate() {
            pass.set_pipeline(if l == 0 { &self.level0 } else { &self.downsample });
            pass.set_bind_group(0, group, &[]);
            let (x, y) = dispatch_size(*size);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}
