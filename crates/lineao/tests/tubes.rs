//! The tube renderer: the rounded-cone intersection against sphere tracing of its exact
//! distance, a straight tube against an independent ray–cylinder solution, curved tubes of
//! varying radius against the nearest hit over all segments, chunking, and LineAO on tubes
//! (r0 of Eq. 16) against its CPU reference.

mod common;

use common::{Frame, cameras_for_polylines, gpu, is_geometry, polylines, polylines_with_octants, render_geometry};
use glam::{Mat4, Vec3, Vec4Swizzles};
use lineao::LineGeometry;
use lineao::passes::lines::{GeometryOptions, VertexAttributes};
use lineao::reference;
use lineao::reference::line_ao_flip_bound;
use lineao::reference::tubes::{intersect_rounded_cone, pixel_ray, rounded_cone_distance, rounded_cone_normal};
use lineao::verify::check_policy;
use lineao::{AoMethod, ChainSettings, TubeSettings};
use lineao::{Bounds, Camera, FrameView, Projection};

fn random(k: u32, stream: u32) -> f32 {
    lineao::noise::uniform(21, stream, k)
}

#[test]
fn the_intersection_agrees_with_sphere_tracing_the_exact_distance() {
    let (mut checked, mut misses) = (0, 0);
    for k in 0..4000u32 {
        let v = |s: u32| Vec3::new(random(k, s), random(k, s + 1), random(k, s + 2)) * 2.0 - 1.0;
        let (pa, pb) = (v(0) * 3.0, v(3) * 3.0);
        let (ra, rb) = (0.2 + random(k, 6), if k % 3 == 0 { 0.2 + random(k, 6) } else { 0.2 + random(k, 7) });
        let ro = v(8).normalize() * 12.0;
        // Aim near the segment so that about half the rays hit.
        let aim = pa.lerp(pb, random(k, 11)) + v(12) * 1.5;
        let rd = (aim - ro).normalize();
        let traced = {
            let mut t = 0.0f32;
            let mut hit = None;
            for _ in 0..400 {
                let d = rounded_cone_distance(ro + t * rd, pa, pb, ra, rb);
                if d < 1e-5 {
                    hit = Some(t);
                    break;
                }
                t += d;
                if t > 40.0 {
                    break;
                }
            }
            hit
        };
        let exact = intersect_rounded_cone(ro, rd, pa, pb, ra, rb).filter(|(t, _)| *t > 0.0);
        match (traced, exact) {
            (Some(t), Some((s, n))) => {
                assert!((t - s).abs() < 2e-3, "ray {k}: traced {t}, intersected {s}");
                // The normal is the distance's gradient.
                let p = ro + s * rd;
                let e = 1e-3;
                let grad = Vec3::new(
                    rounded_cone_distance(p + Vec3::X * e, pa, pb, ra, rb)
                        - rounded_cone_distance(p - Vec3::X * e, pa, pb, ra, rb),
                    rounded_cone_distance(p + Vec3::Y * e, pa, pb, ra, rb)
                        - rounded_cone_distance(p - Vec3::Y * e, pa, pb, ra, rb),
                    rounded_cone_distance(p + Vec3::Z * e, pa, pb, ra, rb)
                        - rounded_cone_distance(p - Vec3::Z * e, pa, pb, ra, rb),
                )
                .normalize();
                assert!(n.distance(grad) < 1e-2, "ray {k}: normal {n} vs gradient {grad}");
                checked += 1;
            }
            (None, None) => misses += 1,
            // A grazing ray that sphere tracing stops short of, or passes.
            (traced, exact) => {
                let closest = (0..2000)
                    .map(|i| rounded_cone_distance(ro + (i as f32 * 0.02) * rd, pa, pb, ra, rb))
                    .fold(f32::INFINITY, f32::min);
                assert!(closest.abs() < 1e-2, "ray {k}: traced {traced:?}, intersected {exact:?}, closest {closest}");
            }
        }
    }
    println!("{checked} hits and {misses} misses agree");
    assert!(checked > 1000 && misses > 1000);
}

