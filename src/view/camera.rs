//! The viewer's orbit camera: yaw and pitch around a target at a distance, in a frame whose up
//! is the scene's (superior, +z, for tractograms). Orbiting, panning and zooming keep the line
//! width in pixels (LineAO's premise); orthographic shows the height the perspective view shows
//! at the target, so switching keeps the scale.

use glam::Vec3;
use lineao::{Camera, Projection};
use lineao_tracts::ViewHint;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    pub distance: f32,
    /// Radians around `up`, and above the plane perpendicular to it (clamped short of the poles).
    pub yaw: f32,
    pub pitch: f32,
    pub up: Vec3,
    pub fov_y_deg: f32,
    pub orthographic: bool,
    home: (Vec3, f32, f32, f32),
}

/// Two orthonormal directions spanning the plane perpendicular to `up`.
fn basis(up: Vec3) -> (Vec3, Vec3) {
    up.any_orthonormal_pair()
}

impl OrbitCamera {
    /// The camera a scene or file suggests.
    pub fn from_hint(hint: &ViewHint) -> OrbitCamera {
        let up = Vec3::from_array(hint.up).normalize_or(Vec3::Z);
        let (target, eye) = (Vec3::from_array(hint.target), Vec3::from_array(hint.eye));
        let offset = eye - target;
        let distance = offset.length().max(1e-3);
        let (a, b) = basis(up);
        let along_up = offset.dot(up) / distance;
        let yaw = offset.dot(b).atan2(offset.dot(a));
        let pitch = along_up.clamp(-1.0, 1.0).asin();
        OrbitCamera {
            target,
            distance,
            yaw,
            pitch,
            up,
            fov_y_deg: hint.fov_y_deg,
            orthographic: false,
            home: (target, distance, yaw, pitch),
        }
    }

    pub fn eye(&self) -> Vec3 {
        lineao_session::cameras::orbit_eye(self.target, self.up, self.distance, self.yaw, self.pitch)
    }

    /// The lineao camera of this view.
    pub fn camera(&self) -> Camera {
        let projection = if self.orthographic {
            Projection::Orthographic { height: 2.0 * self.distance * (self.fov_y_deg.to_radians() * 0.5).tan() }
        } else {
            Projection::Perspective { fov_y_deg: self.fov_y_deg }
        };
        Camera { eye: self.eye(), target: self.target, up: self.up, projection }
    }

    /// Turns by `dx`, `dy` radians (yaw, pitch).
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx;
        let limit = 89f32.to_radians();
        self.pitch = (self.pitch + dy).clamp(-limit, limit);
    }

    /// Moves the target by `dx`, `dy` pixels of a view `height_px` tall (the scene follows the
    /// pointer at the target's depth).
    pub fn pan(&mut self, dx: f32, dy: f32, height_px: f32) {
        let world_per_px = 2.0 * self.distance * (self.fov_y_deg.to_radians() * 0.5).tan() / height_px.max(1.0);
        let forward = (self.target - self.eye()).normalize();
        let right = forward.cross(self.up).normalize_or(Vec3::X);
        let screen_up = right.cross(forward);
        self.target += (-dx * right + dy * screen_up) * world_per_px;
    }

    /// Moves toward the target by `factor` (< 1 nearer).
    pub fn zoom(&mut self, factor: f32) {
        self.distance = (self.distance * factor).clamp(1e-3, 1e7);
    }

    /// Azimuth and elevation in degrees, and the distance as a factor of the home distance:
    /// `--orbit`'s values of this view.
    pub fn orbit_values(&self) -> [f32; 3] {
        [self.yaw.to_degrees(), self.pitch.to_degrees(), self.distance / self.home.1]
    }

    /// Turns to `--orbit`'s values ([`OrbitCamera::orbit_values`]) around the current target.
    pub fn set_orbit_values(&mut self, [azimuth, elevation, zoom]: [f32; 3]) {
        let limit = 89f32.to_radians();
        self.yaw = azimuth.to_radians();
        self.pitch = elevation.to_radians().clamp(-limit, limit);
        self.distance = (self.home.1 * zoom).clamp(1e-3, 1e7);
    }

    pub fn reset(&mut self) {
        (self.target, self.distance, self.yaw, self.pitch) = self.home;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hint_round_trips_and_orbit_keeps_the_distance() {
        let hint = ViewHint {
            eye: [-300.0, 20.0, 40.0],
            target: [0.0, 10.0, 5.0],
            up: [0.0, 0.0, 1.0],
            fov_y_deg: 30.0,
            zoom_unit: 1.0,
        };
        let mut camera = OrbitCamera::from_hint(&hint);
        assert!(camera.eye().distance(Vec3::from_array(hint.eye)) < 1e-3, "{}", camera.eye());
        let d = camera.distance;
        camera.orbit(0.7, -0.3);
        assert!((camera.eye().distance(camera.target) - d).abs() < 1e-3);
        camera.pan(100.0, -50.0, 800.0);
        camera.zoom(0.5);
        camera.reset();
        assert!(camera.eye().distance(Vec3::from_array(hint.eye)) < 1e-3);
        // Orthographic shows what perspective shows at the target.
        camera.orthographic = true;
        let lineao::Projection::Orthographic { height } = camera.camera().projection else { panic!() };
        assert!((height - 2.0 * d * 15f32.to_radians().tan()).abs() < 1e-3);
        // --orbit's values round-trip.
        camera.orbit(0.4, 0.2);
        camera.zoom(0.7);
        let values = camera.orbit_values();
        let eye = camera.eye();
        camera.reset();
        camera.set_orbit_values(values);
        assert!(camera.eye().distance(eye) < 1e-3, "{values:?}");
    }
}
