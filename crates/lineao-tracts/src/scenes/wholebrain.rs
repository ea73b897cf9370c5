//! `wholebrain`: a procedural whole-brain tractogram of any size, streamline by streamline —
//! what today's pipelines (MRtrix `tckgen` + SIFT, TractoFlow) produce, 1–10 M streamlines of
//! 20–200 mm at 1 mm steps, without a 10 GB file.
//!
//! Two hemispheres (ellipsoids of 68 × 164 × 124 mm side by side, MNI-like: RAS+ mm, the
//! anterior commissure near the origin) hold four families of bundles, each a few dozen
//! *templates* — cubic Béziers through control points in the hemispheres' own coordinates —
//! whose streamlines follow their template with a fanning offset (a few mm in the deep white
//! matter, more where they reach the cortex) and a slow wander, so neighbours run together as
//! fascicles do and spread where they end:
//!
//! | family | share | runs | length |
//! |---|---:|---|---|
//! | association | 35 % | frontal ↔ parietal, occipital, temporal cortex within a hemisphere, at 40–75 % of its depth | 70–170 mm |
//! | projection | 25 % | brainstem → internal capsule → a fan over the superior and lateral cortex | 90–160 mm |
//! | commissural | 20 % | cortex → across the corpus callosum (y −35 to +30 mm) → the other hemisphere's cortex | 90–170 mm |
//! | U-fibres | 20 % | between neighbouring gyri, 6–12 mm under the surface | 20–50 mm |
//!
//! Streamline `i` depends only on the seed and `i`, so any range of streamlines can be made on
//! its own (chunks, threads) and the same scene comes out at any chunk size.

use glam::Vec3;
use rand_core::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::Tractogram;

/// Points per streamline on average (measured over the first 100 000 streamlines of seed 1).
pub const MEAN_POINTS: f64 = 113.0;

/// Templates per family.
const TEMPLATES: usize = 48;

/// The centres and semi-axes of the hemispheres (left, right).
const HEMISPHERE_CENTRE: [f32; 3] = [33.0, -17.0, 10.0];
const HEMISPHERE_AXES: [f32; 3] = [34.0, 82.0, 62.0];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Family {
    Association,
    Projection,
    Commissural,
    UFibre,
}

/// A bundle's centre curve (a Catmull–Rom spline through its points: cortex, the deep white
/// matter, cortex) and how far its streamlines spread around it.
#[derive(Clone, Debug)]
struct Template {
    family: Family,
    points: Vec<Vec3>,
    /// Half-width of the bundle in the deep white matter and at its ends (mm).
    core: f32,
    ends: f32,
}

/// The procedural whole brain of one seed with `streamlines` streamlines.
#[derive(Clone, Debug)]
pub struct WholeBrain {
    seed: u64,
    streamlines: u64,
    templates: Vec<Template>,
}