/// Renders polylines as tubes through the chain and reads the targets back.
fn render_tubes(
    gpu: &lineao::Gpu,
    geometry: &LineGeometry,
    camera: &Camera,
    settings: ChainSettings,
    size: (u32, u32),
) -> Frame {
    render_geometry(gpu, geometry, camera, geometry.bounds.unwrap(), settings, size)
}

fn tubes(radius: f32) -> ChainSettings {
    ChainSettings { method: AoMethod::None, tubes: Some(TubeSettings { radius_world: radius }), ..Default::default() }
}

/// What a pixel should show: the nearest hit (view space) and every unit normal a surface has
/// there (several on a crease, where neighbouring segments meet at equal depth and rounding
/// decides which one a ray meets first).
struct Expected {
    point: Vec3,
    normals: Vec<Vec3>,
}

/// Per pixel: the GPU's G-buffer against `expected` (or no geometry). Errors of the f32 ray grow
/// as 1/(n·v) toward a silhouette, so the tolerances do too.
fn compare_gbuffer(name: &str, frame: &Frame, expected: impl Fn([u32; 2]) -> Option<Expected>) {
    let (mut both, mut coverage_differs, mut off) = (0, 0, 0);
    let (mut worst_depth, mut worst_d, mut worst_zoom) = (0.0f32, 0.0f32, 0.0f32);
    let (proj, inv_proj) = (frame.view.proj, frame.view.proj.inverse());
    for y in 0..frame.nd[0].height {
        for x in 0..frame.nd[0].width {
            let nd = frame.nd[0].get(x, y);
            match (is_geometry(nd), expected([x as u32, y as u32])) {
                (true, Some(Expected { point: p, normals })) => {
                    both += 1;
                    let (_, rd) = pixel_ray(&frame.view, inv_proj, [x as u32, y as u32]);
                    let n = Vec3::new(nd[0], nd[1], nd[2]);
                    let grazing = 1.0 / (-rd.dot(normals[0])).max(0.05);
                    let clip = proj * p.extend(1.0);
                    let depth = (frame.depth.get(x, y) - clip.z / clip.w).abs() / grazing;
                    let d = ((-p.z - frame.view.near) / (frame.view.far - frame.view.near)).clamp(0.0, 1.0);
                    let zoom = if frame.view.orthographic { frame.view.f_px } else { frame.view.f_px / -p.z };
                    let zoom = (frame.zoom.get(x, y) / zoom - 1.0).abs() / grazing;
                    let normal_ok = normals.iter().any(|m| m.distance(n) <= 2e-3 * grazing);
                    if !normal_ok || depth > 1e-5 || zoom > 1e-5 {
                        off += 1;
                    }
                    worst_depth = worst_depth.max(depth);
                    worst_d = worst_d.max((nd[3] - d).abs() / grazing);
                    worst_zoom = worst_zoom.max(zoom);
                }
                (false, None) => {}
                _ => coverage_differs += 1,
            }
        }
    }
    println!(
        "{name}: {both} pixels; coverage differs at {coverage_differs}, off at {off}; worst · (n·v) |Δdepth| \
         {worst_depth:.1e}, |Δd| {worst_d:.1e}, zoom relative {worst_zoom:.1e}"
    );
    assert!(both > 1500, "{name}");
    // Only rays that graze a silhouette within rounding may go either way.
    assert!(coverage_differs as f32 <= 0.002 * both as f32, "{name}: coverage differs at {coverage_differs}");
    assert!(off as f32 <= 0.001 * both as f32, "{name}: {off} pixels off");
}

#[test]
fn a_straight_tube_is_the_analytic_cylinder_with_round_ends() {
    // One tube along x, solved independently in f64: the infinite cylinder's quadratic, kept
    // between the end planes, else the end spheres.
    let gpu = gpu();
    let (a, b, r) = (Vec3::new(-20.0, 2.0, 1.0), Vec3::new(25.0, -3.0, -2.0), 4.0f32);
    let geometry = one_segment(&gpu, a, b);
    let perspective = Camera {
        eye: Vec3::new(10.0, 30.0, 80.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 50.0 },
    };
    let orthographic = Camera { projection: Projection::Orthographic { height: 70.0 }, ..perspective };
    for (name, camera) in [("perspective", perspective), ("orthographic", orthographic)] {
        let frame = render_tubes(&gpu, &geometry, &camera, tubes(r), (320, 240));
        compare_with_capsule(name, &frame, [a, b], r);
    }
}

