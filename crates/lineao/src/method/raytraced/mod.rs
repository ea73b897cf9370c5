//! Ray-traced ambient occlusion on the GPU, progressive: the ground truth ([`crate::truth`])
//! converging while one looks, on every wgpu adapter (a compute shader walks the BVH; no
//! ray-tracing hardware needed).
//!
//! Each frame, every geometry pixel traces k = `rays_per_frame` cosine-weighted rays and adds
//! them to its running sum; `ao` is the sum over the rays so far. The rays are the CPU truth's:
//! ray i of a pixel is point i of its scrambled Sobol' sequence (`truth/sequence.rs`), and
//! frame f traces rays f·k .. f·k + k, so after F frames the image *is* the CPU truth with F·k
//! rays (up to f32 against f64 at grazing hits; the tests measure it). The origin, the pixel's
//! own segment, buried origins and both falloffs follow [`crate::truth`] step by step.
//!
//! **Progressive.** The stage remembers what the last frame traced — view, size, the settings
//! the picture depends on, the scene — and starts again from ray 0 when any of it changes. The
//! rays per frame may change between frames (a host adapting them to its frame time): the
//! picture goes on with the next rays of the sequence.
//! After `max_rays` rays a pixel is converged: the pass then only copies the sums into `ao`.
//! [`RayTracedAo::progress`] says how far it is.
//!
//! **Denoiser.** With `RayTracedSettings::denoise` each frame ends with the edge-aware
//! denoiser ([`crate::method::raytraced::denoise`]) writing `ao` from the accumulation.
//!
//! **Scene.** The rays need the geometry itself, not only the G-buffer: a [`RayScene`] uploaded
//! once per geometry ([`crate::AoChain::set_ray_scene`]). Without one there is nothing to hit
//! and `ao` is 0.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use crate::binding::{self, Slot};
use crate::camera::FrameView;
use crate::method::AoMethod;
use crate::passes::dispatch_full_screen;
use crate::ray_scene::RayScene;
use crate::settings::ChainSettings;
use denoise::RayDenoise;

pub mod denoise;
#[cfg(feature = "reference")]
pub(crate) mod reference;
pub(crate) mod settings;
pub(crate) use settings::{RayDenoiseSettings, RayTracedSettings};

use crate::method::BenchPass;

/// The GPU ray tracer in the registry ([`crate::method`]).
pub(crate) const METHOD: super::MethodInfo = super::MethodInfo {
    name: "raytraced",
    label: "ray traced (progressive)",
    help: "Ray-traced AO on the GPU, accumulated while the view rests: the ground truth",
    screen_space: false,
    estimates: super::Estimate::Occlusion,
    traces_scene: true,
    spans: &["raytraced", "ray-denoise"],
    library: crate::shader::Library {
        files: &[("raytraced_ao.wgsl", include_str!("raytraced_ao.wgsl")), denoise::WGSL],
        constants: &[],
    },
    build: Some(|device, _| Box::new(RayTracedAo::new(device))),
    fits,
    own: &super::Own {
        validate: |s, _| RayTracedSettings::validate(s),
        ..super::Own::at(settings::SETTINGS, |c| &c.raytraced, |c| &mut c.raytraced, |_, _, _| 1.0)
    },
    bench: &[
        // One ray per pixel each frame, continuing one picture (started by the first warm-up
        // frame, over the G-buffer).
        BenchPass::of("raytraced-1spp", &["raytraced"], |s, _| one_ray(s)),
        // A new seed each frame: a picture's first frame, which also finds each pixel's own
        // segment and tests its origin for being buried.
        BenchPass::of("raytraced-start-1spp", &["raytraced"], |s, frame| {
            one_ray(s);
            s.raytraced.seed = frame + 1;
        }),
        // The denoiser over a picture of one ray per pixel (its window at full width): after
        // the first frame the tracer only copies the converged sums.
        BenchPass::of("ray-denoise", &["ray-denoise"], |s, _| {
            one_ray(s);
            s.raytraced.max_rays = 1;
            s.raytraced.denoise = Some(RayDenoiseSettings::default());
        }),
    ],
    variant: None,
    fit: None,
    #[cfg(feature = "reference")]
    reference: None,
};

/// The bench's ray tracer: one ray per pixel and frame, no denoiser.
fn one_ray(settings: &mut ChainSettings) {
    settings.raytraced.rays_per_frame = 1;
    settings.raytraced.denoise = None;
}
use crate::targets::{AO_FORMAT, FrameTargets};
use crate::timing::Span;
use crate::truth::{EPSILON_PER_DISTANCE, Falloff};
use crate::view_params::{ViewParams, ViewUniform};

