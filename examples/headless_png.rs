//! The minimal headless use of lineao through its public API: load a tractography file (or
//! build the built-in scene), run the LineAO pass chain into an offscreen texture, save a PNG.
//!
//! ```sh
//! cargo run --release --example headless_png -- bundle.trk out.png
//! cargo run --release --example headless_png                         # built-in scene
//! ```

use std::path::Path;

use glam::Vec3;
use lineao::LineGeometry;
use lineao::{AoChain, ChainSettings, Gpu};
use lineao::{Camera, Projection};
use lineao_tracts::{SceneKind, ViewHint};

/// Renders `file` (or the built-in spiral) at `width` × `height`: RGBA8 sRGB pixels.
fn render(file: Option<&Path>, width: u32, height: u32) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    let (tractogram, view) = match file {
        Some(path) => {
            let tractogram = lineao_tracts::load(path)?.tractogram;
            let view = ViewHint::for_tractogram(&tractogram);
            (tractogram, view)
        }
        None => {
            let scene = SceneKind::Spiral.build(1, 200_000);
            (scene.tractogram, scene.view)
        }
    };
    let gpu = Gpu::headless()?;
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &tractogram.positions, &tractogram.offsets)?;

    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let settings = ChainSettings { zoom_unit: view.zoom_unit, ..ChainSettings::default() };
    let mut chain = AoChain::new(&gpu.device, format, settings)?;
    chain.resize(width, height)?;
    let camera = Camera {
        eye: Vec3::from_array(view.eye),
        target: Vec3::from_array(view.target),
        up: Vec3::from_array(view.up),
        projection: Projection::Perspective { fov_y_deg: view.fov_y_deg },
    };
    chain.prepare(&gpu.device, &gpu.queue, &camera, &geometry.bounds.ok_or("no finite points")?);

    let target = lineao::targets::Target::output(&gpu.device, "example::target", (width, height), format);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &geometry, &target.view)?;
    gpu.queue.submit([encoder.finish()]);
    Ok(lineao::readback::read_texture(&gpu.device, &gpu.queue, &target.texture)?.bytes)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (file, out) = match &args[..] {
        [] => (None, "headless.png"),
        [out] if out.ends_with(".png") => (None, out.as_str()),
        [file] => (Some(Path::new(file)), "headless.png"),
        [file, out, ..] => (Some(Path::new(file)), out.as_str()),
    };
    let (width, height) = (640, 512);
    let rgba = render(file, width, height)?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(out)?), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&rgba)?;
    println!("wrote {out}");
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn renders_a_real_tractogram_and_the_built_in_scene() {
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // SAFETY: set before any thread of ours reads the environment.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
        }
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/data/dipy+dipy/dipy/data/files/tracks300.trk");
        for input in [Some(file.as_path()), None] {
            let rgba = super::render(input, 160, 128).unwrap();
            assert_eq!(rgba.len(), 160 * 128 * 4);
            // Lines on a white background: some pixels are not white.
            let drawn = rgba.chunks(4).filter(|p| p[..3] != [255, 255, 255]).count();
            assert!(drawn > 500, "{input:?}: {drawn} pixels drawn");
        }
    }
}
