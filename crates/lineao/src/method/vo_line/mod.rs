//! Volumetric Obscurance with line samples (Loos & Sloan, "Volumetric Obscurance", I3D 2010,
//! §4.1, §4.3–4.5).
//!
//! Ambient obscurance as a volume: the fraction of a sphere of radius R around P that the depth
//! buffer leaves empty. A *line sample* at disk point s integrates that exactly along the
//! vertical chord of the unit sphere through s: with the chord [−z_s, z_s] (z_s = √(1 − |s|²),
//! z_d pointing away from the camera) and the visible surface at d_r (depth at the sample's pixel
//! minus depth at P, over R), the free length is max(min(z_s, d_r) + z_s, 0) — one depth fetch
//! buys a whole line integral, which is why 5 line samples beat 12 point samples.
//!
//! ```text
//!   ao(P) = 1 − Σ A_i |free ∩ allowed|_i / Σ A_i |allowed|_i
//! ```
//!
//! - **Weights** A_i come with the sample sets (`sample_sets`): the Voronoi column of
//!   each disk point, so every line stands for its share of the sphere.
//! - **Normal clamp** (§4.4): only the half above the tangent plane n · q ≥ 0 is allowed, a
//!   bound on z_d per sample (the plane's depth at s). A plane facing the camera is then wholly
//!   free (ao 0); without the clamp exactly half (ao 0.5).
//! - **Thickness** (§4.3): surfaces are `thickness` deep, free again behind that, so silhouettes
//!   stop casting obscurance on what lies far behind them.
//! - **Randomization** (§4.5): each pixel reflects its samples about a 2D direction from a 4 × 4
//!   tile (a reflection keeps |s|, so chords and weights stay valid).
//! - **Two radii** (Fig. 8): with `radius2_world` the sphere is evaluated at both radii and
//!   the results combined — brightness multiplied, or the darker one.
//!
//! The sphere's radius is in world units, mapped to pixels by the zoom map. The CPU reference
//! is [`crate::reference::vo_line`]. `VoCore` is what line and area sampling
//! ([`crate::method::vo_area`]) share: the uniform, the tables, the pipeline and its bindings.

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::noise;
use crate::passes::dispatch_full_screen;
use crate::sample_sets;
use crate::settings::ChainSettings;

#[cfg(feature = "reference")]
pub(crate) mod reference;
pub(crate) mod settings;
pub(crate) use settings::{VoCombine, VoSettings};

/// VO with line samples in the registry ([`crate::method`]).
pub(crate) const METHOD: super::MethodInfo = super::MethodInfo {
    name: "vo-line",
    label: "VO line",
    help: "Volumetric Obscurance with line samples (Loos & Sloan 2010, §4.1)",
    screen_space: true,
    estimates: super::Estimate::Obscurance,
    traces_scene: false,
    spans: &["vo-line"],
    library: crate::shader::Library { files: &[("vo_line.wgsl", include_str!("vo_line.wgsl"))], constants: &[] },
    build: Some(|device, settings| Box::new(VoLine::new(device, &settings.vo))),
    fits: super::fits_always,
    own: &super::Own {
        validate: |s, _| VoSettings::validate(s),
        ..super::Own::at(
            settings::SETTINGS,
            |c| &c.vo,
            |c| &mut c.vo,
            |preset, s, c| settings::preset(preset, s, c, 2.0, 1.5),
        )
    },
    bench: &[super::BenchPass::of("vo-line-5", &["vo-line"], |s, _| s.vo.samples = 5)],
    variant: None,
    fit: Some(|_, _| super::FitCandidate::radii(2.0, &[1.0, 4.0], |s, r| s.vo.radius_world = r)),
    #[cfg(feature = "reference")]
    reference: None,
};
use crate::method::vo_area::moments::Moments;
use crate::targets::{AO_FORMAT, FrameTargets};
use crate::timing::Span;
use crate::view_params::ViewParams;
use crate::view_params::ViewUniform;

