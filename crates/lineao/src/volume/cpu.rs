//! Object-space AO on the CPU (feature `volume`): the grid, trilinear lookups, the probes and
//! [`vertex_visibility`], which runs a [`VolumeMethod`] per vertex ([`super`] explains it).

use glam::Vec3;

use super::{OctantVisibility, ScalarForm, Sky, VolumeMethod, density, geometry_term, octant_signs, sweep, variance};

/// A cubic-voxel grid: `dims` voxels of edge `voxel` from the corner `origin`, x fastest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeGrid {
    /// Voxels along x, y and z.
    pub dims: [usize; 3],
    /// World position of the corner of voxel (0, 0, 0).
    pub origin: Vec3,
    /// Edge length of the cubic voxels, world units.
    pub voxel: f32,
}

impl VolumeGrid {
    /// The number of voxels.
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    /// Whether it has no voxel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Index of voxel (x, y, z) in a field over the grid.
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    /// World position of the centre of voxel (x, y, z).
    pub fn centre(&self, x: usize, y: usize, z: usize) -> Vec3 {
        self.origin + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * self.voxel
    }

    /// Whether `p` lies within the grid's box.
    pub fn contains(&self, p: Vec3) -> bool {
        let q = (p - self.origin) / self.voxel;
        q.cmpge(Vec3::ZERO).all()
            && q.cmplt(Vec3::new(self.dims[0] as f32, self.dims[1] as f32, self.dims[2] as f32)).all()
    }

    /// Trilinear interpolation of `field` at `p` between voxel centres; positions beyond the
    /// outermost centres take the edge's values.
    #[inline]
    pub fn trilinear<T: Interpolate>(&self, field: &[T], p: Vec3) -> T {
        self.trilinear_at(p).sample(field)
    }

    /// Where and how a trilinear lookup at `p` reads.
    #[inline]
    pub fn trilinear_at(&self, p: Vec3) -> Trilinear {
        self.trilinear_texel((p - self.origin) / self.voxel - 0.5)
    }

    /// A trilinear lookup at texel coordinates `q` (voxel (x, y, z)'s centre at q = (x, y, z)).
    #[inline]
    pub fn trilinear_texel(&self, q: Vec3) -> Trilinear {
        let strides = [1, self.dims[0], self.dims[0] * self.dims[1]];
        let (mut base, mut step, mut f) = (0, [0; 3], Vec3::ZERO);
        for axis in 0..3 {
            let n = self.dims[axis];
            // Clamped to [0, n − 1], so truncation is ⌊·⌋ (no libm call) and NaN reads voxel 0.
            let c = q[axis].clamp(0.0, (n - 1) as f32);
            let lo = (c as usize).min(n.saturating_sub(2));
            base += lo * strides[axis];
            step[axis] = if n > 1 { strides[axis] } else { 0 };
            f[axis] = (c - lo as f32).min(1.0);
        }
        Trilinear { base, step, f }
    }
}

/// A trilinear lookup in a field over a [`VolumeGrid`]: the lowest of the eight voxels, the
/// index step to its neighbour along each axis (0 along an axis one voxel long) and the
/// fractions toward them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trilinear {
    /// The index of the voxel at the lower corner.
    pub base: usize,
    /// The index step to the neighbour along each axis.
    pub step: [usize; 3],
    /// The fractions toward the neighbours.
    pub f: Vec3,
}

/// What a field can hold to be interpolated: `f32`, or [`glam::Vec2`] for two moments at once.
pub trait Interpolate: Copy + std::ops::Mul<f32, Output = Self> + std::ops::Add<Output = Self> {}
impl<T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>> Interpolate for T {}

impl Trilinear {
    #[inline]
    /// The value of `field` at the point.
    pub fn sample<T: Interpolate>(&self, field: &[T]) -> T {
        let ([sx, sy, sz], f, i) = (self.step, self.f, self.base);
        let (gx, gy, gz) = (1.0 - f.x, 1.0 - f.y, 1.0 - f.z);
        let (j, k, l) = (i + sy, i + sz, i + sy + sz);
        let near = (field[i] * gx + field[i + sx] * f.x) * gy + (field[j] * gx + field[j + sx] * f.x) * f.y;
        let far = (field[k] * gx + field[k + sx] * f.x) * gy + (field[l] * gx + field[l + sx] * f.x) * f.y;
        near * gz + far * f.z
    }
}

/// View-independent visibility per vertex (see [`ScalarForm`]), with octant weights
/// `sky` (1 = lit, 0 = dark; [`Sky`]). `tangents` are per vertex (any length; zero vectors
/// take the average over all normals).
pub fn scalar_visibility(octants: &[OctantVisibility], tangents: &[Vec3], form: ScalarForm, sky: &Sky) -> Vec<f32> {
    let weights = sky.weights();
    match form {
        ScalarForm::NoGeometryTerm => {
            octants.iter().map(|v| v.iter().zip(weights).map(|(v, w)| v * w).sum::<f32>() / 8.0).collect()
        }
        ScalarForm::AroundTangent => {
            let table = geometry_term::GeometryTable::around_tangent(geometry_term::TABLE_SIZE);
            octants
                .iter()
                .zip(tangents)
                .map(|(v, t)| geometry_term::weighted_visibility(v, &table.lookup(*t), &weights))
                .collect()
        }
    }
}

