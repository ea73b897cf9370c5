//! Embedding in a host renderer: the ND and zoom maps derived from a host's depth (and normals)
//! against the ones our renderers write; reversed-Z and standard depth, MSAA and single
//! samples, perspective and orthographic cameras against an analytic sphere; and the composite
//! into the host's color formats.

mod common;

use common::{cameras_for_polylines, gpu, host_depth, is_geometry, polylines, sphere_triangles, texture};
use glam::{Mat4, Vec3, Vec4Swizzles};
use lineao::Error::Usage;
use lineao::LineGeometry;
use lineao::passes::nd_from_depth::{HostConfig, HostInputs, HostNormals};
use lineao::readback::{read_f32, read_rgba};
use lineao::reference::tubes::pixel_ray;
use lineao::reference::{Image, NdImage};
use lineao::{AoChain, AoMethod, ChainSettings, HostAo, OverlayAo, TubeSettings};
use lineao::{Bounds, Camera, FrameView, Misuse, Projection};

/// What the host path leaves in the chain's targets.
struct HostFrame {
    nd: NdImage,
    zoom: Image<f32>,
    ao: Image<f32>,
}

/// Runs a chain with `settings` over a host's `depth` (and `normals`) seen through `view`.
fn run_host(
    gpu: &lineao::Gpu,
    settings: ChainSettings,
    config: HostConfig,
    view: FrameView,
    depth: &wgpu::TextureView,
    normals: Option<&wgpu::TextureView>,
) -> HostFrame {
    let (d, q) = (&gpu.device, &gpu.queue);
    let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, settings).unwrap();
    chain.resize(view.width, view.height).unwrap();
    let mut host = HostAo::new(d, chain, config).unwrap();
    host.prepare(d, q, view).unwrap();
    let mut encoder = d.create_command_encoder(&Default::default());
    host.encode(d, &mut encoder, &HostInputs { depth, normals, color: None }, None).unwrap();
    q.submit([encoder.finish()]);
    let t = host.chain().targets().unwrap();
    HostFrame {
        nd: read_rgba(d, q, &t.nd[0]).unwrap(),
        zoom: read_f32(d, q, &t.zoom).unwrap(),
        ao: read_f32(d, q, &t.ao).unwrap(),
    }
}

/// The angle between two normals, stable near 0 (acos of a dot product near 1 is not).
fn angle(a: [f32; 4], b: [f32; 4]) -> f32 {
    let (a, b) = (Vec3::new(a[0], a[1], a[2]).normalize(), Vec3::new(b[0], b[1], b[2]).normalize());
    2.0 * (0.5 * a.distance(b)).min(1.0).asin()
}

fn percentile(mut v: Vec<f32>, p: f32) -> f32 {
    v.sort_by(f32::total_cmp);
    v[((v.len() - 1) as f32 * p) as usize]
}

