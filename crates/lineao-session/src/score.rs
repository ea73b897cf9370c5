//! `lineao score`: every method's AO next to the ray-traced truth on one G-buffer.
//!
//! The truth is traced on the G-buffer of a chain without a guard band; each method renders the
//! same view (its own guard band around the same visible pixels), and its AO — what darkens the
//! image, clamp(strength · ao, 0, 1) after the method's own blur — is compared over the visible
//! pixels that are geometry in both. VO methods are compared with the VO truth (the occupied
//! share of the ball, half or whole as `--no-normal-clamp` says), every other method with the
//! ray-traced AO. `raytraced` is the truth traced again with the next `--ray-seed`: how close
//! two truths are, the bar no method can pass.

use anyhow::{Context, Result};
use lineao::method::Estimate;
use lineao::reference::Image;
use lineao::reference::NdImage;
use lineao::truth::legibility::{self, Absent, Legibility, Shading};
use lineao::truth::metrics::{self, Scores};
use lineao::truth::{Falloff, Reach, Truth, TruthSettings, VoBall};
use lineao::{AoMethod, ChainSettings};
use serde_json::json;

use crate::args::{AoDistance, Method, ScoreArgs, ScoreMethod};
use crate::label::{Rgba8, srgb};
use crate::render::{Panel, Session};

/// One method's scores.
pub struct Row {
    pub method: ScoreMethod,
    /// What it is compared with: `ao`, `vo-half` or `vo-whole`.
    pub truth: &'static str,
    pub scores: Scores,
    /// SSIM of the composited image's luminance against the composite with the truth's AO.
    pub image_ssim: f64,
    /// Its AO against the bundle-scale truth.
    pub bundle: metrics::Agreement,
    /// How legible its composite is (darker is deeper).
    pub legibility: Result<Legibility, Absent>,
    /// Its AO over the visible frame, for the grid.
    pub ao: Image<f32>,
}

/// The reach of `score`'s bundle-scale truth by default: a fifth of the scene's longest side,
/// LineVis's default for its ray-traced AO of lines.
pub const BUNDLE_DISTANCE: AoDistance = AoDistance::Share(0.2);

/// The second truth: obscurance with the linear falloff at a bundle's reach (docs/reference.md
/// "Bundle-scale truth").
///
/// It comes from the local truth's rays, each traced once to the larger reach
/// ([`TruthSettings::second`]): its ray origins are the local truth's (ε = 1e-3 of the local
/// reach), its buried pixels the same ([`Report::truth`]'s).
pub struct Bundle {
    pub ao: Image<f32>,
    pub settings: TruthSettings,
    pub distance: AoDistance,
}

