//! User-facing settings of the LineAO pass chain. Each method's settings default to its paper's
//! values; [`ChainSettings::default()`] is the default preset ([`Preset::Legible`]), which changes
//! LineAO's reach and every method's strength, as every front end does.

use crate::lighting::Lighting;

/// Which ambient occlusion the chain computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AoMethod {
    /// Plain lines (with the illuminated-lines specular), no occlusion.
    None,
    /// LineAO (Eichelbaum et al. 2013).
    #[default]
    LineAo,
    /// Crytek SSAO (Mittring 2007), the LineAO paper's baseline, with its 4 × 4 blur.
    Ssao,
    /// Volumetric Obscurance with line samples (Loos & Sloan 2010, §4.1).
    VoLine,
    /// Volumetric Obscurance with area samples over a pyramid of depth moments (§4.2).
    VoArea,
    /// Ray-traced AO, the ground truth ([`crate::truth`]): computed outside the chain from its
    /// G-buffer and written into `targets().ao` before [`crate::AoChain::encode_composite`]. The
    /// chain itself runs no method pass and needs no guard band.
    RayTraced,
}

impl AoMethod {
    /// The name used on the command line and in `params.json`.
    pub fn name(self) -> &'static str {
        match self {
            AoMethod::None => "none",
            AoMethod::LineAo => "lineao",
            AoMethod::Ssao => "ssao",
            AoMethod::VoLine => "vo-line",
            AoMethod::VoArea => "vo-area",
            AoMethod::RayTraced => "raytraced",
        }
    }

    /// Every screen-space method, in the order `--grid` shows them (not the ray-traced truth,
    /// which is computed outside the chain).
    pub const ALL: [AoMethod; 5] =
        [AoMethod::None, AoMethod::LineAo, AoMethod::VoLine, AoMethod::VoArea, AoMethod::Ssao];

    /// The method called `name` (`none`, `lineao`, `ssao`, `vo-line`, `vo-area`, `raytraced`).
    pub fn from_name(name: &str) -> Option<AoMethod> {
        AoMethod::ALL.into_iter().chain([AoMethod::RayTraced]).find(|m| m.name() == name)
    }
}

/// Which LineAO: the paper's equations, or what the authors' own code does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineAoVariant {
    /// Eq. 4–15 with CONTRACT.md's conventions.
    #[default]
    Paper,
    /// The authors' OpenWalnut shader (DESIGN.md): no pyramid, radii growing 1.5, 4, 7.5 times a
    /// depth-scaled base radius, s_h samples per hemisphere skipping off-screen ones, the
    /// `1.5 − …` light weight, ao = max(0, Σ occ_l / s_r). See [`crate::passes::line_ao`].
    Reference,
}

/// A setting with a fixed set of values, each with the name the command line, `params.json` and
/// CONTRACT.md use and a line of help: what a CLI or a binding (Python, a host's UI) parses and
/// lists, so that it mirrors no enum of its own.
pub trait Named: Copy + Send + Sync + 'static {
    /// Every value, the default first.
    const VALUES: &'static [Self];
    fn name(self) -> &'static str;
    /// What the value does, in one line.
    fn help(self) -> &'static str;
    fn from_name(name: &str) -> Option<Self> {
        Self::VALUES.iter().copied().find(|v| v.name() == name)
    }
}

/// `impl Named` from the inherent `name` and a help line per value.
macro_rules! named {
    ($ty:ty { $($value:ident => $help:literal),+ $(,)? }) => {
        impl Named for $ty {
            const VALUES: &'static [Self] = &[$(<$ty>::$value),+];
            fn name(self) -> &'static str {
                <$ty>::name(self)
            }
            fn help(self) -> &'static str {
                match self {
                    $(<$ty>::$value => $help),+
                }
            }
        }
    };
}
pub(crate) use named;

named!(LineAoVariant {
    Paper => "The paper's equations with CONTRACT.md's conventions",
    Reference => "What the authors' OpenWalnut shader does (no pyramid, growing radii, `1.5 − …` weights)",
});
named!(LineAoOuter {
    Full => "Hemispheres j ≥ 1 at every pixel, as the paper does",
    Level => "Hemispheres j ≥ 1 at level j's resolution, upsampled depth-aware",
});
named!(SsaoKernel {
    Crytek => "Mittring's random kernel, denser near the centre",
    Sphere => "The VO paper's generated point set (8, 12, 16, 24 or 32 samples)",
});
named!(VoCombine {
    Product => "Brightness multiplies: 1 − (1 − ao_a)(1 − ao_b)",
    Min => "The darker of the two",
});
named!(Colormap {
    Viridis => "Perceptually uniform, dark blue to yellow",
    Gray => "Black to white",
    CoolWarm => "Moreland's diverging blue–white–red",
});

impl LineAoVariant {
    /// The name used on the command line and in `params.json`.
    pub fn name(self) -> &'static str {
        match self {
            LineAoVariant::Paper => "paper",
            LineAoVariant::Reference => "reference",
        }
    }
}

