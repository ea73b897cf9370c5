//! The integrated geometry term of occlusion sweeping (seed 000 Eq. 5):
//! G_o(N) = ∫_{Ω_o} max(N·ω, 0) dω over octant o of the sphere.
//!
//! In closed form: an octant is the spherical triangle with corners σ_x e_x, σ_y e_y, σ_z e_z;
//! clipping it by the hemisphere N·ω ≥ 0 leaves a spherical polygon P with great-circle edges,
//! and Lambert's formula gives ∫_P N·ω dω = ½ Σ_k θ_k N·Γ_k over its edges (θ_k the edge's
//! angle, Γ_k the unit normal of its plane, oriented outward-consistently). Σ_o G_o(N) = π for
//! every N, the cosine integral over the hemisphere.
//!
//! The renderer reads G from a [`GeometryTable`] (as the paper's two RGBA textures, Fig. 2): an
//! octahedral map of N, [`TABLE_SIZE`]² texels of eight values, interpolated bilinearly by the
//! shader and by the CPU reference alike. The view-independent form averages G over the
//! normals perpendicular to a line's tangent, in a second table over the tangent.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{OctantVisibility, octant_signs};

/// Texels per side of the octahedral tables (G varies smoothly: 64² keeps the bilinear error
/// below 0.01 of π, measured by the tests).
pub const TABLE_SIZE: usize = 64;

/// G_o(N) for a unit normal `n`, in closed form.
pub fn octant_integral(o: usize, n: Vec3) -> f32 {
    let s = octant_signs(o);
    // Counter-clockwise seen from outside: (v0 × v1)·v2 > 0.
    let (v0, v1, v2) = (Vec3::X * s.x, Vec3::Y * s.y, Vec3::Z * s.z);
    let corners = if v0.cross(v1).dot(v2) > 0.0 { [v0, v1, v2] } else { [v0, v2, v1] };
    // Clip by N·ω ≥ 0 (Sutherland–Hodgman on the sphere: a crossing edge's point is the
    // positive combination of its ends that lies on the great circle).
    let mut polygon: Vec<Vec3> = Vec::with_capacity(5);
    for k in 0..3 {
        let (a, b) = (corners[k], corners[(k + 1) % 3]);
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            polygon.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            polygon.push((a * db.abs() + b * da.abs()).normalize());
        }
    }
    let mut sum = 0.0;
    for k in 0..polygon.len() {
        let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
        let cross = a.cross(b);
        let length = cross.length();
        if length > 1e-7 {
            sum += length.atan2(a.dot(b)) * n.dot(cross / length);
        }
    }
    (0.5 * sum).max(0.0)
}

/// G for all eight octants.
pub fn octant_integrals(n: Vec3) -> [f32; 8] {
    std::array::from_fn(|o| octant_integral(o, n))
}

/// Ḡ_o(T): G_o averaged over the unit normals perpendicular to `t` (the same for −t).
pub fn around_tangent(t: Vec3, steps: usize) -> [f32; 8] {
    let t = t.normalize_or(Vec3::Z);
    let (b1, b2) = t.any_orthonormal_pair();
    let mut sum = [0.0f32; 8];
    for k in 0..steps {
        let phi = 2.0 * PI * (k as f32 + 0.5) / steps as f32;
        let g = octant_integrals(b1 * phi.cos() + b2 * phi.sin());
        sum.iter_mut().zip(g).for_each(|(s, g)| *s += g / steps as f32);
    }
    sum
}

/// Σ_o w_o V_o G_o / Σ_o G_o: visibility normalized to [0, 1] (Σ_o G_o = π for an exact G).
pub fn weighted_visibility(v: &OctantVisibility, g: &[f32; 8], weights: &[f32; 8]) -> f32 {
    let (mut lit, mut total) = (0.0, 0.0);
    for o in 0..8 {
        lit += weights[o] * v[o] * g[o];
        total += g[o];
    }
    if total > 0.0 { lit / total } else { 0.0 }
}

/// Octahedral encoding of a unit vector into [−1, 1]².
pub fn octahedral_encode(n: Vec3) -> Vec2 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs());
    let p = Vec2::new(n.x, n.y);
    if n.z >= 0.0 { p } else { (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign_not_zero(p) }
}

/// The unit vector of an octahedral code in [−1, 1]².
pub fn octahedral_decode(p: Vec2) -> Vec3 {
    let z = 1.0 - p.x.abs() - p.y.abs();
    let xy = if z >= 0.0 { p } else { (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign_not_zero(p) };
    Vec3::new(xy.x, xy.y, z).normalize()
}

fn sign_not_zero(p: Vec2) -> Vec2 {
    Vec2::new(if p.x >= 0.0 { 1.0 } else { -1.0 }, if p.y >= 0.0 { 1.0 } else { -1.0 })
}

/// Eight values per direction on an octahedral map of `size`² texels (texel (i, j) at the
/// code ((i + ½)/size, (j + ½)/size)·2 − 1), row-major, j slowest.
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryTable {
    /// Texels a side.
    pub size: usize,
    /// Eight values per texel, row-major.
    pub values: Vec<[f32; 8]>,
}

impl GeometryTable {
    /// G_o(N) per texel.
    pub fn normals(size: usize) -> GeometryTable {
        Self::build(size, octant_integrals)
    }

    /// Ḡ_o(T) per texel (64 normals around each tangent).
    pub fn around_tangent(size: usize) -> GeometryTable {
        Self::build(size, |t| around_tangent(t, 64))
    }

    fn build(size: usize, f: impl Fn(Vec3) -> [f32; 8]) -> GeometryTable {
        let values = (0..size * size)
            .map(|k| {
                let code = (Vec2::new((k % size) as f32, (k / size) as f32) + 0.5) / size as f32 * 2.0 - 1.0;
                f(octahedral_decode(code))
            })
            .collect();
        GeometryTable { size, values }
    }

    /// Bilinear lookup at direction `n` (any length; zero reads the +z texel), clamped at the
    /// map's border — the arithmetic of `volume_ao.wgsl`'s `geometry_term`.
    pub fn lookup(&self, n: Vec3) -> [f32; 8] {
        let n = n.normalize_or(Vec3::Z);
        let top = (self.size - 1) as f32;
        let f = ((octahedral_encode(n) + 1.0) * 0.5 * self.size as f32 - 0.5).clamp(Vec2::ZERO, Vec2::splat(top));
        let base = f.floor().min(Vec2::splat((top - 1.0).max(0.0)));
        let w = f - base;
        let (i, j) = (base.x as usize, base.y as usize);
        let (i1, j1) = ((i + 1).min(self.size - 1), (j + 1).min(self.size - 1));
        let at = |i: usize, j: usize| &self.values[i + self.size * j];
        std::array::from_fn(|o| {
            let top = at(i, j)[o] * (1.0 - w.x) + at(i1, j)[o] * w.x;
            let bottom = at(i, j1)[o] * (1.0 - w.x) + at(i1, j1)[o] * w.x;
            top * (1.0 - w.y) + bottom * w.y
        })
    }
}
