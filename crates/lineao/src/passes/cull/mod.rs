//! **Culling the lines (and tubes) on the GPU**, exactly: only the pieces of streamline that can leave a
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
//! 4. **settle**: the pyramid of the frame's final depth, and the pieces drawn (the only ones
//!    marked visible) are tested again against it, so that the next frame's early list holds
//!    only what this frame shows (after a first frame or a cut, the late phase marks everything
//!    that passed against the early depth: without this the second frame would draw nearly all
//!    again).
//!
//! **The tests** (`shaders/cull.wgsl`) run coarse to fine. A page's clusters lie along a
//! Morton curve within their draw class, so 16 consecutive ones (a *group*) are a small region
//! of space: `test_groups` tests each group's box (8 projected corners, the pyramid read where
//! the box spans at most 16 × 16 texels: a large box read coarsely nearly always passes) and
//! lists those that may be visible, clearing the marks of the others; then a workgroup per
//! listed group runs an invocation per piece, which tests the piece's *capsule* — the segment
//! between its ends grown by the farthest its points lie from it (a radius found once, when the
//! page is first culled, and kept in 16 bits) — as a segment's box is tested below, from two
//! points decoded instead of nine, and lists the pieces whose capsule passes (a capsule hidden
//! hides every segment in it: its rectangle holds theirs, read at their level of the pyramid
//! or a coarser one, so the marks are the segment test's). A second pass, an invocation per
//! listed piece, so that neighbouring invocations do the same work, tests those *segment by
//! segment*. On lavapipe at 10 M points 26 % of the pieces reach it, and the cull takes 15 %
//! less time than testing every piece of the listed groups segment by segment; on a GPU, which
//! has arithmetic to spare, the second pass and its list cost more than they save (an H200 at
//! 1 G points: 18.5 ms against 13.0), so there every piece of a listed group is tested segment
//! by segment at once (`late_direct`; [`LineCull::set_capsules`]). A segment's two triangles
//! have their corners half a line width from its two points on screen, at those points' depths
//! (the vertex shader pushes points sideways on screen only), so its fragments lie within half a
//! line width (and a pixel, for rounding) of the two points' box on screen and no nearer than
//! the nearer point. It is hidden when that box lies outside the target, or when its nearest
//! depth lies behind the farthest depth the pyramid holds over the box (at the level where the
//! box spans at most 8 × 8 texels: mostly the pixels themselves): then every pixel it could
//! cover already holds a nearer fragment, and the depth test would discard all of its own. A
//! piece is visible where one of its segments is. Segments span a few pixels, so the boxes are
//! tight and the pyramid is read at fine levels: on a whole brain of 10 M points seen from
//! outside, boxes of whole 24-point clusters passed 35 % of the clusters, segments 5 % of the
//! pieces (8 % read at 2 × 2 texels; at 50 M points 1.7 % for 3.7 %).
//!
//! Every piece not drawn early passes this test against a depth buffer holding a subset of
//! what drawing everything leaves, so what it culls is hidden in the full picture too: the
//! G-buffer is the one drawing every piece leaves, but where two fragments tie exactly in depth
//! and the order decides. A page's first frame knows nothing visible: its early phase draws
//! every piece of every [`SEED_STRIDE`]-th cluster (spread over the page by the Morton order),
//! and the late phase culls the rest against the depth they leave — fragments drawn, so the
//! test stays exact — instead of drawing all that passes an empty pyramid (`lineao render
//! --cull on`, 49.6 M points on lavapipe: 36.0 s wall before, 17.9 s with the seed, the same
//! picture; `--cull off` 25.2 s). A camera cut draws first what the view before found visible.
//!
//! **Level of detail** (where asked: [`LineCull::new`]'s `lod`, the chain's default):
//! the settling also picks for each piece drawn and still visible the coarsest level — every
//! 2nd, 4th or 8th point kept, and its last — at which each dropped point lies within
//! [`LOD_PIXELS`] of the segment between the kept points around it, on screen at the piece's
//! nearest point, and the sideways push at it turns by no more (half a line width times how far
//! its tangent turns from the segment's direction). Kept points keep their own tangents, so the
//! strip's corners there and the joins between pieces are the full strip's. The level is kept
//! with the piece's mark, and the next frame's early phase draws the piece at it (a piece seen
//! first is drawn whole by the late phase; the settling tests a compact list, where the late
//! test's invocations beside a visible piece would wait for it) — where the view is close to the
//! one the levels were found for ([`LevelsView::holds`]: the same projection, the eye moved by
//! under 5 % of the near distance, turned by under 0.05 rad); after a cut it draws every piece
//! whole. Coarse pieces are listed from the back of their phase's list and drawn with 12
//! vertices a piece instead of 20. Without it the G-buffer is the full strip's exactly.
//!
//! **Tubes** ([`Shape::Tubes`], `crate::passes::tubes`) are culled the same way, piece by
//! piece: a segment's fragments lie within its billboard (`shaders/shared/billboard.wgsl`: the
//! end spheres' disks on screen hulled by a rectangle, at the depth of the solid's front, which
//! the written depth is never nearer than), bounded for the largest radius the page's points
//! hold (its uniform) or the frame's; a group's box grows by that radius. At a level of detail
//! a tube's solid (its axis grown by the radius) lies within the dropped points' distance of
//! the full one, and its rim turns by the radius times the tangents' turn: the radius (that
//! bound) on screen takes the half line width's place. A segment between kept points leaves its
//! start sphere to the one before, as at full detail (the two share that point); a coarse piece
//! is drawn with 24 vertices a piece instead of 48.
//!
//! Each page keeps its state ([`PageCull`]), one for lines and tubes, at levels of detail or not,
//! each: a word a cluster (its visible pieces), the list of pieces to draw (a word each),
//! the listed groups and the indirect draws and dispatch, about 1.3 bytes a point, made on the
//! page's first culled frame; and where the capsules are tested, the pieces listed for the
//! segment test and the pieces' radii, 0.9 bytes a point more, made when they first are.

