//! Separable bilateral blur, usable after any method.
//!
//! Sparse samples leave noise (SSAO's 4 × 4 pattern, VO's reflected line sets, LineAO's random
//! hemispheres); a plain blur would remove it but also smear occlusion across depth edges —
//! from a line in front onto the bundle behind it. A bilateral blur weighs each neighbour by
//! its distance on screen *and* in depth:
//!
//! ```text
//!   ao'(P) = Σ_k w_k ao(P + k e) / Σ_k w_k,   w_k = exp(−k²/(2σ_s²) − (z_k − z_P)²/(2σ_z²))
//! ```
//!
//! over k ∈ [−r, r] along x, then along y (separable: 2(2r + 1) taps instead of (2r + 1)²),
//! σ_s = r/2, σ_z in world units (`BilateralSettings`). Background pixels neither receive nor
//! give occlusion. Reads `ao`, writes `ao_blur_tmp` then `ao_blurred`, which the composite
//! shows when the blur is on. The CPU reference is [`crate::reference::bilateral`].
//!
//! Over anatomy slices the chain runs it on their pixels only
//! ([`crate::ChainSettings::bilateral`]): the slices' pass writes the G-buffer colour's alpha
//! as 0, every other writer 1, and a pixel whose alpha is not 0 keeps its occlusion (it still
//! gives it to the slices' pixels around it). Then the two halves run only over the 8 × 8 tiles
//! that the slices' fragments marked ([`FrameTargets::slice_tiles`]) and that still show a
//! slice's pixel once everything is drawn (the slices are drawn first, and the lines in front
//! hide every pixel of about half the marked tiles), listed on the GPU and dispatched
//! indirectly: on lavapipe each invocation costs about 13 ns whatever it does, so a pass over
//! the slices' rectangle on screen cost 21 of its 39 ms with no pixel to blur. `ao` is copied to
//! both halves' outputs first: elsewhere no pixel is a slice's, so the copies hold what the
//! halves would write there — which the y half reads above and below its tiles.

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_size;
use crate::settings::BilateralSettings;
use crate::targets::{AO_FORMAT, FrameTargets, tile_grid};
use crate::timing::{self, Span};
use crate::view_params::ViewParams;
use crate::view_params::ViewUniform;

/// Keep in sync with `BilateralUniform` in `shaders/bilateral.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BilateralUniform {
    /// The view's parameters.
    pub view: ViewUniform,
    /// Taps on each side.
    pub radius: i32,
    /// 1/(2σ_s²), σ_s = radius/2.
    pub spatial: f32,
    /// 1/(2σ_z²).
    pub depth: f32,
    /// 1: only the anatomy slices' pixels receive.
    pub slices_only: u32,
    /// Tiles across and down (and two spare).
    pub tiles: [u32; 4],
}

impl BilateralUniform {
    /// The uniform for `view`, `settings` and the region the blur covers.
    pub fn new(view: &FrameView, settings: &BilateralSettings, region: Region) -> BilateralUniform {
        let sigma_s = settings.radius_px as f32 * 0.5;
        let (x, y) = tile_grid(view.banded_size());
        BilateralUniform {
            view: ViewParams::of(view).into(),
            radius: settings.radius_px as i32,
            spatial: 1.0 / (2.0 * sigma_s * sigma_s),
            depth: 1.0 / (2.0 * settings.depth_sigma_world * settings.depth_sigma_world),
            slices_only: (region == Region::Slices) as u32,
            tiles: [x, y, 0, 0],
        }
    }
}

/// Which pixels the blur smooths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// Every geometry pixel.
    All,
    /// The anatomy slices' pixels (the G-buffer colour's alpha 0), in the tiles they marked.
    Slices,
}

/// The listed tiles' bind group and buffers.
struct Tiles {
    /// The listing's group 1 (its group 0 is empty).
    group: wgpu::BindGroup,
    lists: wgpu::Buffer,
    dispatches: wgpu::Buffer,
}

/// The separable, depth-aware blur after a method: a horizontal and a vertical pass.
pub struct Bilateral {
    /// Along x, then along y: over every pixel, and over the listed tiles.
    pipelines: [wgpu::ComputePipeline; 2],
    tile_pipelines: [wgpu::ComputePipeline; 2],
    /// `list_tiles`, `dispatch_args`.
    listing: [wgpu::ComputePipeline; 2],
    layout: wgpu::BindGroupLayout,
    tiles_layout: wgpu::BindGroupLayout,
    empty: wgpu::BindGroup,
    uniform: wgpu::Buffer,
    groups: Vec<wgpu::BindGroup>,
    tiles: Option<Tiles>,
    /// The region of the last `prepare`.
    region: Region,
}

