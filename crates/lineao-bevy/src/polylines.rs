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

#[cfg(feature = "tracts")]
impl From<lineao_tracts::Tractogram> for Polylines {
    fn from(tractogram: lineao_tracts::Tractogram) -> Polylines {
        Polylines { positions: tractogram.positions.into(), offsets: tractogram.offsets.into(), scalars: None }
    }
}
