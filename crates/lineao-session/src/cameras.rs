//! Where the camera is: standard anatomical views (`--views`), the viewer's and the page's
//! orbit (`--orbit`: azimuth, elevation and zoom around the data's own camera), camera paths
//! through orbit keyframes, and turntables about the camera's up axis (Rodrigues' rotation, in
//! f64).

use glam::{DVec3, Vec3};
use lineao::Camera;

/// A standard anatomical view: which side of RAS+ world space the eye is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnatomicalView {
    Left,
    Right,
    Front,
    Back,
    Top,
    Bottom,
}

impl AnatomicalView {
    pub const ALL: [AnatomicalView; 6] = [
        AnatomicalView::Left,
        AnatomicalView::Right,
        AnatomicalView::Front,
        AnatomicalView::Back,
        AnatomicalView::Top,
        AnatomicalView::Bottom,
    ];

    /// Its name, as `--views` takes it and the figure labels it.
    pub fn name(self) -> &'static str {
        match self {
            AnatomicalView::Left => "left",
            AnatomicalView::Right => "right",
            AnatomicalView::Front => "front",
            AnatomicalView::Back => "back",
            AnatomicalView::Top => "top",
            AnatomicalView::Bottom => "bottom",
        }
    }

    /// The view of a name or its anatomical synonym (any case).
    pub fn from_name(name: &str) -> Option<AnatomicalView> {
        let name = name.trim().to_ascii_lowercase();
        let synonym = match name.as_str() {
            "anterior" => "front",
            "posterior" => "back",
            "superior" => "top",
            "inferior" => "bottom",
            other => other,
        };
        AnatomicalView::ALL.into_iter().find(|v| v.name() == synonym)
    }

    /// From the target toward the eye, and the camera's up: the sides look along x with
    /// superior up, front and back along y with superior up, top and bottom along z with
    /// anterior up (radiological conventions aside, each as a person standing there sees it).
    fn axes(self) -> (Vec3, Vec3) {
        match self {
            AnatomicalView::Left => (Vec3::NEG_X, Vec3::Z),
            AnatomicalView::Right => (Vec3::X, Vec3::Z),
            AnatomicalView::Front => (Vec3::Y, Vec3::Z),
            AnatomicalView::Back => (Vec3::NEG_Y, Vec3::Z),
            AnatomicalView::Top => (Vec3::Z, Vec3::Y),
            AnatomicalView::Bottom => (Vec3::NEG_Z, Vec3::Y),
        }
    }

    /// `base` moved to this view: the same target, distance and projection.
    pub fn camera(self, base: &Camera) -> Camera {
        let (toward_eye, up) = self.axes();
        let distance = (base.eye - base.target).length();
        Camera { eye: base.target + toward_eye * distance, target: base.target, up, projection: base.projection }
    }
}

/// One of `--views`, by name or synonym.
pub fn parse_view(name: &str) -> Result<AnatomicalView, String> {
    AnatomicalView::from_name(name).ok_or_else(|| {
        let known: Vec<&str> = AnatomicalView::ALL.iter().map(|v| v.name()).collect();
        format!(
            "'{}' is not a view (one of {}, or anterior, posterior, superior, inferior)",
            name.trim(),
            known.join(", ")
        )
    })
}

/// `--views`' list: each view once.
pub fn check_views(views: &[AnatomicalView]) -> Result<(), String> {
    match views.iter().enumerate().find(|(k, v)| views[..*k].contains(v)) {
        Some((_, view)) => Err(format!("--views names the view '{}' twice", view.name())),
        None => Ok(()),
    }
}

/// `--orbit`: AZIMUTH,ELEVATION,ZOOM (degrees, degrees within ±90, a factor > 0).
pub fn parse_orbit(s: &str) -> Result<[f32; 3], String> {
    let values: Vec<Option<f32>> =
        s.split(',').map(|v| v.trim().parse::<f32>().ok().filter(|v| v.is_finite())).collect();
    match values[..] {
        [Some(azimuth), Some(elevation), Some(zoom)] if zoom > 0.0 && elevation.abs() <= 90.0 => {
            Ok([azimuth, elevation, zoom])
        }
        _ => Err(format!("expected AZIMUTH,ELEVATION,ZOOM (degrees, degrees within ±90, a factor > 0), got '{s}'")),
    }
}

/// The viewer's orbit: the eye at `distance` from `target`, `yaw` radians around `up` (from
/// the first of `up`'s orthonormal pair toward the second) and `pitch` above the plane
/// perpendicular to it. One definition for the viewer, the page's links and `render --orbit`.
pub fn orbit_eye(target: Vec3, up: Vec3, distance: f32, yaw: f32, pitch: f32) -> Vec3 {
    let (a, b) = up.any_orthonormal_pair();
    let horizontal = a * yaw.cos() + b * yaw.sin();
    target + distance * (horizontal * pitch.cos() + up * pitch.sin())
}

/// `home` (the data's default camera) turned to `--orbit`'s values: its target and up, the
/// azimuth and elevation around that up, the distance times the zoom.
pub fn orbit_camera(home: &Camera, [azimuth, elevation, zoom]: [f32; 3]) -> Camera {
    let up = home.up.normalize_or(Vec3::Z);
    let distance = (home.eye - home.target).length().max(1e-3);
    let limit = 89f32.to_radians();
    let pitch = elevation.to_radians().clamp(-limit, limit);
    let eye = orbit_eye(home.target, up, (distance * zoom).clamp(1e-3, 1e7), azimuth.to_radians(), pitch);
    Camera { eye, up, ..*home }
}

/// `frames` cameras along the keyframes `orbits` (at least two): frame k at k / (frames − 1)
/// of the path, linear in azimuth, elevation and zoom between the keyframes it lies between;
/// the first frame is the first keyframe, the last the last.
pub fn camera_path(home: &Camera, orbits: &[[f32; 3]], frames: u32) -> Vec<Camera> {
    let stretches = (orbits.len() - 1) as f64;
    (0..frames)
        .map(|k| {
            let t = if frames > 1 { k as f64 / (frames - 1) as f64 * stretches } else { 0.0 };
            let i = (t.floor() as usize).min(orbits.len() - 2);
            let f = (t - i as f64) as f32;
            let (a, b) = (orbits[i], orbits[i + 1]);
            orbit_camera(home, [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * f))
        })
        .collect()
}

/// `frames` cameras turned from `camera` about its target around its up axis, `degrees` in
/// all, frame k at k / frames of the turn (frame 0 is `camera`).
pub fn turntable(camera: &Camera, frames: u32, degrees: f32) -> Vec<Camera> {
    let (eye, target, up) = (camera.eye.as_dvec3(), camera.target.as_dvec3(), camera.up.as_dvec3());
    let axis = up.normalize();
    let v = eye - target;
    (0..frames)
        .map(|k| {
            let angle = (degrees as f64).to_radians() * k as f64 / frames as f64;
            let (sin, cos) = angle.sin_cos();
            // Rodrigues' rotation of v about the axis.
            let rotated: DVec3 = v * cos + axis.cross(v) * sin + axis * axis.dot(v) * (1.0 - cos);
            Camera { eye: (target + rotated).as_vec3(), ..*camera }
        })
        .collect()
}
