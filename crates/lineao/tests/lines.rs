//! The line renderer against the G-buffer contract (docs/reference.md), with expected values worked
//! out here from the camera and the line: width in pixels, gap-free joins, separate streamlines,
//! normals, normalized depth, zoom, hardware depth, colors, specular, chunked buffers.

mod common;

use common::{Frame, gpu, is_geometry, render};
use glam::Vec3;
use lineao::FrameView;
use lineao::LineGeometry;
use lineao::lighting::{LightingShape, LineShading, illuminated_line};
use lineao::passes::lines::{GeometryOptions, LineRenderer, LineStyle};
use lineao::targets::FrameTargets;
use lineao::{AoMethod, ChainSettings, LineColor};
use lineao::{Bounds, Camera, Projection};

const SIZE: (u32, u32) = (200, 100);

fn camera(projection: Projection) -> Camera {
    Camera { eye: Vec3::new(0.0, 0.0, 100.0), target: Vec3::ZERO, up: Vec3::Y, projection }
}

fn perspective() -> Camera {
    camera(Projection::Perspective { fov_y_deg: 40.0 })
}

/// near = 50, far = 150 for the cameras above.
fn bounds() -> Option<Bounds> {
    Some(Bounds { center: Vec3::ZERO, radius: 50.0 })
}

fn plain(line_width_px: f32) -> ChainSettings {
    ChainSettings { method: AoMethod::None, line_width_px, ..ChainSettings::default() }
}

fn lines(gpu: &lineao::Gpu, polylines: &[&[[f32; 3]]], cam: &Camera, settings: ChainSettings) -> Frame {
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    for line in polylines {
        positions.extend_from_slice(line);
        offsets.push(positions.len() as u64);
    }
    render(gpu, &positions, &offsets, cam, bounds(), settings, SIZE)
}

/// The pixel (column, row) a world point projects to.
fn project(frame: &Frame, p: Vec3) -> (f32, f32) {
    let c = frame.view.proj.project_point3(frame.view.view.transform_point3(p));
    let (w, h) = frame.view.banded_size();
    ((c.x + 1.0) * 0.5 * w as f32, (1.0 - c.y) * 0.5 * h as f32)
}

#[test]
fn lines_are_exactly_their_width_in_pixels() {
    let gpu = gpu();
    for width in [1u32, 3, 4] {
        let frame = lines(&gpu, &[&[[-40.0, 0.0, 0.0], [40.0, 0.0, 0.0]]], &perspective(), plain(width as f32));
        // The line projects to the boundary between rows 49 and 50; columns 60..140 are well inside.
        for x in 60..140 {
            let covered = (0..SIZE.1 as usize).filter(|&y| is_geometry(frame.nd[0].get(x, y))).count();
            assert_eq!(covered, width as usize, "column {x} at width {width}");
        }
    }
}

