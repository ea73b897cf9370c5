//! The minimal headless use of lineao through its public API: build streamlines, run the LineAO
//! pass chain into an offscreen texture, save a PNG.
//!
//! ```sh
//! cargo run --release --example headless_png -- out.png
//! ```

use glam::Vec3;
use lineao::camera::{Camera, Projection};
use lineao::passes::lines::LineGeometry;
use lineao::{AoChain, ChainSettings, Gpu};
use lineao_tracts::SceneKind;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).unwrap_or_else(|| "headless.png".into());
    let (width, height) = (640, 512);

    let scene = SceneKind::Spiral.build(1, 200_000);
    let gpu = Gpu::headless()?;
    let geometry = LineGeometry::new(&gpu.device, &gpu.queue, &scene.tractogram.positions, &scene.tractogram.offsets)?;

    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let mut chain = AoChain::new(&gpu.device, format, ChainSettings::default())?;
    chain.resize(width, height)?;
    let camera = Camera {
        eye: Vec3::from_array(scene.view.eye),
        target: Vec3::from_array(scene.view.target),
        up: Vec3::from_array(scene.view.up),
        projection: Projection::Perspective { fov_y_deg: scene.view.fov_y_deg },
    };
    chain.prepare(&gpu.device, &gpu.queue, &camera, &geometry.bounds.ok_or("no points")?);

    let target = lineao::targets::Target::output(&gpu.device, "example::target", (width, height), format);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    chain.encode(&mut encoder, &geometry, &target.view);
    gpu.queue.submit([encoder.finish()]);

    let image = lineao::readback::read_texture(&gpu.device, &gpu.queue, &target.texture)?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(&path)?), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&image.bytes)?;
    println!("wrote {path}");
    Ok(())
}
