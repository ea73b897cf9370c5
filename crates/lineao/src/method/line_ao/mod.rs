//! LineAO (Eichelbaum et al., TVCG 2013, Eq. 7): ambient occlusion made for dense lines.
//!
//! Plain SSAO samples one hemisphere of fixed radius: on thin lines it sees too little volume,
//! and the fixed line width on screen makes bundles look sparser as one zooms in. LineAO sums
//! s_r hemispheres instead. Hemisphere j has radius r_j = r0 + j · z(P) pixels (the zoom map
//! keeps the effect coherent under zoom), takes n_j = ⌈s_h/(j+1)⌉ samples and reads level j of
//! the Gaussian ND pyramid, so wide hemispheres see merged bundles, not single lines:
//!
//! ```text
//!   LineAO(P) = clamp( Σ_j (1/n_j) Σ_i [Δd > ε] · g_depth(Δd, j) · g_light(n_j(P), ω_i), 0, 1 )
//!   Δd        = d_j(P) − d_j(P + r_j (ω.x, −ω.y))                     (Eq. 10, height-field test)
//!   g_depth   = 1 below δ0, 0 above δ(j) = (1 − j/s_r)², 1 − h(·) between   (Eq. 11–13)
//!   g_light   = 1 − min(Σ_lights BRDF(L, I, n_j(P), ω), 1)                  (Eq. 14–15)
//! ```
//!
//! ω_i = reflect(R1(P), `R2[j][i]`) flipped into the hemisphere of n_j(P) (§3.4, `noise.rs`).
//! Where we depart from the paper (the ε test, the third case of Eq. 12) is in docs/reference.md.
//! The CPU reference is [`crate::reference::line_ao`]; `line_ao.wgsl` is the shader.
//!
//! # Variant `reference`: what the authors' code does
//!
//! The authors' OpenWalnut shader (`WGEPostprocessorLineAO`) differs from the paper in ways
//! that change the picture; [`LineAoVariant::Reference`] reproduces it on our G-buffer so the
//! two can be compared:
//!
//! ```text
//!   base(P)  = z(P)/z_fit · radius_px · (W, H)/max(W, H) / (1 − d(P))   pixels per axis
//!   offset   = (1.5 + 4.0 + … : Σ_{k≤l} (1.5 + k)) · base(P) ⊙ (ω.x, −ω.y),  ω = ±reflect(R2, R1)
//!   occ_l    = 1/used Σ_i [Δd ≥ 1e−5] · (1 − smoothstep(1e−5, (1 − l/(s_r−1))², Δd))
//!                       · (1.5 − max(ω·n, 0) · Σ_lights I (max(n_o·L, 0) + max(n_o·h, 0)^100))
//!   ao       = max(0, Σ_l occ_l / s_r)        (not clamped above: the weights reach 1.5)
//! ```
//!
//! All hemispheres read level 0 (the authors' pyramid is off by default), each takes s_h
//! samples, samples falling outside the texture are skipped and each hemisphere is normalized
//! by the samples it used. The last hemisphere's falloff is 0, which makes every occluder count
//! fully there. Where our G-buffer differs: the authors' zoom factor is the camera's scale
//! relative to the home view; ours is z(P)/z_fit with z_fit the zoom at which the scene's
//! bounding sphere fills the view's shorter side ([`FrameView::zoom_fit`]); the occluder's
//! normal n_o is its ND normal (their G-buffer has tangents, ours does not); the light is the
//! scene's. 1 − d is kept above 1e−6. The radius grows without bound as d → 1, so the guard
//! band of this variant is the cap.