use std::sync::Arc;

use crate::binding::{self, Slot};
use crate::line_geometry::{GROUP_CLUSTERS, LineGeometry, Page};
use crate::passes::Load;
use crate::passes::depth_pyramid::{Built, DepthPyramid};
use crate::targets::FrameTargets;
use crate::timing::Span;

pub(crate) mod page;
use page::PageCapsules;
pub use page::{LevelsView, PageCull};

/// Workgroups per row of a dispatch, as `ROW` in `shaders/cull.wgsl`.
const ROW: u32 = 32768;
/// Invocations of a workgroup of `early` (one a cluster) and `test_groups` (one a group).
const WORKGROUP_INVOCATIONS: u32 = 64;
/// Pieces a cluster has at most (24 segments of 8).
pub const PIECES_PER_CLUSTER: u64 = 3;
/// Words of a page's state before its marks: the four indirect draws (early and late, full and
/// coarse pieces), the count of listed groups and of each draw's pieces (`state` in
/// `shaders/cull.wgsl`).
const STATE_HEADER_WORDS: u64 = 32;
/// Where the count of listed groups lies in the state, and the counts of the draws' pieces.
const LISTED_GROUPS: usize = 16;
const LISTED_PIECES: usize = 17;
/// Where the count of the pieces listed for the late test by their bounding sphere lies.
const LISTED_CANDIDATES: usize = 21;
/// How far from its full strip a piece drawn at a coarser level may lie on screen, in pixels
/// (`LOD_PIXELS` in `shaders/cull.wgsl`).
pub const LOD_PIXELS: f32 = 0.5;
/// A page's first culled frame, which knows nothing visible, draws every piece of every
/// `SEED_STRIDE`-th cluster first (spread over the page: its clusters lie along a Morton curve),
/// so that the late test culls against the depth they leave instead of an empty one — a depth
/// of fragments drawn, so what it hides is hidden in the full picture too.
pub const SEED_STRIDE: u32 = 8;
/// Bits of a cluster's mark that say which pieces are visible (bits 3–8: their levels).
pub const MARK_VISIBLE: u32 = 0b111;
/// Bits of a cluster's mark that say which pieces the test that hid them found outside the
/// view (their group's box, or each of their segments), not behind the pyramid (`OUTSIDE_SHIFT`
/// in `shaders/cull.wgsl`).
pub const MARK_OUTSIDE: u32 = 0b111 << 9;
/// Bytes of the listed groups' indirect dispatch and their count (`listing`).
const LISTING_BYTES: u64 = 16;

/// Dispatches 64 invocations per workgroup over `count` items (rows of [`ROW`] workgroups).
fn dispatch_over(pass: &mut wgpu::ComputePass, count: u32) {
    let groups = count.div_ceil(WORKGROUP_INVOCATIONS);
    pass.dispatch_workgroups(groups.min(ROW), groups.div_ceil(ROW), 1);
}

/// What the culled pieces are drawn as: what bounds a segment's fragments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Lines of the frame's width in pixels (`lines.wgsl`'s `vs_piece`).
    Lines,
    /// Ray-cast tubes (`tubes.wgsl`'s `vs_tube_piece`), bounded for the largest radius of a
    /// page's points.
    Tubes,
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

    /// Where the indirect arguments of its draw of full (or `coarse`) pieces lie in a page's
    /// state.
    pub fn offset(self, coarse: bool) -> u64 {
        16 * (self as u64 + 2 * coarse as u64)
    }
}