/// Keep in sync with `Trace` in `raytraced_ao.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct TraceUniform {
    view: ViewUniform,
    inv_view: [[f32; 4]; 4],
    view_z: [f32; 4],
    frame_rays: u32,
    first_ray: u32,
    seed: u32,
    distance: f32,
    epsilon: f32,
    line_half: f32,
    tube_radius: f32,
    max_radius: f32,
    guard: u32,
    node_count: u32,
    starts_at: u32,
    streamlines: u32,
    // log2 of the scene textures' widths: nodes, vertices, words, triangles.
    shifts: [u32; 4],
    width: u32,
    height: u32,
    _pad: [u32; 2],
}

/// What a pipeline is specialized for (the shader's `override` constants): llvmpipe runs both
/// sides of every branch of a SIMD group, uniform or not, so code a frame cannot need (triangles
/// in a scene of lines, the first frame's point queries in the frames after it) is compiled out
/// rather than branched around. With the scene in textures ([`crate::ray_scene`]) a one-ray
/// frame became 2.4–2.6× faster on lavapipe.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
struct Variant {
    /// Fixed-width lines (else tubes).
    lines: bool,
    /// The scene has triangles.
    triangles: bool,
    /// The vertices carry tube radii.
    radii: bool,
    /// Linear falloff: the nearest hit (else any hit).
    nearest: bool,
    /// A picture's first frame: find each pixel's own segment and whether it is buried.
    start: bool,
    /// Tube pixels find their own segment too (the denoiser's "same tube"; with `start` and
    /// tubes only).
    tube_own: bool,
}

impl Variant {
    fn constants(&self) -> [(&'static str, f64); 6] {
        let flag = |b: bool| b as u32 as f64;
        [
            ("LINES", flag(self.lines)),
            ("TRIANGLES", flag(self.triangles)),
            ("RADII", flag(self.radii)),
            ("NEAREST", flag(self.nearest)),
            ("START", flag(self.start)),
            ("TUBE_OWN", flag(self.tube_own)),
        ]
    }
}

/// How far the accumulation has come.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayProgress {
    /// Rays per geometry pixel traced into the current picture.
    pub rays_per_pixel: u32,
    /// The cap (`RayTracedSettings::max_rays`).
    pub max_rays: u32,
    /// Rays the last recorded frame traced per pixel (0 once converged).
    pub frame_rays: u32,
}

impl RayProgress {
    /// Whether every pixel has traced all its rays.
    pub fn converged(&self) -> bool {
        self.rays_per_pixel >= self.max_rays
    }
}

/// What the last frame traced: a change of any of it starts the picture again.
#[derive(Clone, Debug, Default, PartialEq)]
struct Key {
    bits: Vec<u32>,
}

impl Key {
    fn of(view: &FrameView, settings: &ChainSettings, scene: Option<&RayScene>, targets: &FrameTargets) -> Key {
        let r = &settings.raytraced;
        let mut bits: Vec<u32> = Vec::with_capacity(48);
        bits.extend(view.view.to_cols_array().map(f32::to_bits));
        bits.extend(view.proj.to_cols_array().map(f32::to_bits));
        bits.extend([view.width, view.height, view.guard, view.near.to_bits(), view.far.to_bits()]);
        bits.extend([targets.size.0, targets.size.1]);
        // Not the rays per frame: ray i of a picture is ray i whatever the frames it came in.
        let reach = r.reach(scene.map_or(0.0, RayScene::longest_side));
        bits.extend([reach.to_bits(), (r.falloff == Falloff::Linear) as u32, r.seed]);
        // With the denoiser tube pixels find their own segment on the first frame.
        bits.push(r.denoise.is_some() as u32);
        bits.push(settings.line_width_px.to_bits());
        bits.push(settings.tubes.as_ref().map_or(0, |t| t.radius_world.to_bits()));
        let generation = scene.map_or(0, |s| s.generation);
        bits.extend([generation as u32, (generation >> 32) as u32]);
        Key { bits }
    }
}

#[derive(Default)]
struct Progress {
    key: Key,
    /// Rays per pixel traced so far (before the frame being prepared).
    traced: u32,
    /// Rays the prepared frame traces.
    frame_rays: u32,
    max_rays: u32,
    /// Whether the prepared frame ends with the denoiser.
    denoise: bool,
    /// Whether a frame was prepared and not yet recorded.
    prepared: bool,
    /// The prepared frame's pipeline.
    pipeline: Option<wgpu::ComputePipeline>,
}