/// The truth of one view and every method's scores.
pub struct Report {
    pub truth: Truth,
    pub truth_seconds: f64,
    /// The visible truth (AO, and VO where asked).
    pub ao: Image<f32>,
    pub vo: Option<Image<f32>>,
    pub bundle: Bundle,
    pub mask: Vec<bool>,
    pub rows: Vec<Row>,
    /// The legibility of the pictures that are no method's: `none`, and each truth's AO
    /// composited at strength 1 (`truth`, `bundle-truth`).
    pub pictures: Vec<(&'static str, Result<Legibility, Absent>)>,
    /// Seconds spent on legibility (pairs drawn once, then every picture).
    pub legibility_seconds: f64,
}

/// The methods' chain settings: the command line's, the method and variant set.
pub fn method_settings(session: &Session, args: &crate::args::RenderArgs, m: ScoreMethod) -> ChainSettings {
    // The variant first, so that the preset gives this variant's values and explicit options
    // still win.
    let mut args = args.clone();
    if let Some(variant) = &m.method.info().variant {
        let value = if m.variant.is_some() { variant.value } else { variant.main };
        args.methods.give(variant.setting, lineao::method::setting::Value::Choice(value));
    }
    let mut settings = session.settings(&args, Method { screen: m.method, volume: None });
    settings.blur = None;
    settings.raytraced.denoise = None;
    settings
}

/// A method's occlusion over the visible window, before the composite's strength, and which
/// visible pixels its G-buffer shows geometry at.
pub struct MethodAo {
    pub ao: Image<f32>,
    pub geometry: Vec<bool>,
}

/// Renders `settings` on `session`'s view in `chain` (made on first use, then only changed
/// where the settings differ: the fit renders hundreds of settings) and reads back its AO —
/// after the method's own blur — over the visible `width` × `height` window.
pub fn raw_ao(
    session: &Session,
    chain: &mut Option<lineao::AoChain>,
    settings: ChainSettings,
    width: u32,
    height: u32,
) -> Result<MethodAo> {
    let gpu = &session.gpu;
    let chain = match chain {
        Some(chain) => {
            chain.set_settings(&gpu.device, settings)?;
            chain
        }
        None => {
            let format = wgpu::TextureFormat::Rgba8UnormSrgb;
            let mut made = lineao::AoChain::new(&gpu.device, format, settings)?;
            made.resize(width, height)?;
            chain.insert(made)
        }
    };
    let target = lineao::targets::Target::output(
        &gpu.device,
        "lineao::score::output",
        (width, height),
        wgpu::TextureFormat::Rgba8UnormSrgb,
    );
    // One frame: the fit renders hundreds of settings, each exact after its first frame.
    let gpu_rays = chain.settings().method.info().traces_scene;
    session.frame(chain, &target.view, crate::render::FrameOptions { gpu_rays, ..Default::default() })?;
    let targets = chain.targets().context("nothing was rendered")?;
    let shown = targets.shown();
    let raw = lineao::readback::read_f32(&gpu.device, &gpu.queue, shown)?;
    let nd = lineao::readback::read_rgba(&gpu.device, &gpu.queue, &targets.nd[0])?;
    let guard = targets.guard as usize;
    let (w, h) = (width as usize, height as usize);
    let ao = Image::from_fn(w, h, |x, y| raw.get(x + guard, y + guard));
    let geometry = (0..w * h)
        .map(|i| {
            let t = nd.get(i % w + guard, i / w + guard);
            t[0] != 0.0 || t[1] != 0.0 || t[2] != 0.0
        })
        .collect();
    Ok(MethodAo { ao, geometry })
}

/// Scores `methods` on `session`'s view against the local truth of `args` and the bundle-scale
/// truth reaching `bundle_distance`.
pub fn score(
    session: &Session,
    args: &crate::args::RenderArgs,
    methods: &[ScoreMethod],
    bundle_distance: AoDistance,
) -> Result<Report> {
    let (w, h) = (args.image.width as usize, args.image.height as usize);
    // VO's truth: the half ball where VO clamps to it (`--no-normal-clamp` or `--settings`
    // turn it off), as the settings VO's rows render with say.
    let obscurance = |m: &ScoreMethod| m.method.info().estimates == Estimate::Obscurance;
    let vo = ScoreMethod::all().into_iter().find(obscurance).context("no method estimates obscurance")?;
    let vo_ball = if method_settings(session, args, vo).vo.normal_clamp { VoBall::Half } else { VoBall::Whole };
    let wants_vo = methods.iter().any(obscurance);
    let local = crate::truth::settings(args, session.longest_side);
    let bundle_settings = TruthSettings {
        distance_world: bundle_distance.world(session.longest_side),
        falloff: Falloff::Linear,
        vo: None,
        ..local.clone()
    };
    // Both truths from the same rays, each traced once to the larger reach.
    let second = Reach { distance_world: bundle_settings.distance_world, falloff: Falloff::Linear };
    let truth_settings = TruthSettings { vo: wants_vo.then_some(vo_ball), second: Some(second), ..local };

    // The truth's G-buffer: a chain without a method (and so without a guard band).
    let mut quiet = args.clone();
    (quiet.image.timings, quiet.image.dump) = (false, None);
    let plain = ScoreMethod::main(AoMethod::None);
    let panel = Panel::new(Method { screen: AoMethod::None, volume: None }, method_settings(session, args, plain));
    let rendered = session.render(&quiet, &panel, None, None, None)?;
    let start = std::time::Instant::now();
    let mut truth = session.trace(&rendered.chain, &truth_settings)?;
    let truth_seconds = start.elapsed().as_secs_f64();
    let bundle_ao = truth.second.take().context("the bundle-scale truth")?;
    let (nd, shading) = read_frame(session, &rendered.chain)?;
    let geometry = |image: &lineao::reference::NdImage, x: usize, y: usize| {
        let t = image.get(x, y);
        t[0] != 0.0 || t[1] != 0.0 || t[2] != 0.0
    };
    anyhow::ensure!(truth.geometry_pixels > 0, "{}: no geometry in view", session.lines.name);
    let ao_truth = truth.ao.clone();
    let vo_truth = truth.vo.clone();
    let strength_of = |m: ScoreMethod| method_settings(session, args, m).strength;
    let composite = |ao: &Image<f32>| -> Image<f32> {
        Image::from_fn(w, h, |x, y| srgb(shading.composite(y * w + x, ao.get(x, y))))
    };

    let mut rows = Vec::new();
    let mut mask = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            mask[y * w + x] = geometry(&nd, x, y);
        }
    }
    for &m in methods {
        let (target_truth, truth_name) = match m.method.info().estimates {
            Estimate::Obscurance => (
                vo_truth.as_ref().context("the VO truth")?,
                if vo_ball == VoBall::Half { "vo-half" } else { "vo-whole" },
            ),
            _ => (&ao_truth, "ao"),
        };
        let ao = if m.method.info().traces_scene && args.truth.cpu {
            let again = TruthSettings { seed: truth_settings.seed.wrapping_add(1), vo: None, ..truth_settings.clone() };
            session.trace(&rendered.chain, &again)?.ao
        } else {
            let mut chain = None;
            let mut settings = method_settings(session, args, m);
            // The ray tracer on the GPU traces the truth again with the next seed.
            settings.raytraced.seed = settings.raytraced.seed.wrapping_add(1);
            let view = raw_ao(session, &mut chain, settings, args.image.width, args.image.height)?;
            mask.iter_mut().zip(&view.geometry).for_each(|(m, g)| *m &= g);
            let strength = strength_of(m);
            Image { data: view.ao.data.iter().map(|a| (strength * a).clamp(0.0, 1.0)).collect(), ..view.ao }
        };
        rows.push((m, truth_name, target_truth.clone(), ao));
    }
    let all = vec![true; w * h];
    let true_image = composite(&ao_truth);
    let start = std::time::Instant::now();
    let depth = Image { data: nd.data.iter().map(|t| t[3]).collect(), width: w, height: h };
    let pairs = legibility::Pairs::sample(&depth, &mask);
    let legible = |ao: &Image<f32>| {
        pairs.as_ref().map(|p| p.measure(&shading.darkening(&ao.data, 1.0), &mask)).map_err(Clone::clone)
    };
    let pictures = vec![
        ("none", legible(&Image::filled(w, h, 0.0))),
        ("truth", legible(&ao_truth)),
        ("bundle-truth", legible(&bundle_ao)),
    ];
    let mut legibility_seconds = start.elapsed().as_secs_f64();
    let rows = rows
        .into_iter()
        .map(|(method, truth_name, target, ao)| {
            let scores = metrics::score(&ao, &target, &mask);
            let bundle = metrics::agreement(&ao.data, &bundle_ao.data, &mask);
            let image_ssim = metrics::mean_ssim(&composite(&ao), &true_image, &all);
            let start = std::time::Instant::now();
            let legibility = legible(&ao);
            legibility_seconds += start.elapsed().as_secs_f64();
            Row { method, truth: truth_name, scores, image_ssim, bundle, legibility, ao }
        })
        .collect();
    let bundle = Bundle { ao: bundle_ao, settings: bundle_settings, distance: bundle_distance };
    Ok(Report { truth, truth_seconds, ao: ao_truth, vo: vo_truth, bundle, mask, rows, pictures, legibility_seconds })
}