/// What a frozen cull draws ([`LineCull::set_frozen`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Frozen {
    /// Nothing: it is not frozen, every frame culls.
    #[default]
    No,
    /// The pieces it found visible in the last frame culled ([`crate::DebugView::Frozen`]).
    Visible,
    /// Every piece of the selected streamlines, those it left out with why: outside the view or
    /// behind what it drew ([`crate::DebugView::Culled`], in the pieces' colors).
    All,
}

impl PageCull {
    /// The pieces `phase` draws, as the vertex shader reads them.
    pub(crate) fn draw_group(&self, phase: Phase) -> &wgpu::BindGroup {
        &self.draw_groups[phase as usize]
    }
}

/// The layout of what the tests read of a page: points, records, its uniform and the group
/// boxes, at their bindings in `shaders/shared/clusters.wgsl`.
fn geometry_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let storage = wgpu::BufferBindingType::Storage { read_only: true };
    let entries = [(0, storage), (1, storage), (2, storage), (6, wgpu::BufferBindingType::Uniform), (7, storage)];
    binding::buffers_layout(device, "lineao::LineCull::geometry", wgpu::ShaderStages::COMPUTE, &entries)
}

/// The layout of the visible pieces as the vertex shader reads them (group 2 of the culled
/// line pipelines).
pub(crate) fn pieces_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let visibility = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE;
    binding::layout(device, "lineao::LineCull::pieces", visibility, &[Slot::Storage])
}

/// The two-phase cull of [`LineGeometry`]'s pieces (see the module documentation).
pub struct LineCull {
    device: wgpu::Device,
    shape: Shape,
    pyramid: DepthPyramid,
    /// Whether it picks a level of detail for each piece.
    lod: bool,
    early: wgpu::ComputePipeline,
    /// `early` drawing every piece whole, after a cut (where it picks levels).
    early_whole: wgpu::ComputePipeline,
    /// `early_whole` that also lists every piece of every [`SEED_STRIDE`]-th cluster: a page's
    /// first culled frame.
    early_seeded: wgpu::ComputePipeline,
    /// The view of the frame being recorded ([`LineCull::set_view`]).
    view: std::sync::Mutex<Option<LevelsView>>,
    /// Whether its frames draw what it last found (and left out) and find nothing new
    /// ([`LineCull::set_frozen`]).
    frozen: std::sync::Mutex<Frozen>,
    /// Lists every piece, why it was left out ([`Frozen::All`]).
    list_all: wgpu::ComputePipeline,
    pad: wgpu::ComputePipeline,
    test_groups: wgpu::ComputePipeline,
    size_dispatch: wgpu::ComputePipeline,
    late_bounds: wgpu::ComputePipeline,
    size_late: wgpu::ComputePipeline,
    late: wgpu::ComputePipeline,
    late_direct: wgpu::ComputePipeline,
    /// Whether the late test tries each piece's capsule before its segments
    /// ([`LineCull::set_capsules`]).
    capsules: std::sync::atomic::AtomicBool,
    piece_radii: wgpu::ComputePipeline,
    size_settle: wgpu::ComputePipeline,
    settle: wgpu::ComputePipeline,
    /// A page's points, records and group boxes (`clusters.wgsl`'s bindings 0, 1, 2, 7).
    geometry_layout: wgpu::BindGroupLayout,
    pyramid_layout: wgpu::BindGroupLayout,
    state_layout: wgpu::BindGroupLayout,
    listing_layout: wgpu::BindGroupLayout,
    /// The state, the pieces and their bounds (`bounds` in `shaders/cull.wgsl`, binding 3).
    bounds_layout: wgpu::BindGroupLayout,
    /// The pyramid's bind group, made once for each pyramid (the targets' size).
    pyramid_group: std::sync::Mutex<Option<(Arc<Built>, wgpu::BindGroup)>>,
    pieces_layout: wgpu::BindGroupLayout,
}

