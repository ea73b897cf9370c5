//! The ray-traced ground truth of a rendered frame (`render --method raytraced`, `score`): the
//! frame's G-buffer read back, the BVH over what it drew, the truth on all cores with a progress
//! bar on a terminal, and Ctrl-C stopping it cleanly between rows.

use std::io::IsTerminal;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};
use lineao::method::raytraced::RayTracedAo;
use lineao::reference::Image;
use lineao::truth::{Bvh, LineShape, Truth, TruthSettings};
use lineao::{AoChain, Gpu};
use lineao_tracts::{Tractogram, TriangleMesh};

use crate::args::RenderArgs;

/// What the frame drew, on the CPU.
pub struct Scene<'a> {
    pub tracts: &'a Tractogram,
    pub surfaces: &'a [TriangleMesh],
    /// Per-vertex tube radii (`--tube-radius-field`).
    pub radii: Option<&'a [f32]>,
}

/// The CPU truth's settings from the command line (the ray-traced method's: `--rays`,
/// `--ao-distance`, `--ao-falloff`, `--ray-seed`), in a scene whose bounds' longest side is
/// `longest_side` world units (what `--ao-distance 20%` is a share of).
pub fn settings(args: &RenderArgs, longest_side: f32) -> TruthSettings {
    let rays = gpu_settings(args, longest_side);
    rays.truth(rays.max_rays)
}

/// The GPU ray tracer's settings from the command line, [`budget`]ed.
pub fn gpu_settings(args: &RenderArgs, longest_side: f32) -> lineao::RayTracedSettings {
    let mut rays = given(args).raytraced;
    budget(&mut rays, args, longest_side);
    rays
}

/// `--ao-distance` as given (`2`, `20%`).
pub fn reach_text(args: &RenderArgs) -> String {
    let (_, reach) = crate::method_args::described().find(|(_, s)| s.flag == "ao-distance").expect("described");
    reach.get(&given(args)).to_string()
}

/// The papers' settings with the described settings the command line gave.
fn given(args: &RenderArgs) -> lineao::ChainSettings {
    let mut chain = lineao::ChainSettings::papers();
    args.methods.apply(&mut chain);
    chain
}

/// What the session decides of the ray tracer's settings: the reach in world units (a share
/// of `longest_side`, the scene's bounds', where `--ao-distance` gives one), and unless
/// `--rays-per-frame` is given, all the rays at most [`RAYS_PER_FRAME`] per submitted frame.
pub fn budget(rays: &mut lineao::RayTracedSettings, args: &RenderArgs, longest_side: f32) {
    rays.resolve(longest_side);
    if !args.methods.gives("rays-per-frame") {
        rays.rays_per_frame = rays.max_rays.min(RAYS_PER_FRAME);
    }
}

/// Rays per pixel in one submitted frame of `render --method raytraced`: few enough that a frame
/// stays well under a desktop GPU's watchdog at 1280 × 1024 and 1 M vertices, many enough that
/// the G-buffer drawn again each frame costs little against them.
pub const RAYS_PER_FRAME: u32 = 64;

/// The ray tracer's scene of what the frame draws, built on all cores and uploaded, with a line
/// on stderr saying what it cost.
pub fn ray_scene(gpu: &Gpu, scene: &Scene) -> Result<lineao::RayScene> {
    let start = std::time::Instant::now();
    let meshes: Vec<(&[[f32; 3]], &[u32])> =
        scene.surfaces.iter().map(|m| (&m.positions[..], &m.indices[..])).collect();
    let geometry = lineao::RayGeometry {
        positions: &scene.tracts.positions,
        offsets: &scene.tracts.offsets,
        radii: scene.radii,
        meshes: &meshes,
    };
    let ray_scene = lineao::RayScene::new(&gpu.device, &gpu.queue, &geometry)?;
    eprintln!(
        "lineao: ray tracer's scene: {} MB on the GPU ({:.1} bytes per vertex, {} layer(s) per texture), built in {:.2} s",
        ray_scene.bytes() >> 20,
        ray_scene.bytes_per_vertex(),
        ray_scene.layers(),
        start.elapsed().as_secs_f64()
    );
    Ok(ray_scene)
}