#[test]
fn maps_derived_from_depth_match_the_ones_the_renderers_write() {
    let gpu = gpu();
    let (positions, offsets) = polylines(25, 0.9);
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let (perspective, orthographic) = cameras_for_polylines();
    let size = (240u32, 180u32);
    for (name, camera, tubes) in [
        ("tubes, perspective", perspective, true),
        ("tubes, orthographic", orthographic, true),
        ("lines, perspective", perspective, false),
    ] {
        // Our renderer: tubes (true depth and normals) or lines, no guard band (method none).
        let ours = ChainSettings {
            method: AoMethod::None,
            tubes: tubes.then_some(TubeSettings { radius_world: 2.5 }),
            line_width_px: 4.0,
            ..ChainSettings::default()
        };
        let (d, q) = (&gpu.device, &gpu.queue);
        let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, ours).unwrap();
        chain.resize(size.0, size.1).unwrap();
        let view = chain.prepare(d, q, &camera, &geometry.bounds.unwrap()).unwrap();
        assert_eq!(view.guard, 0);
        let output = lineao::targets::Target::output(d, "test::output", size, common::OUTPUT_FORMAT);
        let mut encoder = d.create_command_encoder(&Default::default());
        chain.encode(&mut encoder, &geometry, &output.view).unwrap();
        q.submit([encoder.finish()]);
        let t = chain.targets().unwrap();
        let (nd, zoom) = (read_rgba(d, q, &t.nd[0]).unwrap(), read_f32(d, q, &t.zoom).unwrap());

        // The host path over that depth, with the same matrices.
        let host_view = FrameView::from_matrices(view.view, view.proj, size.0, size.1, &geometry.bounds.unwrap());
        assert_eq!((host_view.near, host_view.far, host_view.f_px), (view.near, view.far, view.f_px));
        assert_eq!(host_view.orthographic, view.orthographic);
        let derived = run_host(&gpu, ChainSettings::default(), HostConfig::default(), host_view, &t.depth.view, None);
        let (mut worst_d, mut worst_zoom, mut angles) = (0.0f32, 0.0f32, Vec::new());
        for i in 0..nd.data.len() {
            assert_eq!(is_geometry(nd.data[i]), is_geometry(derived.nd.data[i]), "{name}: coverage at {i}");
            if is_geometry(nd.data[i]) {
                worst_d = worst_d.max((nd.data[i][3] - derived.nd.data[i][3]).abs());
                worst_zoom = worst_zoom.max((zoom.data[i] / derived.zoom.data[i] - 1.0).abs());
                angles.push(angle(nd.data[i], derived.nd.data[i]));
            }
        }
        let (median, p75, p90) =
            (percentile(angles.clone(), 0.5), percentile(angles.clone(), 0.75), percentile(angles.clone(), 0.9));
        println!(
            "{name}: {} pixels; worst |Δd| {worst_d:.1e}, zoom relative {worst_zoom:.1e}; normal angle from depth \
             median {median:.3}, 75 % {p75:.3}, 90 % {p90:.3} rad",
            angles.len()
        );
        assert!(angles.len() > 3000, "{name}");
        assert!(worst_d < 1e-5 && worst_zoom < 1e-5, "{name}");
        if tubes {
            // Reconstructed from one-pixel differences of tubes 8 to 12 pixels wide: good inside,
            // poor on the outer rim, where the surface turns away within a pixel (a host with
            // thin geometry passes its normals, which are exact).
            assert!(median < 0.06 && p75 < 0.2, "{name}");
            // With the host's own normals (ours, as view-space floats) they are exact.
            let normals = lineao::targets::Target::new(
                d,
                "test::normals",
                size,
                wgpu::TextureFormat::Rgba32Float,
                wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            );
            lineao::readback::write_target(q, &normals, &nd);
            let config =
                HostConfig { normals: Some(HostNormals { world_space: false, unorm: false }), ..Default::default() };
            let given = run_host(&gpu, ChainSettings::default(), config, host_view, &t.depth.view, Some(&normals.view));
            let worst = (0..nd.data.len())
                .filter(|&i| is_geometry(nd.data[i]))
                .map(|i| angle(nd.data[i], given.nd.data[i]))
                .fold(0.0f32, f32::max);

            assert!(worst < 1e-3, "{name}: host normals off by {worst}");
            // LineAO over the derived G-buffer obscures the bundle.
            assert!(given.ao.data.iter().filter(|&&a| a > 0.05).count() > 300, "{name}");
        }
    }
}

/// The reversed-Z (near at 1, far at 0) variant of a wgpu projection: z' = w − z.
fn reversed(proj: Mat4) -> Mat4 {
    let flip = Mat4::from_cols(
        glam::Vec4::X,
        glam::Vec4::Y,
        glam::Vec4::new(0.0, 0.0, -1.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 1.0),
    );
    flip * proj
}

/// A sphere (centre, radius, its triangles) and a camera looking at it from above and aside.
fn sphere_scene() -> (Vec3, f32, Vec<[f32; 3]>, Camera) {
    let (centre, radius) = (Vec3::new(1.0, -2.0, 0.0), 10.0f32);
    let camera = Camera {
        eye: Vec3::new(6.0, 9.0, 42.0),
        target: centre,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 45.0 },
    };
    (centre, radius, sphere_triangles(centre, radius, 64), camera)
}