/// The LineAO parameters of Eq. 7–15 (CONTRACT.md "LineAO").
#[derive(Clone, Debug, PartialEq)]
pub struct LineAoSettings {
    pub variant: LineAoVariant,
    /// s_r: number of hemispheres and pyramid levels, 1..=5; the paper uses 3 (and needs > 1
    /// for δ(l) to fall off).
    pub s_r: u32,
    /// s_h: samples on the first hemisphere, 1..=256; hemisphere j takes ⌈s_h/(j+1)⌉. Default 32.
    pub s_h: u32,
    /// r0 in pixels for lines; `None` = `r0_per_width` × the line width.
    pub r0_px: Option<f32>,
    /// r0 for lines as a multiple of the line width where `r0_px` is `None`, ≥ 0: 1.5 in the
    /// paper (§3.2.3), 4.5 in the default preset (`legible`).
    pub r0_per_width: f32,
    /// δ0, the depth difference below which an occluder counts fully. Default 1e-4.
    pub delta0: f32,
    /// Scale of the falloff δ(j) = delta_scale · (1 − j/s_r)² (Eq. 11), in (0, 1]: the depth
    /// difference (normalized depth) beyond which hemisphere j's occluders no longer count. The
    /// paper's 1 lets anything in front count, however far; smaller values keep occlusion local
    /// in depth. Default 1 (paper).
    pub delta_scale: f32,
    /// ε: occluded iff Δd > ε. Default 1e-6 (CONTRACT.md departs from Eq. 8's Δd ≥ 0).
    pub epsilon: f32,
    /// Light attenuation g_light of Eq. 15; off means g_light = 1.
    pub light_attenuation: bool,
    /// Seed of the R1/R2 noise (CONTRACT.md "Noise"). Default 1.
    pub noise_seed: u32,
    /// Variant `reference`: the base radius in pixels at the home zoom (the authors'
    /// `u_lineAORadius`). Default 2.
    pub reference_radius_px: f32,
    /// Variant `paper`: hemispheres j ≥ 1 at full resolution or at their level's (CONTRACT.md).
    pub outer: LineAoOuter,
}

/// Where LineAO evaluates its outer hemispheres (j ≥ 1; CONTRACT.md `outer`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineAoOuter {
    /// At every pixel, as the paper does.
    #[default]
    Full,
    /// At every texel of pyramid level j (a quarter of the pixels for j = 1, a sixteenth for
    /// j = 2), then upsampled depth-aware: the wide hemispheres read blurred levels anyway, so
    /// their AO varies slowly and costs far less this way.
    Level,
}

impl LineAoOuter {
    /// The `params.json` and CLI name: `full` or `level`.
    pub fn name(self) -> &'static str {
        match self {
            LineAoOuter::Full => "full",
            LineAoOuter::Level => "level",
        }
    }
}

impl Default for LineAoSettings {
    fn default() -> Self {
        LineAoSettings {
            s_r: 3,
            s_h: 32,
            r0_px: None,
            r0_per_width: 1.5,
            delta0: 1e-4,
            delta_scale: 1.0,
            epsilon: 1e-6,
            light_attenuation: true,
            noise_seed: 1,
            variant: LineAoVariant::Paper,
            reference_radius_px: 2.0,
            outer: LineAoOuter::Full,
        }
    }
}

impl LineAoSettings {
    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        let bad = |what: String| Err(crate::Error::InvalidSettings(what));
        if !(1..=crate::MAX_LEVELS).contains(&self.s_r) {
            return bad(format!("s_r must be in 1..={}, got {}", crate::MAX_LEVELS, self.s_r));
        }
        if !(1..=256).contains(&self.s_h) {
            return bad(format!("s_h must be in 1..=256, got {}", self.s_h));
        }
        if !(self.r0_per_width.is_finite() && self.r0_per_width >= 0.0) {
            return bad(format!("r0 per line width must be finite and >= 0, got {}", self.r0_per_width));
        }
        if !(self.delta_scale.is_finite() && self.delta_scale > 0.0 && self.delta_scale <= 1.0) {
            return bad(format!("the δ scale must be in (0, 1], got {}", self.delta_scale));
        }
        let last_delta = self.delta_scale * (1.0 / self.s_r as f32).powi(2);
        if !(self.delta0.is_finite() && self.delta0 >= 0.0 && self.delta0 < last_delta) {
            return bad(format!("delta0 must be in [0, δ scale · (1/s_r)^2) = [0, {last_delta}), got {}", self.delta0));
        }
        if self.variant == LineAoVariant::Reference && self.outer == LineAoOuter::Level {
            return bad("outer = level applies to variant paper (reference reads level 0 only)".into());
        }
        if !(self.reference_radius_px.is_finite() && self.reference_radius_px >= 0.0) {
            return bad(format!("the reference radius must be >= 0 px, got {}", self.reference_radius_px));
        }
        if !(self.epsilon.is_finite() && self.epsilon >= 0.0) {
            return bad(format!("epsilon must be >= 0, got {}", self.epsilon));
        }
        Ok(())
    }
}

/// Crytek SSAO (`lineao::passes::ssao`).
#[derive(Clone, Debug, PartialEq)]
pub struct SsaoSettings {
    /// Point samples in the sphere (8..=32).
    pub samples: u32,
    /// Radius of the sampling sphere in world units.
    pub radius_world: f32,
    /// Range check: a sample counts as occluded only when the visible surface is in front of it
    /// by less than this (world units), so far-away foreground does not darken the background.
    pub range_world: f32,
    /// Seed of the kernel and the 4 × 4 rotation tile.
    pub noise_seed: u32,
    /// Where the kernel's points come from.
    pub kernel: SsaoKernel,
}