/// Submits frames with `frame` until `chain`'s ray-traced picture has all its rays (the first
/// frame submitted already), with a progress bar on a terminal; Ctrl-C stops it with an error.
pub fn accumulate(
    gpu: &Gpu,
    chain: &mut AoChain,
    mut frame: impl FnMut(&mut AoChain) -> std::result::Result<(), lineao::Error>,
) -> Result<()> {
    let start = std::time::Instant::now();
    let progress = |chain: &AoChain| {
        chain
            .stage()
            .and_then(|s| s.downcast::<lineao::method::raytraced::RayTracedAo>())
            .map(|t| t.progress())
            .context("the ray-traced method is not active")
    };
    let first = progress(chain)?;
    let bar = std::io::stderr().is_terminal().then(|| {
        indicatif::ProgressBar::new(first.max_rays as u64).with_style(
            indicatif::ProgressStyle::with_template(
                "ray tracing (GPU) [{bar:40}] {pos}/{len} rays per pixel, {eta} left",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        )
    });
    let cancel = cancel_on_ctrl_c();
    loop {
        let now = progress(chain)?;
        if let Some(bar) = &bar {
            bar.set_position(now.rays_per_pixel as u64);
        }
        if now.converged() {
            break;
        }
        if cancel.load(Ordering::Relaxed) {
            anyhow::bail!("ray tracing stopped (Ctrl-C)");
        }
        frame(chain)?;
        // One frame in flight: the bar and Ctrl-C follow the GPU, not the queue; a lost device
        // ends it here.
        gpu.wait().context("ray tracing stopped")?;
    }
    gpu.wait().context("ray tracing stopped")?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let p = progress(chain)?;
    eprintln!(
        "lineao: ray traced {} rays per pixel on the GPU in {:.2} s",
        p.rays_per_pixel,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The GPU ray tracer's picture in `chain` as the truth's record: the mean, its standard error
/// from the sums of the rays' values and of their squares (as the CPU truth computes it), the
/// geometry and buried pixels. What `--dump` writes of a GPU-traced truth.
pub fn from_gpu(gpu: &Gpu, chain: &AoChain) -> Result<Truth> {
    let (d, q) = (&gpu.device, &gpu.queue);
    let progress = chain
        .stage()
        .and_then(|s| s.downcast::<lineao::method::raytraced::RayTracedAo>())
        .map(|t| t.progress())
        .context("the ray-traced method is not active")?;
    let accumulation = chain
        .stage()
        .and_then(|s| s.downcast::<RayTracedAo>())
        .and_then(RayTracedAo::accumulation)
        .context("nothing was traced")?;
    let targets = chain.targets().context("nothing was rendered")?;
    let nd = lineao::readback::read_rgba(d, q, &targets.nd[0])?;
    let words: Vec<[u32; 4]> = bytemuck::cast_slice(&lineao::readback::read_buffer(d, q, accumulation)?).to_vec();
    let n = progress.rays_per_pixel as f64;
    let (mut ao, mut stderr) = (Image::filled(nd.width, nd.height, 0.0), Image::filled(nd.width, nd.height, 0.0));
    let (mut geometry_pixels, mut buried) = (0, 0);
    for (i, (texel, w)) in nd.data.iter().zip(&words).enumerate() {
        if texel[..3] == [0.0; 3] || n == 0.0 {
            continue;
        }
        geometry_pixels += 1;
        buried += (w[3] != 0) as usize;
        let (sum, squares) = (f32::from_bits(w[0]) as f64, f32::from_bits(w[1]) as f64);
        let mean = sum / n;
        let variance = if n > 1.0 { ((squares - n * mean * mean) / (n - 1.0)).max(0.0) } else { 0.0 };
        ao.data[i] = mean as f32;
        stderr.data[i] = (variance / n).sqrt() as f32;
    }
    let rays = geometry_pixels as u64 * progress.rays_per_pixel as u64;
    Ok(Truth { ao, stderr, vo: None, second: None, geometry_pixels, buried, rays })
}

/// Set by Ctrl-C while a truth runs.
static CANCEL: AtomicBool = AtomicBool::new(false);

fn cancel_on_ctrl_c() -> &'static AtomicBool {
    static HANDLER: OnceLock<()> = OnceLock::new();
    HANDLER.get_or_init(|| {
        // Without a handler (another one is installed) Ctrl-C ends the process as usual.
        #[cfg(not(target_arch = "wasm32"))]
        let _ = ctrlc::set_handler(|| CANCEL.store(true, Ordering::Relaxed));
    });
    &CANCEL
}

/// Bytes of memory available now (Linux: `MemAvailable`), if known.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kb| kb * 1024)
}

/// The BVH over what `chain`'s last frame drew: lines as sphere-swept segments of its line width
/// in its view, tubes as their cones, surfaces as triangles. A scene too big for the memory
/// available is an error before anything is allocated.
pub fn bvh(chain: &AoChain, scene: &Scene) -> Result<Bvh> {
    let view = chain.frame_view().context("nothing was rendered")?;
    let s = chain.settings();
    let segments = scene.tracts.positions.len();
    let triangles: usize = scene.surfaces.iter().map(|m| m.indices.len() / 3).sum();
    let needed = Bvh::estimated_bytes(segments, triangles) as u64;
    if let Some(available) = available_memory()
        && needed > available
    {
        anyhow::bail!(
            "the ray tracer's BVH for {segments} segments and {triangles} triangles needs about {} MB, more than the \
             {} MB of memory available",
            needed >> 20,
            available >> 20
        );
    }
    let shape = match &s.tubes {
        Some(tubes) => LineShape::Tubes { radius_world: tubes.radius_world, radii: scene.radii },
        None => LineShape::Lines { width_px: s.line_width_px },
    };
    let (positions, offsets) = (&scene.tracts.positions, &scene.tracts.offsets);
    let cones = match shape {
        LineShape::Lines { width_px } => lineao::truth::line_cones(positions, offsets, view, width_px),
        LineShape::Tubes { radius_world, radii } => lineao::truth::tube_cones(positions, offsets, radius_world, radii),
    };
    let triangles =
        scene.surfaces.iter().flat_map(|m| lineao::truth::mesh_triangles(&m.positions, &m.indices)).collect();
    Ok(Bvh::build(cones, triangles))
}

/// The truth on `chain`'s last rendered frame (its G-buffer read back from the GPU).
pub fn trace(gpu: &Gpu, chain: &AoChain, bvh: &Bvh, settings: &TruthSettings) -> Result<Truth> {
    let targets = chain.targets().context("nothing was rendered")?;
    let view = chain.frame_view().context("nothing was rendered")?;
    let nd = lineao::readback::read_rgba(&gpu.device, &gpu.queue, &targets.nd[0])?;
    let frame = lineao::truth::Frame { nd: &nd, view, lines: chain.settings().tubes.is_none() };
    let bar = std::io::stderr().is_terminal().then(|| {
        indicatif::ProgressBar::new(nd.height as u64).with_style(
            indicatif::ProgressStyle::with_template("ray tracing [{bar:40}] {pos}/{len} rows, {eta} left")
                .expect("a valid template")
                .progress_chars("=> "),
        )
    });
    let progress = |done: usize, _total: usize| {
        if let Some(bar) = &bar {
            bar.set_position(done as u64);
        }
    };
    let cancel = cancel_on_ctrl_c();
    let truth = lineao::truth::compute(bvh, &frame, settings, &progress, cancel);
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    match truth {
        Err(lineao::Error::Cancelled) => anyhow::bail!("ray tracing stopped (Ctrl-C)"),
        other => Ok(other?),
    }
}