#[test]
fn reversed_z_msaa_and_both_projections_against_an_analytic_sphere() {
    let gpu = gpu();
    let (centre, radius, triangles, camera) = sphere_scene();
    let bounds = Bounds { center: centre, radius };
    let size = (200u32, 150u32);
    let view_matrix = camera.view_matrix();
    let aspect = size.0 as f32 / size.1 as f32;
    use glam::camera::rh::proj::directx;
    let perspective = directx::perspective(45f32.to_radians(), aspect, 5.0, 200.0);
    let orthographic = directx::orthographic(-14.0 * aspect, 14.0 * aspect, -14.0, 14.0, 5.0, 200.0);
    let mut results: Vec<(String, HostFrame)> = Vec::new();
    for (projection_name, standard) in [("perspective", perspective), ("orthographic", orthographic)] {
        for (reversed_z, samples) in [(false, 1), (true, 1), (false, 4), (true, 4)] {
            let name = format!(
                "{projection_name}, {}, {samples} sample(s)",
                if reversed_z { "reversed-Z" } else { "standard" }
            );
            let proj = if reversed_z { reversed(standard) } else { standard };
            let depth = host_depth(&gpu, &triangles, proj * view_matrix, size, samples, reversed_z);
            let view = FrameView::from_matrices(view_matrix, proj, size.0, size.1, &bounds);
            let config = HostConfig { depth_samples: samples, reversed_z, normals: None };
            let frame =
                run_host(&gpu, ChainSettings::default(), config, view, &depth.create_view(&Default::default()), None);
            // The analytic sphere along each pixel's ray (from the near plane: the standard
            // projection's depth 0).
            let inv_proj = standard.inverse();
            let (mut angles, mut worst_d, mut worst_zoom, mut coverage_differs) = (Vec::new(), 0.0f32, 0.0f32, 0);
            let sphere_view = (view_matrix * centre.extend(1.0)).xyz();
            for y in 0..size.1 {
                for x in 0..size.0 {
                    let (o, dir) = pixel_ray(&view, inv_proj, [x, y]);
                    let oc = o - sphere_view;
                    let (b, c) = (oc.dot(dir), oc.dot(oc) - radius * radius);
                    let hit = (b * b - c > 0.0).then(|| -b - (b * b - c).sqrt());
                    let nd = frame.nd.get(x as usize, y as usize);
                    match (hit, is_geometry(nd)) {
                        (Some(t), true) => {
                            let p = o + t * dir;
                            let n = (p - sphere_view).normalize();
                            angles.push(angle(nd, [n.x, n.y, n.z, 0.0]));
                            // Where the ray grazes the sphere the mesh's polygonal outline is far
                            // from it along the ray: depth is compared where it faces the eye.
                            if -n.dot(dir) > 0.3 {
                                worst_d = worst_d.max((nd[3] - view.normalized_depth(p.z)).abs());
                                let zoom = if view.orthographic { view.f_px } else { view.f_px / -p.z };
                                worst_zoom =
                                    worst_zoom.max((frame.zoom.get(x as usize, y as usize) / zoom - 1.0).abs());
                            }
                        }
                        (None, false) => {}
                        _ => coverage_differs += 1,
                    }
                }
            }
            let (median, p95) = (percentile(angles.clone(), 0.5), percentile(angles.clone(), 0.95));
            println!(
                "{name}: {} pixels (coverage differs at {coverage_differs}); normal angle median {median:.4}, 95 % \
                 {p95:.4} rad; worst |Δd| {worst_d:.1e}, zoom relative {worst_zoom:.1e}",
                angles.len()
            );
            // The mesh is a 64-ring polygon: its facets tilt normals by up to ~π/64, and their sag
            // (≈ 6e-3 units across a quad's diagonal) shows along a ray as sag / (n·v): up to
            // 2e-3 of the 20-unit depth range at n·v ≥ 0.3.
            assert!(angles.len() > 5000 && coverage_differs < angles.len() / 50, "{name}");
            assert!(median < 0.03 && p95 < 0.1, "{name}");
            assert!(worst_d < 2e-3 && worst_zoom < 2e-3, "{name}");
            results.push((name, frame));
        }
    }
    // Reversed-Z and standard depth give the same maps, up to depth precision.
    for pair in results.chunks(2) {
        let [(a, fa), (b, fb)] = pair else { unreachable!() };
        let worst = fa.nd.data.iter().zip(&fb.nd.data).map(|(x, y)| (x[3] - y[3]).abs()).fold(0.0f32, f32::max);
        println!("{a} vs {b}: worst |Δd| {worst:.1e}");
        assert!(worst < 1e-4, "{a} vs {b}");
    }
}

