//! **Lines rasterized in compute**: the pieces the cull lists ([`crate::passes::cull`]) drawn by
//! compute shaders into a visibility buffer instead of by the hardware rasterizer, as point
//! renderers (Schütz, Kerbl & Wimmer, EGSR 2021) and Bevy's meshlets do it for primitives that
//! cover a few pixels each — what a thin line's quad is.
//!
//! A frame's phase (early or late) is three steps (`shaders/raster.wgsl`):
//! 1. `size_raster` turns the phase's indirect draws into an indirect dispatch: a workgroup of
//!    64 per instance (8 pieces of 8 segments).
//! 2. `raster`: an invocation per segment computes its quad's four corners as the vertex shader
//!    does (`shared/line_strip.wgsl`), and for each of its two triangles loops over the pixels
//!    of its box, testing each pixel centre against the triangle's edge functions in fixed
//!    point (1/256 pixel, top-left rule); a covered pixel gets `atomicMax` of
//!    `(!depth_bits) << 32 | id`, so the largest word holds the nearest fragment and its id
//!    (page, list slot, segment, triangle: [`MAX_PAGES`], [`MAX_SLOTS`]).
//! 3. the resolve, a full-screen draw per page, decodes the winning segment of each pixel
//!    again, interpolates its corners' outputs with perspective-correct barycentrics and writes
//!    the G-buffer and the depth, so the cull's depth pyramid is built from it as from the
//!    hardware's.
//!
//! The visibility buffer is a storage buffer of `u64` words (wgpu's
//! `SHADER_INT64_ATOMIC_MIN_MAX`; no R64 texture needed); a device without the feature draws
//! in hardware (`ComputeRaster::new` says why). It is a prototype measured against the
//! hardware draw (`lineao bench`'s `lines-compute` beside `lines-culled`): it leaves out
//! triangles with a corner behind the eye (the hardware clips them), the slab and the octant
//! outputs (object-space AO), and draws over nothing but a cleared frame.

use std::sync::Mutex;

use crate::binding::{self, Slot};
use crate::gbuffer::{self, GeometryBindings, Load, PipelineSpec};
use crate::line_geometry::{LineGeometry, Page};
use crate::passes::cull::{LineCull, Phase};
use crate::targets::FrameTargets;
use crate::timing::Span;

/// Pages a frame may hold (the page's index takes the id's top 5 bits).
pub const MAX_PAGES: usize = 32;
/// Slots a page's two lists may hold (23 bits of the id).
pub const MAX_SLOTS: u64 = 1 << 23;

/// What the rasterizing of one page binds besides the frame and the page: the visibility
/// buffer and the page's cull state and index (group 3 of `raster`), its indirect dispatch
/// (`size_raster`), and the resolve's view of the page, its lists and the visibility buffer.
struct RasterPage {
    /// The cull state and the page's bind group these were made for (a page's attributes
    /// replaced make a new group), and the visibility buffer.
    made_for: (wgpu::Buffer, wgpu::BindGroup, wgpu::Buffer),
    dispatch: wgpu::Buffer,
    sizing: wgpu::BindGroup,
    raster: wgpu::BindGroup,
    resolve_page: wgpu::BindGroup,
    resolve_pieces: wgpu::BindGroup,
    resolve: wgpu::BindGroup,
}

/// The compute rasterizer of the culled lines (see the module documentation).
pub struct ComputeRaster {
    device: wgpu::Device,
    /// `size_raster` and `raster` for each phase.
    sizing: [wgpu::ComputePipeline; 2],
    raster: [wgpu::ComputePipeline; 2],
    /// The resolve of every page's fragments (after the late phase), and of the depth alone
    /// (after the early one, for the depth pyramid: one pass whatever the pages).
    resolve: wgpu::RenderPipeline,
    resolve_depth: wgpu::RenderPipeline,
    sizing_layout: wgpu::BindGroupLayout,
    raster_layout: wgpu::BindGroupLayout,
    resolve_page_layout: wgpu::BindGroupLayout,
    resolve_pieces_layout: wgpu::BindGroupLayout,
    resolve_layout: wgpu::BindGroupLayout,
    /// The visibility buffer, for the targets' size.
    visibility: Mutex<Option<((u32, u32), wgpu::Buffer)>>,
    pages: Mutex<Vec<RasterPage>>,
}