/// Where octant `o`'s visibility of the vertex at `p` with unit tangent `t` (zero: none) is
/// read: r + h/2 from `p` along the octant's diagonal without its part along `t`.
pub fn probe(volume: &density::DensityVolume, p: Vec3, t: Vec3, o: usize) -> Vec3 {
    let diagonal = octant_signs(o).normalize();
    let across = diagonal - diagonal.dot(t) * t;
    let direction = if across.length_squared() > 1e-6 { across.normalize() } else { t.any_orthonormal_vector() };
    p + direction * (volume.radius + 0.5 * volume.grid.voxel)
}

/// Everything [`vertex_visibility`] needs.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeAoOptions {
    /// Occlusion sweeping or variance occlusion maps.
    pub method: VolumeMethod,
    /// How the density volume is made.
    pub density: density::DensityOptions,
    /// Occlusion sweeping's settings.
    pub sweep: sweep::SweepSettings,
    /// Variance occlusion maps' settings.
    pub variance: variance::VarianceSettings,
    /// `None`: the eight octants stay apart, for the geometry term with each pixel's normal
    /// (the paper's way); `Some`: one view-independent value per vertex.
    pub form: Option<ScalarForm>,
    /// Where the light comes from.
    pub sky: Sky,
}

impl Default for VolumeAoOptions {
    fn default() -> Self {
        VolumeAoOptions {
            method: VolumeMethod::Sweep,
            density: density::DensityOptions::default(),
            sweep: sweep::SweepSettings::default(),
            variance: variance::VarianceSettings::default(),
            form: None,
            sky: Sky::Uniform,
        }
    }
}

/// Per-vertex octant visibilities for [`crate::passes::lines::VertexAttributes`], and the sky
/// the chain then applies per pixel ([`crate::VolumeAoSettings::sky`]).
#[derive(Clone, Debug, PartialEq)]
pub struct VertexVisibility {
    /// Each vertex's eight octant visibilities.
    pub octants: Vec<OctantVisibility>,
    /// The options' sky for the per-pixel form; all ones for a view-independent value, which
    /// holds the sky already (and is stored in all eight octants).
    pub sky: [f32; 8],
}

/// Object-space AO of polylines (`positions` split by `offsets`) in one call: voxelized, swept
/// or mapped, evaluated per vertex.
pub fn vertex_visibility(
    positions: &[[f32; 3]],
    offsets: &[u64],
    options: &VolumeAoOptions,
) -> Result<VertexVisibility, crate::Error> {
    let volume = density::voxelize(positions, offsets, &options.density)?;
    let tangents = vertex_tangents(positions, offsets);
    let octants =
        match options.method {
            VolumeMethod::Sweep => sweep::octant_visibility(&volume, positions, &tangents, &options.sweep)?,
            VolumeMethod::VarianceVolume => variance::VarianceMaps::new(&volume, &options.variance)?
                .octant_visibility(&volume, positions, &tangents, options.variance.threads)?,
        };
    Ok(match options.form {
        None => VertexVisibility { octants, sky: options.sky.weights() },
        Some(form) => VertexVisibility {
            octants: scalar_visibility(&octants, &tangents, form, &options.sky).into_iter().map(|v| [v; 8]).collect(),
            sky: [1.0; 8],
        },
    })
}

/// One tangent per position, or a clear error.
pub(super) fn check_tangents(positions: &[[f32; 3]], tangents: &[Vec3]) -> Result<(), crate::Error> {
    if positions.len() != tangents.len() {
        return Err(crate::Error::InvalidGeometry(format!(
            "{} positions but {} tangents",
            positions.len(),
            tangents.len()
        )));
    }
    Ok(())
}

/// Per-vertex tangents of polylines (central differences, one-sided at the ends; zero for a
/// one-point streamline), unit length.
pub fn vertex_tangents(positions: &[[f32; 3]], offsets: &[u64]) -> Vec<Vec3> {
    let mut tangents = vec![Vec3::ZERO; positions.len()];
    for pair in offsets.windows(2) {
        let (start, end) = (pair[0] as usize, (pair[1] as usize).min(positions.len()));
        for (i, tangent) in tangents.iter_mut().enumerate().take(end).skip(start) {
            let (a, b) = (i.saturating_sub(1).max(start), (i + 1).min(end - 1));
            *tangent = (Vec3::from_array(positions[b]) - Vec3::from_array(positions[a])).normalize_or_zero();
        }
    }
    tangents
}
