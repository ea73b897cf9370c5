//! Crytek SSAO (Mittring 2007, "Finding next gen: CryEngine 2", §8.5.4.3): the screen-space
//! ambient occlusion the LineAO paper compares against.
//!
//! For the view-space position P of each pixel, N points q_i = P + R · reflect(k_i, r(P)) of a
//! kernel inside the sphere of radius R are projected back into the image; q_i counts as
//! occluded when the visible surface at its pixel lies in front of it — by more than ε (flat
//! surfaces stay clean of f32 noise) and less than the *range* (a far foreground does not
//! darken what lies behind it):
//!
//! ```text
//!   ao(P) = 1/N Σ_i [ε < depth(q_i) − surface(pixel(q_i)) < range]
//! ```
//!
//! r(P) comes from a 4 × 4 tile of unit vectors, so 16 neighbouring pixels see 16 rotations of
//! the kernel, and [`crate::method::ssao::blur`] averages exactly that 4 × 4 window. Nothing here
//! knows about lines: a surface facing the camera is half occluded by itself (the samples behind
//! it), the grey look that LineAO's hemispheres avoid. The radius is in world units, so thin
//! lines far away get a sphere of a pixel or two — the paper's point about screen-space AO on
//! lines. The CPU reference is [`crate::reference::ssao`].

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::noise;
use crate::passes::dispatch_full_screen;
use crate::settings::ChainSettings;

pub mod blur;
#[cfg(feature = "reference")]
pub(crate) mod reference;
pub(crate) mod settings;
pub(crate) use settings::{SsaoKernel, SsaoSettings};

use crate::method::BenchPass;

/// Crytek SSAO in the registry ([`crate::method`]).
/// A sample counts as occluded only when the surface is in front of it by more than this
/// fraction of the depth range (f32 noise on a flat surface stays unoccluded); the shader's too.
pub const SSAO_EPSILON: f32 = 1e-5;

pub(crate) const METHOD: super::MethodInfo = super::MethodInfo {
    name: "ssao",
    label: "Crytek SSAO",
    help: "Crytek SSAO (Mittring 2007), the LineAO paper's baseline, with its 4 × 4 blur",
    screen_space: true,
    estimates: super::Estimate::Occlusion,
    traces_scene: false,
    spans: &["ssao", "ssao-blur"],
    library: crate::shader::Library {
        files: &[("ssao.wgsl", include_str!("ssao.wgsl")), blur::WGSL],
        constants: &[("SSAO_EPSILON", crate::shader::Constant::F32(SSAO_EPSILON))],
    },
    build: Some(|device, settings| Box::new(SsaoStage::new(device, settings))),
    fits: super::fits_always,
    own: &super::Own {
        validate: |s, _| SsaoSettings::validate(s),
        conform: settings::conform,
        ..super::Own::at(settings::SETTINGS, |c| &c.ssao, |c| &mut c.ssao, settings::preset)
    },
    bench: &[
        BenchPass::of("ssao-12", &["ssao"], |s, _| s.ssao.samples = 12),
        BenchPass::of("ssao-16-chain", &["ssao", "ssao-blur"], |s, _| s.ssao.samples = 16),
    ],
    variant: None,
    fit: Some(|_, _| {
        super::FitCandidate::radii(2.0, &[4.0, 8.0], |s, r| (s.ssao.radius_world, s.ssao.range_world) = (r, r))
    }),
    #[cfg(feature = "reference")]
    reference: Some(reference::of_frame),
};
use crate::targets::{AO_FORMAT, FrameTargets, Target};
use crate::timing::Span;
use crate::view_params::{ViewParams, ViewUniform};

/// Keep in sync with `SsaoUniform` in `ssao.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SsaoUniform {
    /// The view's parameters.
    pub view: ViewUniform,
    /// The visible image's top-left pixel, where the noise tile starts.
    pub noise_origin: [i32; 2],
    /// The sphere's radius, world units.
    pub radius: f32,
    /// The range check's distance, world units.
    pub range: f32,
}

/// Crytek SSAO's compute pass (its blur is [`SsaoBlur`](blur::SsaoBlur)).
pub struct Ssao {
    samples: u32,
    noise_seed: u32,
    kernel: SsaoKernel,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    tables: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

impl Ssao {
    /// The pass for `settings` (the sample count is compiled in).
    pub fn new(device: &wgpu::Device, settings: &SsaoSettings) -> Ssao {
        let layout = binding::layout(
            device,
            "lineao::Ssao::layout",
            wgpu::ShaderStages::COMPUTE,
            &[Slot::Uniform, Slot::Uniform, Slot::Texture, Slot::StorageTexture(AO_FORMAT)],
        );
        let pipeline = binding::compute_pipeline(
            device,
            "lineao::Ssao::pipeline",
            &layout,
            METHOD.library.source("ssao.wgsl"),
            "ssao",
            &[("SAMPLES", settings.samples as f64)],
        );
        Ssao {
            samples: settings.samples,
            noise_seed: settings.noise_seed,
            kernel: settings.kernel,
            pipeline,
            layout,
            uniform: binding::uniform_buffer::<SsaoUniform>(device, "lineao::Ssao::uniform"),
            // The kernel in entries 0..32, the 4 × 4 tile in 32..48 (`tables` in ssao.wgsl).
            tables: binding::two_tables(
                device,
                "lineao::Ssao::tables",
                &settings.kernel_points(),
                32,
                &noise::ssao_noise(settings.noise_seed),
            ),
            group: None,
        }
    }