#[test]
fn the_composite_writes_any_host_color_format() {
    let gpu = gpu();
    let (positions, offsets) = polylines(30, 0.1);
    let (camera, _) = cameras_for_polylines();
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &positions, &offsets).unwrap();
    let bounds = geometry.bounds.unwrap();
    let size = (96u32, 72u32);
    let render = |format: wgpu::TextureFormat| {
        let (d, q) = (&gpu.device, &gpu.queue);
        // Without levels of detail: each format's frame is the full strip's (with them, a frame
        // after the first keeps the pieces within half a pixel of it).
        let exact = ChainSettings { lod: false, ..ChainSettings::default() };
        let mut chain = AoChain::new(d, format, exact).unwrap();
        chain.resize(size.0, size.1).unwrap();
        chain.prepare(d, q, &camera, &bounds).unwrap();
        let target = lineao::targets::Target::output(d, "test::output", size, format);
        let mut encoder = d.create_command_encoder(&Default::default());
        chain.encode(&mut encoder, &geometry, &target.view).unwrap();
        q.submit([encoder.finish()]);
        lineao::readback::read_texture(d, q, &target.texture).unwrap().bytes
    };
    let reference: Vec<f32> = bytemuck::pod_collect_to_vec(&render(wgpu::TextureFormat::Rgba32Float));
    let srgb = |v: f32| if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) };
    for (format, tolerance) in [
        (wgpu::TextureFormat::Rgba8Unorm, 1.0 / 255.0),
        (wgpu::TextureFormat::Bgra8UnormSrgb, 0.02),
        (wgpu::TextureFormat::Rgba16Float, 2e-3),
        (wgpu::TextureFormat::Rgb10a2Unorm, 1.0 / 1023.0),
    ] {
        let bytes = render(format);
        let decoded: Vec<[f32; 3]> = match format {
            wgpu::TextureFormat::Rgba8Unorm => {
                bytes.chunks(4).map(|p| [0, 1, 2].map(|c| p[c] as f32 / 255.0)).collect()
            }
            wgpu::TextureFormat::Bgra8UnormSrgb => {
                bytes.chunks(4).map(|p| [2, 1, 0].map(|c| srgb(p[c] as f32 / 255.0))).collect()
            }
            wgpu::TextureFormat::Rgba16Float => bytemuck::pod_collect_to_vec::<u8, u16>(&bytes)
                .chunks(4)
                .map(|p| [0, 1, 2].map(|c| lineao::readback::f16_to_f32(p[c])))
                .collect(),
            _ => bytemuck::pod_collect_to_vec::<u8, u32>(&bytes)
                .iter()
                .map(|&p| [0, 10, 20].map(|shift| (p >> shift & 0x3ff) as f32 / 1023.0))
                .collect(),
        };
        let worst = decoded
            .iter()
            .zip(reference.chunks(4))
            // Unorm formats clamp to [0, 1]; a float format keeps the specular above 1.
            .map(|(a, b)| {
                let b = |c: usize| if format == wgpu::TextureFormat::Rgba16Float { b[c] } else { b[c].clamp(0.0, 1.0) };
                (0..3).map(|c| (a[c] - b(c)).abs() / b(c).abs().max(1.0)).fold(0.0f32, f32::max)
            })
            .fold(0.0f32, f32::max);
        println!("{format:?}: worst |Δ| {worst:.2e} against Rgba32Float");
        assert!(worst <= tolerance * 1.01, "{format:?}: {worst}");
    }
}

/// Every misuse of the host API is an `Error::Usage` naming what to change, with nothing
/// recorded — never a silent no-op, never a wgpu panic inside lineao.
#[test]
fn host_api_misuse_is_an_error_that_says_what_to_change() {
    use wgpu::TextureFormat as F;
    use wgpu::TextureUsages as U;
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let size = (64u32, 48u32);
    let (camera, bounds) = common::unit_sphere_view();
    let view = |(w, h): (u32, u32)| FrameView::new(&camera, &bounds, w, h, 0, 1.0);
    let depth_usage = U::RENDER_ATTACHMENT | U::TEXTURE_BINDING;
    let depth = texture(&gpu, size, F::Depth32Float, depth_usage, 1);
    let color = texture(&gpu, size, F::Rgba8Unorm, U::TEXTURE_BINDING, 1);
    let output = texture(&gpu, size, common::OUTPUT_FORMAT, U::RENDER_ATTACHMENT, 1);
    let inputs = HostInputs { depth: &depth, normals: None, color: Some(&color) };
    let expect = |result: Result<(), lineao::Error>, says: &str| match result {
        Err(lineao::Error::Usage(misuse)) => {
            let text = misuse.to_string();
            assert!(text.contains(says), "{text:?} should say {says:?}")
        }
        other => panic!("expected a usage error saying {says:?}, got {other:?}"),
    };

    // A depth format where the composite's color format belongs.
    let made = AoChain::new(d, F::Depth32Float, ChainSettings::default());
    expect(made.map(|_| ()), "not the depth's");

    let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, ChainSettings::default()).unwrap();
    chain.resize(size.0, size.1).unwrap();
    let mut encoder = d.create_command_encoder(&Default::default());
    // A sample count no texture has (an encode before making a HostAo cannot be written).
    let no_samples = HostConfig { depth_samples: 0, ..HostConfig::default() };
    let refused = HostAo::new(d, AoChain::new(d, common::OUTPUT_FORMAT, ChainSettings::default()).unwrap(), no_samples);
    let names_it = |e: &lineao::Error| matches!(e, lineao::Error::OutOfRange { setting: "HostConfig::depth_samples", value, .. } if value == "0");
    assert!(refused.as_ref().err().is_some_and(names_it), "{:?}", refused.err());
    let mut host = pollster::block_on(HostAo::new_async(d, chain, HostConfig::default())).unwrap();
    expect(host.encode(d, &mut encoder, &inputs, None), "HostAo::prepare");
    expect(host.prepare(d, q, view((32, 32))).map(|_| ()), "resize");
    host.prepare(d, q, view(size)).unwrap().expect("a view at the chain's size");

    let unsampled = texture(&gpu, size, F::Depth32Float, U::RENDER_ATTACHMENT, 1);
    let multisampled = texture(&gpu, size, F::Depth32Float, depth_usage, 4);
    let small = texture(&gpu, (32, 32), F::Depth32Float, depth_usage, 1);
    let not_depth = texture(&gpu, size, F::R32Float, U::TEXTURE_BINDING, 1);
    let uint_color = texture(&gpu, size, F::R32Uint, U::TEXTURE_BINDING, 1);
    let small_color = texture(&gpu, (32, 32), F::Rgba8Unorm, U::TEXTURE_BINDING, 1);
    let with = |depth, normals, color| HostInputs { depth, normals, color };
    for (inputs, says) in [
        (with(&unsampled, None, None), "TEXTURE_BINDING"),
        (with(&multisampled, None, None), "depth_samples"),
        (with(&small, None, None), "AoChain::resize"),
        (with(&not_depth, None, None), "must be a depth format"),
        (with(&depth, Some(&color), None), "HostInputs::normals was passed but HostConfig::normals says none"),
        (with(&depth, None, Some(&uint_color)), "float or unorm"),
        (with(&depth, None, Some(&small_color)), "32×32"),
    ] {
        expect(host.encode(d, &mut encoder, &inputs, None), says);
    }
    // Normals promised but not passed.
    let normals =
        HostConfig { normals: Some(HostNormals { world_space: false, unorm: true }), ..HostConfig::default() };
    host.set_config(d, normals).unwrap();
    expect(host.encode(d, &mut encoder, &with(&depth, None, None), None), "HostInputs::normals was not passed");
    pollster::block_on(host.set_config_async(d, HostConfig::default())).unwrap();

    // The composite's target: its format, its size, its usage.
    let wrong_format = texture(&gpu, size, F::Rgba16Float, U::RENDER_ATTACHMENT, 1);
    let wrong_size = texture(&gpu, (32, 32), common::OUTPUT_FORMAT, U::RENDER_ATTACHMENT, 1);
    let not_attachment = texture(&gpu, size, common::OUTPUT_FORMAT, U::TEXTURE_BINDING, 1);
    expect(host.encode(d, &mut encoder, &inputs, Some(&wrong_format)), "the chain was made for");
    expect(host.encode(d, &mut encoder, &inputs, Some(&wrong_size)), "32×32");
    expect(host.encode(d, &mut encoder, &inputs, Some(&not_attachment)), "RENDER_ATTACHMENT");

    // What is right records, and the frame runs without a validation error.
    let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
    host.encode(d, &mut encoder, &inputs, Some(&output)).unwrap();
    q.submit([encoder.finish()]);
    assert!(pollster::block_on(scope.pop()).is_none(), "a checked frame must be valid");

    // 0 × 0: nothing to record, no error.
    host.chain_mut().resize(0, 0).unwrap();
    assert!(host.prepare(d, q, view((0, 0))).unwrap().is_none());
    let mut encoder = d.create_command_encoder(&Default::default());
    host.encode(d, &mut encoder, &inputs, None).unwrap();
}

