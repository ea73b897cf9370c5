//! `lineao bench`: GPU time per pass on a built-in scene, as docs/reference.md's `lineao bench --json`.
//!
//! Every pass runs in its own submission, `--frames` times after `--warmup` frames, on the same
//! G-buffer. With timestamp queries the time is the GPU's (`"on": "gpu"`); without, CPU wall time
//! around submit + wait (`"on": "cpu"`, `"timestamps": false`), which for a method's pass is its
//! whole stage's (`ssao-12` with the blur, `lineao` with the pyramid). Baselines measured in the
//! same run give the ratios the numbers are judged by.
//!
//! The bench's own passes are the geometry and what every method shares:
//! - `lines`; `lines-native-1px`: the same segments as the rasterizer's native 1-px `LineList`;
//!   `lines-full-strip`: the same lines always from the full strip (both sides of every point),
//!   against which `lines` shows what its alternating strip saves; `lines-strip`: the same
//!   lines from the strip of earlier versions (a vertex buffer of 40 bytes a point and an index
//!   buffer: what the clusters replaced, timed in the same run);
//! - `lines-transparent`: the same lines seen through one another at α = 0.3, K = 8
//!   ([`lineao::passes::transparency`]: the depths and colours passes and the resolve, over a
//!   G-buffer without opaque lines), against `lines`;
//! - `nd-pyramid`, `composite`; `bilateral`: the separable bilateral blur (radius 4), which can
//!   follow any method;
//! - `lines-all`: every cluster drawn (the alternating strip); `lines-culled`: the default path,
//!   culled on the GPU at levels of detail (both phases, tests and draws); `lines-culled-exact`:
//!   culled without levels of detail (the full strip's G-buffer); `lines-compute`: the same
//!   culled frame as `lines-culled` with its pieces rasterized in compute into a visibility
//!   buffer and resolved ([`lineao::passes::raster`]; where the device lacks 64-bit atomics it
//!   says so and draws in hardware); `cull`: the cull's compute alone;
//! - `tubes`: the same streamlines as ray-cast tubes of radius 0.5 mm (against `lines`);
//!   `tubes-culled`: the same tubes culled on the GPU at levels of detail, both phases (against
//!   `lines-culled`); `tubes-culled-exact`: culled without levels of detail;
//! - `nd-from-depth`: the ND and zoom maps derived from the G-buffer's depth, as from a host
//!   renderer's (what embedding costs besides the method).
//!
//! Every method's passes come from the registry: each method's folder lists them
//! ([`lineao::method::BenchPass`]: a name, what it changes of the settings, which of its stage's
//! spans it times), and the bench builds, prepares and records that stage on the G-buffer:
//! - LineAO: `lineao`; `lineao-tap-floor`, the LineAO shader with the same sample addresses
//!   that only sums the fetched depths; `lineao-chain` (pyramid + LineAO in one span, what a
//!   frame pays for the occlusion); `lineao-level`, `lineao-chain-level` with `outer = level`;
//! - VO: `vo-line-5` (5 line samples, against `ssao-12`: the VO paper's 0.56×), `vo-area-1`
//!   (one area sample, moments pyramid included);
//! - SSAO: `ssao-12` (12 point samples, the VO paper's comparison), `ssao-16-chain` (16 samples
//!   and the 4 × 4 blur: the LineAO paper's baseline frame, against `lineao-chain`);
//! - the GPU ray tracer: `raytraced-1spp`, a frame that continues a picture with one more ray per
//!   geometry pixel (binary AO to 2 mm; the table adds rays per second); `raytraced-start-1spp`,
//!   a picture's first frame, which also finds each pixel's own segment and tests its origin for
//!   being buried; `ray-denoise`, the edge-aware denoiser (7 × 7 window) over a picture.
//!
//! The object-space passes run on the CPU (`"on": "cpu"`), `--frames` times up to 3 (each takes
//! seconds) without warm-up, on the scene's streamlines:
//! - `density-256`: voxelizing them at 256³ (occupancy radius 0.5);
//! - `sweep-256`: voxelizing, the eight occlusion sweeps and every vertex's octant visibilities
//!   (what `--method sweep` costs once per dataset);
//! - `variance-volume-256`: the moments pyramid and every vertex's octant visibilities, on the
//!   density volume of the run (what `--method variance-volume` adds to voxelizing);
//! - `bvh-build-1m`: the ground truth's BVH over the scene's lines as sphere-swept segments
//!   (1 M vertices at the default size), on all cores;
//! - `bvh-upload`: the GPU ray tracer's scene (its BVH with leaves of 8, built on all cores, and
//!   the upload): what a new geometry costs; the table adds its bytes per vertex;
//! - `raytraced-cpu-64`: the CPU truth with 64 rays per geometry pixel of the bench's frame
//!   (binary AO to 2 mm), on all cores; the table adds rays per second per core and the BVH's
//!   bytes per segment;
//! - `select`: a change of selection (every other streamline selected out, then the others):
//!   a bit per cluster uploaded and written into the records on the GPU
//!   ([`LineGeometry::set_selection`]), until the device has finished; compare it with the
//!   frame's `lines-culled`.