/// The ND map (level 0) of `chain`'s last frame and what AO darkens in it.
pub fn read_frame(session: &Session, chain: &lineao::AoChain) -> Result<(NdImage, Shading)> {
    let (device, queue) = (&session.gpu.device, &session.gpu.queue);
    let targets = chain.targets().context("nothing was rendered")?;
    let nd = lineao::readback::read_rgba(device, queue, &targets.nd[0])?;
    let color = lineao::readback::read_texture(device, queue, &targets.color.texture)?.to_vec4();
    let specular = lineao::readback::read_f32(device, queue, &targets.specular)?;
    Ok((nd, Shading::new(&color, &specular.data)))
}

/// The methods whose darkening reaches a transparent line's every layer: object-space AO at
/// each fragment's own point (screen-space AO darkens only the opaque G-buffer).
pub const THROUGH_THE_LAYERS: [&str; 3] = ["sweep", "variance-volume", "lineao+sweep"];

/// Legibility through the layers (`score --alpha …`): each method's transparent picture
/// darkened against the same transparent picture without AO (D = 1 − Y/Y_none, Y the
/// pictures' linear luminance), its depth order that of the nearest line at each pixel (the
/// opaque picture's G-buffer), over the pixels that show a line. Rows: `none` (0 by
/// definition) and [`THROUGH_THE_LAYERS`].
pub fn transparent_legibility(
    session: &mut Session,
    args: &crate::args::RenderArgs,
) -> Result<Vec<(String, Result<Legibility, Absent>)>> {
    let (w, h) = (args.image.width as usize, args.image.height as usize);
    let none = Method { screen: AoMethod::None, volume: None };
    let with = |method: Method, transparency: bool| {
        let mut a = args.clone();
        (a.image.timings, a.image.dump, a.shown.compare, a.shown.grid) = (false, None, None, false);
        a.shown.method = method;
        if !transparency {
            a.context.transparency = Default::default();
        }
        a
    };
    // The nearest line's depth: the opaque picture's G-buffer (no method: no guard band).
    let mut chains = Vec::new();
    session.compose_panels(&with(none, false), &mut chains)?;
    let (nd, _) = read_frame(session, &chains[0])?;
    anyhow::ensure!(chains[0].targets().is_some_and(|t| t.guard == 0), "the opaque picture has a guard band");
    let mask: Vec<bool> = nd.data.iter().map(|t| t[..3] != [0.0; 3]).collect();
    let depth = Image { data: nd.data.iter().map(|t| t[3]).collect(), width: w, height: h };
    let luminance = |image: &Rgba8| -> Vec<f32> {
        let linear = |c: u8| crate::label::linear(c as f32 / 255.0);
        image
            .data
            .chunks_exact(4)
            .map(|p| 0.2126 * linear(p[0]) + 0.7152 * linear(p[1]) + 0.0722 * linear(p[2]))
            .collect()
    };
    let (plain, _) = session.compose_panels(&with(none, true), &mut Vec::new())?;
    let y_none = luminance(&plain);
    let pairs = legibility::Pairs::sample(&depth, &mask);
    let mut rows =
        vec![("none".to_string(), pairs.as_ref().map(|p| p.measure(&vec![0.0; w * h], &mask)).map_err(Clone::clone))];
    for name in THROUGH_THE_LAYERS {
        let method = crate::args::parse_method(name).map_err(anyhow::Error::msg)?;
        let (image, _) = session.compose_panels(&with(method, true), &mut Vec::new())?;
        let d: Vec<f32> = luminance(&image)
            .iter()
            .zip(&y_none)
            .map(|(&y, &none)| if none > 0.0 { 1.0 - y / none } else { 0.0 })
            .collect();
        rows.push((name.to_string(), pairs.as_ref().map(|p| p.measure(&d, &mask)).map_err(Clone::clone)));
    }
    Ok(rows)
}

