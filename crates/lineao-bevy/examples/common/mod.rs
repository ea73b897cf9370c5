//! What the examples share: the app (a window, or none for `--screenshot`), an orbit camera,
//! the method keys, and screenshots read back in the render world.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use bevy::app::PluginsState;
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::prelude::*;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::texture::GpuImage;
use bevy::render::{Render, RenderApp, RenderSystems};
use lineao_bevy::lineao::{AoMethod, wgpu};
use lineao_bevy::{LineAo, LineAoPlugin};

/// `--screenshot PATH`: render without a window, save the picture and exit.
pub fn screenshot_path() -> Option<PathBuf> {
    let args: Vec<String> = std::env::args().collect();
    args.iter().position(|a| a == "--screenshot").and_then(|i| args.get(i + 1)).map(PathBuf::from)
}

/// The app with Bevy's default plugins and lineao's: with a window titled `title`, or none.
pub fn app(title: &str, headless: bool) -> App {
    let mut app = App::new();
    let window = WindowPlugin {
        primary_window: (!headless).then(|| Window {
            title: title.into(),
            resolution: (1280, 800).into(),
            ..default()
        }),
        exit_condition: if headless {
            bevy::window::ExitCondition::DontExit
        } else {
            bevy::window::ExitCondition::OnAllClosed
        },
        ..default()
    };
    let plugins = DefaultPlugins.set(window);
    if headless {
        app.add_plugins((plugins.disable::<bevy::winit::WinitPlugin>(), LineAoPlugin));
    } else {
        app.add_plugins((plugins, LineAoPlugin));
    }
    app.add_systems(Update, (orbit, method_keys));
    app
}

/// An orbit around `target`: drag with the left button to turn, scroll to zoom.
#[derive(Component)]
pub struct Orbit {
    pub target: Vec3,
    pub distance: f32,
    pub yaw: f32,
    pub pitch: f32,
}

impl Orbit {
    /// The orbit whose camera sits at `eye`.
    pub fn looking_from(eye: Vec3, target: Vec3) -> Orbit {
        let d = eye - target;
        Orbit { target, distance: d.length(), yaw: d.x.atan2(d.z), pitch: (d.y / d.length()).asin() }
    }

    pub fn transform(&self) -> Transform {
        let rotation = Quat::from_euler(EulerRot::YXZ, self.yaw, -self.pitch, 0.0);
        Transform::from_translation(self.target + rotation * Vec3::Z * self.distance).looking_at(self.target, Vec3::Y)
    }
}

fn orbit(
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    mut cameras: Query<(&mut Orbit, &mut Transform)>,
) {
    for (mut orbit, mut transform) in &mut cameras {
        if buttons.pressed(MouseButton::Left) {
            orbit.yaw -= motion.delta.x * 0.005;
            orbit.pitch = (orbit.pitch + motion.delta.y * 0.005).clamp(-1.5, 1.5);
        }
        orbit.distance *= (1.0 - 0.1 * scroll.delta.y).clamp(0.5, 2.0);
        *transform = orbit.transform();
    }
}

/// Keys 1–4 switch the method of every camera that is not [`Fixed`] (the GPU ray tracer
/// needs a ray scene the plugin does not build yet); 0 turns its AO off and on.
fn method_keys(keys: Res<ButtonInput<KeyCode>>, mut cameras: Query<&mut LineAo, Without<Fixed>>) {
    let methods = [
        (KeyCode::Digit1, AoMethod::LineAo),
        (KeyCode::Digit2, AoMethod::Ssao),
        (KeyCode::Digit3, AoMethod::VoLine),
        (KeyCode::Digit4, AoMethod::VoArea),
    ];
    for (key, method) in methods {
        if keys.just_pressed(key) {
            for mut ao in &mut cameras {
                ao.set_method(method);
                info!("method: {}", method.name());
            }
        }
    }
    if keys.just_pressed(KeyCode::Digit0) {
        for mut ao in &mut cameras {
            let off = ao.settings.strength == 0.0;
            let strength = if off { LineAo::default().settings.strength } else { 0.0 };
            ao.settings.strength = strength;
        }
    }
}