    /// Whether `settings` can reuse this pipeline and its tables.
    pub fn matches(&self, settings: &SsaoSettings) -> bool {
        (self.samples, self.noise_seed, self.kernel) == (settings.samples, settings.noise_seed, settings.kernel)
    }

    /// Binds `nd[0]`, which it reads, and `raw` (an [`AO_FORMAT`] target of the targets' size,
    /// [`Target::ao`]), where it writes the occlusion before the blur.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets, raw: &Target) {
        self.group = Some(binding::group(
            device,
            "lineao::Ssao::group",
            &self.layout,
            &[
                self.uniform.as_entire_binding(),
                self.tables.as_entire_binding(),
                wgpu::BindingResource::TextureView(&targets.nd[0].view),
                wgpu::BindingResource::TextureView(&raw.view),
            ],
        ));
    }

    /// Writes this frame's uniform.
    pub fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &SsaoSettings) {
        debug_assert_eq!(targets.guard, view.guard);
        let uniform = SsaoUniform {
            view: ViewParams::of(view).into(),
            noise_origin: view.noise_origin(),
            radius: settings.radius_world,
            range: settings.range_world,
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the pass, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let Some(group) = &self.group else { return };
        dispatch_full_screen(encoder, "lineao::Ssao", &self.pipeline, group, targets.size, span);
    }
}

/// Crytek SSAO's [`crate::method::Stage`]: the samples (`nd[0]` → `raw`), then the 4 × 4 blur
/// matched to the rotation tile (`raw` → `ao`).
pub struct SsaoStage {
    ssao: Ssao,
    blur: blur::SsaoBlur,
    /// The occlusion before the blur, at the targets' size.
    raw: Option<Target>,
}

impl SsaoStage {
    /// SSAO and its blur as a stage of the chain.
    pub fn new(device: &wgpu::Device, settings: &ChainSettings) -> SsaoStage {
        SsaoStage { ssao: Ssao::new(device, &settings.ssao), blur: blur::SsaoBlur::new(device), raw: None }
    }
}

impl crate::method::Stage for SsaoStage {
    fn matches(&self, settings: &ChainSettings) -> bool {
        settings.method == crate::AoMethod::Ssao && self.ssao.matches(&settings.ssao)
    }

    /// The sphere's radius in pixels where it is largest (at the near plane), plus the blur's
    /// 2 px.
    fn reach(&self, settings: &ChainSettings, unguarded: &FrameView) -> crate::method::Reach {
        let radius_px = settings.ssao.radius_world * unguarded.zoom_max() / settings.zoom_unit + 2.0;
        crate::method::Reach::Pixels { radius_px, levels: 1 }
    }

    fn spans(&self, _: &ChainSettings) -> &'static [&'static str] {
        &["ssao", "ssao-blur"]
    }

    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let raw = Target::ao(device, "lineao::SsaoStage::raw", targets.size);
        self.ssao.resize(device, targets, &raw);
        self.blur.resize(device, targets, &raw);
        self.raw = Some(raw);
    }

    fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings) {
        self.ssao.prepare(queue, targets, view, &settings.ssao);
    }

    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    ) {
        self.ssao.encode(encoder, targets, span("ssao"));
        self.blur.encode(encoder, targets, span("ssao-blur"));
    }

    fn unblurred(&self) -> Option<&Target> {
        self.raw.as_ref()
    }

    /// docs/reference.md's SSAO keys, its kernel and its 4 × 4 rotation tile.
    #[cfg(all(feature = "serde", feature = "reference"))]
    fn dump(&self, _: &crate::Gpu, s: &ChainSettings, _: &FrameView) -> Result<crate::method::Dump, crate::Error> {
        let ssao = &s.ssao;
        let mut dump = crate::method::Dump::default();
        dump.params(serde_json::json!({
            "samples": ssao.samples,
            "radius_world": ssao.radius_world,
            "ssao_range": ssao.range_world,
            "noise_seed": ssao.noise_seed,
            "ssao_kernel": ssao.kernel.name(),
        }));
        let flat = |v: Vec<[f32; 3]>| v.into_iter().flatten().collect();
        dump.array("ssao_kernel", &[ssao.samples as u64, 3], flat(ssao.kernel_points()));
        dump.array("ssao_noise", &[4, 4, 3], flat(crate::noise::ssao_noise(ssao.noise_seed)));
        Ok(dump)
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        SsaoUniform,
        METHOD.library.source("ssao.wgsl"),
        "SsaoUniform",
        [view, noise_origin, radius, range]
    );
}