//! # `outer = level` (docs/reference.md's optional speed-up)
//!
//! Hemispheres j ≥ 1 read level j of the pyramid, which is blurred and 2^j times smaller, so
//! their AO varies slowly. With [`LineAoOuter::Level`] a pass per j evaluates AO_j once per
//! texel of level j — exactly as `outer = full` would at the texel's representative pixel
//! ⌊(t + ½) · size_0/size_j⌋ (same centre texel, noise, zoom and radius), so the level image is
//! the full image subsampled — and stores (AO_j, d_j). The full-resolution pass then computes
//! hemisphere 0 and adds each AO_j upsampled depth-aware: bilinear over the four nearest texels,
//! each weight times max(0, 1 − |d_j(t) − d_j(t_P)|/τ), τ = [`crate::reference::OUTER_DEPTH_TOLERANCE`],
//! t_P the texel `full` reads its centre from. At the defaults this replaces 27 of 59 taps per
//! pixel by 8 (plus 16/4 + 11/16 per pixel in the level passes). It is not the default: its
//! per-pixel difference from `full` is below the noise (`full` against itself with another
//! seed differs more) but above docs/reference.md's 0.02 (README, "Measured").

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::lighting::{Lighting, LightingShape, LightingUniform};
use crate::method::BenchPass;
use crate::noise;
use crate::passes::dispatch_full_screen;
use crate::settings::ChainSettings;

#[cfg(feature = "reference")]
pub(crate) mod reference;
pub(crate) mod settings;
pub(crate) use settings::{LineAoOuter, LineAoSettings, LineAoVariant};

/// LineAO in the registry ([`crate::method`]).
/// Depth tolerance of the upsampling, in normalized depth: a level texel whose d_j differs from
/// the pixel's own level texel by τ or more does not contribute (the shader's too).
pub const OUTER_DEPTH_TOLERANCE: f32 = 0.005;

/// LineAO's search in `lineao score --fit`. Its paper form: the paper's values first, then s_r ×
/// r0 (multiples of the line width) × the scale of δ(j), outer hemispheres at every pixel
/// (docs/reference.md allows `outer = level` as a default only within 0.02 of `full`, and it
/// differs by its noise) and s_h the paper's 32 (it buys less noise, not another picture: s_h
/// 16 against 32 changed no choice in a trial on the built-in scenes and one real bundle). The
/// authors' shader: its base radius, and s_h (its cost: s_h samples on each of its three
/// hemispheres at full resolution).
fn fit(line_width: f32, variant: bool) -> Vec<super::FitCandidate> {
    let c = |label: String, apply: Box<dyn Fn(&mut ChainSettings)>| super::FitCandidate { label, apply };
    if variant {
        let mut reference = Vec::new();
        for s_h in [32, 16] {
            for radius in [2.0f32, 1.0] {
                reference.push(c(
                    format!("base radius {radius} px, s_h {s_h}"),
                    Box::new(move |s: &mut ChainSettings| {
                        s.line_ao.reference_radius_px = radius;
                        s.line_ao.s_h = s_h;
                    }),
                ));
            }
        }
        return reference;
    }
    let paper = (3, 1.5f32, 1.0f32, 32, LineAoOuter::Full);
    let mut grid = Vec::new();
    for s_r in [2, 3, 4] {
        for k in [1.5f32, 3.0, 4.5, 6.0, 8.0] {
            for delta in [1.0f32, 0.3, 0.1] {
                grid.push((s_r, k, delta, 32, LineAoOuter::Full));
            }
        }
    }
    let mut lineao = Vec::new();
    for (s_r, k, delta_scale, s_h, outer) in std::iter::once(paper).chain(grid.into_iter().filter(|&c| c != paper)) {
        let r0 = k * line_width;
        lineao.push(c(
            format!("s_r {s_r}, r0 {r0} px, δ scale {delta_scale}, s_h {s_h}, outer {}", outer.name()),
            Box::new(move |s: &mut ChainSettings| {
                s.line_ao.s_r = s_r;
                s.line_ao.r0_px = Some(r0);
                s.line_ao.delta_scale = delta_scale;
                s.line_ao.s_h = s_h;
                s.line_ao.outer = outer;
            }),
        ));
    }
    lineao
}

