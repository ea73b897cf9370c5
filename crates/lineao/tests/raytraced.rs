//! The GPU ray tracer against the CPU truth with the same rays (sequence, seed, frame indices):
//! lines, tubes and a mesh, a scene spread over many texture layers, progressive accumulation and
//! its restart, the cap, and linear falloff.

mod common;

use std::sync::Arc;

use common::{OUTPUT_FORMAT, gpu};
use glam::Vec3;
use lineao::passes::meshes::MeshGeometry;
use lineao::readback::{read_f32, read_rgba};
use lineao::reference::{Image, NdImage};
use lineao::targets::Target;
use lineao::truth::{self, Bvh, Falloff};
use lineao::{AoChain, AoMethod, ChainSettings, Gpu, LineGeometry, RayGeometry, RayScene, SurfaceSettings};
use lineao::{Bounds, Camera, FrameView, Projection};

const SIZE: (u32, u32) = (128, 96);

/// The scene: helical polylines, and optionally a square under them.
struct Scene {
    positions: Vec<[f32; 3]>,
    offsets: Vec<u64>,
    radii: Option<Vec<f32>>,
    mesh: Option<([[f32; 3]; 4], [u32; 6])>,
}

impl Scene {
    fn lines(count: usize) -> Scene {
        let (positions, offsets) = common::polylines(count, 0.3);
        Scene { positions, offsets, radii: None, mesh: None }
    }

    fn with_mesh(mut self) -> Scene {
        let (s, y) = (45.0, -42.0);
        self.mesh = Some(([[-s, y, -s], [s, y, -s], [s, y, s], [-s, y, s]], [0, 2, 1, 0, 3, 2]));
        self
    }

    fn meshes(&self) -> Vec<(&[[f32; 3]], &[u32])> {
        self.mesh.iter().map(|(p, i)| (&p[..], &i[..])).collect()
    }
}

/// A chain tracing `scene` on the GPU, frame after frame.
struct Tracer {
    gpu: Gpu,
    chain: AoChain,
    lines: LineGeometry,
    mesh: Option<MeshGeometry>,
    output: Target,
    bounds: Bounds,
}

impl Tracer {
    fn new(scene: &Scene, settings: ChainSettings, max_width: Option<u32>) -> Tracer {
        let gpu = gpu();
        let (d, q) = (&gpu.device, &gpu.queue);
        let lines = LineGeometry::new(d, q, &scene.positions, &scene.offsets).unwrap();
        let mesh = scene.mesh.map(|(p, i)| MeshGeometry::new(d, q, &p, &[[0.0, 1.0, 0.0]; 4], &i).unwrap());
        let mut bounds = lines.bounds.unwrap();
        if let Some(m) = &mesh {
            bounds = bounds.union(&m.bounds.unwrap());
        }
        let meshes = scene.meshes();
        let radii = scene.radii.as_deref();
        let geometry = RayGeometry { positions: &scene.positions, offsets: &scene.offsets, radii, meshes: &meshes };
        let ray_scene = match max_width {
            Some(width) => RayScene::with_max_width(d, q, &geometry, width).unwrap(),
            None => RayScene::new(d, q, &geometry).unwrap(),
        };
        if max_width.is_some() {
            assert!(ray_scene.layers() >= 3, "{} layers", ray_scene.layers());
        }
        let mut chain = AoChain::new(d, OUTPUT_FORMAT, settings).unwrap();
        chain.resize(SIZE.0, SIZE.1).unwrap();
        chain.set_ray_scene(d, Some(Arc::new(ray_scene)));
        let output = Target::output(d, "test::output", SIZE, OUTPUT_FORMAT);
        Tracer { gpu, chain, lines, mesh, output, bounds }
    }

