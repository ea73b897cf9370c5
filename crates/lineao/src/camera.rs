//! Camera, scene bounds and the per-frame view that every pass shares (docs/reference.md
//! "Coordinates and buffers").
//!
//! View space: camera at the origin looking down −z, +y up. The depth range that normalizes the
//! ND map's linear depth comes from the bounding sphere (c, r) of all geometry:
//! near = max(−c_z − r, 1e-3 r), far = −c_z + r. The zoom z(P) is how many pixels `zoom_unit`
//! world units span at P's depth: f_px · zoom_unit / (−z_view) (perspective) or f_px · zoom_unit
//! (orthographic), with f_px = `proj[1][1]` · H / 2.
//!
//! The G-buffer is rendered `guard` pixels larger on every side (paper §3.4); the projection is
//! widened so that the visible W × H window shows exactly what the camera frames, and f_px is the
//! same for both.

use glam::camera::rh::proj::directx;
use glam::{Mat4, Vec3};

/// How the camera projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Vertical field of view in degrees, (0, 180).
    Perspective {
        /// The vertical field of view in degrees.
        fov_y_deg: f32,
    },
    /// Height of the visible window in world units.
    Orthographic {
        /// The visible height in world units.
        height: f32,
    },
}

/// A look-at camera in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the eye is, world units.
    pub eye: Vec3,
    /// The point the eye looks at.
    pub target: Vec3,
    /// Which way is up on screen.
    pub up: Vec3,
    /// Perspective or orthographic.
    pub projection: Projection,
}

impl Camera {
    /// World → view transform (right-handed, looking down −z).
    pub fn view_matrix(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }
}

/// The bounding sphere of all geometry in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The centre of the bounding sphere.
    pub center: Vec3,
    /// Its radius, world units.
    pub radius: f32,
}

impl Bounds {
    /// The corners (min, max) of the axis-aligned box around the finite `points`; `None` when
    /// there are none.
    pub fn corners_of<'a>(points: impl IntoIterator<Item = &'a [f32; 3]>) -> Option<(Vec3, Vec3)> {
        let (lo, hi) = points
            .into_iter()
            .map(|p| Vec3::from_array(*p))
            .filter(|p| p.is_finite())
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(p), hi.max(p)));
        lo.is_finite().then_some((lo, hi))
    }

    /// The sphere around the axis-aligned box of `points` that contains them all; `None` when
    /// there are no finite points. Two passes over the slice, no copy.
    pub fn of_points(points: &[[f32; 3]]) -> Option<Bounds> {
        let finite = || points.iter().map(|p| Vec3::from_array(*p)).filter(|p| p.is_finite());
        let (lo, hi) = Bounds::corners_of(points)?;
        let center = (lo + hi) * 0.5;
        let radius = finite().map(|p| p.distance(center)).fold(0.0f32, f32::max);
        Some(Bounds { center, radius: radius.max(1e-6) })
    }

    /// The smallest sphere holding both spheres (for lines with context surfaces).
    pub fn union(&self, other: &Bounds) -> Bounds {
        let d = self.center.distance(other.center);
        if d + other.radius <= self.radius {
            return *self;
        }
        if d + self.radius <= other.radius {
            return *other;
        }
        let radius = 0.5 * (d + self.radius + other.radius);
        let center = self.center + (other.center - self.center) * ((radius - self.radius) / d);
        Bounds { center, radius }
    }
}

