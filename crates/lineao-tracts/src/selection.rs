//! **Selection**: which streamlines of a tractogram are shown — what every tract viewer lets a
//! user cut a whole brain down to (mrview's include and exclude regions, DSI Studio's and
//! TrackVis's length and property filters, niivue's decimation).
//!
//! The rules, all of which a kept streamline passes:
//! - **subset**: a share of the streamlines, drawn at random but stable for a seed: streamline
//!   i is kept when a hash of (seed, i) lies below the share, so a larger share keeps a
//!   superset and the choice does not depend on how a file is read in chunks;
//! - **length**: its arc length (the sum of its segments' lengths, in world units) within a
//!   range;
//! - **field**: a per-streamline field's value (TRX dps, TrackVis properties) within a range;
//! - **groups**: it belongs to one of the named groups (TRX groups);
//! - **regions** (mrview's rule): for every include region some segment of it passes through
//!   the region, and no segment passes through an exclude region. Regions are spheres and
//!   axis-aligned boxes in world units; a segment passes through one when a point of it lies
//!   inside (a streamline of one point is that point).
//!
//! A streamline's own points and fields decide every rule but the groups, so a file is
//! selected chunk by chunk as it streams ([`Selection::chunk`]) and the groups, which a TRX file
//! lists at its end, are applied once it is read ([`Selection::apply_groups`]).

use glam::Vec3;

use crate::tractogram::{Group, Tractogram};

/// A sphere or an axis-aligned box in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Region {
    /// A ball: a segment meets it when its distance to `center` is at most `radius`.
    Sphere {
        /// The centre.
        center: [f32; 3],
        /// The radius.
        radius: f32,
    },
    /// An axis-aligned box from `min` to `max`.
    Box {
        /// The corner with the smallest coordinates.
        min: [f32; 3],
        /// The corner with the largest coordinates.
        max: [f32; 3],
    },
}