use std::time::Instant;

use anyhow::{Context, Result};
use lineao::LineGeometry;
use lineao::lighting::LightingShape;
use lineao::method::raytraced::RayTracedAo;
use lineao::method::{BenchPass, Stage};
use lineao::passes::Load;
use lineao::passes::bilateral::{Bilateral, Region};
use lineao::passes::composite::Composite;
use lineao::passes::lines::{LineRenderer, LineStyle};
use lineao::passes::nd_from_depth::{HostConfig, HostInputs, NdFromDepth};
use lineao::passes::nd_pyramid::NdPyramid;
use lineao::passes::transparency::Transparency;
use lineao::passes::tubes::TubeRenderer;
use lineao::targets::{FrameTargets, Target};
use lineao::timing::{PassTimer, Span};
use lineao::volume::density::{DensityOptions, voxelize};
use lineao::volume::sweep::{self, SweepSettings};
use lineao::volume::variance::{VarianceMaps, VarianceSettings};
use lineao::volume::vertex_tangents;
use lineao::{AoChain, AoMethod, BilateralSettings, ChainSettings, Gpu, LineAoSettings, TransparencySettings};
use lineao::{FrameView, Projection};
use serde_json::json;

use crate::cli::{BenchArgs, gpu_passes};

/// The opacity of pass `lines-transparent`.
const TRANSPARENT_ALPHA: f32 = 0.3;

/// The radius of pass `tubes` in zoom units (0.5 mm for tractograms).
const TUBE_RADIUS: f32 = 0.5;

/// Every pass of the benchmark, prepared for one view over one G-buffer: the bench's own (the
/// geometry, the shared passes) and every method's from the registry ([`StagePass`]).
struct Passes {
    lines: LineRenderer,
    /// The lines culled on the GPU (`lines-culled`; `cull` times its compute alone).
    lines_culled: LineRenderer,
    /// The same without levels of detail (`lines-culled-exact`): the full strip's G-buffer.
    lines_culled_exact: LineRenderer,
    /// `lines_culled` rasterized in compute (`lines-compute`).
    lines_compute: LineRenderer,
    lines_native: LineRenderer,
    lines_full: LineRenderer,
    /// `lines` seen through one another (`lines-transparent`).
    transparency: Transparency,
    /// The strip of earlier versions and its renderer (`lines-strip`), when selected.
    strip: Option<(lineao::passes::lines::StripGeometry, lineao::passes::lines::StripRenderer)>,
    pyramid: NdPyramid,
    composite: Composite,
    bilateral: Bilateral,
    tubes: TubeRenderer,
    /// The tubes culled on the GPU at levels of detail (`tubes-culled`, the chain's default for
    /// tubes), and without them (`tubes-culled-exact`).
    tubes_culled: TubeRenderer,
    tubes_culled_exact: TubeRenderer,
    /// The ND and zoom maps from the G-buffer's own depth, as from a host's (whose bind group
    /// is made per frame, on the device).
    nd_from_depth: NdFromDepth,
    stages: Vec<StagePass>,
    /// What the stages are prepared with each frame: the bench's settings and view.
    settings: ChainSettings,
    view: FrameView,
    device: wgpu::Device,
    queue: wgpu::Queue,
    output: Target,
}

