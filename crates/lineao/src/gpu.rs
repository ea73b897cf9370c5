//! A headless wgpu device for the CLI, the tests and the examples.
//!
//! Requests the adapter's own limits (wgpu's defaults cap buffers at 256 MiB, far below what an
//! 11 M-vertex tractogram needs) and timestamp queries where the adapter has them. Adapters that
//! cannot run the passes (wgpu's GL backend renders no `Rgba32Float`) are skipped for one that
//! can, or refused with what they lack ([`check_adapter`]).

use std::sync::{Arc, Mutex};

use crate::Error;
use crate::targets;

/// The texture capabilities the passes rely on: the G-buffer is rendered into (`Rgba16Float`
/// color, `Rgba32Float` ND map, `R32Float` zoom and specular), the compute passes write storage
/// textures (`R32Float` AO, `Rgba32Float` levels, the G-buffer from a host's depth), every pass
/// reads textures.
const FORMAT_NEEDS: [(wgpu::TextureFormat, wgpu::TextureUsages); 4] = {
    use wgpu::TextureUsages as U;
    let all = U::RENDER_ATTACHMENT.union(U::STORAGE_BINDING).union(U::TEXTURE_BINDING);
    [
        (targets::ND_FORMAT, all),
        (targets::AO_FORMAT, all),
        (targets::DEPTH_FORMAT, U::RENDER_ATTACHMENT.union(U::TEXTURE_BINDING)),
        (targets::COLOR_FORMAT, all),
    ]
};

/// What an adapter lacks that lineao's passes need ([`check_adapter`],
/// [`Error::AdapterLacks`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Lacking {
    /// Compute shaders (WebGL2's downlevel adapters).
    ComputeShaders,
    /// A G-buffer format without these usages.
    Format {
        /// The format.
        format: wgpu::TextureFormat,
        /// The usages it lacks.
        usages: wgpu::TextureUsages,
    },
    /// Fewer color attachments than the G-buffer's four.
    ColorAttachments {
        /// How many the adapter has.
        has: u32,
    },
}

impl std::fmt::Display for Lacking {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Lacking::ComputeShaders => f.write_str("compute shaders"),
            Lacking::Format { format, usages } => write!(f, "{format:?} for {usages:?}"),
            Lacking::ColorAttachments { has } => write!(f, "4 color attachments (has {has})"),
        }
    }
}

/// Whether `adapter` can run lineao's passes; the error lists everything it lacks.
pub fn check_adapter(adapter: &wgpu::Adapter) -> Result<(), Error> {
    let mut lacking = Vec::new();
    if !adapter.get_downlevel_capabilities().flags.contains(wgpu::DownlevelFlags::COMPUTE_SHADERS) {
        lacking.push(Lacking::ComputeShaders);
    }
    for (format, usages) in FORMAT_NEEDS {
        let usages = usages - adapter.get_texture_format_features(format).allowed_usages;
        if !usages.is_empty() {
            lacking.push(Lacking::Format { format, usages });
        }
    }
    let has = adapter.limits().max_color_attachments;
    if has < 4 {
        lacking.push(Lacking::ColorAttachments { has });
    }
    if lacking.is_empty() {
        return Ok(());
    }
    let info = adapter.get_info();
    Err(Error::AdapterLacks { adapter: format!("{} ({:?})", info.name, info.backend), lacking })
}

/// Runs `create` inside a validation error scope of `device`: what wgpu would report to its
/// uncaptured-error handler (a panic by default) comes back as [`Error::Unsupported`]. A
/// future, for hosts that must not block (the web); native callers block on it.
pub async fn validated_async<T>(device: &wgpu::Device, what: &str, create: impl FnOnce() -> T) -> Result<T, Error> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let value = create();
    match scope.pop().await {
        None => Ok(value),
        Some(error) => Err(Error::Unsupported(format!("{what}: {error}"))),
    }
}

/// Instance, adapter, device and queue of one headless GPU.
pub struct Gpu {
    /// The wgpu instance.
    pub instance: wgpu::Instance,
    /// The adapter the device came from.
    pub adapter: wgpu::Adapter,
    /// The device, with the features lineao asks for where the adapter offers them.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Why the device was lost, once it is: set by the device-lost callback [`Gpu::headless`]
    /// installs (wgpu keeps one callback per device; a host with its own device installs its own).
    lost: Arc<Mutex<Option<String>>>,
}