/// 8-connected components of the covered pixels.
fn components(frame: &Frame) -> usize {
    let (w, h) = (frame.nd[0].width, frame.nd[0].height);
    let mut seen = vec![false; w * h];
    let mut count = 0;
    for start in 0..w * h {
        if seen[start] || !is_geometry(frame.nd[0].data[start]) {
            continue;
        }
        count += 1;
        let mut stack = vec![start];
        seen[start] = true;
        while let Some(i) = stack.pop() {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if !seen[j] && is_geometry(frame.nd[0].data[j]) {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
    }
    count
}

#[test]
fn joins_have_no_gaps_and_streamlines_stay_apart() {
    let gpu = gpu();
    // Hairpin turns of up to 135°, with depth changes, stay one connected line. (Corners are
    // offset along the vertex tangent, so a hairpin's outer tip is bevelled, never broken.)
    let zigzag: Vec<[f32; 3]> = (0..9)
        .map(|k| [-40.0 + 10.0 * k as f32, if k % 2 == 0 { -12.0 } else { 12.0 }, (k % 3) as f32 * 4.0])
        .collect();
    let frame = lines(&gpu, &[&zigzag], &perspective(), plain(3.0));
    assert_eq!(components(&frame), 1, "the zigzag broke apart");
    // Turns of 45° (sharper than tractography's usual angle thresholds): every pixel the centre
    // line passes through is covered, joins included.
    let mut polyline = vec![[-40.0f32, -20.0, 0.0]];
    let mut direction = 0.0f32;
    for k in 0..8 {
        direction += if k % 4 < 2 { 45f32.to_radians() } else { -45f32.to_radians() };
        let last = polyline[polyline.len() - 1];
        polyline.push([last[0] + 9.0 * direction.cos(), last[1] + 9.0 * direction.sin(), last[2] + 2.0]);
    }
    let frame = lines(&gpu, &[&polyline], &perspective(), plain(3.0));
    assert_eq!(components(&frame), 1);
    for pair in polyline.windows(2) {
        let (p0, p1) = (Vec3::from_array(pair[0]), Vec3::from_array(pair[1]));
        for k in 0..=200 {
            let (x, y) = project(&frame, p0.lerp(p1, k as f32 / 200.0));
            let (x, y) = (x.floor() as usize, y.floor() as usize);
            assert!(is_geometry(frame.nd[0].get(x, y)), "gap at pixel ({x}, {y}) between {p0} and {p1}");
        }
    }
    // Two streamlines: no segment joins the end of `a` to the start of `b`.
    let a = [[-40.0, 25.0, 0.0], [-6.0, 25.0, 0.0]];
    let b = [[6.0, -25.0, 0.0], [40.0, -25.0, 0.0]];
    let frame = lines(&gpu, &[&a, &b], &perspective(), plain(3.0));
    assert_eq!(components(&frame), 2);
    let (x, y) = project(&frame, Vec3::ZERO);
    assert!(!is_geometry(frame.nd[0].get(x as usize, y as usize)));
}

#[test]
fn normals_depth_zoom_and_hardware_depth_follow_the_contract() {
    let gpu = gpu();
    let (p0, p1) = (Vec3::new(-30.0, 5.0, -40.0), Vec3::new(30.0, -5.0, 40.0));
    let frame = lines(&gpu, &[&[p0.to_array(), p1.to_array()]], &perspective(), plain(3.0));
    let v = &frame.view;
    assert_eq!((v.near, v.far), (50.0, 150.0));
    let tangent = (p1 - p0).normalize(); // world = view rotation here (camera looks down −z)
    let mut checked = 0;
    for y in 0..SIZE.1 as usize {
        for x in 0..SIZE.0 as usize {
            let nd = frame.nd[0].get(x, y);
            if !is_geometry(nd) {
                assert_eq!(nd, [0.0, 0.0, 0.0, 1.0]);
                assert_eq!(frame.zoom.get(x, y), 0.0);
                assert_eq!(frame.depth.get(x, y), 1.0);
                continue;
            }
            checked += 1;
            // Depth → the point of the line at that view depth, which must project onto this pixel
            // (within half the line width: the quad is pushed sideways from the centre line).
            let depth = v.near + nd[3] * (v.far - v.near);
            let t = ((100.0 - depth) - p0.z) / (p1.z - p0.z);
            let p = p0.lerp(p1, t);
            let (px, py) = project(&frame, p);
            let distance = ((px - x as f32 - 0.5).powi(2) + (py - y as f32 - 0.5).powi(2)).sqrt();
            assert!(distance < 2.2, "pixel ({x}, {y}): depth {depth} puts the line {distance} px away");
            // n = normalize((T × C) × T), C = −p in view space.
            let c = -(p - Vec3::new(0.0, 0.0, 100.0));
            let expected = (c - c.dot(tangent) * tangent).normalize();
            let n = Vec3::new(nd[0], nd[1], nd[2]);
            assert!((n.length() - 1.0).abs() < 1e-4 && n.dot(c) > 0.0);
            assert!(n.distance(expected) < 5e-3, "pixel ({x}, {y}): n {n} expected {expected}");
            // z(P) = f_px · zoom_unit / (−z_view), f_px = proj[1][1] · H / 2.
            let f_px = 1.0 / (20f32.to_radians().tan()) * SIZE.1 as f32 / 2.0;
            let zoom = frame.zoom.get(x, y);
            assert!((zoom - f_px / depth).abs() < 1e-4 * zoom, "zoom {zoom} vs {}", f_px / depth);
            // Hardware depth is the projection's z/w of the same point.
            let clip = v.proj * v.view.extend_point(p);
            let hw = clip.z / clip.w;
            assert!((frame.depth.get(x, y) - hw).abs() < 2e-5, "hardware depth {} vs {hw}", frame.depth.get(x, y));
        }
    }
    assert!(checked > 150, "only {checked} line pixels");
}

trait ExtendPoint {
    fn extend_point(&self, p: Vec3) -> glam::Vec4;
}
impl ExtendPoint for glam::Mat4 {
    fn extend_point(&self, p: Vec3) -> glam::Vec4 {
        *self * p.extend(1.0)
    }
}

#[test]
fn orthographic_zoom_is_constant_and_depth_is_linear() {
    let gpu = gpu();
    let cam = camera(Projection::Orthographic { height: 80.0 });
    let settings = ChainSettings { zoom_unit: 2.0, ..plain(2.0) };
    let frame = lines(&gpu, &[&[[-40.0, 0.0, 10.0], [40.0, 0.0, 10.0]]], &cam, settings);
    let pixels: Vec<_> = frame.nd[0].data.iter().zip(&frame.zoom.data).filter(|(nd, _)| is_geometry(**nd)).collect();
    assert!(pixels.len() > 100);
    for (nd, zoom) in pixels {
        // f_px = H / height = 100 / 80 px per world unit; zoom_unit 2 → 2.5 px.
        assert!((zoom - 2.5).abs() < 1e-5, "{zoom}");
        // −z_view = 90 → (90 − 50) / 100.
        assert!((nd[3] - 0.4).abs() < 1e-5, "{}", nd[3]);
        assert!(Vec3::new(nd[0], nd[1], nd[2]).distance(Vec3::Z) < 1e-4);
    }
}

#[test]
fn colors_and_specular() {
    let gpu = gpu();
    let s2 = std::f32::consts::FRAC_1_SQRT_2;
    let diagonal: &[[f32; 3]] = &[[-30.0, -30.0, 0.0], [30.0, 30.0, 0.0]];
    for shading in [LineShading::Specular, LineShading::CylinderAveraged] {
        let mut settings = plain(3.0);
        settings.lighting.line_shading = shading;
        let frame = lines(&gpu, &[diagonal], &perspective(), settings);
        let mut checked = 0;
        for (i, nd) in frame.nd[0].data.iter().enumerate() {
            let (x, y) = (i % SIZE.0 as usize, i / SIZE.0 as usize);
            let color = frame.color.data[i];
            if !is_geometry(*nd) {
                assert_eq!(color, [1.0, 1.0, 1.0, 1.0], "background color at ({x}, {y})");
                assert_eq!(frame.specular.data[i], 0.0);
                continue;
            }
            checked += 1;
            // V toward the eye from the pixel's view position; T and L as given.
            let depth = frame.view.near + nd[3] * (frame.view.far - frame.view.near);
            let (px, py) = (x as f32 + 0.5 - 100.0, 50.0 - (y as f32 + 0.5));
            let f_px = 50.0 / 20f32.to_radians().tan();
            let p = Vec3::new(px / f_px * depth, py / f_px * depth, -depth);
            let t = Vec3::new(s2, s2, 0.0);
            let (v, l) = (-p.normalize(), Vec3::new(-0.4, 0.6, 0.7).normalize());
            // Specular: Zöckler's ks · (√(1−(L·T)²)·√(1−(V·T)²) − (L·T)(V·T))^α, worked out here;
            // cylinder-averaged: the library's closed form (checked against quadrature below).
            let (lt, vt) = (l.dot(t), v.dot(t));
            let zoeckler = ((1.0 - lt * lt).sqrt() * (1.0 - vt * vt).sqrt() - lt * vt).max(0.0).powf(32.0);
            let (diffuse, specular) = match shading {
                LineShading::Specular => (None, zoeckler),
                LineShading::CylinderAveraged => {
                    let (d, s) = illuminated_line(shading, l, v, t, 32.0);
                    assert!(s <= zoeckler + 1e-6, "the average never exceeds the maximum");
                    (Some(d), s)
                }
            };
            let expected = 0.4 * specular;
            assert!(
                (frame.specular.data[i] - expected).abs() < 2e-3,
                "{shading:?} ({x}, {y}): {} vs {expected}",
                frame.specular.data[i]
            );
            // |T| as RGB (x and y of a 45° tangent), times 1 − kd + kd · diffuse when averaged.
            let shade = diffuse.map_or(1.0, |d| 1.0 - 0.3 + 0.3 * d);
            let want = [s2 * shade, s2 * shade, 0.0];
            assert!((0..3).all(|c| (color[c] - want[c]).abs() < 2e-3), "{shading:?}: {color:?} vs {want:?}");
        }
        assert!(checked > 100);
    }
    let constant = ChainSettings { line_color: LineColor::Constant([0.2, 0.4, 0.6]), ..plain(3.0) };
    let frame = lines(&gpu, &[diagonal], &perspective(), constant);
    let line_colors: Vec<_> =
        frame.color.data.iter().zip(&frame.nd[0].data).filter(|(_, nd)| is_geometry(**nd)).collect();
    // The color target holds half floats: within one ulp (2⁻¹⁰ relative; lavapipe truncates).
    let close = |c: [f32; 3]| c.iter().zip([0.2, 0.4, 0.6]).all(|(a, b)| (a - b).abs() <= b * 2f32.powi(-10));
    assert!(line_colors.iter().all(|(c, _)| close(c.xyz())), "{:?}", line_colors.first());
}

trait Rgb {
    fn xyz(&self) -> [f32; 3];
}
impl Rgb for [f32; 4] {
    fn xyz(&self) -> [f32; 3] {
        [self[0], self[1], self[2]]
    }
}

/// `count` wavy streamlines of `points` points each across x = ±45.
fn waves(count: usize, points: usize) -> (Vec<[f32; 3]>, Vec<u64>) {
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    for k in 0..count {
        let phase = k as f32 * 0.37;
        positions.extend((0..points).map(|i| {
            let s = i as f32 / (points - 1) as f32;
            [-45.0 + 90.0 * s, 30.0 * (phase + 4.0 * s).sin(), 20.0 * (phase * 2.0 + 3.0 * s).cos()]
        }));
        offsets.push(positions.len() as u64);
    }
    (positions, offsets)
}

#[test]
fn pages_render_identically() {
    let gpu = gpu();
    let (positions, offsets) = waves(40, 30);
    let whole = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    // Pages of 64 points hold two streamlines of 30 each.
    let options = GeometryOptions { page_bytes: 64 * 8, ..Default::default() };
    let chunked = LineGeometry::with_options(&gpu.device, &gpu.queue, &positions, &offsets, options).unwrap();
    assert_eq!((whole.page_count(), chunked.page_count()), (1, 20));
    let cam = perspective();
    let a = common::render_geometry(&gpu, &whole, &cam, bounds().unwrap(), plain(2.0), SIZE);
    let b = common::render_geometry(&gpu, &chunked, &cam, bounds().unwrap(), plain(2.0), SIZE);
    let differ = |x: &lineao::reference::NdImage, y: &lineao::reference::NdImage| {
        x.data.iter().zip(&y.data).filter(|(p, q)| p != q).count()
    };
    assert_eq!((differ(&a.nd[0], &b.nd[0]), differ(&a.color, &b.color)), (0, 0), "pixels that differ (ND, color)");
}

#[test]
fn bad_offsets_are_clear_errors() {
    let gpu = gpu();
    let p = [[0.0f32; 3]; 4];
    for (offsets, needle) in
        [(&[][..], "none"), (&[1, 4][..], "start at 0"), (&[0, 3][..], "end at"), (&[0, 3, 2, 4][..], "decrease")]
    {
        let error = LineGeometry::new(&gpu.device, &gpu.queue, &p, offsets).err().expect("an error").to_string();
        assert!(error.contains(needle), "{error}");
    }
}

#[test]
fn native_lines_are_one_pixel() {
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let positions = [[-40.0, 0.0, 0.0], [40.0, 0.0, 0.0], [-40.0, 20.0, 0.0], [0.0, 20.0, 0.0], [40.0, 20.0, 0.0]];
    let offsets = [0, 2, 5];
    let view = FrameView::new(&perspective(), &bounds().unwrap(), SIZE.0, SIZE.1, 0, 1.0);
    let targets = FrameTargets::new(d, SIZE.0, SIZE.1, 0, 1);
    let renderer = LineRenderer::with_style(d, LineStyle::Native1px);
    let s = plain(4.0);
    renderer.prepare(q, &view, s.line_width_px, s.line_color, &s.lighting, None);
    let covered = || {
        let geometry = LineGeometry::new(d, q, &positions, &offsets).unwrap();
        let mut encoder = d.create_command_encoder(&Default::default());
        renderer.encode(&mut encoder, &targets, &geometry, lineao::passes::Load::Clear(s.background), None);
        q.submit([encoder.finish()]);
        let nd = lineao::readback::read_rgba(d, q, &targets.nd[0]).unwrap();
        (60..140).map(|x| (0..SIZE.1 as usize).filter(|&y| is_geometry(nd.get(x, y))).count()).collect::<Vec<_>>()
    };
    // Two horizontal polylines, one pixel high each whatever the line width.
    assert!(covered().iter().all(|&n| n == 2), "{:?}", covered());
}

#[test]
fn scalar_colors_follow_the_colormap_table() {
    // Parallel lines with constant scalars −5, 5, 10, 15 and 40 over the range [0, 20]: each
    // shows the table's color at clamp(t) (the shader interpolates the 16 entries linearly),
    // for lines and for tubes.
    let gpu = gpu();
    let scalars = [-5.0f32, 5.0, 10.0, 15.0, 40.0];
    let mut positions = Vec::new();
    let mut offsets = vec![0u64];
    for (k, _) in scalars.iter().enumerate() {
        let y = -20.0 + 10.0 * k as f32;
        positions.extend([[-30.0, y, 0.0], [30.0, y, 0.0]]);
        offsets.push(positions.len() as u64);
    }
    let per_vertex: Vec<f32> = scalars.iter().flat_map(|&s| [s, s]).collect();
    let mut geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let attributes = lineao::passes::lines::VertexAttributes { scalar: Some(&per_vertex), ..Default::default() };
    geometry.set_attributes(&gpu.device, &gpu.queue, &attributes).unwrap();
    let table = lineao::Colormap::Viridis.table();
    let expected = |s: f32| {
        let x = (s / 20.0).clamp(0.0, 1.0) * 15.0;
        let k = (x as usize).min(14);
        let f = x - k as f32;
        [0, 1, 2].map(|c| table[k][c] * (1.0 - f) + table[k + 1][c] * f)
    };
    let color = LineColor::Scalar { colormap: lineao::Colormap::Viridis, range: [0.0, 20.0] };
    for tubes in [false, true] {
        let settings = ChainSettings {
            line_color: color,
            tubes: tubes.then_some(lineao::TubeSettings { radius_world: 2.0 }),
            lighting: lineao::lighting::Lighting { lights: vec![], ..Default::default() },
            ..plain(5.0)
        };
        let frame = common::render_geometry(&gpu, &geometry, &perspective(), geometry.bounds.unwrap(), settings, SIZE);
        let mut seen = [0usize; 5];
        for (i, nd) in frame.nd[0].data.iter().enumerate() {
            if !is_geometry(*nd) {
                continue;
            }
            let c = frame.color.data[i];
            // Which line: the one whose expected color this pixel shows (tubes darken theirs by
            // the diffuse term without lights: 1 − kd).
            let shade = if tubes { 0.7 } else { 1.0 };
            let k = (0..5)
                .find(|&k| (0..3).all(|ch| (c[ch] - shade * expected(scalars[k])[ch]).abs() < 2e-3))
                .unwrap_or_else(|| panic!("tubes {tubes}: pixel {i} color {c:?} is no line's"));
            seen[k] += 1;
        }
        // Every line shows; −5 and 0, 20 and 40 clamp to the ends.
        assert!(seen.iter().all(|&n| n > 20), "tubes {tubes}: {seen:?}");
    }
}

/// Mallo et al.'s average over the visible half cylinder by quadrature (20 000 midpoints): N(θ)
/// around `t` from V⊥, weighted by N·V⊥; the Phong specular only where N·L > 0.
fn cylinder_quadrature(l: Vec3, v: Vec3, t: Vec3, n: f32) -> (f64, f64) {
    let e1 = (v - v.dot(t) * t).normalize();
    let e2 = t.cross(e1);
    let steps = 20_000;
    let (mut weight, mut diffuse, mut specular) = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..steps {
        let theta = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * (k as f64 + 0.5) / steps as f64;
        let normal = e1 * theta.cos() as f32 + e2 * theta.sin() as f32;
        let w = theta.cos();
        let n_l = normal.dot(l) as f64;
        let r = 2.0 * normal.dot(l) * normal - l;
        weight += w;
        diffuse += w * n_l.max(0.0);
        if n_l > 0.0 {
            specular += w * (r.dot(v) as f64).max(0.0).powf(n as f64);
        }
    }
    (diffuse / weight, specular / weight)
}

#[test]
fn cylinder_averaged_lighting_matches_quadrature() {
    // Directions spread over the sphere (a Fibonacci lattice), every triple of some of them.
    let dirs: Vec<Vec3> = (0..24)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / 24.0;
            let phi = k as f32 * 2.399_963;
            Vec3::new((1.0 - z * z).sqrt() * phi.cos(), (1.0 - z * z).sqrt() * phi.sin(), z)
        })
        .collect();
    let (mut worst_diffuse, mut worst_specular) = (0.0f64, 0.0f64);
    for (i, &t) in dirs.iter().enumerate().step_by(3) {
        for &l in &dirs {
            for &v in dirs.iter().skip(i % 2).step_by(2) {
                // Viewed end-on the visible half is ill-defined (and covers no pixels); lit along
                // the line, N·L = 0 everywhere and the lit arc is degenerate.
                if v.dot(t).abs() > 0.98 || l.dot(t).abs() > 0.999 {
                    continue;
                }
                for n in [8.0, 32.0] {
                    let (d, s) = illuminated_line(LineShading::CylinderAveraged, l, v, t, n);
                    let (qd, qs) = cylinder_quadrature(l, v, t, n);
                    worst_diffuse = worst_diffuse.max((d as f64 - qd).abs());
                    if (s as f64 - qs).abs() > 1e-3 {
                        let (lp, vp) = (l - l.dot(t) * t, v - v.dot(t) * t);
                        eprintln!(
                            "n {n} a {:.3} b {:.3} cos_alpha {:.3} lt {:.3} vt {:.3}: {s:.5} vs {qs:.5}",
                            lp.length(),
                            vp.length(),
                            lp.normalize().dot(vp.normalize()),
                            l.dot(t),
                            v.dot(t)
                        );
                    }
                    worst_specular = worst_specular.max((s as f64 - qs).abs());
                }
            }
        }
    }
    eprintln!("worst |Δ| against quadrature: diffuse {worst_diffuse:.2e}, specular {worst_specular:.2e}");
    assert!(worst_diffuse < 1e-5, "the diffuse average is exact: {worst_diffuse}");
    assert!(worst_specular < 2e-5, "Gauss–Legendre around the highlight: {worst_specular}");
}