pub fn run(args: &ScoreArgs) -> Result<()> {
    let render = &args.render;
    crate::figure::refuse_in_score(&render.figure)?;
    let methods = if args.methods.is_empty() { ScoreMethod::all() } else { args.methods.clone() };
    let mut session = Session::open_with_points(render)?;
    if let Some(t) = render.context.transparency.settings() {
        // The truths start on the opaque G-buffer's lines: through the layers, legibility alone.
        let rows = transparent_legibility(&mut session, render)?;
        println!(
            "{}: {} x {}, alpha {}, context alpha {}, {} layers: legibility through the layers (darkening against the \
             same transparent picture without AO, depth order of the nearest line)",
            session.lines.name, render.image.width, render.image.height, t.alpha, t.context_alpha, t.layers
        );
        println!("{:<17} {:>7} {:>7} {:>7} {:>7} {:>7}", "method", "L 1%", "L 4%", "L 15%", "mean D", "black");
        for (name, l) in rows {
            match l {
                Ok(l) => println!(
                    "{name:<17} {:>+7.3} {:>+7.3} {:>+7.3} {:>7.3} {:>6.1}%",
                    l.scales[0],
                    l.scales[1],
                    l.scales[2],
                    l.mean_darkening,
                    100.0 * l.near_black
                ),
                Err(absent) => println!("{name:<17} {absent}"),
            }
        }
        return Ok(());
    }
    let report = score(&session, render, &methods, args.bundle_distance)?;
    let truth = &report.truth;
    let local = crate::truth::settings(render, session.longest_side);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&to_json(&session, render, &report))?);
    } else {
        let bundle = &report.bundle;
        println!(
            "{}: {} x {}, {} geometry pixels, {} rays; local truth to {} ({} falloff), mean {:.3}, {:.1} % buried; \
             bundle truth to {} = {:.1} ({} falloff), mean {:.3}",
            session.lines.name,
            render.image.width,
            render.image.height,
            truth.geometry_pixels,
            local.rays,
            crate::truth::reach_text(render),
            local.falloff.name(),
            mean_over(&report.ao, &report.mask),
            100.0 * truth.buried_share(),
            bundle.distance,
            bundle.settings.distance_world,
            bundle.settings.falloff.name(),
            mean_over(&bundle.ao, &report.mask),
        );
        println!(
            "{:<17} {:>8} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} | {:>6} {:>7} {:>7} {:>7} | {:>9}",
            "method",
            "truth",
            "mean",
            "bias",
            "mean|Δ|",
            "RMSE",
            "corr",
            "SSIM",
            "scale",
            "bias",
            "RMSE",
            "SSIM",
            "image SSIM"
        );
        for row in &report.rows {
            let s = &row.scores;
            println!(
                "{:<17} {:>8} {:>7.3} {:>+7.3} {:>7.3} {:>7.3} {:>7.3} {:>7.3} | {:>6.3} {:>+7.3} {:>7.3} {:>7.3} | {:>9.3}",
                row.method.name(),
                row.truth,
                s.mean_method,
                s.raw.bias,
                s.raw.mean_abs,
                s.raw.rmse,
                s.correlation,
                s.raw.ssim,
                s.scale,
                s.scaled.bias,
                s.scaled.rmse,
                s.scaled.ssim,
                row.image_ssim
            );
        }
        println!();
        print!("{}", legibility_table(&report));
    }
    if let Some(path) = &render.image.output {
        let image = grid(&report);
        crate::output::write_png(path, image.width, image.height, &image.data)?;
        eprintln!("lineao: score grid -> {}", path.display());
    }
    Ok(())
}

