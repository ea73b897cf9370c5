//! Bevy apps rendering to images without a window, on whatever adapter wgpu finds (lavapipe on
//! CI): the plugin's AO equals lineao's standalone chains fed the same buffers, read in the
//! render world right after Bevy submitted the frame.

use std::sync::{Arc, Mutex};

use bevy::app::PluginsState;
use bevy::camera::Hdr;
use bevy::camera::RenderTarget;
use bevy::core_pipeline::prepass::{DepthPrepass, ViewPrepassTextures};
use bevy::prelude::*;
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::sync_world::MainEntity;
use bevy::render::{Render, RenderApp, RenderSystems};
use lineao::passes::nd_from_depth::HostNormals;
use lineao::reference::{Image as AoImage, NdImage};
use lineao::{AoChain, AoMethod, Bounds, ChainSettings, FrameView, HostAo, HostConfig, HostInputs, LineGeometry, wgpu};
use lineao_bevy::{LineAo, LineAoPlugin, LineAoViews, Polylines};

const SIZE: (u32, u32) = (192, 144);
const EYE: Vec3 = Vec3::new(0.0, 3.0, 6.0);
const LOOK_AT: Vec3 = Vec3::new(0.0, 0.5, 0.0);
/// Bevy's default perspective: 45° vertical, near plane 0.1.
const FOV_Y: f32 = std::f32::consts::FRAC_PI_4;
const NEAR: f32 = 0.1;

/// A Bevy app with the default plugins (no window, no log subscriber: tests share a process)
/// and lineao's, ready to `update`.
fn app() -> App {
    let mut app = App::new();
    let plugins = DefaultPlugins.build().disable::<bevy::log::LogPlugin>();
    #[cfg(feature = "window")]
    let plugins = plugins.disable::<bevy::winit::WinitPlugin>().set(WindowPlugin {
        primary_window: None,
        exit_condition: bevy::window::ExitCondition::DontExit,
        ..default()
    });
    app.add_plugins((plugins, LineAoPlugin));
    while app.plugins_state() == PluginsState::Adding {
        bevy::tasks::tick_global_task_pools_on_main_thread();
    }
    app.finish();
    app.cleanup();
    app
}

/// An image a camera renders into (readable).
fn target(app: &mut App, format: TextureFormat) -> Handle<Image> {
    let mut image = Image::new_target_texture(SIZE.0, SIZE.1, format, None);
    image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
    app.world_mut().resource_mut::<Assets<Image>>().add(image)
}

/// A ground plane 8 m wide, a 1 m cube standing on it at the origin and a light.
fn meshes(app: &mut App) {
    let world = app.world_mut();
    let ground = world.resource_mut::<Assets<Mesh>>().add(Plane3d::default().mesh().size(8.0, 8.0));
    let cube = world.resource_mut::<Assets<Mesh>>().add(Cuboid::new(1.0, 1.0, 1.0));
    let material = world.resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial::default());
    world.spawn((Mesh3d(ground), MeshMaterial3d(material.clone())));
    world.spawn((Mesh3d(cube), MeshMaterial3d(material), Transform::from_xyz(0.0, 0.5, 0.0)));
    world.spawn((DirectionalLight::default(), Transform::from_xyz(2.0, 4.0, 1.0).looking_at(Vec3::ZERO, Vec3::Y)));
}

/// The same sphere the plugin finds: around the ground's and the cube's boxes.
fn mesh_bounds() -> Bounds {
    let mut corners = Vec::new();
    for (center, half) in [(Vec3::ZERO, Vec3::new(4.0, 0.0, 4.0)), (Vec3::new(0.0, 0.5, 0.0), Vec3::splat(0.5))] {
        for i in 0..8 {
            let sign = Vec3::new([-1.0, 1.0][i & 1], [-1.0, 1.0][(i >> 1) & 1], [-1.0, 1.0][i >> 2]);
            corners.push((center + sign * half).to_array());
        }
    }
    Bounds::of_points(&corners).unwrap()
}

/// Twelve helices side by side left of the cube, 1.2 m above the ground: world-space points.
fn helices() -> Lines {
    let (mut positions, mut offsets) = (Vec::new(), vec![0]);
    for k in 0..12 {
        let phase = k as f32 * 0.5;
        for i in 0..120 {
            let t = i as f32 / 119.0;
            let a = phase + t * 12.0;
            positions.push([-2.4 + 0.25 * a.cos() + 0.06 * k as f32, 0.4 + 1.6 * t, 0.25 * a.sin()]);
        }
        offsets.push(positions.len() as u64);
    }
    (positions, offsets)
}