/// Everything about one frame's view that the passes need: matrices for the guard-banded
/// G-buffer, the depth range and the zoom. With `serde` it travels with a frame read back
/// elsewhere (the web page's), for the CPU reference to run on exactly what the passes saw.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FrameView {
    /// World to view space.
    pub view: Mat4,
    /// Projection of the guard-banded G-buffer (wgpu clip space, depth in [0, 1]).
    pub proj: Mat4,
    /// Visible size in pixels (without the guard band).
    pub width: u32,
    /// Visible height in pixels.
    pub height: u32,
    /// Guard band in pixels on each side.
    pub guard: u32,
    /// Normalized depth range, as −z_view.
    pub near: f32,
    /// The far end of the normalized depth range, as −z_view.
    pub far: f32,
    /// Focal length in pixels.
    pub f_px: f32,
    /// World units per zoom unit of z(P) (1 mm for tractograms).
    pub zoom_unit: f32,
    /// Whether the projection is orthographic.
    pub orthographic: bool,
    /// Radius of the scene's bounding sphere, world units.
    pub scene_radius: f32,
    /// Where this frame lies in the picture it is a tile of ([`FrameView::tile`]); untiled,
    /// the whole picture is the frame.
    #[cfg_attr(feature = "serde", serde(default))]
    pub tile: Option<Tile>,
}

/// A frame that is one tile of a larger picture: the picture's size and the tile's top-left
/// pixel in it. The tile's view is the picture's, cut to the tile and its own guard band, so
/// that the tiles stitch into the picture a single frame of its size would show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Tile {
    /// The whole picture's size in pixels.
    pub picture: [u32; 2],
    /// The tile's top-left pixel in the picture.
    pub origin: [u32; 2],
}

impl FrameView {
    /// The view of `camera` on a `width` × `height` image with `guard` pixels of guard band on each side, its depth range from `bounds`.
    pub fn new(camera: &Camera, bounds: &Bounds, width: u32, height: u32, guard: u32, zoom_unit: f32) -> Self {
        let view = camera.view_matrix();
        let (near, far) = depth_range(&view, bounds);
        let r = bounds.radius;
        let (w, h) = (width.max(1) as f32, height.max(1) as f32);
        let (gw, gh) = (w + 2.0 * guard as f32, h + 2.0 * guard as f32);
        // Clip a little outside [near, far] so geometry on the bounding sphere is never clipped.
        let (clip_near, clip_far) = (near * (1.0 - 1e-3), far * (1.0 + 1e-3));
        let (proj, f_px) = match camera.projection {
            Projection::Perspective { fov_y_deg } => {
                let tan_half = (fov_y_deg.to_radians() * 0.5).tan();
                let banded_fov = 2.0 * (tan_half * gh / h).atan();
                (directx::perspective(banded_fov, gw / gh, clip_near, clip_far), h / (2.0 * tan_half))
            }
            Projection::Orthographic { height: view_h } => {
                let half_h = 0.5 * view_h * gh / h;
                let half_w = half_h * gw / gh;
                (directx::orthographic(-half_w, half_w, -half_h, half_h, clip_near, clip_far), h / view_h)
            }
        };
        FrameView {
            view,
            proj,
            width,
            height,
            guard,
            near,
            far,
            f_px,
            zoom_unit,
            orthographic: matches!(camera.projection, Projection::Orthographic { .. }),
            scene_radius: r,
            tile: None,
        }
    }

    /// The view of `tile` (`width` × `height` visible pixels at `tile.origin` of a picture of
    /// `tile.picture`) with a `guard` band: the picture's camera, depth range and focal
    /// length, its projection cut off axis to the tile's guard-banded window.
    pub fn tile(
        camera: &Camera,
        bounds: &Bounds,
        tile: Tile,
        (width, height): (u32, u32),
        guard: u32,
        zoom_unit: f32,
    ) -> Self {
        let (near, far) = depth_range(&camera.view_matrix(), bounds);
        let [pw, ph] = tile.picture.map(|v| v.max(1) as f32);
        let [x0, y0] = tile.origin.map(|v| v as f32);
        let g = guard as f32;
        // The guard-banded window in pixels of the picture, from its centre (y up).
        let (left, right) = (x0 - g - 0.5 * pw, x0 + width as f32 + g - 0.5 * pw);
        let (top, bottom) = (0.5 * ph - (y0 - g), 0.5 * ph - (y0 + height as f32 + g));
        let (clip_near, clip_far) = (near * (1.0 - 1e-3), far * (1.0 + 1e-3));
        let (proj, f_px) = match camera.projection {
            Projection::Perspective { fov_y_deg } => {
                let tan_half = (fov_y_deg.to_radians() * 0.5).tan();
                let f_px = ph / (2.0 * tan_half);
                // An off-axis frustum in tangents of the angle from the axis (x/−z, y/−z).
                let (l, r, t, b) = (left / f_px, right / f_px, top / f_px, bottom / f_px);
                let depth = clip_far / (clip_near - clip_far);
                let proj = Mat4::from_cols(
                    glam::Vec4::new(2.0 / (r - l), 0.0, 0.0, 0.0),
                    glam::Vec4::new(0.0, 2.0 / (t - b), 0.0, 0.0),
                    glam::Vec4::new((r + l) / (r - l), (t + b) / (t - b), depth, -1.0),
                    glam::Vec4::new(0.0, 0.0, depth * clip_near, 0.0),
                );
                (proj, f_px)
            }
            Projection::Orthographic { height: view_h } => {
                let f_px = ph / view_h;
                let (l, r, t, b) = (left / f_px, right / f_px, top / f_px, bottom / f_px);
                (directx::orthographic(l, r, b, t, clip_near, clip_far), f_px)
            }
        };
        let untiled = FrameView::new(camera, bounds, width, height, guard, zoom_unit);
        FrameView { proj, f_px, tile: Some(tile), ..untiled }
    }