/// The mean of `ao` over `mask`.
fn mean_over(ao: &Image<f32>, mask: &[bool]) -> f64 {
    let (sum, n) =
        ao.data.iter().zip(mask).filter(|(_, m)| **m).fold((0.0, 0usize), |(s, n), (a, _)| (s + *a as f64, n + 1));
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// Per picture: L at the three scales and their mean, the mean darkening, the near-black share,
/// and for each method its correlation and RMSE against the bundle-scale truth.
pub fn legibility_table(report: &Report) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let scales: Vec<String> = legibility::SCALES.iter().map(|s| format!("L {:.0} %", s * 100.0)).collect();
    let _ = writeln!(
        out,
        "{:<17} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} | {:>7} {:>7}",
        "legibility", scales[0], scales[1], scales[2], "L mean", "dark", "black", "corr₂", "RMSE₂"
    );
    let line = |out: &mut String, name: &str, l: &Result<Legibility, Absent>, bundle: Option<&metrics::Agreement>| {
        let tail = bundle.map_or(String::new(), |b| format!(" | {:>7.3} {:>7.3}", b.correlation, b.rmse));
        let _ = match l {
            Ok(l) => writeln!(
                out,
                "{:<17} {:>+7.3} {:>+7.3} {:>+7.3} {:>+7.3} {:>7.3} {:>6.1}%{tail}",
                name,
                l.scales[0],
                l.scales[1],
                l.scales[2],
                l.mean(),
                l.mean_darkening,
                100.0 * l.near_black
            ),
            Err(why) => writeln!(out, "{name:<17} absent: {why}{tail}"),
        };
    };
    for (name, l) in &report.pictures {
        line(&mut out, name, l, None);
    }
    for row in &report.rows {
        line(&mut out, row.method.name(), &row.legibility, Some(&row.bundle));
    }
    out
}

/// A legibility as JSON: its three scales, mean, mean darkening and near-black share, or why it
/// is absent.
fn legibility_json(l: &Result<Legibility, Absent>) -> serde_json::Value {
    match l {
        Ok(l) => json!({
            "l_local": l.scales[0],
            "l_bundle": l.scales[1],
            "l_global": l.scales[2],
            "l_mean": l.mean(),
            "mean_darkening": l.mean_darkening,
            "near_black": l.near_black,
            "pixels": l.pixels,
        }),
        Err(why) => json!({"absent": why.to_string()}),
    }
}