fn camera(app: &mut App, target: Handle<Image>, ao: Option<LineAo>) -> Entity {
    let mut camera = app.world_mut().spawn((
        Camera3d::default(),
        RenderTarget::Image(target.into()),
        Msaa::Off,
        Transform::from_translation(EYE).looking_at(LOOK_AT, Vec3::Y),
    ));
    if let Some(ao) = ao {
        camera.insert(ao);
    }
    camera.id()
}

/// The test's own matrices of that camera (not read from Bevy): glam's look-at and Bevy's
/// reversed-Z infinite perspective.
fn matrices() -> (lineao::glam::Mat4, lineao::glam::Mat4) {
    use lineao::glam::{Vec3 as V, camera::rh};
    let v = |v: Vec3| V::from_array(v.to_array());
    let view = rh::view::look_at_mat4(v(EYE), v(LOOK_AT), V::Y);
    let proj = rh::proj::directx::perspective_infinite_reverse(FOV_Y, SIZE.0 as f32 / SIZE.1 as f32, NEAR);
    (view, proj)
}

/// The plugin's meshes AO and ND map.
type MeshesAo = (AoImage<f32>, NdImage);
/// Polylines: points and offsets.
type Lines = (Vec<[f32; 3]>, Vec<u64>);

/// The standalone chains to run beside the plugin's: the meshes' settings, the lines' points.
type Standalone = (ChainSettings, Option<Lines>);

/// What a render-world check hands back to the test.
#[derive(Default)]
struct Captured {
    /// Per camera (main-world entity): the warnings, the plugin's meshes AO and ND map.
    views: Vec<(Entity, Vec<String>, Option<MeshesAo>)>,
    /// The meshes' AO of the standalone `HostAo` over the same prepass, for the first camera.
    standalone_meshes: Option<AoImage<f32>>,
    /// The lines: the plugin's overlay AO and ND map, and a standalone chain's AO.
    lines: Option<(AoImage<f32>, NdImage, AoImage<f32>)>,
}

/// Shared between the test and the render world: when to look, and what was seen.
#[derive(Resource, Clone, Default)]
struct Probe {
    capture: Arc<Mutex<bool>>,
    captured: Arc<Mutex<Option<Captured>>>,
    /// The standalone comparisons to run: the meshes' settings, and the lines' points.
    standalone: Arc<Mutex<Option<Standalone>>>,
    /// The bounds the standalone lines are framed by, where not their own (the plugin frames
    /// every polyline, shown or selected out).
    bounds: Arc<Mutex<Option<Bounds>>>,
}

fn read_ao(d: &wgpu::Device, q: &wgpu::Queue, view: &wgpu::TextureView) -> AoImage<f32> {
    let data = lineao::readback::read_texture(d, q, view.texture()).unwrap();
    AoImage { width: data.width as usize, height: data.height as usize, data: data.to_f32() }
}

fn read_nd(d: &wgpu::Device, q: &wgpu::Queue, chain: &AoChain) -> NdImage {
    lineao::readback::read_rgba(d, q, &chain.targets().unwrap().nd[0]).unwrap()
}