/// A method's bench pass ([`BenchPass`], from the registry) and its stage, bound to the chain's
/// targets (whose pyramid has LineAO's levels; the other methods read its finest).
///
/// Every stage reads the G-buffer `lines` wrote. On lavapipe a pass over one-level targets of
/// its own (a copy of the G-buffer made once) measured 0.03–0.08 ms by its timestamps where on
/// the chain's it took 1.7–5 ms; VO area there measured 40.6 ms by timestamps and 48.5 ms by
/// the wall clock, 45.8–47.6 ms by timestamps on the chain's.
struct StagePass {
    method: AoMethod,
    pass: &'static BenchPass,
    stage: Box<dyn Stage>,
}

impl Passes {
    fn new(
        gpu: &Gpu,
        settings: &ChainSettings,
        targets: &FrameTargets,
        view: &FrameView,
        scene: Option<std::sync::Arc<lineao::RayScene>>,
        strip: Option<lineao::passes::lines::StripGeometry>,
    ) -> Result<Passes> {
        let (device, queue) = (&gpu.device, &gpu.queue);
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        // Compiled for the bench's lighting, as the chain's are.
        let shape = LightingShape::of(&settings.lighting);
        let lines = |style| LineRenderer::with_slab(device, style, false, false, shape);
        let plain = lines(LineStyle::Quads);
        let layers = TransparencySettings::default().layers;
        let mut transparency = Transparency::new(device, &plain, layers, false, false, format);
        transparency.resize(device, targets);
        let opacity = TransparencySettings { alpha: TRANSPARENT_ALPHA, ..TransparencySettings::default() };
        transparency.prepare(queue, view, &opacity, settings.strength, [1.0; 8]);
        let mut passes = Passes {
            lines: plain,
            transparency,
            lines_culled: lines(LineStyle::Quads).culled(device, true),
            lines_culled_exact: lines(LineStyle::Quads).culled(device, false),
            lines_compute: lines(LineStyle::Quads).culled(device, true).rasterized_in_compute(device),
            lines_native: lines(LineStyle::Native1px),
            lines_full: lines(LineStyle::FullStrip),
            strip: strip.map(|geometry| {
                let mut renderer = lineao::passes::lines::StripRenderer::new(device, false, shape);
                renderer.prepare(queue, view, settings);
                (geometry, renderer)
            }),
            pyramid: NdPyramid::new(device),
            composite: Composite::new(device, format),
            bilateral: Bilateral::new(device),
            tubes: TubeRenderer::new(device, false, shape),
            tubes_culled: TubeRenderer::new(device, false, shape).culled(device, true),
            tubes_culled_exact: TubeRenderer::new(device, false, shape).culled(device, false),
            nd_from_depth: NdFromDepth::new(device, HostConfig::default()),
            stages: Vec::new(),
            settings: settings.clone(),
            view: *view,
            device: device.clone(),
            queue: queue.clone(),
            output: Target::output(device, "lineao::bench::output", (view.width, view.height), format),
        };
        let line_passes = [
            &passes.lines,
            &passes.lines_culled,
            &passes.lines_culled_exact,
            &passes.lines_compute,
            &passes.lines_native,
            &passes.lines_full,
        ];
        for renderer in line_passes {
            renderer.prepare(queue, view, settings.line_width_px, settings.line_color, &settings.lighting, None);
        }
        for renderer in [&passes.tubes, &passes.tubes_culled] {
            renderer.prepare(queue, view, TUBE_RADIUS * view.zoom_unit, settings.line_color, &settings.lighting, None);
        }
        passes.nd_from_depth.prepare(queue, view);
        passes.pyramid.resize(device, targets);
        for (method, pass) in lineao::method::bench_passes() {
            let first = pass.settings_for(method, settings, 0);
            let Some(mut stage) = pass.stage(method, device, &first) else { continue };
            // The one stage that traces the scene.
            if let Some(tracer) = (stage.as_mut() as &mut dyn std::any::Any).downcast_mut::<RayTracedAo>() {
                tracer.set_scene(scene.clone());
            }
            if let Some(span) = pass.spans.iter().find(|span| !stage.spans(&first).contains(span)) {
                anyhow::bail!("bench pass {}: its stage records no span '{span}' with these settings", pass.name);
            }
            stage.resize(device, targets);
            passes.stages.push(StagePass { method, pass, stage });
        }
        passes.bilateral.resize(device, targets);
        passes.bilateral.prepare(queue, view, &BilateralSettings::default(), Region::All);
        passes.composite.resize(device, targets, &targets.ao);
        passes.composite.prepare(
            queue,
            targets,
            view,
            settings.strength,
            settings.debug_view,
            lineao::passes::composite::Shown::Screen,
        );
        Ok(passes)
    }