/// Dense smooth streamlines (the case the alternating strip is for: 1 000 points each) and
/// coarse ones with sharp corners, crossing, in front of the perspective camera.
fn dense_and_coarse() -> (Vec<[f32; 3]>, Vec<u64>) {
    let (mut positions, mut offsets) = waves(60, 1000);
    for k in 0..6 {
        let y = -30.0 + 12.0 * k as f32;
        positions.extend((0..9).map(|i| [-40.0 + 10.0 * i as f32, y + 8.0 * (i % 2) as f32, 10.0 - 3.0 * k as f32]));
        offsets.push(positions.len() as u64);
    }
    (positions, offsets)
}

/// The G-buffer's ND map of `geometry` drawn by `style` for `cam`, and whether it alternated.
fn draw(
    gpu: &lineao::Gpu,
    geometry: &LineGeometry,
    style: LineStyle,
    cam: &Camera,
) -> (lineao::reference::NdImage, bool) {
    let (d, q) = (&gpu.device, &gpu.queue);
    let view = FrameView::new(cam, &bounds().unwrap(), SIZE.0, SIZE.1, 0, 1.0);
    let targets = FrameTargets::new(d, SIZE.0, SIZE.1, 0, 1);
    let renderer = LineRenderer::with_style(d, style);
    let s = plain(2.0);
    renderer.prepare(q, &view, s.line_width_px, s.line_color, &s.lighting, None);
    let mut encoder = d.create_command_encoder(&Default::default());
    renderer.encode(&mut encoder, &targets, geometry, lineao::passes::Load::Clear(s.background), None);
    q.submit([encoder.finish()]);
    (lineao::readback::read_rgba(d, q, &targets.nd[0]).unwrap(), renderer.alternates(geometry))
}

