//! CPU reference of `shaders/tubes.wgsl`: the pixel's ray and its first hit with a segment's
//! rounded cone, in the shader's arithmetic.

use glam::{Mat4, Vec3, Vec4Swizzles};

use crate::camera::FrameView;

/// The ray of pixel `pixel` (guard-banded image, pixel centre) in view space, as the shader
/// builds it: the points at NDC depth 0 and 1 unprojected by `inv_proj`; `(origin, unit
/// direction)`.
pub fn pixel_ray(view: &FrameView, inv_proj: Mat4, pixel: [u32; 2]) -> (Vec3, Vec3) {
    let (w, h) = view.banded_size();
    let ndc_x = 2.0 * (pixel[0] as f32 + 0.5) / w as f32 - 1.0;
    let ndc_y = 1.0 - 2.0 * (pixel[1] as f32 + 0.5) / h as f32;
    let near = inv_proj * glam::Vec4::new(ndc_x, ndc_y, 0.0, 1.0);
    let far = inv_proj * glam::Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
    let origin = near.xyz() / near.w;
    (origin, (far.xyz() / far.w - origin).normalize())
}

/// The first hit of the ray `ro + t rd` (unit `rd`) with the rounded cone of spheres (pa, ra)
/// and (pb, rb) — the convex hull of the two, a capsule for ra = rb: `(t, outward unit
/// normal)`. Hits behind the origin are returned too (t < 0 is a miss for the renderer).
///
/// With ba = pb − pa, L = |ba| and sin θ = (ra − rb)/L, a point at axial coordinate x and
/// distance ρ from the axis lies on the cone's body where x sin θ + ρ cos θ = ra (the line
/// tangent to both circles). Squared and multiplied out along the ray, that is
/// k2 t² + 2 k1 t + k0 = 0 (the m's are dot products of ba, oa = ro − pa, ob = ro − pb and rd,
/// d2 = L² − (ra − rb)²), a body point where it lies between the tangent circles: 0 < y < d2,
/// y = L x − ra (ra − rb). Squaring also admits the mirrored cone beyond the apex, so *either*
/// root may be the body's; and the solid is convex, so its entry is the smallest t among the
/// valid body roots and the end spheres' entries (each sphere lies inside the solid).
pub fn intersect_rounded_cone(ro: Vec3, rd: Vec3, pa: Vec3, pb: Vec3, ra: f32, rb: f32) -> Option<(f32, Vec3)> {
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
    let mut best: Option<(f32, Vec3)> = None;
    let mut consider = |t: f32, n: Vec3| {
        if best.is_none_or(|(first, _)| t < first) {
            best = Some((t, n));
        }
    };
    let d2 = m0 - rr * rr;
    if d2 > 0.0 {
        let k2 = d2 - m2 * m2;
        let k1 = d2 * m3 - m1 * m2 + m2 * rr * ra;
        let k0 = d2 * m5 - m1 * m1 + m1 * rr * ra * 2.0 - m0 * ra * ra;
        let h = k1 * k1 - k0 * k2;
        if h >= 0.0 && k2 != 0.0 {
            let roots = [(-h.sqrt() - k1) / k2, (h.sqrt() - k1) / k2];
            // For k2 > 0 the first root enters the infinite cone, which holds the solid: on the
            // body, it is the entry (the common case, decided without the spheres).
            let y0 = m1 - ra * rr + roots[0] * m2;
            if k2 > 0.0 && y0 > 0.0 && y0 < d2 {
                return Some((roots[0], (d2 * (oa + roots[0] * rd) - ba * y0).normalize()));
            }
            for t in roots {
                let y = m1 - ra * rr + t * m2;
                if y > 0.0 && y < d2 {
                    consider(t, (d2 * (oa + t * rd) - ba * y).normalize());
                }
            }
        }
    }
    let h1 = m3 * m3 - m5 + ra * ra;
    if h1 > 0.0 {
        let t = -m3 - h1.sqrt();
        consider(t, (oa + t * rd) / ra);
    }
    let h2 = m6 * m6 - m7 + rb * rb;
    if h2 > 0.0 {
        let t = -m6 - h2.sqrt();
        consider(t, (ob + t * rd) / rb);
    }
    best
}

/// Signed distance from `p` to the rounded cone (exact): the independent check of
/// [`intersect_rounded_cone`] by sphere tracing.
pub fn rounded_cone_distance(p: Vec3, pa: Vec3, pb: Vec3, ra: f32, rb: f32) -> f32 {
    rounded_cone_distance_and_normal(p, pa, pb, ra, rb).0
}

/// The exact distance's gradient at `p`: the outward unit normal of the nearest surface point.
pub fn rounded_cone_normal(p: Vec3, pa: Vec3, pb: Vec3, ra: f32, rb: f32) -> Vec3 {
    rounded_cone_distance_and_normal(p, pa, pb, ra, rb).1
}

fn rounded_cone_distance_and_normal(p: Vec3, pa: Vec3, pb: Vec3, ra: f32, rb: f32) -> (f32, Vec3) {
    let sphere = |c: Vec3, r: f32| (p.distance(c) - r, (p - c).normalize_or(Vec3::Z));
    // In the plane of p and the axis: (along, across) from pa.
    let ba = pb - pa;
    let length = ba.length();
    if (ra - rb).abs() >= length {
        // One sphere holds the other.
        return if ra > rb { sphere(pa, ra) } else { sphere(pb, rb) };
    }
    let axis = ba / length;
    let along = (p - pa).dot(axis);
    let radial = (p - pa) - along * axis;
    let across = radial.length();
    // The tangent line leaves the axis at angle θ with sin θ = (ra − rb) / length.
    let sin = (ra - rb) / length;
    let cos = (1.0 - sin * sin).sqrt();
    // In (across, along) coordinates the body's surface normal is (cos, sin); the component of
    // p along the tangent line's direction (−sin, cos) says which part is closest.
    let k = -sin * across + cos * along;
    if k < 0.0 {
        // Beyond the tangent circle of a: the sphere at a.
        return sphere(pa, ra);
    }
    if k > length * cos {
        return sphere(pb, rb);
    }
    let out = radial.normalize_or(axis.any_orthonormal_vector());
    (along * sin + across * cos - ra, (sin * axis + cos * out).normalize())
}
