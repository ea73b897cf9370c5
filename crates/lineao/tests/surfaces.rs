//! Context surfaces in the G-buffer: a fronto-parallel quad against its closed forms, surfaces
//! and lines occluding each other, and LineAO over both against its CPU reference.

mod common;

use common::{Frame, gpu, is_geometry, render_scene};
use glam::Vec3;
use lineao::LineGeometry;
use lineao::passes::meshes::MeshGeometry;
use lineao::reference;
use lineao::reference::line_ao_flip_bound;
use lineao::verify::check_policy;
use lineao::{AoMethod, ChainSettings, SurfaceSettings};
use lineao::{Camera, Projection};

/// A square of half-size `s` in the plane z = `z`, facing +z (two triangles).
fn square(s: f32, z: f32) -> ([[f32; 3]; 4], [[f32; 3]; 4], [u32; 6]) {
    ([[-s, -s, z], [s, -s, z], [s, s, z], [-s, s, z]], [[0.0, 0.0, 1.0]; 4], [0, 1, 2, 0, 2, 3])
}

fn render(
    gpu: &lineao::Gpu,
    lines: &LineGeometry,
    mesh: &MeshGeometry,
    settings: ChainSettings,
    camera: &Camera,
) -> Frame {
    let bounds = lines.bounds.unwrap().union(&mesh.bounds.unwrap());
    render_scene(gpu, lines, &[mesh], camera, bounds, settings, (160, 120))
}

fn camera(projection: Projection) -> Camera {
    Camera { eye: Vec3::new(0.0, 0.0, 60.0), target: Vec3::ZERO, up: Vec3::Y, projection }
}

#[test]
fn a_fronto_parallel_square_writes_its_closed_form_gbuffer_and_hides_what_is_behind() {
    let gpu = gpu();
    let (positions, normals, indices) = square(30.0, 0.0);
    let mesh = MeshGeometry::new(&gpu.device, &gpu.queue, &positions, &normals, &indices).unwrap();
    // A line crossing the square from in front (z = +8, x < 0) to behind (z = −8, x > 0).
    let lines = LineGeometry::new(&gpu.device, &gpu.queue, &[[-20.0, 5.0, 8.0], [20.0, 5.0, -8.0]], &[0, 2]).unwrap();
    let settings = ChainSettings {
        method: AoMethod::None,
        surfaces: Some(SurfaceSettings { color: [0.5, 0.6, 0.7] }),
        line_width_px: 3.0,
        ..ChainSettings::default()
    };
    for projection in [Projection::Perspective { fov_y_deg: 60.0 }, Projection::Orthographic { height: 70.0 }] {
        let f = render(&gpu, &lines, &mesh, settings.clone(), &camera(projection));
        let light = settings.lighting.lights[0].dir.normalize();
        let (kd, ks, alpha) = (settings.lighting.kd, settings.lighting.ks, settings.lighting.shininess);
        let (mut surface, mut line_in_front, mut line_behind) = (0, 0, 0);
        for y in 0..f.nd[0].height {
            for x in 0..f.nd[0].width {
                let nd = f.nd[0].get(x, y);
                if !is_geometry(nd) {
                    continue;
                }
                if nd[..3] == [0.0, 0.0, 1.0] {
                    // The square: at view depth 60 (the camera looks at it from 60 units away).
                    surface += 1;
                    let d = (60.0 - f.view.near) / (f.view.far - f.view.near);
                    assert!((nd[3] - d).abs() < 1e-5, "d {} vs {d}", nd[3]);
                    let zoom = if f.view.orthographic { f.view.f_px } else { f.view.f_px / 60.0 };
                    assert!((f.zoom.get(x, y) / zoom - 1.0).abs() < 1e-5);
                    let clip = f.view.proj * glam::Vec4::new(0.0, 0.0, -60.0, 1.0);
                    assert!((f.depth.get(x, y) - clip.z / clip.w).abs() < 1e-5);
                    let shade = 1.0 - kd + kd * light.z.max(0.0);
                    let c = f.color.get(x, y);
                    for (k, base) in [0.5, 0.6, 0.7].into_iter().enumerate() {
                        // Half floats, truncated by lavapipe: within one ulp.
                        assert!((c[k] - base * shade).abs() <= base * shade * 2f32.powi(-10), "color {c:?}");
                    }
                    // Blinn-Phong with the view direction toward the eye.
                    let p = if f.view.orthographic {
                        Vec3::Z
                    } else {
                        let (_, rd) = reference::tubes::pixel_ray(&f.view, f.view.proj.inverse(), [x as u32, y as u32]);
                        -rd
                    };
                    let h = (light + p).normalize();
                    let expected = ks * h.z.max(0.0).powf(alpha);
                    assert!(
                        (f.specular.get(x, y) - expected).abs() < 1e-4,
                        "specular {} vs {expected}",
                        f.specular.get(x, y)
                    );
                } else {
                    // The line, only where it is in front of the square (x < 0 in the image's
                    // left half, which the camera sees straight on).
                    if x < f.nd[0].width / 2 - 2 {
                        line_in_front += 1;
                    } else if x > f.nd[0].width / 2 + 2 {
                        line_behind += 1;
                    }
                }
            }
        }
        assert!(surface > 5000 && line_in_front > 40 && line_behind == 0, "{surface} {line_in_front} {line_behind}");
    }
}