impl Default for SsaoSettings {
    fn default() -> Self {
        SsaoSettings { samples: 16, radius_world: 2.0, range_world: 2.0, noise_seed: 1, kernel: SsaoKernel::Crytek }
    }
}

impl SsaoSettings {
    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        let bad = |what: String| Err(crate::Error::InvalidSettings(what));
        if !(8..=32).contains(&self.samples) {
            return bad(format!("SSAO samples must be in 8..=32, got {}", self.samples));
        }
        if self.kernel == SsaoKernel::Sphere && !crate::sample_sets::VO_SPHERE_SAMPLE_COUNTS.contains(&self.samples) {
            return bad(format!(
                "the sphere kernel has {:?} samples, got {}",
                crate::sample_sets::VO_SPHERE_SAMPLE_COUNTS,
                self.samples
            ));
        }
        if !(self.radius_world.is_finite() && self.radius_world > 0.0) {
            return bad(format!("the SSAO radius must be > 0 world units, got {}", self.radius_world));
        }
        if !(self.range_world.is_finite() && self.range_world > 0.0) {
            return bad(format!("the SSAO range must be > 0 world units, got {}", self.range_world));
        }
        Ok(())
    }
}

impl SsaoSettings {
    /// The kernel's points in the unit ball (scaled by the radius in the pass).
    pub fn kernel_points(&self) -> Vec<[f32; 3]> {
        match self.kernel {
            SsaoKernel::Crytek => crate::noise::ssao_kernel(self.noise_seed, self.samples),
            SsaoKernel::Sphere => crate::sample_sets::vo_sphere_samples(self.samples).unwrap_or_default().to_vec(),
        }
    }
}

/// The SSAO kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SsaoKernel {
    /// Mittring's: random directions, lengths growing quadratically (denser near the centre).
    #[default]
    Crytek,
    /// The VO paper's point-sample set (§4.5): every point an equal share of the ball
    /// (`lineao::sample_sets::VO_SPHERE_SAMPLE_COUNTS` sizes only).
    Sphere,
}

impl SsaoKernel {
    /// The CLI and `params.json` name: `crytek` or `sphere`.
    pub fn name(self) -> &'static str {
        match self {
            SsaoKernel::Crytek => "crytek",
            SsaoKernel::Sphere => "sphere",
        }
    }
}

/// How two occlusions combine: VO at two radii (VO paper, Fig. 8), or object-space AO with the
/// screen-space method's ([`VolumeAoSettings`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum VoCombine {
    /// Brightness multiplies: ao = 1 − (1 − ao_small)(1 − ao_large).
    #[default]
    Product,
    /// The darker one: ao = max(ao_small, ao_large).
    Min,
}

impl VoCombine {
    /// The name used on the command line and in `params.json`.
    pub fn name(self) -> &'static str {
        match self {
            VoCombine::Product => "product",
            VoCombine::Min => "min",
        }
    }
}

/// Volumetric Obscurance (`lineao::passes::vo_line`, `lineao::passes::vo_area`).
#[derive(Clone, Debug, PartialEq)]
pub struct VoSettings {
    /// Line samples: one of `lineao::sample_sets::VO_SAMPLE_COUNTS` (5, 7, 9, 12, 13, 16).
    pub samples: u32,
    /// Area samples: one of `lineao::sample_sets::VO_AREA_SAMPLE_COUNTS` (1 or a line count).
    /// Default 1.
    pub area_samples: u32,
    /// Radius of the sphere in world units.
    pub radius_world: f32,
    /// A second radius: VO is evaluated at both and combined by `combine`, so fine features
    /// (the small one) and wide contact shadows (the large one) both show.
    pub radius2_world: Option<f32>,
    pub combine: VoCombine,
    /// Restrict the sphere to the half above the surface's tangent plane (§4.4).
    pub normal_clamp: bool,
    /// Thickness model (§4.3): occupied only this far behind the visible surface, world units;
    /// 0 = off (occupied all the way back).
    pub thickness_world: f32,
    /// Seed of the 4 × 4 tile of 2D reflection directions.
    pub noise_seed: u32,
}

impl VoSettings {
    /// The larger of the radii: what the guard band must cover.
    pub fn max_radius_world(&self) -> f32 {
        self.radius2_world.map_or(self.radius_world, |r| r.max(self.radius_world))
    }
}

impl Default for VoSettings {
    fn default() -> Self {
        VoSettings {
            samples: 9,
            area_samples: 1,
            radius_world: 2.0,
            radius2_world: None,
            combine: VoCombine::Product,
            normal_clamp: true,
            thickness_world: 0.0,
            noise_seed: 1,
        }
    }
}

