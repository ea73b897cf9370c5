//! The ground truth: ambient occlusion ray traced on the geometry the frame shows.
//!
//! Screen-space methods *estimate* ambient occlusion from a G-buffer; this module computes what
//! they estimate, on the CPU, so that [`metrics`] can say how far each one is from it
//! (`lineao score`) and defaults can be calibrated by that measure.
//!
//! **The geometry is the frame's.** Tubes are their rounded cones (per-vertex radii), surfaces
//! their triangles, and a fixed-width line is what the LineAO paper calls its "supposed
//! volume": each segment a sphere-swept segment whose world radius at a vertex is the line's
//! half-width on screen there, r_v = (w/2) · zoom_unit / z(v) = (w/2) · (−z_view(v)) / f_px
//! (orthographic: (w/2) / f_px). Seen from the camera, that volume covers exactly the pixels
//! the line covers ([`line_cones`]).
//!
//! **Where the rays start.** A pixel's world position comes from its ND depth and the camera.
//! - A tube or surface pixel lies on the surface: its rays start at p + ε n.
//! - A line pixel's depth is its centre line's (the ribbon faces the camera at that depth), so
//!   p lies *inside* its own sphere-swept segment. Its own segment is the one holding p most
//!   deeply (the least signed distance; ties between two lines go to the nearer axis). Its rays
//!   start on that segment's surface where the normal is the pixel's normal: at the nearest
//!   axis point c plus r(c) n (the line normal is perpendicular to the axis; on a tapered cone
//!   this is on the surface up to its half-angle, (r_b − r_a)/L, which is below 1e-3 here),
//!   plus ε n. The segment itself never occludes its own surface, nor do its neighbours on the
//!   same streamline (segments k ± 1, and any further ones still holding c at a tight bend).
//! - An origin that still lies inside *another* primitive — a line crossing through this one,
//!   mostly near line ends where volumes overlap — is **buried**: every ray from it is blocked,
//!   so its AO is 1 with no error. [`Truth::buried`] counts these pixels; `score` reports
//!   their share.
//!
//! ε = [`EPSILON_PER_DISTANCE`] · R (2 µm at R = 2 mm): above the f32 error of a reconstructed
//! position (about 1e-7 of the depth range) and far below every feature that occludes.
//!
//! **What is estimated.** N cosine-weighted rays over the normal's hemisphere
//! (`sequence.rs`: stratified, scrambled per pixel, deterministic for a seed), each up to world
//! distance R:
//! - [`Falloff::None`]: binary AO, the fraction of rays that hit within R;
//! - [`Falloff::Linear`]: obscurance, the mean of 1 − t/R over hits.
//!
//! and, for Volumetric Obscurance, its own quantity: the occupied fraction of the ball of radius
//! R around the surface point — all of it ([`VoBall::Whole`]) or the half above the tangent
//! plane ([`VoBall::Half`], VO's normal clamp). A point is occupied inside a cone, or inside a
//! closed surface (an odd number of triangle crossings along +x). Each pixel also gets the
//! standard error of its AO, s/√N with s the sample standard deviation of the N ray values (the
//! i.i.d. estimate; the stratified sequence does better, so it is an upper bound in practice).
//!
//! The work is split by rows over all cores; a progress callback sees each finished row and a
//! flag stops it between rows.

// The GPU ray tracer's scene is built from the BVH and primitives; walking them is the CPU
// truth's, compiled but unused without it.
#[cfg_attr(not(feature = "truth"), allow(dead_code))]
pub(crate) mod bvh;
#[cfg(feature = "truth")]
mod cpu;
#[cfg(feature = "truth")]
pub mod legibility;
#[cfg(feature = "truth")]
pub mod metrics;
#[cfg_attr(not(feature = "truth"), allow(dead_code))]
pub(crate) mod primitive;
// The rays' sequence on the CPU (the GPU tracer's WGSL has its own; the tests compare the
// two tracers' pictures ray for ray).
#[cfg(feature = "truth")]
pub(crate) mod sequence;

