//! Built-in synthetic scenes: deterministic by seed, scalable to a requested vertex count, each
//! with a camera that frames it well.
//!
//! - `bundles`: nine curved, crossing fibre bundles of a human brain's size in RAS+ mm (corpus
//!   callosum, corticospinal tracts, arcuate fasciculi, cingula, fronto-occipital fasciculi),
//!   streamlines sampled every millimetre — thousands of streamlines at the default size.
//! - `spiral`: a dense helical bundle with more distant straight bundles behind and beside it,
//!   like the LineAO paper's Fig. 3 (where the depth falloff δ(l) matters).
//! - `vortex`: streamlines of a flow around a pair of counter-rotating, gently bent vortex tubes
//!   with an axial jet, integrated with RK4.
//! - `wholebrain`: a whole-brain tractogram of any size (association, projection and
//!   commissural bundles and U-fibres in two hemispheres, 20–200 mm at 1 mm steps), made
//!   streamline by streamline ([`wholebrain`]).

pub mod wholebrain;

use glam::Vec3;
use rand_core::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::Tractogram;

/// A camera suggestion in world units: a look-at and a vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewHint {
    /// The eye, world units.
    pub eye: [f32; 3],
    /// The point looked at.
    pub target: [f32; 3],
    /// The camera's up vector.
    pub up: [f32; 3],
    /// The vertical field of view in degrees.
    pub fov_y_deg: f32,
    /// World units per zoom unit (LineAO's z(P)); 1 = 1 mm.
    pub zoom_unit: f32,
}

/// A built-in scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Which scene it is.
    pub kind: SceneKind,
    /// Its streamlines.
    pub tractogram: Tractogram,
    /// The camera it is best seen from.
    pub view: ViewHint,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
/// The built-in scenes (`--scene`).
pub enum SceneKind {
    /// Dense bundles of parallel fibres crossing each other, like tractography.
    Bundles,
    /// A bundle wound along a helix.
    Spiral,
    /// Streamlines of two counter-rotating vortex tubes.
    Vortex,
    /// A synthetic whole brain of any size (`--vertices`), made as it streams.
    WholeBrain,
}

impl SceneKind {
    /// Every scene, in the order the help lists them.
    pub const ALL: [SceneKind; 4] = [SceneKind::Bundles, SceneKind::Spiral, SceneKind::Vortex, SceneKind::WholeBrain];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Bundles => "bundles",
            SceneKind::Spiral => "spiral",
            SceneKind::Vortex => "vortex",
            SceneKind::WholeBrain => "wholebrain",
        }
    }

    /// The vertex count of the scene when none is requested.
    pub fn default_vertices(self) -> usize {
        match self {
            SceneKind::WholeBrain => 1_000_000,
            _ => 400_000,
        }
    }

    /// Builds the scene with about `vertices` vertices (at least a few streamlines).
    pub fn build(self, seed: u64, vertices: usize) -> Scene {
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x6c69_6e65_616f);
        let (tractogram, view) = match self {
            SceneKind::Bundles => bundles(&mut rng, vertices),
            SceneKind::Spiral => spiral(&mut rng, vertices),
            SceneKind::Vortex => vortex(&mut rng, vertices),
            SceneKind::WholeBrain => {
                let brain = wholebrain::WholeBrain::new(seed, vertices as u64);
                let tractogram = brain.tractogram(0..brain.streamlines());
                let view = ViewHint::for_tractogram(&tractogram);
                (tractogram, view)
            }
        };
        Scene { kind: self, tractogram, view }
    }
}

impl std::str::FromStr for SceneKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        SceneKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("unknown scene '{s}' (expected one of: bundles, spiral, vortex, wholebrain)"))
    }
}

fn uniform(rng: &mut Pcg64Mcg) -> f32 {
    (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
}

/// A uniform point in the unit disk.
fn disk(rng: &mut Pcg64Mcg) -> (f32, f32) {
    let r = uniform(rng).sqrt();
    let phi = std::f32::consts::TAU * uniform(rng);
    (r * phi.cos(), r * phi.sin())
}

/// A bundle around `centre(t)`, t ∈ [0, 1]: each streamline keeps a random position in the
/// cross-section (scaled by `width(t)` along two axes of a frame that follows the curve), wanders
/// slowly, and starts and ends a little apart from its neighbours.
struct Bundle<'a> {
    centre: &'a dyn Fn(f32) -> Vec3,
    /// Half-widths of the cross-section along the frame's two axes, by t.
    width: &'a dyn Fn(f32) -> (f32, f32),
    /// A direction not parallel to the curve, to build the frame.
    reference: Vec3,
    /// Share of the scene's vertices.
    share: f32,
}

