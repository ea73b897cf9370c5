//! **Culling the lines on the GPU**, exactly: only the pieces of streamline that can leave a
//! fragment in front of what is already drawn are drawn. A whole brain seen from outside is a
//! hairy surface hundreds of lines deep (`scripts/depth-complexity.py`: 225 fragments a
//! covered pixel at 10 M points), and screen-space AO sees only the front one.
//!
//! The unit is a **piece**: eight segments of a cluster's strip (`line_geometry`), so a
//! cluster of 24 points has three. Pieces are drawn as their part of the *full* strip — the
//! same triangles, so culled lines draw the full strip's pixels exactly; the alternating strip
//! (half the vertices) is for drawing everything, which culling replaces.
//!
//! Two phases a frame, as meshlet renderers do it (Bevy's, Nanite's), so nothing visible is
//! ever missed, with no read back:
//! 1. **early**: a compute pass lists the pieces that were visible in the last frame, and they
//!    are drawn — most of what this frame shows, when the camera moved little;
//! 2. the [`DepthPyramid`] of the depth they left is built (farthest depth per texel);
//! 3. **late**: compute passes test every piece against the view and the pyramid, mark it
//!    visible or not for the next frame, and list the visible ones not drawn early, which are
//!    drawn over the first;
//! 4. **settle**: the pyramid of the frame's final depth, and the pieces marked visible are
//!    tested again against it, so that the next frame's early list holds only what this frame
//!    shows (after a first frame or a cut, the late phase marks everything that passed against
//!    the early depth: without this the second frame would draw nearly all again).
//!
//! **The tests** (`shaders/cull.wgsl`) run coarse to fine. A page's clusters lie along a
//! Morton curve within their draw class, so 64 consecutive ones (a *group*) are a small region
//! of space: `test_groups` tests each group's box (8 projected corners) and lists those that
//! may be visible, clearing the marks of the others; then a workgroup per listed group runs an
//! invocation per piece, which tests the piece *segment by segment*. A segment's two triangles
//! have their corners half a line width from its two points on screen, at those points' depths
//! (the vertex shader pushes points sideways on screen only), so its fragments lie within half a
//! line width (and a pixel, for rounding) of the two points' box on screen and no nearer than
//! the nearer point. It is hidden when that box lies outside the target, or when its nearest
//! depth lies behind the farthest depth the pyramid holds over the box (at the level where the
//! box spans at most 2 × 2 texels): then every pixel it could cover already holds a nearer
//! fragment, and the depth test would discard all of its own. A piece is visible where one of
//! its segments is. Segments span a few pixels, so the boxes are tight and the pyramid is read
//! at fine levels: on a whole brain of 10 M points seen from outside, boxes of whole 24-point
//! clusters passed 35 % of the clusters, segments 8 % of the pieces.
//!
//! Every piece not drawn early passes this test against a depth buffer holding a subset of
//! what drawing everything leaves, so what it culls is hidden in the full picture too: the
//! G-buffer is the one drawing every piece leaves, but where two fragments tie exactly in depth
//! and the order decides. A first frame, a camera cut or a resize costs one full draw (nothing
//! was visible before, so the late phase draws all that passes against an empty pyramid).
//!
//! Each page keeps its state ([`PageCull`]): a word a cluster (its visible pieces), the list
//! of pieces to draw (a word each), the listed groups and the indirect draws and dispatch:
//! about 0.7 bytes a point, made on the page's first culled frame.

use std::sync::Arc;

use crate::binding::{self, Slot};
use crate::line_geometry::{GROUP_CLUSTERS, LineGeometry, Page};
use crate::passes::Load;
use crate::passes::depth_pyramid::{Built, DepthPyramid};
use crate::targets::FrameTargets;
use crate::timing::Span;

/// Workgroups per row of a dispatch, as `ROW` in `shaders/cull.wgsl`.
const ROW: u32 = 32768;
/// Invocations of a workgroup of `early` (one a cluster) and `test_groups` (one a group).
const WORKGROUP_INVOCATIONS: u32 = 64;
/// Pieces a cluster has at most (24 segments of 8).
pub const PIECES_PER_CLUSTER: u64 = 3;
/// Words of a page's state before its marks: the indirect draws, early and late, the count of
/// listed groups and of each draw's pieces (`state` in `shaders/cull.wgsl`).
const STATE_HEADER_WORDS: u64 = 16;
/// Bytes of the listed groups' indirect dispatch and their count (`listing`).
const LISTING_BYTES: u64 = 16;

/// Dispatches 64 invocations per workgroup over `count` items (rows of [`ROW`] workgroups).
fn dispatch_over(pass: &mut wgpu::ComputePass, count: u32) {
    let groups = count.div_ceil(WORKGROUP_INVOCATIONS);
    pass.dispatch_workgroups(groups.min(ROW), groups.div_ceil(ROW), 1);
}

