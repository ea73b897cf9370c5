//! A tractogram in Bevy: fixed-width lines drawn by lineao with LineAO, beside the same view
//! with Crytek SSAO in a second window.
//!
//! `cargo run --example tractogram --features window -- [FILE | --scene bundles|spiral|vortex]`
//! opens any file lineao-tracts reads (.trk, .tck, .trx, .vtk, … gzip'd or not) or a built-in
//! scene (default `bundles`). Drag to turn, scroll to zoom; keys 1–4 switch the first window's
//! method (LineAO, SSAO, VO line, VO area), 0 its AO off and on. `--no-compare`: one window.
//! `-- --screenshot compare.png` renders no AO | LineAO | SSAO side by side without a window.

mod common;

use bevy::camera::RenderTarget;
use bevy::prelude::*;
use bevy::window::WindowRef;
use common::{Fixed, Orbit};
use lineao_bevy::lineao::AoMethod;
use lineao_bevy::{LineAo, Polylines};
use lineao_tracts::{SceneKind, Tractogram, ViewHint};

/// The file or scene of the command line.
fn tractogram() -> Tractogram {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut args = args.iter().filter(|a| !a.starts_with("--no-"));
    let mut scene = "bundles".to_string();
    let mut file = None;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--scene" => scene = args.next().cloned().unwrap_or(scene),
            "--screenshot" => _ = args.next(),
            path => file = Some(path.to_string()),
        }
    }
    if let Some(path) = file {
        match lineao_tracts::load(&path) {
            Ok(loaded) => return loaded.tractogram,
            Err(error) => {
                eprintln!("{error}");
                std::process::exit(1);
            }
        }
    }
    let Some(kind) = SceneKind::ALL.into_iter().find(|k| k.name() == scene) else {
        eprintln!("no scene {scene}: bundles, spiral or vortex");
        std::process::exit(2);
    };
    kind.build(1, kind.default_vertices()).tractogram
}

fn main() {
    let tractogram = tractogram();
    let hint = ViewHint::for_tractogram(&tractogram);
    println!("{} streamlines, {} points", tractogram.offsets.len() - 1, tractogram.positions.len());
    // RAS+ (superior up) into Bevy's Y-up world.
    let ras_to_bevy = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    let orbit = move || Orbit::looking_from(ras_to_bevy * Vec3::from(hint.eye), ras_to_bevy * Vec3::from(hint.target));
    let projection =
        move || Projection::Perspective(PerspectiveProjection { fov: hint.fov_y_deg.to_radians(), ..default() });
    let polylines = (Polylines::from(tractogram), Transform::from_rotation(ras_to_bevy));
    let ssao = || LineAo::with_method(AoMethod::Ssao);

    let screenshot = common::screenshot_path();
    let compare = !std::env::args().any(|a| a == "--no-compare");
    let mut app = common::app("lineao in Bevy: LineAO", screenshot.is_some());
    app.insert_resource(ClearColor(Color::srgb(0.02, 0.02, 0.03)));
    app.world_mut().spawn(polylines);
    let Some(path) = screenshot else {
        app.add_systems(Startup, move |mut commands: Commands| {
            commands.spawn((common::camera_3d(), projection(), LineAo::default(), orbit().transform(), orbit()));
            if compare {
                let window = commands.spawn(Window { title: "lineao in Bevy: Crytek SSAO".into(), ..default() }).id();
                commands.spawn((
                    common::camera_3d(),
                    projection(),
                    ssao(),
                    Fixed,
                    RenderTarget::Window(WindowRef::Entity(window)),
                    orbit().transform(),
                    orbit(),
                ));
            }
        });
        app.run();
        return;
    };
    let (width, height) = (640, 560);
    let mut images = app.world_mut().resource_mut::<Assets<Image>>();
    let targets: Vec<_> = (0..3).map(|_| common::target_image(&mut images, width, height)).collect();
    // No AO (the lines' strength 0) | LineAO | Crytek SSAO.
    let mut none = LineAo::default();
    none.lines.strength = 0.0;
    for (target, ao) in targets.iter().zip([none, LineAo::default(), ssao()]) {
        app.world_mut().spawn((
            common::camera_3d(),
            projection(),
            ao,
            RenderTarget::Image(target.clone().into()),
            orbit().transform(),
        ));
    }
    let pictures = common::render_images(&mut app, &targets, 4);
    common::save_side_by_side(&path, &pictures);
}
