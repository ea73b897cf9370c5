//! Object-space ambient occlusion for lines: computed once per dataset over a volume, stable
//! under camera motion, free of screen-space halos — the complement of LineAO.
//!
//! 1. [`density`]: the tractogram voxelized as fractional occupancy (the coverage of each voxel
//!    by the streamlines swept with an occupancy radius).
//! 2. Per vertex, the *visibility of each octant* of directions, V_o ∈ [0, 1], from either
//!    - [`sweep`]: fast occlusion sweeping (Singh, Yuksel, House 2009, Eq. 3–8), eight diagonal
//!      sweeps that propagate visibility voxel to voxel, or
//!    - [`variance`]: variance occlusion maps (filterable occlusion maps, Penner & Mitchell
//!      2008, §3.4, §4): a pyramid of occupancy moments queried with Chebyshev's bound;
//!
//!    and [`monte_carlo`], rays cast through the same grid, the reference both are judged by.
//! 3. At draw time the eight V_o meet the normal through the integrated geometry term of
//!    [`geometry_term`] (Eq. 4–5): visibility = Σ_o w_o V_o G_o(N) / Σ_o G_o(N), ao = 1 − visibility.
//!    Lines have a view-dependent normal, so this happens per pixel
//!    ([`passes::volume_ao`](crate::passes::volume_ao)); [`scalar_visibility`] gives the
//!    view-independent forms (G averaged over the normals around the tangent, or no G at all),
//!    which a renderer stores in all eight channels.
//!
//! Octant `o` (0..8) holds the directions whose signs are [`octant_signs`]`(o)`: bit 0 set means
//! x < 0, bit 1 y < 0, bit 2 z < 0. V_o is the light arriving *from* those directions.
//!
//! A vertex lies on the axis of its own tube of occupancy (radius r), which would hide it from
//! every direction once voxels are finer than r. The surface that sees octant o is the tube's
//! side facing it, so each V_o is read at a [`probe`]: the vertex moved r + h/2 (h the voxel)
//! along the octant's diagonal made perpendicular to the tangent. What remains of the line's
//! own occupancy there is the little self-occlusion a tube has.

#[cfg(feature = "volume")]
mod cpu;
#[cfg(feature = "volume")]
pub mod density;
pub mod geometry_term;
#[cfg(feature = "volume")]
pub mod monte_carlo;
#[cfg(feature = "volume")]
pub mod sweep;
#[cfg(feature = "volume")]
pub mod variance;

#[cfg(feature = "volume")]
use cpu::check_tangents;
#[cfg(feature = "volume")]
pub use cpu::*;

use glam::Vec3;

/// The eight octant visibilities of one vertex, indexed as [`octant_signs`].
pub type OctantVisibility = [f32; 8];

/// Direction signs (±1 per axis) of octant `o`.
pub fn octant_signs(o: usize) -> Vec3 {
    let sign = |bit: usize| if o >> bit & 1 == 1 { -1.0 } else { 1.0 };
    Vec3::new(sign(0), sign(1), sign(2))
}

/// How the eight octant visibilities become one view-independent scalar.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ScalarForm {
    /// Σ_o V_o Ḡ_o(T) / π with Ḡ the geometry term averaged over the normals perpendicular to
    /// the line's tangent T: the view-dependent result averaged over every view.
    #[default]
    AroundTangent,
    /// Σ_o V_o / 8: the geometry term dropped (seed 000 Fig. 6), every octant counts the same.
    NoGeometryTerm,
}

/// Which octants the sky lights (seed 000 §4.1: eight area lights whose intensities may change
/// at draw time).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Sky {
    /// An isotropic sky: every octant at full intensity.
    #[default]
    Uniform,
    /// A cloudy day (seed 000 Fig. 7): only the four octants above, "up" being +z (superior
    /// in RAS+ tractography coordinates).
    Cloudy,
    /// A cloudy day with another "up": the octants whose diagonal points within 90° of it
    /// (four for an axis).
    Above([f32; 3]),
    /// Each octant's intensity in [0, 1], indexed as [`octant_signs`].
    Custom([f32; 8]),
}

impl Sky {
    /// A cloudy day lit from the world axis nearest to a camera's `up` (its sign kept): the
    /// sky that stays put while the camera orbits.
    pub fn above_nearest_axis(up: [f32; 3]) -> Sky {
        // The first of equal components, as glam's `max_position`.
        let axis = (1..3).fold(0, |best, a| if up[a].abs() > up[best].abs() { a } else { best });
        let mut direction = [0.0; 3];
        direction[axis] = if up[axis] < 0.0 { -1.0 } else { 1.0 };
        Sky::Above(direction)
    }

    /// The eight octants' weights.
    pub fn weights(&self) -> [f32; 8] {
        match self {
            Sky::Uniform => [1.0; 8],
            Sky::Cloudy => Sky::Above([0.0, 0.0, 1.0]).weights(),
            Sky::Above(up) => {
                std::array::from_fn(|o| if octant_signs(o).dot(Vec3::from_array(*up)) > 0.0 { 1.0 } else { 0.0 })
            }
            Sky::Custom(w) => *w,
        }
    }
}

/// The object-space method that computes the octant visibilities.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeMethod {
    /// Fast occlusion sweeping ([`sweep`]).
    Sweep,
    /// Variance occlusion maps ([`variance`]).
    VarianceVolume,
}

impl VolumeMethod {
    /// Every method, the default first.
    pub const ALL: [VolumeMethod; 2] = [VolumeMethod::Sweep, VolumeMethod::VarianceVolume];

    /// The CLI and `params.json` name: `sweep` or `variance-volume`.
    pub fn name(self) -> &'static str {
        match self {
            VolumeMethod::Sweep => "sweep",
            VolumeMethod::VarianceVolume => "variance-volume",
        }
    }

    /// The method called `name`.
    pub fn from_name(name: &str) -> Option<VolumeMethod> {
        VolumeMethod::ALL.into_iter().find(|m| m.name() == name)
    }
}
