//! Reading textures back to the CPU, for tests, `--dump` and PNG output.

use crate::Error;

#[cfg(feature = "reference")]
pub use images::{read_f32, read_image, read_rgba, write_target};

/// A texture's texels, rows tightly packed.
pub struct TextureData {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// The texture's format.
    pub format: wgpu::TextureFormat,
    /// The texels, row after row.
    pub bytes: Vec<u8>,
}

impl TextureData {
    /// The texels as f32 (R32Float, Rgba32Float, Depth32Float).
    pub fn to_f32(&self) -> Vec<f32> {
        bytemuck::pod_collect_to_vec(&self.bytes)
    }

    /// The texels as [f32; 4] (Rgba32Float, or Rgba16Float widened exactly).
    pub fn to_vec4(&self) -> Vec<[f32; 4]> {
        if self.format == wgpu::TextureFormat::Rgba16Float {
            let halves: Vec<u16> = bytemuck::pod_collect_to_vec(&self.bytes);
            return halves.chunks_exact(4).map(|h| [0, 1, 2, 3].map(|c| f16_to_f32(h[c]))).collect();
        }
        bytemuck::pod_collect_to_vec(&self.bytes)
    }
}

/// An IEEE 754 half to f32 (exact: every half is an f32), subnormals, infinities and NaN
/// included.
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let (exponent, mantissa) = (i32::from((h >> 10) & 0x1f), f32::from(h & 0x3ff));
    sign * match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

/// Copies `texture` (mip 0) to the CPU and waits for it, in bands of rows that fit the
/// device's largest buffer.
pub fn read_texture(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture) -> Result<TextureData, Error> {
    let format = texture.format();
    let (width, height) = (texture.width(), texture.height());
    let aspect =
        if format.is_depth_stencil_format() { wgpu::TextureAspect::DepthOnly } else { wgpu::TextureAspect::All };
    let texel =
        format.block_copy_size(Some(aspect)).ok_or_else(|| Error::Gpu(format!("cannot read back {format:?}")))?;
    let row = width * texel;
    let padded_row = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let band = (device.limits().max_buffer_size / padded_row as u64).min(height as u64) as u32;
    // Depth can only be copied whole.
    if band == 0 || (format.is_depth_stencil_format() && band < height) {
        let max = device.limits().max_buffer_size;
        let message =
            format!("reading {width} x {height} {format:?} needs a larger buffer than the device's {max} bytes");
        let value = padded_row as u64 * if format.is_depth_stencil_format() { height as u64 } else { 1 };
        return Err(Error::TooLarge { limit: crate::Limit::BufferSize, value, max, message });
    }
    let mut bytes = Vec::with_capacity((row * height) as usize);
    for first in (0..height).step_by(band as usize) {
        let rows = band.min(height - first);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lineao::readback"),
            size: padded_row as u64 * rows as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::readback") });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: first, z: 0 },
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d { width, height: rows, depth_or_array_layers: 1 },
        );
        queue.submit([encoder.finish()]);
        map_read(device, &buffer)?;
        let mapped = buffer.slice(..).get_mapped_range().map_err(|e| Error::Gpu(e.to_string()))?;
        for r in 0..rows as usize {
            let start = r * padded_row as usize;
            bytes.extend_from_slice(&mapped[start..start + row as usize]);
        }
        drop(mapped);
        buffer.unmap();
    }
    Ok(TextureData { width, height, format, bytes })
}

/// Maps `buffer` for reading and waits for it. A lost device fails the mapping (wgpu reports the
/// buffer invalid): an error here, not wgpu's panicking default handler.
fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<(), Error> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let mapped = std::sync::Arc::new(std::sync::Mutex::new(None));
    let result = mapped.clone();
    buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        *result.lock().unwrap_or_else(|poisoned| poisoned.into_inner()) = Some(r);
    });
    let polled = device.poll(wgpu::PollType::wait_indefinitely());
    if let Some(error) = pollster::block_on(scope.pop()) {
        return Err(Error::Gpu(format!("reading back: {error}")));
    }
    polled.map_err(|e| Error::Gpu(e.to_string()))?;
    match mapped.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).take() {
        Some(Ok(())) => Ok(()),
        Some(Err(e)) => Err(Error::Gpu(format!("reading back: {e}"))),
        None => Err(Error::Gpu("reading back: the buffer was never mapped".into())),
    }
}

/// Copies `buffer` (created with `COPY_SRC`) to the CPU and waits for it.
pub fn read_buffer(device: &wgpu::Device, queue: &wgpu::Queue, buffer: &wgpu::Buffer) -> Result<Vec<u8>, Error> {
    pollster::block_on(read_buffer_async(device, queue, buffer))
}

/// A small buffer read back without waiting: [`LateReadback::copy`] records a copy into it and
/// asks for it to be mapped once that submission has run; [`LateReadback::try_take`] returns
/// the bytes when it has. While one copy waits to be read, later frames' copies are skipped
/// (a host's render loop asks once per frame and gets an earlier frame's values). A copy
/// recorded but never submitted stops the readback until it is made again.
pub struct LateReadback {
    buffer: wgpu::Buffer,
    /// [`FREE`], [`PENDING`] or [`MAPPED`]; the map callback writes it.
    state: std::sync::Arc<std::sync::atomic::AtomicU8>,
}

/// Where the buffer stands: free (the next copy goes into it), waiting for its submission to
/// run, or mapped and readable.
const FREE: u8 = 0;
const PENDING: u8 = 1;
const MAPPED: u8 = 2;