    /// One frame from `camera`: the G-buffer's ND map and the accumulated AO.
    fn frame(&mut self, camera: &Camera) -> (NdImage, Image<f32>) {
        let (d, q) = (&self.gpu.device, &self.gpu.queue);
        self.chain.prepare(d, q, camera, &self.bounds).unwrap();
        let mut encoder = d.create_command_encoder(&Default::default());
        let meshes: Vec<&MeshGeometry> = self.mesh.iter().collect();
        self.chain.encode(&mut encoder, (&self.lines, &meshes[..]), &self.output.view).unwrap();
        q.submit([encoder.finish()]);
        let t = self.chain.targets().unwrap();
        (read_rgba(d, q, &t.nd[0]).unwrap(), read_f32(d, q, &t.ao).unwrap())
    }
}

/// The CPU truth with `rays` rays on the chain's last frame.
fn cpu_truth(tracer: &Tracer, scene: &Scene, nd: &NdImage, rays: u32) -> Image<f32> {
    let s = tracer.chain.settings();
    let view = tracer.chain.frame_view().unwrap();
    let cones = match &s.tubes {
        Some(t) => truth::tube_cones(&scene.positions, &scene.offsets, t.radius_world, scene.radii.as_deref()),
        None => truth::line_cones(&scene.positions, &scene.offsets, view, s.line_width_px),
    };
    let triangles = scene.meshes().iter().flat_map(|(p, i)| truth::mesh_triangles(p, i)).collect();
    let bvh = Bvh::build(cones, triangles);
    let frame = truth::Frame { nd, view, lines: s.tubes.is_none() };
    let settings = s.raytraced.truth(rays);
    let cancel = std::sync::atomic::AtomicBool::new(false);
    truth::compute(&bvh, &frame, &settings, &|_, _| {}, &cancel).unwrap().ao
}

/// Binary AO: the share of geometry pixels whose hit counts agree, the largest difference in
/// rays, and the number of geometry pixels.
fn compare_counts(nd: &NdImage, gpu: &Image<f32>, cpu: &Image<f32>, rays: u32) -> (f64, u32, usize) {
    let (mut same, mut worst, mut geometry) = (0usize, 0u32, 0usize);
    for ((g, c), texel) in gpu.data.iter().zip(&cpu.data).zip(&nd.data) {
        if !common::is_geometry(*texel) {
            assert_eq!((*g, *c), (0.0, 0.0), "background has no occlusion");
            continue;
        }
        let (g, c) = ((g * rays as f32).round() as i64, (c * rays as f32).round() as i64);
        geometry += 1;
        same += (g == c) as usize;
        worst = worst.max(g.abs_diff(c) as u32);
    }
    (same as f64 / geometry.max(1) as f64, worst, geometry)
}

fn settings(rays_per_frame: u32) -> ChainSettings {
    let mut s = ChainSettings { method: AoMethod::RayTraced, ..ChainSettings::default() };
    s.raytraced.rays_per_frame = rays_per_frame;
    s.raytraced.distance_world = 12.0;
    s
}

fn camera() -> Camera {
    common::cameras_for_polylines().0
}

/// ≥ 99.9 % of geometry pixels trace the same number of hits on both sides, the rest within one
/// ray (float ties), and there is occlusion to compare.
fn assert_same_hits(nd: &NdImage, gpu: &Image<f32>, cpu: &Image<f32>, rays: u32, what: &str) {
    let (share, worst, geometry) = compare_counts(nd, gpu, cpu, rays);
    let mean: f32 = cpu.data.iter().sum::<f32>() / geometry.max(1) as f32;
    eprintln!("{what}: {geometry} pixels, {:.4} % same hits, worst {worst} rays, mean AO {mean:.3}", 100.0 * share);
    assert!(geometry > 1000, "{what}: only {geometry} geometry pixels");
    assert!(mean > 0.05 && mean < 0.95, "{what}: mean AO {mean}: nothing to compare");
    assert!(share >= 0.999 && worst <= 1, "{what}: {share} same, worst {worst}");
}