/// A camera whose method the keys leave alone (the compare's reference side).
#[derive(Component)]
pub struct Fixed;

/// A 3D camera as the examples use it: no MSAA (polylines need it off) and a tonemapping
/// without lookup tables (Bevy's default one needs the `tonemapping_luts` feature, which this
/// crate leaves to the application).
pub fn camera_3d() -> impl Bundle {
    (Camera3d::default(), Msaa::Off, bevy::core_pipeline::tonemapping::Tonemapping::AcesFitted)
}

/// An RGBA8 picture: width, height, rows.
pub type Picture = (u32, u32, Vec<u8>);

/// A readable image for a camera to render into.
pub fn target_image(images: &mut Assets<Image>, width: u32, height: u32) -> Handle<Image> {
    let mut image = Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None);
    image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
    images.add(image)
}

/// Renders `frames` frames without a window, then reads `images` back (RGBA8, sRGB) after
/// Bevy submitted the last one.
pub fn render_images(app: &mut App, images: &[Handle<Image>], frames: usize) -> Vec<Picture> {
    #[derive(Resource, Clone)]
    struct Grab(Vec<AssetId<Image>>, Arc<Mutex<Option<Vec<Picture>>>>, Arc<Mutex<bool>>);
    fn grab(grab: Res<Grab>, gpu: Res<RenderAssets<GpuImage>>, device: Res<RenderDevice>, queue: Res<RenderQueue>) {
        if !std::mem::take(&mut *grab.2.lock().unwrap()) {
            return;
        }
        let (d, q): (&wgpu::Device, &wgpu::Queue) = (device.wgpu_device(), &queue);
        let read = |id: &AssetId<Image>| {
            let image = gpu.get(*id).expect("the image is on the GPU");
            let data = lineao_bevy::lineao::readback::read_texture(d, q, &image.texture).expect("readback");
            (data.width, data.height, data.bytes)
        };
        *grab.1.lock().unwrap() = Some(grab.0.iter().map(read).collect());
    }
    finish(app);
    let state = Grab(images.iter().map(Handle::id).collect(), Arc::default(), Arc::default());
    let render = app.sub_app_mut(RenderApp);
    render.insert_resource(state.clone());
    render.add_systems(Render, grab.after(RenderSystems::Render).before(RenderSystems::Cleanup));
    for _ in 0..frames {
        app.update();
    }
    *state.2.lock().unwrap() = true;
    app.update();
    state.1.lock().unwrap().take().expect("the render world read the images")
}

/// Finishes building an app that is updated by hand (what `App::run` does first).
pub fn finish(app: &mut App) {
    while app.plugins_state() == PluginsState::Adding {
        bevy::tasks::tick_global_task_pools_on_main_thread();
    }
    app.finish();
    app.cleanup();
}

/// Pictures side by side (same height) into one PNG.
pub fn save_side_by_side(path: &Path, pictures: &[Picture]) {
    let height = pictures[0].1;
    let width: u32 = pictures.iter().map(|p| p.0).sum();
    let mut rgba = vec![0u8; (width * height * 4) as usize];
    let mut x0 = 0;
    for (w, h, bytes) in pictures {
        assert_eq!(*h, height);
        for y in 0..*h as usize {
            let row = &bytes[y * *w as usize * 4..(y + 1) * *w as usize * 4];
            let at = (y * width as usize + x0) * 4;
            rgba[at..at + row.len()].copy_from_slice(row);
        }
        x0 += *w as usize;
    }
    let file = std::io::BufWriter::new(std::fs::File::create(path).expect("create the screenshot"));
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    encoder.write_header().and_then(|mut w| w.write_image_data(&rgba)).expect("write the screenshot");
    println!("wrote {} ({width} x {height})", path.display());
}
