//! One shape for every screen-space method: a [`Stage`] reads the G-buffer in
//! [`FrameTargets`] and writes `ao`, between the geometry and the composite.
//!
//! A stage knows its own pipelines ([`Stage::matches`] says whether they still compute the
//! settings), how far on screen it reads ([`Stage::reach`], which sizes the guard band), the
//! timing spans it records, and its bind, prepare and encode. The chain builds only the active
//! method's stage ([`build`]), keeps a few built ones for settings it may come back to, and
//! never branches on the method itself.
//!
//! Why a trait object and not an enum of stage types: a stage is called a handful of times per
//! frame (not per pixel), so dynamic dispatch costs nothing measurable, and a new method then
//! touches its own module, its WGSL file and the one `match` in [`build`] — the chain, the
//! guard band and the timings follow from the trait.

use std::sync::Arc;

use crate::camera::FrameView;
use crate::passes::raytraced_ao::RayProgress;
use crate::ray_scene::RayScene;
use crate::settings::{AoMethod, ChainSettings};
use crate::targets::FrameTargets;
use crate::timing::Span;

/// How far from a pixel a stage reads, for the guard band (CONTRACT.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reach {
    /// At most `radius_px` pixels (before any blur), on a pyramid of `levels` levels (the band
    /// is rounded to the deepest level's texel).
    Pixels { radius_px: f32, levels: u32 },
    /// Without bound (it grows toward the far plane): the largest band allowed.
    Unbounded,
}

/// What a method does in the chain. The timing span names are CONTRACT.md's.
pub trait Stage: wgpu::WasmNotSendSync {
    /// Whether this stage, as built, computes `settings`' method (else the chain builds another).
    fn matches(&self, settings: &ChainSettings) -> bool;
    /// How far it reads for a frame seen as `unguarded` (the frame's size, no guard band).
    fn reach(&self, settings: &ChainSettings, unguarded: &FrameView) -> Reach;
    /// The spans it records, in order, under `settings`.
    fn spans(&self, settings: &ChainSettings) -> &'static [&'static str];
    /// Binds newly allocated targets.
    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets);
    /// Takes the geometry itself, for a stage that traces it (the ray-traced method); `targets`
    /// are bound again when given. Others ignore it.
    fn set_scene(&mut self, _device: &wgpu::Device, _scene: Option<&Arc<RayScene>>, _targets: Option<&FrameTargets>) {}
    /// How far a progressive stage's picture has come; `None` for the others.
    fn progress(&self) -> Option<RayProgress> {
        None
    }
    /// A progressive stage's per-pixel accumulation (`COPY_SRC`); `None` for the others.
    fn accumulation(&self) -> Option<&wgpu::Buffer> {
        None
    }
    /// Writes the frame's uniforms.
    fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings);
    /// Records the stage; `span(name)` times one of [`Stage::spans`].
    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    );
}

/// The targets a method's stage writes besides the G-buffer, its pyramid and `ao`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Needs {
    /// `ao_raw`: an occlusion before the stage's own blur (SSAO).
    pub ao_raw: bool,
    /// The moments pyramid of VO area sampling.
    pub moments: bool,
    /// LineAO's `outer = level` targets.
    pub outer: bool,
}

/// What `settings`' method needs allocated ([`Needs`]): the second entry of the list a new
/// method adds to.
pub fn needs(settings: &ChainSettings) -> Needs {
    use crate::settings::{LineAoOuter, LineAoVariant};
    let ao = &settings.line_ao;
    match settings.method {
        AoMethod::LineAo => Needs {
            outer: ao.variant == LineAoVariant::Paper && ao.outer == LineAoOuter::Level && ao.s_r > 1,
            ..Needs::default()
        },
        AoMethod::Ssao => Needs { ao_raw: true, ..Needs::default() },
        AoMethod::VoArea => Needs { moments: true, ..Needs::default() },
        AoMethod::VoLine | AoMethod::None | AoMethod::RayTraced => Needs::default(),
    }
}

/// The stage of `settings`' method; `None` for `None`. The list of methods: adding one is one
/// arm here.
pub fn build(device: &wgpu::Device, settings: &ChainSettings) -> Option<Box<dyn Stage>> {
    use crate::passes::{line_ao, raytraced_ao, ssao, vo_area, vo_line};
    Some(match settings.method {
        AoMethod::LineAo => Box::new(line_ao::LineAoStage::new(device, settings)),
        AoMethod::Ssao => Box::new(ssao::SsaoStage::new(device, settings)),
        AoMethod::VoLine => Box::new(vo_line::VoLine::new(device, &settings.vo)),
        AoMethod::VoArea => Box::new(vo_area::VoArea::new(device, &settings.vo)),
        AoMethod::RayTraced => Box::new(raytraced_ao::RayTracedAo::new(device)),
        AoMethod::None => return None,
    })
}

/// The built stages: the active one and a few for settings the caller may come back to (the
/// viewer's method list, `--compare`), so switching back costs no pipeline compilation.
#[derive(Default)]
pub struct Stages {
    active: Option<Box<dyn Stage>>,
    /// Least recently used first.
    kept: Vec<Box<dyn Stage>>,
    /// The geometry for stages that trace it, given to each that becomes active.
    scene: Option<Arc<RayScene>>,
}

/// Built stages kept besides the active one.
const KEPT: usize = 3;

impl Stages {
    /// The active stage, if the method has one.
    pub fn active(&self) -> Option<&dyn Stage> {
        self.active.as_deref()
    }

    /// Makes `settings`' stage the active one: the current one if it matches, else a kept one,
    /// else a new one from `build`. Binds `targets` to a stage that becomes active.
    pub fn select(
        &mut self,
        settings: &ChainSettings,
        targets: Option<&FrameTargets>,
        device: &wgpu::Device,
        build: impl FnOnce() -> Option<Box<dyn Stage>>,
    ) {
        let wanted = |stage: &dyn Stage| stage.matches(settings);
        let unchanged = match &self.active {
            Some(stage) => wanted(stage.as_ref()),
            None => settings.method == AoMethod::None,
        };
        if unchanged {
            return;
        }
        let next = match self.kept.iter().position(|s| wanted(s.as_ref())) {
            Some(i) => Some(self.kept.remove(i)),
            None => build(),
        };
        if let Some(previous) = std::mem::replace(&mut self.active, next) {
            self.kept.push(previous);
            if self.kept.len() > KEPT {
                self.kept.remove(0);
            }
        }
        if let Some(stage) = &mut self.active {
            stage.set_scene(device, self.scene.as_ref(), None);
            if let Some(targets) = targets {
                stage.resize(device, targets);
            }
        }
    }

    /// Gives `scene` to the active stage (binding `targets` again) and to each one activated later.
    pub fn set_scene(&mut self, device: &wgpu::Device, scene: Option<Arc<RayScene>>, targets: Option<&FrameTargets>) {
        self.scene = scene;
        if let Some(stage) = &mut self.active {
            stage.set_scene(device, self.scene.as_ref(), targets);
        }
    }

    /// Binds newly allocated targets to the active stage (kept ones are bound when selected).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        if let Some(stage) = &mut self.active {
            stage.resize(device, targets);
        }
    }
}