impl LineCull {
    /// The cull of geometry drawn as `shape` with `frame` (the renderer's group 0: its frame
    /// uniform and lighting), picking a level of detail for each piece where `lod`.
    pub fn new(device: &wgpu::Device, frame: &wgpu::BindGroupLayout, shape: Shape, lod: bool) -> LineCull {
        let label = "lineao::LineCull";
        let compute = wgpu::ShaderStages::COMPUTE;
        let pyramid_layout = binding::layout(device, label, compute, &[Slot::Uniform, Slot::Storage]);
        // The state and the pieces, and with the listed groups' dispatch (for the passes that
        // write it). With the page's four arrays and the pyramid, eight storage buffers: the
        // WebGPU default a stage may bind.
        let state = [Slot::StorageReadWrite; 3];
        let state_layout = binding::layout(device, label, compute, &state[..2]);
        let listing_layout = binding::layout(device, label, compute, &state);
        let read_write = wgpu::BufferBindingType::Storage { read_only: false };
        let bounds = [(0, read_write), (1, read_write), (3, read_write)];
        let bounds_layout = binding::buffers_layout(device, label, compute, &bounds);
        let page = geometry_layout(device);
        let module = crate::shader::module(device, "cull.wgsl");
        let constants = |lod: bool, seed: u32| {
            [("TUBES", (shape == Shape::Tubes) as u32 as f64), ("LOD", lod as u32 as f64), ("SEED", seed as f64)]
        };
        let pipeline_with = |entry: &str, groups: &[Option<&wgpu::BindGroupLayout>], lod: bool, seed: u32| {
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
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants(lod, seed),
                    ..Default::default()
                },
                cache: None,
            })
        };
        let pipeline_of =
            |entry: &str, groups: &[Option<&wgpu::BindGroupLayout>], lod: bool| pipeline_with(entry, groups, lod, 0);
        let pipeline_seeded =
            |entry: &str, groups: &[Option<&wgpu::BindGroupLayout>]| pipeline_with(entry, groups, false, SEED_STRIDE);
        let pipeline = |entry: &str, groups: &[Option<&wgpu::BindGroupLayout>]| pipeline_of(entry, groups, lod);
        let all = [Some(frame), Some(&page), Some(&pyramid_layout), Some(&state_layout)];
        let listing = [Some(frame), Some(&page), Some(&pyramid_layout), Some(&listing_layout)];
        let with_bounds = [Some(frame), Some(&page), Some(&pyramid_layout), Some(&bounds_layout)];
        let marks = [None, Some(&page), None, Some(&state_layout)];
        LineCull {
            device: device.clone(),
            shape,
            pyramid: DepthPyramid::new(device),
            early: pipeline("early", &marks),
            early_whole: pipeline_of("early", &marks, false),
            early_seeded: pipeline_seeded("early", &marks),
            view: Default::default(),
            frozen: Default::default(),
            list_all: pipeline_of("list_all", &marks, false),
            pad: pipeline("pad", &[None, None, None, Some(&state_layout)]),
            lod,
            test_groups: pipeline("test_groups", &listing),
            size_dispatch: pipeline("size_dispatch", &[None, None, None, Some(&listing_layout)]),
            late_bounds: pipeline("late_bounds", &with_bounds),
            size_late: pipeline("size_late", &[None, None, None, Some(&listing_layout)]),
            late: pipeline("late", &with_bounds),
            late_direct: pipeline("late_direct", &all),
            capsules: (device.adapter_info().device_type == wgpu::DeviceType::Cpu).into(),
            piece_radii: pipeline("piece_radii", &[None, Some(&page), None, Some(&bounds_layout)]),
            size_settle: pipeline("size_settle", &[None, None, None, Some(&listing_layout)]),
            settle: pipeline("settle", &all),
            pieces_layout: pieces_layout(device),
            geometry_layout: page,
            pyramid_layout,
            state_layout,
            listing_layout,
            bounds_layout,
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
        page.cull[self.slot()].get_or_init(|| {
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
            // The early list, then the late one where a storage binding may start; each with
            // room for its full and its coarse pieces padded to whole instances.
            let align = u64::from(device.limits().min_storage_buffer_offset_alignment);
            let list = (4 * (PIECES_PER_CLUSTER * clusters + 16)).next_multiple_of(align);
            let pieces = buffer("lineao::LineCull::pieces", 2 * list, wgpu::BufferUsages::empty());
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
            let draw_groups = [0, list].map(|offset| {
                let list = wgpu::BufferBinding { buffer: &pieces, offset, size: wgpu::BufferSize::new(list) };
                let list = wgpu::BindingResource::Buffer(list);
                binding::group(device, "lineao::LineCull::pieces", &self.pieces_layout, &[list])
            });
            let buffers = [(0, &page.xy), (1, &page.z), (2, &page.clusters), (6, &page.uniform), (7, &page.groups)];
            let geometry =
                binding::buffers_group(device, "lineao::LineCull::geometry", &self.geometry_layout, &buffers);
            PageCull {
                state,
                draw_groups,
                compute_group,
                listing_group,
                geometry,
                pieces,
                listing,
                capsules: Default::default(),
                levels_of: Default::default(),
                culled_before: Default::default(),
            }
        })
    }

    /// `page`'s capsules (its `state`'s), made the first time.
    fn capsules_of<'p>(&self, page: &Page, state: &'p PageCull) -> &'p PageCapsules {
        state.capsules.get_or_init(|| {
            let device = &self.device;
            // Three words a piece listed for `late`, two a cluster for the radii.
            let bounds = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lineao::LineCull::bounds"),
                size: 4 * (PIECES_PER_CLUSTER + 2) * page.records as u64,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            });
            let buffers = [(0, &state.state), (1, &state.pieces), (3, &bounds)];
            let group = binding::buffers_group(device, "lineao::LineCull::bounds", &self.bounds_layout, &buffers);
            PageCapsules { bounds, group }
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
        let pages = geometry.pages();
        // Frozen, once every page has been culled: the pieces it last found visible (or every
        // piece, with why it left them out), nothing tested, nothing marked (the early phase
        // alone).
        let frozen = match *self.frozen.lock().unwrap_or_else(|poisoned| poisoned.into_inner()) {
            _ if pages.iter().any(|page| page.cull[self.slot()].get().is_none()) => Frozen::No,
            frozen => frozen,
        };
        let (first, last) = if frozen == Frozen::No { Span::split(span) } else { (span, None) };
        for page in pages {
            encoder.clear_buffer(&self.state(page).state, 0, Some(4 * STATE_HEADER_WORDS));
        }
        // A page's pieces' bounding radii, once (its points do not change), where the capsules
        // are tested: when its capsules are made.
        let capsules = self.capsules();
        let unbounded: Vec<&Page> =
            pages.iter().filter(|page| capsules && self.state(page).capsules.get().is_none()).collect();
        if !unbounded.is_empty() {
            self.over_pages(encoder, unbounded, None, &self.piece_radii, None, |pass, page, state| {
                pass.set_bind_group(3, &self.capsules_of(page, state).group, &[]);
                dispatch_over(pass, page.records);
            });
        }
        let view = *self.view.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let list = if frozen == Frozen::All { &self.list_all } else { &self.early };
        self.over_pages(encoder, pages, None, list, first, |pass, page, state| {
            if self.lod && frozen != Frozen::All {
                let mut levels_of = state.levels_of.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
                let hold = matches!((*levels_of, view), (Some(then), Some(now)) if then.holds(&now));
                pass.set_pipeline(if hold { &self.early } else { &self.early_whole });
                // This frame's settling finds them for this view.
                if frozen == Frozen::No {
                    *levels_of = view;
                }
            }
            if frozen == Frozen::No && !state.culled_before.swap(true, std::sync::atomic::Ordering::Relaxed) {
                pass.set_pipeline(&self.early_seeded);
            }
            pass.set_bind_group(3, &state.compute_group, &[]);
            dispatch_over(pass, page.records);
        });
        self.pad(encoder, pages);
        draw(encoder, Phase::Early, None);
        if frozen != Frozen::No {
            return;
        }
        let built = self.pyramid.encode(encoder, &targets.depth, None);
        let late = [(&self.size_dispatch, &self.late_bounds), (&self.size_late, &self.late)];
        let late = if capsules { &late[..] } else { &[(&self.size_dispatch, &self.late_direct)] };
        self.test(encoder, pages, frame, &built, late, capsules, None);
        self.pad(encoder, pages);
        draw(encoder, Phase::Late, None);
        let built = self.pyramid.encode(encoder, &targets.depth, None);
        self.test(encoder, pages, frame, &built, &[(&self.size_settle, &self.settle)], false, last);
    }

    /// Pads each page's lists to whole instances (`pad`).
    fn pad(&self, encoder: &mut wgpu::CommandEncoder, pages: &[Page]) {
        self.over_pages(encoder, pages, None, &self.pad, None, |pass, _, state| {
            pass.set_bind_group(3, &state.compute_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        });
    }

    /// Freezes the cull (or thaws it: [`Frozen::No`]): its frames draw the pieces it found
    /// visible in the last frame before (and with [`Frozen::All`] the others, in the colors of
    /// why it left them out), and test and mark nothing, so a camera moved away shows what it
    /// drew for that view ([`crate::DebugView::Frozen`], [`crate::DebugView::Culled`]). A
    /// geometry not culled yet is culled once first.
    pub fn set_frozen(&self, frozen: Frozen) {
        *self.frozen.lock().unwrap_or_else(|poisoned| poisoned.into_inner()) = frozen;
    }

    /// Whether the late test tries each piece's bounding capsule before its segments (two
    /// points decoded instead of nine, in a pass of its own that lists the pieces that pass),
    /// or tests every piece of a visible group segment by segment at once. The marks, and so
    /// the pictures, are the same. By default on a CPU adapter, where the arithmetic saved is
    /// the cost (lavapipe, 10 M points: the cull 15 % faster), and off on a GPU, where the
    /// extra pass is (an H200, 50 M points: the cull 0.90 ms without, 1.22 with).
    pub fn set_capsules(&self, on: bool) {
        self.capsules.store(on, std::sync::atomic::Ordering::Relaxed);
    }

    /// Whether the late test tries the pieces' capsules first ([`LineCull::set_capsules`]).
    pub fn capsules(&self) -> bool {
        self.capsules.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Whether it picks a level of detail for each piece.
    pub fn lod(&self) -> bool {
        self.lod
    }

    /// The view of the frames it records next (the renderer's `prepare`): where it is not close
    /// to the one a page's levels were found for, the early phase draws that page whole.
    pub fn set_view(&self, view: &crate::FrameView) {
        *self.view.lock().unwrap_or_else(|poisoned| poisoned.into_inner()) = Some(LevelsView::of(view));
    }

    /// Which of a page's culling states is its own: lines or tubes, each at levels of detail or not.
    fn slot(&self) -> usize {
        2 * (self.shape == Shape::Tubes) as usize + self.lod as usize
    }

    /// One compute pass of `pipeline` timed into `span`, with the frame and the pyramid bound
    /// (`bound`) where it reads them, and each page's geometry; `dispatch` binds the page's state
    /// and dispatches over it.
    fn over_pages<'p>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pages: impl IntoIterator<Item = &'p Page>,
        bound: Option<(&wgpu::BindGroup, &wgpu::BindGroup)>,
        pipeline: &wgpu::ComputePipeline,
        span: Option<Span>,
        dispatch: impl Fn(&mut wgpu::ComputePass, &Page, &PageCull),
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lineao::LineCull"),
            timestamp_writes: crate::timing::compute_writes(span),
        });
        if let Some((frame, pyramid)) = bound {
            pass.set_bind_group(0, frame, &[]);
            pass.set_bind_group(2, pyramid, &[]);
        }
        pass.set_pipeline(pipeline);
        for page in pages {
            let state = self.state(page);
            pass.set_bind_group(1, &state.geometry, &[]);
            dispatch(&mut pass, page, state);
        }
    }

    /// A test against the pyramid `built`: every page's groups (the pieces of hidden ones
    /// unmarked), then each of `stages`: `size` (`size_dispatch`, `size_late`, `size_settle`)
    /// writes each page's indirect dispatch of `pieces` — the capsules of the listed groups'
    /// pieces and the late test of those that pass (`late_bounds`, `late`: `bounds` says
    /// they read the pieces' bounds, the page's capsules), or the settling of the pieces drawn.
    #[allow(clippy::too_many_arguments)]
    fn test(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pages: &[Page],
        frame: &wgpu::BindGroup,
        built: &Arc<Built>,
        stages: &[(&wgpu::ComputePipeline, &wgpu::ComputePipeline)],
        bounds: bool,
        span: Option<Span>,
    ) {
        let pyramid = self.pyramid_group(built);
        let bound = Some((frame, &pyramid));
        let (first, mut last) = Span::split(span);
        for page in pages {
            encoder.clear_buffer(&self.state(page).listing, 0, None);
        }
        // Separate passes: on lavapipe, dispatches within one pass did not see each other's
        // writes.
        self.over_pages(encoder, pages, bound, &self.test_groups, first, |pass, page, state| {
            pass.set_bind_group(3, &state.listing_group, &[]);
            dispatch_over(pass, page.records.div_ceil(GROUP_CLUSTERS as u32));
        });
        for (k, &(size, pieces)) in stages.iter().enumerate() {
            self.over_pages(encoder, pages, None, size, None, |pass, _, state| {
                pass.set_bind_group(3, &state.listing_group, &[]);
                pass.dispatch_workgroups(1, 1, 1);
            });
            let span = if k + 1 == stages.len() { last.take() } else { None };
            self.over_pages(encoder, pages, bound, pieces, span, |pass, page, state| {
                let group = if bounds { &self.capsules_of(page, state).group } else { &state.compute_group };
                pass.set_bind_group(3, group, &[]);
                pass.dispatch_workgroups_indirect(&state.listing, 0);
            });
        }
    }

    /// Each page's state after the last frame recorded, read back (waits for the device): its
    /// header words and its marks (none for a page not culled yet).
    fn read_states(&self, queue: &wgpu::Queue, geometry: &LineGeometry) -> Result<Vec<Option<Vec<u32>>>, crate::Error> {
        let read = |page: &Page| -> Result<_, crate::Error> {
            let Some(state) = page.cull[self.slot()].get() else { return Ok(None) };
            let bytes = pollster::block_on(crate::readback::read_buffer_async(&self.device, queue, &state.state))?;
            let words: &[u32] = bytemuck::cast_slice(&bytes);
            Ok(Some(words[..(STATE_HEADER_WORDS + page.records as u64) as usize].to_vec()))
        };
        geometry.pages().iter().map(read).collect()
    }

    /// What the last frame recorded drew of `geometry`, read back (waits for the device): what
    /// `--timings` and the bench report.
    pub fn counts(&self, queue: &wgpu::Queue, geometry: &LineGeometry) -> Result<CullCounts, crate::Error> {
        let mut counts = CullCounts {
            early: 0,
            late: 0,
            coarse: 0,
            listed_groups: 0,
            segment_tested: self.capsules().then_some(0),
            groups: geometry.pages().iter().map(|p| p.records.div_ceil(GROUP_CLUSTERS as u32) as u64).sum(),
            pieces: LineCull::pieces(geometry),
            visible_clusters: 0,
            clusters: geometry.clusters() as u64,
        };
        for words in self.read_states(queue, geometry)?.into_iter().flatten() {
            let listed = |d: usize| words[LISTED_PIECES + d] as u64;
            counts.early += listed(0) + listed(2);
            counts.late += listed(1) + listed(3);
            counts.coarse += listed(2) + listed(3);
            counts.listed_groups += words[LISTED_GROUPS] as u64;
            if let Some(tested) = counts.segment_tested.as_mut() {
                *tested += words[LISTED_CANDIDATES] as u64;
            }
            let marks = &words[STATE_HEADER_WORDS as usize..];
            counts.visible_clusters += marks.iter().filter(|&&bits| bits & MARK_VISIBLE != 0).count() as u64;
        }
        Ok(counts)
    }

    /// Each page's marks after the last frame recorded, a word per cluster (bit p: piece p
    /// passed; bits 3 + 2p and 4 + 2p: the level it was drawn at; bit 9 + p: the test that hid
    /// it found it outside the view, [`MARK_OUTSIDE`]), read back (waits for the device): what
    /// the CPU reference checks.
    pub fn marks(&self, queue: &wgpu::Queue, geometry: &LineGeometry) -> Result<Vec<Vec<u32>>, crate::Error> {
        let states = self.read_states(queue, geometry)?;
        let marks = states.into_iter().zip(geometry.pages()).map(|(words, page)| match words {
            Some(words) => words[STATE_HEADER_WORDS as usize..].to_vec(),
            None => vec![0; page.records as usize],
        });
        Ok(marks.collect())
    }

    /// Pieces `geometry` has (what drawing everything would draw).
    pub fn pieces(geometry: &LineGeometry) -> u64 {
        geometry.pages().iter().map(|p| p.pieces).sum()
    }
}

