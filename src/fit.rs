//! `lineao score --fit`: the calibration behind `--preset calibrated`.
//!
//! Views: every built-in scene and every tractogram found under `--data` (at least 10
//! streamlines), each from `--views` cameras orbiting its own about the up axis. Even views fit,
//! odd views report (held out). On each view the truth is traced once (AO, and the VO truth of
//! the half ball for VO); every candidate setting of a method is rendered and its raw AO read
//! back; then, on the CPU, every strength s of a grid is applied as the composite does,
//! clamp(s · ao, 0, 1). The objective is the RMSE against the truth over the compared pixels,
//! averaged over views. The best candidate and strength on the fit half are reported with
//! both halves' errors, next to the paper's values at strength 1, and, per real tractogram, the
//! mean AO of both next to the truth's.

use std::path::{Path, PathBuf};

use anyhow::Result;
use glam::Quat;
use lineao::truth::{TruthSettings, VoBall};
use lineao::{AoMethod, ChainSettings, LineAoVariant};

use crate::cli::{Method, RenderArgs, ScoreArgs, ScoreMethod};
use crate::render::Session;
use crate::score::raw_ao;

/// A family's candidate: a label and what it changes.
struct Candidate {
    label: String,
    apply: Box<dyn Fn(&mut ChainSettings)>,
}

struct Family {
    method: ScoreMethod,
    /// The first candidate is the paper's (our defaults').
    candidates: Vec<Candidate>,
}

fn families(line_width: f32) -> Vec<Family> {
    let c = |label: String, apply: Box<dyn Fn(&mut ChainSettings)>| Candidate { label, apply };
    // The paper's first, then s_r × r0 (multiples of the line width) × the scale of δ(j).
    let mut lineao = Vec::new();
    let paper = (3, 1.5f32, 1.0f32);
    let grid = [1, 2, 3].into_iter().flat_map(|s_r| {
        [1.0f32, 1.5, 3.0]
            .into_iter()
            .flat_map(move |k| [1.0f32, 0.3, 0.1, 0.03].into_iter().map(move |delta| (s_r, k, delta)))
    });
    for (s_r, k, delta_scale) in std::iter::once(paper).chain(grid.filter(|&c| c != paper)) {
        let r0 = k * line_width;
        lineao.push(c(
            format!("s_r {s_r}, r0 {r0} px, δ scale {delta_scale}"),
            Box::new(move |s: &mut ChainSettings| {
                s.line_ao.s_r = s_r;
                s.line_ao.r0_px = Some(r0);
                s.line_ao.delta_scale = delta_scale;
            }),
        ));
    }
    let radii = |paper: f32, others: &[f32], set: fn(&mut ChainSettings, f32)| -> Vec<Candidate> {
        std::iter::once(paper)
            .chain(others.iter().copied())
            .map(|r| c(format!("radius {r}"), Box::new(move |s: &mut ChainSettings| set(s, r))))
            .collect()
    };
    let vo = |s: &mut ChainSettings, r: f32| s.vo.radius_world = r;
    let ssao = |s: &mut ChainSettings, r: f32| {
        s.ssao.radius_world = r;
        s.ssao.range_world = r;
    };
    let reference = |s: &mut ChainSettings, r: f32| s.line_ao.reference_radius_px = r;
    let family = |method, variant, candidates| Family { method: ScoreMethod { method, variant }, candidates };
    let paper = LineAoVariant::Paper;
    vec![
        family(AoMethod::LineAo, paper, lineao),
        family(AoMethod::LineAo, LineAoVariant::Reference, radii(2.0, &[1.0, 3.0], reference)),
        family(AoMethod::VoLine, paper, radii(2.0, &[1.0, 1.5, 3.0], vo)),
        family(AoMethod::VoArea, paper, radii(2.0, &[1.0, 3.0], vo)),
        family(AoMethod::Ssao, paper, radii(2.0, &[1.0, 1.5, 3.0], ssao)),
    ]
}

/// The strengths tried: 0.02 to 2 in steps of 0.02.
fn strengths() -> impl Iterator<Item = f32> {
    (1..=100).map(|i| i as f32 * 0.02)
}