/// `OverlayAo` draws the lines into a host's frame: the host's colour stays on the
/// background and where its depth is nearer; the lines' pixels equal `encode`'s, and the depth
/// they leave is the host projection's depth of their view-space z (reversed-Z with an infinite
/// far plane, and standard depth), tested against what the host drew before.
#[test]
fn the_overlay_keeps_the_hosts_frame_and_writes_its_depth() {
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = polylines(30, 0.3);
    let (camera, _) = cameras_for_polylines();
    let geometry = LineGeometry::new(d, q, &positions, &offsets).unwrap();
    let bounds = geometry.bounds.unwrap();
    let size = (96u32, 72u32);
    let host_color = [0.25f32, 0.5, 0.75, 1.0];
    let [reversed_infinite, standard] = host_projections(&camera, size);

    // Without levels of detail, so that each frame is the first's.
    let exact = ChainSettings { lod: false, ..ChainSettings::default() };
    let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, exact).unwrap();
    chain.resize(size.0, size.1).unwrap();
    let view = chain.prepare(d, q, &camera, &bounds).unwrap();
    let plain = lineao::targets::Target::output(d, "test::plain", size, common::OUTPUT_FORMAT);
    let mut encoder = d.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &geometry, &plain.view).unwrap();
    q.submit([encoder.finish()]);
    let plain: Vec<[f32; 4]> = read_texture_vec4(&gpu, &plain.texture);
    let nd = read_rgba(d, q, &chain.targets().unwrap().nd[0]).unwrap();
    let g = view.guard as usize;
    let nd_at = |x: usize, y: usize| nd.data[(y + g) * nd.width + x + g];
    let z_of = |x, y| -(view.near + nd_at(x, y)[3] * (view.far - view.near));
    let mut overlay = OverlayAo::new(d, chain, None).unwrap();

    for (name, proj) in [("reversed-Z, infinite far", reversed_infinite), ("standard", standard)] {
        let depth_at = |z: f32| proj.project_point3(Vec3::new(0.0, 0.0, z)).z;
        // The host drew a wall at the depth of the lines' middle: lines behind it stay hidden.
        let wall_z = -0.5 * (view.near + view.far);
        let wall = depth_at(wall_z);
        let color = lineao::targets::Target::output(d, "test::host_color", size, common::OUTPUT_FORMAT);
        let depth = d.create_texture(&wgpu::TextureDescriptor {
            label: Some("test::host_depth"),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let depth_view = depth.create_view(&Default::default());
        let mut encoder = d.create_command_encoder(&Default::default());
        let [r, g_, b, a] = host_color.map(f64::from);
        common::host_frame(&mut encoder, Some((&color.view, wgpu::Color { r, g: g_, b, a })), &depth_view, wall);
        overlay.set_depth(d, Some(lineao::OverlayDepth { format: wgpu::TextureFormat::Depth32Float, proj })).unwrap();
        overlay.chain_mut().prepare(d, q, &camera, &bounds).unwrap();
        overlay.encode(&mut encoder, &geometry, &[], &color.view, Some(&depth_view)).unwrap();
        q.submit([encoder.finish()]);
        let shown = read_texture_vec4(&gpu, &color.texture);
        let depths: Vec<f32> =
            bytemuck::pod_collect_to_vec(&lineao::readback::read_texture(d, q, &depth).unwrap().bytes);
        let (mut drawn, mut hidden, mut worst) = (0, 0, 0.0f32);
        for y in 0..size.1 as usize {
            for x in 0..size.0 as usize {
                let i = y * size.0 as usize + x;
                let in_front = is_geometry(nd_at(x, y)) && z_of(x, y) > wall_z;
                if in_front {
                    drawn += 1;
                    assert_eq!(shown[i], plain[i], "{name}: a line pixel ({x}, {y}) as encode draws it");
                    let expected = depth_at(z_of(x, y));
                    worst = worst.max((depths[i] - expected).abs() / expected.abs().max(1e-6));
                } else {
                    hidden += is_geometry(nd_at(x, y)) as usize;
                    assert_eq!(shown[i], host_color, "{name}: the host's pixel ({x}, {y}) stays");
                    assert_eq!(depths[i], wall, "{name}: the host's depth at ({x}, {y}) stays");
                }
            }
        }
        println!("{name}: {drawn} line pixels drawn, {hidden} behind the wall, worst relative depth error {worst:.1e}");
        assert!(
            drawn > 100 && hidden > 100,
            "{name}: the wall should split the lines ({drawn} drawn, {hidden} hidden)"
        );
        assert!(worst < 1e-5, "{name}: depth {worst}");
    }

    // Misuse: a depth the overlay was not made for, or none where it was (an overlay encode
    // before the overlay is made cannot be written).
    let other = texture(&gpu, size, wgpu::TextureFormat::Depth24Plus, wgpu::TextureUsages::RENDER_ATTACHMENT, 1);
    let output = lineao::targets::Target::output(d, "test::output", size, common::OUTPUT_FORMAT);
    let mut encoder = d.create_command_encoder(&Default::default());
    let result = overlay.encode(&mut encoder, &geometry, &[], &output.view, Some(&other));
    let format = wgpu::TextureFormat::Depth24Plus;
    assert!(matches!(&result, Err(Usage(Misuse::TextureFormat { format: f, .. })) if *f == format), "{result:?}");
    let result = overlay.encode(&mut encoder, &geometry, &[], &output.view, None);
    assert!(matches!(&result, Err(Usage(Misuse::Input { given: false, .. }))), "{result:?}");
    overlay.set_depth(d, None).unwrap();
    let result = overlay.encode(&mut encoder, &geometry, &[], &output.view, Some(&other));
    assert!(matches!(&result, Err(Usage(Misuse::Input { given: true, .. }))), "{result:?}");
    let bad = lineao::OverlayDepth { format: wgpu::TextureFormat::Rgba8Unorm, proj: standard };
    assert!(matches!(overlay.set_depth(d, Some(bad)), Err(lineao::Error::Usage(_))));
    let fresh = AoChain::new(d, common::OUTPUT_FORMAT, ChainSettings::default()).unwrap();
    assert!(matches!(OverlayAo::new(d, fresh, Some(bad)), Err(lineao::Error::Usage(_))));

    // The chain's own encode checks alike: a frame not prepared, a target of another size or
    // format; a 0 × 0 chain records nothing.
    let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, ChainSettings::default()).unwrap();
    chain.resize(size.0, size.1).unwrap();
    let result = chain.encode(&mut encoder, &geometry, &output.view);
    let order = Misuse::Order { call: "AoChain::encode", first: "AoChain::prepare" };
    assert!(matches!(&result, Err(Usage(m)) if m.to_string() == order.to_string()), "{result:?}");
    chain.prepare(d, q, &camera, &bounds).unwrap();
    let small = lineao::targets::Target::output(d, "test::small", (size.0 / 2, size.1), common::OUTPUT_FORMAT);
    let result = chain.encode(&mut encoder, &geometry, &small.view);
    assert!(matches!(&result, Err(Usage(Misuse::Size { size, chain, .. })) if size != chain), "{result:?}");
    let float = lineao::targets::Target::output(d, "test::float", size, wgpu::TextureFormat::Rgba16Float);
    let result = chain.encode(&mut encoder, &geometry, &float.view);
    let float = wgpu::TextureFormat::Rgba16Float;
    assert!(matches!(&result, Err(Usage(Misuse::TextureFormat { format, .. })) if *format == float), "{result:?}");
    chain.encode(&mut encoder, &geometry, &output.view).unwrap();
    chain.resize(0, 0).unwrap();
    chain.encode(&mut encoder, &geometry, &small.view).unwrap();
}