/// Ray-traced AO on the GPU, progressive: a BVH over the scene's rounded cones and triangles,
/// rays accumulated frame by frame while the view rests.
pub struct RayTracedAo {
    device: wgpu::Device,
    layout: wgpu::BindGroupLayout,
    /// The pipelines compiled so far, made when a frame first needs them.
    pipelines: Mutex<HashMap<Variant, wgpu::ComputePipeline>>,
    uniform: wgpu::Buffer,
    scene: Option<Arc<RayScene>>,
    accumulation: Option<wgpu::Buffer>,
    group: Option<wgpu::BindGroup>,
    denoise: RayDenoise,
    progress: Mutex<Progress>,
}

const LABEL: &str = "lineao::RayTracedAo";

/// Bytes of the accumulation per pixel: the sums of the rays' values and of their squares (f32),
/// the own segment, the buried flag (u32). Every geometry pixel of a picture has traced the same
/// rays ([`RayProgress::rays_per_pixel`]): the mean is sum / rays, the standard error
/// √((squares − rays · mean²) / (rays − 1) / rays).
pub const ACCUMULATION_BYTES: u64 = 16;

/// Whether the accumulation for a guard-banded `size` fits the device's storage buffers (the
/// method's entry in the registry's size check).
fn fits(size: (u32, u32), limits: &wgpu::Limits) -> Result<(), crate::Error> {
    let bytes = size.0 as u64 * size.1 as u64 * ACCUMULATION_BYTES;
    super::fits_storage("the ray tracer's accumulation", size, bytes, limits)
}

impl RayTracedAo {
    /// The pass and its denoiser; the scene is given with [`RayTracedAo::set_scene`].
    pub fn new(device: &wgpu::Device) -> RayTracedAo {
        let mut slots = vec![Slot::Uniform, Slot::Texture, Slot::StorageTexture(AO_FORMAT), Slot::StorageReadWrite];
        // The scene: nodes, vertices, words, triangles.
        slots.extend([Slot::UintTextureArray; 4]);
        let layout = binding::layout(device, LABEL, wgpu::ShaderStages::COMPUTE, &slots);
        RayTracedAo {
            device: device.clone(),
            pipelines: Mutex::new(HashMap::new()),
            layout,
            uniform: binding::uniform_buffer::<TraceUniform>(device, LABEL),
            scene: None,
            accumulation: None,
            group: None,
            denoise: RayDenoise::new(device),
            progress: Mutex::new(Progress::default()),
        }
    }

    /// The pipeline for `variant`, compiled on first use.
    fn pipeline(&self, variant: Variant) -> wgpu::ComputePipeline {
        let mut pipelines = self.pipelines.lock().expect("the pipelines lock");
        let pipeline = pipelines.entry(variant).or_insert_with(|| {
            let constants = variant.constants();
            binding::compute_pipeline(
                &self.device,
                LABEL,
                &self.layout,
                METHOD.library.source("raytraced_ao.wgsl"),
                "raytraced_ao",
                &constants,
            )
        });
        pipeline.clone()
    }

    /// Traces against `scene` from now on (and starts again).
    pub fn set_scene(&mut self, scene: Option<Arc<RayScene>>) {
        self.scene = scene;
        self.group = None;
    }