impl ComputeRaster {
    /// The compute rasterizer for lines drawn with `bindings` (the line renderer's group 0) of
    /// the pages laid out as `page` — or why this device cannot have one.
    pub(crate) fn new(
        device: &wgpu::Device,
        bindings: &GeometryBindings,
        page: &wgpu::BindGroupLayout,
        pieces: &wgpu::BindGroupLayout,
    ) -> Result<ComputeRaster, String> {
        let needed = wgpu::Features::SHADER_INT64 | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX;
        if !device.features().contains(needed) {
            return Err(format!(
                "lines are drawn by the hardware rasterizer: this device lacks {:?} for a visibility buffer",
                needed - device.features()
            ));
        }
        let label = "lineao::ComputeRaster";
        let compute = wgpu::ShaderStages::COMPUTE;
        let storage = |read_only| wgpu::BufferBindingType::Storage { read_only };
        let uniform = wgpu::BufferBindingType::Uniform;
        let raster_layout =
            binding::buffers_layout(device, label, compute, &[(0, storage(false)), (1, storage(true)), (2, uniform)]);
        let sizing_layout = binding::buffers_layout(device, label, compute, &[(1, storage(true)), (4, storage(false))]);
        let fragment = wgpu::ShaderStages::FRAGMENT;
        // What the resolve reads of a page: its points, records, scalars and uniform.
        let page_entries =
            [(0, storage(true)), (1, storage(true)), (2, storage(true)), (4, storage(true)), (6, uniform)];
        let resolve_page_layout = binding::buffers_layout(device, label, fragment, &page_entries);
        let resolve_pieces_layout = binding::layout(device, label, fragment, &[Slot::Storage]);
        let resolve_layout = binding::buffers_layout(device, label, fragment, &[(2, uniform), (3, storage(true))]);
        let module = crate::shader::module(device, "raster.wgsl");
        let compute_pipeline = |entry: &str, phase: Phase, groups: &[Option<&wgpu::BindGroupLayout>]| {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: groups,
                immediate_size: 0,
            });
            let constants = [("PHASE", phase as u32 as f64)];
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
                cache: None,
            })
        };
        let phases = [Phase::Early, Phase::Late];

        let sizing =
            phases.map(|phase| compute_pipeline("size_raster", phase, &[None, None, None, Some(&sizing_layout)]));
        let raster_groups = [Some(&bindings.layout), Some(page), Some(pieces), Some(&raster_layout)];
        let raster = phases.map(|phase| compute_pipeline("raster", phase, &raster_groups));
        // Every pixel's nearest fragment is known: the resolve writes it whatever the depth
        // buffer holds (the early phase's depth alone, or nothing).
        let resolve_pipeline = |fragment, writes| {
            let spec = PipelineSpec {
                label,
                groups: &[&resolve_page_layout, &resolve_pieces_layout, &resolve_layout],
                module: &module,
                vertex: "vs_resolve",
                fragment,
                buffers: &[],
                topology: wgpu::PrimitiveTopology::TriangleList,
                octants: false,
                constants: &[],
            };
            gbuffer::pipeline_writing(device, bindings, spec, wgpu::CompareFunction::Always, writes)
        };
        let resolve = resolve_pipeline("fs_resolve", wgpu::ColorWrites::ALL);
        let resolve_depth = resolve_pipeline("fs_resolve_depth", wgpu::ColorWrites::empty());
        Ok(ComputeRaster {
            device: device.clone(),
            sizing,
            raster,
            resolve,
            resolve_depth,
            sizing_layout,
            raster_layout,
            resolve_page_layout,
            resolve_pieces_layout,
            resolve_layout,
            visibility: Mutex::new(None),
            pages: Mutex::new(Vec::new()),
        })
    }

    /// Why it cannot draw `geometry` into `targets` as the frame asks (`load`), if it cannot:
    /// the hardware path draws it then.
    pub(crate) fn unsupported(&self, targets: &FrameTargets, geometry: &LineGeometry, load: Load) -> Option<String> {
        if !matches!(load, Load::Clear(_)) {
            return Some("the compute raster draws only a frame's first geometry".into());
        }
        let pages = geometry.pages();
        if pages.len() > MAX_PAGES {
            return Some(format!("{} pages: the compute raster's ids hold {MAX_PAGES}", pages.len()));
        }
        let align = self.device.limits().min_storage_buffer_offset_alignment;
        if let Some(page) = pages.iter().find(|p| list_slots(p, align) > MAX_SLOTS) {
            return Some(format!(
                "a page of {} clusters: the compute raster's ids hold {MAX_SLOTS} slots",
                page.records
            ));
        }
        let bytes = visibility_bytes(targets.size);
        let max = self.device.limits().max_storage_buffer_binding_size;
        (bytes > max).then(|| {
            let (w, h) = targets.size;
            format!("a visibility buffer of {w} × {h} × 8 = {bytes} bytes exceeds the device's storage binding ({max})")
        })
    }

    fn visibility(&self, size: (u32, u32)) -> wgpu::Buffer {
        let mut visibility = self.visibility.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        match &*visibility {
            Some((made, buffer)) if *made == size => buffer.clone(),
            _ => {
                let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("lineao::ComputeRaster::visibility"),
                    size: visibility_bytes(size),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                *visibility = Some((size, buffer.clone()));
                buffer
            }
        }
    }

    /// Records `phase` of a culled frame of `geometry` into `targets` (`frame`: the renderer's
    /// group 0), in place of the hardware draw ([`LineCull::encode`]'s `draw`): the early phase
    /// clears the visibility buffer and the targets as `load` asks.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        cull: &LineCull,
        frame: &wgpu::BindGroup,
        phase: Phase,
        load: Load,
        span: Option<Span>,
    ) {
        let visibility = self.visibility(targets.size);
        if phase == Phase::Early {
            encoder.clear_buffer(&visibility, 0, None);
        }
        let mut pages = self.pages.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        pages.truncate(geometry.pages().len());
        for (index, page) in geometry.pages().iter().enumerate() {
            let state = cull.state(page);
            let made_for = (state.state.clone(), page.group.clone(), visibility.clone());
            if pages.get(index).is_none_or(|p| p.made_for != made_for) {
                let made = self.page(index, page, geometry.scalars(page), &state.state, &state.pieces, made_for);
                match pages.get_mut(index) {
                    Some(slot) => *slot = made,
                    None => pages.push(made),
                }
            }
        }
        let phase_index = phase as usize;
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("lineao::ComputeRaster"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.sizing[phase_index]);
            for raster in pages.iter() {
                pass.set_bind_group(3, &raster.sizing, &[]);
                pass.dispatch_workgroups(1, 1, 1);
            }
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("lineao::ComputeRaster"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.raster[phase_index]);
            pass.set_bind_group(0, frame, &[]);
            for (page, raster) in geometry.pages().iter().zip(pages.iter()) {
                pass.set_bind_group(1, &page.group, &[]);
                pass.set_bind_group(2, cull.state(page).draw_group(phase), &[]);
                pass.set_bind_group(3, &raster.raster, &[]);
                pass.dispatch_workgroups_indirect(&raster.dispatch, 16 * phase as u64);
            }
        }
        let mut pass =
            gbuffer::begin(encoder, "lineao::ComputeRaster::resolve", targets, phase.load(load), false, span);
        pass.set_pipeline(if phase == Phase::Early { &self.resolve_depth } else { &self.resolve });
        pass.set_bind_group(0, frame, &[]);
        let resolved = if phase == Phase::Early { &pages[..pages.len().min(1)] } else { &pages[..] };
        for raster in resolved {
            pass.set_bind_group(1, &raster.resolve_page, &[]);
            pass.set_bind_group(2, &raster.resolve_pieces, &[]);
            pass.set_bind_group(3, &raster.resolve, &[]);
            pass.draw(0..3, 0..1);
        }
    }

    /// The bind groups of page `index` (`page` and its `scalars`, its cull's `state` and
    /// `pieces`).
    fn page(
        &self,
        index: usize,
        page: &Page,
        scalars: &wgpu::Buffer,
        state: &wgpu::Buffer,
        pieces: &wgpu::Buffer,
        made_for: (wgpu::Buffer, wgpu::BindGroup, wgpu::Buffer),
    ) -> RasterPage {
        use wgpu::util::DeviceExt;
        let device = &self.device;
        let label = "lineao::ComputeRaster::page";
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(&[index as u32, 0, 0, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let dispatch = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: 32,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
            mapped_at_creation: false,
        });
        let visibility = &made_for.2;
        let group = |layout, buffers: &[(u32, &wgpu::Buffer)]| binding::buffers_group(device, label, layout, buffers);
        RasterPage {
            sizing: group(&self.sizing_layout, &[(1, state), (4, &dispatch)]),
            raster: group(&self.raster_layout, &[(0, visibility), (1, state), (2, &uniform)]),
            resolve_page: group(
                &self.resolve_page_layout,
                &[(0, &page.xy), (1, &page.z), (2, &page.clusters), (4, scalars), (6, &page.uniform)],
            ),
            resolve_pieces: binding::group(device, label, &self.resolve_pieces_layout, &[pieces.as_entire_binding()]),
            resolve: group(&self.resolve_layout, &[(2, &uniform), (3, visibility)]),
            dispatch,
            made_for,
        }
    }
}

/// Bytes of the visibility buffer of targets of `size`: a `u64` a pixel.
pub fn visibility_bytes((width, height): (u32, u32)) -> u64 {
    8 * width as u64 * height as u64
}

/// The slots of a page's two lists (each its pieces' room padded to a storage binding's
/// alignment `align`, as [`crate::passes::cull`] makes them).
fn list_slots(page: &Page, align: u32) -> u64 {
    let words = crate::passes::cull::PIECES_PER_CLUSTER * page.records as u64 + 16;
    2 * (4 * words).next_multiple_of(u64::from(align)) / 4
}