/// A renderer's culled drawing: its [`LineCull`], the pipelines that draw the visible pieces
/// (group 0 the renderer's frame, 1 the page, 2 its visible pieces), and why it draws
/// everything after all, once a frame found out (a device whose storage bindings cannot hold
/// the depth pyramid).
pub struct Culled {
    cull: LineCull,
    /// The full pieces' pipeline, and the coarse ones' where it picks levels of detail.
    plain: Vec<wgpu::RenderPipeline>,
    octants: Option<Vec<wgpu::RenderPipeline>>,
    note: std::sync::OnceLock<String>,
}

impl Culled {
    /// The cull of `shape` for a renderer whose group 0 is `frame`, at levels of detail where
    /// `lod`; `create(fragment outputs with octants, coarse)` makes a pipeline drawing the
    /// visible full (or coarse) pieces, `octants` whether the renderer writes them.
    pub(crate) fn new(
        device: &wgpu::Device,
        frame: &wgpu::BindGroupLayout,
        shape: Shape,
        lod: bool,
        octants: bool,
        create: impl Fn(bool, bool) -> wgpu::RenderPipeline,
    ) -> Culled {
        let cull = LineCull::new(device, frame, shape, lod);
        let lists = if cull.lod { 2 } else { 1 };
        let pipelines = |octants: bool| (0..lists).map(|list| create(octants, list == 1)).collect();
        Culled { plain: pipelines(false), octants: octants.then(|| pipelines(true)), cull, note: Default::default() }
    }