impl Gpu {
    /// The default adapter of the environment (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME` are honoured),
    /// with its full limits.
    pub fn headless() -> Result<Gpu, Error> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let preferred = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| Error::NoAdapter(e.to_string()))?;
        let adapter = match check_adapter(&preferred) {
            Ok(()) => preferred,
            // Another adapter of the environment may do (e.g. Vulkan beside GL).
            Err(refusal) => pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()))
                .into_iter()
                .find(|a| check_adapter(a).is_ok())
                .ok_or(refusal)?,
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&Self::device_descriptor(&adapter)))
            .map_err(|e| Error::RequestDevice(e.to_string()))?;
        Ok(Gpu::new(instance, adapter, device, queue))
    }

    /// A `Gpu` of a device made elsewhere, with lineao's device-lost callback installed on it.
    pub fn new(instance: wgpu::Instance, adapter: wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Gpu {
        let lost = Arc::new(Mutex::new(None));
        let reason = lost.clone();
        device.set_device_lost_callback(move |why, message| {
            let text = if message.is_empty() { format!("{why:?}") } else { format!("{why:?}: {message}") };
            *reason.lock().unwrap_or_else(|poisoned| poisoned.into_inner()) = Some(text);
        });
        Gpu { instance, adapter, device, queue, lost }
    }

    /// What lineao asks of an adapter: its own limits, plus timestamp queries, early depth
    /// tests before a shader that writes its depth (the tubes'), filtered f32 textures (the
    /// anatomy slices' volume), blended f32 targets (transparent lines over an Rgba32Float
    /// picture) and 64-bit atomics (the lines rasterized in compute) when offered.
    pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
        let wanted = wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
            | wgpu::Features::SHADER_EARLY_DEPTH_TEST
            | wgpu::Features::FLOAT32_FILTERABLE
            | wgpu::Features::FLOAT32_BLENDABLE
            | wgpu::Features::SHADER_INT64
            | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX;
        wgpu::DeviceDescriptor {
            label: Some("lineao::Gpu::device"),
            required_features: adapter.features() & wanted,
            required_limits: adapter.limits(),
            ..Default::default()
        }
    }

    /// "name (backend)" of the adapter.
    pub fn describe(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} ({:?})", info.name, info.backend)
    }

    /// Blocks until the queue is idle; [`Error::DeviceLost`] once the device is lost (wgpu then
    /// drops the work quietly, so a loop of frames checks here to stop).
    pub fn wait(&self) -> Result<(), Error> {
        let polled = self.device.poll(wgpu::PollType::wait_indefinitely());
        if let Some(why) = self.lost() {
            return Err(Error::DeviceLost(why));
        }
        polled.map(|_| ()).map_err(|e| Error::Gpu(e.to_string()))
    }

    /// Why the device was lost, if it was (known after the next poll or [`Gpu::wait`]).
    pub fn lost(&self) -> Option<String> {
        self.lost.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).clone()
    }
}

/// Runs `create`, an allocation of `size` bytes for `what`, in an out-of-memory error scope:
/// a device that cannot hold it answers with [`Error::TooLarge`] naming the size and the
/// device's largest buffer, not with wgpu's panicking default handler. Natively wgpu answers
/// at once; a web page cannot wait for the answer, so there the allocation is not checked.
pub(crate) fn allocating<T>(
    device: &wgpu::Device,
    what: &str,
    size: u64,
    create: impl FnOnce() -> T,
) -> Result<T, Error> {
    #[cfg(not(target_arch = "wasm32"))]
    {
        let scope = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let value = create();
        match pollster::block_on(scope.pop()) {
            None => Ok(value),
            Some(error) => {
                let max = device.limits().max_buffer_size;
                let message = format!(
                    "{what}: {size} bytes do not fit the device's memory (its largest buffer: {max} bytes): {error}"
                );
                Err(Error::TooLarge { limit: crate::Limit::Memory, value: size, max, message })
            }
        }
    }
    #[cfg(target_arch = "wasm32")]
    {
        let _ = (device, what, size);
        Ok(create())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_an_adapter_lacks_is_listed_by_name() {
        let error = Error::AdapterLacks {
            adapter: "WebGL2 (Gl)".into(),
            lacking: vec![
                Lacking::ComputeShaders,
                Lacking::Format { format: wgpu::TextureFormat::R32Float, usages: wgpu::TextureUsages::STORAGE_BINDING },
                Lacking::ColorAttachments { has: 2 },
            ],
        };
        assert_eq!(
            error.to_string(),
            "the GPU cannot run lineao: WebGL2 (Gl) lacks compute shaders, R32Float for TextureUsages(STORAGE_BINDING), \
             4 color attachments (has 2)"
        );
    }
}