impl VoSettings {
    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        let bad = |what: String| Err(crate::Error::InvalidSettings(what));
        if !crate::sample_sets::VO_SAMPLE_COUNTS.contains(&self.samples) {
            return bad(format!(
                "VO samples must be one of {:?}, got {}",
                crate::sample_sets::VO_SAMPLE_COUNTS,
                self.samples
            ));
        }
        if !crate::sample_sets::VO_AREA_SAMPLE_COUNTS.contains(&self.area_samples) {
            return bad(format!(
                "VO area samples must be one of {:?}, got {}",
                crate::sample_sets::VO_AREA_SAMPLE_COUNTS,
                self.area_samples
            ));
        }
        for radius in std::iter::once(self.radius_world).chain(self.radius2_world) {
            if !(radius.is_finite() && radius > 0.0) {
                return bad(format!("a VO radius must be > 0 world units, got {radius}"));
            }
        }
        if !(self.thickness_world.is_finite() && self.thickness_world >= 0.0) {
            return bad(format!("the VO thickness must be >= 0 world units, got {}", self.thickness_world));
        }
        Ok(())
    }
}

/// Object-space AO in the chain ([`crate::volume`], [`crate::passes::volume_ao`]): the
/// geometry's per-vertex octant visibilities ([`crate::passes::lines::VertexAttributes`])
/// turned into occlusion with each pixel's normal, alone (with [`AoMethod::None`]) or combined
/// with the screen-space method's.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeAoSettings {
    /// Light from each octant, in [0, 1], indexed as [`crate::volume::octant_signs`]
    /// ([`crate::volume::Sky::weights`]). Visibilities that already include a sky (the
    /// view-independent forms of [`crate::volume::scalar_visibility`]) take all ones. Default:
    /// all ones (an open sky).
    pub sky: [f32; 8],
    /// How it meets the screen-space method's occlusion. Default: brightness multiplies.
    pub combine: VoCombine,
}

impl Default for VolumeAoSettings {
    fn default() -> Self {
        VolumeAoSettings { sky: [1.0; 8], combine: VoCombine::Product }
    }
}

/// The separable depth-aware (bilateral) blur that can follow any method
/// (`lineao::passes::bilateral`).
#[derive(Clone, Debug, PartialEq)]
pub struct BilateralSettings {
    /// Taps on each side of the centre, 1..=16; the spatial Gaussian's σ is half of it.
    /// Default 4.
    pub radius_px: u32,
    /// σ of the depth Gaussian in world units: neighbours this much nearer or farther count
    /// e^(−1/2) as much, so occlusion does not bleed across depth edges. Default 1.
    pub depth_sigma_world: f32,
}

impl Default for BilateralSettings {
    fn default() -> Self {
        BilateralSettings { radius_px: 4, depth_sigma_world: 1.0 }
    }
}

impl BilateralSettings {
    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        let bad = |what: String| Err(crate::Error::InvalidSettings(what));
        if !(1..=16).contains(&self.radius_px) {
            return bad(format!("the blur radius must be in 1..=16 px, got {}", self.radius_px));
        }
        if !(self.depth_sigma_world.is_finite() && self.depth_sigma_world > 0.0) {
            return bad(format!("the blur's depth sigma must be > 0, got {}", self.depth_sigma_world));
        }
        Ok(())
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DebugView {
    /// color · (1 − strength · ao) + specular.
    #[default]
    Final,
    /// 1 − ao as gray.
    Ao,
    /// Level-0 normals as n · 0.5 + 0.5.
    Normals,
    /// Normalized linear depth.
    Depth,
    /// z(P) / z_max.
    Zoom,
    /// Normals of pyramid level k.
    Level(u32),
}

impl DebugView {
    pub(crate) fn code(self) -> (u32, u32) {
        match self {
            DebugView::Final => (0, 0),
            DebugView::Ao => (1, 0),
            DebugView::Normals => (2, 0),
            DebugView::Depth => (3, 0),
            DebugView::Zoom => (4, 0),
            DebugView::Level(k) => (5, k),
        }
    }
}

/// How lines are colored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LineColor {
    /// |T| of the world-space tangent as RGB (x red, y green, z blue: the DEC colormap of
    /// tractography, left-right red, anterior-posterior green, superior-inferior blue).
    Tangent,
    /// One linear RGB color.
    Constant([f32; 3]),
    /// The geometry's per-vertex scalar ([`crate::passes::lines::VertexAttributes::scalar`]:
    /// FA, curvature, a bundle index …) through `colormap`, `range` mapped to its ends (values
    /// beyond clamp). Geometry without scalars shows the colormap's low end.
    Scalar { colormap: Colormap, range: [f32; 2] },
}

/// Colormaps for [`LineColor::Scalar`], perceptually ordered where it matters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Colormap {
    /// Matplotlib's viridis: perceptually uniform, readable in grayscale and by most color-blind
    /// viewers. The default.
    #[default]
    Viridis,
    /// Black to white.
    Gray,
    /// Blue through white to red (Moreland's diverging map), for signed values.
    CoolWarm,
}

impl Colormap {
    pub const ALL: [Colormap; 3] = [Colormap::Viridis, Colormap::Gray, Colormap::CoolWarm];