#[test]
fn the_alternating_strip_stays_within_half_a_pixel_of_the_full_strip() {
    let gpu = gpu();
    let (positions, offsets) = dense_and_coarse();
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let (full, _) = draw(&gpu, &geometry, LineStyle::FullStrip, &perspective());
    // Also in pages of two streamlines.
    let options = GeometryOptions { page_bytes: 2000 * 8, ..Default::default() };
    let chunked = LineGeometry::with_options(&gpu.device, &gpu.queue, &positions, &offsets, options).unwrap();
    assert_eq!(chunked.page_count(), 31);
    for geometry in [&geometry, &chunked] {
        let (alternating, alternated) = draw(&gpu, geometry, LineStyle::Quads, &perspective());
        assert!(alternated, "this view is far enough for the alternating strip");
        within_a_pixel(&full, &alternating);
    }
}

/// Checks that `alternating` covers what `full` does but for edges moved by less than a pixel,
/// at the same depth.
fn within_a_pixel(full: &lineao::reference::NdImage, alternating: &lineao::reference::NdImage) {
    let covered = |image: &lineao::reference::NdImage, x: usize, y: usize| is_geometry(image.get(x, y));
    let near = |image: &lineao::reference::NdImage, x: usize, y: usize| {
        (x.saturating_sub(1)..(x + 2).min(SIZE.0 as usize))
            .any(|i| (y.saturating_sub(1)..(y + 2).min(SIZE.1 as usize)).any(|j| covered(image, i, j)))
    };
    let (mut both, mut moved, mut far, mut same_depth) = (0, 0, 0, 0);
    for y in 0..SIZE.1 as usize {
        for x in 0..SIZE.0 as usize {
            match (covered(full, x, y), covered(alternating, x, y)) {
                (true, true) => {
                    both += 1;
                    same_depth += ((full.get(x, y)[3] - alternating.get(x, y)[3]).abs() < 1e-3) as usize;
                }
                (true, false) => {
                    moved += 1;
                    far += !near(alternating, x, y) as usize;
                }
                (false, true) => {
                    moved += 1;
                    far += !near(full, x, y) as usize;
                }
                (false, false) => {}
            }
        }
    }
    println!("covered by both {both}, by one {moved}, farther than a pixel {far}, same depth {same_depth}");
    // Edges move by less than a pixel: a pixel covered by one strip only touches the other's.
    assert_eq!(far, 0);
    assert!(moved as f64 <= 0.02 * both as f64, "{moved} of {both} pixels changed coverage");
    assert!(same_depth as f64 >= 0.98 * both as f64, "{same_depth} of {both} pixels kept their depth");
}