use crate::Error;
use crate::named::Named;
#[cfg(feature = "truth")]
pub use bvh::{Bvh, Prim};
#[cfg(feature = "truth")]
pub use cpu::*;
#[cfg(feature = "truth")]
pub use primitive::{RoundedCone, Triangle};

/// ε, the rays' offset along the normal, as a share of the distance R.
pub const EPSILON_PER_DISTANCE: f64 = 1e-3;

/// How a hit counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Falloff {
    /// Binary AO: a hit within R counts 1.
    #[default]
    None,
    /// Obscurance: a hit at t counts 1 − t/R.
    Linear,
}

impl Falloff {
    /// Every falloff, the default first.
    pub const ALL: [Falloff; 2] = [Falloff::None, Falloff::Linear];

    /// The name on the command line and in `params.json` (`none`, `linear`).
    pub fn name(self) -> &'static str {
        match self {
            Falloff::None => "none",
            Falloff::Linear => "linear",
        }
    }

    /// The falloff called `name`.
    pub fn from_name(name: &str) -> Option<Falloff> {
        Falloff::ALL.into_iter().find(|f| f.name() == name)
    }
}

crate::named::named!(Falloff {
    None => "Binary AO: the fraction of rays that hit within the distance",
    Linear => "Obscurance: the mean of 1 − t/R over hits",
});

/// Which ball the VO truth measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VoBall {
    /// The whole ball (VO without the normal clamp).
    Whole,
    /// The half above the tangent plane (VO's normal clamp, its default).
    Half,
}

/// What the truth computes.
#[derive(Clone, Debug, PartialEq)]
pub struct TruthSettings {
    /// Rays per geometry pixel, N ≥ 1.
    pub rays: u32,
    /// The rays' reach R in world units (> 0, finite).
    pub distance_world: f32,
    /// Binary AO or obscurance with a linear falloff.
    pub falloff: Falloff,
    /// Seed of the per-pixel scramble.
    pub seed: u32,
    /// Also the VO truth over this ball (N points per pixel).
    pub vo: Option<VoBall>,
    /// Also a second estimate from the same rays, to another reach with its own falloff
    /// ([`Truth::second`]): each ray is traced to the larger reach once, and both values come
    /// from its first hit. What `lineao score` traces its local and bundle-scale truths with.
    pub second: Option<Reach>,
    /// Worker threads; 0 = one per core.
    pub threads: usize,
}

impl Default for TruthSettings {
    /// 256 rays (LineVis's reference count) to R = 2 world units: the reach VO and SSAO sample by
    /// default and that of LineAO's widest hemisphere on the built-in scenes (r0 + 2 z(P) px),
    /// so the truth measures what the methods claim to see.
    fn default() -> Self {
        TruthSettings {
            rays: 256,
            distance_world: 2.0,
            falloff: Falloff::None,
            seed: 1,
            vo: None,
            second: None,
            threads: 0,
        }
    }
}

/// How far a ray looks and how its hit counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reach {
    /// R in world units (> 0, finite).
    pub distance_world: f32,
    /// Binary AO or obscurance with a linear falloff.
    pub falloff: Falloff,
}

impl TruthSettings {
    /// Its ranges, as [`Error::OutOfRange`].
    pub fn validate(&self) -> Result<(), Error> {
        if self.rays == 0 {
            return Err(Error::out_of_range("rays", self.rays, "≥ 1"));
        }
        if let Some(second) = self.second
            && !(second.distance_world.is_finite() && second.distance_world > 0.0)
        {
            return Err(Error::out_of_range("bundle-distance", second.distance_world, "> 0 world units"));
        }
        if !(self.distance_world.is_finite() && self.distance_world > 0.0) {
            return Err(Error::out_of_range("ao-distance", self.distance_world, "> 0 world units"));
        }
        Ok(())
    }
}