#[test]
fn lineao_sees_surfaces_and_matches_its_cpu_reference() {
    let gpu = gpu();
    let (positions, normals, indices) = square(40.0, 0.0);
    let mesh = MeshGeometry::new(&gpu.device, &gpu.queue, &positions, &normals, &indices).unwrap();
    // Lines lying just in front of the square: LineAO darkens the surface around them (and the
    // lines where the surface rises behind them).
    let (line_positions, offsets) = {
        let mut p = Vec::new();
        let mut o = vec![0u64];
        for k in 0..12 {
            let y = -20.0 + 3.5 * k as f32;
            p.extend((0..40).map(|i| [-25.0 + 50.0 * i as f32 / 39.0, y, 1.0 + 0.5 * (i as f32 * 0.3).sin()]));
            o.push(p.len() as u64);
        }
        (p, o)
    };
    let lines = LineGeometry::new(&gpu.device, &gpu.queue, &line_positions, &offsets).unwrap();
    let s =
        ChainSettings { surfaces: Some(SurfaceSettings::default()), line_width_px: 3.0, ..ChainSettings::default() };
    let cam = Camera { eye: Vec3::new(10.0, -30.0, 60.0), ..camera(Projection::Perspective { fov_y_deg: 55.0 }) };
    let f = render(&gpu, &lines, &mesh, s.clone(), &cam);
    let cpu = reference::line_ao(
        &f.nd,
        &f.zoom,
        &lineao::noise::noise_tile(1),
        &lineao::method::line_ao::sample_table(&s.line_ao),
        &reference::LineAoParams::new(&s, &f.view),
    );
    let stats = check_policy(&f.ao, &cpu, &f.nd[0], line_ao_flip_bound(3, 32)).unwrap();
    println!("lines over a surface: {stats}");
    // The surface near the lines is more occluded than the surface far from them (LineAO darkens
    // any tilted surface somewhat: it compares depths without the tangent plane).
    let n = (f.view.view * glam::Vec4::Z).truncate();
    let is_surface = |x: usize, y: usize| {
        let nd = f.nd[0].get(x, y);
        Vec3::new(nd[0], nd[1], nd[2]).distance(n) < 1e-4
    };
    let is_line = |x: usize, y: usize| is_geometry(f.nd[0].get(x, y)) && !is_surface(x, y);
    let near_line = |x: usize, y: usize, r: usize| {
        (y.saturating_sub(r)..(y + r + 1).min(f.ao.height))
            .any(|yy| (x.saturating_sub(r)..(x + r + 1).min(f.ao.width)).any(|xx| is_line(xx, yy)))
    };
    let (mut near, mut far) = (Vec::new(), Vec::new());
    for y in 0..f.ao.height {
        for x in 0..f.ao.width {
            if is_surface(x, y) {
                if near_line(x, y, 3) {
                    near.push(f.ao.get(x, y));
                } else if !near_line(x, y, 15) {
                    far.push(f.ao.get(x, y));
                }
            }
        }
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    println!(
        "surface AO: {:.3} next to the lines ({} px), {:.3} away from them ({} px)",
        mean(&near),
        near.len(),
        mean(&far),
        far.len()
    );
    assert!(near.len() > 500 && far.len() > 500 && mean(&near) > mean(&far) + 0.1);
}

#[test]
fn bad_meshes_are_errors() {
    let gpu = gpu();
    let (positions, normals, _) = square(1.0, 0.0);
    for (indices, normals, needle) in [
        (&[0u32, 1, 9][..], &normals[..], "index 9"),
        (&[0, 1], &normals[..], "three per triangle"),
        (&[0, 1, 2], &normals[..3], "normals"),
    ] {
        let error = MeshGeometry::new(&gpu.device, &gpu.queue, &positions, normals, indices).err().unwrap().to_string();
        assert!(error.contains(needle), "{error}");
    }
}
