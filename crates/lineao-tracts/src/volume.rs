//! **Volumes** in NIfTI-1 (`.nii`, `.nii.gz`), read by the `nifti` crate and placed in RAS+
//! millimetres as nibabel places them, and sampled along streamlines.
//!
//! **Placement** (nibabel's `get_best_affine`): the sform where `sform_code` is set, else the
//! qform (the quaternion, its offsets and the voxel sizes, the third axis flipped where
//! `pixdim[0]` is negative) where `qform_code` is set, else the voxel sizes about the volume's
//! centre with x flipped (Analyze's convention). The affine maps voxel *indices* to millimetres:
//! voxel (i, j, k)'s centre lies at `affine · (i, j, k, 1)`.
//!
//! **Values**: the data type converted to f32 through the crate, scaled by `scl_slope` and
//! `scl_inter` where the slope is finite and not zero (nibabel's rule: NaN or 0 means none).
//!
//! **Sampling** ([`Volume::sample`]): trilinear between voxel centres, a point mapped to voxel
//! coordinates through the inverse affine (in f64); NaN outside the box of the voxel centres —
//! the same numbers as `scipy.ndimage.map_coordinates(data, ijk, order=1, cval=nan)` on
//! nibabel's array, which the Python tests check.
//!
//! The file is read whole (gzip inflated up to the loaders' limit: 256 MiB or 64 × its size) and
//! its declared size checked against the bytes there before anything is allocated by it.

use std::io::Read;
use std::path::Path;

use glam::{DMat4, DVec3, DVec4};

use crate::error::{Error, ErrorKind, bad};

/// A 3-D scalar volume in RAS+ millimetres.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Voxels along i, j, k.
    pub dims: [usize; 3],
    /// Values, i fastest (NIfTI's order).
    pub values: Vec<f32>,
    /// Voxel indices → RAS+ mm.
    pub affine: DMat4,
    to_voxel: DMat4,
}

/// Bytes of a NIfTI-1 header.
const HEADER_BYTES: usize = 348;

impl Volume {
    /// A volume of `dims` voxels (`values` i fastest) placed by `affine`; an error where the
    /// sizes disagree or the affine cannot be inverted.
    pub fn new(dims: [usize; 3], values: Vec<f32>, affine: DMat4) -> Result<Volume, ErrorKind> {
        if dims.iter().product::<usize>() != values.len() || dims.contains(&0) {
            return Err(ErrorKind::Unsupported(format!("{dims:?} voxels with {} values", values.len())));
        }
        let determinant = affine.determinant();
        if !determinant.is_finite() || determinant.abs() < 1e-12 || !affine.is_finite() {
            return Err(ErrorKind::Unsupported(format!(
                "a volume whose affine is singular or not finite (determinant {determinant})"
            )));
        }
        Ok(Volume { dims, values, affine, to_voxel: affine.inverse() })
    }

