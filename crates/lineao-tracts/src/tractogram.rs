//! The one in-memory representation every loader produces and every writer consumes.

/// Streamlines as one flat array of points: streamline i is
/// `positions[offsets[i] as usize..offsets[i + 1] as usize]`.
///
/// Positions are RAS+ millimetres (or a built-in scene's world units). Data attached to vertices
/// or streamlines is kept by name, as `f32` columns; groups are lists of streamline indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tractogram {
    /// Points in RAS+ millimetres.
    pub positions: Vec<[f32; 3]>,
    /// N + 1 entries, first 0, last `positions.len()`, never decreasing.
    pub offsets: Vec<u64>,
    /// Per-vertex data (`values.len() == vertices() * columns`): TrackVis scalars, TRX dpv,
    /// VTK POINT_DATA, the values of a `.tsf`.
    pub vertex_fields: Vec<Field>,
    /// Per-streamline data (`values.len() == streamlines() * columns`): TrackVis properties,
    /// TRX dps, VTK CELL_DATA.
    pub streamline_fields: Vec<Field>,
    /// Named subsets of streamlines (TRX groups, DSI Studio clusters).
    pub groups: Vec<Group>,
    /// The voxel grid the streamlines were tracked in, where the format records one.
    pub space: Option<VoxelSpace>,
}

/// Named data with `columns` values per vertex or per streamline, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// Its name in the file (trailing spaces and NULs trimmed).
    pub name: String,
    /// Values per entry (1 for a scalar, 3 for a colour).
    pub columns: usize,
    /// The values, `columns` per vertex or per streamline, row-major.
    pub values: Vec<f32>,
}

/// A named set of streamline indices, with optional data per group (TRX dpg).
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// Its name in the file.
    pub name: String,
    /// The indices of its streamlines.
    pub streamlines: Vec<u32>,
    /// TRX `dpg/<group>/<name>`: `columns` values for the whole group.
    pub data: Vec<Field>,
}

/// The reference image of a tractogram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelSpace {
    /// Voxel indices to RAS+ mm, row-major 4 × 4.
    pub affine: [[f64; 4]; 4],
    /// The grid's size in voxels.
    pub dimensions: [u32; 3],
    /// Absent where the format records only the affine (TRX).
    pub voxel_sizes: Option<[f32; 3]>,
}

/// Axis-aligned bounds of all points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The smallest coordinate on each axis.
    pub min: [f32; 3],
    /// The largest coordinate on each axis.
    pub max: [f32; 3],
}

/// The 4 × 4 identity: the affine of a file without one.
pub const IDENTITY: [[f64; 4]; 4] =
    [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];

impl Tractogram {
    /// An empty tractogram.
    pub fn new() -> Tractogram {
        Tractogram { offsets: vec![0], ..Tractogram::default() }
    }