pub(crate) const METHOD: super::MethodInfo = super::MethodInfo {
    name: "lineao",
    label: "LineAO",
    help: "LineAO (Eichelbaum et al. 2013): hemispheres of growing radius on a Gaussian pyramid of normals and depth",
    screen_space: true,
    estimates: super::Estimate::Occlusion,
    traces_scene: false,
    spans: &["nd-pyramid", "lineao"],
    library: crate::shader::Library {
        files: &[("line_ao.wgsl", include_str!("line_ao.wgsl"))],
        constants: &[("OUTER_DEPTH_TOLERANCE", crate::shader::Constant::F32(OUTER_DEPTH_TOLERANCE))],
    },
    build: Some(|device, settings| Box::new(LineAoStage::new(device, settings))),
    fits: super::fits_always,
    own: &super::Own {
        validate: settings::validate,
        levels: |s| if s.variant == LineAoVariant::Paper { s.s_r } else { 1 },
        conform: settings::conform,
        ..super::Own::at(settings::SETTINGS, |c| &c.line_ao, |c| &mut c.line_ao, settings::preset)
    },
    bench: &[
        BenchPass::of("lineao", &["lineao"], |_, _| {}),
        BenchPass {
            build: Some(|device, settings| Box::new(LineAoStage::tap_floor(device, settings))),
            ..BenchPass::of("lineao-tap-floor", &["lineao"], |_, _| {})
        },
        BenchPass::of("lineao-chain", &["nd-pyramid", "lineao"], |_, _| {}),
        BenchPass::of("lineao-level", &["lineao"], |s, _| s.line_ao.outer = LineAoOuter::Level),
        BenchPass::of("lineao-chain-level", &["nd-pyramid", "lineao"], |s, _| s.line_ao.outer = LineAoOuter::Level),
    ],
    variant: Some(super::Variant {
        setting: "variant",
        value: "reference",
        main: "paper",
        name: "lineao-reference",
        label: "authors' code",
        help: "LineAO's `reference` variant (the authors' LineVis: radius in zoom units, no pyramid)",
    }),
    fit: Some(fit),
    #[cfg(feature = "reference")]
    reference: Some(reference::of_frame),
};
use crate::targets::{AO_FORMAT, FrameTargets, LevelsUniform, Target};
use crate::timing::Span;

/// Keep in sync with `LineAoUniform` in `line_ao.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LineAoUniform {
    /// The pyramid's levels: their sizes and UV scales.
    pub levels: LevelsUniform,
    /// The visible image's top-left pixel, where R1's tile starts.
    pub noise_origin: [i32; 2],
    /// r0 in pixels.
    pub r0_px: f32,
    /// δ0 in normalized depth.
    pub delta0: f32,
    /// Variant `reference`: radius_px / z_fit · (W, H) / max(W, H).
    pub reference_scale: [f32; 2],
    /// ε: occluded iff Δd > ε.
    pub epsilon: f32,
    /// r0's part per unit of zoom (tubes, Eq. 16): r0(P) = r0_px + r0_zoom · z(P).
    pub r0_zoom: f32,
    /// δ(j) = delta_scale · (1 − j/s_r)².
    pub delta_scale: f32,
    /// Padding to WGSL's 16-byte alignment.
    pub _pad: [f32; 3],
}

/// The `reference` variant's base radius per axis, in pixels per unit of zoom z(P) at d = 0.
pub fn reference_scale(view: &FrameView, radius_px: f32) -> [f32; 2] {
    let (w, h) = view.picture_size();
    let (w, h) = (w.max(1) as f32, h.max(1) as f32);
    let k = radius_px / view.zoom_fit() / w.max(h);
    [k * w, k * h]
}

/// What the shader does with the samples it fetches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Evaluation {
    /// LineAO.
    #[default]
    Occlusion,
    /// The same sample addresses (noise, ω, levels, early exits) that only sum the fetched
    /// depths: the cost of the memory traffic alone, which `lineao bench` reports as
    /// `lineao-tap-floor` so that LineAO's arithmetic can be judged against it.
    TapFloor,
}

