//! The CPU reference of the line cull ([`crate::passes::cull`], `shaders/cull.wgsl`), line by
//! line: the max-depth pyramid, the groups' boxes, the pieces' segments.
//!
//! After a frame the GPU's marks are exactly the pieces that pass against the pyramid of the
//! frame's *final* depth: the late test marks what passes against the early depth, which is
//! never nearer than the final one, so everything passing at the end passed then too, and the
//! settling unmarks the rest. The reference recomputes that set from the depth read back. The
//! GPU rounds its projections and the rasterizer's interpolation its own way, so each test is
//! made twice — with the rectangle `slack` pixels narrower and the depth margin smaller, and
//! with both larger — and a piece is *visible* where even the narrow test passes, *hidden*
//! where even the wide one fails, else *unsure*: the GPU must agree on every sure one.
//!
//! The level of detail each visible piece is drawn at next ([`levels`], `piece_level` in
//! `cull.wgsl`): the coarsest stride (2^level points, level < 4) at which every dropped point
//! lies within [`LOD_PIXELS`](crate::passes::cull::LOD_PIXELS) of the segment between the kept
//! points around it, its distance measured at the scale of the piece's nearest point, plus the
//! turn of the sideways push at it; a piece with a point behind the eye is drawn whole.

use glam::{Mat4, Vec3, Vec4Swizzles};

use super::Image;
pub use crate::line_geometry::PageContents;
use crate::line_geometry::{GROUP_CLUSTERS, PIECE_SEGMENTS};

/// The frame the cull tested against.
pub struct CullView {
    /// World to view space.
    pub view: Mat4,
    /// The guard-banded projection.
    pub proj: Mat4,
    /// The targets' guard-banded size.
    pub size: (u32, u32),
    /// The lines' width in pixels.
    pub line_width_px: f32,
    /// Tubes of this radius (world units; the pages' largest or the frame's, as the GPU bounds
    /// them) instead of lines, for the levels of detail.
    pub tube_radius: Option<f32>,
}

/// What a test says once the GPU's rounding is allowed for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Certainly seen.
    Visible,
    /// Certainly hidden.
    Hidden,
    /// Within the GPU's rounding of the bound: either is right.
    Unsure,
}

/// How far the GPU may round: pixels of a rectangle's edges, and depth.
#[derive(Clone, Copy, Debug)]
pub struct Slack {
    /// In pixels.
    pub px: f32,
    /// In depth.
    pub depth: f32,
}

/// `DEPTH_MARGIN` of `shaders/cull.wgsl`.
const DEPTH_MARGIN: f32 = 2e-6;

/// The max-depth pyramid of `depth`, level 0 first, down to 1 × 1 (`depth_pyramid.wgsl`).
pub fn depth_pyramid(depth: &Image<f32>) -> Vec<Image<f32>> {
    let mut levels = vec![depth.clone()];
    while levels.last().is_some_and(|l| l.width > 1 || l.height > 1) {
        let below = levels.last().expect("a level");
        let (w, h) = (below.width.div_ceil(2), below.height.div_ceil(2));
        let at = |x: usize, y: usize| below.data[y.min(below.height - 1) * below.width + x.min(below.width - 1)];
        let data = (0..w * h)
            .map(|i| {
                let (x, y) = (2 * (i % w), 2 * (i / w));
                at(x, y).max(at(x + 1, y)).max(at(x, y + 1)).max(at(x + 1, y + 1))
            })
            .collect();
        levels.push(Image { width: w, height: h, data });
    }
    levels
}

