//! The ray-traced ground truth of a rendered frame (`render --method raytraced`, `score`): the
//! frame's G-buffer read back, the BVH over what it drew, the truth on all cores with a progress
//! bar on a terminal, and Ctrl-C stopping it cleanly between rows.

use std::io::IsTerminal;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};
use lineao::truth::{Bvh, LineShape, Truth, TruthSettings};
use lineao::{AoChain, Gpu};
use lineao_tracts::{Tractogram, TriangleMesh};

use crate::cli::RenderArgs;

/// What the frame drew, on the CPU.
pub struct Scene<'a> {
    pub tracts: &'a Tractogram,
    pub surfaces: &'a [TriangleMesh],
    /// Per-vertex tube radii (`--tube-radius-field`).
    pub radii: Option<&'a [f32]>,
}

/// The truth's settings from the command line.
pub fn settings(args: &RenderArgs) -> TruthSettings {
    TruthSettings {
        rays: args.rays,
        distance_world: args.ao_distance,
        falloff: args.ao_falloff,
        seed: args.ray_seed,
        vo: None,
        threads: 0,
    }
}

/// Set by Ctrl-C while a truth runs.
static CANCEL: AtomicBool = AtomicBool::new(false);

fn cancel_on_ctrl_c() -> &'static AtomicBool {
    static HANDLER: OnceLock<()> = OnceLock::new();
    HANDLER.get_or_init(|| {
        // Without a handler (another one is installed) Ctrl-C ends the process as usual.
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
    let nd = lineao::verify::read_rgba(&gpu.device, &gpu.queue, &targets.nd[0])?;
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
