//! **Volumes** in NIfTI-1 or NIfTI-2 (`.nii`, `.nii.gz`), read by the `nifti` crate (NIfTI-2's
//! header by our own code, which the crate lacks) and placed in RAS+ millimetres as nibabel
//! places them, and sampled along streamlines.
//!
//! **Headers**: NIfTI-2 (2011, for HCP's CIFTI and large grids) is NIfTI-1's header with its
//! sizes, offsets and geometry widened to 64 bits and reordered, 540 bytes against 348; which
//! one a file holds, and its byte order, is read from `sizeof_hdr`, as nibabel does. Either
//! becomes one `Header` of the fields the placement and the voxels need.
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
use num_traits::FromPrimitive;

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

/// Which NIfTI a header is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Version {
    Nifti1,
    Nifti2,
}

impl Version {
    /// The header's size (`sizeof_hdr`): the voxels start there at the earliest.
    fn header_bytes(self) -> usize {
        match self {
            Version::Nifti1 => 348,
            Version::Nifti2 => 540,
        }
    }

    /// Where `dim` lies in the header.
    fn dim_offset(self) -> u64 {
        match self {
            Version::Nifti1 => 40,
            Version::Nifti2 => 16,
        }
    }
}

/// What placing a volume and reading its voxels take from its header, NIfTI-1's or NIfTI-2's
/// (the same fields, NIfTI-2's widened to 64 bits and reordered).
struct Header {
    version: Version,
    dim: [i64; 8],
    datatype: i16,
    pixdim: [f64; 8],
    vox_offset: f64,
    scl_slope: f64,
    scl_inter: f64,
    qform_code: i32,
    sform_code: i32,
    /// `quatern_b`, `quatern_c`, `quatern_d`, then `qoffset_x`, `qoffset_y`, `qoffset_z`.
    quatern: [f64; 6],
    /// `srow_x`, `srow_y`, `srow_z`.
    srow: [[f64; 4]; 3],
    endianness: nifti::Endianness,
}

/// NIfTI-2's magic for a single file (`n+2` and a line-ending check); `ni2` is a `.hdr` whose
/// voxels are in an `.img` beside it.
const NIFTI2_MAGIC: &[u8; 8] = b"n+2\0\r\n\x1a\n";
const NIFTI2_PAIR_MAGIC: &[u8; 8] = b"ni2\0\r\n\x1a\n";

/// Whether `head` (a file's first bytes, inflated) begins a NIfTI-1 or NIfTI-2 header with its
/// magic: a volume handed where streamlines were asked for is told as one.
pub(crate) fn is_nifti(head: &[u8]) -> bool {
    let Some(&sizeof_hdr) = head.first_chunk::<4>() else { return false };
    let sizes = [i32::from_le_bytes(sizeof_hdr), i32::from_be_bytes(sizeof_hdr)];
    let nifti1 = sizes.contains(&348) && matches!(head.get(344..348), Some(b"n+1\0" | b"ni1\0"));
    let nifti2 =
        sizes.contains(&540) && matches!(head.get(4..12), Some(m) if m == NIFTI2_MAGIC || m == NIFTI2_PAIR_MAGIC);
    nifti1 || nifti2
}

impl Header {
    /// The header at the start of `bytes`: NIfTI-2 where `sizeof_hdr` reads 540 in either byte
    /// order, else NIfTI-1 (348), read by the `nifti` crate.
    fn read(bytes: &[u8]) -> Result<Header, ErrorKind> {
        let Some(&sizeof_hdr) = bytes.first_chunk::<4>() else {
            return bad(bytes.len() as u64, "a NIfTI header");
        };
        let nifti2 = Version::Nifti2.header_bytes() as i32;
        if i32::from_le_bytes(sizeof_hdr) == nifti2 {
            return Header::nifti2(bytes, nifti::Endianness::Little);
        }
        if i32::from_be_bytes(sizeof_hdr) == nifti2 {
            return Header::nifti2(bytes, nifti::Endianness::Big);
        }
        let size = Version::Nifti1.header_bytes();
        if bytes.len() < size {
            return bad(bytes.len() as u64, format!("a NIfTI-1 header of {size} bytes"));
        }
        let h = nifti::NiftiHeader::from_reader(&bytes[..size])
            .map_err(|e| ErrorKind::Format { offset: 0, expected: format!("a NIfTI-1 header ({e})") })?;
        let wide = |values: [f32; 4]| values.map(f64::from);
        Ok(Header {
            version: Version::Nifti1,
            dim: h.dim.map(i64::from),
            datatype: h.datatype,
            pixdim: h.pixdim.map(f64::from),
            vox_offset: h.vox_offset.into(),
            scl_slope: h.scl_slope.into(),
            scl_inter: h.scl_inter.into(),
            qform_code: h.qform_code.into(),
            sform_code: h.sform_code.into(),
            quatern: [h.quatern_b, h.quatern_c, h.quatern_d, h.quatern_x, h.quatern_y, h.quatern_z].map(f64::from),
            srow: [wide(h.srow_x), wide(h.srow_y), wide(h.srow_z)],
            endianness: h.endianness,
        })
    }