    /// The size of the picture this frame shows (or is a tile of).
    pub fn picture_size(&self) -> (u32, u32) {
        self.tile.map_or((self.width, self.height), |t| (t.picture[0], t.picture[1]))
    }

    /// The visible window's top-left pixel in the picture: (0, 0) untiled.
    pub fn origin(&self) -> [u32; 2] {
        self.tile.map_or([0, 0], |t| t.origin)
    }

    /// The optical axis in pixels of the guard-banded frame: its centre untiled, the
    /// picture's centre moved to the tile otherwise.
    pub fn center(&self) -> [f32; 2] {
        let (w, h) = self.picture_size();
        let [x0, y0] = self.origin();
        let g = 2 * self.guard;
        [(w + g) as f32 * 0.5 - x0 as f32, (h + g) as f32 * 0.5 - y0 as f32]
    }

    /// The noise tiles' origin in pixels of the guard-banded frame: the picture's top-left
    /// visible pixel, so that every tile of a picture sees the picture's noise.
    pub fn noise_origin(&self) -> [i32; 2] {
        let [x0, y0] = self.origin();
        [self.guard as i32 - x0 as i32, self.guard as i32 - y0 as i32]
    }

    /// The view of a host renderer's own `view` and `proj` matrices (wgpu clip space; any depth
    /// convention: standard or reversed-Z, finite or infinite far plane) for a `width` × `height`
    /// image without a guard band. The normalized depth range comes from `bounds` as for
    /// [`FrameView::new`]; f_px = `proj[1][1]` · H / 2; the projection is orthographic when
    /// its last row is (0, 0, 0, 1). The frustum must be symmetric.
    ///
    /// The zoom unit is the chain's ([`crate::ChainSettings::zoom_unit`]): [`crate::HostAo::prepare`]
    /// sets it, so it is said in one place; this view holds 1 until then.
    pub fn from_matrices(view: Mat4, proj: Mat4, width: u32, height: u32, bounds: &Bounds) -> Self {
        let (near, far) = depth_range(&view, bounds);
        let r = bounds.radius;
        FrameView {
            view,
            proj,
            width,
            height,
            guard: 0,
            near,
            far,
            f_px: proj.y_axis.y * height.max(1) as f32 / 2.0,
            zoom_unit: 1.0,
            orthographic: proj.row(3) == glam::Vec4::W,
            scene_radius: r,
            tile: None,
        }
    }

    /// Size of the guard-banded G-buffer.
    pub fn banded_size(&self) -> (u32, u32) {
        (self.width + 2 * self.guard, self.height + 2 * self.guard)
    }

    /// The largest zoom anywhere in the image: at the nearest geometry for perspective.
    pub fn zoom_max(&self) -> f32 {
        if self.orthographic { self.f_px * self.zoom_unit } else { self.f_px * self.zoom_unit / self.near }
    }