    /// Why it draws everything though asked to cull, once a frame found it out.
    pub fn note(&self) -> Option<&str> {
        self.note.get().map(String::as_str)
    }

    /// Records a frame of `geometry` into `targets` as [`LineCull::encode`] does, its draws
    /// with the pipelines (`octants`: the targets' octants too), the first loading the targets
    /// as `load` says; `false`, recording nothing, when the device cannot cull into `targets`
    /// (the renderer then draws everything).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        frame: &wgpu::BindGroup,
        label: &str,
        load: Load,
        octants: bool,
        span: Option<Span>,
    ) -> bool {
        if let Some(reason) = self.cull.unsupported(targets) {
            // Said once; every frame then draws everything.
            self.note.get_or_init(|| reason);
        }
        if self.note.get().is_some() {
            return false;
        }
        let pipelines = if octants { self.octants.as_ref() } else { Some(&self.plain) };
        let pipelines = pipelines.expect("culled pipelines with octants where the renderer has them");
        let draw = |encoder: &mut wgpu::CommandEncoder, phase: Phase, span| {
            let mut pass = crate::gbuffer::begin(encoder, label, targets, phase.load(load), octants, span);
            pass.set_bind_group(0, frame, &[]);
            for (list, pipeline) in pipelines.iter().enumerate() {
                pass.set_pipeline(pipeline);
                for page in geometry.pages() {
                    let state = self.cull.state(page);
                    pass.set_bind_group(1, &page.group, &[]);
                    pass.set_bind_group(2, state.draw_group(phase), &[]);
                    pass.draw_indirect(&state.state, phase.offset(list == 1));
                }
            }
        };
        self.cull.encode(encoder, targets, geometry, frame, span, draw);
        true
    }

    /// The cull's compute alone, as [`Culled::encode`] records it but for the draws (the
    /// bench's `cull`).
    pub(crate) fn encode_compute(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        frame: &wgpu::BindGroup,
        span: Option<Span>,
    ) {
        self.cull.encode(encoder, targets, geometry, frame, span, |_, _, _| {});
    }

    /// The cull itself (what it drew, its marks).
    pub fn cull(&self) -> &LineCull {
        &self.cull
    }

    /// What the last frame recorded drew ([`LineCull::counts`]).
    pub fn counts(&self, queue: &wgpu::Queue, geometry: &LineGeometry) -> Result<CullCounts, crate::Error> {
        self.cull.counts(queue, geometry)
    }
}