const STEP_MM: f32 = 1.0;

impl Bundle<'_> {
    fn length(&self) -> f32 {
        (0..64).map(|k| (self.centre)((k + 1) as f32 / 64.0).distance((self.centre)(k as f32 / 64.0))).sum()
    }

    fn frame(&self, t: f32) -> (Vec3, Vec3) {
        let dt = 1e-3;
        let tangent = ((self.centre)((t + dt).min(1.0)) - (self.centre)((t - dt).max(0.0))).normalize_or(Vec3::X);
        let a = tangent.cross(self.reference).normalize_or(tangent.any_orthonormal_vector());
        (a, tangent.cross(a))
    }

    fn add_to(&self, rng: &mut Pcg64Mcg, tractogram: &mut Tractogram, vertices: usize) {
        let length = self.length();
        let per_line = (length / STEP_MM).max(2.0);
        // Trimming the ends keeps 92 % of the curve on average.
        let lines = ((vertices as f32 * self.share / (0.92 * per_line)).ceil() as usize).max(8);
        for _ in 0..lines {
            let (u, v) = disk(rng);
            let (wu, wv) = (uniform(rng) * std::f32::consts::TAU, uniform(rng) * std::f32::consts::TAU);
            let t0 = 0.08 * uniform(rng);
            let t1 = 1.0 - 0.08 * uniform(rng);
            let steps = ((t1 - t0) * per_line) as usize;
            tractogram.push((0..=steps).map(|k| {
                let t = t0 + (t1 - t0) * k as f32 / steps as f32;
                let (a, b) = self.frame(t);
                let (hu, hv) = (self.width)(t);
                // A slow wander of up to 12 % of the half-width keeps lines from being parallel.
                let du = u + 0.12 * (wu + 9.0 * t).sin();
                let dv = v + 0.12 * (wv + 7.0 * t).cos();
                ((self.centre)(t) + a * (du * hu) + b * (dv * hv)).to_array()
            }));
        }
    }
}

/// Camera looking at the tractogram's bounding sphere from direction `from`, filling the frame.
/// Non-finite points are ignored.
fn framed(tractogram: &Tractogram, from: Vec3, up: Vec3, fov_y_deg: f32) -> ViewHint {
    let centre = tractogram.bounds().map_or(Vec3::ZERO, |b| (Vec3::from_array(b.min) + Vec3::from_array(b.max)) * 0.5);
    let radius = tractogram
        .positions
        .iter()
        .map(|p| Vec3::from_array(*p).distance(centre))
        .filter(|d| d.is_finite())
        .fold(1.0f32, f32::max);
    framing(centre, radius, from, up, fov_y_deg)
}

/// Camera looking at the sphere (`centre`, `radius` ≥ 1) from direction `from`, filling the frame.
fn framing(centre: Vec3, radius: f32, from: Vec3, up: Vec3, fov_y_deg: f32) -> ViewHint {
    let radius = radius.max(1.0);
    let distance = 0.9 * radius / (fov_y_deg.to_radians() * 0.5).tan();
    ViewHint {
        eye: (centre + from.normalize() * distance).to_array(),
        target: centre.to_array(),
        up: up.to_array(),
        fov_y_deg,
        zoom_unit: 1.0,
    }
}

/// Where a tractogram is seen from: the left, a little anterior and superior.
const TRACTOGRAM_VIEW: Vec3 = Vec3::new(-1.0, 0.35, 0.3);

impl ViewHint {
    /// The default view of a loaded tractogram in RAS+ mm: from the left, a little anterior and
    /// superior (most association bundles run anterior–posterior and show best sagittally),
    /// superior up, 1 mm per zoom unit.
    pub fn for_tractogram(tractogram: &Tractogram) -> ViewHint {
        framed(tractogram, TRACTOGRAM_VIEW, Vec3::Z, 35.0)
    }