#[test]
fn close_up_the_full_strip_is_drawn() {
    let gpu = gpu();
    let (positions, offsets) = dense_and_coarse();
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    // The depth range starts 2 units ahead (the bounds reach z = 50): a world unit can cover
    // over 100 px there.
    let close = Camera { eye: Vec3::new(0.0, 0.0, 52.0), ..perspective() };
    let (full, _) = draw(&gpu, &geometry, LineStyle::FullStrip, &close);
    let (quads, alternated) = draw(&gpu, &geometry, LineStyle::Quads, &close);
    assert!(!alternated);
    assert!(full.data == quads.data, "the same strip, the same pixels");
}

/// The G-buffer of `draw` (the clusters' or the earlier strip's renderer) for `cam`: color, ND,
/// zoom, specular and hardware depth.
fn gbuffer_of(
    gpu: &lineao::Gpu,
    size: (u32, u32),
    draw: impl FnOnce(&mut wgpu::CommandEncoder, &FrameTargets),
) -> [lineao::reference::NdImage; 4] {
    let (d, q) = (&gpu.device, &gpu.queue);
    let targets = FrameTargets::new(d, size.0, size.1, 0, 1);
    let mut encoder = d.create_command_encoder(&Default::default());
    draw(&mut encoder, &targets);
    q.submit([encoder.finish()]);
    common::read_gbuffer(gpu, &targets)
}