/// Which of a frame's two draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// The pieces visible in the last frame.
    Early,
    /// The visible pieces the early draw did not draw.
    Late,
}

impl Phase {
    /// How its draw loads the targets: the early one as the frame asks, the late one over it.
    pub fn load(self, frame: Load) -> Load {
        match self {
            Phase::Early => frame,
            Phase::Late => Load::Keep,
        }
    }

    /// Where its indirect arguments lie in a page's draws buffer.
    pub fn offset(self) -> u64 {
        match self {
            Phase::Early => 0,
            Phase::Late => 16,
        }
    }
}

/// A page's culling state (see the module documentation).
pub struct PageCull {
    /// The indirect draws (and, in the same buffer, the marks and the listed groups).
    pub(crate) state: wgpu::Buffer,
    /// The visible pieces, read by the vertex shader (`lines.wgsl`'s group 2).
    pub(crate) draw_group: wgpu::BindGroup,
    compute_group: wgpu::BindGroup,
    /// With the listed groups' dispatch (`test_groups`, `size_dispatch`).
    listing_group: wgpu::BindGroup,
    /// The page's arrays the tests read.
    geometry: wgpu::BindGroup,
    pieces: wgpu::Buffer,
    listing: wgpu::Buffer,
}

impl PageCull {
    /// Bytes of its buffers.
    pub fn bytes(&self) -> u64 {
        self.state.size() + self.pieces.size() + self.listing.size()
    }
}

/// The layout of the page's arrays the tests read: points, records and group boxes, at their
/// bindings in `shaders/shared/clusters.wgsl`.
fn geometry_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entries = [0, 1, 2, 7].map(|binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    });
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("lineao::LineCull::geometry"),
        entries: &entries,
    })
}

/// The layout of the visible pieces as the vertex shader reads them (group 2 of the culled
/// line pipelines).
pub(crate) fn pieces_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    binding::layout(device, "lineao::LineCull::pieces", wgpu::ShaderStages::VERTEX, &[Slot::Storage])
}

/// The two-phase cull of [`LineGeometry`]'s pieces (see the module documentation).
pub struct LineCull {
    device: wgpu::Device,
    pyramid: DepthPyramid,
    early: wgpu::ComputePipeline,
    test_groups: wgpu::ComputePipeline,
    size_dispatch: wgpu::ComputePipeline,
    late: wgpu::ComputePipeline,
    settle: wgpu::ComputePipeline,
    /// A page's points, records and group boxes (`clusters.wgsl`'s bindings 0, 1, 2, 7).
    geometry_layout: wgpu::BindGroupLayout,
    pyramid_layout: wgpu::BindGroupLayout,
    state_layout: wgpu::BindGroupLayout,
    listing_layout: wgpu::BindGroupLayout,
    /// The pyramid's bind group, made once for each pyramid (the targets' size).
    pyramid_group: std::sync::Mutex<Option<(Arc<Built>, wgpu::BindGroup)>>,
    pieces_layout: wgpu::BindGroupLayout,
}