    /// Binds `nd[0]`, `ao`, a new accumulation buffer and the scene.
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        let (w, h) = targets.size;
        let accumulation = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lineao::RayTracedAo::accumulation"),
            size: (w as u64 * h as u64 * ACCUMULATION_BYTES).max(ACCUMULATION_BYTES),
            // Read back for the standard error (`AoChain::stage`) and by the tests.
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        self.group = self.scene.as_ref().map(|scene| {
            let mut resources = vec![
                self.uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&targets.nd[0].view),
                wgpu::BindingResource::TextureView(&targets.ao.view),
                accumulation.as_entire_binding(),
            ];
            resources.extend(scene.textures().map(|t| wgpu::BindingResource::TextureView(&t.view)));
            binding::group(device, LABEL, &self.layout, &resources)
        });
        self.denoise.resize(device, targets, &accumulation);
        self.accumulation = Some(accumulation);
        // A new buffer holds nothing yet.
        self.progress.lock().expect("the progress lock").key = Key::default();
    }

    /// Writes the frame's uniform: the next rays of the same picture, or ray 0 of a new one.
    pub fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings) {
        let r = &settings.raytraced;
        let key = Key::of(view, settings, self.scene.as_deref(), targets);
        let mut progress = self.progress.lock().expect("the progress lock");
        if progress.key != key {
            *progress = Progress { key, ..Progress::default() };
        }
        progress.max_rays = r.max_rays;
        progress.frame_rays = r.rays_per_frame.min(r.max_rays.saturating_sub(progress.traced));
        progress.denoise = r.denoise.is_some();
        progress.prepared = true;
        if let Some(denoise) = &r.denoise {
            let rays = progress.traced + progress.frame_rays;
            self.denoise.prepare(queue, targets, view, denoise, (rays, settings.tubes.is_some()));
        }
        let Some(scene) = &self.scene else { return };
        let regions = scene.regions;
        let (lines, start) = (settings.tubes.is_none(), progress.traced == 0);
        let variant = Variant {
            lines,
            triangles: regions.triangles > 0,
            radii: regions.radii,
            nearest: r.falloff == Falloff::Linear,
            start,
            // Only a first frame of tubes looks for own segments: no second pipeline elsewhere.
            tube_own: start && !lines && r.denoise.is_some(),
        };
        progress.pipeline = Some(self.pipeline(variant));
        let inv_view = view.view.inverse();
        let row = view.view.row(2);
        let tube_radius = settings.tubes.as_ref().map_or(0.0, |t| t.radius_world);
        let uniform = TraceUniform {
            view: ViewParams::of(view).into(),
            inv_view: inv_view.to_cols_array_2d(),
            view_z: row.to_array(),
            frame_rays: progress.frame_rays,
            first_ray: progress.traced,
            seed: r.seed,
            distance: r.reach(scene.longest_side()),
            epsilon: (EPSILON_PER_DISTANCE * r.reach(scene.longest_side()) as f64) as f32,
            line_half: 0.5 * settings.line_width_px / view.f_px,
            tube_radius,
            max_radius: tube_radius.max(scene.max_vertex_radius),
            guard: view.guard,
            node_count: regions.node_count,
            starts_at: regions.starts,
            streamlines: regions.streamlines,
            shifts: scene.textures().map(|t| t.shift),
            width: targets.size.0,
            height: targets.size.1,
            _pad: [0; 2],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Records the frame's rays (or, once converged, only the copy into `ao`), timed into `span`,
    /// and the denoiser when the settings have one, timed into `denoise_span`. One `encode` per
    /// `prepare`: the next `prepare` continues after these rays, and an `encode` without a new
    /// `prepare` records nothing (it would add the same rays again).
    pub fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: Option<Span<'t>>,
        denoise_span: Option<Span<'t>>,
    ) {
        let Some(group) = &self.group else { return };
        let mut progress = self.progress.lock().expect("the progress lock");
        if !std::mem::take(&mut progress.prepared) {
            return;
        }
        let Some(pipeline) = progress.pipeline.take() else { return };
        dispatch_full_screen(encoder, LABEL, &pipeline, group, targets.size, span);
        progress.traced += progress.frame_rays;
        if progress.denoise {
            self.denoise.encode(encoder, targets, denoise_span);
        }
    }

    /// The accumulation ([`ACCUMULATION_BYTES`] per pixel), once sized.
    pub fn accumulation(&self) -> Option<&wgpu::Buffer> {
        self.accumulation.as_ref()
    }

    /// How far the picture has come: rays per pixel so far, after the last recorded frame.
    pub fn progress(&self) -> RayProgress {
        let progress = self.progress.lock().expect("the progress lock");
        RayProgress { rays_per_pixel: progress.traced, max_rays: progress.max_rays, frame_rays: progress.frame_rays }
    }
}

impl crate::method::Stage for RayTracedAo {
    fn matches(&self, settings: &ChainSettings) -> bool {
        settings.method == AoMethod::RayTraced
    }

    /// Rays go through the scene, not the screen: no guard band.
    fn reach(&self, _: &ChainSettings, _: &FrameView) -> crate::method::Reach {
        crate::method::Reach::Pixels { radius_px: 0.0, levels: 1 }
    }

    fn spans(&self, settings: &ChainSettings) -> &'static [&'static str] {
        if settings.raytraced.denoise.is_some() { &["raytraced", "ray-denoise"] } else { &["raytraced"] }
    }

    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        RayTracedAo::resize(self, device, targets);
    }

    fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings) {
        RayTracedAo::prepare(self, queue, targets, view, settings);
    }

    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    ) {
        RayTracedAo::encode(self, encoder, targets, span("raytraced"), span("ray-denoise"));
    }
}

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        TraceUniform,
        METHOD.library.source("raytraced_ao.wgsl"),
        "Trace",
        [
            view,
            inv_view,
            view_z,
            frame_rays,
            first_ray,
            seed,
            distance,
            epsilon,
            line_half,
            tube_radius,
            max_radius,
            guard,
            node_count,
            starts_at,
            streamlines,
            shifts,
            width,
            height
        ]
    );
}
