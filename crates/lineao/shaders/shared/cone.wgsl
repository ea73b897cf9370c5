// The ray ro + t rd (|rd| = 1) against the rounded cone between spheres (pa, ra) and (pb, rb):
// the terms of the body's quadratic k2 t² + 2 k1 t + k0 = 0 (h its discriminant; squaring
// admits the mirrored cone beyond the apex, so a root t is the body's where
// 0 < y < d2, y = m1 − ra rr + t m2) and of the end spheres' t² + 2 m3 t + m5 − ra² = 0 and
// t² + 2 m6 t + m7 − rb² = 0. Derived in `lineao::reference::tubes::intersect_rounded_cone`;
// the tube renderer (first hit and normal) and the ray tracer (nearest hit in an interval)
// take their roots from here.
struct ConeTerms {
    ba: vec3<f32>,
    oa: vec3<f32>,
    ob: vec3<f32>,
    rr: f32,
    m1: f32,
    m2: f32,
    m3: f32,
    m5: f32,
    m6: f32,
    m7: f32,
    d2: f32,
    k0: f32,
    k1: f32,
    k2: f32,
    h: f32,
}

fn cone_terms(ro: vec3<f32>, rd: vec3<f32>, pa: vec3<f32>, pb: vec3<f32>, ra: f32, rb: f32) -> ConeTerms {
    var c: ConeTerms;
    c.ba = pb - pa;
    c.oa = ro - pa;
    c.ob = ro - pb;
    c.rr = ra - rb;
    let m0 = dot(c.ba, c.ba);
    c.m1 = dot(c.ba, c.oa);
    c.m2 = dot(c.ba, rd);
    c.m3 = dot(rd, c.oa);
    c.m5 = dot(c.oa, c.oa);
    c.m6 = dot(c.ob, rd);
    c.m7 = dot(c.ob, c.ob);
    c.d2 = m0 - c.rr * c.rr;
    c.k2 = c.d2 - c.m2 * c.m2;
    c.k1 = c.d2 * c.m3 - c.m1 * c.m2 + c.m2 * c.rr * ra;
    c.k0 = c.d2 * c.m5 - c.m1 * c.m1 + c.m1 * c.rr * ra * 2.0 - m0 * ra * ra;
    c.h = c.k1 * c.k1 - c.k0 * c.k2;
    return c;
}