/// Every piece's verdict (per page, per cluster, pieces 0–2; a piece a cluster lacks, and
/// every piece of a cluster selected out, is hidden) for a frame of `view` whose final depth is `depth`.
pub fn marks(pages: &[PageContents], view: &CullView, depth: &Image<f32>, slack: Slack) -> Vec<Vec<[Verdict; 3]>> {
    let pyramid = depth_pyramid(depth);
    let test = Tester { view, pyramid: &pyramid };
    let both = |visible: &dyn Fn(f32, f32) -> bool| {
        let (narrow, wide) = (visible(-slack.px, -slack.depth), visible(slack.px, slack.depth));
        match (narrow, wide) {
            (true, true) => Verdict::Visible,
            (false, false) => Verdict::Hidden,
            _ => Verdict::Unsure,
        }
    };
    pages
        .iter()
        .map(|page| {
            let groups: Vec<Verdict> =
                page.groups.iter().map(|&(lo, hi)| both(&|px, d| test.world_box(lo, hi, px, d))).collect();
            page.records
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    std::array::from_fn(|p| {
                        let drawn = c.drawn() as usize;
                        let first = p * PIECE_SEGMENTS as usize;
                        // A cluster selected out is never visible.
                        if first + 1 >= drawn || !c.is_selected() {
                            return Verdict::Hidden;
                        }
                        let last = (first + PIECE_SEGMENTS as usize).min(drawn - 1);
                        let points: Vec<Vec3> =
                            (first..=last).map(|k| Vec3::from_array(page.points[c.first as usize + k])).collect();
                        let piece = both(&|px, d| test.piece(&points, px, d));
                        match (groups[i / GROUP_CLUSTERS], piece) {
                            (Verdict::Hidden, _) | (_, Verdict::Hidden) => Verdict::Hidden,
                            (Verdict::Visible, Verdict::Visible) => Verdict::Visible,
                            _ => Verdict::Unsure,
                        }
                    })
                })
                .collect()
        })
        .collect()
}

/// `LEVELS` of `cull.wgsl`: strides 1, 2, 4 and 8.
const LEVELS: u32 = 4;

/// Every piece's level of detail (per page, per cluster, pieces 0–2): the one the GPU picks for
/// a visible piece of a frame of `view`, or `None` where a level's test lies within `slack`
/// pixels of [`LOD_PIXELS`](crate::passes::cull::LOD_PIXELS) (the GPU's f32 may go either way)
/// or the piece does not exist.
pub fn levels(pages: &[PageContents], view: &CullView, slack: f32) -> Vec<Vec<[Option<u32>; 3]>> {
    let viewport = glam::Vec2::new(view.size.0 as f32, view.size.1 as f32);
    let scale = 0.5 * (view.proj.x_axis.x * viewport.x).max(view.proj.y_axis.y * viewport.y);
    let half_width = 0.5 * view.line_width_px;
    let level = |points: &[Vec3]| -> Option<u32> {
        let mut nearest = f32::INFINITY;
        let mut p = Vec::with_capacity(points.len());
        for &point in points {
            let view_pos = view.view.transform_point3(point);
            let w = (view.proj * view_pos.extend(1.0)).w;
            if w <= 0.0 {
                return Some(0);
            }
            nearest = nearest.min(w);
            p.push(view_pos);
        }
        let px = scale / nearest;
        // How far the sideways push (lines) or the rim (tubes) turns with the direction.
        let reach = view.tube_radius.map_or(half_width, |r| r * px);
        let n = p.len();
        for level in (1..LEVELS).rev() {
            let stride = 1 << level;
            // The test's largest value over the dropped points: within `slack` of the bound,
            // the GPU may decide either way.
            let worst = (1..n.saturating_sub(1))
                .filter(|k| k % stride != 0)
                .map(|k| {
                    let (a, b) = (p[k - k % stride], p[(k - k % stride + stride).min(n - 1)]);
                    let ab = b - a;
                    let t = ((p[k] - a).dot(ab) / ab.dot(ab).max(1e-30)).clamp(0.0, 1.0);
                    let off_line = (p[k] - (a + t * ab)).length() * px;
                    let turn = ((p[k + 1] - p[k - 1]).normalize() - ab.normalize()).length() * reach;
                    off_line + turn
                })
                .fold(0.0f32, f32::max);
            if (worst - crate::passes::cull::LOD_PIXELS).abs() <= slack {
                return None;
            }
            if worst <= crate::passes::cull::LOD_PIXELS {
                return Some(level);
            }
        }
        Some(0)
    };
    pages
        .iter()
        .map(|page| {
            page.records
                .iter()
                .map(|c| {
                    std::array::from_fn(|p| {
                        let (drawn, first) = (c.drawn() as usize, p * PIECE_SEGMENTS as usize);
                        if first + 1 >= drawn {
                            return None;
                        }
                        let last = (first + PIECE_SEGMENTS as usize).min(drawn - 1);
                        let points: Vec<Vec3> =
                            (first..=last).map(|k| Vec3::from_array(page.points[c.first as usize + k])).collect();
                        level(&points)
                    })
                })
                .collect()
        })
        .collect()
}