impl Region {
    /// Whether segment `a`–`b` has a point inside the region.
    pub fn meets(&self, a: Vec3, b: Vec3) -> bool {
        match *self {
            Region::Sphere { center, radius } => {
                let (c, ab) = (Vec3::from_array(center), b - a);
                let t = if ab.length_squared() > 0.0 {
                    ((c - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (a + t * ab).distance_squared(c) <= radius * radius
            }
            Region::Box { min, max } => {
                // The slab test: the part of the segment (t in [0, 1]) within each axis's slab.
                let (min, max, ab) = (Vec3::from_array(min), Vec3::from_array(max), b - a);
                let (mut t0, mut t1) = (0.0f32, 1.0f32);
                for axis in 0..3 {
                    if ab[axis] == 0.0 {
                        if a[axis] < min[axis] || a[axis] > max[axis] {
                            return false;
                        }
                    } else {
                        let (u, v) = ((min[axis] - a[axis]) / ab[axis], (max[axis] - a[axis]) / ab[axis]);
                        t0 = t0.max(u.min(v));
                        t1 = t1.min(u.max(v));
                    }
                }
                t0 <= t1
            }
        }
    }

    /// Whether some segment of `points` (or its only point) meets the region.
    fn meets_polyline(&self, points: &[[f32; 3]]) -> bool {
        match points {
            [] => false,
            [p] => self.meets(Vec3::from_array(*p), Vec3::from_array(*p)),
            _ => points.windows(2).any(|w| self.meets(Vec3::from_array(w[0]), Vec3::from_array(w[1]))),
        }
    }
}

/// The rules a shown streamline passes (module documentation); the default keeps everything.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Selection {
    /// The share of streamlines kept (in [0, 1]) and the seed that draws them.
    pub subset: Option<(f64, u64)>,
    /// Arc length range, world units.
    pub length: Option<[f32; 2]>,
    /// A per-streamline field's name and the range of its values kept.
    pub field: Option<(String, [f32; 2])>,
    /// Groups a kept streamline belongs to one of (none: any streamline).
    pub groups: Vec<String>,
    /// Regions each kept streamline passes through (all of them).
    pub include: Vec<Region>,
    /// Regions no kept streamline passes through.
    pub exclude: Vec<Region>,
}

/// A rule that names what the tractogram lacks: the message lists what it has.
#[derive(Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct SelectionError(pub String);

impl Selection {
    /// Whether every streamline passes (no rule is set).
    pub fn is_everything(&self) -> bool {
        *self == Selection::default()
    }

    /// Its include and exclude regions alone (every other rule passes everything): what a viewer
    /// that keeps no points judges as a file arrives.
    pub fn regions(&self) -> Selection {
        Selection { include: self.include.clone(), exclude: self.exclude.clone(), ..Selection::default() }
    }

    /// Whether the rules that a streamline's index in its file and its arc length decide (the
    /// subset, the length range) keep it: what a viewer that keeps only the lengths can change.
    pub fn keeps(&self, index: u64, length: f32) -> bool {
        self.in_subset(index) && self.length.is_none_or(|[lo, hi]| (lo..=hi).contains(&length))
    }

    /// Whether streamline `index` (of its file) is in the subset.
    fn in_subset(&self, index: u64) -> bool {
        let Some((share, seed)) = self.subset else { return true };
        // SplitMix64 of the seed and the index: uniform bits, stable across runs and platforms.
        let mix = |mut z: u64| {
            z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        let u = (mix(seed ^ mix(index)) >> 11) as f64 / (1u64 << 53) as f64;
        u < share
    }

    /// Per streamline of `chunk`, streamline `first + i` of its file: whether it passes every
    /// rule but the groups ([`Selection::apply_groups`]).
    pub fn chunk(&self, chunk: &Tractogram, first: u64) -> Result<Vec<bool>, SelectionError> {
        let field = match &self.field {
            Some((name, range)) => Some((field_values(chunk, name)?, *range)),
            None => None,
        };
        Ok((0..chunk.streamlines())
            .map(|i| {
                let points = &chunk.positions[chunk.offsets[i] as usize..chunk.offsets[i + 1] as usize];
                self.keeps(first + i as u64, arc_length(points))
                    && field.as_ref().is_none_or(|(values, [lo, hi])| (*lo..=*hi).contains(&values[i]))
                    && self.include.iter().all(|r| r.meets_polyline(points))
                    && !self.exclude.iter().any(|r| r.meets_polyline(points))
            })
            .collect())
    }

    /// Leaves out of `mask` (one entry per streamline of the file) the streamlines of none of
    /// the groups named; a name the file lacks is an error listing its groups.
    pub fn apply_groups(&self, mask: &mut [bool], groups: &[Group]) -> Result<(), SelectionError> {
        if self.groups.is_empty() {
            return Ok(());
        }
        let mut member = vec![false; mask.len()];
        for name in &self.groups {
            let group = groups.iter().find(|g| &g.name == name).ok_or_else(|| {
                let names: Vec<&str> = groups.iter().map(|g| g.name.as_str()).collect();
                SelectionError(format!(
                    "no group '{name}' (the file's groups: {})",
                    if names.is_empty() { "none".into() } else { names.join(", ") }
                ))
            })?;
            for &s in &group.streamlines {
                if let Some(m) = member.get_mut(s as usize) {
                    *m = true;
                }
            }
        }
        for (kept, member) in mask.iter_mut().zip(member) {
            *kept &= member;
        }
        Ok(())
    }

    /// Leaves out of `mask` (one entry per streamline of `t`) the streamlines whose
    /// per-streamline field is outside the field rule's range: what a viewer that keeps the
    /// fields but not the points changes ([`Selection::chunk`] judges it with the others).
    pub fn apply_field(&self, mask: &mut [bool], t: &Tractogram) -> Result<(), SelectionError> {
        let Some((name, [lo, hi])) = &self.field else { return Ok(()) };
        let values = field_values(t, name)?;
        for (kept, value) in mask.iter_mut().zip(values) {
            *kept &= (*lo..=*hi).contains(value);
        }
        Ok(())
    }

    /// Leaves out of `mask` (one entry per streamline of `t`) the streamlines that miss an
    /// include region or meet an exclude region: what a viewer that keeps each streamline's
    /// length, and reads the points again for regions, adds ([`Selection::chunk`] judges them
    /// with the others).
    pub fn apply_regions(&self, mask: &mut [bool], t: &Tractogram) {
        if self.include.is_empty() && self.exclude.is_empty() {
            return;
        }
        for (i, kept) in mask.iter_mut().enumerate().filter(|(_, kept)| **kept) {
            let points = &t.positions[t.offsets[i] as usize..t.offsets[i + 1] as usize];
            *kept = self.include.iter().all(|r| r.meets_polyline(points))
                && !self.exclude.iter().any(|r| r.meets_polyline(points));
        }
    }

    /// Every rule on a whole tractogram: one entry per streamline.
    pub fn mask(&self, t: &Tractogram) -> Result<Vec<bool>, SelectionError> {
        let mut mask = self.chunk(t, 0)?;
        self.apply_groups(&mut mask, &t.groups)?;
        Ok(mask)
    }
}

/// The sum of the lengths of the segments between consecutive finite points.
pub fn arc_length(points: &[[f32; 3]]) -> f32 {
    let finite = |p: &[f32; 3]| p.iter().all(|c| c.is_finite());
    points
        .windows(2)
        .filter(|w| finite(&w[0]) && finite(&w[1]))
        .map(|w| Vec3::from_array(w[0]).distance(Vec3::from_array(w[1])))
        .sum()
}

/// The one-column per-streamline field `name` of `t`, one value a streamline; an error that
/// lists the per-streamline fields otherwise.
fn field_values<'a>(t: &'a Tractogram, name: &str) -> Result<&'a [f32], SelectionError> {
    let listed = || {
        let names: Vec<&str> = t.streamline_fields.iter().map(|f| f.name.as_str()).collect();
        if names.is_empty() { "none".to_string() } else { names.join(", ") }
    };
    match t.streamline_fields.iter().find(|f| f.name == name) {
        Some(f) if f.columns == 1 => Ok(&f.values),
        Some(f) => Err(SelectionError(format!("the per-streamline field '{name}' has {} columns, not one", f.columns))),
        None if t.vertex_fields.iter().any(|f| f.name == name) => Err(SelectionError(format!(
            "'{name}' is a per-vertex field; a selection takes a per-streamline one (the file's: {})",
            listed()
        ))),
        None => Err(SelectionError(format!("no per-streamline field '{name}' (the file's: {})", listed()))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tractogram::Field;

    /// Three streamlines along x at y = 0, 10, 20 of lengths 2, 4 and 6, with a field 1, 2, 3.
    fn three() -> Tractogram {
        let line = |y: f32, len: usize| (0..=len).map(move |x| [x as f32, y, 0.0]);
        let positions: Vec<[f32; 3]> = line(0.0, 2).chain(line(10.0, 4)).chain(line(20.0, 6)).collect();
        Tractogram {
            positions,
            offsets: vec![0, 3, 8, 15],
            streamline_fields: vec![Field { name: "weight".into(), columns: 1, values: vec![1.0, 2.0, 3.0] }],
            groups: vec![Group { name: "top".into(), streamlines: vec![2], data: Vec::new() }],
            ..Tractogram::default()
        }
    }

    #[test]
    fn each_rule_keeps_what_it_says() {
        let t = three();
        let mask = |s: Selection| s.mask(&t).unwrap();
        assert_eq!(mask(Selection::default()), [true; 3]);
        assert_eq!(mask(Selection { length: Some([3.0, 10.0]), ..Default::default() }), [false, true, true]);
        let weight = Selection { field: Some(("weight".into(), [1.5, 3.0])), ..Default::default() };
        assert_eq!(mask(weight.clone()), [false, true, true]);
        // The field rule alone on the fields (a viewer without the points): the same.
        let mut alone = [true; 3];
        weight.apply_field(&mut alone, &Tractogram { positions: Vec::new(), ..t.clone() }).unwrap();
        assert_eq!(alone, [false, true, true]);
        assert_eq!(mask(Selection { groups: vec!["top".into()], ..Default::default() }), [false, false, true]);
        // A sphere the middle line passes near, a box the last one crosses at its end.
        let sphere = Region::Sphere { center: [3.5, 11.0, 0.0], radius: 1.2 };
        let cube = Region::Box { min: [5.5, 19.0, -1.0], max: [7.0, 21.0, 1.0] };
        assert_eq!(mask(Selection { include: vec![sphere], ..Default::default() }), [false, true, false]);
        assert_eq!(mask(Selection { include: vec![cube], ..Default::default() }), [false, false, true]);
        assert_eq!(mask(Selection { exclude: vec![sphere, cube], ..Default::default() }), [true, false, false]);
        // Both include regions must be met.
        assert_eq!(mask(Selection { include: vec![sphere, cube], ..Default::default() }), [false; 3]);
        // The regions alone (a viewer that keeps the lengths): what `mask` says, and what an
        // earlier rule left out stays out.
        let mut regions = [true; 3];
        Selection { exclude: vec![sphere, cube], ..Default::default() }.apply_regions(&mut regions, &t);
        assert_eq!(regions, [true, false, false]);
        let mut after = [false, true, true];
        Selection { include: vec![cube], ..Default::default() }.apply_regions(&mut after, &t);
        assert_eq!(after, [false, false, true]);
    }

    #[test]
    fn a_subset_is_stable_nested_and_near_its_share() {
        let subset = |share: f64, seed: u64| {
            let s = Selection { subset: Some((share, seed)), ..Default::default() };
            (0..100_000u64).map(|i| s.in_subset(i)).collect::<Vec<bool>>()
        };
        let (tenth, half) = (subset(0.1, 7), subset(0.5, 7));
        let count = |m: &[bool]| m.iter().filter(|&&k| k).count();
        assert!((9_500..10_500).contains(&count(&tenth)), "{}", count(&tenth));
        assert!(tenth.iter().zip(&half).all(|(&a, &b)| !a || b), "a larger share keeps a superset");
        assert_eq!(tenth, subset(0.1, 7));
        assert_ne!(tenth, subset(0.1, 8));
        assert_eq!(count(&subset(0.0, 1)), 0);
        assert_eq!(count(&subset(1.0, 1)), 100_000);
    }

    #[test]
    fn a_missing_field_or_group_names_what_the_file_has() {
        let t = three();
        let field = Selection { field: Some(("fa".into(), [0.0, 1.0])), ..Default::default() };
        assert_eq!(field.mask(&t).unwrap_err().0, "no per-streamline field 'fa' (the file's: weight)");
        let group = Selection { groups: vec!["left".into()], ..Default::default() };
        assert_eq!(group.mask(&t).unwrap_err().0, "no group 'left' (the file's groups: top)");
    }

    #[test]
    fn a_segment_crossing_a_box_meets_it_though_no_point_lies_inside() {
        let cube = Region::Box { min: [-1.0; 3], max: [1.0; 3] };
        assert!(cube.meets(Vec3::new(-5.0, 0.0, 0.0), Vec3::new(5.0, 0.5, 0.0)));
        assert!(!cube.meets(Vec3::new(-5.0, 3.0, 0.0), Vec3::new(5.0, 3.0, 0.0)));
        let ball = Region::Sphere { center: [0.0; 3], radius: 1.0 };
        assert!(ball.meets(Vec3::new(-5.0, 0.5, 0.0), Vec3::new(5.0, 0.5, 0.0)));
        assert!(!ball.meets(Vec3::new(2.0, 0.0, 0.0), Vec3::new(5.0, 0.0, 0.0)));
    }
}