/// Runs after Bevy submitted the frame (between `Render` and `Cleanup`).
fn capture(
    probe: Res<Probe>,
    views: Res<LineAoViews>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    cameras: Query<(&MainEntity, Option<&ViewPrepassTextures>)>,
) {
    if !std::mem::take(&mut *probe.capture.lock().unwrap()) {
        return;
    }
    let (d, q): (&wgpu::Device, &wgpu::Queue) = (device.wgpu_device(), &queue);
    let mut captured = Captured::default();
    let mut cameras: Vec<_> = cameras.iter().collect();
    cameras.sort_by_key(|(main, _)| main.id());
    for (main, prepass) in cameras {
        let Some(view) = views.get(main.id()) else { continue };
        let mut warnings: Vec<String> = view.warnings().map(String::from).collect();
        warnings.sort();
        let meshes = view.meshes().and_then(|host| {
            let ao = host.chain().ao_view()?;
            Some((read_ao(d, q, ao), read_nd(d, q, host.chain())))
        });
        if captured.standalone_meshes.is_none()
            && let (Some(prepass), Some((settings, lines))) = (prepass, probe.standalone.lock().unwrap().clone())
        {
            let (view_m, proj) = matrices();
            let mut chain = AoChain::new(d, wgpu::TextureFormat::Rgba8UnormSrgb, settings).unwrap();
            chain.resize(SIZE.0, SIZE.1).unwrap();
            let normals = Some(HostNormals { world_space: true, unorm: true });
            let config = HostConfig { depth_samples: 1, reversed_z: true, normals };
            let mut host = HostAo::new(d, chain, config).unwrap();
            host.prepare(d, q, FrameView::from_matrices(view_m, proj, SIZE.0, SIZE.1, &mesh_bounds())).unwrap();
            let inputs = HostInputs {
                depth: prepass.depth_only_view().unwrap(),
                normals: prepass.normal_view().map(|v| &**v),
                color: None,
            };
            let mut encoder = d.create_command_encoder(&Default::default());
            host.encode(d, &mut encoder, &inputs, None).unwrap();
            q.submit([encoder.finish()]);
            captured.standalone_meshes = Some(read_ao(d, q, host.chain().ao_view().unwrap()));

            if let (Some((positions, offsets)), Some(overlay)) = (lines, view.lines()) {
                let geometry = LineGeometry::new(d, q, &positions, &offsets).unwrap();
                let settings = overlay.chain().settings().clone();
                let mut chain = AoChain::new(d, wgpu::TextureFormat::Rgba8UnormSrgb, settings).unwrap();
                chain.resize(SIZE.0, SIZE.1).unwrap();
                let lg = |v: Vec3| lineao::glam::Vec3::from_array(v.to_array());
                let camera = lineao::Camera {
                    eye: lg(EYE),
                    target: lg(LOOK_AT),
                    up: lineao::glam::Vec3::Y,
                    projection: lineao::Projection::Perspective { fov_y_deg: FOV_Y.to_degrees() },
                };
                let bounds = probe.bounds.lock().unwrap().unwrap_or(geometry.bounds.unwrap());
                chain.prepare(d, q, &camera, &bounds).unwrap();
                let output = lineao::targets::Target::output(d, "test", SIZE, wgpu::TextureFormat::Rgba8UnormSrgb);
                let mut encoder = d.create_command_encoder(&Default::default());
                chain.encode(&mut encoder, &geometry, &output.view).unwrap();
                q.submit([encoder.finish()]);
                let plugin = overlay.chain();
                captured.lines = Some((
                    read_ao(d, q, plugin.ao_view().unwrap()),
                    read_nd(d, q, plugin),
                    read_ao(d, q, chain.ao_view().unwrap()),
                ));
            }
        }
        captured.views.push((main.id(), warnings, meshes));
    }
    *probe.captured.lock().unwrap() = Some(captured);
}

/// Runs `frames` frames, then one more that the render world captures.
fn run(app: &mut App, frames: usize) -> Captured {
    let probe = app.sub_app(RenderApp).world().resource::<Probe>().clone();
    for _ in 0..frames {
        app.update();
    }
    *probe.capture.lock().unwrap() = true;
    app.update();
    probe.captured.lock().unwrap().take().expect("the render world captured the frame")
}

fn probed_app() -> (App, Probe) {
    let mut app = app();
    let probe = Probe::default();
    let render = app.sub_app_mut(RenderApp);
    render.insert_resource(probe.clone());
    render.add_systems(Render, capture.after(RenderSystems::Render).before(RenderSystems::Cleanup));
    (app, probe)
}

/// The pixel a world point projects to, by the test's own matrices.
fn pixel_of(p: Vec3) -> (usize, usize) {
    let (view, proj) = matrices();
    let ndc = (proj * view).project_point3(lineao::glam::Vec3::from_array(p.to_array()));
    let x = (ndc.x * 0.5 + 0.5) * SIZE.0 as f32;
    let y = (0.5 - ndc.y * 0.5) * SIZE.1 as f32;
    (x as usize, y as usize)
}