/// The compile-time shape of the pass: sample counts and the noise they index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Shape {
    variant: LineAoVariant,
    outer: LineAoOuter,
    s_r: u32,
    s_h: u32,
    noise_seed: u32,
    light_attenuation: bool,
    lighting: LightingShape,
}

impl Shape {
    fn of(settings: &LineAoSettings, lighting: &Lighting) -> Shape {
        Shape {
            variant: settings.variant,
            outer: if settings.variant == LineAoVariant::Paper { settings.outer } else { LineAoOuter::Full },
            s_r: settings.s_r,
            s_h: settings.s_h,
            noise_seed: settings.noise_seed,
            light_attenuation: settings.light_attenuation,
            // Lines' shading is not LineAO's: a change of it keeps the pipeline.
            lighting: LightingShape { line_shading: None, ..LightingShape::of(lighting) },
        }
    }
}

/// R2 as the variant uses it: ⌈s_h/(j+1)⌉ samples on hemisphere j (`paper`), or s_h on each
/// (`reference`); zero-padded to `s_r × s_h`.
pub fn sample_table(settings: &LineAoSettings) -> Vec<[f32; 3]> {
    let (seed, s_r, s_h) = (settings.noise_seed, settings.s_r, settings.s_h);
    match settings.variant {
        LineAoVariant::Paper => noise::sample_table(seed, s_r, s_h, |j| noise::samples_on_hemisphere(s_h, j)),
        LineAoVariant::Reference => noise::sample_table(seed, s_r, s_h, |_| s_h),
    }
}

/// LineAO's compute pass: every hemisphere's samples over the ND pyramid, into the AO target.
pub struct LineAo {
    shape: Shape,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    /// `outer = level`: one pipeline per hemisphere j ≥ 1 (`line_ao_outer`), their layout (the
    /// main one plus the output) and groups, and the targets they write: hemisphere j's
    /// (AO_j, d_j) at level j's size (`outer[j − 1]`), which the main pass reads.
    outer_pipelines: Vec<wgpu::ComputePipeline>,
    outer_layout: wgpu::BindGroupLayout,
    outer_groups: Vec<wgpu::BindGroup>,
    outer: Vec<Target>,
    uniform: wgpu::Buffer,
    lighting: wgpu::Buffer,
    noise: wgpu::Buffer,
    samples: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

/// `outer = level`: (AO_j, d_j) per texel of level j.
pub const OUTER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// Entries of the uniform sample table (`samples` in `line_ao.wgsl`): s_r ≤ 5, s_h ≤ 256.
const SAMPLE_TABLE_LEN: usize = crate::MAX_LEVELS as usize * 256;

impl LineAo {
    /// The pass for `settings` lit by `lighting` (the number of lights is compiled in).
    pub fn new(device: &wgpu::Device, settings: &LineAoSettings, lighting: &Lighting) -> LineAo {
        Self::with_evaluation(device, settings, lighting, Evaluation::Occlusion)
    }