#[test]
fn lines_accumulate_to_the_cpu_truth_with_the_same_rays_and_restart_when_the_camera_moves() {
    let scene = Scene::lines(60);
    let mut tracer = Tracer::new(&scene, settings(4), None);
    let (nd, first) = tracer.frame(&camera());
    assert_eq!(progress(&tracer.chain).rays_per_pixel, 4);
    assert_same_hits(&nd, &first, &cpu_truth(&tracer, &scene, &nd, 4), 4, "lines, 1 frame × 4");
    // Two more frames: rays 4..12 continue the same sequence.
    tracer.frame(&camera());
    let (nd, third) = tracer.frame(&camera());
    assert_eq!(progress(&tracer.chain).rays_per_pixel, 12);
    assert_same_hits(&nd, &third, &cpu_truth(&tracer, &scene, &nd, 12), 12, "lines, 3 frames × 4");
    // More rays per frame continue the picture: rays 12..20, the CPU truth's 20.
    let mut more = tracer.chain.settings().clone();
    more.raytraced.rays_per_frame = 8;
    tracer.chain.set_settings(&tracer.gpu.device, more).unwrap();
    let (nd, fourth) = tracer.frame(&camera());
    assert_eq!(progress(&tracer.chain).rays_per_pixel, 20);
    assert_same_hits(&nd, &fourth, &cpu_truth(&tracer, &scene, &nd, 20), 20, "lines, 3 frames × 4 + 8");
    // A second encode without a prepare records nothing: the same rays are not added twice.
    let (d, q) = (&tracer.gpu.device, &tracer.gpu.queue);
    let mut encoder = d.create_command_encoder(&Default::default());
    tracer.chain.encode(&mut encoder, &tracer.lines, &tracer.output.view).unwrap();
    q.submit([encoder.finish()]);
    assert_eq!(progress(&tracer.chain).rays_per_pixel, 20);
    assert_eq!(read_f32(d, q, &tracer.chain.targets().unwrap().ao).unwrap().data, fourth.data);
    // The camera moves: the count starts again, and the picture is the new view's first 8 rays.
    let moved = Camera { eye: Vec3::new(-60.0, 20.0, 120.0), ..camera() };
    let (nd, restarted) = tracer.frame(&moved);
    assert_eq!(progress(&tracer.chain).rays_per_pixel, 8);
    assert_same_hits(&nd, &restarted, &cpu_truth(&tracer, &scene, &nd, 8), 8, "lines, moved");
}

#[test]
fn tubes_with_per_vertex_radii_and_a_mesh_spread_over_many_texture_layers_match_the_cpu_truth() {
    let mut scene = Scene::lines(40).with_mesh();
    // Every third vertex carries its own radius; the others take the settings'.
    scene.radii = Some((0..scene.positions.len()).map(|v| if v % 3 == 0 { 1.6 } else { 0.0 }).collect());
    let mut s = settings(8);
    s.tubes = Some(lineao::TubeSettings { radius_world: 1.0 });
    s.surfaces = Some(SurfaceSettings::default());
    // Layers of 16 × 16 texels: every region wraps rows and spans layers.
    let mut tracer = Tracer::new(&scene, s, Some(16));
    let (nd, ao) = tracer.frame(&camera());
    assert_same_hits(&nd, &ao, &cpu_truth(&tracer, &scene, &nd, 8), 8, "tubes + mesh, split");
}

#[test]
fn an_orthographic_view_with_a_mesh_matches_and_the_cap_stops_tracing() {
    let scene = Scene::lines(40).with_mesh();
    let mut s = settings(4);
    s.surfaces = Some(SurfaceSettings::default());
    s.raytraced.max_rays = 6;
    let mut tracer = Tracer::new(&scene, s, None);
    let orthographic = Camera { projection: Projection::Orthographic { height: 110.0 }, ..camera() };
    tracer.frame(&orthographic);
    // The cap: the second frame traces the 2 rays left, the third none and keeps the picture.
    let (nd, capped) = tracer.frame(&orthographic);
    let capped_at = progress(&tracer.chain);
    assert_eq!((capped_at.rays_per_pixel, capped_at.frame_rays, capped_at.converged()), (6, 2, true));
    assert_same_hits(&nd, &capped, &cpu_truth(&tracer, &scene, &nd, 6), 6, "orthographic + mesh, capped at 6");
    let (_, after) = tracer.frame(&orthographic);
    assert_eq!(progress(&tracer.chain).frame_rays, 0);
    assert_eq!(after.data, capped.data);
}