    pub fn name(self) -> &'static str {
        match self {
            Colormap::Viridis => "viridis",
            Colormap::Gray => "gray",
            Colormap::CoolWarm => "coolwarm",
        }
    }

    /// sRGB control points at evenly spaced positions from 0 to 1.
    // Viridis samples, not approximations of π (0.318) or e.
    #[allow(clippy::approx_constant)]
    fn control_points(self) -> &'static [[f32; 3]] {
        match self {
            Colormap::Viridis => &[
                [0.267, 0.005, 0.329],
                [0.283, 0.141, 0.458],
                [0.254, 0.265, 0.530],
                [0.207, 0.372, 0.553],
                [0.164, 0.471, 0.558],
                [0.128, 0.567, 0.551],
                [0.135, 0.659, 0.518],
                [0.267, 0.749, 0.441],
                [0.478, 0.821, 0.318],
                [0.741, 0.873, 0.150],
                [0.993, 0.906, 0.144],
            ],
            Colormap::Gray => &[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]],
            Colormap::CoolWarm => &[[0.230, 0.299, 0.754], [0.865, 0.865, 0.865], [0.706, 0.016, 0.150]],
        }
    }

    /// The linear RGB color at `t` in [0, 1] (clamped): the sRGB control points interpolated,
    /// then decoded.
    pub fn color(self, t: f32) -> [f32; 3] {
        let points = self.control_points();
        let x = t.clamp(0.0, 1.0) * (points.len() - 1) as f32;
        let k = (x as usize).min(points.len() - 2);
        let f = x - k as f32;
        let decode = |c: f32| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
        std::array::from_fn(|c| decode(points[k][c] * (1.0 - f) + points[k + 1][c] * f))
    }

    /// [`COLORMAP_ENTRIES`] linear RGB entries from 0 to 1, as the shaders interpolate them.
    pub fn table(self) -> [[f32; 4]; COLORMAP_ENTRIES] {
        std::array::from_fn(|k| {
            let [r, g, b] = self.color(k as f32 / (COLORMAP_ENTRIES - 1) as f32);
            [r, g, b, 1.0]
        })
    }
}

/// Entries of a colormap's table in the geometry passes' uniform.
pub const COLORMAP_ENTRIES: usize = 16;

/// Streamlines as tubes (`lineao::passes::tubes`) instead of fixed-width lines.
#[derive(Clone, Debug, PartialEq)]
pub struct TubeSettings {
    /// Radius in world units (mm for tractograms) where the geometry carries no per-vertex
    /// radius, > 0. LineAO's r0 follows it (paper Eq. 16).
    pub radius_world: f32,
}

/// The ray-traced method on the GPU ([`crate::passes::raytraced_ao`]): rays per frame while the
/// view rests, accumulated up to a cap, as the CPU truth traces them.
#[derive(Clone, Debug, PartialEq)]
pub struct RayTracedSettings {
    /// Rays per geometry pixel each frame, ≥ 1. Default 4 (LineVis's).
    pub rays_per_frame: u32,
    /// Rays per pixel after which the frame is converged and nothing more is traced, ≥ 1.
    /// Default 1024.
    pub max_rays: u32,
    /// The rays' reach R in world units, > 0. Default 2 (the truth's).
    pub distance_world: f32,
    pub falloff: crate::truth::Falloff,
    /// Seed of the per-pixel scramble (the CPU truth's `seed`).
    pub seed: u32,
    /// The edge-aware denoiser ([`crate::passes::ray_denoise`]), or none. Default none: the
    /// picture as traced (what `lineao score` scores).
    pub denoise: Option<RayDenoiseSettings>,
}

/// The ray tracer's edge-aware denoiser: each pixel's mean averaged with its neighbours' on the
/// same surface, in a window whose Gaussian narrows as 1/√rays, so it smooths the first frames
/// and fades out as the picture converges.
#[derive(Clone, Debug, PartialEq)]
pub struct RayDenoiseSettings {
    /// Pixels on each side of the window, 1..=8. Default 3.
    pub radius_px: u32,
    /// σ of the spatial Gaussian at 4 rays per pixel, in pixels, > 0 (σ = sigma_px · √(4/rays);
    /// below a quarter pixel the window is the pixel alone). Default 1.5.
    pub sigma_px: f32,
    /// Neighbours count with max(n·n', 0)^normal_power, ≥ 0. Default 32.
    pub normal_power: f32,
    /// Lines and tubes: neighbours whose own segments are at most this many vertices apart along
    /// the polyline, ≥ 0. Default 2.
    pub reach_vertices: u32,
    /// Meshes: neighbours whose depth differs by at most this share of the pixel's, in (0, 1].
    /// Default 0.02.
    pub depth_tolerance: f32,
}

impl Default for RayDenoiseSettings {
    fn default() -> Self {
        RayDenoiseSettings { radius_px: 3, sigma_px: 1.5, normal_power: 32.0, reach_vertices: 2, depth_tolerance: 0.02 }
    }
}

impl RayDenoiseSettings {
    /// 1/(2σ²) of the spatial Gaussian after `rays` rays per pixel, or 0 where σ is below a
    /// quarter pixel (the pixel alone). Tubes take half the σ: several pixels wide, their
    /// occlusion changes across their width, which lines a pixel or two wide do not show
    /// (measured against the truth in docs/ground-truth.md).
    pub fn spatial(&self, rays: u32, tubes: bool) -> f32 {
        let sigma = self.sigma_px * (4.0 / rays.max(1) as f32).sqrt() * if tubes { 0.5 } else { 1.0 };
        if sigma < 0.25 { 0.0 } else { 1.0 / (2.0 * sigma * sigma) }
    }