/// Keep in sync with `VoUniform` in `shaders/shared/vo.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct VoUniform {
    /// The view's parameters.
    pub view: ViewUniform,
    /// The visible image's top-left pixel, where the noise tile starts.
    pub noise_origin: [i32; 2],
    /// The two radii, world units (the second 0 where there is none).
    pub radius: [f32; 2],
    /// World units per zoom unit.
    pub zoom_unit: f32,
    /// The thickness model's depth, world units (0: off).
    pub thickness: f32,
    /// 1 with the normal clamp.
    pub normal_clamp: u32,
    /// How two radii combine: 0 product, 1 the darker.
    pub combine: u32,
    /// The moments pyramid's last level (area samples).
    pub max_level: f32,
    /// σ below which depth counts as a step (area samples).
    pub sigma_floor: f32,
    /// The number of samples in the tables (set by the pass that owns them).
    pub samples: u32,
    /// Padding to WGSL's 16-byte alignment.
    pub _pad: u32,
}

impl VoUniform {
    /// The uniform for a frame; `max_level` is the moments pyramid's deepest level (area
    /// sampling; 0 for lines).
    pub fn new(targets: &FrameTargets, view: &FrameView, settings: &VoSettings, max_level: u32) -> VoUniform {
        debug_assert_eq!(targets.guard, view.guard);
        VoUniform {
            view: ViewParams::of(view).into(),
            noise_origin: view.noise_origin(),
            radius: [settings.radius_world, settings.radius2_world.unwrap_or(settings.radius_world)],
            zoom_unit: view.zoom_unit,
            thickness: settings.thickness_world,
            normal_clamp: settings.normal_clamp as u32,
            combine: (settings.combine == VoCombine::Min) as u32,
            max_level: max_level as f32,
            sigma_floor: crate::sample_sets::vo_sigma_floor(view.near, view.far),
            samples: 0,
            _pad: 0,
        }
    }
}

/// What both VO passes hold: a pipeline over (uniform, tables, `nd[0]`, `zoom`, [moments
/// layout, moments], `ao`), its uniform and its table of (x, y, A_i, w) samples and 2D
/// reflection directions.
pub(crate) struct VoCore {
    label: &'static str,
    /// (samples, noise seed, radii): what the pipeline and the tables were built for.
    key: (u32, u32, u32),
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    tables: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

impl VoCore {
    /// `samples`: (x, y, A_i, w) per sample, w for the shader's own use.
    pub(crate) fn new(
        device: &wgpu::Device,
        label: &'static str,
        shader: crate::shader::Source<'_>,
        samples: &[[f32; 4]],
        settings: &VoSettings,
        reads_moments: bool,
    ) -> VoCore {
        // `shared/vo_pass.wgsl`'s bindings, then the moments of area sampling.
        let mut slots =
            vec![Slot::Uniform, Slot::Uniform, Slot::Texture, Slot::Texture, Slot::StorageTexture(AO_FORMAT)];
        if reads_moments {
            slots.extend([Slot::Uniform, Slot::Storage]);
        }
        let layout = binding::layout(device, label, wgpu::ShaderStages::COMPUTE, &slots);
        let radii = 1 + settings.radius2_world.is_some() as u32;
        let constants = [("RADII", radii as f64)];
        let pipeline = binding::compute_pipeline(device, label, &layout, shader, "vo", &constants);
        let tile: Vec<[f32; 4]> = noise::vo_noise(settings.noise_seed).iter().map(|u| [u[0], u[1], 0.0, 0.0]).collect();
        VoCore {
            label,
            key: (samples.len() as u32, settings.noise_seed, radii),
            pipeline,
            layout,
            uniform: binding::uniform_buffer::<VoUniform>(device, label),
            // The samples in entries 0..16, the 4 × 4 tile of directions in 16..32.
            tables: binding::two_tables(device, label, samples, 16, &tile),
            group: None,
        }
    }

    pub(crate) fn matches(&self, samples: u32, settings: &VoSettings) -> bool {
        self.key == (samples, settings.noise_seed, 1 + settings.radius2_world.is_some() as u32)
    }

    /// Binds `nd[0]`, `zoom`, `ao`, and the moments when given.
    pub(crate) fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets, moments: Option<&Moments>) {
        let mut resources = vec![
            self.uniform.as_entire_binding(),
            self.tables.as_entire_binding(),
            wgpu::BindingResource::TextureView(&targets.nd[0].view),
            wgpu::BindingResource::TextureView(&targets.zoom.view),
            wgpu::BindingResource::TextureView(&targets.ao.view),
        ];
        if let Some(m) = moments {
            resources.extend([m.layout.as_entire_binding(), m.buffer.as_entire_binding()]);
        }
        self.group = Some(binding::group(device, self.label, &self.layout, &resources));
    }