    /// The pass evaluating `evaluation`: the occlusion, or (for the bench's tap floor) only the sum
    /// of the same fetches.
    pub fn with_evaluation(
        device: &wgpu::Device,
        settings: &LineAoSettings,
        lighting: &Lighting,
        evaluation: Evaluation,
    ) -> LineAo {
        // line_ao.wgsl's bindings: 0..=5, the pyramid, then outer1..outer4 and outer_out.
        let mut slots = vec![
            Slot::Uniform,
            Slot::Uniform,
            Slot::Storage,
            Slot::Uniform,
            Slot::Texture,
            Slot::StorageTexture(AO_FORMAT),
        ];
        slots.extend([Slot::Texture; 2 * crate::MAX_LEVELS as usize - 1]);
        let layout = binding::layout(device, "lineao::LineAo::layout", wgpu::ShaderStages::COMPUTE, &slots);
        slots.push(Slot::StorageTexture(OUTER_FORMAT));
        let outer_layout = binding::layout(device, "lineao::LineAo::outer_layout", wgpu::ShaderStages::COMPUTE, &slots);
        let shape = Shape::of(settings, lighting);
        let outer_level = shape.outer == LineAoOuter::Level;
        let mut constants = vec![
            ("S_R", shape.s_r as f64),
            ("S_H", shape.s_h as f64),
            ("TAP_FLOOR", (evaluation == Evaluation::TapFloor) as u32 as f64),
            ("LIGHT_ATTENUATION", shape.light_attenuation as u32 as f64),
            ("REFERENCE", (shape.variant == LineAoVariant::Reference) as u32 as f64),
            ("OUTER_LEVEL", outer_level as u32 as f64),
        ];
        constants.extend(shape.lighting.constants());
        let pipeline = binding::compute_pipeline(
            device,
            "lineao::LineAo::pipeline",
            &layout,
            METHOD.library.source("line_ao.wgsl"),
            "line_ao",
            &constants,
        );
        let outer_pipelines = (1..if outer_level { shape.s_r } else { 1 })
            .map(|j| {
                let mut constants = constants.to_vec();
                constants.push(("LEVEL", j as f64));
                let label = format!("lineao::LineAo::outer[{j}]");
                binding::compute_pipeline(
                    device,
                    &label,
                    &outer_layout,
                    METHOD.library.source("line_ao.wgsl"),
                    "line_ao_outer",
                    &constants,
                )
            })
            .collect();
        LineAo {
            shape,
            pipeline,
            uniform: binding::uniform_buffer::<LineAoUniform>(device, "lineao::LineAo::uniform"),
            lighting: binding::uniform_buffer::<LightingUniform>(device, "lineao::LineAo::lighting"),
            noise: binding::vec4_buffer(
                device,
                "lineao::LineAo::noise",
                &noise::noise_tile(shape.noise_seed),
                0,
                wgpu::BufferUsages::STORAGE,
            ),
            samples: binding::vec4_buffer(
                device,
                "lineao::LineAo::samples",
                &sample_table(settings),
                SAMPLE_TABLE_LEN,
                wgpu::BufferUsages::UNIFORM,
            ),
            layout,
            group: None,
            outer_pipelines,
            outer_layout,
            outer_groups: Vec::new(),
            outer: Vec::new(),
        }
    }

    /// Whether `settings` and `lighting` need a new pipeline or noise (then make a new pass and
    /// `resize` it).
    pub fn matches(&self, settings: &LineAoSettings, lighting: &Lighting) -> bool {
        self.shape == Shape::of(settings, lighting)
    }

    /// Binds `targets` and allocates the `outer = level` targets at their levels' sizes.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let usage =
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC;
        self.outer = (targets.nd.iter().enumerate().skip(1).take(self.outer_pipelines.len()))
            .map(|(j, level)| {
                Target::new(device, &format!("lineao::LineAo::outer[{j}]"), level.size(), OUTER_FORMAT, usage)
            })
            .collect();
        let mut resources = vec![
            self.uniform.as_entire_binding(),
            self.lighting.as_entire_binding(),
            self.noise.as_entire_binding(),
            self.samples.as_entire_binding(),
            wgpu::BindingResource::TextureView(&targets.zoom.view),
            wgpu::BindingResource::TextureView(&targets.ao.view),
        ];
        let levels = targets.level_views();
        resources.extend(levels.iter().map(|v| wgpu::BindingResource::TextureView(v)));
        let common = resources.len();
        // outer1..outer4, padded with the last pyramid level (never read).
        let pad = &targets.nd[targets.nd.len() - 1].view;
        let outer = (1..crate::MAX_LEVELS as usize).map(|j| self.outer.get(j - 1).map_or(pad, |t| &t.view));
        resources.extend(outer.map(wgpu::BindingResource::TextureView));
        self.group = Some(binding::group(device, "lineao::LineAo::group", &self.layout, &resources));
        // Each outer pass writes its level, so it must not also bind it for reading: the
        // pyramid's levels stand in for outer1..outer4 there (line_ao_outer reads none of them).
        resources.truncate(common);
        resources.extend(levels[1..].iter().map(|v| wgpu::BindingResource::TextureView(v)));
        self.outer_groups = (self.outer.iter())
            .map(|target| {
                let mut resources = resources.clone();
                resources.push(wgpu::BindingResource::TextureView(&target.view));
                binding::group(device, "lineao::LineAo::outer_group", &self.outer_layout, &resources)
            })
            .collect();
    }