    /// [`ViewHint::for_tractogram`] of streamlines whose bounding sphere (around their box's
    /// centre) is `centre`, `radius`: for one streamed in, whose points are not kept.
    pub fn for_sphere(centre: [f32; 3], radius: f32) -> ViewHint {
        framing(Vec3::from_array(centre), radius, TRACTOGRAM_VIEW, Vec3::Z, 35.0)
    }
}

fn lerp3(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    a + (b - a) * t
}

/// Quadratic Bézier through control points.
fn bezier(p0: Vec3, p1: Vec3, p2: Vec3, t: f32) -> Vec3 {
    lerp3(lerp3(p0, p1, t), lerp3(p1, p2, t), t)
}

fn bundles(rng: &mut Pcg64Mcg, vertices: usize) -> (Tractogram, ViewHint) {
    let mut t = Tractogram::new();
    use std::f32::consts::PI;
    // Corpus callosum: an arch from the left to the right hemisphere, a broad sheet front to back.
    let cc = |s: f32| Vec3::new(-62.0 + 124.0 * s, -12.0, 12.0 + 30.0 * (PI * s).sin());
    Bundle { centre: &cc, width: &|s| (4.0 + 3.0 * (1.0 - (PI * s).sin()), 34.0), reference: Vec3::Y, share: 0.32 }
        .add_to(rng, &mut t, vertices);
    for side in [-1.0f32, 1.0] {
        // Corticospinal tract: brainstem up to the motor cortex, fanning out at the top.
        let cst = move |s: f32| {
            bezier(
                Vec3::new(side * 9.0, -22.0, -55.0),
                Vec3::new(side * 16.0, -18.0, 10.0),
                Vec3::new(side * 36.0, -14.0, 68.0),
                s,
            )
        };
        Bundle { centre: &cst, width: &|s| (3.5 + 16.0 * s * s, 3.5 + 22.0 * s * s), reference: Vec3::X, share: 0.12 }
            .add_to(rng, &mut t, vertices);
        // Arcuate fasciculus: frontal lobe, back around the Sylvian fissure, down into the temporal lobe.
        let af = move |s: f32| {
            let a = PI * 1.25 * s;
            Vec3::new(
                side * (42.0 + 6.0 * s),
                18.0 - 48.0 * (0.5 - 0.5 * a.cos()) - 20.0 * s,
                22.0 * a.cos().max(-0.7) + 4.0,
            )
        };
        Bundle { centre: &af, width: &|_| (5.0, 7.0), reference: Vec3::X, share: 0.1 }.add_to(rng, &mut t, vertices);
        // Cingulum: front to back above the corpus callosum.
        let cg = move |s: f32| Vec3::new(side * 9.0, 42.0 - 100.0 * s, 28.0 + 14.0 * (PI * s).sin() - 25.0 * s * s);
        Bundle { centre: &cg, width: &|_| (3.0, 4.0), reference: Vec3::X, share: 0.06 }.add_to(rng, &mut t, vertices);
        // Inferior fronto-occipital fasciculus: long and low, narrowing at the external capsule.
        let ifof = move |s: f32| {
            Vec3::new(side * (30.0 + 6.0 * (2.0 * PI * s).cos()), 62.0 - 160.0 * s, 2.0 - 10.0 * (PI * s).sin())
        };
        Bundle {
            centre: &ifof,
            width: &|s| (4.0 + 6.0 * (2.0 * s - 1.0).powi(2), 5.0 + 9.0 * (2.0 * s - 1.0).powi(2)),
            reference: Vec3::Z,
            share: 0.06,
        }
        .add_to(rng, &mut t, vertices);
    }
    let view = framed(&t, Vec3::new(-0.8, 0.45, 0.45), Vec3::Z, 35.0);
    (t, view)
}

