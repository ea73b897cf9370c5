// The billboard a tube segment is ray-cast on (`tubes.wgsl`), and what the cull bounds it by
// (`cull.wgsl`): on screen the disks that hold its two end spheres' projections, hulled by a
// rectangle along the segment; in depth the solid's nearest point, the nearer end sphere's
// front, which the fragment shader's written depth is never nearer than. The rounded cone is
// the convex hull of its end spheres, so its projection is the hull of theirs (a projection
// keeps convex hulls of what lies before the eye): every pixel whose ray meets the solid lies
// within the rectangle, which is as large as that needs and no larger. Its fragments are most
// of a tube frame's cost (a billboard a pixel wider all round, as before, made `tubes` 1.27×
// as slow on lavapipe at 1 M vertices).
#import shared/geometry.wgsl

// How far in pixels the projection of a sphere of radius `r` at view position `p` reaches from
// the projection of its centre: at most r f |p| / (d (d − r)) at depth d = −p_z > r. For a point
// p + r w of the sphere (|w| ≤ 1) the offset is f r (d w_xy + w_z p_xy) / (d (d − r w_z)), and
// |d w_xy + w_z p_xy| ≤ |w| |p| (Cauchy–Schwarz on (w_xy, w_z) and (d, |p_xy|)). On the optical
// axis r f / (d − r); off it a sphere projects to an ellipse that reaches further (|p| / d). The
// last term is f32's rounding of the projected ends (about 1e-4 px), not a margin.
fn screen_radius(p: vec3<f32>, r: f32) -> f32 {
    if is_orthographic() {
        return r * frame.f_px + ROUNDING_PX;
    }
    let d = -p.z;
    if d <= r * 1.0001 {
        return 2.0 * max(frame.viewport.x, frame.viewport.y);
    }
    return r * frame.f_px * length(p) / (d * (d - r)) + ROUNDING_PX;
}

const ROUNDING_PX: f32 = 1.0 / 64.0;

fn to_pixels(clip: vec4<f32>) -> vec2<f32> {
    return (clip.xy / clip.w * vec2<f32>(0.5, -0.5) + 0.5) * frame.viewport;
}

// The billboard of the segment between view positions `a` and `b` with radii `ra`, `rb`: its
// ends in pixels, how far it reaches beyond each (pixels), and its depth (NDC).
struct Billboard {
    pa: vec2<f32>,
    pb: vec2<f32>,
    reach_a: f32,
    reach_b: f32,
    depth: f32,
}

fn billboard(a: vec3<f32>, b: vec3<f32>, ra: f32, rb: f32) -> Billboard {
    var out: Billboard;
    out.pa = to_pixels(frame.proj * vec4<f32>(a, 1.0));
    out.pb = to_pixels(frame.proj * vec4<f32>(b, 1.0));
    out.reach_a = screen_radius(a, ra);
    out.reach_b = screen_radius(b, rb);
    // At the solid's nearest depth (the nearer end sphere's front).
    let front = min(-a.z - ra, -b.z - rb);
    let near_clip = frame.proj * vec4<f32>(0.0, 0.0, -max(front, 1e-6), 1.0);
    out.depth = clamp(near_clip.z / near_clip.w, 0.0, 1.0);
    return out;
}

// How far (back, front) in pixels along the unit screen direction `s` the projection of the
// circle where the body of the rounded cone from `a` to `b` (view positions, radii `ra`, `rb`)
// meets end a's sphere reaches from the projection of `a`; the disk's reach where one sphere
// holds the other. The body is the hull of that circle and its twin at b, so a billboard that
// leaves end a's sphere to the segment before (which holds it whole) starts this far behind a.
// The circle: centre a + u ra sin φ, radius ρ = ra cos φ, normal u (unit a → b; sin φ =
// (ra − rb) / |b − a|). A point a + δ of it projects to offset f (d δ_xy + δ_z a_xy) / (d (d − δ_z))
// from a's (d = −a_z), along s: f (δ · g) / (d (d − δ_z)) with g = (d s, s · a_xy); over the
// circle δ · g = ra sin φ (u · g) + ρ (w · g) for unit w ⊥ u, within ±ρ |g⊥u|, and |δ| ≤ ra bounds
// the denominator below by d (d − ra). Orthographic: f (δ · (s, 0)).
fn body_reach(a: vec3<f32>, b: vec3<f32>, ra: f32, rb: f32, s: vec2<f32>, disk: f32) -> vec2<f32> {
    let axis = b - a;
    let l2 = dot(axis, axis);
    let d2 = l2 - (ra - rb) * (ra - rb);
    if d2 <= 0.0 || l2 <= 0.0 {
        return vec2<f32>(disk);
    }
    let l = sqrt(l2);
    let u = axis / l;
    let sin_phi = (ra - rb) / l;
    let rho = ra * sqrt(d2) / l;
    // Screen y runs down, view y up.
    let s_view = vec2<f32>(s.x, -s.y);
    var g = vec3<f32>(s_view, 0.0);
    var scale = frame.f_px;
    if !is_orthographic() {
        let d = -a.z;
        if d <= ra * 1.0001 {
            return vec2<f32>(disk);
        }
        g = vec3<f32>(d * s_view, dot(s_view, a.xy));
        scale = frame.f_px / (d * (d - ra));
    }
    let gu = dot(g, u);
    let g_perp = sqrt(max(dot(g, g) - gu * gu, 0.0));
    let centre = ra * sin_phi * gu;
    let spread = rho * g_perp;
    let front = max(centre + spread, 0.0) * scale;
    let back = max(spread - centre, 0.0) * scale;
    return min(vec2<f32>(back, front), vec2<f32>(disk)) + ROUNDING_PX;
}

// Whether an end at view position `p` lies behind the eye: its segment draws no billboard.
fn behind_eye(p: vec3<f32>) -> bool {
    return !is_orthographic() && -p.z <= 0.0;
}
