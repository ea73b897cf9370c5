//! Snapshot images of every pass on the built-in scenes, and of `lineao render --grid` and
//! `--compare`, to catch regressions (correctness comes from the CPU reference and the
//! closed-form tests). `UPDATE_SNAPSHOTS=1 cargo test` rewrites them; a failure leaves
//! `*.actual.png` and `*.diff.png` beside the snapshot (ignored by git).

use std::path::{Path, PathBuf};

mod common;
use common::read_png;

use glam::Vec3;
use lineao::LineGeometry;
use lineao::readback::read_texture;
use lineao::targets::Target;
use lineao::{AoChain, AoMethod, BilateralSettings, ChainSettings, DebugView, Gpu, LineAoSettings, LineAoVariant};
use lineao::{Camera, Projection};
use lineao_tracts::SceneKind;

const SIZE: (u32, u32) = (160, 128);
/// Per-channel difference that counts as a changed pixel (lavapipe is deterministic; this
/// absorbs rounding from another LLVM version), and the share of changed pixels allowed.
const CHANNEL_TOLERANCE: u8 = 3;
const MAX_CHANGED: f64 = 0.005;

fn snapshot_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots").join(format!("{name}.png"))
}

fn write_png(path: &Path, (width, height): (u32, u32), rgba: &[u8]) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header().unwrap().write_image_data(rgba).unwrap();
}

/// Compares a `size` image against the stored snapshot; returns a description of the failure.
fn check(name: &str, size: (u32, u32), rgba: &[u8]) -> Option<String> {
    let path = snapshot_path(name);
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
        write_png(&path, size, rgba);
        return None;
    }
    if !path.exists() {
        return Some(format!("{name}: no snapshot at {} (run with UPDATE_SNAPSHOTS=1)", path.display()));
    }
    let (stored, expected) = read_png(&path);
    if stored != size {
        return Some(format!("{name}: the snapshot is {stored:?}, the image {size:?}"));
    }
    let mut diff = vec![0u8; rgba.len()];
    let mut changed = 0usize;
    for (i, (a, b)) in rgba.chunks(4).zip(expected.chunks(4)).enumerate() {
        let worst = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap();
        if worst > CHANNEL_TOLERANCE {
            changed += 1;
        }
        diff[4 * i..4 * i + 4].copy_from_slice(&[worst.saturating_mul(8), 0, 0, 255]);
    }
    let share = changed as f64 / (size.0 * size.1) as f64;
    if share > MAX_CHANGED {
        write_png(&path.with_extension("actual.png"), size, rgba);
        write_png(&path.with_extension("diff.png"), size, &diff);
        return Some(format!(
            "{name}: {:.2} % of pixels changed (allowed {:.2} %)",
            100.0 * share,
            100.0 * MAX_CHANGED
        ));
    }
    None
}

#[test]
fn every_pass_on_every_scene() {
    // SAFETY: set before any thread of ours reads the environment.
    unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
    let gpu = Gpu::headless().expect("a wgpu adapter (install mesa-vulkan-drivers for lavapipe)");
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let target = Target::output(&gpu.device, "snapshot", SIZE, format);
    // Without levels of detail: each view is a frame after the first, which would keep the
    // pieces within half a pixel of the full strip; the snapshots hold the full strip's.
    let papers = ChainSettings { lod: false, ..ChainSettings::papers() };
    let mut chain = AoChain::new(&gpu.device, format, papers.clone()).unwrap();
    chain.resize(SIZE.0, SIZE.1).unwrap();
    let debug = |debug_view| ChainSettings { debug_view, ..papers.clone() };
    let reference = ChainSettings {
        line_ao: LineAoSettings { variant: LineAoVariant::Reference, ..Default::default() },
        debug_view: DebugView::Ao,
        ..papers.clone()
    };
    let views = [
        ("final", debug(DebugView::Final)),
        ("ao", debug(DebugView::Ao)),
        ("normals", debug(DebugView::Normals)),
        ("depth", debug(DebugView::Depth)),
        ("zoom", debug(DebugView::Zoom)),
        ("level1", debug(DebugView::Level(1))),
        ("level2", debug(DebugView::Level(2))),
        ("reference_ao", reference),
        ("ssao_ao", ChainSettings { method: AoMethod::Ssao, debug_view: DebugView::Ao, ..papers.clone() }),
        ("ssao_final", ChainSettings { method: AoMethod::Ssao, ..papers.clone() }),
        ("vo_line_ao", ChainSettings { method: AoMethod::VoLine, debug_view: DebugView::Ao, ..papers.clone() }),
        ("vo_area_ao", ChainSettings { method: AoMethod::VoArea, debug_view: DebugView::Ao, ..papers.clone() }),
        (
            "bilateral_ao",
            ChainSettings { blur: Some(BilateralSettings::default()), debug_view: DebugView::Ao, ..papers.clone() },
        ),
    ];
    let mut failures = Vec::new();
    for kind in SceneKind::ALL {
        let scene = kind.build(1, 40_000);
        let t = &scene.tractogram;
        let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &t.positions, &t.offsets).unwrap();
        let camera = Camera {
            eye: Vec3::from_array(scene.view.eye),
            target: Vec3::from_array(scene.view.target),
            up: Vec3::from_array(scene.view.up),
            projection: Projection::Perspective { fov_y_deg: scene.view.fov_y_deg },
        };
        for (view_name, settings) in views.clone() {
            chain.set_settings(&gpu.device, settings).unwrap();
            chain.prepare(&gpu.device, &gpu.queue, &camera, &geometry.bounds.unwrap()).unwrap();
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            chain.encode(&mut encoder, &geometry, &target.view).unwrap();
            gpu.queue.submit([encoder.finish()]);
            let image = read_texture(&gpu.device, &gpu.queue, &target.texture).unwrap();
            failures.extend(check(&format!("{}_{view_name}", kind.name()), SIZE, &image.bytes));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `lineao render --grid` (every method, labelled) on every scene, and `--compare` on one, with
/// the papers' values (`--preset paper`: the snapshots were made before the calibrated preset
/// became the default, and keep the papers' equations pinned).
#[test]
fn the_comparison_images() {
    let dir = common::scratch("snapshots-compare");
    // The whole brain's passes are pinned above; its grid (a million points through every
    // method, the CPU ones included) would cost CI more than it tells.
    let scenes = SceneKind::ALL.iter().filter(|&&k| k != SceneKind::WholeBrain);
    let mut runs: Vec<(String, Vec<&str>)> =
        scenes.map(|k| (format!("{}_grid", k.name()), vec!["--scene", k.name(), "--grid"])).collect();
    runs.push(("bundles_compare_lineao_ssao".into(), vec!["--scene", "bundles", "--compare", "lineao,ssao"]));
    let mut failures = Vec::new();
    for (name, extra) in &runs {
        let png = dir.join(format!("{name}.png"));
        let mut args =
            vec!["render", "--preset", "paper", "--vertices", "40000", "--width", "160", "--height", "128", "-o"];
        args.push(png.to_str().unwrap());
        args.extend(extra);
        let output = common::lineao(&args);
        assert!(output.status.success(), "{name}: {}", String::from_utf8_lossy(&output.stderr));
        let (size, rgba) = read_png(&png);
        failures.extend(check(name, size, &rgba));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