#[test]
fn a_reach_given_as_a_share_of_the_scene_traces_as_its_length() {
    // 10 % of the scene's longest side (its lines' and the square's box) is the same picture as
    // that length given in world units.
    let scene = Scene::lines(40).with_mesh();
    let mut s = settings(4);
    s.surfaces = Some(SurfaceSettings::default());
    s.raytraced.distance_share = Some(0.1);
    let mut shared = Tracer::new(&scene, s.clone(), None);
    let square = scene.mesh.unwrap().0;
    let points = scene.positions.iter().chain(&square);
    let (lo, hi) = Bounds::corners_of(points).unwrap();
    let longest = (hi - lo).max_element();
    assert!(longest > 80.0, "the square's 90 world units: {longest}");
    let (nd, by_share) = shared.frame(&camera());
    (s.raytraced.distance_share, s.raytraced.distance_world) = (None, 0.1 * longest);
    let mut world = Tracer::new(&scene, s, None);
    let (_, by_length) = world.frame(&camera());
    assert_eq!(by_share.data, by_length.data);
    let geometry = nd.data.iter().filter(|t| common::is_geometry(**t)).count();
    let mean = by_share.data.iter().sum::<f32>() / geometry as f32;
    assert!(mean > 0.05, "occlusion to compare: {mean}");
}

#[test]
fn linear_falloff_matches_the_cpu_truth() {
    let scene = Scene::lines(60);
    let mut s = settings(8);
    s.raytraced.falloff = Falloff::Linear;
    let mut tracer = Tracer::new(&scene, s, None);
    let (nd, gpu) = tracer.frame(&camera());
    let cpu = cpu_truth(&tracer, &scene, &nd, 8);
    // Each of the 8 rays adds 1 − t/R: f32 against f64 moves t by far less than 1e-3 R, unless a
    // ray hits on one side only (a float tie), which moves the mean by up to 1/8.
    let (mut close, mut geometry) = (0usize, 0usize);
    for ((g, c), texel) in gpu.data.iter().zip(&cpu.data).zip(&nd.data) {
        if !common::is_geometry(*texel) {
            continue;
        }
        geometry += 1;
        close += ((g - c).abs() < 1e-3) as usize;
        assert!((g - c).abs() <= 0.126, "{g} vs {c}");
    }
    let share = close as f64 / geometry as f64;
    eprintln!("linear falloff: {geometry} pixels, {:.4} % within 1e-3", 100.0 * share);
    assert!(share >= 0.999, "{share}");
}

#[test]
fn a_scene_beyond_the_adapters_texture_arrays_is_too_large_and_no_scene_is_no_occlusion() {
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    // Layers of 2 × 2 texels: the adapter's layers hold 4 per layer, and 60 vertices a line
    // need more than that.
    let layers = d.limits().max_texture_array_layers as usize;
    let scene = Scene::lines(layers / 20 + 1);
    let geometry = RayGeometry { positions: &scene.positions, offsets: &scene.offsets, ..Default::default() };
    match RayScene::with_max_width(d, q, &geometry, 2) {
        Err(lineao::Error::TooLarge { limit, value, max, message }) => {
            // Two texels a vertex (a segment up to two).
            assert_eq!((limit, value), (lineao::Limit::TextureArrayTexels, 2 * scene.positions.len() as u64));
            assert!(value > max, "{value} of at most {max}");
            assert!(message.contains(&format!("{} vertices", scene.positions.len())), "{message}");
            assert!(message.contains("max_texture_array_layers"), "{message}");
        }
        other => panic!("expected TooLarge, got {:?}", other.map(|s| s.bytes())),
    }
    assert!(matches!(
        RayScene::with_max_width(d, q, &geometry, 3),
        Err(lineao::Error::OutOfRange { setting: "RayScene::max_width", .. })
    ));
    // An empty scene uploads (a texel per texture) and hits nothing.
    let empty = RayScene::new(d, q, &RayGeometry::default()).unwrap();
    assert!(empty.is_empty());
}

