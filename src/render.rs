//! `lineao render`: a tractography file or a built-in scene through the pass chain into a PNG (and `--dump`).

use anyhow::{Context, Result};
use glam::Vec3;
use lineao::camera::{Camera, Projection};
use lineao::passes::lines::LineGeometry;
use lineao::{
    AoChain, AoMethod, ChainSettings, Gpu, LineAoSettings, LineAoVariant, LineColor, SsaoSettings, VoSettings,
};
use lineao_tracts::scenes::ViewHint;

use crate::cli::{ColorArg, Method, RenderArgs, Variant};

/// The chain's settings from the command line.
pub fn settings(args: &RenderArgs, zoom_unit: f32) -> ChainSettings {
    ChainSettings {
        method: match args.method {
            Method::None => AoMethod::None,
            Method::Lineao => AoMethod::LineAo,
            Method::Ssao => AoMethod::Ssao,
            Method::VoLine => AoMethod::VoLine,
        },
        vo: VoSettings {
            // --samples counts the chosen method's samples; the other keeps its default.
            samples: args.samples.filter(|_| args.method == Method::VoLine).unwrap_or(VoSettings::default().samples),
            radius_world: args.radius,
            normal_clamp: !args.no_normal_clamp,
            thickness_world: args.thickness,
            noise_seed: args.noise_seed,
        },
        ssao: SsaoSettings {
            samples: args.samples.filter(|_| args.method == Method::Ssao).unwrap_or(SsaoSettings::default().samples),
            radius_world: args.radius,
            range_world: args.ssao_range.unwrap_or(args.radius),
            noise_seed: args.noise_seed,
        },
        line_ao: LineAoSettings {
            s_r: args.s_r,
            s_h: args.s_h,
            r0_px: args.r0,
            delta0: args.delta0,
            epsilon: args.epsilon,
            light_attenuation: !args.no_light_attenuation,
            noise_seed: args.noise_seed,
            guard_max_px: args.guard_max,
            variant: match args.variant {
                Variant::Paper => LineAoVariant::Paper,
                Variant::Reference => LineAoVariant::Reference,
            },
            reference_radius_px: args.reference_radius,
        },
        line_width_px: args.line_width,
        line_color: match args.color {
            ColorArg::Tangent => LineColor::Tangent,
            ColorArg::Constant(rgb) => LineColor::Constant(rgb),
        },
        background: args.background,
        strength: args.strength,
        debug_view: args.debug_view,
        zoom_unit: args.zoom_unit.unwrap_or(zoom_unit),
        ..ChainSettings::default()
    }
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let (name, tracts, hint) = match &args.file {
        Some(path) => {
            let loaded = crate::info::load(path)?;
            if !loaded.tractogram.has_points() {
                anyhow::bail!(
                    "{}: a .{} holds values without points; render its .tck",
                    path.display(),
                    loaded.format.name()
                );
            }
            let hint = ViewHint::for_tractogram(&loaded.tractogram);
            (path.display().to_string(), loaded.tractogram, hint)
        }
        None => {
            let vertices = args.vertices.unwrap_or(args.scene.default_vertices());
            let scene = args.scene.build(args.seed, vertices);
            (scene.kind.name().to_string(), scene.tractogram, scene.view)
        }
    };
    let settings = settings(args, hint.zoom_unit);
    settings.validate()?;
    let camera = Camera {
        eye: Vec3::from_array(args.eye.unwrap_or(hint.eye)),
        target: Vec3::from_array(args.target.unwrap_or(hint.target)),
        up: Vec3::from_array(args.up.unwrap_or(hint.up)),
        projection: match (args.ortho, args.fov) {
            (Some(height), _) => Projection::Orthographic { height },
            (None, fov) => Projection::Perspective { fov_y_deg: fov.unwrap_or(hint.fov_y_deg) },
        },
    };
    validate_camera(&camera)?;

    let gpu = Gpu::headless()?;
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &tracts.positions, &tracts.offsets)?;
    let bounds = geometry.bounds.with_context(|| format!("{name} has no finite points"))?;
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let mut chain = AoChain::new(&gpu.device, format, settings)?;
    if args.timings {
        chain.set_timing(&gpu.device, &gpu.queue, true);
    }
    chain.resize(args.width, args.height)?;
    chain.prepare(&gpu.device, &gpu.queue, &camera, &bounds);
    let target =
        lineao::targets::Target::output(&gpu.device, "lineao::render::output", (args.width, args.height), format);
    let mut encoder =
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::render") });
    chain.encode(&mut encoder, &geometry, &target.view);
    let start = std::time::Instant::now();
    gpu.queue.submit([encoder.finish()]);
    if args.timings {
        gpu.wait()?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        match chain.pass_times(&gpu.device)? {
            Some(times) => {
                for t in &times {
                    eprintln!("lineao: {:<12} {:9.2} ms (GPU)", t.name, t.ms);
                }
                eprintln!("lineao: {:<12} {:9.2} ms (GPU, sum)", "frame", times.iter().map(|t| t.ms).sum::<f64>());
            }
            None => eprintln!("lineao: frame {wall_ms:.2} ms (CPU wall time: the adapter has no timestamp queries)"),
        }
    }
    let image = lineao::readback::read_texture(&gpu.device, &gpu.queue, &target.texture)?;
    crate::output::write_png(&args.output, args.width, args.height, &image.bytes)?;
    if let Some(dir) = &args.dump {
        crate::dump::write(dir, &gpu, &chain, &camera)?;
    }
    eprintln!(
        "lineao: {} ({} streamlines, {} vertices) with {} on {} -> {}",
        name,
        geometry.streamlines,
        geometry.vertices,
        chain.settings().method.name(),
        gpu.describe(),
        args.output.display()
    );
    Ok(())
}

/// The camera a built-in scene suggests.
pub fn camera_from_hint(hint: &ViewHint) -> Camera {
    Camera {
        eye: Vec3::from_array(hint.eye),
        target: Vec3::from_array(hint.target),
        up: Vec3::from_array(hint.up),
        projection: Projection::Perspective { fov_y_deg: hint.fov_y_deg },
    }
}

fn validate_camera(camera: &Camera) -> Result<()> {
    let forward = camera.target - camera.eye;
    anyhow::ensure!(forward.length() > 0.0, "the camera's eye and target coincide");
    anyhow::ensure!(
        forward.cross(camera.up).length() > 1e-6 * forward.length() * camera.up.length(),
        "the camera's up vector is parallel to its view direction (or zero)"
    );
    match camera.projection {
        Projection::Perspective { fov_y_deg } => {
            anyhow::ensure!(fov_y_deg > 0.0 && fov_y_deg < 180.0, "--fov must be in (0, 180) degrees, got {fov_y_deg}")
        }
        Projection::Orthographic { height } => {
            anyhow::ensure!(height > 0.0 && height.is_finite(), "--ortho must be a positive height, got {height}")
        }
    }
    Ok(())
}