impl LineCull {
    /// The cull of geometry drawn with `frame` (the line renderer's group 0: its frame
    /// uniform and lighting).
    pub fn new(device: &wgpu::Device, frame: &wgpu::BindGroupLayout) -> LineCull {
        let label = "lineao::LineCull";
        let compute = wgpu::ShaderStages::COMPUTE;
        let pyramid_layout = binding::layout(device, label, compute, &[Slot::Uniform, Slot::Storage]);
        // The state and the pieces, and with the listed groups' dispatch (for the passes that
        // write it). With the page's four arrays and the pyramid, eight storage buffers: the
        // WebGPU default a stage may bind.
        let state = [Slot::StorageReadWrite; 3];
        let state_layout = binding::layout(device, label, compute, &state[..2]);
        let listing_layout = binding::layout(device, label, compute, &state);
        let page = geometry_layout(device);
        let module = crate::shader::module(device, "cull.wgsl");
        let pipeline = |entry: &str, groups: &[Option<&wgpu::BindGroupLayout>]| {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: groups,
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let all = [Some(frame), Some(&page), Some(&pyramid_layout), Some(&state_layout)];
        let listing = [Some(frame), Some(&page), Some(&pyramid_layout), Some(&listing_layout)];
        LineCull {
            device: device.clone(),
            pyramid: DepthPyramid::new(device),
            early: pipeline("early", &[None, Some(&page), None, Some(&state_layout)]),
            test_groups: pipeline("test_groups", &listing),
            size_dispatch: pipeline("size_dispatch", &[None, None, None, Some(&listing_layout)]),
            late: pipeline("late", &all),
            settle: pipeline("settle", &all),
            pieces_layout: pieces_layout(device),
            geometry_layout: page,
            pyramid_layout,
            state_layout,
            listing_layout,
            pyramid_group: std::sync::Mutex::new(None),
        }
    }

    /// Why this device cannot cull into `targets`, if it cannot: the pyramid is one storage
    /// binding (the rest of the state fits where a page's points do).
    pub fn unsupported(&self, targets: &FrameTargets) -> Option<String> {
        let limits = self.device.limits();
        let bytes = DepthPyramid::bytes(targets.size);
        let most = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        (bytes > most).then(|| {
            format!(
                "lines drawn whole, not culled: the depth pyramid of {} x {} px takes {bytes} bytes, over the \
                 device's storage binding limit of {most}",
                targets.size.0, targets.size.1
            )
        })
    }

    /// The bind group of pyramid `built` (made when the pyramid is).
    fn pyramid_group(&self, built: &Arc<Built>) -> wgpu::BindGroup {
        let mut cached = self.pyramid_group.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        match cached.as_ref() {
            Some((of, group)) if Arc::ptr_eq(of, built) => group.clone(),
            _ => {
                let group = binding::group(
                    &self.device,
                    "lineao::LineCull::pyramid",
                    &self.pyramid_layout,
                    &[built.uniform.as_entire_binding(), built.texels.as_entire_binding()],
                );
                *cached = Some((built.clone(), group.clone()));
                group
            }
        }
    }

    /// `page`'s state, made on its first frame.
    pub(crate) fn state<'p>(&self, page: &'p Page) -> &'p PageCull {
        page.cull.get_or_init(|| {
            let device = &self.device;
            let buffer = |label, size: u64, usage| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: wgpu::BufferUsages::STORAGE | usage,
                    mapped_at_creation: false,
                })
            };
            let clusters = page.records as u64;
            let groups = clusters.div_ceil(GROUP_CLUSTERS as u64);
            // Zeroed at creation: nothing was visible before the first frame.
            let state = buffer(
                "lineao::LineCull::state",
                4 * (STATE_HEADER_WORDS + clusters + groups),
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            );
            let pieces =
                buffer("lineao::LineCull::pieces", 4 * PIECES_PER_CLUSTER * clusters, wgpu::BufferUsages::empty());
            let listing = buffer(
                "lineao::LineCull::listing",
                LISTING_BYTES,
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            );
            let bound = [&state, &pieces, &listing].map(|b| b.as_entire_binding());
            let group =
                |layout, count: usize| binding::group(device, "lineao::LineCull::state", layout, &bound[..count]);
            let compute_group = group(&self.state_layout, 2);
            let listing_group = group(&self.listing_layout, 3);
            let draw_group =
                binding::group(device, "lineao::LineCull::pieces", &self.pieces_layout, &[pieces.as_entire_binding()]);
            let geometry = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("lineao::LineCull::geometry"),
                layout: &self.geometry_layout,
                entries: &[(0, &page.xy), (1, &page.z), (2, &page.clusters), (7, &page.groups)]
                    .map(|(binding, buffer)| wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }),
            });
            PageCull { state, draw_group, compute_group, listing_group, geometry, pieces, listing }
        })
    }

    /// Records a frame of `geometry` into `targets`: the early list and `draw(Phase::Early)`
    /// (which loads the targets as the frame asks, the late draw keeping what it left),
    /// the pyramid, the late test and `draw(Phase::Late)`, the pyramid again and the settling
    /// test; `frame` is the renderer's group 0, written for this frame. `span` times all of it.
    pub fn encode<'s>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        frame: &wgpu::BindGroup,
        span: Option<Span<'s>>,
        mut draw: impl FnMut(&mut wgpu::CommandEncoder, Phase, Option<Span<'s>>),
    ) {
        let (first, last) = Span::split(span);
        let pages = geometry.pages();
        for page in pages {
            encoder.clear_buffer(&self.state(page).state, 0, Some(4 * STATE_HEADER_WORDS));
        }
        {
            let mut pass = self.compute_pass(encoder, first);
            pass.set_pipeline(&self.early);
            for page in pages {
                let state = self.state(page);
                pass.set_bind_group(1, &state.geometry, &[]);
                pass.set_bind_group(3, &state.compute_group, &[]);
                dispatch_over(&mut pass, page.records);
            }
        }
        draw(encoder, Phase::Early, None);
        let built = self.pyramid.encode(encoder, &targets.depth, None);
        self.test(encoder, pages, frame, &built, &self.late, None);
        draw(encoder, Phase::Late, None);
        let built = self.pyramid.encode(encoder, &targets.depth, None);
        self.test(encoder, pages, frame, &built, &self.settle, last);
    }

    fn compute_pass<'e>(&self, encoder: &'e mut wgpu::CommandEncoder, span: Option<Span>) -> wgpu::ComputePass<'e> {
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lineao::LineCull"),
            timestamp_writes: crate::timing::compute_writes(span),
        })
    }

    /// One compute pass testing every page's groups against the pyramid `built`, then the
    /// pieces of the listed groups with `pieces` (the late test or the settling).
    fn test(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pages: &[Page],
        frame: &wgpu::BindGroup,
        built: &Arc<Built>,
        pieces: &wgpu::ComputePipeline,
        span: Option<Span>,
    ) {
        let pyramid = self.pyramid_group(built);
        for page in pages {
            encoder.clear_buffer(&self.state(page).listing, 0, None);
        }
        // Three passes: on lavapipe, dispatches within one pass did not see each other's
        // writes.
        let (first, last) = Span::split(span);
        let mut pass = self.compute_pass(encoder, first);
        pass.set_bind_group(0, frame, &[]);
        pass.set_bind_group(2, &pyramid, &[]);
        pass.set_pipeline(&self.test_groups);
        for page in pages {
            let state = self.state(page);
            pass.set_bind_group(1, &state.geometry, &[]);
            pass.set_bind_group(3, &state.listing_group, &[]);
            dispatch_over(&mut pass, page.records.div_ceil(GROUP_CLUSTERS as u32));
        }
        drop(pass);
        let mut pass = self.compute_pass(encoder, None);
        pass.set_pipeline(&self.size_dispatch);
        for page in pages {
            let state = self.state(page);
            pass.set_bind_group(1, &state.geometry, &[]);
            pass.set_bind_group(3, &state.listing_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        drop(pass);
        let mut pass = self.compute_pass(encoder, last);
        pass.set_bind_group(0, frame, &[]);
        pass.set_bind_group(2, &pyramid, &[]);
        pass.set_pipeline(pieces);
        for page in pages {
            let state = self.state(page);
            pass.set_bind_group(1, &state.geometry, &[]);
            pass.set_bind_group(3, &state.compute_group, &[]);
            pass.dispatch_workgroups_indirect(&state.listing, 0);
        }
    }

    /// The pieces each page drew in the last frame recorded, early and late, read back (waits
    /// for the device): what `--timings` and the bench report.
    pub fn drawn(&self, queue: &wgpu::Queue, geometry: &LineGeometry) -> Result<(u64, u64), crate::Error> {
        let mut drawn = (0, 0);
        for page in geometry.pages() {
            let Some(state) = page.cull.get() else { continue };
            let bytes = pollster::block_on(crate::readback::read_buffer_async(&self.device, queue, &state.state))?;
            let words: &[u32] = bytemuck::cast_slice(&bytes);
            drawn.0 += words[9] as u64;
            drawn.1 += words[10] as u64;
        }
        Ok(drawn)
    }

    /// The clusters with a piece marked visible after the last frame recorded, read back (waits
    /// for the device).
    pub fn visible_clusters(&self, queue: &wgpu::Queue, geometry: &LineGeometry) -> Result<u64, crate::Error> {
        let mut visible = 0;
        for page in geometry.pages() {
            let Some(state) = page.cull.get() else { continue };
            let bytes = pollster::block_on(crate::readback::read_buffer_async(&self.device, queue, &state.state))?;
            let marks =
                &bytemuck::cast_slice::<u8, u32>(&bytes)[STATE_HEADER_WORDS as usize..][..page.records as usize];
            visible += marks.iter().filter(|&&bits| bits != 0).count() as u64;
        }
        Ok(visible)
    }

    /// Each page's marks after the last frame recorded, a word per cluster (bit p: piece p
    /// passed), read back (waits for the device): what the CPU reference checks.
    pub fn marks(&self, queue: &wgpu::Queue, geometry: &LineGeometry) -> Result<Vec<Vec<u32>>, crate::Error> {
        geometry
            .pages()
            .iter()
            .map(|page| {
                let Some(state) = page.cull.get() else { return Ok(vec![0; page.records as usize]) };
                let bytes = pollster::block_on(crate::readback::read_buffer_async(&self.device, queue, &state.state))?;
                Ok(bytemuck::cast_slice::<u8, u32>(&bytes)[STATE_HEADER_WORDS as usize..][..page.records as usize]
                    .to_vec())
            })
            .collect()
    }

    /// Pieces `geometry` has (what drawing everything would draw).
    pub fn pieces(geometry: &LineGeometry) -> u64 {
        geometry.pages().iter().map(|p| p.pieces).sum()
    }
}