/// docs/reference.md's `lineao score --json` object.
pub fn to_json(session: &Session, args: &crate::args::RenderArgs, report: &Report) -> serde_json::Value {
    let errors = |e: &metrics::Errors| json!({"bias": e.bias, "mean_abs": e.mean_abs, "rmse": e.rmse, "ssim": e.ssim});
    let settings = crate::truth::settings(args, session.longest_side);
    let bundle = &report.bundle;
    json!({
        "scene": session.lines.name,
        "width": args.image.width,
        "height": args.image.height,
        "rays": settings.rays,
        "ao_distance_world": settings.distance_world,
        "ao_falloff": settings.falloff.name(),
        "ray_seed": settings.seed,
        "geometry_pixels": report.truth.geometry_pixels,
        "compared_pixels": report.mask.iter().filter(|m| **m).count(),
        "buried_share": report.truth.buried_share(),
        "truth_seconds": report.truth_seconds,
        "truth_mean": mean_over(&report.ao, &report.mask),
        "bundle_truth": {
            "ao_distance": bundle.distance.to_string(),
            "ao_distance_world": bundle.settings.distance_world,
            "ao_falloff": bundle.settings.falloff.name(),
            "mean": mean_over(&bundle.ao, &report.mask),
            "buried_share": report.truth.buried_share(),
        },
        "legibility_scales": legibility::SCALES,
        "legibility_seconds": report.legibility_seconds,
        "pictures": report.pictures.iter().map(|(name, l)| json!({"picture": name, "legibility": legibility_json(l)})).collect::<Vec<_>>(),
        "methods": report.rows.iter().map(|row| {
            let s = &row.scores;
            let mut value = errors(&s.raw);
            if let Some(object) = value.as_object_mut() {
                object.extend([
                    ("method".to_string(), json!(row.method.name())),
                    ("truth".to_string(), json!(row.truth)),
                    ("pixels".to_string(), json!(s.pixels)),
                    ("mean".to_string(), json!(s.mean_method)),
                    ("truth_mean".to_string(), json!(s.mean_truth)),
                    ("correlation".to_string(), json!(s.correlation)),
                    ("scale".to_string(), json!(s.scale)),
                    ("scaled".to_string(), errors(&s.scaled)),
                    ("image_ssim".to_string(), json!(row.image_ssim)),
                    ("bundle".to_string(), {
                        let b = &row.bundle;
                        json!({"bias": b.bias, "mean_abs": b.mean_abs, "rmse": b.rmse,
                               "correlation": b.correlation, "truth_mean": b.mean_truth})
                    }),
                    ("legibility".to_string(), legibility_json(&row.legibility)),
                ]);
            }
            value
        }).collect::<Vec<_>>(),
    })
}

/// A gray AO map (white = open, black = occluded) with background in light blue.
fn gray(ao: &Image<f32>, mask: &[bool]) -> Rgba8 {
    let mut data = Vec::with_capacity(ao.data.len() * 4);
    for (a, &m) in ao.data.iter().zip(mask) {
        let v = (255.0 * (1.0 - a.clamp(0.0, 1.0))).round() as u8;
        data.extend(if m { [v, v, v, 255] } else { [210, 225, 240, 255] });
    }
    Rgba8 { width: ao.width as u32, height: ao.height as u32, data }
}

/// Signed error: red where the method is darker than the truth, blue where lighter, white
/// where equal (full colour at |Δ| = 0.5).
fn error_map(ao: &Image<f32>, truth: &Image<f32>, mask: &[bool]) -> Rgba8 {
    let mut data = Vec::with_capacity(ao.data.len() * 4);
    for ((a, t), &m) in ao.data.iter().zip(&truth.data).zip(mask) {
        let d = ((a - t) * 2.0).clamp(-1.0, 1.0);
        let fade = (255.0 * (1.0 - d.abs())).round() as u8;
        data.extend(match (m, d >= 0.0) {
            (false, _) => [210, 225, 240, 255],
            (true, true) => [255, fade, fade, 255],
            (true, false) => [fade, fade, 255, 255],
        });
    }
    Rgba8 { width: ao.width as u32, height: ao.height as u32, data }
}

/// Per method: its AO, the truth it is compared with, the signed error — a row each.
fn grid(report: &Report) -> Rgba8 {
    let mut tiles: Vec<(String, Rgba8)> = Vec::new();
    for row in &report.rows {
        let truth = match row.truth {
            "ao" => &report.ao,
            _ => report.vo.as_ref().unwrap_or(&report.ao),
        };
        tiles.push((row.method.name().to_string(), gray(&row.ao, &report.mask)));
        tiles.push((format!("truth ({})", row.truth), gray(truth, &report.mask)));
        tiles.push((format!("{} - truth", row.method.name()), error_map(&row.ao, truth, &report.mask)));
    }
    let labelled: Vec<(&str, &Rgba8)> = tiles.iter().map(|(l, t)| (l.as_str(), t)).collect();
    crate::label::grid(&labelled, 3)
}