    pub fn validate(&self) -> Result<(), crate::Error> {
        let ok = (1..=8).contains(&self.radius_px)
            && self.sigma_px.is_finite()
            && self.sigma_px > 0.0
            && self.normal_power.is_finite()
            && self.normal_power >= 0.0
            && self.depth_tolerance > 0.0
            && self.depth_tolerance <= 1.0;
        if ok {
            return Ok(());
        }
        Err(crate::Error::InvalidSettings(format!(
            "ray denoiser: radius 1..=8 px, σ > 0, normal power ≥ 0 and depth tolerance in (0, 1], got {self:?}"
        )))
    }
}

impl Default for RayTracedSettings {
    fn default() -> Self {
        let truth = crate::truth::TruthSettings::default();
        RayTracedSettings {
            rays_per_frame: 4,
            max_rays: 1024,
            distance_world: truth.distance_world,
            falloff: truth.falloff,
            seed: truth.seed,
            denoise: None,
        }
    }
}

impl RayTracedSettings {
    /// The CPU truth's settings tracing the same rays as `rays` rays per pixel of these.
    pub fn truth(&self, rays: u32) -> crate::truth::TruthSettings {
        crate::truth::TruthSettings {
            rays,
            distance_world: self.distance_world,
            falloff: self.falloff,
            seed: self.seed,
            vo: None,
            second: None,
            threads: 0,
        }
    }

    pub fn validate(&self) -> Result<(), crate::Error> {
        if self.rays_per_frame == 0 || self.max_rays == 0 {
            return Err(crate::Error::InvalidSettings(format!(
                "rays per frame and the ray cap must be at least 1, got {} and {}",
                self.rays_per_frame, self.max_rays
            )));
        }
        if let Some(denoise) = &self.denoise {
            denoise.validate()?;
        }
        self.truth(1).validate()
    }
}

/// Context surfaces (`lineao::passes::meshes`) drawn with the lines.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceSettings {
    /// Linear RGB of the surfaces. Default a light gray (0.8, 0.8, 0.8).
    pub color: [f32; 3],
}

impl Default for SurfaceSettings {
    fn default() -> Self {
        SurfaceSettings { color: [0.8; 3] }
    }
}

/// LineAO's first radius r0(P) = `px` + `per_zoom` · z(P) pixels: a constant for lines (1.5 ×
/// the line width), 1.5 · t_s · z(P) for tubes of width t_s zoom units (paper Eq. 16).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct R0 {
    pub px: f32,
    pub per_zoom: f32,
}

impl From<f32> for R0 {
    fn from(px: f32) -> R0 {
        R0 { px, per_zoom: 0.0 }
    }
}

/// Everything the pass chain needs to know besides the camera.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainSettings {
    pub method: AoMethod,
    pub line_ao: LineAoSettings,
    pub ssao: SsaoSettings,
    pub vo: VoSettings,
    pub raytraced: RayTracedSettings,
    /// The bilateral blur after the method, or none. Default none. After the ray tracer it is
    /// its denoiser for low ray counts (`lineao score` scores the rays undenoised).
    pub blur: Option<BilateralSettings>,
    /// Object-space AO from the geometry's attributes, or none. Default none.
    pub volume: Option<VolumeAoSettings>,
    pub lighting: Lighting,
    /// Line width in pixels, > 0. Default 2.
    pub line_width_px: f32,
    /// Tubes instead of lines, or none. Default none.
    pub tubes: Option<TubeSettings>,
    /// Context surfaces drawn with the lines ([`crate::AoChain::encode_with_meshes`]), or none.
    /// Default none.
    pub surfaces: Option<SurfaceSettings>,
    pub line_color: LineColor,
    /// Linear RGB of the background.
    pub background: [f32; 3],
    /// AO strength in the composite, ≥ 0. Default 1.
    pub strength: f32,
    pub debug_view: DebugView,
    /// World units per zoom unit (1 mm for tractography). Default 1.
    pub zoom_unit: f32,
    /// Upper bound of the guard band in pixels, whatever the method. Default 128.
    pub guard_max_px: u32,
}

impl Default for ChainSettings {
    /// The default preset's settings ([`Preset::Legible`], what every front end starts from):
    /// the papers' values ([`ChainSettings::papers`]) with the preset's for LineAO.
    fn default() -> Self {
        ChainSettings::papers().with_preset(Preset::default())
    }
}

impl ChainSettings {
    /// The papers' values for every setting (LineAO s_r 3, r0 1.5 × the line width, δ scale 1,
    /// strength 1; VO and SSAO spheres of 2 world units): `ChainSettings::default()` before the
    /// default preset is applied, and what [`Preset::Paper`] restores.
    pub fn papers() -> Self {
        ChainSettings {
            method: AoMethod::LineAo,
            line_ao: LineAoSettings::default(),
            ssao: SsaoSettings::default(),
            vo: VoSettings::default(),
            raytraced: RayTracedSettings::default(),
            blur: None,
            volume: None,
            lighting: Lighting::default(),
            line_width_px: 2.0,
            tubes: None,
            surfaces: None,
            line_color: LineColor::Tangent,
            background: [1.0, 1.0, 1.0],
            strength: 1.0,
            debug_view: DebugView::Final,
            zoom_unit: 1.0,
            guard_max_px: 128,
        }
    }
}