    /// A NIfTI-2 header (`nifti2.h`'s layout). Ours: the `nifti` crate reads NIfTI-1 alone
    /// (nifti-rs#89; its pull request #96 is not merged), and NIfTI-2's header is NIfTI-1's
    /// fields at fixed offsets, so the crate still decodes the voxels.
    fn nifti2(bytes: &[u8], endianness: nifti::Endianness) -> Result<Header, ErrorKind> {
        let size = Version::Nifti2.header_bytes();
        if bytes.len() < size {
            return bad(bytes.len() as u64, format!("a NIfTI-2 header of {size} bytes"));
        }
        match &bytes[4..12] {
            magic if magic == NIFTI2_MAGIC => {}
            magic if magic == NIFTI2_PAIR_MAGIC => {
                return Err(ErrorKind::Unsupported(
                    "a NIfTI-2 header whose voxels are in another file (`ni2`, an .hdr/.img pair): \
                     a single .nii (`n+2`) is read"
                        .into(),
                ));
            }
            _ => return bad(4, "NIfTI-2's magic \"n+2\\0\\r\\n\\x1a\\n\""),
        }
        let big = endianness == nifti::Endianness::Big;
        let word = |at: usize| -> [u8; 8] { bytes[at..at + 8].try_into().expect("within the header") };
        let i64_at = |at: usize| if big { i64::from_be_bytes(word(at)) } else { i64::from_le_bytes(word(at)) };
        let f64_at = |at: usize| if big { f64::from_be_bytes(word(at)) } else { f64::from_le_bytes(word(at)) };
        let i32_at = |at: usize| {
            let b: [u8; 4] = bytes[at..at + 4].try_into().expect("within the header");
            if big { i32::from_be_bytes(b) } else { i32::from_le_bytes(b) }
        };
        let datatype = [bytes[12], bytes[13]];
        Ok(Header {
            version: Version::Nifti2,
            dim: std::array::from_fn(|k| i64_at(16 + 8 * k)),
            datatype: if big { i16::from_be_bytes(datatype) } else { i16::from_le_bytes(datatype) },
            pixdim: std::array::from_fn(|k| f64_at(104 + 8 * k)),
            vox_offset: i64_at(168) as f64,
            scl_slope: f64_at(176),
            scl_inter: f64_at(184),
            qform_code: i32_at(344),
            sform_code: i32_at(348),
            quatern: std::array::from_fn(|k| f64_at(352 + 8 * k)),
            srow: std::array::from_fn(|row| std::array::from_fn(|col| f64_at(400 + 32 * row + 8 * col))),
            endianness,
        })
    }
}

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

    /// Reads a NIfTI-1 or NIfTI-2 file (`.nii`, or `.nii.gz` by its content).
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

    /// A NIfTI-1 or NIfTI-2 file's bytes (gzip-wrapped or not), inflating at most `max_inflated` bytes.
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
        let header = Header::read(bytes)?;
        let dim = header.dim;
        let rank = dim[0];
        // 4-D and up only where every further axis is 1.
        if !(1..=7).contains(&rank) || dim[4..=rank.max(3) as usize].iter().any(|&d| d != 1) {
            let shown = &dim[..=rank.clamp(0, 7) as usize];
            return bad(header.version.dim_offset(), format!("a 3-D volume (dim {shown:?})"));
        }
        // The crate's volumes hold u16 sizes (NIfTI-1's); NIfTI-2's are 64 bits.
        let dims = [1, 2, 3].map(|a| if a <= rank { u16::try_from(dim[a as usize]).ok() } else { Some(1) });
        let [Some(i), Some(j), Some(k)] = dims else {
            return bad(header.version.dim_offset(), format!("0 to 65 535 voxels an axis (dim {:?})", &dim[1..4]));
        };
        let dims = [i, j, k].map(usize::from);
        let datatype = nifti::NiftiType::from_i16(header.datatype)
            .ok_or_else(|| ErrorKind::Unsupported(format!("datatype {}", header.datatype)))?;
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
        let start = header.vox_offset.max(header.version.header_bytes() as f64) as usize;
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
        let volume = nifti::volume::InMemNiftiVolume::from_raw_fields(
            raw_dim,
            datatype,
            slope as f32,
            inter as f32,
            raw,
            header.endianness,
        )
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

    /// [`Volume::sample`] at every point, on every core (on this thread for fewer than 2^14).
    pub fn sample_points(&self, points: &[[f32; 3]]) -> Vec<f32> {
        let mut out = vec![0.0f32; points.len()];
        let sample_all = |points: &[[f32; 3]], out: &mut [f32]| {
            for (p, o) in points.iter().zip(out) {
                *o = self.sample(*p);
            }
        };
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(16);
        let chunk = points.len().div_ceil(threads).max(1 << 14);
        if points.len() <= chunk {
            sample_all(points, &mut out);
            return out;
        }
        std::thread::scope(|scope| {
            for (points, out) in points.chunks(chunk).zip(out.chunks_mut(chunk)) {
                scope.spawn(move || sample_all(points, out));
            }
        });
        out
    }
}

/// nibabel's `get_best_affine`: sform, else qform, else the voxel sizes about the centre.
fn best_affine(h: &Header, dims: [usize; 3]) -> DMat4 {
    let zooms = [1, 2, 3].map(|a| if h.pixdim[a].is_finite() && h.pixdim[a] != 0.0 { h.pixdim[a] } else { 1.0 });
    if h.sform_code != 0 {
        let [x, y, z] = h.srow.map(DVec4::from_array);
        return DMat4::from_cols(x, y, z, DVec4::W).transpose();
    }
    if h.qform_code != 0 {
        let [b, c, d, qx, qy, qz] = h.quatern;
        let a = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
        let rotation = glam::DMat3::from_cols_array_2d(&[
            [a * a + b * b - c * c - d * d, 2.0 * (b * c + a * d), 2.0 * (b * d - a * c)],
            [2.0 * (b * c - a * d), a * a + c * c - b * b - d * d, 2.0 * (c * d + a * b)],
            [2.0 * (b * d + a * c), 2.0 * (c * d - a * b), a * a + d * d - c * c - b * b],
        ]);
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let scale = glam::DMat3::from_diagonal(DVec3::new(zooms[0], zooms[1], zooms[2] * qfac));
        let offset = DVec3::new(qx, qy, qz);
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