/// Issue "whole-brain tractograms": the clusters draw the G-buffer the strip of earlier versions
/// drew (44 bytes a point there with its alternating strip, 7 here), on a scene of a million
/// points seen from afar and close up, both as the full strip (the alternating strips of the
/// two triangulate differently — they restart at every cluster — which moves interpolated
/// values inside the lines; `the_alternating_strip_stays_within_half_a_pixel_of_the_full_strip`
/// bounds that): depth within 1e-5; ≥ 99.5 % of the geometry pixels equal in every channel
/// (within 1e-3, a step of the f16 colour near 1: the strip's tangents were snorm16, the
/// clusters' are exact), the rest on a line's edge (a neighbour is background or another line,
/// more than 1e-5 away in depth) or ties of two lines within 1e-5 in depth (at most 0.1 %).
#[test]
fn clusters_draw_the_g_buffer_of_the_earlier_strip() {
    use lineao::passes::lines::{StripGeometry, StripRenderer};
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = waves(1000, 1000);
    let geometry = LineGeometry::new(d, q, &positions, &offsets).unwrap();
    let strip = StripGeometry::new(d, q, &positions, &offsets).unwrap();
    let bounds = geometry.bounds.unwrap();
    assert_eq!(Some(bounds), strip.bounds);
    let bytes = geometry.gpu_bytes() as f64 / positions.len() as f64;
    println!("clusters: {bytes:.2} bytes a point; strip: {:.2}", strip.gpu_bytes() as f64 / positions.len() as f64);
    assert!(bytes <= 8.0, "{bytes} bytes a point");
    let size = (400, 300);
    let close = Camera { eye: Vec3::new(0.0, 0.0, 70.0), ..perspective() };
    for (name, cam) in [("far", perspective()), ("close", close)] {
        let view = FrameView::new(&cam, &bounds, size.0, size.1, 0, 1.0);
        let settings = plain(2.0);
        let renderer = LineRenderer::with_style(d, LineStyle::FullStrip);
        renderer.prepare(q, &view, settings.line_width_px, settings.line_color, &settings.lighting, None);
        let background = lineao::passes::Load::Clear(settings.background);
        let new = gbuffer_of(&gpu, size, |e, t| renderer.encode(e, t, &geometry, background, None));
        let mut old_renderer = StripRenderer::new(d, true, LightingShape::ANY);
        old_renderer.prepare(q, &view, &settings);
        let old = gbuffer_of(&gpu, size, |e, t| old_renderer.encode(e, t, &strip, background, None));
        let (w, h) = (size.0 as usize, size.1 as usize);
        let covered = |image: &lineao::reference::NdImage, x: usize, y: usize| is_geometry(image.get(x, y));
        let on_edge = |x: usize, y: usize| {
            let depth = old[1].get(x, y)[3];
            (x.saturating_sub(1)..(x + 2).min(w)).any(|i| {
                (y.saturating_sub(1)..(y + 2).min(h)).any(|j| {
                    [&old[1], &new[1]].iter().any(|nd| !covered(nd, i, j) || (nd.get(i, j)[3] - depth).abs() > 1e-5)
                })
            })
        };
        let (mut geometry_pixels, mut equal, mut off_edge, mut worst_depth) = (0usize, 0usize, 0usize, 0.0f32);
        let mut ties = 0usize;
        for y in 0..h {
            for x in 0..w {
                if !covered(&old[1], x, y) && !covered(&new[1], x, y) {
                    continue;
                }
                geometry_pixels += 1;
                let same = (0..4).all(|target| {
                    let (a, b) = (old[target].get(x, y), new[target].get(x, y));
                    (0..4).all(|c| (a[c] - b[c]).abs() <= 1e-3)
                });
                if same {
                    equal += 1;
                    worst_depth = worst_depth.max((old[3].get(x, y)[0] - new[3].get(x, y)[0]).abs());
                    worst_depth = worst_depth.max((old[1].get(x, y)[3] - new[1].get(x, y)[3]).abs());
                } else if covered(&old[1], x, y)
                    && covered(&new[1], x, y)
                    && (old[1].get(x, y)[3] - new[1].get(x, y)[3]).abs() <= 1e-5
                {
                    // Two lines within 1e-5 of each other in depth: which one a pixel shows
                    // is rounding and draw order.
                    ties += 1;
                } else if !on_edge(x, y) {
                    off_edge += 1;
                }
            }
        }
        let share = equal as f64 / geometry_pixels as f64;
        println!(
            "{name}: {geometry_pixels} geometry pixels, {:.3} % equal, {ties} ties in depth, {off_edge} differing \
             off an edge, worst depth {worst_depth:.1e}",
            100.0 * share
        );
        assert!(ties * 1000 <= geometry_pixels, "{name}: {ties} ties");
        assert!(geometry_pixels > 20_000, "{name}");
        assert!(share >= 0.995, "{name}: {:.3} % equal", 100.0 * share);
        assert_eq!(off_edge, 0, "{name}");
        assert!(worst_depth <= 1e-5, "{name}: {worst_depth}");
    }
}