/// One view's compared pixels: the truth and each candidate's raw AO there.
struct View {
    source: String,
    real: bool,
    fit: bool,
    /// Per family: the truth it is compared with, and per candidate the raw AO at its pixels.
    families: Vec<(Vec<f32>, Vec<Vec<f32>>)>,
}

fn rmse(ao: &[f32], truth: &[f32], strength: f32) -> f64 {
    let sum: f64 = ao.iter().zip(truth).map(|(a, t)| ((strength * a).clamp(0.0, 1.0) as f64 - *t as f64).powi(2)).sum();
    (sum / ao.len().max(1) as f64).sqrt()
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, c), v| (s + v, c + 1));
    if count == 0 { f64::NAN } else { sum / count as f64 }
}

/// Tractograms under `dir` with at least 10 streamlines.
fn real_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if let Ok(loaded) = lineao_tracts::load(&path)
                && loaded.tractogram.has_points()
                && loaded.tractogram.streamlines() >= 10
            {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

pub fn run(args: &ScoreArgs) -> Result<()> {
    // The candidates change the paper's values, the strength is searched apart.
    let base = &RenderArgs { preset: lineao::Preset::Paper, ..args.render.clone() };
    let mut sources: Vec<RenderArgs> =
        lineao_tracts::SceneKind::ALL.iter().map(|&scene| RenderArgs { scene, file: None, ..base.clone() }).collect();
    let files = real_files(&args.data);
    eprintln!(
        "lineao: fitting on {} scenes and {} tractograms from {}",
        sources.len(),
        files.len(),
        args.data.display()
    );
    sources.extend(files.into_iter().map(|f| RenderArgs { file: Some(f), ..base.clone() }));
    let families = families(base.line_width);
    let truth_settings = TruthSettings { vo: Some(VoBall::Half), ..crate::truth::settings(base) };
    let mut views: Vec<View> = Vec::new();
    for source in &sources {
        let mut session = Session::open(source)?;
        let home = session.camera;
        let real = source.file.is_some();
        for k in 0..args.views {
            let angle = std::f32::consts::TAU * k as f32 / args.views as f32;
            let turn = Quat::from_axis_angle(home.up.normalize(), angle);
            session.camera.eye = home.target + turn * (home.eye - home.target);
            let plain = session.settings(source, Method { screen: AoMethod::None, volume: None });
            let mut chain = None;
            let gbuffer = raw_ao(&session, &mut chain, plain, source.width, source.height)?;
            let truth = session.trace(chain.as_ref().expect("rendered"), &truth_settings)?;
            if truth.geometry_pixels == 0 {
                continue;
            }
            let mut per_family = Vec::new();
            for family in &families {
                let mut chain = None;
                let mut maps = Vec::new();
                let mut mask = gbuffer.geometry.clone();
                for candidate in &family.candidates {
                    let mut settings = crate::score::method_settings(&session, source, family.method);
                    (candidate.apply)(&mut settings);
                    let view = raw_ao(&session, &mut chain, settings, source.width, source.height)?;
                    mask.iter_mut().zip(&view.geometry).for_each(|(m, g)| *m &= g);
                    maps.push(view.ao.data);
                }
                let target = match family.method.method {
                    AoMethod::VoLine | AoMethod::VoArea => truth.vo.as_ref().expect("asked for"),
                    _ => &truth.ao,
                };
                let pick = |data: &[f32]| data.iter().zip(&mask).filter(|(_, m)| **m).map(|(v, _)| *v).collect();
                per_family.push((pick(&target.data), maps.iter().map(|m| pick(m)).collect()));
            }
            eprintln!(
                "lineao: fit view {} of {} ({} geometry pixels)",
                k + 1,
                session.lines.name,
                truth.geometry_pixels
            );
            views.push(View { source: session.lines.name.clone(), real, fit: k % 2 == 0, families: per_family });
        }
    }
    report(&families, &views);
    Ok(())
}

fn report(families: &[Family], views: &[View]) {
    println!("| method | setting | strength | RMSE fit | RMSE held out | paper RMSE fit | paper RMSE held out |");
    println!("|---|---|---:|---:|---:|---:|---:|");
    let mut chosen = Vec::new();
    for (f, family) in families.iter().enumerate() {
        let error = |views: &mut dyn Iterator<Item = &View>, c: usize, s: f32| {
            mean(views.map(|v| rmse(&v.families[f].1[c], &v.families[f].0, s)))
        };
        let fit = || views.iter().filter(|v| v.fit);
        let held = || views.iter().filter(|v| !v.fit);
        // The default must keep every real tractogram readable: on each, the mean AO over all
        // its views within 0.1 of the truth's (a requirement on the default, checked where it
        // is reported, not an objective: the RMSE still chooses on the fit half alone). The
        // least RMSE among the settings that keep it; the least RMSE overall where none does.
        let mean_of = |values: &[f32], s: f32| mean(values.iter().map(|a| (s * a).clamp(0.0, 1.0) as f64));
        let readable = |c: usize, s: f32| {
            let mut sources: Vec<&str> = views.iter().filter(|v| v.real).map(|v| v.source.as_str()).collect();
            sources.dedup();
            sources.iter().all(|source| {
                let of = || views.iter().filter(|v| v.source == *source);
                let method = mean(of().map(|v| mean_of(&v.families[f].1[c], s)));
                let truth = mean(of().map(|v| mean_of(&v.families[f].0, 1.0)));
                (method - truth).abs() <= 0.1
            })
        };
        let mut best = (f64::INFINITY, 0usize, 1.0f32);
        let mut best_readable = (f64::INFINITY, 0usize, 1.0f32);
        for c in 0..family.candidates.len() {
            for s in strengths() {
                let e = error(&mut fit(), c, s);
                if e < best.0 {
                    best = (e, c, s);
                }
                if e < best_readable.0 && readable(c, s) {
                    best_readable = (e, c, s);
                }
            }
        }
        let (_, c, s) = if best_readable.0.is_finite() { best_readable } else { best };
        if !best_readable.0.is_finite() {
            eprintln!("lineao: {}: no setting keeps every tractogram's mean within 0.1", family.method.name());
        }
        println!(
            "| {} | {} | {:.2} | {:.4} | {:.4} | {:.4} | {:.4} |",
            family.method.name(),
            family.candidates[c].label,
            s,
            error(&mut fit(), c, s),
            error(&mut held(), c, s),
            error(&mut fit(), 0, 1.0),
            error(&mut held(), 0, 1.0)
        );
        chosen.push((c, s));
    }
    // Per source: the mean AO of the paper's LineAO and the calibrated one against the truth.
    println!();
    println!(
        "| data | views | truth mean AO | lineao (paper) | lineao (calibrated) | calibrated − truth | vo-line (calibrated) − its truth |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    let mut sources: Vec<&str> = views.iter().map(|v| v.source.as_str()).collect();
    sources.dedup();
    for source in sources {
        let of: Vec<&View> = views.iter().filter(|v| v.source == source).collect();
        let mean_of = |values: &[f32], s: f32| mean(values.iter().map(|a| (s * a).clamp(0.0, 1.0) as f64));
        let truth = mean(of.iter().map(|v| mean_of(&v.families[0].0, 1.0)));
        let paper = mean(of.iter().map(|v| mean_of(&v.families[0].1[0], 1.0)));
        let (c, s) = chosen[0];
        let calibrated = mean(of.iter().map(|v| mean_of(&v.families[0].1[c], s)));
        let (vc, vs) = chosen[2];
        let vo = mean(of.iter().map(|v| mean_of(&v.families[2].1[vc], vs) - mean_of(&v.families[2].0, 1.0)));
        println!(
            "| {}{} | {} | {truth:.3} | {paper:.3} | {calibrated:.3} | {:+.3} | {:+.3} |",
            source,
            if of[0].real { "" } else { " (built-in)" },
            of.len(),
            calibrated - truth,
            vo
        );
    }
}
