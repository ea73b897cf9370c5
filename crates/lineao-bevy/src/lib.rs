//! # lineao-bevy — LineAO, VO and Crytek SSAO in Bevy 0.20
//!
//! lineao's passes inside Bevy's render graph: a [`LineAo`] camera component darkens what Bevy
//! draws by the ambient occlusion lineao computes from Bevy's own depth and normal prepass, and
//! [`Polylines`] are drawn by lineao's line renderer into Bevy's frame, with the fixed screen
//! width, exact normal/depth and zoom maps and the line occlusion of the LineAO paper.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use lineao_bevy::{LineAo, LineAoPlugin};
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, LineAoPlugin))
//!     .add_systems(Startup, |mut commands: Commands| {
//!         // `LineAo` adds the depth and normal prepass it reads.
//!         commands.spawn((Camera3d::default(), Msaa::Off, LineAo::default()));
//!     })
//!     .run();
//! ```
//!
//! ## Where it runs in the frame
//!
//! Per camera, in the `Core3d` schedule **after the main pass and before post-processing**
//! (tonemapping, bloom): lineao's chain derives its G-buffer from the prepass
//! ([`lineao::HostAo`]: Bevy's depth is `Depth32Float` with reversed Z and an infinite far
//! plane, its normals world-space unit vectors packed into `Rgb10a2Unorm` as n · 0.5 + 0.5),
//! runs the camera's method and blur, and composites colour · (1 − strength · AO) from the main
//! texture into the other one of Bevy's post-process pair (no copy). Then the polylines are
//! drawn over that picture ([`lineao::OverlayAo`]), tested against and writing Bevy's depth.
//!
//! Bevy's own SSAO runs between the prepass and the main pass and feeds PBR's indirect diffuse
//! term through resources that are private to `bevy_pbr`; a plugin cannot put its AO there.
//! Compositing after the main pass darkens direct light too — as lineao does everywhere, and as
//! the LineAO paper composites lines — and works for unlit materials and HDR and LDR targets
//! alike (the composite writes the main texture's format, linear values before tonemapping).
//!
//! ## Limits, each a warning and never a panic
//! - An adapter without what lineao needs ([`lineao::check_adapter`]): the plugin warns once and
//!   adds nothing.
//! - A camera without [`DepthPrepass`](bevy::core_pipeline::prepass::DepthPrepass) (removed after
//!   `LineAo` required it): a warning naming it, the frame without AO.
//! - MSAA: the AO reads the multisampled depth and reconstructs the normals from it (Bevy's
//!   normal prepass is multisampled then, lineao reads one sample); polylines need
//!   `Msaa::Off` (they are written into the single-sample main texture and depth) and are
//!   skipped with a warning otherwise.
//! - Invalid settings: lineao's error is logged once per camera and that camera's effect is
//!   off until the settings change.
//! - A camera with a [`Viewport`](bevy::camera::Viewport): not supported yet (the prepass covers
//!   the whole target); warned, no AO.
//! - A 0 × 0 target (a minimised window): nothing is recorded.

// Systems name their data in their queries' types, as Bevy's own code and templates do.
#![allow(clippy::type_complexity)]

mod polylines;
mod render;

use bevy::core_pipeline::prepass::{DepthPrepass, NormalPrepass};
use bevy::prelude::*;
use lineao::{AoMethod, Bounds, ChainSettings, Preset};

pub use lineao;
#[cfg(feature = "tracts")]
pub use polylines::ColorSource;
pub use polylines::{PolylineSelection, Polylines};
pub use render::{LineAoSystems, LineAoViews, ViewAo};

// The README's code compiles as it stands: `cargo test --doc` checks it.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// Adds lineao's passes to every 3D camera that has a [`LineAo`], and draws [`Polylines`].
pub struct LineAoPlugin;

impl Plugin for LineAoPlugin {
    fn build(&self, app: &mut App) {
        render::build(app);
    }

    fn finish(&self, app: &mut App) {
        render::finish(app);
    }
}

/// Ambient occlusion for a 3D camera, by lineao: LineAO (Eichelbaum et al. 2013), Volumetric
/// Obscurance, Crytek SSAO or the GPU ray tracer, over what Bevy draws and over [`Polylines`].
///
/// Requires [`LineAoPlugin`]; adds [`DepthPrepass`] and [`NormalPrepass`] to the camera. Like
/// Bevy's `ScreenSpaceAmbientOcclusion` it works on what the camera sees (screen space), so it
/// costs the same for any scene size; unlike it, it darkens the final colour (direct light too),
/// after the main pass.
///
/// Lengths are in world units (metres in most Bevy scenes) unless a field says pixels; every
/// field of the two settings is documented in [`ChainSettings`], and
/// [`ChainSettings::validate`] says what is out of range.
#[derive(Component, Clone, Debug, PartialEq)]
#[require(DepthPrepass, NormalPrepass)]
pub struct LineAo {
    /// What darkens Bevy's meshes (the prepass): the method (`settings.method`) and its
    /// settings. Default: [`ChainSettings::for_meshes`] of a 5 m scene — Volumetric Obscurance
    /// with line samples reaching 0.5 m (Bevy's SSAO reaches 0.73 m), strength 1.75, the normal
    /// clamp and the bilateral blur: the mesh settings lineao chose against the ray-traced truth
    /// (open ground stays at ≈ 0, contacts darken as the truth says).
    pub settings: ChainSettings,
    /// How [`Polylines`] are drawn and darken each other: line width in pixels
    /// (`line_width_px`), colouring (`line_color`), lighting, method. Default:
    /// [`ChainSettings::default`], lineao's calibrated LineAO for tractograms.
    pub lines: ChainSettings,
    /// The sphere that holds the scene, world units: it sets the normalized depth range of
    /// lineao's G-buffer. `None` (the default): each frame, the union of the visible meshes'
    /// bounding boxes (for the meshes' AO) and of the polylines (for theirs).
    pub bounds: Option<Bounds>,
}

impl Default for LineAo {
    fn default() -> Self {
        LineAo { settings: ChainSettings::for_meshes(5.0), lines: ChainSettings::default(), bounds: None }
    }
}

impl LineAo {
    /// The default with `method` for both the meshes and the polylines ([`LineAo::set_method`]).
    pub fn with_method(method: AoMethod) -> LineAo {
        let mut ao = LineAo::default();
        ao.set_method(method);
        ao
    }

    /// Switches the meshes' and the polylines' method; the chains are rebuilt at the next frame.
    /// The polylines get the method's strength and reach of lineao's default preset, as
    /// `lineao render --method` and the viewer do ([`ChainSettings::with_preset`]); the meshes
    /// keep their world-unit reach and strength (the presets are made for lines).
    pub fn set_method(&mut self, method: AoMethod) {
        self.settings.method = method;
        self.lines = ChainSettings { method, ..self.lines.clone() }.with_preset(Preset::default());
    }
}
