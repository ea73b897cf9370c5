//! The view as the screen-space passes and their CPU references both use it: from a pixel and
//! its normalized depth to view space and back ([`ViewParams`], plain Rust), and the same
//! numbers as the uniform `ViewParams` of `shaders/shared/view.wgsl` ([`ViewUniform`]). Shared
//! here so that neither the passes import the reference nor the reference the passes.

use crate::camera::FrameView;

/// What a screen-space pass needs to go from a pixel and its normalized depth to view space
/// and back: the linear depth range of the ND map and the projection in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewParams {
    /// −z_view at normalized depth 0 and 1 (world units).
    pub near: f32,
    /// −z_view at normalized depth 1.
    pub far: f32,
    /// Focal length in pixels (perspective) or pixels per world unit (orthographic).
    pub f_px: f32,
    /// Whether the projection is orthographic.
    pub orthographic: bool,
    /// The optical axis in pixel coordinates of the guard-banded image: (W, H) / 2, or a
    /// tile's share of its picture's ([`FrameView::center`]).
    pub center: [f32; 2],
}

impl ViewParams {
    /// The parameters of `view`.
    pub fn of(view: &FrameView) -> ViewParams {
        ViewParams {
            near: view.near,
            far: view.far,
            f_px: view.f_px,
            orthographic: view.orthographic,
            center: view.center(),
        }
    }

    /// −z_view of a normalized depth.
    pub fn linear_depth(&self, d: f32) -> f32 {
        self.near + d * (self.far - self.near)
    }

    /// The view-space point seen at pixel (x, y) at linear depth `depth`.
    pub fn view_position(&self, x: u32, y: u32, depth: f32) -> [f32; 3] {
        let sx = (x as f32 + 0.5 - self.center[0]) / self.f_px;
        let sy = (self.center[1] - (y as f32 + 0.5)) / self.f_px;
        if self.orthographic { [sx, sy, -depth] } else { [sx * depth, sy * depth, -depth] }
    }

    /// The pixel coordinates (not yet floored) a view-space point projects to.
    pub fn project(&self, q: [f32; 3]) -> [f32; 2] {
        let depth = -q[2];
        if self.orthographic {
            [self.center[0] + self.f_px * q[0], self.center[1] - self.f_px * q[1]]
        } else {
            [self.center[0] + self.f_px * q[0] / depth, self.center[1] - self.f_px * q[1] / depth]
        }
    }
}

/// `ViewParams` in `shaders/shared/view.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ViewUniform {
    pub near: f32,
    pub far: f32,
    pub f_px: f32,
    pub orthographic: u32,
    pub center: [f32; 2],
    pub _pad: [f32; 2],
}

impl From<ViewParams> for ViewUniform {
    fn from(v: ViewParams) -> Self {
        ViewUniform {
            near: v.near,
            far: v.far,
            f_px: v.f_px,
            orthographic: v.orthographic as u32,
            center: v.center,
            _pad: [0.0; 2],
        }
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        ViewUniform,
        "shared/view.wgsl",
        "ViewParams",
        [near, far, f_px, orthographic, center]
    );
}