/// A named set of parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Preset {
    /// The papers' values ([`ChainSettings::papers`]).
    Paper,
    /// Each method's strength and reach fitted for *legibility* — visibly darker pixels lie
    /// deeper ([`crate::truth::legibility`]) — with the picture kept readable (near-black ≤ 2 %,
    /// mean darkening in [0.15, 0.45]): `lineao score --fit`, docs/ground-truth.md.
    #[default]
    Legible,
    /// Each method's strength and reach fitted to the local ray-traced truth (binary AO within
    /// 2 mm, least RMSE): physically close at that reach, but so faint on whole brains that it
    /// looks like no AO at all. Was called `calibrated`, a name still accepted.
    Physical,
}

impl Preset {
    pub const ALL: [Preset; 3] = [Preset::Legible, Preset::Physical, Preset::Paper];

    /// The name on the command line (`legible`, `physical`, `paper`).
    pub fn name(self) -> &'static str {
        match self {
            Preset::Paper => "paper",
            Preset::Legible => "legible",
            Preset::Physical => "physical",
        }
    }

    /// The preset called `name`; `calibrated`, the name `physical` had before, too.
    pub fn from_name(name: &str) -> Option<Preset> {
        match name {
            "calibrated" => Some(Preset::Physical),
            _ => Preset::ALL.into_iter().find(|p| p.name() == name),
        }
    }
}

/// A preset's values of one method. `physical`: the least mean RMSE against binary AO to
/// R = 2 mm (session 13's `lineao score --fit`, when it was called `calibrated`) among the
/// settings that keep every real tractogram's mean AO within 0.1 of the truth's; `legible`: the
/// most legible settings under the readability constraints (docs/ground-truth.md has both
/// tables, fit and held out).
struct Calibrated {
    strength: f32,
    /// LineAO: hemispheres, r0 as a multiple of the line width, and the scale of δ(j).
    s_r: u32,
    r0_per_width: f32,
    delta_scale: f32,
    /// The reference variant's base radius, px.
    reference_radius_px: f32,
    /// VO's and SSAO's sphere, zoom units.
    radius: f32,
}

impl ChainSettings {
    /// `self` with `preset`'s values for its method (and LineAO variant): the strength, LineAO's
    /// s_r, δ scale and r0 (lines; tubes keep Eq. 16's r0), VO's and SSAO's radius in zoom units.
    /// [`Preset::Paper`] restores the papers' values of those ([`ChainSettings::papers`]).
    pub fn with_preset(mut self, preset: Preset) -> ChainSettings {
        let paper = Calibrated {
            strength: 1.0,
            s_r: 3,
            r0_per_width: 1.5,
            delta_scale: 1.0,
            reference_radius_px: 2.0,
            radius: 2.0,
        };
        let c = match (preset, self.method, self.line_ao.variant) {
            (Preset::Paper, ..) => paper,
            // The most legible settings that keep every view readable (`lineao score --fit
            // --width 640 --height 512 --views 2 --rays 32`, docs/ground-truth.md): LineAO with
            // two hemispheres, the first reaching past a line's own width to its neighbours
            // (r0 4.5 × the width), the paper's δ (occluders far in front count: depth order is
            // the question); held-out legibility +0.371 (the papers' values +0.29 on the real
            // files), never near-black. The authors' variant is more legible (+0.497) but costs
            // 2.55 × Crytek SSAO's frame on lavapipe, so it is not what `lineao` renders by
            // default.
            (Preset::Legible, AoMethod::LineAo, LineAoVariant::Paper) => {
                Calibrated { strength: 0.6, s_r: 2, r0_per_width: 4.5, ..paper }
            }
            (Preset::Legible, AoMethod::LineAo, LineAoVariant::Reference) => Calibrated { strength: 0.6, ..paper },
            (Preset::Legible, AoMethod::VoLine, _) => Calibrated { strength: 0.8, ..paper },
            (Preset::Legible, AoMethod::VoArea, _) => Calibrated { strength: 0.8, radius: 1.0, ..paper },
            (Preset::Legible, AoMethod::Ssao, _) => Calibrated { strength: 1.0, radius: 8.0, ..paper },

            // Two hemispheres with δ a tenth of the paper's: the third hemisphere and occluders
            // far in front (in depth) darken dense and sparse data alike, where the truth tells
            // them apart; with them LineAO's mean stays within 0.1 of the truth's on every
            // real tractogram (within 0.09), and its held-out RMSE is 0.204 (paper: 0.450).
            (Preset::Physical, AoMethod::LineAo, LineAoVariant::Paper) => {
                Calibrated { strength: 0.58, s_r: 2, delta_scale: 0.1, ..paper }
            }
            (Preset::Physical, AoMethod::LineAo, LineAoVariant::Reference) => {
                Calibrated { strength: 0.46, reference_radius_px: 1.0, ..paper }
            }
            (Preset::Physical, AoMethod::VoLine, _) => Calibrated { strength: 0.22, radius: 1.5, ..paper },
            (Preset::Physical, AoMethod::VoArea, _) => Calibrated { strength: 0.22, radius: 1.0, ..paper },
            (Preset::Physical, AoMethod::Ssao, _) => Calibrated { strength: 0.68, radius: 3.0, ..paper },
            (_, AoMethod::None | AoMethod::RayTraced, _) => paper,
        };
        self.strength = c.strength;
        self.line_ao.s_r = c.s_r;
        self.line_ao.delta_scale = c.delta_scale;
        // r0 follows the line width (tubes keep Eq. 16's r0, which ignores it).
        self.line_ao.r0_px = None;
        self.line_ao.r0_per_width = c.r0_per_width;
        self.line_ao.reference_radius_px = c.reference_radius_px;
        self.vo.radius_world = c.radius * self.zoom_unit;
        self.ssao.radius_world = c.radius * self.zoom_unit;
        self.ssao.range_world = c.radius * self.zoom_unit;
        self
    }