struct Tester<'a> {
    view: &'a CullView,
    pyramid: &'a [Image<f32>],
}

/// Texels across at most where a group's box and a segment's read the pyramid (`GROUP_SPAN`,
/// `SEGMENT_SPAN` in `cull.wgsl`).
const GROUP_SPAN: usize = 16;
const SEGMENT_SPAN: usize = 8;

impl Tester<'_> {
    /// `p` in NDC, none behind the eye.
    fn project(&self, p: Vec3) -> Option<Vec3> {
        let clip = self.view.proj * (self.view.view * p.extend(1.0));
        (clip.w > 0.0).then(|| clip.xyz() / clip.w)
    }

    /// `box_in_view_visible`.
    fn world_box(&self, lo: Vec3, hi: Vec3, px: f32, depth: f32) -> bool {
        let (mut a, mut b) = (Vec3::splat(3.0e38), Vec3::splat(-3.0e38));
        for k in 0..8 {
            let corner = Vec3::select(glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), hi, lo);
            let Some(ndc) = self.project(corner) else { return true };
            (a, b) = (a.min(ndc), b.max(ndc));
        }
        self.ndc_box(a, b, px, depth, GROUP_SPAN)
    }

    /// `visible_segments` of `piece_visible`: whether one of the segments between `points` may.
    fn piece(&self, points: &[Vec3], px: f32, depth: f32) -> bool {
        let mut previous = None;
        for &p in points {
            let Some(ndc) = self.project(p) else { return true };
            if previous.is_some_and(|q: Vec3| self.ndc_box(q.min(ndc), q.max(ndc), px, depth, SEGMENT_SPAN)) {
                return true;
            }
            previous = Some(ndc);
        }
        false
    }

    /// `box_visible`, its rectangle `px` wider on each side and its margin `depth` larger, read
    /// at the finest level where it spans at most `span` texels across.
    fn ndc_box(&self, lo: Vec3, hi: Vec3, px: f32, depth: f32, span: usize) -> bool {
        if hi.z < 0.0 || lo.z > 1.0 {
            return false;
        }
        let (w, h) = (self.view.size.0 as f32, self.view.size.1 as f32);
        let reach = 0.5 * self.view.line_width_px + 1.0 + px;
        let (x0, y0) = ((lo.x * 0.5 + 0.5) * w - reach, (0.5 - hi.y * 0.5) * h - reach);
        let (x1, y1) = ((hi.x * 0.5 + 0.5) * w + reach, (0.5 - lo.y * 0.5) * h + reach);
        if x1 < 0.0 || y1 < 0.0 || x0 >= w || y0 >= h {
            return false;
        }
        let texel = |v: f32, most: f32| v.floor().clamp(0.0, most - 1.0) as usize;
        let (ax, ay, bx, by) = (texel(x0, w), texel(y0, h), texel(x1, w), texel(y1, h));
        let mut l = 0;
        while l + 1 < self.pyramid.len() && ((bx >> l) - (ax >> l) >= span || (by >> l) - (ay >> l) >= span) {
            l += 1;
        }
        let level = &self.pyramid[l];
        let farthest = ((ay >> l)..=(by >> l))
            .flat_map(|y| ((ax >> l)..=(bx >> l)).map(move |x| level.data[y * level.width + x]))
            .fold(0.0f32, f32::max);
        lo.z <= farthest + DEPTH_MARGIN + depth
    }
}
