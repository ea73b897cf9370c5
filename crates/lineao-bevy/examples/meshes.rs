//! Bevy's usual 3D scene — a ground, boxes, a sphere, a light — with lineao's AO in place of
//! Bevy's SSAO: the default mesh settings (Volumetric Obscurance with line samples, 0.5 m reach).
//!
//! `cargo run --example meshes --features window` (drag to turn, scroll to zoom, keys 1–4 for
//! LineAO, SSAO, VO line, VO area, 0 for none); `-- --screenshot meshes.png` renders it without
//! a window, with and without AO side by side.

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
