//! The primitives the ground truth is traced against, and their exact intersections.
//!
//! - A **rounded cone**: the convex hull of two spheres (a, r_a) and (b, r_b) — a segment of a
//!   tube, or of a fixed-width line's "supposed volume" (a sphere-swept segment whose radius
//!   changes linearly along it). A capsule when r_a = r_b, a sphere when a = b.
//! - A **triangle** of a context surface.
//!
//! Positions are stored as f32 (what the frame drew); every intersection is computed in f64
//! *relative to the ray's origin*, so coordinates near 1e5 keep their sub-micrometre detail.
//!
//! The cone's algebra is that of `reference::tubes::intersect_rounded_cone`, which stays apart on
//! purpose: it follows the tube shader's f32 arithmetic step by step to prove the shader, while
//! this one is the truth's — f64, an interval (t_min, t_max) and every root kept, so rays from
//! inside a volume meet its surface too.

use glam::{DVec3, Vec3};

/// A segment's rounded cone, with where it came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoundedCone {
    /// One end.
    pub a: Vec3,
    /// The other end.
    pub b: Vec3,
    /// The radius at `a`.
    pub ra: f32,
    /// The radius at `b`.
    pub rb: f32,
    /// The streamline it belongs to, and its segment index within it (segment k joins points
    /// k and k + 1): what tells a line pixel's own segment and its neighbours.
    pub streamline: u32,
    /// Its segment within the streamline.
    pub segment: u32,
}

/// A triangle of a context surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The corners.
    pub v: [Vec3; 3],
}

impl RoundedCone {
    /// The axis-aligned box around it.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let lo = (self.a - Vec3::splat(self.ra)).min(self.b - Vec3::splat(self.rb));
        let hi = (self.a + Vec3::splat(self.ra)).max(self.b + Vec3::splat(self.rb));
        (lo, hi)
    }

    /// The nearest point of the axis to `p` as a parameter in [0, 1] of a → b.
    pub fn axis_parameter(&self, p: DVec3) -> f64 {
        let (a, b) = (self.a.as_dvec3(), self.b.as_dvec3());
        let ba = b - a;
        let length2 = ba.length_squared();
        if length2 == 0.0 { 0.0 } else { ((p - a).dot(ba) / length2).clamp(0.0, 1.0) }
    }

    /// The point of the axis at parameter `t` and the radius there.
    pub fn axis_point(&self, t: f64) -> (DVec3, f64) {
        let (a, b) = (self.a.as_dvec3(), self.b.as_dvec3());
        (a + (b - a) * t, self.ra as f64 + (self.rb as f64 - self.ra as f64) * t)
    }

    /// Signed distance from `p` (negative inside), exact.
    pub fn distance(&self, p: DVec3) -> f64 {
        rounded_cone_distance(p, self.a.as_dvec3(), self.b.as_dvec3(), self.ra as f64, self.rb as f64)
    }

    /// The nearest surface point along `ro + t rd` (unit `rd`) with t in (t_min, t_max).
    pub fn intersect(&self, ro: DVec3, rd: DVec3, t_min: f64, t_max: f64) -> Option<f64> {
        intersect_rounded_cone(
            ro,
            rd,
            self.a.as_dvec3(),
            self.b.as_dvec3(),
            self.ra as f64,
            self.rb as f64,
            t_min,
            t_max,
        )
    }
}

impl Triangle {
    /// Its axis-aligned box.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.v[0].min(self.v[1]).min(self.v[2]), self.v[0].max(self.v[1]).max(self.v[2]))
    }

    /// The nearest hit along the ray ro + t rd in (t_min, t_max), if any.
    pub fn intersect(&self, ro: DVec3, rd: DVec3, t_min: f64, t_max: f64) -> Option<f64> {
        intersect_triangle(ro, rd, self.v.map(Vec3::as_dvec3), t_min, t_max)
    }
}