    /// Records pass `name` of frame `frame` timed into `span` (a method's stage prepared with
    /// what its settings make of that frame first).
    fn encode(
        &self,
        name: &str,
        frame: u32,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        geometry: &LineGeometry,
        span: Option<Span>,
    ) {
        let background = self.settings.background;
        match name {
            "lines" | "lines-all" => self.lines.encode(encoder, targets, geometry, Load::Clear(background), span),
            "lines-transparent" => {
                // No opaque line hides them.
                lineao::passes::clear(encoder, targets, background);
                self.transparency.encode(encoder, geometry, &self.lines, &self.output.view, span);
            }
            "lines-culled" => self.lines_culled.encode(encoder, targets, geometry, Load::Clear(background), span),
            "lines-culled-exact" => {
                self.lines_culled_exact.encode(encoder, targets, geometry, Load::Clear(background), span)
            }
            "lines-compute" => self.lines_compute.encode(encoder, targets, geometry, Load::Clear(background), span),
            "cull" => self.lines_culled.encode_cull(encoder, targets, geometry, span),
            "lines-native-1px" => self.lines_native.encode(encoder, targets, geometry, Load::Clear(background), span),
            "lines-full-strip" => self.lines_full.encode(encoder, targets, geometry, Load::Clear(background), span),
            "lines-strip" => {
                if let Some((strip, renderer)) = &self.strip {
                    renderer.encode(encoder, targets, strip, Load::Clear(background), span);
                }
            }
            "nd-pyramid" => self.pyramid.encode(encoder, targets, span),
            "composite" => self.composite.encode(encoder, &self.output.view, span),
            "bilateral" => self.bilateral.encode(encoder, targets, span),
            "tubes" => self.tubes.encode(encoder, targets, geometry, Load::Clear(background), span),
            "tubes-culled" => self.tubes_culled.encode(encoder, targets, geometry, Load::Clear(background), span),
            "tubes-culled-exact" => {
                self.tubes_culled_exact.encode(encoder, targets, geometry, Load::Clear(background), span)
            }
            "nd-from-depth" => {
                let inputs = HostInputs { depth: &targets.depth.view, normals: None, color: None };
                self.nd_from_depth.encode(&self.device, encoder, targets, &inputs, span);
            }
            _ => {
                let s = self.stages.iter().find(|s| s.pass.name == name).expect("every bench pass is listed");
                let settings = s.pass.settings_for(s.method, &self.settings, frame);
                s.stage.prepare(&self.queue, targets, &self.view, &settings);
                // The pass's spans as one: the first's start, the last's end.
                let (first, last) = (s.pass.spans[0], s.pass.spans[s.pass.spans.len() - 1]);
                let of = |name: &'static str| match (name == first, name == last) {
                    (true, true) => span,
                    (true, false) => span.map(Span::begin_only),
                    (false, true) => span.map(Span::end_only),
                    (false, false) => None,
                };
                s.stage.encode(encoder, targets, &of);
            }
        }
    }
}

fn summary(name: &str, on: &str, mut ms: Vec<f64>) -> serde_json::Value {
    ms.sort_by(f64::total_cmp);
    let median = if ms.len() % 2 == 1 { ms[ms.len() / 2] } else { (ms[ms.len() / 2 - 1] + ms[ms.len() / 2]) / 2.0 };
    json!({"name": name, "on": on, "ms_median": median, "ms_min": ms[0], "ms_max": ms[ms.len() - 1]})
}