    /// Reads a NIfTI-1 file (`.nii`, or `.nii.gz` by its content).
    pub fn load(path: impl AsRef<Path>) -> Result<Volume, Error> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|e| ErrorKind::Io(e).at(path))?;
        // The loaders' limit: 256 MiB or 64 × the file, whichever is larger.
        let limit = (256u64 << 20).max((bytes.len() as u64).saturating_mul(64));
        Volume::from_bytes(&bytes, limit).map_err(|kind| kind.at(path))
    }

    /// Whether a file's name is a NIfTI volume's (`.nii`, `.nii.gz`, any case): what a viewer
    /// that is handed files opens as the anatomy.
    pub fn is_nifti_name(name: &str) -> bool {
        let name = name.to_ascii_lowercase();
        name.ends_with(".nii") || name.ends_with(".nii.gz")
    }

    /// A NIfTI-1 file's bytes (gzip-wrapped or not), inflating at most `max_inflated` bytes.
    pub fn from_bytes(bytes: &[u8], max_inflated: u64) -> Result<Volume, ErrorKind> {
        let inflated;
        let bytes = if bytes.starts_with(&[0x1f, 0x8b]) {
            let mut out = Vec::new();
            let mut decoder = flate2::read::MultiGzDecoder::new(bytes).take(max_inflated.saturating_add(1));
            decoder
                .read_to_end(&mut out)
                .map_err(|e| ErrorKind::Format { offset: out.len() as u64, expected: format!("gzip data ({e})") })?;
            if out.len() as u64 > max_inflated {
                return Err(ErrorKind::TooLarge { offset: max_inflated, limit: max_inflated });
            }
            inflated = out;
            &inflated[..]
        } else {
            bytes
        };
        if bytes.len() < HEADER_BYTES {
            return bad(bytes.len() as u64, format!("a NIfTI-1 header of {HEADER_BYTES} bytes"));
        }
        let header = nifti::NiftiHeader::from_reader(&bytes[..HEADER_BYTES])
            .map_err(|e| ErrorKind::Format { offset: 0, expected: format!("a NIfTI-1 header ({e})") })?;
        let dim = header.dim;
        let rank = dim[0] as usize;
        // 4-D and up only where every further axis is 1.
        if !(1..=7).contains(&rank) || dim[4..=rank.max(3)].iter().any(|&d| d != 1) {
            return bad(40, format!("a 3-D volume (dim {:?})", &dim[..=rank.min(7)]));
        }
        let dims = [0, 1, 2].map(|a| if a < rank { dim[a + 1] as usize } else { 1 });
        let datatype =
            header.data_type().map_err(|_| ErrorKind::Unsupported(format!("datatype {}", header.datatype)))?;
        if matches!(
            datatype,
            nifti::NiftiType::Rgb24
                | nifti::NiftiType::Rgba32
                | nifti::NiftiType::Complex64
                | nifti::NiftiType::Complex128
        ) || datatype.size_of() == 0
        {
            return Err(ErrorKind::Unsupported(format!("a volume of {datatype:?} values (scalars only)")));
        }
        let start = header.vox_offset.max(HEADER_BYTES as f32) as usize;
        let voxels = dims.iter().product::<usize>();
        let size = voxels.saturating_mul(datatype.size_of());
        if bytes.len() < start || bytes.len() - start < size {
            return bad(
                bytes.len() as u64,
                format!("{size} bytes of voxels from byte {start} ({dims:?} {datatype:?})"),
            );
        }
        // NaN or 0 slope: no scaling (nibabel); the crate would scale by it.
        let (slope, inter) = match header.scl_slope {
            s if s.is_finite() && s != 0.0 => (s, if header.scl_inter.is_finite() { header.scl_inter } else { 0.0 }),
            _ => (0.0, 0.0),
        };
        let mut raw_dim = [1u16; 8];
        raw_dim[0] = 3;
        raw_dim[1..4].copy_from_slice(&dims.map(|d| d as u16));
        let raw = bytes[start..start + size].to_vec();
        let volume =
            nifti::volume::InMemNiftiVolume::from_raw_fields(raw_dim, datatype, slope, inter, raw, header.endianness)
                .map_err(|e| ErrorKind::Format { offset: start as u64, expected: format!("voxels ({e})") })?;
        use nifti::IntoNdArray;
        let array = volume
            .into_ndarray::<f32>()
            .map_err(|e| ErrorKind::Format { offset: start as u64, expected: format!("voxels ({e})") })?;
        // The transposed array's logical order: i fastest, as NIfTI stores them.
        let values = array.t().iter().copied().collect::<Vec<f32>>();
        Volume::new(dims, values, best_affine(&header, dims))
    }

    /// The value of voxel (i, j, k).
    pub fn voxel(&self, [i, j, k]: [usize; 3]) -> f32 {
        self.values[i + self.dims[0] * (j + self.dims[1] * k)]
    }

    /// The axis-aligned box (min, max) in RAS+ mm around the voxel centres.
    pub fn world_box(&self) -> ([f32; 3], [f32; 3]) {
        let last = self.dims.map(|d| d.saturating_sub(1) as f64);
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for c in 0..8 {
            let corner = DVec3::new(
                if c & 1 != 0 { last[0] } else { 0.0 },
                if c & 2 != 0 { last[1] } else { 0.0 },
                if c & 4 != 0 { last[2] } else { 0.0 },
            );
            let p = self.affine.transform_point3(corner);
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        (lo.as_vec3().to_array(), hi.as_vec3().to_array())
    }

    /// RAS+ mm → voxel coordinates (voxel centres at whole numbers).
    pub fn to_voxel(&self, p: [f32; 3]) -> DVec3 {
        self.to_voxel.transform_point3(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
    }

    /// The trilinear value at `p` (RAS+ mm) between voxel centres; NaN outside them.
    pub fn sample(&self, p: [f32; 3]) -> f32 {
        let v = self.to_voxel(p);
        let mut base = [0usize; 3];
        let mut frac = [0f64; 3];
        for a in 0..3 {
            let last = (self.dims[a] - 1) as f64;
            let c = v[a];
            if !(0.0..=last).contains(&c) {
                return f32::NAN;
            }
            // The upper corner of the last cell is the last voxel (weight 0 beyond it).
            let b = (c.floor() as usize).min(self.dims[a].saturating_sub(2));
            base[a] = b;
            frac[a] = c - b as f64;
        }
        let mut sum = 0.0f64;
        for corner in 0..8 {
            let mut weight = 1.0;
            let mut at = base;
            for a in 0..3 {
                let up = (corner >> a) & 1 == 1;
                if up {
                    weight *= frac[a];
                    at[a] = (at[a] + 1).min(self.dims[a] - 1);
                } else {
                    weight *= 1.0 - frac[a];
                }
            }
            if weight != 0.0 {
                sum += weight * self.voxel(at) as f64;
            }
        }
        sum as f32
    }

    /// [`Volume::sample`] at every point, on every core.
    pub fn sample_points(&self, points: &[[f32; 3]]) -> Vec<f32> {
        let mut out = vec![0.0f32; points.len()];
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(16);
        let chunk = points.len().div_ceil(threads).max(1 << 14);
        std::thread::scope(|scope| {
            for (points, out) in points.chunks(chunk).zip(out.chunks_mut(chunk)) {
                scope.spawn(move || {
                    for (p, o) in points.iter().zip(out) {
                        *o = self.sample(*p);
                    }
                });
            }
        });
        out
    }
}

/// nibabel's `get_best_affine`: sform, else qform, else the voxel sizes about the centre.
fn best_affine(h: &nifti::NiftiHeader, dims: [usize; 3]) -> DMat4 {
    let zooms = [1, 2, 3].map(|a| if h.pixdim[a].is_finite() && h.pixdim[a] != 0.0 { h.pixdim[a] as f64 } else { 1.0 });
    if h.sform_code != 0 {
        let row = |r: [f32; 4]| DVec4::from_array(r.map(f64::from));
        return DMat4::from_cols(row(h.srow_x), row(h.srow_y), row(h.srow_z), DVec4::W).transpose();
    }
    if h.qform_code != 0 {
        let (b, c, d) = (h.quatern_b as f64, h.quatern_c as f64, h.quatern_d as f64);
        let a = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
        let rotation = glam::DMat3::from_cols_array_2d(&[
            [a * a + b * b - c * c - d * d, 2.0 * (b * c + a * d), 2.0 * (b * d - a * c)],
            [2.0 * (b * c - a * d), a * a + c * c - b * b - d * d, 2.0 * (c * d + a * b)],
            [2.0 * (b * d + a * c), 2.0 * (c * d - a * b), a * a + d * d - c * c - b * b],
        ]);
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let scale = glam::DMat3::from_diagonal(DVec3::new(zooms[0], zooms[1], zooms[2] * qfac));
        let offset = DVec3::new(h.quatern_x as f64, h.quatern_y as f64, h.quatern_z as f64);
        return DMat4::from_mat3(rotation * scale)
            + DMat4::from_cols(DVec4::ZERO, DVec4::ZERO, DVec4::ZERO, offset.extend(0.0));
    }
    let origin = dims.map(|n| (n as f64 - 1.0) / 2.0);
    DMat4::from_cols(
        DVec4::new(-zooms[0], 0.0, 0.0, 0.0),
        DVec4::new(0.0, zooms[1], 0.0, 0.0),
        DVec4::new(0.0, 0.0, zooms[2], 0.0),
        DVec4::new(origin[0] * zooms[0], -origin[1] * zooms[1], -origin[2] * zooms[2], 1.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A volume of `dims` whose value is linear in the voxel indices, placed by `affine`.
    fn linear(dims: [usize; 3], affine: DMat4) -> Volume {
        let mut values = Vec::new();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    values.push((2 * i + 3 * j) as f32 - 0.5 * k as f32);
                }
            }
        }
        Volume::new(dims, values, affine).unwrap()
    }

    #[test]
    fn trilinear_sampling_is_exact_on_linear_data_and_nan_outside() {
        // 2 mm voxels, x flipped, shifted.
        let affine = DMat4::from_cols(
            DVec4::new(-2.0, 0.0, 0.0, 0.0),
            DVec4::new(0.0, 2.0, 0.0, 0.0),
            DVec4::new(0.0, 0.0, 2.0, 0.0),
            DVec4::new(30.0, -40.0, -10.0, 1.0),
        );
        let v = linear([8, 9, 7], affine);
        for &(i, j, k) in &[(0.0, 0.0, 0.0), (3.25, 4.5, 1.75), (7.0, 8.0, 6.0), (6.999, 0.001, 5.5)] {
            let p = affine.transform_point3(DVec3::new(i, j, k)).as_vec3().to_array();
            let expected = 2.0 * i + 3.0 * j - 0.5 * k;
            assert!((v.sample(p) as f64 - expected).abs() < 1e-4, "{i} {j} {k}: {}", v.sample(p));
        }
        for &(i, j, k) in &[(-0.01, 1.0, 1.0), (7.01, 1.0, 1.0), (1.0, 1.0, 6.5)] {
            let p = affine.transform_point3(DVec3::new(i, j, k)).as_vec3().to_array();
            assert!(v.sample(p).is_nan(), "{i} {j} {k}");
        }
        assert_eq!(v.sample_points(&[[30.0, -40.0, -10.0]; 3]), vec![0.0; 3]);
    }

    #[test]
    fn a_singular_affine_or_wrong_sizes_are_errors() {
        assert!(Volume::new([2, 2, 2], vec![0.0; 8], DMat4::ZERO).is_err());
        assert!(Volume::new([2, 2, 2], vec![0.0; 7], DMat4::IDENTITY).is_err());
    }
}