fn uniform(rng: &mut Pcg64Mcg) -> f32 {
    (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
}

fn symmetric(rng: &mut Pcg64Mcg) -> f32 {
    2.0 * uniform(rng) - 1.0
}

/// The hemispheres' surface is folded: a few per cent of the radius in low-frequency waves over
/// the direction (gyri and sulci a centimetre or two across).
fn folding(d: Vec3) -> f32 {
    1.0 + 0.035 * (7.0 * d.x + 3.0 * d.y).sin() * (6.0 * d.z).cos() + 0.025 * (9.0 * d.y - 4.0 * d.z).sin()
}

/// A point of hemisphere `side` (−1 left, +1 right) at direction `direction` from its centre
/// (+x lateral for both), at `depth` of the way to the folded surface (1 = the surface).
fn in_hemisphere(side: f32, direction: Vec3, depth: f32) -> Vec3 {
    let d = direction.normalize_or(Vec3::X);
    let axes = Vec3::from_array(HEMISPHERE_AXES);
    let centre = Vec3::from_array(HEMISPHERE_CENTRE);
    let p = centre + d * axes * depth * folding(d);
    // The medial wall is flat: nothing crosses x = ±2 mm but the commissures.
    Vec3::new(side * p.x.max(2.0), p.y, p.z)
}

/// A random direction from the hemisphere's centre whose components lie in the given ranges
/// (before normalising): a region of the cortex.
fn region(rng: &mut Pcg64Mcg, x: (f32, f32), y: (f32, f32), z: (f32, f32)) -> Vec3 {
    let pick = |rng: &mut Pcg64Mcg, (lo, hi): (f32, f32)| lo + (hi - lo) * uniform(rng);
    Vec3::new(pick(rng, x), pick(rng, y), pick(rng, z)).normalize_or(Vec3::X)
}

impl Template {
    fn new(family: Family, rng: &mut Pcg64Mcg) -> Template {
        let side = if rng.next_u32() & 1 == 0 { -1.0 } else { 1.0 };
        let h = |d: Vec3, depth: f32| in_hemisphere(side, d, depth);
        // Streamlines enter the cortex radially: the last two points of an end share its
        // direction.
        let (points, core, ends) = match family {
            Family::Association => {
                // Frontal cortex to a posterior region, through the deep white matter.
                let front = region(rng, (0.1, 0.9), (0.5, 1.0), (-0.4, 0.8));
                let back = region(rng, (0.1, 0.9), (-1.0, -0.2), (-0.8, 0.7));
                let depth = 0.4 + 0.3 * uniform(rng);
                let lateral = 0.2 + 0.6 * uniform(rng);
                let mid1 = Vec3::new(lateral, 0.3, front.z * 0.4);
                let mid2 = Vec3::new(lateral, -0.4, back.z * 0.4);
                let points =
                    vec![h(front, 0.98), h(front, 0.8), h(mid1, depth), h(mid2, depth), h(back, 0.8), h(back, 0.98)];
                (points, 2.5 + 2.5 * uniform(rng), 7.0)
            }
            Family::Projection => {
                // Brainstem, internal capsule, corona radiata, a superior or lateral region.
                let y = -27.0 + 4.0 * symmetric(rng);
                let top = region(rng, (0.1, 0.9), (-0.7, 0.7), (0.2, 1.0));
                let capsule = Vec3::new(side * (17.0 + 3.0 * uniform(rng)), -14.0 + 14.0 * symmetric(rng), 2.0);
                let corona = h(Vec3::new(top.x * 0.5, top.y * 0.6, 0.7), 0.5);
                let points = vec![
                    Vec3::new(side * 6.0, y, -62.0),
                    Vec3::new(side * 8.0, y + 4.0, -38.0),
                    capsule,
                    corona,
                    h(top, 0.8),
                    h(top, 0.98),
                ];
                (points, 2.0 + 2.0 * uniform(rng), 9.0)
            }
            Family::Commissural => {
                // Cortex of one hemisphere, over the corpus callosum, the other's.
                let y = -35.0 + 65.0 * uniform(rng);
                let z = 18.0 + 6.0 * uniform(rng);
                let target = region(rng, (0.1, 0.9), (-0.6, 0.6), (0.0, 0.9));
                let along = (y - HEMISPHERE_CENTRE[1]) / HEMISPHERE_AXES[1];
                let target = (target + Vec3::new(0.0, 1.2 * along, 0.0)).normalize();
                let other = (target + Vec3::new(0.0, 0.1 * symmetric(rng), 0.1 * symmetric(rng))).normalize();
                let points = vec![
                    in_hemisphere(-1.0, target, 0.98),
                    in_hemisphere(-1.0, target, 0.75),
                    Vec3::new(-14.0, y, z + 6.0),
                    Vec3::new(0.0, y, z + 10.0),
                    Vec3::new(14.0, y, z + 6.0),
                    in_hemisphere(1.0, other, 0.75),
                    in_hemisphere(1.0, other, 0.98),
                ];
                (points, 2.0 + 2.0 * uniform(rng), 7.0)
            }
            Family::UFibre => {
                // Between two neighbouring patches of cortex, dipping under the surface.
                let a = region(rng, (-0.3, 1.0), (-1.0, 1.0), (-0.8, 1.0));
                let turn = a.any_orthonormal_vector() * (0.16 + 0.2 * uniform(rng));
                let b = (a + turn).normalize();
                let depth = 0.8 + 0.06 * uniform(rng);
                let points = vec![h(a, 0.98), h(a, 0.88), h(a + turn * 0.5, depth), h(b, 0.88), h(b, 0.98)];
                (points, 1.5, 3.0)
            }
        };
        Template { family, points, core, ends }
    }

    /// The spline at t ∈ [0, 1] (uniform Catmull–Rom; the end points repeated).
    fn at(&self, t: f32) -> Vec3 {
        let n = self.points.len();
        let x = t.clamp(0.0, 1.0) * (n - 1) as f32;
        let k = (x as usize).min(n - 2);
        let u = x - k as f32;
        let p = |i: isize| self.points[i.clamp(0, n as isize - 1) as usize];
        let (p0, p1, p2, p3) = (p(k as isize - 1), p(k as isize), p(k as isize + 1), p(k as isize + 2));
        let (u2, u3) = (u * u, u * u * u);
        (p1 * 2.0 + (p2 - p0) * u + (p0 * 2.0 - p1 * 5.0 + p2 * 4.0 - p3) * u2 + (p1 * 3.0 - p0 - p2 * 3.0 + p3) * u3)
            * 0.5
    }
}

/// Arc-length samples of a template: chords per spline point (templates have at most 8).
const SAMPLES_PER_POINT: usize = 16;

impl WholeBrain {
    /// The whole brain of `seed` with about `vertices` points.
    pub fn new(seed: u64, vertices: u64) -> WholeBrain {
        let streamlines = ((vertices as f64 / MEAN_POINTS).round() as u64).max(16);
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x7768_6f6c_6562_7261);
        let families = [Family::Association, Family::Projection, Family::Commissural, Family::UFibre];
        let templates = families.iter().flat_map(|&f| (0..TEMPLATES).map(move |_| f)).collect::<Vec<_>>();
        let templates = templates.into_iter().map(|f| Template::new(f, &mut rng)).collect();
        WholeBrain { seed, streamlines, templates }
    }

    /// How many streamlines it makes.
    pub fn streamlines(&self) -> u64 {
        self.streamlines
    }

    /// Streamline `i` appended to `out`.
    pub fn streamline(&self, i: u64, out: &mut Vec<[f32; 3]>) {
        let mut rng = Pcg64Mcg::seed_from_u64(self.seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ i);
        // Family by share: 35 % association, 25 % projection, 20 % commissural, 20 % U-fibres.
        let roll = uniform(&mut rng);
        let family = match roll {
            r if r < 0.35 => 0,
            r if r < 0.60 => 1,
            r if r < 0.80 => 2,
            _ => 3,
        };
        let template = &self.templates[family * TEMPLATES + (rng.next_u32() as usize % TEMPLATES)];
        let samples = SAMPLES_PER_POINT * (template.points.len() - 1);
        // The arc length along the template, for 1 mm steps.
        let mut lengths = [0.0f32; SAMPLES_PER_POINT * 8 + 1];
        let mut previous = template.at(0.0);
        for k in 1..=samples {
            let p = template.at(k as f32 / samples as f32);
            lengths[k] = lengths[k - 1] + p.distance(previous);
            previous = p;
        }
        // Where this streamline starts and ends along its bundle, and its place across it.
        let total = lengths[samples];
        let t0 = 0.06 * uniform(&mut rng);
        let t1 = 1.0 - 0.06 * uniform(&mut rng);
        let (s0, s1) = (t0 * total, t1 * total);
        let points = ((s1 - s0).round() as usize).max(2) + 1;
        // A place in the bundle's round cross-section (uniform in the unit ball).
        let across = loop {
            let v = Vec3::new(symmetric(&mut rng), symmetric(&mut rng), symmetric(&mut rng));
            if v.length_squared() <= 1.0 {
                break v;
            }
        };
        let (wander, phase) = (0.6 + 0.6 * uniform(&mut rng), std::f32::consts::TAU * uniform(&mut rng));
        let family = template.family;
        let mut k = 0usize;
        for j in 0..points {
            let s = s0 + (s1 - s0) * j as f32 / (points - 1) as f32;
            while k + 1 < samples && lengths[k + 1] < s {
                k += 1;
            }
            let span = (lengths[k + 1] - lengths[k]).max(1e-6);
            let t = (k as f32 + ((s - lengths[k]) / span).clamp(0.0, 1.0)) / samples as f32;
            let centre = template.at(t);
            // Narrow in the deep white matter, fanning out toward the cortex (both ends, but
            // for projections only the cortical one).
            let end = match family {
                Family::Projection => t * t,
                _ => (2.0 * t - 1.0).powi(2),
            };
            let width = template.core + (template.ends - template.core) * end;
            let offset = across * width
                + Vec3::new((phase + 0.09 * s).sin(), (phase * 1.7 + 0.07 * s).cos(), (phase * 0.6 + 0.05 * s).sin())
                    * wander;
            out.push((centre + offset).to_array());
        }
    }

    /// Streamlines `range` as a tractogram.
    pub fn tractogram(&self, range: std::ops::Range<u64>) -> Tractogram {
        let mut t = Tractogram::new();
        t.positions.reserve((range.end - range.start) as usize * (MEAN_POINTS as usize + 8));
        for i in range {
            self.streamline(i, &mut t.positions);
            t.offsets.push(t.positions.len() as u64);
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streamlines_are_the_same_in_any_chunking_and_have_a_brains_extent() {
        let brain = WholeBrain::new(1, 200_000);
        let whole = brain.tractogram(0..brain.streamlines());
        let mut pieces = Vec::new();
        for start in (0..brain.streamlines()).step_by(37) {
            let chunk = brain.tractogram(start..(start + 37).min(brain.streamlines()));
            pieces.extend_from_slice(&chunk.positions);
        }
        assert_eq!(whole.positions, pieces);
        let mean = whole.vertices() as f64 / whole.streamlines() as f64;
        assert!((mean - MEAN_POINTS).abs() < 6.0, "mean {mean} points");
        let lengths: Vec<usize> = (0..whole.streamlines()).map(|i| whole.streamline(i).len()).collect();
        assert!(lengths.iter().all(|&n| (15..=230).contains(&n)), "{:?}", lengths.iter().max());
        let b = whole.bounds().unwrap();
        let extent: Vec<f32> = (0..3).map(|a| b.max[a] - b.min[a]).collect();
        // A brain: about 140 × 170 × 130 mm (the brainstem adds below).
        assert!((120.0..160.0).contains(&extent[0]) && (140.0..190.0).contains(&extent[1]), "{extent:?}");
        assert!((110.0..170.0).contains(&extent[2]), "{extent:?}");
        // Consecutive points 1 mm apart.
        let steps: Vec<f32> =
            whole.positions.windows(2).take(5000).map(|w| Vec3::from(w[0]).distance(Vec3::from(w[1]))).collect();
        let median = {
            let mut s = steps.clone();
            s.sort_by(f32::total_cmp);
            s[s.len() / 2]
        };
        assert!((0.8..1.3).contains(&median), "step {median}");
    }
}