/// The first surface point of the rounded cone of spheres (pa, ra) and (pb, rb) along
/// `ro + t rd` (unit `rd`) with t in (t_min, t_max), or `None`.
///
/// With ba = pb − pa, L = |ba| and sin θ = (ra − rb)/L, a point at axial coordinate x and
/// distance ρ from the axis lies on the cone's body where x sin θ + ρ cos θ = ra (the line
/// tangent to both spheres). Squared along the ray that is k2 t² + 2 k1 t + k0 = 0, a body
/// point where it lies between the tangent circles: 0 < y < d2 with y = L x − ra (ra − rb) and
/// d2 = L² − (ra − rb)². Squaring also admits the mirrored cone, so each root is checked; the
/// end spheres add their two roots. Every candidate lies in the solid, which is convex: the
/// entry of a ray from outside is the smallest candidate, and one from inside meets the surface
/// first at the smallest candidate beyond its origin. When one sphere holds the other
/// (d2 ≤ 0) the body is empty and the spheres alone are the solid.
///
/// The same algebra as [`crate::reference::tubes::intersect_rounded_cone`], kept apart on
/// purpose: that one replays the tube shader's f32 arithmetic and early exits (so the shader
/// can be compared with it bit for bit) and returns the normal; this one is the ground truth,
/// in f64 relative to the ray's origin, with an interval (t_min, t_max) and origins inside.
#[allow(clippy::too_many_arguments)]
pub fn intersect_rounded_cone(
    ro: DVec3,
    rd: DVec3,
    pa: DVec3,
    pb: DVec3,
    ra: f64,
    rb: f64,
    t_min: f64,
    t_max: f64,
) -> Option<f64> {
    let ba = pb - pa;
    let oa = ro - pa;
    let ob = ro - pb;
    let rr = ra - rb;
    let m0 = ba.dot(ba);
    let m1 = ba.dot(oa);
    let m2 = ba.dot(rd);
    let m3 = rd.dot(oa);
    let m5 = oa.dot(oa);
    let m6 = ob.dot(rd);
    let m7 = ob.dot(ob);
    let mut best = f64::INFINITY;
    let mut consider = |t: f64| {
        if t > t_min && t < t_max && t < best {
            best = t;
        }
    };
    let d2 = m0 - rr * rr;
    if d2 > 0.0 {
        let k2 = d2 - m2 * m2;
        let k1 = d2 * m3 - m1 * m2 + m2 * rr * ra;
        let k0 = d2 * m5 - m1 * m1 + m1 * rr * ra * 2.0 - m0 * ra * ra;
        let h = k1 * k1 - k0 * k2;
        if h >= 0.0 && k2 != 0.0 {
            let s = h.sqrt();
            for t in [(-s - k1) / k2, (s - k1) / k2] {
                let y = m1 - ra * rr + t * m2;
                if y > 0.0 && y < d2 {
                    consider(t);
                }
            }
        }
    }
    for (m, c2, r) in [(m3, m5, ra), (m6, m7, rb)] {
        let h = m * m - c2 + r * r;
        if h >= 0.0 {
            let s = h.sqrt();
            consider(-m - s);
            consider(-m + s);
        }
    }
    best.is_finite().then_some(best)
}

/// Ray–triangle (Möller–Trumbore in f64, relative to the ray's origin): the hit's t in
/// (t_min, t_max). Rays in the triangle's plane miss.
pub fn intersect_triangle(ro: DVec3, rd: DVec3, v: [DVec3; 3], t_min: f64, t_max: f64) -> Option<f64> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = rd.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = ro - v[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let w = rd.dot(q) * inv;
    if w < 0.0 || u + w > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > t_min && t < t_max).then_some(t)
}