    /// Writes this frame's uniform, lighting, noise and sample tables.
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        targets: &FrameTargets,
        view: &FrameView,
        settings: &LineAoSettings,
        r0: crate::R0,
        lighting: &Lighting,
    ) {
        debug_assert_eq!(targets.guard, view.guard);
        let uniform = LineAoUniform {
            levels: targets.levels_uniform(),
            noise_origin: view.noise_origin(),
            r0_px: r0.px,
            delta0: settings.delta0,
            reference_scale: reference_scale(view, settings.reference_radius_px),
            epsilon: settings.epsilon,
            r0_zoom: r0.per_zoom,
            delta_scale: settings.delta_scale,
            _pad: [0.0; 3],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        queue.write_buffer(&self.lighting, 0, bytemuck::bytes_of(&lighting.uniform()));
    }

    /// `outer = level`: hemisphere j's (AO_j, d_j) at level j's size (`outer[j − 1]`), empty
    /// for `outer = full`.
    pub fn outer(&self) -> &[Target] {
        &self.outer
    }

    /// Records the pass (with `outer = level` first one pass per outer hemisphere at its level's
    /// size), timed into `span` when given.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets, span: Option<Span>) {
        let Some(group) = &self.group else { return };
        let (first, last) = if self.outer_pipelines.is_empty() { (None, span) } else { Span::split(span) };
        let outer = self.outer_pipelines.iter().zip(&self.outer_groups).zip(&self.outer);
        for (k, ((pipeline, group), target)) in outer.enumerate() {
            let span = first.filter(|_| k == 0);
            dispatch_full_screen(encoder, "lineao::LineAo::outer", pipeline, group, target.size(), span);
        }
        dispatch_full_screen(encoder, "lineao::LineAo", &self.pipeline, group, targets.size, last);
    }
}

/// LineAO's [`crate::method::Stage`]: the Gaussian ND pyramid (when s_r > 1), then the
/// hemispheres (or the authors' variant on level 0).
pub struct LineAoStage {
    pyramid: crate::passes::nd_pyramid::NdPyramid,
    line_ao: LineAo,
}

impl LineAoStage {
    /// LineAO as a stage of the chain, with the ND pyramid it reads.
    pub fn new(device: &wgpu::Device, settings: &ChainSettings) -> LineAoStage {
        LineAoStage {
            pyramid: crate::passes::nd_pyramid::NdPyramid::new(device),
            line_ao: LineAo::new(device, &settings.line_ao, &settings.lighting),
        }
    }

    /// The stage with [`Evaluation::TapFloor`]: what `lineao-tap-floor` times.
    fn tap_floor(device: &wgpu::Device, settings: &ChainSettings) -> LineAoStage {
        let evaluation = Evaluation::TapFloor;
        LineAoStage {
            pyramid: crate::passes::nd_pyramid::NdPyramid::new(device),
            line_ao: LineAo::with_evaluation(device, &settings.line_ao, &settings.lighting, evaluation),
        }
    }

    /// The `outer = level` targets of the last frame ([`LineAo::outer`]).
    pub fn outer(&self) -> &[Target] {
        self.line_ao.outer()
    }
}

