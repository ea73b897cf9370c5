//! Scene lights. LineAO attenuates occlusion where a light reaches the surface (Eq. 14–15) and the
//! line renderer adds the illuminated-lines specular with the same lights (paper §3.3).

use glam::Vec3;

/// At most this many lights reach the shaders.
pub const MAX_LIGHTS: usize = 4;

/// A directional light in view space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Direction toward the light, view space (normalized when uploaded).
    pub dir: Vec3,
    /// Intensity I.
    pub intensity: f32,
}

/// Lights and the Blinn-Phong material of Eq. 14 (and of the illuminated-lines specular).
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    /// Up to [`MAX_LIGHTS`] lights; more are an error when the chain is prepared.
    pub lights: Vec<Light>,
    /// Diffuse coefficient kd, default 0.3.
    pub kd: f32,
    /// Specular coefficient ks, default 0.4.
    pub ks: f32,
    /// Shininess α, default 32.
    pub shininess: f32,
}

impl Default for Lighting {
    /// CONTRACT.md: one light toward normalize(−0.4, 0.6, 0.7), I = 1, kd 0.3, ks 0.4, α 32.
    fn default() -> Self {
        Lighting {
            lights: vec![Light { dir: Vec3::new(-0.4, 0.6, 0.7).normalize(), intensity: 1.0 }],
            kd: 0.3,
            ks: 0.4,
            shininess: 32.0,
        }
    }
}

/// Keep in sync with `shaders/shared/lighting.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightingUniform {
    pub lights: [[f32; 4]; MAX_LIGHTS],
    pub count: u32,
    pub kd: f32,
    pub ks: f32,
    pub shininess: f32,
}

impl Lighting {
    /// Light directions normalized, as the shaders see them.
    pub fn normalized(&self) -> Vec<Light> {
        self.lights.iter().map(|l| Light { dir: l.dir.normalize_or_zero(), intensity: l.intensity }).collect()
    }

    pub fn uniform(&self) -> LightingUniform {
        let mut lights = [[0.0; 4]; MAX_LIGHTS];
        let normalized = self.normalized();
        for (slot, light) in lights.iter_mut().zip(&normalized) {
            *slot = [light.dir.x, light.dir.y, light.dir.z, light.intensity];
        }
        LightingUniform {
            lights,
            count: normalized.len().min(MAX_LIGHTS) as u32,
            kd: self.kd,
            ks: self.ks,
            shininess: self.shininess,
        }
    }
}