/// Signed distance from `p` to the rounded cone (negative inside), exact: in the plane of `p`
/// and the axis, the nearest point is on an end sphere or on the tangent line between them.
pub fn rounded_cone_distance(p: DVec3, pa: DVec3, pb: DVec3, ra: f64, rb: f64) -> f64 {
    let ba = pb - pa;
    let length = ba.length();
    if (ra - rb).abs() >= length {
        // One sphere holds the other (or a zero-length segment).
        return if ra >= rb { p.distance(pa) - ra } else { p.distance(pb) - rb };
    }
    let axis = ba / length;
    let along = (p - pa).dot(axis);
    let across = ((p - pa) - along * axis).length();
    let sin = (ra - rb) / length;
    let cos = (1.0 - sin * sin).sqrt();
    // The component of p along the tangent line's direction (−sin, cos) tells which part is
    // nearest.
    let k = -sin * across + cos * along;
    if k < 0.0 {
        p.distance(pa) - ra
    } else if k > length * cos {
        p.distance(pb) - rb
    } else {
        along * sin + across * cos - ra
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const X: DVec3 = DVec3::X;

    fn cone(a: [f64; 3], b: [f64; 3], ra: f64, rb: f64) -> (DVec3, DVec3, f64, f64) {
        (DVec3::from(a), DVec3::from(b), ra, rb)
    }

    fn hit(ro: DVec3, rd: DVec3, c: (DVec3, DVec3, f64, f64)) -> Option<f64> {
        intersect_rounded_cone(ro, rd.normalize(), c.0, c.1, c.2, c.3, 0.0, f64::INFINITY)
    }

    #[test]
    fn capsule_hit_distances_are_exact() {
        // A capsule of radius 1 along x from 0 to 10: from (5, 0, 5) straight down, the body at
        // z = 1; from (-5, 0, 0) along +x, the cap at x = -1; from the side at y = 0.6, the body
        // at z = sqrt(1 - 0.36) = 0.8.
        let c = cone([0.0; 3], [10.0, 0.0, 0.0], 1.0, 1.0);
        assert!((hit(DVec3::new(5.0, 0.0, 5.0), -DVec3::Z, c).unwrap() - 4.0).abs() < 1e-12);
        assert!((hit(DVec3::new(-5.0, 0.0, 0.0), X, c).unwrap() - 4.0).abs() < 1e-12);
        assert!((hit(DVec3::new(5.0, 0.6, 5.0), -DVec3::Z, c).unwrap() - 4.2).abs() < 1e-12);
        // Beyond the cap's rim from above: x = 10.6 meets the cap sphere at z = 0.8.
        assert!((hit(DVec3::new(10.6, 0.0, 5.0), -DVec3::Z, c).unwrap() - 4.2).abs() < 1e-12);
        // Misses: passing above, and pointing away.
        assert_eq!(hit(DVec3::new(5.0, 0.0, 1.5), X, c), None);
        assert_eq!(hit(DVec3::new(5.0, 0.0, 5.0), DVec3::Z, c), None);
    }

    #[test]
    fn cone_body_hit_matches_its_closed_form() {
        // Radii 2 → 1 over length 10: sin θ = 0.1. Coming down the z axis at x = 5 the surface
        // is where x sin θ + z cos θ = 2, z = (2 − 0.5) / cos θ.
        let c = cone([0.0; 3], [10.0, 0.0, 0.0], 2.0, 1.0);
        let cos = (1.0f64 - 0.01).sqrt();
        let expected = 10.0 - 1.5 / cos;
        assert!((hit(DVec3::new(5.0, 0.0, 10.0), -DVec3::Z, c).unwrap() - expected).abs() < 1e-12);
    }

    #[test]
    fn grazing_rays_touch_or_miss() {
        let c = cone([0.0; 3], [10.0, 0.0, 0.0], 1.0, 1.0);
        // Tangent to the body at z = 1: a touch is a (double) hit; a hair above, none.
        let t = hit(DVec3::new(5.0, -5.0, 1.0), DVec3::Y, c).unwrap();
        assert!((t - 5.0).abs() < 1e-6, "{t}");
        assert_eq!(hit(DVec3::new(5.0, -5.0, 1.0 + 1e-9), DVec3::Y, c), None);
    }

    #[test]
    fn origins_inside_meet_the_surface_beyond() {
        let c = cone([0.0; 3], [10.0, 0.0, 0.0], 1.0, 1.0);
        let t = hit(DVec3::new(5.0, 0.0, 0.0), DVec3::Z, c).unwrap();
        assert!((t - 1.0).abs() < 1e-12);
        assert!(rounded_cone_distance(DVec3::new(5.0, 0.0, 0.0), c.0, c.1, c.2, c.3) < 0.0);
    }

    #[test]
    fn degenerate_segments_are_spheres() {
        // Zero length, and one sphere holding the other.
        for c in [cone([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], 0.5, 0.5), cone([1.0, 2.0, 3.0], [1.1, 2.0, 3.0], 0.5, 0.2)] {
            let t = hit(DVec3::new(1.0, 2.0, 10.0), -DVec3::Z, c).unwrap();
            assert!((t - 6.5).abs() < 1e-12, "{t}");
            let d = rounded_cone_distance(DVec3::new(1.0, 2.0, 10.0), c.0, c.1, c.2, c.3);
            assert!((d - 6.5).abs() < 1e-12);
        }
    }

    #[test]
    fn far_from_the_origin_the_precision_holds() {
        // Coordinates near 1e5 with a 0.05-unit radius, in f32 storage as the scenes are.
        let base = Vec3::new(1.0e5, -1.0e5, 1.0e5);
        let c =
            RoundedCone { a: base, b: base + Vec3::new(1.0, 0.0, 0.0), ra: 0.05, rb: 0.05, streamline: 0, segment: 0 };
        let ro = base.as_dvec3() + DVec3::new(0.5, 0.0, 1.0);
        let t = c.intersect(ro, -DVec3::Z, 0.0, 10.0).unwrap();
        assert!((t - 0.95).abs() < 1e-9, "{t}");
        assert!((c.distance(ro) - 0.95).abs() < 1e-9);
    }

    #[test]
    fn triangle_hits_and_edges() {
        let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let t = intersect_triangle(DVec3::new(0.2, 0.2, 3.0), -DVec3::Z, v, 0.0, 10.0).unwrap();
        assert!((t - 3.0).abs() < 1e-12);
        assert_eq!(intersect_triangle(DVec3::new(0.6, 0.6, 3.0), -DVec3::Z, v, 0.0, 10.0), None);
        // Parallel to the plane.
        assert_eq!(intersect_triangle(DVec3::new(0.2, 0.2, 0.0), X, v, 0.0, 10.0), None);
        // Beyond t_max.
        assert_eq!(intersect_triangle(DVec3::new(0.2, 0.2, 3.0), -DVec3::Z, v, 0.0, 2.0), None);
        // Far from the origin.
        let o = DVec3::splat(1.0e5);
        let far = v.map(|p| p + o);
        let t = intersect_triangle(o + DVec3::new(0.25, 0.25, 0.001), -DVec3::Z, far, 0.0, 1.0).unwrap();
        assert!((t - 0.001).abs() < 1e-9);
    }

    #[test]
    fn hits_lie_on_the_surface() {
        // Random rays against random cones: every hit point is at distance 0 from the surface
        // (the exact signed distance as the independent check), and no point before it is inside.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut hits = 0;
        for _ in 0..20_000 {
            let pa = DVec3::new(rnd(), rnd(), rnd()) * 4.0;
            let pb = DVec3::new(rnd(), rnd(), rnd()) * 4.0;
            let (ra, rb) = (0.1 + rnd(), 0.1 + rnd());
            let ro = DVec3::new(rnd(), rnd(), rnd()) * 12.0 - DVec3::splat(4.0);
            if rounded_cone_distance(ro, pa, pb, ra, rb) <= 0.0 {
                continue;
            }
            let rd = (DVec3::new(rnd(), rnd(), rnd()) * 4.0 + pa - ro).normalize();
            if let Some(t) = intersect_rounded_cone(ro, rd, pa, pb, ra, rb, 0.0, f64::INFINITY) {
                hits += 1;
                let d = rounded_cone_distance(ro + t * rd, pa, pb, ra, rb);
                assert!(d.abs() < 1e-9, "hit at t = {t} is {d} from the surface");
                for k in 1..8 {
                    assert!(rounded_cone_distance(ro + t * rd * (k as f64 / 8.0), pa, pb, ra, rb) > -1e-9);
                }
            }
        }
        assert!(hits > 1_000, "{hits}");
    }
}
