//! The chain's built stages ([`crate::method::Stage`]): the active method's and a few for
//! settings the caller may come back to (the viewer's method list, `--compare`), so switching
//! back costs no pipeline compilation.

use std::sync::Arc;

use crate::method::Stage;
use crate::method::raytraced::RayTracedAo;
use crate::ray_scene::RayScene;
use crate::settings::{AoMethod, ChainSettings};
use crate::targets::FrameTargets;

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
        let scene = self.scene.clone();
        if let Some(tracer) = self.ray_tracer_mut() {
            tracer.set_scene(scene);
        }
        if let (Some(stage), Some(targets)) = (&mut self.active, targets) {
            stage.resize(device, targets);
        }
    }

    /// Gives `scene` to the active stage (binding `targets` again) and to each one activated later.
    pub fn set_scene(&mut self, device: &wgpu::Device, scene: Option<Arc<RayScene>>, targets: Option<&FrameTargets>) {
        if same(&self.scene, &scene) {
            return;
        }
        self.scene = scene.clone();
        if let Some(tracer) = self.ray_tracer_mut() {
            tracer.set_scene(scene);
            if let Some(targets) = targets {
                tracer.resize(device, targets);
            }
        }
    }

    /// The active stage if it is the ray tracer: the one stage that takes the scene.
    fn ray_tracer_mut(&mut self) -> Option<&mut RayTracedAo> {
        let stage: &mut dyn std::any::Any = self.active.as_deref_mut()?;
        stage.downcast_mut()
    }

    /// Binds newly allocated targets to the active stage (kept ones are bound when selected).
    pub fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets) {
        if let Some(stage) = &mut self.active {
            stage.resize(device, targets);
        }
    }
}

/// Whether `a` and `b` are the same shared value (or both none): setting it again changes nothing.
pub(crate) fn same<T>(a: &Option<Arc<T>>, b: &Option<Arc<T>>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => Arc::ptr_eq(a, b),
        (a, b) => a.is_none() && b.is_none(),
    }
}