/// Issue "whole-brain tractograms": every point the GPU draws (decoded by its shaders, read
/// back) lies within 1e-4 of its cluster's extent of the f32 input (plus f32's rounding of a
/// coordinate that large), for clusters a micrometre across at the origin and a kilometre
/// across far from it. Clusters are the runs' consecutive 32 points (a rest of one makes the
/// last two 31 and 2).
#[test]
fn drawn_points_lie_within_their_clusters_bound() {
    let gpu = gpu();
    let helix = |size: f32, at: f32, n: usize| -> Vec<[f32; 3]> {
        (0..n)
            .map(|i| {
                let s = i as f32 / (n - 1) as f32;
                let a = s * 40.0;
                [at + size * a.cos(), at + size * a.sin(), at + size * (2.0 * s - 1.0)]
            })
            .collect()
    };
    let lines = [helix(1e-3, 0.0, 1000), helix(1e6, -3e6, 65), helix(1.0, 120.0, 97)];
    let positions: Vec<[f32; 3]> = lines.concat();
    let offsets = [0u64, 1000, 1065, 1162];
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let decoded = geometry.decoded_points(&gpu.device, &gpu.queue).unwrap();
    assert_eq!(decoded.len(), positions.len());
    // The extent of the cluster of each input point.
    let mut extent = vec![0.0f32; positions.len()];
    for w in offsets.windows(2) {
        let (first, len) = (w[0] as usize, (w[1] - w[0]) as usize);
        let mut sizes = vec![32; len / 32];
        match len % 32 {
            0 => {}
            1 => {
                sizes.pop();
                sizes.extend([31, 2]);
            }
            r => sizes.push(r),
        }
        let mut start = first;
        for size in sizes {
            let points = &positions[start..start + size];
            let lo = points.iter().fold(Vec3::INFINITY, |m, p| m.min(Vec3::from_array(*p)));
            let hi = points.iter().fold(Vec3::NEG_INFINITY, |m, p| m.max(Vec3::from_array(*p)));
            extent[start..start + size].fill((hi - lo).max_element());
            start += size;
        }
    }
    let mut worst = 0.0f32;
    for (input, point) in decoded {
        let p = Vec3::from_array(positions[input as usize]);
        let error = (Vec3::from_array(point) - p).abs().max_element();
        let ulp = p.abs().max_element() * f32::EPSILON;
        assert!(
            error <= 1e-4 * extent[input as usize] + ulp,
            "point {input}: {error:e} of {:e}",
            extent[input as usize]
        );
        worst = worst.max(error / extent[input as usize]);
    }
    println!("worst error {worst:.2e} of the cluster's extent");
}

