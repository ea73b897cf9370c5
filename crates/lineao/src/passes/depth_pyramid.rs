//! The **depth pyramid** (a hierarchical max-depth buffer) that the line cull
//! ([`crate::passes::cull`]) tests against: level 0 is the G-buffer's hardware depth, and each
//! level above it, ⌈W/2⌉ × ⌈H/2⌉, keeps the *farthest* depth of the up to 2 × 2 texels below.
//! So texel (x, y) of level L bounds from behind every pixel of [x·2^L, (x+1)·2^L) ×
//! [y·2^L, (y+1)·2^L) (the last column and row of an odd level cover one texel below): a
//! fragment nearer than that may be visible there, one farther than it is hidden behind what
//! is already drawn at every one of those pixels. A rectangle of pixels spans at most 2 × 2
//! texels of the level where its longer side, in texels, is at most one, so four reads bound
//! the depth behind any rectangle — the test of meshlet renderers (Bevy's, Nanite's), here
//! kept conservative in every step (max, never min or an average: the ND pyramid's Gaussian
//! depth is no bound).
//!
//! All levels lie in one storage buffer, level after level (about 4/3 × 4 bytes a pixel).

use std::sync::Mutex;

use crate::binding::{self, Slot};
use crate::targets::{Target, level_sizes};

/// Levels the pyramid has at most (a side of 2^15 pixels).
pub const MAX_LEVELS: usize = 16;

/// What the cull reads of the pyramid. Keep in sync with `Pyramid` in `shaders/cull.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PyramidUniform {
    /// Level 0's size (the targets' guard-banded size).
    pub size: [u32; 2],
    /// How many levels it has.
    pub levels: u32,
    /// Padding to WGSL's 16-byte alignment.
    pub _pad: u32,
    /// Per level: its first texel in the buffer, its width and height.
    pub level: [[u32; 4]; MAX_LEVELS],
}

/// One reduction step. Keep in sync with `Level` in `shaders/depth_pyramid.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct LevelUniform {
    read_at: u32,
    write_at: u32,
    read_size: [u32; 2],
    write_size: [u32; 2],
    _pad: [u32; 2],
}

/// The pyramid built for one depth texture.
pub struct Built {
    /// The depth texture it is built from (rebuilt when the targets change).
    depth: wgpu::Texture,
    /// Every level, level 0 first.
    pub texels: wgpu::Buffer,
    /// [`PyramidUniform`] of this pyramid.
    pub uniform: wgpu::Buffer,
    /// Its levels' layout.
    pub description: PyramidUniform,
    steps: Vec<(wgpu::BindGroup, (u32, u32))>,
}

/// Builds the max-depth pyramid of a depth target (see the module documentation).
pub struct DepthPyramid {
    device: wgpu::Device,
    layout: wgpu::BindGroupLayout,
    copy: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
    built: Mutex<Option<std::sync::Arc<Built>>>,
}

impl DepthPyramid {
    /// Its pipeline and layout.
    pub fn new(device: &wgpu::Device) -> DepthPyramid {
        let label = "lineao::DepthPyramid";
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::DepthTexture { multisampled: false }, Slot::StorageReadWrite],
        );
        let pipeline = |entry| binding::compute_pipeline(device, label, &layout, "depth_pyramid.wgsl", entry, &[]);
        DepthPyramid {
            device: device.clone(),
            copy: pipeline("copy_depth"),
            reduce: pipeline("reduce_max"),
            layout,
            built: Mutex::new(None),
        }
    }

    /// Bytes of the pyramid of a `size` depth target (all levels).
    pub fn bytes(size: (u32, u32)) -> u64 {
        level_sizes(size, MAX_LEVELS as u32).iter().map(|&(w, h)| 4 * w as u64 * h as u64).sum()
    }

    /// The pyramid's buffers for `depth` (made when its texture changes).
    fn for_depth(&self, depth: &Target) -> std::sync::Arc<Built> {
        let mut built = self.built.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(b) = built.as_ref().filter(|b| b.depth == depth.texture) {
            return b.clone();
        }
        let b = std::sync::Arc::new(self.build(depth));
        *built = Some(b.clone());
        b
    }

    fn build(&self, depth: &Target) -> Built {
        use wgpu::util::DeviceExt;
        let device = &self.device;
        let label = "lineao::DepthPyramid";
        let sizes = level_sizes(depth.size(), MAX_LEVELS as u32);
        let levels = sizes.iter().position(|&s| s == (1, 1)).map_or(sizes.len(), |i| i + 1);
        let mut description = PyramidUniform {
            size: [depth.size().0, depth.size().1],
            levels: levels as u32,
            _pad: 0,
            level: [[0; 4]; MAX_LEVELS],
        };
        let mut first = 0u32;
        for (l, &(w, h)) in sizes.iter().take(levels).enumerate() {
            description.level[l] = [first, w, h, 0];
            first += w * h;
        }
        let texels = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lineao::DepthPyramid::texels"),
            size: 4 * first as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lineao::DepthPyramid::uniform"),
            contents: bytemuck::bytes_of(&description),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let steps = (0..levels)
            .map(|l| {
                let [write_at, w, h, _] = description.level[l];
                let [read_at, rw, rh, _] = description.level[l.saturating_sub(1)];
                let step = LevelUniform { read_at, write_at, read_size: [rw, rh], write_size: [w, h], _pad: [0; 2] };
                let step = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytemuck::bytes_of(&step),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let group = binding::group(
                    device,
                    label,
                    &self.layout,
                    &[
                        step.as_entire_binding(),
                        wgpu::BindingResource::TextureView(&depth.view),
                        texels.as_entire_binding(),
                    ],
                );
                (group, (w, h))
            })
            .collect();
        Built { depth: depth.texture.clone(), texels, uniform, description, steps }
    }

    /// Records the pyramid of `depth` as it is at this point of the encoder, timed into `span`.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        depth: &Target,
        span: Option<crate::timing::Span>,
    ) -> std::sync::Arc<Built> {
        let built = self.for_depth(depth);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lineao::DepthPyramid"),
            timestamp_writes: crate::timing::compute_writes(span),
        });
        for (l, (group, size)) in built.steps.iter().enumerate() {
            pass.set_pipeline(if l == 0 { &self.copy } else { &self.reduce });
            pass.set_bind_group(0, group, &[]);
            let (x, y) = super::dispatch_size(*size);
            pass.dispatch_workgroups(x, y, 1);
        }
        drop(pass);
        built
    }
}

#[cfg(test)]
#[test]
fn the_uniforms_match_their_wgsl_structs() {
    crate::shader::assert_wgsl_layout!(
        LevelUniform,
        "depth_pyramid.wgsl",
        "Level",
        [read_at, write_at, read_size, write_size]
    );
}
