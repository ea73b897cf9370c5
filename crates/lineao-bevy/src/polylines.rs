//! Lines as Bevy entities: streamlines, tractograms, field lines, drawn by lineao's line renderer
//! (screen-aligned strips of a fixed width in pixels, the paper's ND and zoom maps) into every
//! camera with a [`crate::LineAo`].

use std::sync::Arc;

use bevy::prelude::*;

/// Polylines in the entity's local space (its [`GlobalTransform`] places them), drawn with the
/// camera's [`LineAo::lines`](crate::LineAo::lines) settings: width in pixels, colouring (the
/// tangent's direction, one colour, or per-vertex scalars through a colormap), lighting, method.
///
/// The data is shared ([`Arc`]): cloning the component copies no points. Changing it, or the
/// entity's transform, uploads every visible polyline again at the next frame (the render world
/// keeps one vertex buffer of all of them in world space).
#[derive(Component, Clone, Debug)]
#[require(Transform, Visibility)]
pub struct Polylines {
    positions: Arc<[[f32; 3]]>,
    offsets: Arc<[u64]>,
    scalars: Option<Arc<[f32]>>,
}

impl Polylines {
    /// Polylines of `positions`, the `i`-th one from `offsets[i]` to `offsets[i + 1]` (so
    /// `offsets` starts at 0 and ends at the number of points, as in .trk/.tck readers). Offsets
    /// out of order or past the points are a [`lineao::Error::InvalidGeometry`].
    pub fn new(positions: Vec<[f32; 3]>, offsets: Vec<u64>) -> Result<Polylines, lineao::Error> {
        lineao::passes::lines::validate_offsets(&offsets, positions.len())?;
        Ok(Polylines { positions: positions.into(), offsets: offsets.into(), scalars: None })
    }

    /// One value per point (FA, a bundle index …), coloured through the `Scalar` line colour's
    /// colormap. A count other than the points' is a [`lineao::Error::InvalidGeometry`].
    pub fn with_scalars(mut self, scalars: Vec<f32>) -> Result<Polylines, lineao::Error> {
        if scalars.len() != self.positions.len() {
            return Err(lineao::Error::InvalidGeometry(format!(
                "{} scalars for {} points",
                scalars.len(),
                self.positions.len()
            )));
        }
        self.scalars = Some(scalars.into());
        Ok(self)
    }

    /// A tractogram or streamline file, any format lineao-tracts reads (.trk, .tck, .tsf, .trx,
    /// .vtk, .vtp, .tt.gz, glTF and OBJ lines, gzip'd or not), in its world (RAS+ mm) space.
    #[cfg(feature = "tracts")]
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Polylines, lineao_tracts::Error> {
        Ok(Polylines::from(lineao_tracts::load(path)?.tractogram))
    }

    /// The points, in the entity's space.
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }

    /// Where each polyline starts, and the number of points last.
    pub fn offsets(&self) -> &[u64] {
        &self.offsets
    }

    /// The per-point scalars, if any.
    pub fn scalars(&self) -> Option<&[f32]> {
        self.scalars.as_deref()
    }

    /// Number of polylines.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Whether there is no polyline.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Which of an entity's [`Polylines`] are shown: one flag per polyline. Selected-out polylines
/// are neither drawn nor occlude. Changing it selects on the GPU (a bit per cluster of points)
/// without uploading the polylines again; removing it shows every polyline.
///
/// A count other than the polylines' shows them all, with a warning.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct PolylineSelection(pub Arc<[bool]>);

impl PolylineSelection {
    /// The polylines `keep` marks (`lineao_tracts::Selection::mask` makes one from a
    /// tractogram: a random share, lengths, fields, groups, regions).
    pub fn new(keep: impl Into<Arc<[bool]>>) -> PolylineSelection {
        PolylineSelection(keep.into())
    }
}

