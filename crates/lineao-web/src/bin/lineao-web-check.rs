//! `lineao-web-check DIR...`: each DIR a frame the web page read back (scripts/test-web.sh
//! saves them), checked against lineao's CPU reference on exactly its inputs. Exits 1 when a
//! frame breaks docs/reference.md's agreement policy.
//!
//! `lineao-web-check --load FILE`: the page's parse of FILE (its bytes in memory, as a drop or a
//! fetch leaves them) natively, the median of five, for the page's load time to be compared.
//!
//! `lineao-web-check --color-range FILE COLOR`: the colour range (JSON `[min, max]`) the native
//! viewer and `lineao render` give FILE's lines coloured by `COLOR` (`volume:NII`, `tsf:TSF`,
//! `field:NAME`), for the page's to be compared.

use std::path::PathBuf;
use std::process::ExitCode;

use lineao_web::check::{Readback, check};

/// The native time of what the page's worker times as `loadMs`.
fn load(path: &str) -> ExitCode {
    let bytes: std::sync::Arc<[u8]> = match std::fs::read(path) {
        Ok(bytes) => bytes.into(),
        Err(e) => {
            eprintln!("{path}: {e}");
            return ExitCode::FAILURE;
        }
    };
    let source = lineao_cli::source::Source::Bytes { name: path.to_string(), bytes };
    let mut times = Vec::new();
    for _ in 0..5 {
        let start = std::time::Instant::now();
        if let Err(e) = source.load(None) {
            eprintln!("{e:#}");
            return ExitCode::FAILURE;
        }
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    println!("{path}: parsed natively from memory in {:.1} ms (median of 5)", times[2]);
    ExitCode::SUCCESS
}

/// The range of [`lineao_cli::render::percentile_range`] over FILE's values of `color`.
fn color_range(file: &str, color: &str) -> Result<[f32; 2], String> {
    let color = lineao_cli::args::parse_color(color)?;
    let mut tracts = lineao_tracts::load(file).map_err(|e| e.to_string())?.tractogram;
    if let Some(sampled) = lineao_cli::source::Sampled::of(&color).map_err(|e| format!("{e:#}"))? {
        sampled.add_to(&mut tracts, 0, file).map_err(|e| format!("{e:#}"))?;
    }
    let field = color.field().ok_or("a colour by no field has no range")?;
    let values =
        tracts.vertex_fields.iter().find(|f| f.name == field).ok_or_else(|| format!("{file}: no field {field}"))?;
    Ok(lineao_cli::render::percentile_range(&values.values))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, file, color] = &args[..]
        && flag == "--color-range"
    {
        return match color_range(file, color) {
            Ok([min, max]) => {
                println!("[{min}, {max}]");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("{e}");
                ExitCode::FAILURE
            }
        };
    }
    if let [flag, file] = &args[..]
        && flag == "--load"
    {
        return load(file);
    }
    let dirs: Vec<PathBuf> = args.iter().map(PathBuf::from).collect();
    if dirs.is_empty() {
        eprintln!(
            "usage: lineao-web-check DIR...  (frames the web page read back) | --load FILE | --color-range FILE COLOR"
        );
        return ExitCode::from(2);
    }
    let mut failed = false;
    for dir in &dirs {
        let outcome = Readback::read(dir).map_err(|e| format!("{e:#}")).and_then(|frame| {
            let agreement = check(&frame)?;
            Ok((frame.meta, agreement))
        });
        match outcome {
            Ok((meta, agreement)) => println!(
                "{}: {} on {} ({} × {} + guard {}): page vs CPU reference: {agreement}",
                dir.display(),
                meta.settings.method.name(),
                meta.adapter,
                meta.view.width,
                meta.view.height,
                meta.view.guard
            ),
            Err(e) => {
                eprintln!("{}: {e}", dir.display());
                failed = true;
            }
        }
    }
    if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}