/// The streamline of the one segment from `a` to `b`, on the GPU.
fn one_segment(gpu: &lineao::Gpu, a: Vec3, b: Vec3) -> LineGeometry {
    LineGeometry::new(&gpu.device, &gpu.queue, &[a.to_array(), b.to_array()], &[0, 2]).unwrap()
}

/// The frame against the analytic capsule of world ends `ends` and radius `r`, in f64.
fn compare_with_capsule(name: &str, frame: &Frame, ends: [Vec3; 2], r: f32) {
    let [va, vb] = ends.map(|p| (frame.view.view * p.extend(1.0)).xyz().as_dvec3());
    let inv_proj = frame.view.proj.inverse();
    compare_gbuffer(name, frame, |pixel| {
        let (o, d) = pixel_ray(&frame.view, inv_proj, pixel);
        analytic_capsule(o.as_dvec3(), d.as_dvec3(), va, vb, r as f64)
            .map(|(p, n)| Expected { point: p.as_vec3(), normals: vec![n.as_vec3()] })
    });
}

/// A short, thick tube close to the eye in a corner of a wide view, where a sphere projects to
/// its most stretched ellipse: the billboard (`shaders/shared/billboard.wgsl`, bounded with no
/// margin) still holds every pixel whose ray meets it, against the analytic capsule.
#[test]
fn a_tube_in_the_corner_of_a_wide_view_is_whole() {
    let gpu = gpu();
    let (a, b, r) = (Vec3::new(20.0, 14.0, 15.0), Vec3::new(23.0, 15.0, 13.0), 4.0f32);
    let geometry = one_segment(&gpu, a, b);
    let camera = Camera {
        eye: Vec3::new(0.0, 0.0, 30.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 100.0 },
    };
    let frame =
        render_geometry(&gpu, &geometry, &camera, Bounds { center: Vec3::ZERO, radius: 40.0 }, tubes(r), (320, 240));
    let va = (frame.view.view * a.extend(1.0)).xyz();
    assert!(va.x / -va.z > 1.2 && va.y / -va.z > 0.8, "in the view's corner: {va}");
    compare_with_capsule("corner", &frame, [a, b], r);
}

/// Ray o + t d (unit d) against the capsule of [a, b] with radius r: first hit and normal.
fn analytic_capsule(
    o: glam::DVec3,
    d: glam::DVec3,
    a: glam::DVec3,
    b: glam::DVec3,
    r: f64,
) -> Option<(glam::DVec3, glam::DVec3)> {
    let length = a.distance(b);
    let u = (b - a) / length;
    let mut best: Option<f64> = None;
    let mut consider = |t: f64| {
        if t > 0.0 && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    };
    // |(o + t d − a) − ((o + t d − a)·u) u|² = r²
    let (w, dp) = (o - a - (o - a).dot(u) * u, d - d.dot(u) * u);
    let (qa, qb, qc) = (dp.dot(dp), 2.0 * w.dot(dp), w.dot(w) - r * r);
    let disc = qb * qb - 4.0 * qa * qc;
    if disc >= 0.0 && qa > 0.0 {
        let t = (-qb - disc.sqrt()) / (2.0 * qa);
        let along = (o + t * d - a).dot(u);
        if (0.0..=length).contains(&along) {
            consider(t);
        }
    }
    for c in [a, b] {
        let oc = o - c;
        let (hb, hc) = (oc.dot(d), oc.dot(oc) - r * r);
        if hb * hb - hc >= 0.0 {
            consider(-hb - (hb * hb - hc).sqrt());
        }
    }
    best.map(|t| {
        let p = o + t * d;
        let foot = a + (p - a).dot(u).clamp(0.0, length) * u;
        (p, (p - foot).normalize())
    })
}