/// Where a tractogram's colours come from ([`Polylines::colored`]): the values that the `Scalar`
/// line colour's colormap turns into colours.
#[cfg(feature = "tracts")]
#[derive(Clone, Copy, Debug)]
pub enum ColorSource<'a> {
    /// A per-vertex field (a .trk scalar, TRX dpv, .tsf) or a per-streamline one (a .trk
    /// property, TRX dps) at each of its vertices.
    Field(&'a str),
    /// The index of each streamline's first TRX group (NaN outside every group): with
    /// [`lineao::Colormap::Categories`] over [0, 15], a colour each.
    Groups,
    /// A volume sampled at each vertex, trilinear through its affine (NaN outside it).
    Volume(&'a lineao_tracts::Volume),
}

#[cfg(feature = "tracts")]
impl Polylines {
    /// `tractogram`'s streamlines, coloured by `source`. A field the tractogram lacks (or of
    /// several columns) is a [`lineao::Error::InvalidGeometry`] listing the fields it has.
    pub fn colored(mut tractogram: lineao_tracts::Tractogram, source: ColorSource) -> Result<Polylines, lineao::Error> {
        let scalars = match source {
            ColorSource::Field(name) => {
                tractogram.spread_streamline_field(name);
                let field = tractogram.vertex_fields.iter().find(|f| f.name == name && f.columns == 1);
                match field {
                    Some(field) => field.values.clone(),
                    None => {
                        let names = tractogram.vertex_fields.iter().chain(&tractogram.streamline_fields);
                        let names: Vec<&str> = names.filter(|f| f.columns == 1).map(|f| f.name.as_str()).collect();
                        return Err(lineao::Error::InvalidGeometry(format!(
                            "no one-column field '{name}' (the tractogram has: {})",
                            if names.is_empty() { "none".into() } else { names.join(", ") }
                        )));
                    }
                }
            }
            ColorSource::Groups => tractogram.group_indices(lineao::COLORMAP_ENTRIES),
            ColorSource::Volume(volume) => volume.sample_points(&tractogram.positions),
        };
        Polylines::from(tractogram).with_scalars(scalars)
    }
}

#[cfg(feature = "tracts")]
impl From<lineao_tracts::Tractogram> for Polylines {
    fn from(tractogram: lineao_tracts::Tractogram) -> Polylines {
        Polylines { positions: tractogram.positions.into(), offsets: tractogram.offsets.into(), scalars: None }
    }
}

#[cfg(all(test, feature = "tracts"))]
mod tests {
    use super::*;
    use lineao_tracts::{Field, Group, Tractogram};

    fn two_lines() -> Tractogram {
        let mut t = Tractogram::new();
        t.positions = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 2.0, 0.0], [0.0, 3.0, 0.0]];
        t.offsets = vec![0, 2, 5];
        t.streamline_fields.push(Field { name: "weight".into(), columns: 1, values: vec![0.5, 2.0] });
        t.groups.push(Group { name: "b".into(), streamlines: vec![1], data: Vec::new() });
        t
    }

    #[test]
    fn a_tractograms_colours_come_from_a_field_its_groups_or_a_volume() {
        let weights = Polylines::colored(two_lines(), ColorSource::Field("weight")).unwrap();
        assert_eq!(weights.scalars().unwrap(), [0.5, 0.5, 2.0, 2.0, 2.0]);
        let groups = Polylines::colored(two_lines(), ColorSource::Groups).unwrap();
        let groups = groups.scalars().unwrap();
        assert!(groups[..2].iter().all(|g| g.is_nan()) && groups[2..] == [0.0; 3], "{groups:?}");
        // A 2 × 2 × 2 volume of x + 10 y + 100 z at unit voxels: trilinear at the points.
        let values = (0..8).map(|i| ((i & 1) + 10 * ((i >> 1) & 1) + 100 * (i >> 2)) as f32).collect();
        let volume = lineao_tracts::Volume::new([2, 2, 2], values, lineao::glam::DMat4::IDENTITY).unwrap();
        let sampled = Polylines::colored(two_lines(), ColorSource::Volume(&volume)).unwrap();
        let sampled = sampled.scalars().unwrap();
        assert_eq!(sampled[..3], [0.0, 1.0, 10.0]);
        assert!(sampled[3].is_nan(), "outside the volume: {sampled:?}");
        let error = Polylines::colored(two_lines(), ColorSource::Field("fa")).unwrap_err().to_string();
        assert!(error.contains("no one-column field 'fa'") && error.contains("weight"), "{error}");
    }
}
