//! `lineao view` as a user runs it: a real window on an X server (Xvfb, which `.ci/run` installs),
//! drawn by eframe's wgpu renderer on lavapipe, saved by `--screenshot` after `--frames` and
//! checked: the window's size, the control panel's colours on the left, the render in the
//! middle (the scene's lines over the white background, LineAO and SSAO side by side), and a
//! bad file's exit status and message. The in-process UI tests are in `src/view/tests.rs`.

use std::path::Path;
use std::process::{Command, Output};

mod common;
use common::{read_png, scratch};

/// Runs `lineao view ARGS` under `xvfb-run`, at most 300 s.
fn view(args: &[&str]) -> Output {
    let xvfb = Command::new("xvfb-run").arg("--help").output();
    assert!(
        xvfb.is_ok(),
        "xvfb-run is missing: install xvfb (`apt-get install xvfb xauth`, as .ci/run does) to test the viewer's window"
    );
    Command::new("timeout")
        .args(["300", "xvfb-run", "-a", "-s", "-screen 0 1600x1000x24", env!("CARGO_BIN_EXE_lineao"), "view"])
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The mean of `f` over the pixels in columns `x0..x1`, rows 60..height−60 (below the menu,
/// above the status bar).
fn region_mean(((w, h), rgba): &((u32, u32), Vec<u8>), x0: u32, x1: u32, f: impl Fn(&[u8]) -> f64) -> f64 {
    let (mut sum, mut total) = (0.0, 0usize);
    for y in 60..h - 60 {
        for x in x0..x1.min(*w) {
            sum += f(&rgba[((y * w + x) * 4) as usize..][..3]);
            total += 1;
        }
    }
    sum / total as f64
}

/// The fraction of pixels that are neither white nor a gray of egui's panels: the lines.
fn lines_fraction(image: &((u32, u32), Vec<u8>), x0: u32, x1: u32) -> f64 {
    region_mean(image, x0, x1, |p| (p[0].abs_diff(p[1]) >= 8 || p[1].abs_diff(p[2]) >= 8) as u8 as f64)
}

fn mean_luminance(image: &((u32, u32), Vec<u8>), x0: u32, x1: u32) -> f64 {
    region_mean(image, x0, x1, |p| (p[0] as f64 + p[1] as f64 + p[2] as f64) / 765.0)
}

#[test]
fn the_window_shows_the_panel_and_the_render_side_by_side() {
    let dir = scratch("view_window");
    let png = dir.join("window.png");
    let out = view(&[
        "--scene",
        "bundles",
        "--vertices",
        "80000",
        "--compare",
        "lineao,ssao",
        "--size",
        "1000x640",
        "--screenshot",
        png.to_str().unwrap(),
        "--frames",
        "5",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let image = read_png(&png);
    assert_eq!(image.0, (1000, 640));
    // The control panel (egui's dark theme) on the left, the render's white background right.
    let (panel, render) = (mean_luminance(&image, 0, 250), mean_luminance(&image, 360, 980));
    assert!(panel < 0.3 && render > 0.6, "panel {panel:.2}, render {render:.2}");
    // The render on the right of it, both halves of the split showing lines.
    let (left, right) = (lines_fraction(&image, 360, 640), lines_fraction(&image, 700, 980));
    assert!(left > 0.05 && right > 0.05, "lines on both sides: {left:.3}, {right:.3}");
}

#[test]
fn a_real_file_opens_and_a_bad_one_exits_1_naming_it() {
    let dir = scratch("view_files");
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    let file = data.join("dipy+dipy/dipy/data/files/tracks300.trk");
    let png = dir.join("tracks300.png");
    let out = view(&[file.to_str().unwrap(), "--size", "800x600", "--screenshot", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let image = read_png(&png);
    assert_eq!(image.0, (800, 600));
    assert!(lines_fraction(&image, 360, 780) > 0.02, "the tracts are on screen");

    let bad = dir.join("broken.tck");
    std::fs::write(&bad, b"mrtrix tracks\ncount: 3\ndatatype: Float32LE\nfile: . 9999\nEND\n").unwrap();
    let shot = dir.join("broken.png");
    let out = view(&[bad.to_str().unwrap(), "--size", "800x600", "--screenshot", shot.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("broken.tck"), "{}", stderr(&out));
    // The window showed the message, and the screenshot has it.
    assert_eq!(read_png(&shot).0, (800, 600));
}

/// `--record MOVIE --frames N` records what the window shows: N PNG frames of the window
/// beside the movie, and an animated PNG of them that the `png` crate's decoder reads back.
#[test]
fn the_viewer_records_what_it_shows() {
    let dir = scratch("view_record");
    let movie = dir.join("rec.apng");
    let out = view(&["--vertices", "30000", "--size", "640x480", "--record", movie.to_str().unwrap(), "--frames", "4"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(stderr(&out).contains("4 frames"), "{}", stderr(&out));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&movie).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    assert_eq!(reader.info().animation_control.map(|a| a.num_frames), Some(4));
    for k in 0..4 {
        let mut frame = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut frame).unwrap();
        let png = read_png(&dir.join(format!("rec-0000{k}.png")));
        assert_eq!((png.0, &png.1[..]), ((640, 480), &frame[..info.buffer_size()]), "frame {k}");
        assert!(lines_fraction(&png, 360, 620) > 0.02, "frame {k} shows the tracts");
    }
    // A movie it cannot write is refused before anything is recorded, naming it.
    let out = view(&["--vertices", "3000", "--size", "320x240", "--record", "rec.avi", "--frames", "2"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("--record rec.avi"), "{}", stderr(&out));
}

/// `--scale K --screenshot PNG` saves the view on screen rendered at K × the image's size by
/// `render`'s own path (the same data, camera and settings), not the window.
#[test]
fn a_picture_at_a_scale_is_the_view_at_that_size() {
    let dir = scratch("view_scale");
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    let file = data.join("dipy+dipy/dipy/data/files/tracks300.trk");
    let png = dir.join("scaled.png");
    let args = [file.to_str().unwrap(), "--size", "800x600", "--scale", "2", "--screenshot", png.to_str().unwrap()];
    let out = view(&args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let image = read_png(&png);
    let (w, h) = image.0;
    // Twice the image beside the side panel, below the menu: not the window's 800 × 600.
    assert!(w % 2 == 0 && h % 2 == 0 && (300..800).contains(&(w / 2)) && (400..600).contains(&(h / 2)), "{w} x {h}");
    assert!(lines_fraction(&image, 0, w) > 0.02, "the tracts are in the picture");
    assert!(stderr(&out).contains(&format!("at {w} x {h}")), "{}", stderr(&out));
}