/// Lines and meshes in one Bevy frame: the meshes' AO is what lineao's `HostAo` makes of the
/// same prepass, with the camera's matrices and the scene's bounds computed by the test; the
/// lines' AO is what a standalone `AoChain` makes of the same polylines seen by the same camera;
/// both within docs/reference.md's agreement policy. On the open ground the default mesh settings
/// leave the AO under 0.02 and darken the cube's contact with the ground.
#[test]
fn the_plugin_adds_no_error_to_lineaos_chains() {
    let (mut app, probe) = probed_app();
    meshes(&mut app);
    let (positions, offsets) = helices();
    let polylines = app.world_mut().spawn(Polylines::new(positions.clone(), offsets.clone()).unwrap()).id();
    let image = target(&mut app, TextureFormat::Rgba8UnormSrgb);
    // The lines without levels of detail: the plugin's third frame against a standalone chain's
    // first, both the full strip's (with them, the plugin's frames after the first keep each piece
    // within half a pixel of it).
    let ao = LineAo { lines: ChainSettings { lod: false, ..ChainSettings::default() }, ..LineAo::default() };
    let camera = camera(&mut app, image, Some(ao.clone()));
    *probe.standalone.lock().unwrap() = Some((ao.settings.clone(), Some((positions, offsets))));
    let captured = run(&mut app, 3);

    let (entity, warnings, meshes) = &captured.views[0];
    assert_eq!(*entity, camera);
    assert!(warnings.is_empty(), "{warnings:?}");
    let (plugin, nd) = meshes.as_ref().expect("the meshes' AO ran");
    let standalone = captured.standalone_meshes.as_ref().unwrap();
    let bound = 2.0 / ao.settings.vo.samples as f32;
    let agreement = lineao::verify::check_policy(plugin, standalone, nd, bound).unwrap();
    println!("meshes: {agreement:?}");
    let geometry = nd.data.iter().filter(|p| p[..3] != [0.0; 3]).count();
    assert!(geometry > plugin.data.len() / 2, "the prepass holds the ground and the cube ({geometry} pixels)");

    // Open ground: points of the ground at least 1.5 m from the cube.
    let mut open = Vec::new();
    for x in [-3.0f32, -1.5, 1.5, 3.0] {
        for z in [-2.0f32, -1.5, 1.5, 2.0] {
            let (px, py) = pixel_of(Vec3::new(x, 0.0, z));
            if px < plugin.width && py < plugin.height {
                open.push(plugin.data[py * plugin.width + px]);
            }
        }
    }
    assert!(open.len() >= 10, "{} open-ground points in view", open.len());
    let open_mean = open.iter().sum::<f32>() / open.len() as f32;
    // The contacts: the ground 3 cm in front of the cube's faces that the camera sees.
    let contacts: Vec<f32> = [Vec3::new(0.0, 0.0, 0.53), Vec3::new(0.53, 0.0, 0.0), Vec3::new(-0.53, 0.0, 0.0)]
        .iter()
        .map(|&p| {
            let (px, py) = pixel_of(p);
            plugin.data[py * plugin.width + px]
        })
        .collect();
    println!("open ground mean AO {open_mean:.4} ({open:?}), contacts {contacts:?}");
    assert!(open_mean < 0.02, "open ground darkened: {open_mean}");
    // Composited with strength 1.75: at least 17 % darker than the open ground.
    assert!(contacts.iter().all(|&c| c > 0.1 && c > 20.0 * open_mean), "contacts not darker: {contacts:?}");

    let (plugin, nd, standalone) = captured.lines.as_ref().expect("the lines were drawn");
    let settings = ChainSettings::default();
    let bound = lineao::reference::line_ao_flip_bound(settings.line_ao.s_r, settings.line_ao.s_h);
    let agreement = lineao::verify::check_policy(plugin, standalone, nd, bound).unwrap();
    println!("lines: {agreement:?}");
    let lines = nd.data.iter().filter(|p| p[..3] != [0.0; 3]).count();
    assert!(lines > 500, "the helices cover {lines} pixels");

    // The left six helices selected out: the frame is a standalone chain's of the other six
    // alone (selected-out lines neither drawn nor occluding), no points uploaded again.
    let keep: Vec<bool> = (0..12).map(|k| k >= 6).collect();
    let (all_positions, all_offsets) = helices();
    let kept: Vec<[f32; 3]> = all_offsets
        .windows(2)
        .enumerate()
        .filter(|(k, _)| keep[*k])
        .flat_map(|(_, w)| all_positions[w[0] as usize..w[1] as usize].to_vec())
        .collect();
    let kept_offsets: Vec<u64> = (0..=6).map(|i| i * 120).collect();
    app.world_mut().entity_mut(polylines).insert(lineao_bevy::PolylineSelection::new(keep));
    *probe.bounds.lock().unwrap() = Bounds::of_points(&all_positions);
    *probe.standalone.lock().unwrap() = Some((ao.settings.clone(), Some((kept, kept_offsets))));
    let captured = run(&mut app, 3);
    let (plugin, nd, standalone) = captured.lines.as_ref().expect("the lines were drawn");
    let agreement = lineao::verify::check_policy(plugin, standalone, nd, bound).unwrap();
    println!("selected lines: {agreement:?}");
    let half = nd.data.iter().filter(|p| p[..3] != [0.0; 3]).count();
    assert!(half > 100 && half < lines * 3 / 4, "six helices cover {half} pixels, twelve {lines}");

    // The polylines despawned: the frame renders, nothing is said.
    app.world_mut().despawn(polylines);
    *probe.standalone.lock().unwrap() = None;
    let captured = run(&mut app, 1);
    assert!(captured.views[0].1.is_empty(), "{:?}", captured.views[0].1);
    assert!(captured.views[0].2.is_some(), "the meshes' AO still runs");
}

