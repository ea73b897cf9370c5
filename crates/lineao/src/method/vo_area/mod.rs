//! Volumetric Obscurance with area samples (Loos & Sloan, I3D 2010, §4.2).
//!
//! Line sampling reads one depth per disk sample; area sampling reads the *distribution* of
//! depth over the part of the disk the sample stands for. The [`MomentsPyramid`] gives the mean
//! μ and standard deviation σ of depth over any footprint; the paper models the distribution as
//! a box over μ ± σ (a Gaussian's convolution with the step has no closed form), so the chance
//! that a point at depth z_d of the chord lies in front of the surface is 1 before μ − σ, falls
//! linearly to 0 at μ + σ, and the chord's free length is the two-part integral
//!
//! ```text
//!   V = (min(z_max, μ − σ) − z_min)⁺  +  a (z1² − z0²)/2 + b (z1 − z0),
//!   a = −1/(2σ), b = −a (μ + σ), [z0, z1] = [μ − σ, μ + σ] ∩ [z_min, z_max]
//! ```
//!
//! with everything in the unit sphere's coordinates, as for lines (σ = 0 *is* a line sample).
//! The normal clamp, the thickness model, the per-pixel reflection and two radii work as in
//! [`crate::method::vo_line`]. The footprint of sample i covers π r² A_i/ΣA pixels for a sphere
//! of r pixels: one log2 per pixel plus a precomputed per-sample offset gives its level of
//! detail (`sample_sets::vo_area_lod_offsets`); reads are trilinear. One sample — the
//! whole sphere — already darkens creases and contacts without any noise; more samples keep
//! finer structure. σ below 1e-3 · (far − near) is f32 cancellation and counts as 0
//! (docs/reference.md). The CPU reference is [`crate::reference::vo_area`].

use crate::camera::FrameView;
use crate::method::vo_line::VoSettings;
use crate::method::vo_line::settings::{AREA_SETTINGS, preset as vo_preset};
use crate::method::vo_line::{VoCore, VoUniform};
use crate::sample_sets;
use crate::settings::ChainSettings;
use moments::MomentsPyramid;

pub mod moments;
#[cfg(feature = "reference")]
pub(crate) mod reference;

/// VO with area samples in the registry ([`crate::method`]); its settings are VO's
/// ([`VoSettings`], `ChainSettings::vo`).
pub(crate) const METHOD: super::MethodInfo = super::MethodInfo {
    name: "vo-area",
    label: "VO area",
    help: "Volumetric Obscurance with area samples over a pyramid of depth moments (Loos & Sloan 2010, §4.2)",
    screen_space: true,
    estimates: super::Estimate::Obscurance,
    traces_scene: false,
    spans: &["moments", "vo-area"],
    library: crate::shader::Library {
        files: &[("vo_area.wgsl", include_str!("vo_area.wgsl")), moments::LIBRARY.files[0], moments::LIBRARY.files[1]],
        constants: moments::LIBRARY.constants,
    },
    build: Some(|device, settings| Box::new(VoArea::new(device, &settings.vo))),
    fits: moments::fits,
    own: &super::Own {
        validate: |s, _| VoSettings::validate(s),
        ..super::Own::at(AREA_SETTINGS, |c| &c.vo, |c| &mut c.vo, |preset, s, c| vo_preset(preset, s, c, 1.0, 1.0))
    },
    bench: &[super::BenchPass::of("vo-area-1", &["moments", "vo-area"], |s, _| s.vo.area_samples = 1)],
    variant: None,
    fit: Some(|_, _| super::FitCandidate::radii(2.0, &[1.0, 4.0], |s, r| s.vo.radius_world = r)),
    #[cfg(feature = "reference")]
    reference: None,
};
use crate::targets::FrameTargets;
use crate::timing::Span;

/// VO with area samples: the moments pyramid and the pass that reads it.
pub struct VoArea {
    moments: MomentsPyramid,
    core: VoCore,
    max_level: u32,
}