#[test]
fn a_lost_device_is_an_error_to_stop_on_never_a_panic() {
    let scene = Scene::lines(20);
    let mut tracer = Tracer::new(&scene, settings(4), None);
    tracer.frame(&camera());
    assert_eq!(tracer.gpu.lost(), None);
    tracer.gpu.device.destroy();
    // A frame on the lost device records and submits without a panic (wgpu drops the work) …
    let (d, q) = (&tracer.gpu.device, &tracer.gpu.queue);
    tracer.chain.prepare(d, q, &camera(), &tracer.bounds);
    let mut encoder = d.create_command_encoder(&Default::default());
    tracer.chain.encode(&mut encoder, &tracer.lines, &tracer.output.view).unwrap();
    q.submit([encoder.finish()]);
    // … and the next wait says the device is gone: what a loop of frames stops on.
    match tracer.gpu.wait() {
        Err(lineao::Error::DeviceLost(why)) => assert!(why.contains("Destroyed"), "{why}"),
        other => panic!("expected DeviceLost, got {other:?}"),
    }
    assert!(tracer.gpu.lost().is_some());
    // Reading back is an error too.
    assert!(read_f32(d, q, &tracer.chain.targets().unwrap().ao).is_err());
}

#[test]
fn the_scene_takes_at_most_32_bytes_per_vertex_on_the_gpu() {
    // 180 000 vertices of lines (no radii): nodes, references, positions and streamline starts.
    let gpu = gpu();
    let (positions, offsets) = common::polylines(3000, 0.3);
    let geometry = RayGeometry { positions: &positions, offsets: &offsets, ..Default::default() };
    let scene = RayScene::new(&gpu.device, &gpu.queue, &geometry).unwrap();
    // The vertices alone are 16 bytes per vertex; the rest is the BVH.
    let (bytes, per_vertex) = (scene.bytes(), scene.bytes_per_vertex());
    eprintln!("{} vertices: {bytes} bytes, {per_vertex:.1} bytes per vertex", positions.len());
    assert_eq!(per_vertex, bytes as f64 / positions.len() as f64);
    assert!((16.0..=32.0).contains(&per_vertex), "{per_vertex} bytes per vertex");
}

#[test]
fn a_host_renderers_depth_traces_like_the_cpu_truth_through_the_embedding_api() {
    use lineao::passes::nd_from_depth::{HostConfig, HostInputs};
    // The host's scene: a sphere resting on a ground square, drawn by the host into its depth;
    // the same triangles are the ray tracer's scene.
    let gpu = gpu();
    let (d, q) = (&gpu.device, &gpu.queue);
    let mut triangles = common::sphere_triangles(Vec3::ZERO, 1.0, 24);
    let (g, y) = (4.0, -1.0);
    let ground = [[-g, y, -g], [g, y, -g], [g, y, g], [-g, y, g]];
    triangles.extend([0, 2, 1, 0, 3, 2].map(|i| ground[i]));
    let indices: Vec<u32> = (0..triangles.len() as u32).collect();
    let camera = Camera {
        eye: Vec3::new(1.0, 2.5, 5.5),
        target: Vec3::new(0.0, -0.5, 0.0),
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 45.0 },
    };
    let bounds = lineao::Bounds { center: Vec3::ZERO, radius: 6.0 };
    let view_matrix = camera.view_matrix();
    let proj = glam::camera::rh::proj::directx::perspective(45f32.to_radians(), 4.0 / 3.0, 0.5, 50.0);
    let depth = common::host_depth(&gpu, &triangles, proj * view_matrix, SIZE, 1, false);
    let depth = depth.create_view(&Default::default());

    let mut s = settings(8);
    s.raytraced.distance_world = 3.0;
    let mut chain = AoChain::new(d, OUTPUT_FORMAT, s.clone()).unwrap();
    chain.resize(SIZE.0, SIZE.1).unwrap();
    let meshes = [(&triangles[..], &indices[..])];
    let geometry = RayGeometry { meshes: &meshes, ..Default::default() };
    chain.set_ray_scene(d, Some(Arc::new(RayScene::new(d, q, &geometry).unwrap())));
    let mut host = lineao::HostAo::new(d, chain, HostConfig::default()).unwrap();
    let view = lineao::FrameView::from_matrices(view_matrix, proj, SIZE.0, SIZE.1, &bounds);
    let inputs = HostInputs { depth: &depth, normals: None, color: None };
    for _ in 0..2 {
        host.prepare(d, q, view).unwrap();
        let mut encoder = d.create_command_encoder(&Default::default());
        host.encode(d, &mut encoder, &inputs, None).unwrap();
        q.submit([encoder.finish()]);
    }
    let chain = host.chain();
    assert_eq!(progress(chain).rays_per_pixel, 16);
    let t = chain.targets().unwrap();
    let (nd, ao) = (read_rgba(d, q, &t.nd[0]).unwrap(), read_f32(d, q, &t.ao).unwrap());

    // The CPU truth over the G-buffer the host path derived, with the same 16 rays.
    let bvh = Bvh::build(Vec::new(), truth::mesh_triangles(&triangles, &indices));
    let frame = truth::Frame { nd: &nd, view: chain.frame_view().unwrap(), lines: false };
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let cpu = truth::compute(&bvh, &frame, &s.raytraced.truth(16), &|_, _| {}, &cancel).unwrap().ao;
    assert_same_hits(&nd, &ao, &cpu, 16, "host depth, sphere on a ground");
}