    /// Writes `uniform` with the sample count of this pass's tables.
    pub(crate) fn prepare(&self, queue: &wgpu::Queue, uniform: &VoUniform) {
        let uniform = VoUniform { samples: self.key.0, ..*uniform };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    pub(crate) fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let Some(group) = &self.group else { return };
        dispatch_full_screen(encoder, self.label, &self.pipeline, group, targets.size, span);
    }
}

/// VO with line samples' compute pass.
pub struct VoLine {
    core: VoCore,
}

impl VoLine {
    /// `settings` must be valid (`ChainSettings::validate`): its sample count has a table.
    pub fn new(device: &wgpu::Device, settings: &VoSettings) -> VoLine {
        let samples: Vec<[f32; 4]> = sample_sets::vo_disk_samples(settings.samples)
            .unwrap_or_default()
            .iter()
            .map(|s| [s[0], s[1], s[2], crate::sample_sets::vo_chord_half(s[0], s[1])])
            .collect();
        VoLine {
            core: VoCore::new(
                device,
                "lineao::VoLine",
                METHOD.library.source("vo_line.wgsl"),
                &samples,
                settings,
                false,
            ),
        }
    }

    /// Whether `settings` can reuse this pipeline and its tables.
    pub fn matches(&self, settings: &VoSettings) -> bool {
        self.core.matches(settings.samples, settings)
    }

    /// Reads `nd[0]` and `zoom`, writes `ao`.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        self.core.resize(device, targets, None);
    }

    /// Writes this frame's uniform.
    pub fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &VoSettings) {
        self.core.prepare(queue, &VoUniform::new(targets, view, settings, 0));
    }

    /// Records the pass, timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        self.core.encode(encoder, targets, span);
    }
}

impl crate::method::Stage for VoLine {
    fn matches(&self, settings: &ChainSettings) -> bool {
        settings.method == crate::AoMethod::VoLine && VoLine::matches(self, &settings.vo)
    }

    /// The sphere's radius in pixels where it is largest (at the near plane).
    fn reach(&self, settings: &ChainSettings, unguarded: &FrameView) -> crate::method::Reach {
        let radius_px = settings.vo.max_radius_world() * unguarded.zoom_max() / settings.zoom_unit;
        crate::method::Reach::Pixels { radius_px, levels: 1 }
    }

    fn spans(&self, _: &ChainSettings) -> &'static [&'static str] {
        &["vo-line"]
    }

    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        VoLine::resize(self, device, targets);
    }

    fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings) {
        VoLine::prepare(self, queue, targets, view, &settings.vo);
    }

    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    ) {
        VoLine::encode(self, encoder, targets, span("vo-line"));
    }

    #[cfg(all(feature = "serde", feature = "reference"))]
    fn dump(&self, _: &crate::Gpu, s: &ChainSettings, _: &FrameView) -> Result<crate::method::Dump, crate::Error> {
        dump(&s.vo, s.vo.samples, sample_sets::vo_disk_samples(s.vo.samples).map(<[_]>::to_vec))
    }
}

/// docs/reference.md's VO keys, its `count` samples and its 4 × 4 rotation tile: VO lines' and
/// VO area's (`samples`: their set, `None` where there is none of that size).
#[cfg(all(feature = "serde", feature = "reference"))]
pub(crate) fn dump(
    vo: &VoSettings,
    count: u32,
    samples: Option<Vec<[f32; 3]>>,
) -> Result<crate::method::Dump, crate::Error> {
    let samples = samples.ok_or_else(|| crate::Error::out_of_range("vo-samples", count, "a VO sample set's count"))?;
    let mut dump = crate::method::Dump::default();
    dump.params(serde_json::json!({
        "samples": count,
        "radius_world": vo.radius_world,
        "normal_clamp": vo.normal_clamp,
        "thickness": vo.thickness_world,
        "noise_seed": vo.noise_seed,
    }));
    if let Some(r2) = vo.radius2_world {
        dump.params(serde_json::json!({"radius2_world": r2, "combine": vo.combine.name()}));
    }
    dump.array("vo_samples", &[count as u64, 3], samples.into_iter().flatten().collect());
    dump.array("vo_noise", &[4, 4, 2], noise::vo_noise(vo.noise_seed).into_iter().flatten().collect());
    Ok(dump)
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        VoUniform,
        "shared/vo.wgsl",
        "VoUniform",
        [view, noise_origin, radius, zoom_unit, thickness, normal_clamp, combine, max_level, sigma_floor, samples]
    );
}
