//! The 4 × 4 blur that belongs to Crytek SSAO: the mean of its raw occlusion over the window
//! x−2..=x+1, y−2..=y+1, which holds each of the 16 kernel rotations of the 4 × 4 tile exactly
//! once, so the rotation pattern cancels. Only geometry pixels are averaged (the background has
//! no occlusion to spread into the lines' silhouettes). Reads SSAO's raw occlusion, writes `ao`. The CPU
//! reference is [`crate::reference::ssao_blur`].

use crate::binding::{self, Slot};
use crate::passes::dispatch_full_screen;
use crate::shader::Library;
use crate::targets::{AO_FORMAT, FrameTargets, Target};
use crate::timing::Span;

/// Its WGSL file, one of SSAO's ([`super::METHOD`]'s library lists it).
pub(crate) const WGSL: (&str, &str) = ("ssao_blur.wgsl", include_str!("ssao_blur.wgsl"));
const LIBRARY: Library = Library { files: &[WGSL], constants: &[] };

/// Crytek SSAO's 4 × 4 box blur over its occlusion.
pub struct SsaoBlur {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    group: Option<wgpu::BindGroup>,
}

impl SsaoBlur {
    /// Its pipeline and layout.
    pub fn new(device: &wgpu::Device) -> SsaoBlur {
        let layout = binding::layout(
            device,
            "lineao::SsaoBlur::layout",
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Texture, Slot::Texture, Slot::StorageTexture(AO_FORMAT)],
        );
        let pipeline = binding::compute_pipeline(
            device,
            "lineao::SsaoBlur::pipeline",
            &layout,
            LIBRARY.source(WGSL.0),
            "blur",
            &[],
        );
        SsaoBlur { pipeline, layout, group: None }
    }

    /// Binds `raw` (SSAO's occlusion, [`Target::ao`] at the targets' size) → `ao`.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets, raw: &Target) {
        self.group = Some(binding::group(
            device,
            "lineao::SsaoBlur::group",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(&targets.nd[0].view),
                wgpu::BindingResource::TextureView(&raw.view),
                wgpu::BindingResource::TextureView(&targets.ao.view),
            ],
        ));
    }

    /// Records the pass, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let Some(group) = &self.group else { return };
        dispatch_full_screen(encoder, "lineao::SsaoBlur", &self.pipeline, group, targets.size, span);
    }
}