/// Two cameras, one HDR: each gets its own chains in its target's format; switching one's
/// method at run time rebuilds its chain and changes its AO, the other's stays; a camera
/// without the depth prepass renders, without AO, with a warning that names what to add;
/// settings lineao refuses are said once and the effect is off until they change.
#[test]
fn cameras_switches_missing_prepass_and_bad_settings() {
    let (mut app, _probe) = probed_app();
    meshes(&mut app);
    let ldr = target(&mut app, TextureFormat::Rgba8UnormSrgb);
    let hdr = target(&mut app, TextureFormat::Rgba16Float);
    let first = camera(&mut app, ldr.clone(), Some(LineAo::default()));
    let second = camera(&mut app, hdr, Some(LineAo::with_method(AoMethod::Ssao)));
    app.world_mut().entity_mut(second).insert(Hdr);
    let captured = run(&mut app, 2);
    let ao_of = |captured: &Captured, camera: Entity| {
        let (_, _, meshes) = captured.views.iter().find(|(e, ..)| *e == camera).unwrap();
        meshes.as_ref().unwrap().0.data.clone()
    };
    assert!(captured.views.iter().all(|(_, warnings, _)| warnings.is_empty()), "{:?}", captured.views[0].1);
    let (first_ao, second_ao) = (ao_of(&captured, first), ao_of(&captured, second));
    assert_ne!(first_ao, second_ao, "VO line and SSAO differ");

    // Switching the first camera to SSAO: the same AO as the second's (the same view).
    app.world_mut().get_mut::<LineAo>(first).unwrap().set_method(AoMethod::Ssao);
    let captured = run(&mut app, 0);
    let switched = ao_of(&captured, first);
    let differing = switched.iter().zip(&second_ao).filter(|(a, b)| (*a - *b).abs() > 1e-3).count();
    assert!(differing * 200 < switched.len(), "{differing} pixels differ after the switch");

    // Out of range: said once, no AO, no panic; fixed: AO again.
    let mut bad = LineAo::default();
    bad.settings.strength = -1.0;
    app.world_mut().entity_mut(first).insert(bad);
    app.world_mut().entity_mut(second).remove::<DepthPrepass>();
    let captured = run(&mut app, 1);
    for (camera, needle) in [(first, "invalid settings"), (second, "add DepthPrepass")] {
        let (_, warnings, _) = captured.views.iter().find(|(e, ..)| *e == camera).unwrap();
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains(needle), "{warnings:?}");
    }
    app.world_mut().entity_mut(first).insert(LineAo::default());
    let captured = run(&mut app, 0);
    assert_eq!(ao_of(&captured, first), first_ao, "the default settings again give the first frame's AO");

    // The target resized: the chain follows.
    let extent = bevy::render::render_resource::Extent3d { width: 96, height: 64, depth_or_array_layers: 1 };
    app.world_mut().resource_mut::<Assets<Image>>().get_mut(&ldr).unwrap().resize(extent);
    let captured = run(&mut app, 1);
    assert_eq!(ao_of(&captured, first).len(), 96 * 64);
}

/// MSAA: the AO reads the multisampled depth (normals reconstructed from it: Bevy's normal
/// prepass is multisampled too) and still darkens the contacts and leaves open ground; the
/// polylines, which need one sample, are skipped with a warning that says so.
#[test]
fn msaa_reads_the_multisampled_depth_and_skips_polylines() {
    let (mut app, _probe) = probed_app();
    meshes(&mut app);
    let (positions, offsets) = helices();
    app.world_mut().spawn(Polylines::new(positions, offsets).unwrap());
    let image = target(&mut app, TextureFormat::Rgba8UnormSrgb);
    let camera = camera(&mut app, image, Some(LineAo::default()));
    app.world_mut().entity_mut(camera).insert(Msaa::Sample4);
    let captured = run(&mut app, 2);
    let (_, warnings, meshes) = &captured.views[0];
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("Msaa::Off"), "{warnings:?}");
    let (ao, _) = meshes.as_ref().expect("the meshes' AO ran with MSAA");
    let at = |p: Vec3| {
        let (x, y) = pixel_of(p);
        ao.data[y * ao.width + x]
    };
    let (open, contact) = (at(Vec3::new(-1.5, 0.0, 1.5)), at(Vec3::new(0.0, 0.0, 0.53)));
    println!("MSAA 4: open ground {open}, contact {contact}");
    assert!(open < 0.02 && contact > 0.1, "open ground {open}, contact {contact}");
}