/// Per pixel, the nearest hit over every segment of `positions`/`offsets` (radii per vertex),
/// by brute force over the segments whose screen box holds the pixel, with the normal of every
/// segment whose surface passes within 1e-3 world units of it (rounding of a ray near a crease
/// moves the first hit about that far).
fn nearest_hits(view: &FrameView, positions: &[[f32; 3]], offsets: &[u64], radii: &[f32]) -> Vec<Option<Expected>> {
    let (w, h) = view.banded_size();
    let inv_proj: Mat4 = view.proj.inverse();
    let to_view = |i: usize| (view.view * Vec3::from_array(positions[i]).extend(1.0)).xyz();
    let segments: Vec<(Vec3, Vec3, f32, f32)> = offsets
        .windows(2)
        .flat_map(|pair| {
            (pair[0] as usize..pair[1] as usize - 1).map(|i| (to_view(i), to_view(i + 1), radii[i], radii[i + 1]))
        })
        .collect();
    let mut hits: Vec<Vec<(f32, Vec3, usize)>> = vec![Vec::new(); (w * h) as usize];
    for (k, &(a, b, ra, rb)) in segments.iter().enumerate() {
        // A generous screen box: the projected corners of the segment's bounding box.
        let r = ra.max(rb);
        let (lo, hi) = (a.min(b) - r, a.max(b) + r);
        let (mut min, mut max) = (glam::Vec2::splat(f32::INFINITY), glam::Vec2::splat(f32::NEG_INFINITY));
        for c in 0..8 {
            let corner = Vec3::new([lo.x, hi.x][c & 1], [lo.y, hi.y][c >> 1 & 1], [lo.z, hi.z][c >> 2]);
            let clip = view.proj * corner.extend(1.0);
            let px = (clip.xy() / clip.w * glam::Vec2::new(0.5, -0.5) + 0.5) * glam::Vec2::new(w as f32, h as f32);
            (min, max) = (min.min(px), max.max(px));
        }
        let (x0, x1) = ((min.x - 2.0).max(0.0) as u32, (max.x + 2.0).min(w as f32 - 1.0).max(0.0) as u32);
        let (y0, y1) = ((min.y - 2.0).max(0.0) as u32, (max.y + 2.0).min(h as f32 - 1.0).max(0.0) as u32);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (o, d) = pixel_ray(view, inv_proj, [x, y]);
                if let Some((t, _)) = intersect_rounded_cone(o, d, a, b, ra, rb).filter(|(t, _)| *t > 0.0) {
                    hits[(y * w + x) as usize].push((t, o + t * d, k));
                }
            }
        }
    }
    hits.into_iter()
        .map(|hits| {
            let &(_, point, first) = hits.iter().min_by(|a, b| a.0.total_cmp(&b.0))?;
            let (a, b, ra, rb) = segments[first];
            let mut normals = vec![rounded_cone_normal(point, a, b, ra, rb)];
            for &(a, b, ra, rb) in &segments {
                if rounded_cone_distance(point, a, b, ra, rb).abs() < 1e-3 {
                    normals.push(rounded_cone_normal(point, a, b, ra, rb));
                }
            }
            Some(Expected { point, normals })
        })
        .collect()
}

#[test]
fn curved_tubes_of_varying_radius_are_the_union_of_their_segments() {
    let gpu = gpu();
    let (positions, offsets) = polylines(16, 0.7);
    // Radii swelling and shrinking along each polyline, 1.2 to 3.2 world units.
    let radii: Vec<f32> = (0..positions.len()).map(|i| 2.2 + (i as f32 * 0.21).sin()).collect();
    let (perspective, orthographic) = cameras_for_polylines();
    for (name, camera, varying) in [
        ("perspective, one radius", perspective, false),
        ("perspective, per-vertex radii", perspective, true),
        ("orthographic, per-vertex radii", orthographic, true),
    ] {
        let mut geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
        // The radii as the geometry stores them (f16), which the shader reads.
        let stored: Vec<f32> = radii.iter().map(|&r| lineao::passes::lines::stored_radius(r)).collect();
        let used: Vec<f32> = if varying { stored } else { vec![1.5; positions.len()] };
        if varying {
            let attributes = VertexAttributes { radius: Some(&radii), ..Default::default() };
            geometry.set_attributes(&gpu.device, &gpu.queue, &attributes).unwrap();
        }
        let frame = render_tubes(&gpu, &geometry, &camera, tubes(1.5), (240, 180));
        let hits = nearest_hits(&frame.view, &positions, &offsets, &used);
        let width = frame.nd[0].width;
        compare_gbuffer(name, &frame, |[x, y]| {
            hits[y as usize * width + x as usize]
                .as_ref()
                .map(|e| Expected { point: e.point, normals: e.normals.clone() })
        });
    }
}

