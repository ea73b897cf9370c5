//! The viewer driven headlessly by egui's test harness (kittest): real input events, the real
//! render thread on lavapipe, and the window's pixels rendered by egui's wgpu renderer and
//! compared with the frames the render thread produced — so "the screen shows the render" is
//! checked pixel by pixel, not assumed. `tests/view.rs` runs the binary itself under Xvfb.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use egui::{Event, Modifiers, PointerButton, Pos2, Rect};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use lineao::AoMethod;
use lineao_tracts::SceneKind;

use super::app::{App, Options};
use super::controls::{ColorMode, Controls, RAY_TRACED, methods};
use super::loading::PREVIEW_VERTICES;
use super::worker::Source;
use lineao::Preset;

const SIZE: [f32; 2] = [1000.0, 640.0];

fn options(source: Source, methods: [crate::cli::Method; 2], compare: bool) -> Options {
    Options {
        anatomy: None,
        source: Some(source),
        controls: Controls::new(methods, compare, Preset::Paper),
        orthographic: false,
        orbit: None,
        screenshot: None,
        record: None,
        scale: 1,
        sampled: None,
    }
}

fn scene(kind: SceneKind, vertices: usize) -> Source {
    Source::Scene { kind, vertices, seed: 1 }
}

/// The app in egui's harness, rendered by egui's wgpu renderer. The harness steps the UI itself
/// (`settle` polls), so the render thread's repaint requests go to a context of their own; the
/// eframe window around the app is `tests/view.rs`'s.
fn harness(options: Options) -> Harness<'static, App> {
    let app = App::new(&egui::Context::default(), options);
    Harness::builder().with_size(SIZE).wgpu().build_ui_state(|ui, app: &mut App| app.show(ui), app)
}

/// Steps the UI until the newest view is on screen (or an error is), then once more.
fn settle(harness: &mut Harness<'_, App>) {
    let deadline = Instant::now() + Duration::from_secs(300);
    harness.step();
    while !harness.state().settled() {
        assert!(Instant::now() < deadline, "the viewer did not settle in 300 s");
        std::thread::sleep(Duration::from_millis(10));
        harness.step();
    }
    harness.step();
}

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data").join(rel)
}

/// The fraction of the window's pixels in `region` that show `image` (RGBA8, `size`) drawn at
/// `rect` within 2 levels: the app draws frames on whole pixels, one texel per pixel (points are
/// pixels here).
fn screen_vs_frame(screen: &image::RgbaImage, region: Rect, rect: Rect, image: &[u8], size: (u32, u32)) -> f32 {
    let (mut matched, mut total) = (0usize, 0usize);
    for y in region.top().ceil() as u32..region.bottom().floor() as u32 {
        for x in region.left().ceil() as u32..region.right().floor() as u32 {
            let (tx, ty) = (x - rect.left() as u32, y - rect.top() as u32);
            let t = ((ty.min(size.1 - 1) * size.0 + tx.min(size.0 - 1)) * 4) as usize;
            let s = screen.get_pixel(x, y).0;
            matched += (0..3).all(|c| s[c].abs_diff(image[t + c]) <= 2) as usize;
            total += 1;
        }
    }
    matched as f32 / total as f32
}

/// Opens the combo box showing `showing` and picks `item` in it, as a user does; then settles.
fn choose(harness: &mut Harness<'_, App>, showing: &str, item: &str) {
    let combo =
        harness.get_all_by_role(egui::accesskit::Role::ComboBox).find(|n| n.value().as_deref() == Some(showing));
    combo.unwrap_or_else(|| panic!("a combo box showing {showing}")).click();
    harness.run_steps(2);
    harness.get_by_label(item).click();
    settle(harness);
}

/// Moves the pointer to `pos` and presses the primary button there.
fn press_at(harness: &mut Harness<'_, App>, pos: Pos2) {
    harness.event(Event::PointerMoved(pos));
    harness.step();
    button(harness, pos, true);
}

fn button(harness: &Harness<'_, App>, pos: Pos2, pressed: bool) {
    let modifiers = Modifiers::NONE;
    harness.event(Event::PointerButton { pos, button: PointerButton::Primary, pressed, modifiers });
}

fn mean_luminance(image: &[u8]) -> f64 {
    image.chunks_exact(4).map(|p| p[0] as f64 + p[1] as f64 + p[2] as f64).sum::<f64>()
        / (image.len() / 4) as f64
        / 765.0
}

fn non_background(image: &[u8]) -> f64 {
    image.chunks_exact(4).filter(|p| p[..3] != [255, 255, 255]).count() as f64 / (image.len() / 4) as f64
}