/// The passes that need the scene's points on the CPU: the earlier strip is built from them,
/// the ray tracers' BVH and object-space AO's volumes too.
fn needs_points(name: &str) -> bool {
    name == "lines-strip" || name.starts_with("ray") || crate::cli::CPU_PASSES.contains(&name)
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let source = crate::source::Source::Scene { kind: args.scene, vertices: args.vertices, seed: args.seed };
    let selected = |name: &str| args.passes.is_empty() || args.passes.iter().any(|p| p == name);
    let all = gpu_passes();
    let points = all.iter().chain(crate::cli::CPU_PASSES.iter()).any(|p| selected(p) && needs_points(p));
    let gpu = Gpu::headless()?;
    let (device, queue) = (&gpu.device, &gpu.queue);
    // The scene streamed onto the GPU as a file would be (the whole brain chunk by chunk on all
    // cores), its points kept only where a selected pass needs them.
    let start = Instant::now();
    let keep = crate::source::Keep { points, ..Default::default() };
    let mut scene = crate::source::Lines::stream(&source, &keep, None, &gpu)?;
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    let geometry = &scene.geometry;
    let bytes_per_vertex = geometry.gpu_bytes() as f64 / geometry.vertices.max(1) as f64;
    eprintln!(
        "lineao: {} with {} streamlines, {} vertices made and uploaded in {load_ms:.0} ms: {} clusters in {} page(s), \
         {:.2} bytes a vertex on the GPU",
        scene.name,
        geometry.streamlines,
        geometry.vertices,
        geometry.clusters(),
        geometry.page_count(),
        bytes_per_vertex
    );
    // LineAO as the preset sets it; SSAO, VO and the rest keep the papers' values (their
    // presets' reach and strength do not change what a pass costs; their sample counts do).
    let papers = ChainSettings {
        line_ao: LineAoSettings { light_attenuation: !args.no_light_attenuation, ..LineAoSettings::default() },
        zoom_unit: scene.hint.zoom_unit,
        ..ChainSettings::papers()
    };
    let settings = ChainSettings { line_ao: papers.clone().with_preset(args.preset).line_ao, ..papers };
    let mut camera = crate::render::camera_from_hint(&scene.hint);
    if let Some(fov_y_deg) = args.fov {
        camera.projection = Projection::Perspective { fov_y_deg };
    }
    crate::render::validate_camera(&camera)?;
    let bounds = geometry.bounds.context("the scene has no finite points")?;

    // The chain decides the guard band; the passes below share one G-buffer with every target
    // any of them writes (`outer = level`'s, SSAO's before its blur, the bilateral blur's).
    let mut chain = AoChain::new(device, wgpu::TextureFormat::Rgba8UnormSrgb, settings.clone())?;
    chain.resize(args.width, args.height)?;
    let view = chain.prepare(device, queue, &camera, &bounds).context("nothing to render at this size")?;
    let targets = &FrameTargets::new(device, args.width, args.height, view.guard, settings.levels()).with_blur(device);
    let tractogram = &scene.tracts;
    let ray_geometry =
        lineao::RayGeometry { positions: &tractogram.positions, offsets: &tractogram.offsets, ..Default::default() };
    let tracing = all.iter().any(|p| selected(p) && p.starts_with("ray"));
    let ray_scene = match tracing {
        true => Some(std::sync::Arc::new(lineao::RayScene::new(device, queue, &ray_geometry)?)),
        false => None,
    };
    let strip = match selected("lines-strip") {
        true => {
            Some(lineao::passes::lines::StripGeometry::new(device, queue, &tractogram.positions, &tractogram.offsets)?)
        }
        false => None,
    };
    let strip_bytes = strip.as_ref().map(|s| s.gpu_bytes() as f64 / geometry.vertices.max(1) as f64);
    let passes = Passes::new(&gpu, &settings, targets, &view, ray_scene.clone(), strip)?;
    eprintln!(
        "lineao: lines: {:.1} % of the clusters drawn as the alternating strip in this view",
        100.0 * passes.lines.alternating_share(geometry)
    );
    let timer = if args.no_timestamps { None } else { PassTimer::new(device, queue, &all) };

    let mut times: Vec<Vec<f64>> = vec![Vec::new(); all.len()];
    // `lines` last among the line passes, so the G-buffer the later passes read is the chain's.
    let first = [
        "lines-transparent",
        "lines-native-1px",
        "lines-full-strip",
        "lines-strip",
        "lines-all",
        "lines-culled-exact",
        "lines-compute",
        "lines-culled",
        "cull",
    ];
    let order = first.into_iter().chain(all.iter().copied().filter(|p| !first.contains(p)));
    // The G-buffer and pyramid every later pass reads, also when `--passes` leaves them out.
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::bench") });
    passes.encode("lines", 0, &mut encoder, targets, geometry, None);
    passes.encode("nd-pyramid", 0, &mut encoder, targets, geometry, None);
    queue.submit([encoder.finish()]);
    for frame in 0..args.warmup + args.frames {
        for name in order.clone().filter(|name| selected(name)) {
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::bench") });
            encoder.push_debug_group(name);
            let span = timer.as_ref().and_then(|t| t.span(name));
            passes.encode(name, frame, &mut encoder, targets, geometry, span);
            encoder.pop_debug_group();
            if let Some(timer) = &timer {
                timer.resolve(&mut encoder);
            }
            let start = Instant::now();
            queue.submit([encoder.finish()]);
            gpu.wait()?;
            let wall_ms = start.elapsed().as_secs_f64() * 1e3;
            let ms = match &timer {
                Some(timer) => timer.read(device, &[name])?[0].ms,
                None => wall_ms,
            };
            if frame >= args.warmup {
                times[all.iter().position(|p| *p == name).expect("every pass is listed")].push(ms);
            }
        }
    }

    if let Some(note) = passes.lines_compute.raster_note().filter(|_| selected("lines-compute")) {
        eprintln!("lineao: lines-compute: {note}");
    }
    // What the culled lines and tubes drew in their last frame (they ran last among their
    // passes).
    let mut visible = (None, None);
    for (name, renderer) in [("lines-culled", passes.lines_culled.cull()), ("tubes-culled", passes.tubes_culled.cull())]
    {
        let Some(culled) = renderer.filter(|_| selected(name) || (name == "lines-culled" && selected("cull"))) else {
            continue;
        };
        if let Some(note) = culled.note() {
            eprintln!("lineao: {name}: {note}");
        }
        let counts = culled.counts(queue, geometry)?;
        eprintln!("lineao: {name}: {counts}");
        if name == "lines-culled" {
            visible = (Some(counts.drawn_share()), Some(counts.visible_share()));
        }
    }
    let (visible_pieces, visible_clusters) = visible;
    let on = if timer.is_some() { "gpu" } else { "cpu" };
    let mut passes: Vec<_> =
        all.iter().zip(times).filter(|(name, _)| selected(name)).map(|(name, ms)| summary(name, on, ms)).collect();
    let runs = args.frames.min(3);
    for (name, ms) in object_space_times(&tractogram.positions, &tractogram.offsets, runs, &selected)? {
        passes.push(summary(name, "cpu", ms));
    }
    for (name, ms) in ray_tracing_times(&gpu, &chain, targets, &view, tractogram, runs, &selected)? {
        passes.push(summary(name, "cpu", ms));
    }
    if selected("bvh-upload") {
        let mut ms = Vec::new();
        for _ in 0..runs {
            let start = Instant::now();
            let scene = lineao::RayScene::new(device, queue, &ray_geometry)?;
            gpu.wait()?;
            ms.push(start.elapsed().as_secs_f64() * 1e3);
            drop(scene);
        }
        passes.push(summary("bvh-upload", "cpu", ms));
    }
    if let (true, Some(ray_scene)) = (selected("raytraced-1spp"), &ray_scene) {
        let geometry_pixels = lineao::readback::read_rgba(device, queue, &targets.nd[0])?
            .data
            .iter()
            .filter(|texel| texel[..3] != [0.0; 3])
            .count();
        let ms = passes.iter().find(|p| p["name"] == "raytraced-1spp").and_then(|p| p["ms_median"].as_f64());
        eprintln!(
            "lineao: raytraced-1spp: {geometry_pixels} rays, {:.1} M rays/s; the scene {} bytes, {:.1} bytes per vertex, \
             {} layer(s) per texture",
            geometry_pixels as f64 / ms.unwrap_or(f64::NAN) / 1e3,
            ray_scene.bytes(),
            ray_scene.bytes_per_vertex(),
            ray_scene.layers()
        );
    }
    let vertices = geometry.vertices;
    if selected("select") {
        let geometry = &mut scene.geometry;
        let mut ms = Vec::new();
        for run in 0..runs {
            let keep: Vec<bool> = (0..geometry.streamlines).map(|i| (i + run as usize).is_multiple_of(2)).collect();
            let start = Instant::now();
            geometry.set_selection(device, queue, Some(&keep))?;
            gpu.wait()?;
            ms.push(start.elapsed().as_secs_f64() * 1e3);
        }
        geometry.set_selection(device, queue, None)?;
        passes.push(summary("select", "cpu", ms));
    }
    let info = gpu.adapter.get_info();
    let report = json!({
        "adapter": info.name,
        "backend": info.backend.to_str(),
        "width": args.width,
        "height": args.height,
        "scene": scene.name,
        "vertices": vertices,
        "gpu_bytes_per_vertex": bytes_per_vertex,
        "strip_bytes_per_vertex": strip_bytes,
        "visible_pieces": visible_pieces,
        "visible_clusters": visible_clusters,
        "load_ms": load_ms,
        "frames": args.frames,
        "timestamps": timer.is_some(),
        "passes": passes,
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_table(&report, &passes);
    }
    Ok(())
}

/// Times of the selected CPU passes over `runs` runs each.
fn object_space_times(
    positions: &[[f32; 3]],
    offsets: &[u64],
    runs: u32,
    selected: &dyn Fn(&str) -> bool,
) -> Result<Vec<(&'static str, Vec<f64>)>> {
    let density = DensityOptions { resolution: 256, occupancy_radius: 0.5, threads: 0 };
    let timed = |f: &mut dyn FnMut() -> Result<()>| -> Result<Vec<f64>> {
        (0..runs)
            .map(|_| {
                let start = Instant::now();
                f()?;
                Ok(start.elapsed().as_secs_f64() * 1e3)
            })
            .collect()
    };
    let mut out = Vec::new();
    if selected("density-256") {
        out.push(("density-256", timed(&mut || voxelize(positions, offsets, &density).map(drop).map_err(Into::into))?));
    }
    let tangents = vertex_tangents(positions, offsets);
    if selected("sweep-256") {
        let ms = timed(&mut || {
            let volume = voxelize(positions, offsets, &density)?;
            sweep::octant_visibility(&volume, positions, &tangents, &SweepSettings::default())?;
            Ok(())
        })?;
        out.push(("sweep-256", ms));
    }
    if selected("variance-volume-256") {
        let volume = voxelize(positions, offsets, &density)?;
        let ms = timed(&mut || {
            let maps = VarianceMaps::new(&volume, &VarianceSettings::default())?;
            maps.octant_visibility(&volume, positions, &tangents, 0)?;
            Ok(())
        })?;
        out.push(("variance-volume-256", ms));
    }
    Ok(out)
}

/// Times of the ground truth's CPU passes on the bench's frame (its G-buffer as the chain's
/// `lines` left it).
fn ray_tracing_times(
    gpu: &Gpu,
    chain: &AoChain,
    targets: &FrameTargets,
    view: &FrameView,
    tractogram: &lineao_tracts::Tractogram,
    runs: u32,
    selected: &dyn Fn(&str) -> bool,
) -> Result<Vec<(&'static str, Vec<f64>)>> {
    use lineao::truth::{Bvh, TruthSettings};
    let mut out = Vec::new();
    if !selected("bvh-build-1m") && !selected("raytraced-cpu-64") {
        return Ok(out);
    }
    let width = chain.settings().line_width_px;
    let build =
        || Bvh::build(lineao::truth::line_cones(&tractogram.positions, &tractogram.offsets, view, width), Vec::new());
    let mut bvh = build();
    eprintln!(
        "lineao: BVH of {} segments: {} bytes, {:.1} bytes per segment",
        bvh.cones.len(),
        bvh.bytes(),
        bvh.bytes() as f64 / bvh.cones.len().max(1) as f64
    );
    if selected("bvh-build-1m") {
        let mut ms = Vec::new();
        for _ in 0..runs {
            drop(bvh);
            let start = Instant::now();
            bvh = build();
            ms.push(start.elapsed().as_secs_f64() * 1e3);
        }
        out.push(("bvh-build-1m", ms));
    }
    if selected("raytraced-cpu-64") {
        // The bench's G-buffer (the chain itself only sized the guard band and drew nothing).
        let nd = lineao::readback::read_rgba(&gpu.device, &gpu.queue, &targets.nd[0])?;
        let frame = lineao::truth::Frame { nd: &nd, view, lines: true };
        let settings = TruthSettings { rays: 64, ..TruthSettings::default() };
        let cancel = std::sync::atomic::AtomicBool::new(false);
        let mut ms = Vec::new();
        for _ in 0..runs {
            let start = Instant::now();
            let truth = lineao::truth::compute(&bvh, &frame, &settings, &|_, _| {}, &cancel)?;
            let seconds = start.elapsed().as_secs_f64();
            ms.push(seconds * 1e3);
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            eprintln!(
                "lineao: raytraced-cpu-64: {} rays over {} geometry pixels, {:.2} M rays/s per core ({cores} cores)",
                truth.rays,
                truth.geometry_pixels,
                truth.rays as f64 / seconds / cores as f64 / 1e6
            );
        }
        out.push(("raytraced-cpu-64", ms));
    }
    Ok(out)
}

fn print_table(report: &serde_json::Value, passes: &[serde_json::Value]) {
    println!(
        "{} ({}), {}x{}, {} with {} vertices, {} frames, {} time",
        report["adapter"].as_str().unwrap_or_default(),
        report["backend"].as_str().unwrap_or_default(),
        report["width"],
        report["height"],
        report["scene"].as_str().unwrap_or_default(),
        report["vertices"],
        report["frames"],
        if report["timestamps"] == true { "GPU timestamp" } else { "CPU wall" },
    );
    println!("{:<20} {:>10} {:>10} {:>10}", "pass", "median ms", "min ms", "max ms");
    let median = |name: &str| passes.iter().find(|p| p["name"] == name).and_then(|p| p["ms_median"].as_f64());
    for p in passes {
        let f = |k: &str| p[k].as_f64().unwrap_or(f64::NAN);
        println!(
            "{:<20} {:>10.2} {:>10.2} {:>10.2}",
            p["name"].as_str().unwrap_or_default(),
            f("ms_median"),
            f("ms_min"),
            f("ms_max")
        );
    }
    for (a, b) in [
        ("lineao", "lineao-tap-floor"),
        ("lines", "lines-native-1px"),
        ("lines-transparent", "lines"),
        ("lines-culled", "lines-all"),
        ("lines-culled", "lines-culled-exact"),
        ("lines-compute", "lines-culled"),
        ("cull", "lines-all"),
        ("lines-full-strip", "lines-native-1px"),
        ("lines", "lines-strip"),
        ("tubes", "lines"),
        ("tubes-culled", "lines-culled"),
        ("tubes-culled", "tubes"),
        ("tubes-culled", "tubes-culled-exact"),
        ("lineao-chain", "ssao-16-chain"),
        ("lineao-level", "lineao"),
        ("lineao-chain-level", "ssao-16-chain"),
        ("vo-line-5", "ssao-12"),
        ("vo-area-1", "ssao-12"),
        ("raytraced-1spp", "lineao-chain"),
        ("raytraced-start-1spp", "lineao-chain"),
        ("ray-denoise", "raytraced-1spp"),
    ] {
        if let (Some(x), Some(y)) = (median(a), median(b)) {
            println!("{a} / {b}: {:.2}x", x / y);
        }
    }
}