/// A host depth the chain can read (`TEXTURE_BINDING`) seeds the G-buffer's
/// (`passes::seed_depth`): behind the host's wall no line leaves a pixel in the G-buffer, in
/// front of it every pixel is the one drawing every line leaves; culled, fewer pieces are
/// drawn than without the seed (`tests/cull.rs` checks the culled G-buffer over a seeded depth
/// bit for bit). Reversed-Z with an infinite far plane, and standard depth.
#[test]
fn a_host_depth_the_chain_can_read_seeds_the_g_buffer_and_culls_what_it_hides() {
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (positions, offsets) = polylines(150, 0.3);
    let (camera, _) = cameras_for_polylines();
    let geometry = LineGeometry::new(d, q, &positions, &offsets).unwrap();
    let bounds = geometry.bounds.unwrap();
    let size = (160u32, 120u32);
    let [reversed_infinite, standard] = host_projections(&camera, size);
    let format = wgpu::TextureFormat::Depth32Float;
    for (name, proj) in [("reversed-Z, infinite far", reversed_infinite), ("standard", standard)] {
        // Two frames into a host's frame whose depth is a wall at `wall_z` (view space), the
        // chain culling or not, the host's depth readable or not: the G-buffer, the chain's view
        // and what the cull drew.
        let run = |wall_z: f32, cull: bool, readable: bool| {
            let settings = ChainSettings { lod: false, cull, ..ChainSettings::default() };
            let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, settings).unwrap();
            chain.resize(size.0, size.1).unwrap();
            let depth_of = lineao::OverlayDepth { format, proj };
            let mut overlay = OverlayAo::new(d, chain, Some(depth_of)).unwrap();
            let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
                | if readable { wgpu::TextureUsages::TEXTURE_BINDING } else { wgpu::TextureUsages::empty() };
            let depth = texture(&gpu, size, format, usage, 1);
            let color = lineao::targets::Target::output(d, "test::host_color", size, common::OUTPUT_FORMAT);
            let wall = proj.project_point3(Vec3::new(0.0, 0.0, wall_z)).z.clamp(0.0, 1.0);
            let mut view = None;
            for _ in 0..2 {
                let mut encoder = d.create_command_encoder(&Default::default());
                common::host_frame(&mut encoder, Some((&color.view, wgpu::Color::BLACK)), &depth, wall);
                view = Some(overlay.chain_mut().prepare(d, q, &camera, &bounds).unwrap());
                overlay.encode(&mut encoder, &geometry, &[], &color.view, Some(&depth)).unwrap();
                q.submit([encoder.finish()]);
            }
            let gbuffer = common::read_gbuffer(&gpu, overlay.chain().targets().unwrap());
            (gbuffer, view.unwrap(), overlay.chain().cull_counts(q, &geometry).unwrap())
        };
        // Every line, no seed: where the wall goes (the middle of the lines' depths).
        let (plain, view, _) = run(-1e6, false, false);
        let z_of = |nd: [f32; 4]| -(view.near + nd[3] * (view.far - view.near));
        let wall_z = -0.5 * (view.near + view.far);
        let (all, _, _) = run(wall_z, false, true);
        let (_, _, counts) = run(wall_z, true, true);
        let (unseeded, _, unseeded_counts) = run(wall_z, true, false);
        let (counts, unseeded_counts) = (counts.unwrap(), unseeded_counts.unwrap());
        let (mut front, mut hidden) = (0, 0);
        for i in 0..plain[1].data.len() {
            let nd = plain[1].data[i];
            if is_geometry(all[1].data[i]) {
                let z = z_of(all[1].data[i]);
                assert!(z > wall_z * (1.0 + 2e-5), "{name}: a line at z {z} behind the wall at {wall_z} (pixel {i})");
            }
            if is_geometry(nd) && z_of(nd) > wall_z * (1.0 - 1e-4) {
                front += 1;
                assert_eq!(all[1].data[i], nd, "{name}: the line in front of the wall at pixel {i}");
            } else if is_geometry(nd) && z_of(nd) < wall_z * (1.0 + 1e-4) {
                hidden += 1;
                assert!(!is_geometry(all[1].data[i]), "{name}: a pixel behind the wall drawn at {i}");
            }
        }
        let drawn = |c: &lineao::passes::cull::CullCounts| c.early + c.late;
        println!(
            "{name}: {front} line pixels in front of the wall, {hidden} behind it; culled against the seed {} of {} \
             pieces drawn, without it {}",
            drawn(&counts),
            counts.pieces,
            drawn(&unseeded_counts)
        );
        assert!(front > 200 && hidden > 200, "{name}: the wall should split the lines ({front}, {hidden})");
        assert!(drawn(&counts) * 10 < drawn(&unseeded_counts) * 9, "{name}: {counts} against {unseeded_counts}");
        // Without the seed the lines behind the wall stay in the G-buffer (and darken their
        // neighbours in front).
        let behind = unseeded[1].data.iter().filter(|&&nd| is_geometry(nd) && z_of(nd) < wall_z).count();
        assert!(behind > 200, "{name}: {behind} pixels behind the wall without the seed");
    }
}

