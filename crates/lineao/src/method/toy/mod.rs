//! A method made by the registry alone, for the tests: this folder and its line in
//! [`crate::method`]'s registry are all it took — its two settings included, which the front
//! ends show as flags, keywords, controls and URL keys from their descriptions here. It darkens
//! every geometry pixel by a quarter per zoom unit of its "radius" (the complement when
//! inverted), so a test can tell that the chain ran it with its settings.

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::passes::dispatch_full_screen;
use crate::settings::ChainSettings;
use crate::targets::{AO_FORMAT, FrameTargets};
use crate::timing::Span;

mod settings;
pub use settings::ToySettings;

/// `ToyUniform` in toy.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ToyUniform {
    occlusion: f32,
    _pad: [f32; 3],
}

pub(crate) const METHOD: super::MethodInfo = super::MethodInfo {
    name: "toy",
    label: "toy",
    help: "A quarter of occlusion on every line (the registry's test)",
    // Not among the screen-space methods that `--grid` and the viewer show, so the snapshots
    // stay the papers' methods in a test build.
    screen_space: false,
    estimates: super::Estimate::Occlusion,
    traces_scene: false,
    spans: &["toy"],
    library: crate::shader::Library { files: &[("toy.wgsl", include_str!("toy.wgsl"))], constants: &[] },
    build: Some(|device, _| Box::new(Toy::new(device))),
    fits: super::fits_always,
    own: &super::Own::at(settings::SETTINGS, |c| &c.toy, |c| &mut c.toy, |_, _, _| 1.0),
    bench: &[super::BenchPass::of("toy", &["toy"], |_, _| {})],
    variant: None,
    fit: None,
    #[cfg(feature = "reference")]
    reference: None,
};

struct Toy {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

impl Toy {
    fn new(device: &wgpu::Device) -> Toy {
        let slots = [Slot::Uniform, Slot::Texture, Slot::StorageTexture(AO_FORMAT)];
        let layout = binding::layout(device, "lineao::Toy", wgpu::ShaderStages::COMPUTE, &slots);
        let pipeline =
            binding::compute_pipeline(device, "lineao::Toy", &layout, METHOD.library.source("toy.wgsl"), "toy", &[]);
        let uniform = binding::uniform_buffer::<ToyUniform>(device, "lineao::Toy");
        Toy { pipeline, layout, uniform, group: None }
    }
}

impl super::Stage for Toy {
    fn matches(&self, settings: &ChainSettings) -> bool {
        settings.method == super::AoMethod::Toy
    }

    fn reach(&self, _: &ChainSettings, _: &FrameView) -> super::Reach {
        super::Reach::Pixels { radius_px: 0.0, levels: 1 }
    }

    fn spans(&self, _: &ChainSettings) -> &'static [&'static str] {
        METHOD.spans
    }

    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let resources = [
            self.uniform.as_entire_binding(),
            wgpu::BindingResource::TextureView(&targets.nd[0].view),
            wgpu::BindingResource::TextureView(&targets.ao.view),
        ];
        self.group = Some(binding::group(device, "lineao::Toy", &self.layout, &resources));
    }

    fn prepare(&self, queue: &wgpu::Queue, _: &FrameTargets, _: &FrameView, settings: &ChainSettings) {
        queue.write_buffer(
            &self.uniform,
            0,
            bytemuck::bytes_of(&ToyUniform { occlusion: settings.toy.occlusion(), _pad: [0.0; 3] }),
        );
    }

    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    ) {
        if let Some(group) = &self.group {
            dispatch_full_screen(encoder, "lineao::Toy", &self.pipeline, group, targets.size, span("toy"));
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::camera::{Camera, Projection};
    use crate::{AoChain, AoMethod, ChainSettings, Gpu, LineGeometry};

    #[test]
    fn the_uniform_is_laid_out_as_the_wgsl_reads_it() {
        crate::shader::assert_wgsl_layout!(
            super::ToyUniform,
            super::METHOD.library.source("toy.wgsl"),
            "ToyUniform",
            [occlusion]
        );
    }

    #[test]
    fn the_registry_alone_puts_a_method_in_the_chain() {
        let toy = AoMethod::from_name("toy").expect("the registry lists it");
        assert!(AoMethod::REGISTRY.contains(&toy));
        assert!(crate::method::bench_passes().any(|(m, pass)| m == toy && pass.name == "toy"));
        assert!(crate::method::pass_names().contains(&"toy"));
        assert!(crate::shader::raw("toy.wgsl", &super::METHOD.library).is_some());
        // Its preset and validation come through the registry too.
        let mut settings =
            ChainSettings { method: toy, ..ChainSettings::default() }.with_preset(crate::Preset::Legible);
        settings.validate().unwrap();
        assert_eq!(settings.strength, 1.0);
        // Its settings too, checked by their descriptions with the flag named.
        settings.toy.radius_zoom = 5.0;
        let refused = settings.validate().unwrap_err();
        assert!(
            matches!(&refused, crate::Error::OutOfRange { setting: "toy-radius", value, .. } if value == "5"),
            "{refused:?}"
        );
        assert_eq!(refused.to_string(), "invalid settings: --toy-radius must be in [0.25, 4] zoom units, got 5");
        settings.toy = super::ToySettings { radius_zoom: 1.5, invert: true };

        let gpu = Gpu::headless().unwrap();
        let (device, queue) = (&gpu.device, &gpu.queue);
        let positions = [[-4.0, 0.0, 0.0], [4.0, 0.0, 0.0]];
        let geometry = LineGeometry::new(device, queue, &positions, &[0, 2]).unwrap();
        let mut chain = AoChain::new(device, wgpu::TextureFormat::Rgba8Unorm, settings).unwrap();
        chain.resize(64, 32).unwrap();
        let camera = Camera {
            eye: [0.0, 0.0, 20.0].into(),
            target: glam::Vec3::ZERO,
            up: glam::Vec3::Y,
            projection: Projection::Perspective { fov_y_deg: 45.0 },
        };
        chain.prepare(device, queue, &camera, &geometry.bounds.unwrap());
        let target = device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d { width: 64, height: 32, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        chain.encode(&mut encoder, &geometry, &target.create_view(&Default::default())).unwrap();
        queue.submit([encoder.finish()]);
        let targets = chain.targets().unwrap();
        let ao = crate::readback::read_texture(device, queue, &targets.ao.texture).unwrap().to_f32();
        let nd = crate::readback::read_texture(device, queue, &targets.nd[0].texture).unwrap().to_vec4();
        let background = |nd: &[f32; 4]| nd[..3] == [0.0; 3];
        assert!(nd.iter().any(|n| !background(n)), "the line is in view");
        for (ao, nd) in ao.iter().zip(&nd) {
            let expected = if background(nd) { 0.0 } else { 1.0 - 0.25 * 1.5 };
            assert_eq!(*ao, expected);
        }
    }
}