/// The denoiser's inputs and output after `frames` frames of a standalone ray-traced pass over
/// the G-buffer of a chain with no method: the accumulation, `nd[0]`, the denoised `ao`.
fn denoised_frames(scene: &Scene, s: &ChainSettings, frames: u32) -> (Image<[u32; 4]>, NdImage, Image<f32>, FrameView) {
    use lineao::method::raytraced::RayTracedAo;
    let drawing = ChainSettings { method: AoMethod::None, ..s.clone() };
    let mut tracer = Tracer::new(scene, drawing, None);
    tracer.frame(&camera());
    let (d, q) = (&tracer.gpu.device, &tracer.gpu.queue);
    let (targets, view) = (tracer.chain.targets().unwrap(), *tracer.chain.frame_view().unwrap());
    let meshes = scene.meshes();
    let geometry = RayGeometry {
        positions: &scene.positions,
        offsets: &scene.offsets,
        radii: scene.radii.as_deref(),
        meshes: &meshes,
    };
    let mut pass = RayTracedAo::new(d);
    pass.set_scene(Some(Arc::new(RayScene::new(d, q, &geometry).unwrap())));
    pass.resize(d, targets);
    for _ in 0..frames {
        pass.prepare(q, targets, &view, s);
        let mut encoder = d.create_command_encoder(&Default::default());
        pass.encode(&mut encoder, targets, None, None);
        q.submit([encoder.finish()]);
    }
    let bytes = lineao::readback::read_buffer(d, q, pass.accumulation().unwrap()).unwrap();
    let (w, h) = (targets.size.0 as usize, targets.size.1 as usize);
    let accumulation = Image { width: w, height: h, data: bytemuck::cast_slice(&bytes).to_vec() };
    (accumulation, read_rgba(d, q, &targets.nd[0]).unwrap(), read_f32(d, q, &targets.ao).unwrap(), view)
}