impl LateReadback {
    /// A buffer of `bytes` to read back into.
    pub fn new(device: &wgpu::Device, label: &str, bytes: u64) -> LateReadback {
        LateReadback {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }),
            state: std::sync::Arc::new(std::sync::atomic::AtomicU8::new(FREE)),
        }
    }

    /// Records the copy of `source` (as large as this buffer) unless an earlier copy waits to
    /// be read; returns whether it did.
    pub fn copy(&self, encoder: &mut wgpu::CommandEncoder, source: &wgpu::Buffer) -> bool {
        use std::sync::atomic::Ordering;
        if self.state.compare_exchange(FREE, PENDING, Ordering::AcqRel, Ordering::Acquire).is_err() {
            return false;
        }
        encoder.copy_buffer_to_buffer(source, 0, &self.buffer, 0, self.buffer.size());
        let state = std::sync::Arc::clone(&self.state);
        encoder.map_buffer_on_submit(&self.buffer, wgpu::MapMode::Read, .., move |result| {
            state.store(if result.is_ok() { MAPPED } else { FREE }, Ordering::Release);
        });
        true
    }

    /// Never waits: the bytes of the last copy once its submission has run, else `None`.
    pub fn try_take(&self, device: &wgpu::Device) -> Result<Option<Vec<u8>>, Error> {
        use std::sync::atomic::Ordering;
        device.poll(wgpu::PollType::Poll).map_err(|e| Error::Gpu(e.to_string()))?;
        if self.state.load(Ordering::Acquire) != MAPPED {
            return Ok(None);
        }
        let bytes = self.buffer.slice(..).get_mapped_range().map_err(|e| Error::Gpu(e.to_string()))?.to_vec();
        self.buffer.unmap();
        self.state.store(FREE, Ordering::Release);
        Ok(Some(bytes))
    }

    /// Waits for the submitted copy; `None` when none was recorded.
    pub fn take(&self, device: &wgpu::Device) -> Result<Option<Vec<u8>>, Error> {
        device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(e.to_string()))?;
        self.try_take(device)
    }
}

/// [`read_buffer`] as a future, for hosts that must not block (the web: the page's event loop
/// maps the buffer). Natively it waits for the device before it returns.
pub async fn read_buffer_async(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
) -> Result<Vec<u8>, Error> {
    use std::sync::{Arc, Mutex};
    use std::task::{Poll, Waker};
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("lineao::readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::readback") });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    // The mapping's answer and whoever waits for it.
    type Answer = (Option<Result<(), wgpu::BufferAsyncError>>, Option<Waker>);
    let answer: Arc<Mutex<Answer>> = Arc::new(Mutex::new((None, None)));
    let sender = answer.clone();
    encoder.map_buffer_on_submit(&staging, wgpu::MapMode::Read, .., move |result| {
        let mut state = sender.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        state.0 = Some(result);
        if let Some(waker) = state.1.take() {
            waker.wake();
        }
    });
    queue.submit([encoder.finish()]);
    #[cfg(not(target_arch = "wasm32"))]
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(e.to_string()))?;
    let result = std::future::poll_fn(|cx| {
        let mut state = answer.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        match state.0.take() {
            Some(result) => Poll::Ready(result),
            None => {
                state.1 = Some(cx.waker().clone());
                Poll::Pending
            }
        }
    })
    .await;
    result.map_err(|e| Error::Gpu(format!("reading back: {e}")))?;
    let bytes = staging.slice(..).get_mapped_range().map_err(|e| Error::Gpu(e.to_string()))?.to_vec();
    staging.unmap();
    Ok(bytes)
}

/// Targets as the CPU's images ([`crate::reference::Image`]): what the reference's tests,
/// `verify`, the truth and `--dump` read and write (feature `reference`).
#[cfg(feature = "reference")]
mod images {
    use super::read_texture;
    use crate::Error;
    use crate::image::{Image, NdImage};
    use crate::targets::Target;

    /// A target of one f32 channel (zoom, specular, ao, depth) as an image.
    pub fn read_f32(device: &wgpu::Device, queue: &wgpu::Queue, target: &Target) -> Result<Image<f32>, Error> {
        let data = read_texture(device, queue, &target.texture)?;
        Ok(Image { width: data.width as usize, height: data.height as usize, data: data.to_f32() })
    }

    /// An Rgba32Float or Rgba16Float target (an ND level, color) as an image.
    pub fn read_rgba(device: &wgpu::Device, queue: &wgpu::Queue, target: &Target) -> Result<NdImage, Error> {
        let data = read_texture(device, queue, &target.texture)?;
        Ok(Image { width: data.width as usize, height: data.height as usize, data: data.to_vec4() })
    }

    /// A target of any format as an image of `T` (one texel's bytes each), e.g. `[u32; 2]` for the
    /// `octants` target.
    pub fn read_image<T: bytemuck::Pod>(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target: &Target,
    ) -> Result<Image<T>, Error> {
        let data = read_texture(device, queue, &target.texture)?;
        Ok(Image {
            width: data.width as usize,
            height: data.height as usize,
            data: bytemuck::pod_collect_to_vec(&data.bytes),
        })
    }

    /// Writes `image` into an Rgba32Float or R32Float target (a host's own G-buffer, or a test's).
    pub fn write_target<T: bytemuck::Pod>(queue: &wgpu::Queue, target: &Target, image: &Image<T>) {
        let texel = std::mem::size_of::<T>() as u32;
        queue.write_texture(
            target.texture.as_image_copy(),
            bytemuck::cast_slice(&image.data),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(image.width as u32 * texel),
                rows_per_image: Some(image.height as u32),
            },
            target.texture.size(),
        );
    }
}