fn spiral(rng: &mut Pcg64Mcg, vertices: usize) -> (Tractogram, ViewHint) {
    let mut t = Tractogram::new();
    let helix = |s: f32| {
        let a = std::f32::consts::TAU * 2.5 * s;
        Vec3::new(32.0 * a.cos(), 32.0 * a.sin(), -45.0 + 90.0 * s)
    };
    Bundle { centre: &helix, width: &|_| (6.0, 6.0), reference: Vec3::Z, share: 0.7 }.add_to(rng, &mut t, vertices);
    // More distant bundles: behind the spiral and to its side, at clearly larger depth.
    let behind = |s: f32| Vec3::new(-90.0 + 180.0 * s, -70.0, -20.0 + 25.0 * (3.0 * s).sin());
    Bundle { centre: &behind, width: &|_| (7.0, 7.0), reference: Vec3::Z, share: 0.18 }.add_to(rng, &mut t, vertices);
    let beside = |s: f32| Vec3::new(75.0, -40.0 + 20.0 * s, -70.0 + 140.0 * s);
    Bundle { centre: &beside, width: &|_| (5.0, 5.0), reference: Vec3::X, share: 0.12 }.add_to(rng, &mut t, vertices);
    let view = framed(&t, Vec3::new(0.15, 1.0, 0.35), Vec3::Z, 35.0);
    (t, view)
}

/// Velocity of two counter-rotating vortex tubes along z (smoothed cores, slightly bent) with
/// an axial jet in their cores.
fn vortex_velocity(p: Vec3) -> Vec3 {
    let mut v = Vec3::ZERO;
    for (sign, x0) in [(1.0f32, -18.0f32), (-1.0, 18.0)] {
        let centre_x = x0 + 5.0 * (p.z / 30.0).sin();
        let (dx, dy) = (p.x - centre_x, p.y);
        let r2 = dx * dx + dy * dy;
        let core = 36.0;
        let swirl = sign * 400.0 / (r2 + core);
        v += Vec3::new(-dy * swirl, dx * swirl, 6.0 * (-r2 / 400.0).exp());
    }
    v + Vec3::new(0.0, 0.0, 0.8)
}

fn vortex(rng: &mut Pcg64Mcg, vertices: usize) -> (Tractogram, ViewHint) {
    let mut t = Tractogram::new();
    let per_line = 180;
    let lines = (vertices / per_line).max(8);
    for _ in 0..lines {
        let (u, v) = disk(rng);
        let mut p = Vec3::new(u * 55.0, v * 40.0, -60.0 + 10.0 * uniform(rng));
        let mut line = Vec::with_capacity(per_line);
        for _ in 0..per_line {
            line.push(p.to_array());
            // RK4 along the unit direction field: steps of one unit of arc length.
            let dir = |q: Vec3| vortex_velocity(q).normalize_or(Vec3::Z);
            let k1 = dir(p);
            let k2 = dir(p + k1 * 0.5);
            let k3 = dir(p + k2 * 0.5);
            let k4 = dir(p + k3);
            p += (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0;
        }
        t.push(line);
    }
    let view = framed(&t, Vec3::new(0.9, -0.6, 0.5), Vec3::Z, 35.0);
    (t, view)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_are_deterministic_and_scale() {
        for kind in SceneKind::ALL {
            let a = kind.build(7, 50_000);
            let b = kind.build(7, 50_000);
            assert_eq!(a.tractogram, b.tractogram, "{}", kind.name());
            assert_ne!(a.tractogram, kind.build(8, 50_000).tractogram);
            let n = a.tractogram.vertices();
            assert!((40_000..70_000).contains(&n), "{}: {n} vertices for 50 000", kind.name());
            let big = kind.build(7, 400_000).tractogram.vertices();
            assert!((340_000..480_000).contains(&big), "{}: {big} vertices for 400 000", kind.name());
            assert!(a.tractogram.positions.iter().flatten().all(|c| c.is_finite()));
        }
    }

    #[test]
    fn bundles_are_brain_sized_with_thousands_of_streamlines() {
        let scene = SceneKind::Bundles.build(1, SceneKind::Bundles.default_vertices());
        assert!(scene.tractogram.streamlines() > 2000, "{}", scene.tractogram.streamlines());
        let (lo, hi) = scene.tractogram.positions.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(mut lo, mut hi), p| {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
            (lo, hi)
        });
        let extent: Vec<f32> = (0..3).map(|k| hi[k] - lo[k]).collect();
        // A human brain is about 140 × 170 × 120 mm (x left-right, y front-back, z up).
        assert!(extent.iter().all(|e| (90.0..220.0).contains(e)), "{extent:?}");
    }

    #[test]
    fn names_round_trip() {
        for kind in SceneKind::ALL {
            assert_eq!(kind.name().parse::<SceneKind>().unwrap(), kind);
        }
        assert!("nope".parse::<SceneKind>().is_err());
    }
}
