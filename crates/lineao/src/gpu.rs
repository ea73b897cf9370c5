//! A headless wgpu device for the CLI, the tests and the examples.
//!
//! Requests the adapter's own limits (wgpu's defaults cap buffers at 256 MiB, far below what an
//! 11 M-vertex tractogram needs) and timestamp queries where the adapter has them.

use crate::Error;

/// Instance, adapter, device and queue of one headless GPU.
pub struct Gpu {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
}

impl Gpu {
    /// The default adapter of the environment (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME` are honoured),
    /// with its full limits.
    pub fn headless() -> Result<Gpu, Error> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| Error::NoAdapter(e.to_string()))?;
        let (device, queue) = pollster::block_on(adapter.request_device(&Self::device_descriptor(&adapter)))
            .map_err(|e| Error::RequestDevice(e.to_string()))?;
        Ok(Gpu { instance, adapter, device, queue })
    }

    /// What lineao asks of an adapter: its own limits, plus timestamp queries when offered.
    pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
        let wanted = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
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

    /// Blocks until the queue is idle.
    pub fn wait(&self) -> Result<(), Error> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).map(|_| ()).map_err(|e| Error::Gpu(e.to_string()))
    }
}
