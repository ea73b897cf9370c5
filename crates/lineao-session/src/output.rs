//! Writing images.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{Context, Result};

/// Writes 8-bit sRGB RGBA rows as a PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    let file = File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    encode(BufWriter::new(file), width, height, rgba).with_context(|| format!("cannot write {}", path.display()))
}

/// 8-bit sRGB RGBA rows as the bytes of a PNG (Jupyter's `_repr_png_`).
pub fn encode_png(width: u32, height: u32, rgba: &[u8]) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    encode(&mut bytes, width, height, rgba)?;
    Ok(bytes)
}

fn encode(out: impl Write, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    anyhow::ensure!(
        rgba.len() as u64 == 4 * width as u64 * height as u64,
        "{} bytes are not {width} x {height} RGBA pixels",
        rgba.len()
    );
    let mut encoder = png::Encoder::new(out, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgba)?;
    writer.finish()?;
    Ok(())
}