/// A host's projections of `camera` at `size`: reversed-Z with an infinite far plane, and
/// standard depth.
fn host_projections(camera: &Camera, size: (u32, u32)) -> [Mat4; 2] {
    let Projection::Perspective { fov_y_deg } = camera.projection else { unreachable!() };
    let (fov, aspect) = (fov_y_deg.to_radians(), size.0 as f32 / size.1 as f32);
    use glam::camera::rh::proj::directx;
    [directx::perspective_infinite_reverse(fov, aspect, 0.1), directx::perspective(fov, aspect, 0.1, 1000.0)]
}

fn read_texture_vec4(gpu: &lineao::Gpu, texture: &wgpu::Texture) -> Vec<[f32; 4]> {
    bytemuck::pod_collect_to_vec(&lineao::readback::read_texture(&gpu.device, &gpu.queue, texture).unwrap().bytes)
}

/// Geometry outside the bounds' depth range is counted (`pixels_outside_bounds`), never
/// silently clamped: none with the sphere's own bounds, and with bounds of half its radius the
/// pixels whose analytic depth lies outside the smaller range.
#[test]
fn geometry_outside_the_bounds_is_counted() {
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let (centre, radius, triangles, camera) = sphere_scene();
    let size = (160u32, 120u32);
    let view_matrix = camera.view_matrix();
    let proj = glam::camera::rh::proj::directx::perspective(45f32.to_radians(), 4.0 / 3.0, 5.0, 200.0);
    let depth = host_depth(&gpu, &triangles, proj * view_matrix, size, 1, false);
    let depth = depth.create_view(&Default::default());
    let mut chain = AoChain::new(d, common::OUTPUT_FORMAT, ChainSettings::default()).unwrap();
    chain.resize(size.0, size.1).unwrap();
    let mut host = HostAo::new(d, chain, HostConfig::default()).unwrap();
    assert_eq!(host.pixels_outside_bounds(d).unwrap(), None, "no host frame yet");
    for (scale, name) in [(1.0, "the sphere's bounds"), (0.5, "half its radius")] {
        let bounds = Bounds { center: centre, radius: radius * scale };
        let view = FrameView::from_matrices(view_matrix, proj, size.0, size.1, &bounds);
        host.prepare(d, q, view).unwrap();
        let mut encoder = d.create_command_encoder(&Default::default());
        host.encode(d, &mut encoder, &HostInputs { depth: &depth, normals: None, color: None }, None).unwrap();
        q.submit([encoder.finish()]);
        d.poll(wgpu::PollType::wait_indefinitely()).unwrap();
        let counted = host.pixels_outside_bounds(d).unwrap().expect("the frame has run");
        // The analytic count: pixels whose sphere hit lies outside [near, far].
        let inv_proj = proj.inverse();
        let sphere_view = (view_matrix * centre.extend(1.0)).xyz();
        let mut expected = 0;
        for y in 0..size.1 {
            for x in 0..size.0 {
                let (o, dir) = pixel_ray(&view, inv_proj, [x, y]);
                let oc = o - sphere_view;
                let (b, c) = (oc.dot(dir), oc.dot(oc) - radius * radius);
                if b * b - c > 0.0 {
                    let z = -(o + (-b - (b * b - c).sqrt()) * dir).z;
                    expected += (z < view.near * (1.0 - 1e-4) || z > view.far * (1.0 + 1e-4)) as u32;
                }
            }
        }
        println!("{name}: {counted} pixels outside counted, {expected} analytic");
        let slack = (expected as f32 * 0.03).max(0.0) as u32 + 2 * (size.0 + size.1) / 10;
        assert!(counted.abs_diff(expected) <= slack, "{name}: {counted} vs {expected}");
        if scale == 1.0 {
            assert_eq!(counted, 0, "{name}: nothing lies outside the sphere's own bounds");
        } else {
            assert!(counted > 1000, "{name}: {counted}");
        }
    }
}
