//! Bevy's usual 3D scene — a ground, boxes, a sphere, a light — with lineao's AO in place of
//! Bevy's SSAO: the default mesh settings (Volumetric Obscurance with line samples, 0.5 m reach).
//!
//! `cargo run --example meshes --features window` (drag to turn, scroll to zoom, keys 1–4 for
//! LineAO, SSAO, VO line, VO area, 0 for none); `-- --screenshot meshes.png` renders it without
//! a window, with and without AO side by side; `-- --bench 30` times the plugin's passes against
//! lineao's standalone `HostAo` on the same prepass, frame by frame (GPU timestamps).

mod common;

use bevy::camera::RenderTarget;
use bevy::prelude::*;
use common::Orbit;
use lineao_bevy::LineAo;

fn scene(mut commands: Commands, mut meshes: ResMut<Assets<Mesh>>, mut materials: ResMut<Assets<StandardMaterial>>) {
    let material = |color: Color| StandardMaterial { base_color: color, perceptual_roughness: 0.8, ..default() };
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(10.0, 10.0))),
        MeshMaterial3d(materials.add(material(Color::srgb(0.75, 0.75, 0.72)))),
    ));
    let cube = meshes.add(Cuboid::new(1.0, 1.0, 1.0));
    let boxes = materials.add(material(Color::srgb(0.8, 0.55, 0.35)));
    for (x, z, s) in [(0.0, 0.0, 1.0), (1.3, -0.4, 0.6), (-1.1, 0.7, 0.45), (0.2, -1.6, 1.4)] {
        commands.spawn((
            Mesh3d(cube.clone()),
            MeshMaterial3d(boxes.clone()),
            Transform::from_xyz(x, 0.5 * s, z).with_scale(Vec3::splat(s)),
        ));
    }
    commands.spawn((
        Mesh3d(meshes.add(Sphere::new(0.4).mesh().uv(48, 24))),
        MeshMaterial3d(materials.add(material(Color::srgb(0.4, 0.6, 0.85)))),
        Transform::from_xyz(-0.4, 0.4, 1.3),
    ));
    commands.spawn((
        DirectionalLight { illuminance: 6000.0, shadow_maps_enabled: true, ..default() },
        Transform::from_xyz(3.0, 6.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
}

const EYE: Vec3 = Vec3::new(3.5, 3.0, 5.0);
const TARGET: Vec3 = Vec3::new(0.0, 0.4, 0.0);

fn main() {
    if let Some(frames) = std::env::args().skip_while(|a| a != "--bench").nth(1) {
        return bench::run(frames.parse().expect("--bench FRAMES"));
    }
    let screenshot = common::screenshot_path();
    let mut app = common::app("lineao in Bevy: meshes", screenshot.is_some());
    app.add_systems(Startup, scene);
    let orbit = || Orbit::looking_from(EYE, TARGET);
    let Some(path) = screenshot else {
        app.add_systems(Startup, move |mut commands: Commands| {
            commands.spawn((common::camera_3d(), LineAo::default(), orbit().transform(), orbit()));
        });
        app.run();
        return;
    };
    let (width, height) = (640, 480);
    let mut images = app.world_mut().resource_mut::<Assets<Image>>();
    let targets = [common::target_image(&mut images, width, height), common::target_image(&mut images, width, height)];
    for (i, target) in targets.iter().enumerate() {
        let mut camera = app.world_mut().spawn((
            common::camera_3d(),
            RenderTarget::Image(target.clone().into()),
            orbit().transform(),
        ));
        if i == 0 {
            camera.insert(LineAo::default());
        }
    }
    let pictures = common::render_images(&mut app, &targets, 4);
    common::save_side_by_side(&path, &pictures);
}

/// `--bench FRAMES`: what the plugin adds to a Bevy frame against lineao's standalone chain
/// doing the same work on the same view. Wall clock with the GPU waited for, not timestamps:
/// lavapipe's timestamps charge a pass with the unfinished rasterization before it (Bevy's main
/// pass), so they cannot split a frame that Bevy and lineao share.
mod bench {
    use std::sync::{Arc, Mutex};
    use std::time::Instant;

    use bevy::camera::RenderTarget;
    use bevy::core_pipeline::prepass::ViewPrepassTextures;
    use bevy::prelude::*;
    use bevy::render::renderer::{RenderDevice, RenderQueue};
    use bevy::render::view::ViewTarget;
    use bevy::render::{Render, RenderApp, RenderSystems};
    use lineao_bevy::lineao::passes::nd_from_depth::HostNormals;
    use lineao_bevy::lineao::{AoChain, FrameView, HostAo, HostConfig, HostInputs, wgpu};
    use lineao_bevy::{LineAo, LineAoViews};

    /// The standalone chain's wall time per frame (ms), while it runs.
    #[derive(Resource, Clone, Default)]
    struct Standalone(Arc<Mutex<Option<Vec<f64>>>>);

    /// After Bevy's submission: waits for the GPU (so a frame's wall time holds its GPU work);
    /// in the standalone phase, then runs lineao's `HostAo` over the same prepass and main
    /// texture into a texture of its own, and times that (submit to finish).
    #[allow(clippy::too_many_arguments)]
    fn after_frame(
        standalone: Res<Standalone>,
        views: Res<LineAoViews>,
        device: Res<RenderDevice>,
        queue: Res<RenderQueue>,
        cameras: Query<(&ViewPrepassTextures, &ViewTarget)>,
        mut plugin_view: Local<Option<(lineao_bevy::lineao::ChainSettings, FrameView)>>,
        mut host: Local<Option<(HostAo, lineao_bevy::lineao::targets::Target)>>,
    ) {
        let (d, q): (&wgpu::Device, &wgpu::Queue) = (device.wgpu_device(), &queue);
        d.poll(wgpu::PollType::wait_indefinitely()).unwrap();
        if let Some(chain) = views.iter().next().and_then(|v| v.meshes()).map(|h| h.chain()) {
            *plugin_view = Some((chain.settings().clone(), *chain.frame_view().unwrap()));
        }
        let mut times = standalone.0.lock().unwrap();
        let (Some(times), Some((settings, frame)), Ok((prepass, target))) =
            (times.as_mut(), &*plugin_view, cameras.single())
        else {
            return;
        };
        let format = target.main_texture_format();
        let (host, output) = host.get_or_insert_with(|| {
            let mut chain = AoChain::new(d, format, settings.clone()).unwrap();
            chain.resize(frame.width, frame.height).unwrap();
            let normals = Some(HostNormals { world_space: true, unorm: true });
            let output = lineao_bevy::lineao::targets::Target::output(d, "bench", (frame.width, frame.height), format);
            (HostAo::new(d, chain, HostConfig { depth_samples: 1, reversed_z: true, normals }).unwrap(), output)
        });
        let start = Instant::now();
        host.prepare(d, q, *frame).unwrap();
        let inputs = HostInputs {
            depth: prepass.depth_only_view().unwrap(),
            normals: prepass.normal_view().map(|v| &**v),
            color: Some(target.main_texture_view()),
        };
        let mut encoder = d.create_command_encoder(&Default::default());
        host.encode(d, &mut encoder, &inputs, Some(&output.view)).unwrap();
        q.submit([encoder.finish()]);
        d.poll(wgpu::PollType::wait_indefinitely()).unwrap();
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }

    fn median(mut v: Vec<f64>) -> f64 {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    }

    pub fn run(frames: usize) {
        let mut app = super::common::app("bench", true);
        app.add_systems(Startup, super::scene);
        let (width, height) = (1280, 720);
        let mut images = app.world_mut().resource_mut::<Assets<Image>>();
        let target = super::common::target_image(&mut images, width, height);
        let orbit = super::Orbit::looking_from(super::EYE, super::TARGET);
        let camera = app
            .world_mut()
            .spawn((
                super::common::camera_3d(),
                RenderTarget::Image(target.clone().into()),
                orbit.transform(),
                LineAo::default(),
            ))
            .id();
        let standalone = Standalone::default();
        super::common::finish(&mut app);
        let render = app.sub_app_mut(RenderApp);
        render.insert_resource(standalone.clone());
        render.add_systems(Render, after_frame.after(RenderSystems::Render).before(RenderSystems::Cleanup));
        let frame = |app: &mut App| {
            let start = Instant::now();
            app.update();
            start.elapsed().as_secs_f64() * 1e3
        };
        // Blocks of frames with and without LineAo, alternating (lavapipe's speed drifts): the
        // camera keeps its prepass without LineAo, and the standalone chain runs after each
        // frame of those blocks.
        let (mut with_ao, mut without, mut chain) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..4 {
            app.world_mut().entity_mut(camera).insert(LineAo::default());
            for _ in 0..2 {
                frame(&mut app);
            }
            with_ao.extend((0..frames.div_ceil(4)).map(|_| frame(&mut app)));
            app.world_mut().entity_mut(camera).remove::<LineAo>();
            for _ in 0..2 {
                frame(&mut app);
            }
            *standalone.0.lock().unwrap() = Some(Vec::new());
            let block: Vec<f64> = (0..frames.div_ceil(4)).map(|_| frame(&mut app)).collect();
            let times = standalone.0.lock().unwrap().take().unwrap();
            without.extend(block.iter().zip(&times).map(|(f, c)| f - c));
            chain.extend(times);
        }
        let frames = with_ao.len();
        let (with_ao, without, chain) = (median(with_ao), median(without), median(chain));
        let added = with_ao - without;
        println!(
            "{frames} frames at {width} x {height} (medians, wall clock with the GPU waited for): Bevy frame {without:.1} ms \
             without LineAo, {with_ao:.1} ms with it: the plugin adds {added:.1} ms; lineao's HostAo alone on the same \
             view {chain:.1} ms; added / standalone = {:.2}",
            added / chain
        );
    }
}
