//! What the cull keeps of a page between frames ([`PageCull`], held by the page itself:
//! [`crate::line_geometry`]'s `Page::cull`), and the view its levels of detail were found for.
//! Apart from the pass ([`super`]) so that the geometry, which holds it, needs nothing else of
//! the cull.

/// The view a page's levels of detail were found for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelsView {
    pub(super) view: glam::Mat4,
    pub(super) proj: glam::Mat4,
    pub(super) near: f32,
    pub(super) orthographic: bool,
}

impl LevelsView {
    /// The levels of the depth pyramid for `view`.
    pub fn of(view: &crate::camera::FrameView) -> LevelsView {
        LevelsView { view: view.view, proj: view.proj, near: view.near, orthographic: view.orthographic }
    }

    /// Whether levels found for this view keep a frame of `now` within about their bound: the
    /// same projection, and (perspective) the eye moved by under 5 % of the near distance —
    /// what the nearest line's depth, and so its pixels per unit, changes by at most — and the
    /// view direction turned by under 0.05 rad.
    pub fn holds(&self, now: &LevelsView) -> bool {
        if self.proj != now.proj {
            return false;
        }
        if self.orthographic {
            // Orthographic: a unit spans the same pixels wherever it lies.
            return true;
        }
        let (before, after) = (self.view.inverse(), now.view.inverse());
        let moved = before.w_axis.truncate().distance(after.w_axis.truncate());
        let turned = before.z_axis.truncate().angle_between(after.z_axis.truncate());
        moved < 0.05 * self.near && turned < 0.05
    }
}

/// A page's capsules: the pieces `late_bounds` lists for `late` and each piece's bounding
/// radius (about 0.9 bytes a point), with the state and the pieces (`late_bounds`, `late`,
/// `piece_radii`).
pub(super) struct PageCapsules {
    pub(super) bounds: wgpu::Buffer,
    pub(super) group: wgpu::BindGroup,
}

/// A page's culling state (see the module documentation).
pub struct PageCull {
    /// The indirect draws (and, in the same buffer, the marks and the listed groups).
    pub(crate) state: wgpu::Buffer,
    /// The early and the late list of visible pieces, read by the vertex shader (group 2 of
    /// `lines.wgsl`, `tubes.wgsl`).
    pub(super) draw_groups: [wgpu::BindGroup; 2],
    pub(super) compute_group: wgpu::BindGroup,
    /// With the listed groups' dispatch (`test_groups`, `size_dispatch`).
    pub(super) listing_group: wgpu::BindGroup,
    /// The page's arrays the tests read.
    pub(super) geometry: wgpu::BindGroup,
    pub(crate) pieces: wgpu::Buffer,
    pub(super) listing: wgpu::Buffer,
    /// What the capsule test adds, made where it first runs ([`super::LineCull::set_capsules`]).
    pub(super) capsules: std::sync::OnceLock<PageCapsules>,
    /// The view its marks' levels of detail were found for.
    pub(super) levels_of: std::sync::Mutex<Option<LevelsView>>,
    /// Whether a frame culled it before (its first lists a seed: [`super::SEED_STRIDE`]).
    pub(super) culled_before: std::sync::atomic::AtomicBool,
}

impl PageCull {
    /// Bytes of its buffers.
    pub fn bytes(&self) -> u64 {
        let capsules = self.capsules.get().map_or(0, |c| c.bounds.size());
        self.state.size() + self.pieces.size() + self.listing.size() + capsules
    }
}