#[test]
fn the_denoiser_matches_its_cpu_reference_on_lines_and_tubes() {
    use lineao::reference::{ViewParams, ray_denoise};
    for tubes in [false, true] {
        let scene = Scene::lines(60);
        let mut s = settings(4);
        s.tubes = tubes.then_some(lineao::TubeSettings { radius_world: 1.0 });
        let denoise = lineao::RayDenoiseSettings::default();
        s.raytraced.denoise = Some(denoise.clone());
        let (accumulation, nd, gpu, view) = denoised_frames(&scene, &s, 2);
        let cpu = ray_denoise(&accumulation, &nd, &ViewParams::of(&view), &denoise, (8, tubes));
        let (mut worst, mut changed, mut geometry, mut own) = (0.0f32, 0usize, 0usize, 0usize);
        for ((g, c), (a, texel)) in gpu.data.iter().zip(&cpu.data).zip(accumulation.data.iter().zip(&nd.data)) {
            worst = worst.max((g - c).abs());
            if common::is_geometry(*texel) {
                geometry += 1;
                own += (a[2] != u32::MAX) as usize;
                changed += ((g - f32::from_bits(a[0]) / 8.0).abs() > 1e-3) as usize;
            }
        }
        let what = if tubes { "tubes" } else { "lines" };
        eprintln!(
            "{what}: {geometry} pixels ({own} with a segment), {changed} denoised, worst |GPU − CPU| {worst:.2e}"
        );
        // exp and pow on the GPU against Rust's: a few ulps of weights summed over 49 taps.
        assert!(worst < 1e-4, "{what}: {worst}");
        assert!(changed * 3 > geometry, "{what}: the denoiser changed only {changed} of {geometry} pixels");
        assert!(own * 100 > geometry * 99, "{what}: own segments on {own} of {geometry} pixels");
    }
}

#[test]
fn the_denoiser_brings_few_rays_closer_to_the_truth_and_fades_out() {
    let scene = Scene::lines(60);
    let mut s = settings(4);
    s.raytraced.denoise = Some(lineao::RayDenoiseSettings::default());
    let (accumulation, nd, denoised, _) = denoised_frames(&scene, &s, 1);
    // The truth with 16 times the rays (rays 0..64, the first 4 of them the frame's).
    let mut tracer = Tracer::new(&scene, settings(4), None);
    let (nd_truth, _) = tracer.frame(&camera());
    assert_eq!(nd_truth.data, nd.data, "the same G-buffer");
    let truth = cpu_truth(&tracer, &scene, &nd, 64);
    let rmse = |ao: &dyn Fn(usize) -> f32| {
        let geometry: Vec<usize> = (0..nd.data.len()).filter(|&i| common::is_geometry(nd.data[i])).collect();
        let sum: f64 = geometry.iter().map(|&i| ((ao(i) - truth.data[i]) as f64).powi(2)).sum();
        (sum / geometry.len() as f64).sqrt()
    };
    let raw = rmse(&|i| f32::from_bits(accumulation.data[i][0]) / 4.0);
    let smooth = rmse(&|i| denoised.data[i]);
    eprintln!("4 rays against 64: RMSE {raw:.4} as traced, {smooth:.4} denoised");
    assert!(smooth < 0.8 * raw, "{smooth} vs {raw}");
    // σ narrows as 1/√rays: past 4 · (σ/0.25)² rays per pixel the window is the pixel alone.
    let d = lineao::RayDenoiseSettings::default();
    assert!(d.spatial(4, false) > 0.0 && d.spatial(64, false) > 0.0);
    assert_eq!(d.spatial(145, false), 0.0);
}

/// The bundle-scale truth's identity (docs/reference.md): obscurance with the linear falloff over
/// [0, R] is binary AO averaged over radii R' uniform in [0, R] — a hit at t counts 1 − t/R,
/// the share of those radii beyond t. Checked numerically with the same rays: the mean of
/// binary truths at the midpoints of K bins of [0, R] against the linear truth at R.
#[test]
fn linear_falloff_is_binary_ao_averaged_over_uniform_radii() {
    with_cpu_truths(check_linear_falloff);
}