impl VoArea {
    /// `settings` must be valid (`ChainSettings::validate`): its area sample count has a set.
    pub fn new(device: &wgpu::Device, settings: &VoSettings) -> VoArea {
        let samples = sample_sets::vo_area_samples(settings.area_samples).unwrap_or_default();
        let lod = sample_sets::vo_area_lod_offsets(&samples);
        let table: Vec<[f32; 4]> = samples.iter().zip(lod).map(|(s, w)| [s[0], s[1], s[2], w]).collect();
        VoArea {
            moments: MomentsPyramid::new(device),
            core: VoCore::new(device, "lineao::VoArea", METHOD.library.source("vo_area.wgsl"), &table, settings, true),
            max_level: 0,
        }
    }

    /// Whether `settings` can reuse this pipeline and its tables.
    pub fn matches(&self, settings: &VoSettings) -> bool {
        self.core.matches(settings.area_samples, settings)
    }

    /// Reads `nd[0]`, `zoom` and its moments pyramid (which it writes first, allocated here at
    /// the targets' size), writes `ao`.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        self.moments.resize(device, targets);
        let moments = self.moments.moments().expect("sized above");
        self.core.resize(device, targets, Some(moments));
        self.max_level = moments.levels.len() as u32 - 1;
    }

    /// The moments pyramid of the last frame (for readback: [`Moments::read`](moments::Moments::read)).
    pub fn moments(&self) -> Option<&moments::Moments> {
        self.moments.moments()
    }

    /// Writes this frame's uniforms.
    pub fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &VoSettings) {
        self.moments.prepare(queue, view);
        self.core.prepare(queue, &VoUniform::new(targets, view, settings, self.max_level));
    }

    /// Records the moments pyramid and the pass, timed into `moments` and `span` when given.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        moments: Option<Span>,
        span: Option<Span>,
    ) {
        if self.moments.moments().is_none() {
            return;
        }
        self.moments.encode(encoder, moments);
        self.core.encode(encoder, targets, span);
    }
}

impl crate::method::Stage for VoArea {
    fn matches(&self, settings: &ChainSettings) -> bool {
        settings.method == crate::AoMethod::VoArea && VoArea::matches(self, &settings.vo)
    }

    /// Area samples read moments over a footprint around each sample point: half its side is at
    /// most ½ √π r < r, and the Gaussian levels' tails reach about as far again, so 2 r covers
    /// what they read.
    fn reach(&self, settings: &ChainSettings, unguarded: &FrameView) -> crate::method::Reach {
        let radius_px = 2.0 * settings.vo.max_radius_world() * unguarded.zoom_max() / settings.zoom_unit;
        crate::method::Reach::Pixels { radius_px, levels: 1 }
    }

    fn spans(&self, _: &ChainSettings) -> &'static [&'static str] {
        &["moments", "vo-area"]
    }

    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        VoArea::resize(self, device, targets);
    }

    fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings) {
        VoArea::prepare(self, queue, targets, view, &settings.vo);
    }

    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    ) {
        VoArea::encode(self, encoder, targets, span("moments"), span("vo-area"));
    }

    /// VO's keys and tables ([`crate::method::vo_line`]'s) with the area samples, and the
    /// moments pyramid read back (`moments_L.npy`).
    #[cfg(all(feature = "serde", feature = "reference"))]
    fn dump(&self, gpu: &crate::Gpu, s: &ChainSettings, _: &FrameView) -> Result<crate::method::Dump, crate::Error> {
        let vo = &s.vo;
        let mut dump =
            crate::method::vo_line::dump(vo, vo.area_samples, sample_sets::vo_area_samples(vo.area_samples))?;
        if let Some(moments) = self.moments() {
            for (l, level) in moments.read(&gpu.device, &gpu.queue)?.into_iter().enumerate() {
                let shape = [level.height as u64, level.width as u64, 2];
                dump.array(&format!("moments_{l}"), &shape, level.data.concat());
            }
        }
        Ok(dump)
    }
}