/// What a culled frame drew: pieces of eight segments drawn early and late of all the
/// geometry has (and of those, at a coarser level of detail), and the clusters with a piece
/// found visible.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CullCounts {
    /// Pieces drawn in the early phase.
    pub early: u64,
    /// Pieces drawn in the late phase.
    pub late: u64,
    /// Of the drawn pieces, those drawn at a coarser level of detail.
    pub coarse: u64,
    /// Groups of 16 clusters whose pieces the late test tested, of all.
    pub listed_groups: u64,
    /// Pieces of the listed groups whose bounding capsule passed, tested segment by segment
    /// (`None` where the cull tests no capsules: [`LineCull::set_capsules`]).
    pub segment_tested: Option<u64>,
    /// Groups of 16 clusters in all.
    pub groups: u64,
    /// Pieces in all.
    pub pieces: u64,
    /// Clusters with a piece found visible.
    pub visible_clusters: u64,
    /// Clusters in all.
    pub clusters: u64,
}

impl CullCounts {
    /// The share of the pieces drawn.
    pub fn drawn_share(&self) -> f64 {
        (self.early + self.late) as f64 / self.pieces.max(1) as f64
    }

    /// The share of the clusters found visible.
    pub fn visible_share(&self) -> f64 {
        self.visible_clusters as f64 / self.clusters.max(1) as f64
    }
}

impl std::fmt::Display for CullCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "drew {} + {} of {} pieces of 8 segments ({:.2} %; {:.1} % of them coarser), {:.2} % of the {} clusters \
             visible; tested the pieces of {:.2} % of the groups",
            self.early,
            self.late,
            self.pieces,
            100.0 * self.drawn_share(),
            100.0 * self.coarse as f64 / (self.early + self.late).max(1) as f64,
            100.0 * self.visible_share(),
            self.clusters,
            100.0 * self.listed_groups as f64 / self.groups.max(1) as f64,
        )?;
        match self.segment_tested {
            Some(tested) => {
                let share = 100.0 * tested as f64 / self.pieces.max(1) as f64;
                write!(f, " by their capsules, {tested} segment by segment ({share:.2} % of all)")
            }
            None => write!(f, " segment by segment"),
        }
    }
}