/// Pipelines compiled for a lighting's shape (the chain's: the number of lights, a whole
/// shininess and the line shading as constants) draw the G-buffer of those that read the same
/// lighting from the uniform ([`LightingShape::ANY`], which the reference tests above check
/// through the chain too), lines and tubes, for lightings of every kind: none, one light at a
/// whole and at a fractional shininess, three lights averaged over the cylinder. Within 1e-5 (a
/// whole power is multiplied out, `pow` is exp2 ∘ log2).
#[test]
fn lighting_shapes_draw_what_the_uniform_draws() {
    use lineao::lighting::{Light, Lighting};
    use lineao::passes::tubes::TubeRenderer;
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = waves(40, 200);
    let geometry = LineGeometry::new(d, q, &positions, &offsets).unwrap();
    let view = FrameView::new(&perspective(), &bounds().unwrap(), 200, 160, 0, 1.0);
    let light = |x: f32, y: f32, intensity: f32| Light { dir: Vec3::new(x, y, 1.0), intensity };
    let lightings = [
        Lighting { lights: vec![], ..Lighting::default() },
        Lighting::default(),
        Lighting { shininess: 7.5, ..Lighting::default() },
        Lighting {
            lights: vec![light(-0.4, 0.6, 0.7), light(0.8, 0.1, 0.5), light(0.0, -0.9, 0.3)],
            shininess: 8.0,
            line_shading: LineShading::CylinderAveraged,
            ..Lighting::default()
        },
    ];
    let background = lineao::passes::Load::Clear([1.0; 3]);
    for lighting in &lightings {
        let shape = LightingShape::of(lighting);
        assert!(shape.fits(lighting) && LightingShape::ANY.fits(lighting));
        let draw = |shape| {
            let lines = LineRenderer::with_slab(d, LineStyle::Quads, false, false, shape);
            lines.prepare(q, &view, 3.0, LineColor::Tangent, lighting, None);
            let tubes = TubeRenderer::new(d, false, shape);
            tubes.prepare(q, &view, 0.6, LineColor::Tangent, lighting, None);
            [
                gbuffer_of(&gpu, (200, 160), |e, t| lines.encode(e, t, &geometry, background, None)),
                gbuffer_of(&gpu, (200, 160), |e, t| tubes.encode(e, t, &geometry, background, None)),
            ]
        };
        let (uniform, constant) = (draw(LightingShape::ANY), draw(shape));
        for (name, a, b) in [("lines", &uniform[0], &constant[0]), ("tubes", &uniform[1], &constant[1])] {
            let lit = a[1].data.iter().filter(|nd| is_geometry(**nd)).count();
            assert!(lit > 2_000, "{name}: {lit} geometry pixels");
            for (target, (a, b)) in a.iter().zip(b).enumerate() {
                let worst = a.data.iter().zip(&b.data).flat_map(|(p, q)| (0..4).map(move |c| (p[c] - q[c]).abs()));
                let worst = worst.fold(0.0f32, f32::max);
                assert!(worst <= 1e-5, "{name}, {lighting:?}, target {target}: {worst}");
            }
        }
    }
}