#[test]
fn a_built_in_scene_is_on_screen_with_the_panel() {
    let mut harness = harness(options(scene(SceneKind::Bundles, 60_000), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let frame = app.shown.as_ref().expect("a frame");
    let rect = app.image_rect.expect("laid out");
    // The image fills the central area at its size in pixels.
    assert_eq!(frame.size, (rect.width().round() as u32, rect.height().round() as u32));
    assert!(non_background(&frame.images[0]) > 0.05, "the scene covers the image");
    let image = frame.images[0].clone();
    let size = frame.size;
    // The panel: the method, the compare switch, the presets, the parameters of LineAO.
    for label in ["Compare side by side", "Paper (dense)", "Reset to defaults", "s_r hemispheres", "GPU time per pass"]
    {
        assert!(harness.query_all_by_label(label).next().is_some(), "the panel shows '{label}'");
    }
    harness.get_by_label_contains(" streamlines · ");
    let screen = harness.render().expect("the window renders");
    let matched = screen_vs_frame(&screen, rect, rect, &image, size);
    assert!(matched > 0.97, "{:.1} % of the window's pixels show the frame", 100.0 * matched);
}

#[test]
fn the_viewer_renders_what_the_library_renders() {
    // The render thread's frame against an AoChain driven directly, same settings and camera.
    let mut harness = harness(options(scene(SceneKind::Spiral, 30_000), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    let frame = harness.state().shown.as_ref().expect("a frame");
    let gpu = lineao::Gpu::headless().unwrap();
    let built = SceneKind::Spiral.build(1, 30_000);
    let t = &built.tractogram;
    let geometry = lineao::LineGeometry::new(&gpu.device, &gpu.queue, &t.positions, &t.offsets).unwrap();
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let mut chain = lineao::AoChain::new(&gpu.device, format, frame.view.panels[0].settings.clone()).unwrap();
    chain.resize(frame.size.0, frame.size.1).unwrap();
    chain.prepare(&gpu.device, &gpu.queue, &frame.view.camera, &geometry.bounds.unwrap());
    let target = lineao::targets::Target::output(&gpu.device, "test", frame.size, format);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &geometry, &target.view).unwrap();
    gpu.queue.submit([encoder.finish()]);
    let direct = lineao::readback::read_texture(&gpu.device, &gpu.queue, &target.texture).unwrap().bytes;
    let differing = direct.iter().zip(&frame.images[0]).filter(|(a, b)| a.abs_diff(**b) > 1).count();
    assert!(differing * 1000 < direct.len(), "{differing} of {} bytes differ", direct.len());
}

#[test]
fn compare_shows_two_methods_split_at_the_divider_which_drags() {
    let mut harness = harness(options(scene(SceneKind::Bundles, 60_000), [methods()[1], methods()[4]], true));
    settle(&mut harness);
    let app = harness.state();
    let frame = app.shown.as_ref().expect("a frame");
    assert_eq!(frame.images.len(), 2);
    assert_eq!(frame.view.panels[0].settings.method, AoMethod::LineAo);
    assert_eq!(frame.view.panels[1].settings.method, AoMethod::Ssao);
    assert_ne!(frame.images[0], frame.images[1], "two methods, two images");
    let rect = app.image_rect.unwrap();
    // Drag the divider from the middle to a quarter of the width.
    let from = Pos2::new(rect.left() + 0.5 * rect.width(), rect.center().y);
    let to = Pos2::new(rect.left() + 0.25 * rect.width(), rect.center().y);
    press_at(&mut harness, from);
    harness.step();
    for k in 1..=8 {
        harness.event(Event::PointerMoved(from + (to - from) * (k as f32 / 8.0)));
        harness.step();
    }
    button(&harness, to, false);
    harness.step();
    let app = harness.state();
    assert!((app.divider - 0.25).abs() < 0.01, "divider at {}", app.divider);
    assert!(app.settled(), "moving the divider renders nothing new");
    let frame = app.shown.as_ref().unwrap();
    let (images, size) = (frame.images.clone(), frame.size);
    let split = rect.left() + 0.25 * rect.width();
    let left = Rect::from_x_y_ranges(rect.left()..=split - 4.0, rect.top() + 40.0..=rect.bottom());
    let right = Rect::from_x_y_ranges(split + 4.0..=rect.right(), rect.top() + 40.0..=rect.bottom());
    let screen = harness.render().unwrap();
    let l = screen_vs_frame(&screen, left, rect, &images[0], size);
    let r = screen_vs_frame(&screen, right, rect, &images[1], size);
    assert!(l > 0.97 && r > 0.97, "left {l:.3}, right {r:.3} of the pixels show their method");
    // And the other way round fails: the halves really differ.
    let swapped = screen_vs_frame(&screen, right, rect, &images[0], size);
    assert!(swapped < r, "LineAO's image does not also match the SSAO half ({swapped:.3})");
}

#[test]
fn the_method_selector_switches_the_method() {
    let mut harness = harness(options(scene(SceneKind::Bundles, 60_000), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    let lineao = harness.state().shown.as_ref().unwrap().images[0].clone();
    choose(&mut harness, "LineAO", "none");
    let frame = harness.state().shown.as_ref().unwrap();
    assert_eq!(frame.view.panels[0].settings.method, AoMethod::None);
    let none = &frame.images[0];
    // Occlusion only darkens: without it the same view is brighter.
    assert!(
        mean_luminance(none) > mean_luminance(&lineao) + 0.005,
        "{} vs {}",
        mean_luminance(none),
        mean_luminance(&lineao)
    );
}

/// A method's panel made from its settings' descriptions (the registry's test method `toy`):
/// its slider and checkbox are there, and the checkbox changes the picture.
#[test]
fn a_methods_described_settings_are_its_controls() {
    let toy = crate::cli::Method { screen: AoMethod::from_name("toy").expect("the tests' build has it"), volume: None };
    let mut harness = harness(options(scene(SceneKind::Bundles, 20_000), [toy, methods()[4]], false));
    settle(&mut harness);
    let quarter = harness.state().shown.as_ref().unwrap().images[0].clone();
    assert!(harness.query_all_by_label_contains("radius (zoom units)").count() > 0, "the slider");
    harness.get_by_label("invert").click();
    settle(&mut harness);
    let frame = harness.state().shown.as_ref().unwrap();
    assert!(frame.view.panels[0].settings.toy.invert, "the checkbox sets the toy's switch");
    // Three quarters of occlusion instead of one.
    assert!(mean_luminance(&frame.images[0]) < mean_luminance(&quarter) - 0.005);
}

/// Opens `file` of the shared images coloured by `color` (a file beside it: `volume:`, `tsf:`)
/// and returns the colour range the lines are drawn with (the side panel's colour bar says it)
/// and the share of the picture they cover.
fn colour_range_by_file(file: &str, color: crate::args::ColorArg) -> ([f32; 2], f64) {
    let images = "niivue+niivue/packages/niivue/demos/images";
    let mut options = options(Source::File(data(&format!("{images}/{file}"))), [methods()[1], methods()[4]], false);
    options.sampled = crate::source::Sampled::of(&color).unwrap();
    options.controls.color = super::controls::ColorMode::Field(color.field().unwrap());
    let mut harness = harness(options);
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let frame = app.shown.as_ref().unwrap();
    let lineao::LineColor::Scalar { range, .. } = frame.view.panels[0].settings.line_color else {
        panic!("coloured by {color:?}: {:?}", frame.view.panels[0].settings.line_color)
    };
    let drawn = non_background(&frame.images[0]);
    for label in crate::label::legend_labels(range) {
        harness.get_by_label(&label);
    }
    (range, drawn)
}

#[test]
fn a_volume_colours_the_lines_it_is_sampled_at() {
    // `--color volume:strokez.nii.gz` on stroke.trk.gz: the z-map sampled at every vertex as it
    // arrives, a field the lines are coloured by through the colormap.
    let volume = data("niivue+niivue/packages/niivue/demos/images/strokez.nii.gz");
    let (range, drawn) = colour_range_by_file("stroke.trk.gz", crate::args::ColorArg::Volume(volume));
    // The z-map along the streamlines spans 0 to about 1 (its 2nd to 98th percentile).
    assert!(range[0] >= 0.0 && range[1] > 0.5 && range[1] < 1.3, "{range:?}");
    assert!(drawn > 0.05, "{drawn}");
}

#[test]
fn a_tsf_colours_the_tck_it_belongs_to() {
    // `--color tsf:mni152.SLF1_R.tsf` on tract.SLF1_R.tck (mrview's scalar file): its values, a
    // vertex each, the field the lines are coloured by as they arrive.
    let tsf = data("niivue+niivue/packages/niivue/demos/images/mni152.SLF1_R.tsf");
    let (range, drawn) = colour_range_by_file("tract.SLF1_R.tck", crate::args::ColorArg::Tsf(tsf.clone()));
    assert!(drawn > 0.002, "13 streamlines drawn: {drawn}");
    let values = &lineao_tracts::load(&tsf).unwrap().tractogram.vertex_fields[0].values;
    let (lo, hi) = values.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    assert!(range[0] >= lo && range[1] <= hi && range[1] - range[0] > 0.5 * (hi - lo), "{range:?} in {lo}..{hi}");
}

#[test]
fn a_tsf_opened_beside_its_tck_colours_it_and_another_tractogram_is_left_alone() {
    // `view tract.SLF1_R.tck`, then mni152.SLF1_R.tsf opened (or dropped) beside it: the values
    // are added to the lines shown, without reading the .tck again, and coloured by; a .tsf
    // opened first waits for the tractogram; another tractogram opened next is not coloured by
    // it; a .tsf of another tractogram is an error naming both, the lines kept.
    let images = "niivue+niivue/packages/niivue/demos/images";
    let (tck, tsf) = (data(&format!("{images}/tract.SLF1_R.tck")), data(&format!("{images}/mni152.SLF1_R.tsf")));
    let coloured_by = |harness: &Harness<'_, App>| match &harness.state().controls.color {
        ColorMode::Field(name) => harness.state().dataset.as_ref().unwrap().fields.iter().any(|(f, _)| f == name),
        _ => false,
    };
    let mut harness = harness(options(Source::File(tck.clone()), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    let plain = harness.state().shown.as_ref().unwrap().images[0].clone();
    harness.state_mut().open_path(tsf.clone());
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    assert!(coloured_by(&harness), "{:?}", harness.state().controls.color);
    let shown = &harness.state().shown.as_ref().unwrap().images[0];
    let changed = shown.chunks_exact(4).zip(plain.chunks_exact(4)).filter(|(a, b)| a != b).count();
    assert!(changed > 1000, "{changed} pixels recoloured");
    // Another tractogram: its own colours.
    harness.state_mut().open_path(data(&format!("{images}/tract.IFOF_R.trk")));
    settle(&mut harness);
    assert!(harness.state().error.is_none(), "{:?}", harness.state().error);
    assert_eq!(harness.state().controls.color, ColorMode::Tangent);
    // The .tsf beside it: not its streamlines.
    harness.state_mut().open_path(tsf.clone());
    settle(&mut harness);
    let error = harness.state().error.clone().expect("an error");
    assert!(error.contains("mni152.SLF1_R.tsf does not belong to") && error.contains("tract.IFOF_R.trk"), "{error}");
    assert_eq!(harness.state().dataset.as_ref().unwrap().streamlines, 14, "the lines stay");
    assert_eq!(harness.state().controls.color, ColorMode::Tangent, "in their own colours");

    // The .tsf first, in a window with nothing open yet: the next tractogram takes it.
    let empty = Options { source: None, ..options(Source::File(tck.clone()), [methods()[1], methods()[4]], false) };
    let mut harness = self::harness(empty);
    harness.state_mut().open_path(tsf);
    harness.state_mut().open_path(tck);
    settle(&mut harness);
    assert!(harness.state().error.is_none(), "{:?}", harness.state().error);
    assert!(coloured_by(&harness), "{:?}", harness.state().controls.color);
}

#[test]
fn a_volume_given_after_a_streamed_tractogram_arrived_colours_it() {
    // stroke.trk.gz streamed (its points not kept), then strokez.nii.gz's values asked for (a
    // page's colour by address, were it to come late): read again for its points and sampled,
    // the range the command line's.
    let images = "niivue+niivue/packages/niivue/demos/images";
    let (trk, nii) = (data(&format!("{images}/stroke.trk.gz")), data(&format!("{images}/strokez.nii.gz")));
    let mut harness = harness(options(Source::File(trk.clone()), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    let volume = lineao_tracts::Volume::load(&nii).unwrap();
    let sampled = crate::source::Sampled::from_volume("strokez.nii.gz", volume.clone());
    harness.state_mut().colour_by(std::sync::Arc::new(sampled));
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    assert_eq!(app.controls.color, ColorMode::Field("volume:strokez.nii.gz".into()));
    let fields = &app.dataset.as_ref().unwrap().fields;
    let (_, range) = fields.iter().find(|(name, _)| name == "volume:strokez.nii.gz").expect("the volume's field");
    let points = lineao_tracts::load(&trk).unwrap().tractogram.positions;
    assert_eq!(*range, crate::render::percentile_range(&volume.sample_points(&points)));
}

#[test]
fn the_anatomy_colours_the_lines_chosen_in_the_side_panel() {
    // `view stroke.trk.gz`, strokez.nii.gz opened beside it as the anatomy, then "anatomy"
    // chosen in the colour list: the lines (streamed, so read again for their points) take the
    // volume's values, the range `--color volume:` gives; asked while a tractogram arrives, they
    // follow once it is whole; a tractogram opened next takes them as it arrives.
    let images = "niivue+niivue/packages/niivue/demos/images";
    let (trk, nii) = (data(&format!("{images}/stroke.trk.gz")), data(&format!("{images}/strokez.nii.gz")));
    let field = format!("volume:{}", nii.display());
    let volume = lineao_tracts::Volume::load(&nii).unwrap();
    let points = lineao_tracts::load(&trk).unwrap().tractogram.positions;
    let expected = crate::render::percentile_range(&volume.sample_points(&points));
    let coloured = |harness: &Harness<'_, App>| {
        let app = harness.state();
        assert!(app.error.is_none(), "{:?}", app.error);
        assert_eq!(app.controls.color, ColorMode::Field(field.clone()));
        let frame = app.shown.as_ref().unwrap();
        let lineao::LineColor::Scalar { range, .. } = frame.view.panels[0].settings.line_color else {
            panic!("{:?}", frame.view.panels[0].settings.line_color)
        };
        range
    };
    let mut harness = harness(options(Source::File(trk.clone()), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    assert!(harness.query_by_label("anatomy").is_none(), "no anatomy, no such colour");
    harness.state_mut().open_path(nii.clone());
    settle(&mut harness);
    choose(&mut harness, "direction", "anatomy");
    assert_eq!(coloured(&harness), expected);
    let combo =
        harness.get_all_by_role(egui::accesskit::Role::ComboBox).find(|n| n.value().as_deref() == Some("anatomy"));
    assert!(combo.is_some(), "the colour list says what colours the lines");
    // The next tractogram opened: sampled as it arrives.
    harness.state_mut().load(Source::File(trk.clone()));
    settle(&mut harness);
    assert_eq!(coloured(&harness), expected);
    // `view stroke.trk.gz --volume strokez.nii.gz`, the colour asked for while the tractogram
    // arrives: it follows once the tractogram is whole.
    let mut options = options(Source::File(trk), [methods()[1], methods()[4]], false);
    options.anatomy = Some((nii.display().to_string(), std::sync::Arc::new(volume)));
    let mut harness = self::harness(options);
    assert!(harness.state().is_loading());
    harness.state_mut().colour_by_anatomy();
    settle(&mut harness);
    assert_eq!(coloured(&harness), expected);
}

#[test]
fn a_real_file_opens_and_a_bad_one_says_why() {
    let path = data("niivue+niivue/packages/niivue/demos/images/stroke.trk.gz");
    let mut harness = harness(options(Source::File(path.clone()), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let dataset = app.dataset.as_ref().unwrap();
    // FACTS.txt (nibabel): 36763 streamlines, 237468 points.
    assert_eq!((dataset.streamlines, dataset.vertices), (36763, 237468));
    assert!(non_background(&app.shown.as_ref().unwrap().images[0]) > 0.05);
    harness.get_by_label_contains("stroke.trk.gz");

    // A truncated copy: an error naming the file, shown in the window; no panic.
    // Removed when the test ends, failed or not (its files are ~90 MB).
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let bad = dir.join("truncated.trk");
    let bytes = std::fs::read(data("dipy+dipy/dipy/data/files/tracks300.trk")).unwrap();
    std::fs::write(&bad, &bytes[..1200]).unwrap();
    harness.state_mut().load(Source::File(bad.clone()));
    settle(&mut harness);
    let error = harness.state().error.clone().expect("an error");
    assert!(error.contains("truncated.trk"), "{error}");
    assert!(harness.state().dataset.is_none() && harness.state().shown.is_none());
    harness.get_by_label(&error);

    // A large file cut short in its data: drawn as it arrives, then the error naming the file
    // and its byte beside what arrived, which stays (and answers the camera) — drawn after the
    // error where the reading failed before a first picture (a file shorter than a page read in
    // a step).
    let brain = lineao_tracts::scenes::wholebrain::WholeBrain::new(1, 4_000_000);
    let whole = dir.join("whole.tck");
    lineao_tracts::save(&brain.tractogram(0..brain.streamlines()), &whole).unwrap();
    let bytes = std::fs::read(&whole).unwrap();
    let cut = dir.join("cut.tck");
    std::fs::write(&cut, &bytes[..bytes.len() * 9 / 10 + 5]).unwrap();
    harness.state_mut().load(Source::File(cut.clone()));
    settle(&mut harness);
    let deadline = Instant::now() + Duration::from_secs(300);
    while harness.state().dataset.is_some() && harness.state().shown.is_none() {
        assert!(Instant::now() < deadline, "what arrived was not drawn in 300 s");
        std::thread::sleep(Duration::from_millis(10));
        harness.step();
    }
    let app = harness.state();
    let error = app.error.clone().expect("an error");
    assert!(error.contains("cut.tck") && error.contains("at byte"), "{error}");
    let dataset = app.dataset.as_ref().expect("what arrived before the error");
    assert!(dataset.vertices > 1_000_000 && !dataset.complete, "{} vertices", dataset.vertices);
    assert!(non_background(&app.shown.as_ref().expect("a frame").images[0]) > 0.05);

    // Dropping a good file onto the window opens it.
    #[derive(Debug)]
    struct Dropped(PathBuf);
    impl egui::DroppedFile for Dropped {
        fn path(&self) -> &Path {
            &self.0
        }
        fn bytes(&self) -> Result<Vec<u8>, String> {
            std::fs::read(&self.0).map_err(|e| e.to_string())
        }
    }
    let good = data("dipy+dipy/dipy/data/files/tracks300.trk");
    harness.input_mut().dropped_files.push(std::sync::Arc::new(Dropped(good)));
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    assert_eq!(app.dataset.as_ref().map(|d| (d.streamlines, d.vertices)), Some((300, 14576)));
}

#[test]
fn big_data_previews_while_the_camera_moves_without_blocking_input() {
    let vertices = 2 * PREVIEW_VERTICES + 50_000;
    let mut harness = harness(options(scene(SceneKind::Bundles, vertices), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    let full = harness.state().shown.as_ref().unwrap().size;
    let rect = harness.state().image_rect.unwrap();
    let home = harness.state().camera.unwrap();
    // Orbit by dragging on the image.
    let start = rect.center();
    press_at(&mut harness, start);
    harness.step();
    for k in 1..=5 {
        harness.event(Event::PointerMoved(start + egui::vec2(12.0 * k as f32, 0.0)));
        harness.step();
        // The step that requested a frame returned before that frame exists: rendering runs
        // beside the UI, not in it.
        assert!(!harness.state().settled(), "step {k} waited for the render");
    }
    let moved = harness.state().camera.unwrap();
    assert!((moved.yaw - home.yaw).abs() > 0.1, "the drag orbits the camera");
    button(&harness, start, false);
    // While moving: previews at half resolution of a subset of the streamlines.
    let deadline = Instant::now() + Duration::from_secs(300);
    while !harness.state().shown.as_ref().is_some_and(|f| f.view.preview) {
        assert!(Instant::now() < deadline, "no preview frame");
        std::thread::sleep(Duration::from_millis(5));
        harness.step();
    }
    let preview = harness.state().shown.as_ref().unwrap();
    assert_eq!(preview.size, ((full.0 / 2).max(1), (full.1 / 2).max(1)));
    // At rest: full detail again.
    std::thread::sleep(Duration::from_millis(400));
    settle(&mut harness);
    let last = harness.state().shown.as_ref().unwrap();
    assert!(!last.view.preview);
    assert_eq!(last.size, full);
}

#[test]
fn keys_orbit_zoom_reset_and_switch_to_orthographic() {
    let mut harness = harness(options(scene(SceneKind::Vortex, 20_000), [methods()[0], methods()[4]], false));
    settle(&mut harness);
    let home = harness.state().camera.unwrap();
    harness.key_press(egui::Key::ArrowLeft);
    harness.key_press(egui::Key::Minus);
    harness.step();
    let moved = harness.state().camera.unwrap();
    assert!((moved.yaw - home.yaw).abs() > 0.05 && moved.distance > home.distance);
    harness.key_press(egui::Key::R);
    harness.key_press(egui::Key::O);
    harness.step();
    let reset = harness.state().camera.unwrap();
    assert_eq!((reset.yaw, reset.distance), (home.yaw, home.distance));
    assert!(reset.orthographic);
    settle(&mut harness);
    let frame = harness.state().shown.as_ref().unwrap();
    assert!(matches!(frame.view.camera.projection, lineao::Projection::Orthographic { .. }));
}

#[test]
fn the_ray_traced_method_accumulates_while_the_camera_rests_and_shows_lineao_while_it_moves() {
    let mut options = options(scene(SceneKind::Spiral, 30_000), [RAY_TRACED, methods()[4]], false);
    options.controls.params.chain.raytraced.max_rays = 12;
    let mut harness = harness(options);
    // Frame after frame, 4 more rays per pixel until 12, each on screen as it comes.
    let (deadline, mut seen) = (Instant::now() + Duration::from_secs(300), Vec::new());
    harness.step();
    while !harness.state().complete() {
        assert!(Instant::now() < deadline, "the picture did not complete in 300 s");
        std::thread::sleep(Duration::from_millis(5));
        harness.step();
        let rays = harness.state().shown.as_ref().and_then(|f| f.rays[0]).map(|r| r.progress.rays_per_pixel);
        if let Some(rays) = rays.filter(|r| seen.last() != Some(r)) {
            seen.push(rays);
        }
    }
    harness.step();
    assert!(harness.state().error.is_none(), "{:?}", harness.state().error);
    assert_eq!(seen.last(), Some(&12), "{seen:?}");
    assert!(seen.windows(2).all(|w| w[0] < w[1]) && seen.iter().all(|r| r % 4 == 0), "{seen:?}");
    harness.get_by_label("ray traced: 12 rays per pixel, complete");
    // Complete: the render thread stops sending frames.
    let received = harness.state().frames_received;
    assert!(received >= 3, "one frame per 4 rays");
    std::thread::sleep(Duration::from_millis(300));
    harness.run_steps(3);
    assert_eq!(harness.state().frames_received, received, "frames after the cap");

    // The picture is the library's: a chain tracing the same scene with the same settings.
    let frame = harness.state().shown.as_ref().unwrap();
    let gpu = lineao::Gpu::headless().unwrap();
    let (d, q) = (&gpu.device, &gpu.queue);
    let t = SceneKind::Spiral.build(1, 30_000).tractogram;
    let geometry = lineao::LineGeometry::new(d, q, &t.positions, &t.offsets).unwrap();
    let rays = lineao::RayGeometry { positions: &t.positions, offsets: &t.offsets, ..Default::default() };
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let mut chain = lineao::AoChain::new(d, format, frame.view.panels[0].settings.clone()).unwrap();
    chain.set_ray_scene(d, Some(std::sync::Arc::new(lineao::RayScene::new(d, q, &rays).unwrap())));
    chain.resize(frame.size.0, frame.size.1).unwrap();
    let target = lineao::targets::Target::output(d, "test", frame.size, format);
    for _ in 0..3 {
        chain.prepare(d, q, &frame.view.camera, &geometry.bounds.unwrap());
        let mut encoder = d.create_command_encoder(&Default::default());
        chain.encode(&mut encoder, &geometry, &target.view).unwrap();
        q.submit([encoder.finish()]);
    }
    assert_eq!(
        chain
            .stage()
            .and_then(|s| s.downcast::<lineao::method::raytraced::RayTracedAo>())
            .map(|t| t.progress())
            .unwrap()
            .rays_per_pixel,
        12
    );
    let direct = lineao::readback::read_texture(d, q, &target.texture).unwrap().bytes;
    let differing = direct.iter().zip(&frame.images[0]).filter(|(a, b)| a.abs_diff(**b) > 1).count();
    assert!(differing * 1000 < direct.len(), "{differing} of {} bytes differ", direct.len());

    // While the camera moves: LineAO; at rest the rays start again.
    let rect = harness.state().image_rect.unwrap();
    press_at(&mut harness, rect.center());
    harness.event(Event::PointerMoved(rect.center() + egui::vec2(30.0, 0.0)));
    harness.step();
    button(&harness, rect.center() + egui::vec2(30.0, 0.0), false);
    harness.step();
    let requested = harness.state().requested.as_ref().unwrap();
    assert_eq!(requested.panels[0].settings.method, AoMethod::LineAo, "LineAO while moving");
    std::thread::sleep(Duration::from_millis(400));
    settle(&mut harness);
    let frame = harness.state().shown.as_ref().unwrap();
    assert_eq!(frame.view.panels[0].settings.method, AoMethod::RayTraced, "ray traced at rest");
    assert!(frame.rays[0].is_some_and(|r| r.progress.rays_per_pixel <= 12));
}

#[test]
fn the_t_key_sees_through_the_lines_and_back() {
    let mut harness = harness(options(scene(SceneKind::Vortex, 20_000), [methods()[0], methods()[4]], false));
    settle(&mut harness);
    let opaque = harness.state().shown.as_ref().unwrap().images[0].clone();
    harness.key_press(egui::Key::T);
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let frame = app.shown.as_ref().unwrap();
    let transparency = frame.view.panels[0].settings.transparency.clone();
    assert_eq!(transparency.map(|t| t.alpha), Some(0.3));
    // Lines over the white background are lighter seen through: less darkening of the white.
    let darkening = |image: &[u8]| {
        image.chunks_exact(4).map(|p| p[..3].iter().map(|&c| 255.0 - c as f64).sum::<f64>()).sum::<f64>()
    };
    let (seen, solid) = (darkening(&frame.images[0]), darkening(&opaque));
    assert!(seen < 0.8 * solid, "{seen} against {solid}");
    harness.key_press(egui::Key::T);
    settle(&mut harness);
    assert_eq!(harness.state().shown.as_ref().unwrap().view.panels[0].settings.transparency, None);
}

#[test]
fn a_slab_cuts_the_lines_and_the_brackets_move_it() {
    let path = data("niivue+niivue/packages/niivue/demos/images/stroke.trk.gz");
    let mut harness = harness(options(Source::File(path), [methods()[1], methods()[4]], false));
    settle(&mut harness);
    let whole = non_background(&harness.state().shown.as_ref().unwrap().images[0]);
    let slab = lineao::Slab { axis: lineao::SlabAxis::Z, center: 10.0, thickness: 6.0 };
    harness.state_mut().controls.params.chain.slab = Some(slab);
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let frame = app.shown.as_ref().unwrap();
    assert_eq!(frame.view.panels[0].settings.slab, Some(slab));
    let cut = non_background(&frame.images[0]);
    assert!(cut > 0.005 && cut < 0.5 * whole, "{cut} of the pixels in the slab, {whole} without it");
    // `]` moves it a quarter of its thickness along its axis.
    harness.key_press(egui::Key::CloseBracket);
    settle(&mut harness);
    let moved = harness.state().shown.as_ref().unwrap().view.panels[0].settings.slab.unwrap();
    assert_eq!(moved.center, 11.5);
}

#[test]
fn a_volume_opened_beside_the_tractogram_shows_its_slices_and_each_axis_turns_off() {
    // `view stroke.trk.gz`, then MNI152_2009_template.nii.gz dropped on the window (the page's
    // drop and `view --volume` come to the same [`App::set_anatomy`]): the axial slice at z = 10
    // under the lines, gray (no line is drawn gray), transparent around the brain (the
    // template's zeros) unless opaque.
    let images = "niivue+niivue/packages/niivue/demos/images";
    // Without occlusion: the lines' own darkest pixels stay far from black.
    let options = options(Source::File(data(&format!("{images}/stroke.trk.gz"))), [methods()[0], methods()[4]], false);
    let mut harness = harness(options);
    settle(&mut harness);
    let gray = |image: &[u8]| {
        let pixels = image.chunks_exact(4);
        let count = pixels.clone().filter(|p| p[0] == p[1] && p[1] == p[2] && p[0] < 250).count();
        count as f64 / pixels.len() as f64
    };
    let shown_gray = |harness: &Harness<'_, App>| gray(&harness.state().shown.as_ref().unwrap().images[0]);
    let lines = shown_gray(&harness);
    assert!(lines < 0.001, "{lines} of the pixels gray with the lines alone");
    harness.state_mut().open_path(data(&format!("{images}/MNI152_2009_template.nii.gz")));
    harness.state_mut().controls.params.chain.slices.as_mut().unwrap().positions = [None, None, Some(10.0)];
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    assert!(app.dataset.as_ref().unwrap().name.ends_with("stroke.trk.gz"), "the tractogram stays");
    let shown = shown_gray(&harness);
    assert!(shown > 0.01, "{shown} of the pixels gray");
    harness.state_mut().controls.params.chain.slices.as_mut().unwrap().opaque = true;
    settle(&mut harness);
    let opaque = shown_gray(&harness);
    assert!(opaque > shown + 0.03, "{opaque} of the pixels gray with the zeros shown, {shown} without");
    // Its checkbox off: no slice, no black.
    harness.state_mut().controls.params.chain.slices.as_mut().unwrap().positions[2] = None;
    settle(&mut harness);
    let off = shown_gray(&harness);
    assert!(off < 0.001, "{off} of the pixels gray without the slice, {shown} with it");
    assert!(harness.query_all_by_label_contains("z (axial)").count() > 0, "the axial slider");
    // A volume that cannot be read is said; the tractogram stays.
    harness.state_mut().open_path(PathBuf::from("/nonexistent/t1.nii.gz"));
    let app = harness.state();
    let error = app.error.as_deref().unwrap_or_default();
    assert!(error.contains("t1.nii.gz") && error.contains("without slices"), "{error}");
    assert!(app.dataset.is_some());
}

#[test]
fn a_trx_files_groups_colour_and_select_its_streamlines() {
    // pyAFQ's arcuate fasciculi: ARC_L (486 streamlines) and ARC_R (22), coloured a group each.
    let path = data(
        "niivue+niivue/packages/niivue/demos/images/sub-01_ses-01_dwi_space-RASMM_model-probCSD_algo-AFQ_tractography.trx",
    );
    let mut options = options(Source::File(path), [methods()[0], methods()[4]], false);
    options.controls.color = super::controls::ColorMode::Groups;
    let mut harness = harness(options);
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    assert_eq!(app.dataset.as_ref().unwrap().groups, ["ARC_L", "ARC_R"]);
    assert_eq!(app.controls.color, super::controls::ColorMode::Groups, "kept once the groups are known");
    let settings = &app.shown.as_ref().unwrap().view.panels[0].settings;
    assert!(matches!(settings.line_color, lineao::LineColor::Scalar { colormap: lineao::Colormap::Categories, .. }));
    let drawn = |harness: &Harness<'_, App>| non_background(&harness.state().shown.as_ref().unwrap().images[0]);
    let both = drawn(&harness);
    // ARC_L's checkbox off: ARC_R's 22 streamlines alone; both off: the background.
    harness.state_mut().controls.groups[0].1 = false;
    settle(&mut harness);
    let right = drawn(&harness);
    assert!(right > 0.0005 && right < 0.5 * both, "{right} of the pixels with ARC_R, {both} with both");
    harness.state_mut().controls.groups[1].1 = false;
    settle(&mut harness);
    assert_eq!(drawn(&harness), 0.0);
    assert!(harness.query_all_by_label_contains("ARC_L").count() > 0, "ARC_L's checkbox");
}

#[test]
fn a_per_streamline_field_range_selects_streamlines() {
    // dpsv.trx's dps DataSetID: 74 of its 460 streamlines hold 0 (`lineao info --field
    // DataSetID,-0.5,0.5` counts them).
    let path = data("niivue+niivue/packages/niivue/demos/images/dpsv.trx");
    let mut harness = harness(options(Source::File(path), [methods()[0], methods()[4]], false));
    settle(&mut harness);
    let app = harness.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let fields = &app.dataset.as_ref().unwrap().streamline_fields;
    let (_, [lo, hi]) = fields.iter().find(|(name, _)| name == "DataSetID").expect("the dps field").clone();
    assert!(lo == 0.0 && hi > 1.0, "DataSetID's range {lo}..{hi}");
    let drawn = |harness: &Harness<'_, App>| non_background(&harness.state().shown.as_ref().unwrap().images[0]);
    let all = drawn(&harness);
    harness.state_mut().controls.field = Some(("DataSetID".into(), [0.0, 0.0]));
    settle(&mut harness);
    let zero = drawn(&harness);
    assert!(zero > 0.001 && zero < 0.6 * all, "{zero} of the pixels with DataSetID 0, {all} with all");
    // Between two of its whole numbers: none.
    harness.state_mut().controls.field = Some(("DataSetID".into(), [0.25, 0.75]));
    settle(&mut harness);
    assert_eq!(drawn(&harness), 0.0, "no streamline in the range");
    assert!(harness.query_all_by_label_contains("by field").count() > 0, "the checkbox");
}

#[test]
fn a_share_and_a_length_range_select_streamlines_on_the_gpu() {
    let path = data("niivue+niivue/packages/niivue/demos/images/stroke.trk.gz");
    let mut harness = harness(options(Source::File(path), [methods()[0], methods()[4]], false));
    settle(&mut harness);
    let drawn = |harness: &Harness<'_, App>| non_background(&harness.state().shown.as_ref().unwrap().images[0]);
    let all = drawn(&harness);
    let max_length = harness.state().dataset.as_ref().unwrap().max_length;
    assert!(max_length > 100.0, "the longest of stroke.trk.gz's streamlines: {max_length} mm");
    // A hundredth of the streamlines (of these short, dense ones 5 % still cover 60 % of the
    // pixels all of them cover).
    harness.state_mut().controls.subset = 0.01;
    settle(&mut harness);
    let share = drawn(&harness);
    assert!(share > 0.002 && share < 0.4 * all, "{share} of the pixels with 1 % of the streamlines, {all} with all");
    // All of them again (but for a level of detail chosen another frame), then only the
    // longest: a streamline or two.
    harness.state_mut().controls.subset = 1.0;
    settle(&mut harness);
    assert!((drawn(&harness) - all).abs() < 1e-3, "{} of the pixels, {all} before", drawn(&harness));
    harness.state_mut().controls.length = Some([0.99 * max_length, max_length]);
    settle(&mut harness);
    let longest = drawn(&harness);
    assert!(longest > 0.0 && longest < 0.01, "{longest} of the pixels for the longest streamlines");
    assert!(harness.query_all_by_label_contains("% of streamlines").count() > 0);
}

#[test]
fn include_and_exclude_regions_select_streamlines_as_groups_do() {
    // pyAFQ's arcuate fasciculi: ARC_R's 22 streamlines lie right of the midline (x > 0, RAS),
    // ARC_L's 486 left of it (`lineao info --include box:0,-300,-300,300,300,300` counts 22,
    // `--exclude` the same box 486). A box over the right half keeps what ARC_R's group keeps.
    let path = data(
        "niivue+niivue/packages/niivue/demos/images/sub-01_ses-01_dwi_space-RASMM_model-probCSD_algo-AFQ_tractography.trx",
    );
    let mut harness = harness(options(Source::File(path), [methods()[0], methods()[4]], false));
    settle(&mut harness);
    // Every line drawn whole: the pictures of the same streamlines are then the same bit for bit
    // (culled, a level of detail chosen another frame moves edges by under half a pixel).
    harness.state_mut().controls.params.chain.cull = false;
    assert!(harness.state().error.is_none(), "{:?}", harness.state().error);
    let image = |harness: &Harness<'_, App>| harness.state().shown.as_ref().unwrap().images[0].clone();
    let differing = |a: &[u8], b: &[u8]| {
        let pixels = a.chunks(4).zip(b.chunks(4));
        pixels.filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 2)).count() as f64
            / (a.len() / 4) as f64
    };
    let right = lineao_tracts::Region::Box { min: [0.0, -300.0, -300.0], max: [300.0; 3] };
    let rule = |include| super::controls::RegionRule { include, region: right };
    for (include, group) in [(true, 1), (false, 0)] {
        harness.state_mut().controls.regions = vec![rule(include)];
        settle(&mut harness);
        assert!(harness.state().error.is_none(), "{:?}", harness.state().error);
        let by_region = image(&harness);
        harness.state_mut().controls.regions.clear();
        harness.state_mut().controls.groups[1 - group].1 = false;
        settle(&mut harness);
        let by_group = image(&harness);
        harness.state_mut().controls.groups[1 - group].1 = true;
        let shown = non_background(&by_group);
        assert!(shown > 0.0005, "{shown} of the pixels with {}", ["ARC_L", "ARC_R"][group]);
        // The same streamlines: the same picture.
        let share = differing(&by_region, &by_group);
        assert!(share == 0.0, "{share} of the pixels differ between the region's and the group's picture");
    }
    // A sphere of 8 mm in the left arcuate: 10 of its streamlines (`lineao info`), few pixels.
    let sphere = lineao_tracts::Region::Sphere { center: [-40.0, -20.0, 20.0], radius: 8.0 };
    harness.state_mut().controls.regions = vec![super::controls::RegionRule { include: true, region: sphere }];
    settle(&mut harness);
    let few = non_background(&image(&harness));
    harness.state_mut().controls.regions.clear();
    settle(&mut harness);
    let all = non_background(&image(&harness));
    assert!(few > 0.0 && few < 0.3 * all, "{few} of the pixels through the sphere, {all} with all");
    assert!(harness.query_all_by_label_contains("+ sphere").count() > 0, "the button that adds a region");
}

#[test]
fn regions_select_streamlines_while_the_file_arrives() {
    // A whole brain arriving in chunks, opened with an include sphere at its centre: the frames
    // drawn while it arrives already leave out what misses the sphere (judged as each chunk
    // came; before, regions waited for the whole file and read it again), and the last keeps
    // what the selection keeps of the whole tractogram.
    let vertices = 3_000_000;
    let brain = lineao_tracts::scenes::wholebrain::WholeBrain::new(1, vertices as u64);
    let whole = brain.tractogram(0..brain.streamlines());
    let n = whole.positions.len() as f32;
    let sum = whole.positions.iter().fold([0.0f32; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]]);
    let sphere = lineao_tracts::Region::Sphere { center: sum.map(|c| c / n), radius: 15.0 };
    let selection = lineao_tracts::Selection { include: vec![sphere], ..Default::default() };
    let expected = selection.mask(&whole).unwrap().iter().filter(|&&k| k).count();
    assert!(expected > 0 && expected < whole.streamlines() / 2, "{expected} of {}", whole.streamlines());
    let mut options = options(scene(SceneKind::WholeBrain, vertices as usize), [methods()[1], methods()[4]], false);
    options.controls.regions = vec![super::controls::RegionRule { include: true, region: sphere }];
    let mut harness = harness(options);
    let (deadline, mut arriving) = (Instant::now() + Duration::from_secs(300), Vec::new());
    loop {
        harness.step();
        let app = harness.state();
        let complete = app.dataset.as_ref().is_some_and(|d| d.complete);
        if let (Some(frame), false) = (&app.shown, complete) {
            arriving.extend(frame.selected);
        }
        if complete && app.settled() {
            break;
        }
        assert!(Instant::now() < deadline, "the whole brain did not arrive in 300 s");
        std::thread::sleep(Duration::from_millis(10));
    }
    settle(&mut harness);
    assert!(harness.state().error.is_none(), "{:?}", harness.state().error);
    let partial = arriving.iter().find(|&&(_, all)| all < whole.streamlines());
    let &(kept, all) = partial.expect("a frame drawn while the file arrived, with the sphere's selection");
    assert!(kept < all, "while arriving: {kept} of {all} kept");
    let last = harness.state().shown.as_ref().unwrap().selected;
    assert_eq!(last, Some((expected, whole.streamlines())));
}

#[test]
fn a_frozen_cull_shows_from_behind_what_it_drew_for_the_view_before() {
    let mut harness = harness(options(scene(SceneKind::Bundles, 200_000), [methods()[0], methods()[4]], false));
    settle(&mut harness);
    assert!(harness.state().controls.params.chain.cull, "the viewer culls by default");
    let drawn = |harness: &Harness<'_, App>| non_background(&harness.state().shown.as_ref().unwrap().images[0]);
    harness.state_mut().controls.debug_view = lineao::DebugView::Frozen;
    settle(&mut harness);
    // Half way round: the pieces found for the front, seen from behind.
    harness.state_mut().camera.as_mut().unwrap().yaw += std::f32::consts::PI;
    settle(&mut harness);
    let frozen = drawn(&harness);
    // Still frozen for the front, every piece: those it left out behind the front are purple.
    harness.state_mut().controls.debug_view = lineao::DebugView::Culled;
    settle(&mut harness);
    let image = harness.state().shown.as_ref().unwrap().images[0].clone();
    let purple =
        image.chunks_exact(4).filter(|p| p[0] as u32 > p[1] as u32 + 40 && p[2] as u32 > p[1] as u32 + 40).count()
            as f64
            / (image.len() / 4) as f64;
    let every = non_background(&image);
    harness.state_mut().controls.debug_view = lineao::DebugView::Pieces;
    settle(&mut harness);
    let whole = drawn(&harness);
    assert!(frozen > 0.0 && frozen < 0.95 * whole, "{frozen} of the pixels frozen, {whole} culled afresh");
    assert!((every - whole).abs() < 0.01 * whole, "{every} of the pixels with every piece, {whole} culled afresh");
    assert!(purple > 0.25 * every, "{purple} of the pixels purple (left out behind the front) of {every}");
}