    /// The zoom at which the scene's bounding sphere just fills the shorter side of the view:
    /// the "home view" that the authors' zoom factor of 1 stands for (variant `reference`).
    pub fn zoom_fit(&self) -> f32 {
        let (w, h) = self.picture_size();
        w.min(h).max(1) as f32 * self.zoom_unit / (2.0 * self.scene_radius)
    }

    /// Normalized linear depth of a view-space z (docs/reference.md).
    pub fn normalized_depth(&self, z_view: f32) -> f32 {
        ((-z_view - self.near) / (self.far - self.near)).clamp(0.0, 1.0)
    }
}

/// The normalized depth range (near, far) as −z_view: the bounding sphere's, in front of the eye.
fn depth_range(view: &Mat4, bounds: &Bounds) -> (f32, f32) {
    let c_z = view.transform_point3(bounds.center).z;
    let r = bounds.radius;
    let near = (-c_z - r).max(1e-3 * r);
    let far = (-c_z + r).max(near * (1.0 + 1e-4) + 1e-6);
    (near, far)
}

/// How far, in full-resolution pixels, a nearest-texel read of pyramid level `level` reaches
/// beyond the sample point: the texel spans 2^j − 1 more pixels, and the binomial [1 4 6 4 1]
/// of each level reaches two texels further, 2 (2^j − 1) pixels over j levels.
pub fn pyramid_reach(level: u32) -> f32 {
    3.0 * ((1u32 << level.min(16)) - 1) as f32
}

/// The guard band of docs/reference.md: `radius_px` rounded up to a multiple of 2^(s_r−1), capped.
pub fn guard_band(radius_px: f32, s_r: u32, cap: u32) -> u32 {
    let step = 1u32 << s_r.saturating_sub(1).min(16);
    let needed = radius_px.max(0.0).ceil().min(u32::MAX as f32 / 2.0) as u32;
    needed.div_ceil(step).saturating_mul(step).min(cap)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(projection: Projection) -> Camera {
        Camera { eye: Vec3::new(0.0, 0.0, 100.0), target: Vec3::ZERO, up: Vec3::Y, projection }
    }

    #[test]
    fn guard_keeps_the_visible_window_and_focal_length() {
        let bounds = Bounds { center: Vec3::ZERO, radius: 10.0 };
        for projection in [Projection::Perspective { fov_y_deg: 40.0 }, Projection::Orthographic { height: 30.0 }] {
            let cam = camera(projection);
            let plain = FrameView::new(&cam, &bounds, 200, 100, 0, 1.0);
            let banded = FrameView::new(&cam, &bounds, 200, 100, 16, 1.0);
            assert!((plain.f_px - banded.f_px).abs() < 1e-3);
            assert_eq!((plain.near, plain.far), (90.0, 110.0));
            // A point that projects to a visible pixel lands on the same pixel + guard.
            let p = Vec3::new(3.0, -2.0, 5.0);
            let to_pixel = |fv: &FrameView| {
                let c = fv.proj.project_point3(fv.view.transform_point3(p));
                let (w, h) = fv.banded_size();
                ((c.x + 1.0) * 0.5 * w as f32, (1.0 - c.y) * 0.5 * h as f32)
            };
            let (a, b) = (to_pixel(&plain), to_pixel(&banded));
            assert!((a.0 + 16.0 - b.0).abs() < 1e-3 && (a.1 + 16.0 - b.1).abs() < 1e-3, "{a:?} {b:?}");
            // f_px = proj[1][1] · H / 2 for the unbanded projection.
            assert!((plain.proj.col(1).y * 50.0 - plain.f_px).abs() < 1e-3);
        }
    }

    #[test]
    fn guard_band_rounding() {
        assert_eq!(guard_band(13.2, 3, 128), 16);
        assert_eq!(guard_band(16.0, 3, 128), 16);
        assert_eq!(guard_band(0.0, 3, 128), 0);
        assert_eq!(guard_band(500.0, 3, 128), 128);
        assert_eq!(guard_band(5.0, 1, 128), 5);
    }
}