impl Bilateral {
    /// Its pipelines and layout.
    pub fn new(device: &wgpu::Device) -> Bilateral {
        let label = "lineao::Bilateral";
        use Slot::*;
        let layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[Uniform, Texture, Texture, StorageTexture(AO_FORMAT), Texture, Storage],
        );
        let tiles_layout = binding::layout(
            device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[Uniform, Storage, StorageReadWrite, StorageReadWrite, Texture],
        );
        let empty_layout = binding::layout(device, label, wgpu::ShaderStages::COMPUTE, &[]);
        let module = crate::shader::module(device, "bilateral.wgsl");
        let blurs = binding::pipeline_layout(device, label, &layout);
        let listings = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&empty_layout), Some(&tiles_layout)],
            immediate_size: 0,
        });
        let pipeline = |layout: &wgpu::PipelineLayout, entry: &str, axis: f64| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &[("AXIS", axis)],
                    ..Default::default()
                },
                cache: None,
            })
        };
        Bilateral {
            pipelines: [pipeline(&blurs, "bilateral", 0.0), pipeline(&blurs, "bilateral", 1.0)],
            tile_pipelines: [pipeline(&blurs, "bilateral_tiles", 0.0), pipeline(&blurs, "bilateral_tiles", 1.0)],
            listing: [pipeline(&listings, "list_tiles", 0.0), pipeline(&listings, "dispatch_args", 0.0)],
            uniform: binding::uniform_buffer::<BilateralUniform>(device, label),
            empty: binding::group(device, label, &empty_layout, &[]),
            layout,
            tiles_layout,
            groups: Vec::new(),
            tiles: None,
            region: Region::All,
        }
    }

    /// `ao` → `ao_blur_tmp` (x) → `ao_blurred` (y), depth from `nd[0]`, the slices' mark from
    /// `color` and their tiles from `slice_tiles` (without the blur's targets the pass records
    /// nothing).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let (Some(tmp), Some(blurred), Some(marked)) =
            (&targets.ao_blur_tmp, &targets.ao_blurred, &targets.slice_tiles)
        else {
            self.groups.clear();
            self.tiles = None;
            return;
        };
        let label = "lineao::Bilateral";
        let storage = |size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | usage,
                mapped_at_creation: false,
            })
        };
        // A count (and three spare), then room for every tile.
        let lists = storage(16 + 4 * targets.tile_count() as u64, wgpu::BufferUsages::COPY_DST);
        let dispatches = storage(12, wgpu::BufferUsages::INDIRECT);
        let [uniform, marked, listed, dispatched] =
            [&self.uniform, marked, &lists, &dispatches].map(wgpu::Buffer::as_entire_binding);
        let color = wgpu::BindingResource::TextureView(&targets.color.view);
        let group = binding::group(device, label, &self.tiles_layout, &[uniform, marked, listed, dispatched, color]);
        let halves = [(&targets.ao, tmp), (tmp, blurred)];
        self.groups = halves
            .iter()
            .map(|(src, dst)| {
                binding::group(
                    device,
                    label,
                    &self.layout,
                    &[
                        self.uniform.as_entire_binding(),
                        wgpu::BindingResource::TextureView(&targets.nd[0].view),
                        wgpu::BindingResource::TextureView(&src.view),
                        wgpu::BindingResource::TextureView(&dst.view),
                        wgpu::BindingResource::TextureView(&targets.color.view),
                        lists.as_entire_binding(),
                    ],
                )
            })
            .collect();
        self.tiles = Some(Tiles { group, lists, dispatches });
    }

    /// Writes the uniform for `view`, `settings` and the pixels of `region`.
    pub fn prepare(&mut self, queue: &wgpu::Queue, view: &FrameView, settings: &BilateralSettings, region: Region) {
        let uniform = BilateralUniform::new(view, settings, region);
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        self.region = region;
    }

    /// Records both halves (over the slices: after listing their tiles), timed into `span`
    /// when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let (Some(tmp), Some(blurred), Some(tiles), false) =
            (&targets.ao_blur_tmp, &targets.ao_blurred, &self.tiles, self.groups.is_empty())
        else {
            return;
        };
        fn pass<'e>(encoder: &'e mut wgpu::CommandEncoder, span: Option<Span>) -> wgpu::ComputePass<'e> {
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("lineao::Bilateral"),
                timestamp_writes: timing::compute_writes(span),
            })
        }
        if self.region == Region::All {
            let mut pass = pass(encoder, span);
            let (x, y) = dispatch_size(targets.size);
            for (pipeline, group) in self.pipelines.iter().zip(&self.groups) {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
            return;
        }
        encoder.clear_buffer(&tiles.lists, 0, Some(16));
        // Separate passes: on lavapipe, dispatches within one pass did not see each other's
        // writes (`passes::cull`). The copies within the timed span.
        let (first, last) = Span::split(span);
        let listing = |encoder: &mut wgpu::CommandEncoder, pipeline, size, span| {
            let mut pass = pass(encoder, span);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &self.empty, &[]);
            pass.set_bind_group(1, &tiles.group, &[]);
            pass.dispatch_workgroups(size, 1, 1);
        };
        let [list, args] = &self.listing;
        listing(encoder, list, targets.tile_count().div_ceil(64), first);
        for copy in [tmp, blurred] {
            let size = targets.ao.texture.size();
            encoder.copy_texture_to_texture(targets.ao.texture.as_image_copy(), copy.texture.as_image_copy(), size);
        }
        listing(encoder, args, 1, None);
        let mut pass = pass(encoder, last);
        for (pipeline, group) in self.tile_pipelines.iter().zip(&self.groups) {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups_indirect(&tiles.dispatches, 0);
        }
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        BilateralUniform,
        "bilateral.wgsl",
        "BilateralUniform",
        [view, radius, spatial, depth, slices_only, tiles]
    );
}