fn check_linear_falloff(nd: &NdImage, trace: &dyn Fn(&truth::TruthSettings) -> truth::Truth) {
    let reach = 6.0;
    let at = |distance_world: f32, falloff: Falloff| {
        trace(&truth::TruthSettings { rays: 32, distance_world, falloff, ..Default::default() })
    };
    let linear = at(reach, Falloff::Linear);
    const K: usize = 48;
    let binary: Vec<_> = (0..K).map(|k| at(reach * (k as f32 + 0.5) / K as f32, Falloff::None).ao).collect();
    let (mut sum_abs, mut worst, mut geometry) = (0.0f64, 0.0f32, 0usize);
    for (i, texel) in nd.data.iter().enumerate() {
        // Buried origins are AO 1 under both; the rest must agree.
        if !common::is_geometry(*texel) || linear.ao.data[i] >= 1.0 {
            continue;
        }
        let mean = binary.iter().map(|b| b.data[i]).sum::<f32>() / K as f32;
        let d = (mean - linear.ao.data[i]).abs();
        sum_abs += d as f64;
        worst = worst.max(d);
        geometry += 1;
    }
    let mean_abs = sum_abs / geometry as f64;
    eprintln!("linear vs mean of {K} binary: {geometry} pixels, mean |Δ| {mean_abs:.5}, worst {worst:.4}");
    assert!(geometry > 1000 && linear.ao.data.iter().any(|&a| a > 0.1), "occlusion to compare");
    // The midpoint rule moves each hit by at most 1/(2K); the origins' offset ε = 1e-3 R' moves
    // with R', so a ray grazing a line may hit at one radius and not another.
    assert!(mean_abs < 0.005, "mean |Δ| {mean_abs}");
    assert!(worst <= 1.0 / K as f32 + 0.05, "worst {worst}");
}

/// `TruthSettings::second`: one trace gives the local truth exactly as alone and the
/// bundle-scale one as its own trace does (up to the rays' origins: ε is 1e-3 of the local
/// reach for both, not of each).
#[test]
fn a_second_reach_from_the_same_rays_matches_its_own_trace() {
    with_cpu_truths(check_second_reach);
}

fn check_second_reach(nd: &NdImage, trace: &dyn Fn(&truth::TruthSettings) -> truth::Truth) {
    let local = truth::TruthSettings { rays: 32, distance_world: 2.0, ..Default::default() };
    let bundle = truth::TruthSettings { distance_world: 12.0, falloff: Falloff::Linear, ..local.clone() };
    let second = truth::Reach { distance_world: 12.0, falloff: Falloff::Linear };
    let both = trace(&truth::TruthSettings { second: Some(second), ..local.clone() });
    let (alone, bundle_alone) = (trace(&local), trace(&bundle));
    let (mut same, mut sum_abs, mut geometry) = (0usize, 0.0f64, 0usize);
    for (i, texel) in nd.data.iter().enumerate() {
        if !common::is_geometry(*texel) {
            continue;
        }
        geometry += 1;
        same += (both.ao.data[i] == alone.ao.data[i]) as usize;
        sum_abs += (both.second.as_ref().unwrap().data[i] - bundle_alone.ao.data[i]).abs() as f64;
    }
    let mean_abs = sum_abs / geometry as f64;
    eprintln!("second reach: {geometry} pixels, {same} local values equal, bundle mean |Δ| {mean_abs:.5}");
    assert!(same * 1000 >= geometry * 999, "{same} of {geometry}");
    assert!(mean_abs < 0.005, "{mean_abs}");
    assert!(bundle_alone.ao.data.iter().sum::<f32>() > alone.ao.data.iter().sum::<f32>(), "the longer reach sees more");
}

/// Renders 60 lines and hands `check` the frame's ND map and the CPU truth of that frame for
/// any settings (one BVH).
fn with_cpu_truths(check: impl FnOnce(&NdImage, &dyn Fn(&truth::TruthSettings) -> truth::Truth)) {
    let scene = Scene::lines(60);
    let mut tracer = Tracer::new(&scene, settings(8), None);
    let (nd, _) = tracer.frame(&camera());
    let view = tracer.chain.frame_view().unwrap();
    let cones = truth::line_cones(&scene.positions, &scene.offsets, view, tracer.chain.settings().line_width_px);
    let bvh = Bvh::build(cones, Vec::new());
    let frame = truth::Frame { nd: &nd, view, lines: true };
    let cancel = std::sync::atomic::AtomicBool::new(false);
    check(&nd, &|s| truth::compute(&bvh, &frame, s, &|_, _| {}, &cancel).unwrap());
}

/// How far the chain's ray tracer has come.
fn progress(chain: &AoChain) -> lineao::method::raytraced::RayProgress {
    chain.stage().and_then(|s| s.downcast::<lineao::method::raytraced::RayTracedAo>()).unwrap().progress()
}