    /// Appends one streamline.
    pub fn push(&mut self, points: impl IntoIterator<Item = [f32; 3]>) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        self.positions.extend(points);
        self.offsets.push(self.positions.len() as u64);
    }

    /// The number of streamlines.
    pub fn streamlines(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Vertices described by the offsets; equals `positions.len()` except for value-only
    /// files (a `.tsf`), whose values sit in a vertex field without points.
    pub fn vertices(&self) -> usize {
        self.offsets.last().map_or(self.positions.len(), |&n| n as usize)
    }

    /// False for value-only files such as a `.tsf`.
    pub fn has_points(&self) -> bool {
        self.positions.len() == self.vertices() && (self.vertices() > 0 || self.vertex_fields.is_empty())
    }

    /// The points of streamline `i`.
    pub fn streamline(&self, i: usize) -> &[[f32; 3]] {
        &self.positions[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Bounds of every point that is finite; `None` when there is none.
    pub fn bounds(&self) -> Option<Bounds> {
        // Four points (12 lanes) at a time with selects rather than f32::min/max, whose NaN
        // rules block vectorising; NaN and ±Inf fail `finite`, so they never move a bound.
        let flat: &[f32] = bytemuck::cast_slice(&self.positions);
        let mut lo = [f32::INFINITY; 12];
        let mut hi = [f32::NEG_INFINITY; 12];
        let mut fold = |chunk: &[f32; 12]| {
            for i in 0..12 {
                let finite = chunk[i].abs() < f32::INFINITY;
                let (a, b) = if finite { (chunk[i], chunk[i]) } else { (f32::INFINITY, f32::NEG_INFINITY) };
                lo[i] = if a < lo[i] { a } else { lo[i] };
                hi[i] = if b > hi[i] { b } else { hi[i] };
            }
        };
        let chunks = flat.chunks_exact(12);
        let mut rest = [f32::NAN; 12];
        rest[..chunks.remainder().len()].copy_from_slice(chunks.remainder());
        chunks.for_each(|c| fold(c.try_into().unwrap()));
        fold(&rest);
        let min: [f32; 3] = std::array::from_fn(|a| (0..4).map(|k| lo[3 * k + a]).fold(f32::INFINITY, f32::min));
        let max: [f32; 3] = std::array::from_fn(|a| (0..4).map(|k| hi[3 * k + a]).fold(f32::NEG_INFINITY, f32::max));
        (min[0] <= max[0] && min[1] <= max[1] && min[2] <= max[2]).then_some(Bounds { min, max })
    }

    /// The per-vertex field called `name`.
    pub fn vertex_field(&self, name: &str) -> Option<&Field> {
        self.vertex_fields.iter().find(|f| f.name == name)
    }

    /// The per-streamline field called `name`.
    pub fn streamline_field(&self, name: &str) -> Option<&Field> {
        self.streamline_fields.iter().find(|f| f.name == name)
    }

    /// Makes the per-streamline field `name` (TrackVis properties, TRX dps) a per-vertex one as
    /// well, each streamline's values repeated at its vertices, where there is no per-vertex
    /// field of that name: what colours (or sizes) whole streamlines. Whether it did.
    pub fn spread_streamline_field(&mut self, name: &str) -> bool {
        if self.vertex_field(name).is_some() {
            return false;
        }
        let Some(field) = self.streamline_field(name) else { return false };
        let columns = field.columns;
        if field.values.len() != self.streamlines() * columns {
            return false;
        }
        let mut values = Vec::with_capacity(self.vertices() * columns);
        for (s, range) in self.offsets.windows(2).enumerate() {
            let row = &field.values[s * columns..(s + 1) * columns];
            for _ in range[0]..range[1] {
                values.extend_from_slice(row);
            }
        }
        self.vertex_fields.push(Field { name: name.to_string(), columns, values });
        true
    }

    /// Per vertex, the index among [`Tractogram::groups`] of its streamline's first group
    /// (modulo `colors`: what a palette of that many colours shows), NaN outside every group.
    pub fn group_indices(&self, colors: usize) -> Vec<f32> {
        let mut first = vec![f32::NAN; self.streamlines()];
        for (k, group) in self.groups.iter().enumerate().rev() {
            for &s in &group.streamlines {
                if let Some(slot) = first.get_mut(s as usize) {
                    *slot = (k % colors.max(1)) as f32;
                }
            }
        }
        self.offsets.windows(2).zip(first).flat_map(|(w, v)| std::iter::repeat_n(v, (w[1] - w[0]) as usize)).collect()
    }

    /// The streamlines `keep` marks (one entry per streamline), with their per-vertex and
    /// per-streamline fields; groups and the voxel grid are left out (their indices would not
    /// hold).
    pub fn select(&self, keep: &[bool]) -> Tractogram {
        let kept: Vec<usize> = (0..self.streamlines()).filter(|&i| keep.get(i).copied().unwrap_or(false)).collect();
        let mut out = Tractogram::new();
        let range = |i: usize| self.offsets[i] as usize..self.offsets[i + 1] as usize;
        for &i in &kept {
            out.positions.extend_from_slice(&self.positions[range(i)]);
            out.offsets.push(out.positions.len() as u64);
        }
        let pick = |field: &Field, per: &dyn Fn(usize) -> std::ops::Range<usize>| Field {
            name: field.name.clone(),
            columns: field.columns,
            values: kept
                .iter()
                .flat_map(|&i| per(i))
                .flat_map(|r| field.values[r * field.columns..(r + 1) * field.columns].iter().copied())
                .collect(),
        };
        out.vertex_fields = self.vertex_fields.iter().map(|f| pick(f, &range)).collect();
        out.streamline_fields = self.streamline_fields.iter().map(|f| pick(f, &|i| i..i + 1)).collect();
        out
    }

    /// Checks the invariants every loader guarantees: offsets start at 0, never decrease and end
    /// at the vertex count; every field and group fits.
    pub fn validate(&self) -> Result<(), String> {
        if self.offsets.first() != Some(&0) {
            return Err("offsets must start with 0".into());
        }
        if self.offsets.windows(2).any(|w| w[1] < w[0]) {
            return Err("offsets must not decrease".into());
        }
        let last = *self.offsets.last().unwrap();
        let value_only = self.positions.is_empty() && !self.vertex_fields.is_empty();
        if last != self.positions.len() as u64 && !value_only {
            return Err(format!(
                "the last offset {} is not the vertex count {}",
                self.offsets.last().unwrap(),
                self.positions.len()
            ));
        }
        let check = |fields: &[Field], rows: usize, what: &str| {
            fields.iter().try_for_each(|f| {
                if f.values.len() != rows * f.columns {
                    Err(format!(
                        "{what} field '{}' holds {} values, expected {rows} × {}",
                        f.name,
                        f.values.len(),
                        f.columns
                    ))
                } else {
                    Ok(())
                }
            })
        };
        check(&self.vertex_fields, self.vertices(), "vertex")?;
        check(&self.streamline_fields, self.streamlines(), "streamline")?;
        for g in &self.groups {
            if let Some(&i) = g.streamlines.iter().find(|&&i| i as usize >= self.streamlines()) {
                return Err(format!("group '{}' names streamline {i} of {}", g.name, self.streamlines()));
            }
        }
        Ok(())
    }
}

/// Applies a row-major 4 × 4 affine to a point, in f64.
pub fn apply_affine(m: &[[f64; 4]; 4], p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
}

/// The inverse of an affine map (rotation/scale part must be invertible).
pub fn invert_affine(m: &[[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let a = [[m[0][0], m[0][1], m[0][2]], [m[1][0], m[1][1], m[1][2]], [m[2][0], m[2][1], m[2][2]]];
    let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if !det.is_finite() || det.abs() < 1e-12 {
        return None;
    }
    let cof = |r0: usize, r1: usize, c0: usize, c1: usize| a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0];
    let inv = [
        [cof(1, 2, 1, 2) / det, -cof(0, 2, 1, 2) / det, cof(0, 1, 1, 2) / det],
        [-cof(1, 2, 0, 2) / det, cof(0, 2, 0, 2) / det, -cof(0, 1, 0, 2) / det],
        [cof(1, 2, 0, 1) / det, -cof(0, 2, 0, 1) / det, cof(0, 1, 0, 1) / det],
    ];
    let t = [m[0][3], m[1][3], m[2][3]];
    let mut out = IDENTITY;
    for r in 0..3 {
        out[r][..3].copy_from_slice(&inv[r]);
        out[r][3] = -(inv[r][0] * t[0] + inv[r][1] * t[1] + inv[r][2] * t[2]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_streamline_field_spreads_to_its_vertices() {
        let mut t = Tractogram::new();
        t.positions = vec![[0.0; 3]; 5];
        t.offsets = vec![0, 2, 2, 5];
        t.streamline_fields.push(Field { name: "weight".into(), columns: 1, values: vec![1.0, 2.0, 3.0] });
        assert!(t.spread_streamline_field("weight"));
        assert_eq!(t.vertex_field("weight").unwrap().values, [1.0, 1.0, 3.0, 3.0, 3.0]);
        // Once, and never over a per-vertex field of the same name; none where there is none.
        assert!(!t.spread_streamline_field("weight"));
        assert!(!t.spread_streamline_field("length"));
    }
}