#[test]
fn paged_tubes_render_the_same() {
    let gpu = gpu();
    let (positions, offsets) = polylines(30, 0.2);
    let whole = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    // Pages of 96 points: each holds a few whole polylines.
    let options = GeometryOptions { page_bytes: 96 * 8, ..Default::default() };
    let chunked = LineGeometry::with_options(&gpu.device, &gpu.queue, &positions, &offsets, options).unwrap();
    assert!(chunked.page_count() > 10, "{} pages", chunked.page_count());
    let (camera, _) = cameras_for_polylines();
    // Drawn whole, in page order: the culled draw lists its pieces in the order the cull's
    // invocations append them, so where two segments tie in depth at a joint either may win
    // (tests/cull.rs holds the culled tubes to every tube, ties counted).
    let settings = ChainSettings { cull: false, ..tubes(1.0) };
    let a = render_tubes(&gpu, &whole, &camera, settings.clone(), (160, 120));
    let b = render_tubes(&gpu, &chunked, &camera, settings, (160, 120));
    assert_eq!(a.nd, b.nd);
    assert_eq!(a.depth, b.depth);
}

#[test]
fn lineao_on_tubes_takes_r0_from_the_zoom_and_matches_its_cpu_reference() {
    let gpu = gpu();
    let (positions, offsets) = polylines(60, 0.4);
    let (perspective, orthographic) = cameras_for_polylines();
    let s = ChainSettings { tubes: Some(TubeSettings { radius_world: 0.8 }), ..ChainSettings::default() };
    // Eq. 16: r0 = 1.5 · z(P) · t_s, t_s = 2 · 0.8 zoom units.
    assert_eq!(s.r0(), lineao::R0 { px: 0.0, per_zoom: 1.5 * 1.6 });
    for (name, camera) in [("perspective", perspective), ("orthographic", orthographic)] {
        let frame = common::render(&gpu, &positions, &offsets, &camera, None, s.clone(), (240, 180));
        let cpu = reference::line_ao(
            &frame.nd,
            &frame.zoom,
            &lineao::noise::noise_tile(1),
            &lineao::method::line_ao::sample_table(&s.line_ao),
            &reference::LineAoParams::new(&s, &frame.view),
        );
        let stats = check_policy(&frame.ao, &cpu, &frame.nd[0], line_ao_flip_bound(3, 32))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name}: {stats}");
        assert!(frame.ao.data.iter().filter(|&&a| a > 0.05).count() > 300, "{name}: tubes occlude each other");
    }
}

#[test]
fn tubes_carry_the_octant_visibilities_to_object_space_ao() {
    let gpu = gpu();
    let c = 102.0 / 255.0;
    let geometry = polylines_with_octants(&gpu, 20, 0.5, c);
    let (camera, _) = cameras_for_polylines();
    let settings = ChainSettings { volume: Some(Default::default()), ..tubes(1.2) };
    let frame = render_tubes(&gpu, &geometry, &camera, settings, (160, 120));
    let (nd, packed, volume_ao) = (&frame.nd[0], frame.octants.unwrap(), frame.volume_ao.unwrap());
    let mut pixels = 0;
    for i in (0..nd.data.len()).filter(|&i| is_geometry(nd.data[i])) {
        assert_eq!(reference::unpack_octants(packed.data[i]), [c; 8]);
        assert!((volume_ao.data[i] - (1.0 - c)).abs() < 1e-5);
        pixels += 1;
    }
    assert!(pixels > 2000, "{pixels}");
}