    /// Settings for a host's triangle meshes (`AoChain::encode_host`) in a scene of bounding
    /// radius `scene_radius` (world units), chosen against the ray-traced truth: Volumetric
    /// Obscurance with line samples, the normal clamp and a thickness of one radius, reaching
    /// a tenth of the scene's radius, strength 1.75, then the bilateral blur.
    ///
    /// `cargo run --release --example embed_renderer -- --fit` scores every method on that
    /// example's meshes on a ground plane (binary AO to the same reach, 128 rays, each method at
    /// its least-squares strength; docs/measurements.md has the table): this one has the least
    /// RMSE (0.053, correlation 0.95; LineAO's best 0.118, SSAO 0.162, VO area 0.155), leaves
    /// the open ground at 0.0007 and darkens the contacts by 0.50 where the truth says 0.53.
    /// Without the clamp VO darkens every open surface; without the thickness it darkens
    /// around every silhouette; LineAO, made for lines, darkens open ground by 3–8 %.
    pub fn for_meshes(scene_radius: f32) -> ChainSettings {
        let reach = 0.1 * scene_radius;
        let mut settings = ChainSettings {
            method: AoMethod::VoLine,
            strength: 1.75,
            blur: Some(BilateralSettings::default()),
            ..ChainSettings::default()
        };
        settings.vo.radius_world = reach;
        settings.vo.thickness_world = reach;
        settings.vo.normal_clamp = true;
        settings
    }

    /// r0's constant part in pixels: the explicit value, or `r0_per_width` × the line width
    /// (tubes: 0).
    pub fn r0_px(&self) -> f32 {
        let default = if self.tubes.is_some() { 0.0 } else { self.line_ao.r0_per_width * self.line_width_px };
        self.line_ao.r0_px.unwrap_or(default)
    }

    /// r0(P) of LineAO (paper §3.2.3, Eq. 16): for tubes 1.5 · z(P) · t_s, t_s = 2 × the radius
    /// in zoom units; an explicit `r0_px` replaces the default constant part.
    pub fn r0(&self) -> R0 {
        let per_zoom = self.tubes.as_ref().map_or(0.0, |t| 1.5 * 2.0 * t.radius_world / self.zoom_unit);
        R0 { px: self.r0_px(), per_zoom }
    }

    /// Pyramid levels the chain needs: s_r for LineAO; one for plain lines and for the
    /// `reference` variant (the authors' pyramid is off by default).
    pub fn levels(&self) -> u32 {
        match (self.method, self.line_ao.variant) {
            (AoMethod::LineAo, LineAoVariant::Paper) => self.line_ao.s_r,
            _ => 1,
        }
    }

    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        let bad = |what: String| Err(crate::Error::InvalidSettings(what));
        // Each method's own settings, then what the chain adds.
        self.line_ao.validate()?;
        self.ssao.validate()?;
        self.vo.validate()?;
        self.raytraced.validate()?;
        if let Some(blur) = &self.blur {
            blur.validate()?;
        }
        if !(self.line_width_px.is_finite() && self.line_width_px > 0.0 && self.line_width_px <= 256.0) {
            return bad(format!("line width must be in (0, 256] px, got {}", self.line_width_px));
        }
        if let Some(tubes) = &self.tubes
            && !(tubes.radius_world.is_finite() && tubes.radius_world > 0.0)
        {
            return bad(format!("the tube radius must be > 0 world units, got {}", tubes.radius_world));
        }
        if !(self.r0_px().is_finite() && self.r0_px() >= 0.0) {
            return bad(format!("r0 must be a finite number of pixels >= 0, got {}", self.r0_px()));
        }
        if let Some(volume) = &self.volume
            && !volume.sky.iter().all(|w| (0.0..=1.0).contains(w))
        {
            return bad(format!("sky intensities must be in [0, 1], got {:?}", volume.sky));
        }
        if !(self.strength.is_finite() && self.strength >= 0.0) {
            return bad(format!("strength must be >= 0, got {}", self.strength));
        }
        if !(self.zoom_unit.is_finite() && self.zoom_unit > 0.0) {
            return bad(format!("zoom unit must be > 0, got {}", self.zoom_unit));
        }
        if self.lighting.lights.len() > crate::lighting::MAX_LIGHTS {
            return bad(format!("at most {} lights, got {}", crate::lighting::MAX_LIGHTS, self.lighting.lights.len()));
        }
        if let DebugView::Level(k) = self.debug_view
            && k >= self.levels()
        {
            return bad(format!("debug level {k} does not exist: the pyramid has {} levels", self.levels()));
        }
        Ok(())
    }
}