impl crate::method::Stage for LineAoStage {
    fn matches(&self, settings: &ChainSettings) -> bool {
        settings.method == crate::AoMethod::LineAo && self.line_ao.matches(&settings.line_ao, &settings.lighting)
    }

    fn reach(&self, settings: &ChainSettings, unguarded: &FrameView) -> crate::method::Reach {
        let ao = &settings.line_ao;
        match ao.variant {
            // Its radius grows as 1/(1 − d), without bound toward the far plane.
            LineAoVariant::Reference => crate::method::Reach::Unbounded,
            // The widest hemisphere reads the deepest level, whose texels near the band's edge
            // are filtered with clamp-to-edge: the band covers that reach too.
            LineAoVariant::Paper => {
                let deepest = ao.s_r - 1;
                let r0 = settings.r0();
                let radius_px = r0.px
                    + (r0.per_zoom + deepest as f32) * unguarded.zoom_max()
                    + crate::camera::pyramid_reach(deepest);
                crate::method::Reach::Pixels { radius_px, levels: ao.s_r }
            }
        }
    }

    fn spans(&self, settings: &ChainSettings) -> &'static [&'static str] {
        if settings.levels() > 1 { &["nd-pyramid", "lineao"] } else { &["lineao"] }
    }

    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        self.pyramid.resize(device, targets);
        self.line_ao.resize(device, targets);
    }

    fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings) {
        self.line_ao.prepare(queue, targets, view, &settings.line_ao, settings.r0(), &settings.lighting);
    }

    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    ) {
        if targets.nd.len() > 1 {
            self.pyramid.encode(encoder, targets, span("nd-pyramid"));
        }
        self.line_ao.encode(encoder, targets, span("lineao"));
    }

    /// docs/reference.md's LineAO keys (each variant's own) and its noise tile and sample table.
    #[cfg(all(feature = "serde", feature = "reference"))]
    fn dump(&self, _: &crate::Gpu, s: &ChainSettings, view: &FrameView) -> Result<crate::method::Dump, crate::Error> {
        use serde_json::json;
        let ao = &s.line_ao;
        let lights: Vec<_> = s
            .lighting
            .normalized()
            .iter()
            .map(|l| json!({"dir": l.dir.to_array(), "intensity": l.intensity}))
            .collect();
        let mut dump = crate::method::Dump::default();
        dump.params(json!({
            "variant": ao.variant.name(),
            "s_r": ao.s_r,
            "s_h": ao.s_h,
            "light_attenuation": ao.light_attenuation,
            "lights": lights,
            "noise_seed": ao.noise_seed,
            "outer": ao.outer.name(),
        }));
        if ao.outer == LineAoOuter::Level {
            dump.params(json!({"outer_depth_tolerance": OUTER_DEPTH_TOLERANCE}));
        }
        dump.params(match ao.variant {
            LineAoVariant::Paper => json!({
                "r0_px": s.r0().px,
                "delta0": ao.delta0,
                "delta_scale": ao.delta_scale,
                "epsilon": ao.epsilon,
                "kd": s.lighting.kd,
                "ks": s.lighting.ks,
                "shininess": s.lighting.shininess,
            }),
            // Our extension of docs/reference.md: what the authors' radius needs.
            LineAoVariant::Reference => json!({
                "reference_radius_px": ao.reference_radius_px,
                "zoom_fit": view.zoom_fit(),
            }),
        });
        let flat = |v: Vec<[f32; 3]>| v.into_iter().flatten().collect();
        dump.array("noise", &[64, 64, 3], flat(noise::noise_tile(ao.noise_seed)));
        dump.array("samples", &[ao.s_r as u64, ao.s_h as u64, 3], flat(sample_table(ao)));
        Ok(dump)
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        LineAoUniform,
        METHOD.library.source("line_ao.wgsl"),
        "LineAoUniform",
        [levels, noise_origin, r0_px, delta0, reference_scale, epsilon, r0_zoom, delta_scale]
    );
}
