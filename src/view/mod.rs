//! `lineao view`: a window (eframe + egui on wgpu) to orbit a tractogram and see LineAO against
//! the other methods, side by side on the same frame.
//!
//! - [`app`]: the window — menu, controls, image, divider, overlays, input.
//! - [`controls`]: the side panel's state and widgets, turned into the chain's settings.
//! - [`worker`]: the render thread with its own device, so that seconds-long lavapipe frames
//!   never block input; previews while the camera moves.
//! - [`camera`]: the orbit camera.
//!
//! The same viewer runs in a web page (the crate `lineao-web`): there the worker is stepped on
//! the page's thread ([`App::inline`]) and the options come from the page's URL.

pub mod app;
pub mod camera;
pub mod controls;
mod export;
pub mod keys;
mod loading;
pub mod record;
#[cfg(test)]
mod tests;
pub mod worker;

#[cfg(not(target_arch = "wasm32"))]
use anyhow::{Context, Result};

use crate::cli::{ColorArg, GeometryArg, ViewArgs};
use controls::{ColorMode, Controls, Geometry};
use worker::Source;

pub use app::{App, Options};

/// The viewer's opening state from the command line (or a web page's URL).
pub fn options(args: &ViewArgs) -> app::Options {
    let source = match &args.file {
        Some(path) => Source::File(path.clone()),
        None => {
            let kind = args.scene.unwrap_or(lineao_tracts::SceneKind::Bundles);
            Source::Scene { kind, vertices: args.vertices.unwrap_or(kind.default_vertices()), seed: 1 }
        }
    };
    // A volume or .tsf to colour by that cannot be read is said, and the lines keep their tangent
    // colours (the page cannot read files by name: it drops them).
    let sampled = crate::source::Sampled::of(&args.color).unwrap_or_else(|e| {
        eprintln!("lineao: {e:#}");
        None
    });
    // Likewise a volume for the slices (the lines are shown without them).
    let anatomy = args.volume.as_ref().and_then(|path| match lineao_tracts::Volume::load(path) {
        Ok(volume) => Some((path.display().to_string(), std::sync::Arc::new(volume))),
        Err(e) => {
            eprintln!("lineao: {e}; the tractogram is shown without its slices");
            None
        }
    });
    let preset = args.preset;
    let (methods, compare) = match args.compare {
        Some(pair) => (pair, true),
        None => ([args.method, crate::cli::Method { screen: lineao::AoMethod::Ssao, volume: None }], false),
    };
    let mut controls = Controls::new(methods, compare, preset);
    controls.geometry = match args.geometry {
        GeometryArg::Lines => Geometry::Lines,
        GeometryArg::Tubes => Geometry::Tubes,
    };
    controls.line_shading = args.line_shading;
    controls.color = match &args.color {
        ColorArg::Tangent => ColorMode::Tangent,
        ColorArg::Constant(rgb) => ColorMode::Constant(rgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)),
        ColorArg::Field(name) => ColorMode::Field(name.clone()),
        // Sampled at (or read for) every vertex as the lines arrive: a field.
        ColorArg::Volume(_) | ColorArg::Tsf(_) if sampled.is_some() => {
            ColorMode::Field(args.color.field().expect("a file's field"))
        }
        ColorArg::Volume(_) | ColorArg::Tsf(_) => ColorMode::Tangent,
        // Direction until the file's groups are known (`Controls::set_groups`).
        ColorArg::Groups => ColorMode::Groups,
    };
    controls.colormap = args.colormap;
    controls.debug_view = args.debug_view;
    controls.timings = args.timings;
    controls.params.chain.cull = args.cull;
    controls.params.chain.lod = args.lod;
    args.methods.apply(&mut controls.params.chain);
    controls.given = args.methods.clone();
    controls.set_selection(&args.select);
    if let Some(slab) = args.slab {
        (controls.slab, controls.params.chain.slab) = (slab, Some(slab));
    }
    if let Some(transparency) = args.transparency.settings() {
        controls.transparency = transparency.clone();
        controls.params.chain.transparency = Some(transparency);
    }
    controls.opaque_slices = args.opaque_slices;
    if let Some((name, volume)) = &anatomy {
        controls.set_anatomy(name, volume.world_box(), args.slices);
    }
    app::Options {
        source: Some(source),
        controls,
        orthographic: args.ortho,
        orbit: args.orbit,
        screenshot: args.screenshot.clone().map(|path| (path, args.frames)),
        record: args.record.clone().map(|path| (path, args.frames)),
        scale: args.scale,
        sampled,
        anatomy,
    }
}

/// Opens the viewer's window and runs it until it closes.
#[cfg(not(target_arch = "wasm32"))]
pub fn run(args: &ViewArgs) -> Result<()> {
    let options = options(args);
    let screenshot = options.screenshot.clone();
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("lineao")
            .with_inner_size([args.size[0] as f32, args.size[1] as f32]),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    let outcome = std::sync::Arc::new(std::sync::Mutex::new(app::Outcome::default()));
    let shared = outcome.clone();
    eframe::run_native(
        "lineao",
        native,
        Box::new(move |cc| {
            let mut app = app::App::new(&cc.egui_ctx, options);
            app.outcome = shared;
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| anyhow::anyhow!("{e}"))
    .context("cannot open the viewer's window (no display? run under xvfb-run, or use `lineao render`)")?;
    let outcome = outcome.lock().expect("not poisoned");
    if args.record.is_some() {
        if let Some(error) = &outcome.error {
            anyhow::bail!("{error}");
        }
        anyhow::ensure!(outcome.recorded.is_some(), "the window closed before the recording was written");
    }
    if let Some((path, _)) = screenshot {
        if let Some(error) = &outcome.error {
            anyhow::bail!("{error} (the screenshot {} shows it)", path.display());
        }
        anyhow::ensure!(outcome.saved.as_ref() == Some(&path), "the window closed before the screenshot was taken");
        match args.scale {
            1 => eprintln!("lineao: saved the window to {}", path.display()),
            k => eprintln!("lineao: saved the view at {k}× to {}", path.display()),
        }
    }
    Ok(())
}
