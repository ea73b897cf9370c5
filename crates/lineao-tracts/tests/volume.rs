//! NIfTI volumes (`lineao_tracts::Volume`) against what nibabel reads of the shared ones
//! (`../shared/data/FACTS.txt`): shape, affine (sform; the z-map's x axis flipped), value range
//! and a voxel at a stated RAS+ position; the same files rewritten as NIfTI-2; and bad files as
//! typed errors.

use std::path::{Path, PathBuf};

use lineao_tracts::{ErrorKind, Volume};

fn images(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/niivue+niivue/packages/niivue/demos/images")
        .join(name)
}

/// Shape, affine rows, minimum and maximum, and a voxel with its value and RAS+ centre.
struct Fact {
    file: &'static str,
    dims: [usize; 3],
    affine: [[f64; 4]; 3],
    range: [f32; 2],
    voxel: ([usize; 3], f32, [f32; 3]),
}

const FACTS: [Fact; 2] = [
    Fact {
        file: "MNI152_2009_template.nii.gz",
        dims: [193, 229, 193],
        affine: [[1.0, 0.0, 0.0, -96.0], [0.0, 1.0, 0.0, -132.0], [0.0, 0.0, 1.0, -78.0]],
        range: [0.0, 1570.0],
        voxel: ([96, 114, 96], 58.0, [0.0, -18.0, 18.0]),
    },
    Fact {
        file: "strokez.nii.gz",
        dims: [157, 189, 156],
        affine: [[-1.0, 0.0, 0.0, 78.0], [0.0, 1.0, 0.0, -112.0], [0.0, 0.0, 1.0, -70.0]],
        range: [0.0, 1.295],
        voxel: ([78, 94, 78], 0.0, [0.0, -18.0, 8.0]),
    },
];

#[test]
fn the_shared_volumes_are_what_nibabel_reads() {
    for fact in FACTS {
        let v = Volume::load(images(fact.file)).unwrap();
        assert_eq!(v.dims, fact.dims, "{}", fact.file);
        for (r, row) in fact.affine.iter().enumerate() {
            assert_eq!(v.affine.row(r).to_array(), *row, "{}: affine row {r}", fact.file);
        }
        let (lo, hi) = v.values.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        assert_eq!(lo, fact.range[0], "{}", fact.file);
        assert!((hi - fact.range[1]).abs() < 1e-3, "{}: max {hi}", fact.file);
        let (ijk, value, ras) = fact.voxel;
        assert_eq!(v.voxel(ijk), value, "{}", fact.file);
        // At the voxel's centre the trilinear sample is the voxel's value.
        assert_eq!(v.sample(ras), value, "{}", fact.file);
        assert_eq!(v.to_voxel(ras).to_array(), ijk.map(|c| c as f64), "{}", fact.file);
    }
    // The template's voxel at RAS (1, -18, 18) is one step along i (its x axis is not flipped),
    // the z-map's one step back (flipped): the sample halfway is the mean of the two voxels.
    let t = Volume::load(images("MNI152_2009_template.nii.gz")).unwrap();
    let halfway = t.sample([0.5, -18.0, 18.0]);
    assert_eq!(halfway, 0.5 * (t.voxel([96, 114, 96]) + t.voxel([97, 114, 96])));
    let z = Volume::load(images("strokez.nii.gz")).unwrap();
    assert_eq!(z.to_voxel([1.0, -18.0, 8.0]).x, 77.0);
}

#[test]
fn bad_volumes_are_typed_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(images("strokez.nii.gz")).unwrap();
    let mut inflated = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&bytes[..]), &mut inflated).unwrap();
    // Truncated: the header promises more voxels than the file holds.
    let path = dir.path().join("truncated.nii");
    std::fs::write(&path, &inflated[..inflated.len() / 2]).unwrap();
    let e = Volume::load(&path).unwrap_err();
    assert_eq!(e.path, path);
    assert!(matches!(e.kind, ErrorKind::Format { .. }), "{e}");
    assert!(e.to_string().contains("bytes of voxels"), "{e}");
    // Shorter than a header.
    std::fs::write(&path, &inflated[..100]).unwrap();
    assert!(Volume::load(&path).unwrap_err().to_string().contains("NIfTI-1 header"));
    // 4-D: two volumes in time.
    let mut four = inflated.clone();
    four[40..42].copy_from_slice(&4u16.to_le_bytes());
    four[48..50].copy_from_slice(&2u16.to_le_bytes());
    std::fs::write(&path, &four).unwrap();
    assert!(Volume::load(&path).unwrap_err().to_string().contains("a 3-D volume"));
    // A zero sform with its code set: singular.
    let mut singular = inflated.clone();
    singular[280..328].fill(0);
    std::fs::write(&path, &singular).unwrap();
    assert!(Volume::load(&path).unwrap_err().to_string().contains("singular"));
    // An unknown datatype.
    let mut unknown = inflated;
    unknown[70..72].copy_from_slice(&1234i16.to_le_bytes());
    std::fs::write(&path, &unknown).unwrap();
    assert!(Volume::load(&path).unwrap_err().to_string().contains("datatype"));
}

/// `nifti1` (an uncompressed single-file NIfTI-1, little-endian) rewritten as NIfTI-2 by
/// `nifti2.h`'s layout, every field copied by its offset in either header, in `big`-endian
/// order if asked (the voxels swapped too); its voxels start at byte 544.
fn as_nifti2(nifti1: &[u8], big: bool) -> Vec<u8> {
    let i16_at = |at: usize| i16::from_le_bytes([nifti1[at], nifti1[at + 1]]);
    let f32_at = |at: usize| f32::from_le_bytes(nifti1[at..at + 4].try_into().unwrap());
    let mut out = vec![0u8; 544];
    let mut put = |at: usize, le: &[u8]| {
        let bytes: Vec<u8> = if big { le.iter().rev().copied().collect() } else { le.to_vec() };
        out[at..at + bytes.len()].copy_from_slice(&bytes);
    };
    put(0, &540i32.to_le_bytes());
    put(12, &i16_at(70).to_le_bytes()); // datatype
    put(14, &i16_at(72).to_le_bytes()); // bitpix
    for k in 0..8 {
        put(16 + 8 * k, &i64::from(i16_at(40 + 2 * k)).to_le_bytes()); // dim
        put(104 + 8 * k, &f64::from(f32_at(76 + 4 * k)).to_le_bytes()); // pixdim
    }
    put(168, &544i64.to_le_bytes()); // vox_offset
    put(176, &f64::from(f32_at(112)).to_le_bytes()); // scl_slope
    put(184, &f64::from(f32_at(116)).to_le_bytes()); // scl_inter
    put(344, &i32::from(i16_at(252)).to_le_bytes()); // qform_code
    put(348, &i32::from(i16_at(254)).to_le_bytes()); // sform_code
    for k in 0..18 {
        // quatern_b, c, d, qoffset_x, y, z, then srow_x, y, z: one run of floats in both.
        put(352 + 8 * k, &f64::from(f32_at(256 + 4 * k)).to_le_bytes());
    }
    out[4..12].copy_from_slice(b"n+2\0\r\n\x1a\n");
    let start = f32_at(108) as usize;
    let size = (i16_at(72) / 8) as usize;
    for voxel in nifti1[start..].chunks(size) {
        if big {
            out.extend(voxel.iter().rev());
        } else {
            out.extend_from_slice(voxel);
        }
    }
    out
}

fn inflated(name: &str) -> Vec<u8> {
    let bytes = std::fs::read(images(name)).unwrap();
    let mut out = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&bytes[..]), &mut out).unwrap();
    out
}

#[test]
fn a_nifti2_file_is_the_same_volume() {
    for fact in FACTS {
        let nifti1 = inflated(fact.file);
        let expected = Volume::from_bytes(&nifti1, u64::MAX).unwrap();
        for big in [false, true] {
            let nifti2 = as_nifti2(&nifti1, big);
            assert_eq!(&nifti2[4..8], b"n+2\0");
            let got = Volume::from_bytes(&nifti2, u64::MAX).unwrap();
            assert!(got == expected, "{}: NIfTI-2, big-endian {big}", fact.file);
        }
        // And through its qform alone (the template's sform and qform agree: nibabel's FACTS).
        let mut qform_only = as_nifti2(&nifti1, false);
        qform_only[348..352].fill(0);
        let got = Volume::from_bytes(&qform_only, u64::MAX).unwrap();
        let worst = (got.affine - expected.affine).to_cols_array().iter().fold(0.0f64, |m, d| m.max(d.abs()));
        assert!(worst < 1e-6, "{}: qform against sform, {worst}", fact.file);
    }
}

#[test]
fn bad_nifti2_files_are_typed_errors() {
    let nifti2 = as_nifti2(&inflated("strokez.nii.gz"), false);
    let error = |bytes: &[u8]| Volume::from_bytes(bytes, u64::MAX).unwrap_err().to_string();
    assert!(error(&nifti2[..300]).contains("a NIfTI-2 header of 540 bytes"), "{}", error(&nifti2[..300]));
    assert!(error(&nifti2[..nifti2.len() - 1]).contains("bytes of voxels"));
    let mut pair = nifti2.clone();
    pair[4..8].copy_from_slice(b"ni2\0");
    assert!(error(&pair).contains(".hdr/.img pair"), "{}", error(&pair));
    let mut magic = nifti2.clone();
    magic[6] = b'3';
    assert!(error(&magic).contains("at byte 4: expected NIfTI-2's magic"), "{}", error(&magic));
    // An axis of 2^32 voxels: more than the u16 sizes the voxels are read with, not allocated.
    let mut huge = nifti2.clone();
    huge[24..32].copy_from_slice(&(1i64 << 32).to_le_bytes());
    assert!(error(&huge).contains("at byte 16: expected 0 to 65 535 voxels an axis"), "{}", error(&huge));
    let mut negative = nifti2;
    negative[32..40].copy_from_slice(&(-5i64).to_le_bytes());
    assert!(error(&negative).contains("voxels an axis"), "{}", error(&negative));
}

#[test]
fn a_volume_opened_as_a_tractogram_is_told_as_one() {
    // The tractogram's place given a NIfTI file, gzip or not, NIfTI-1 or NIfTI-2.
    let nifti1 = inflated("strokez.nii.gz");
    for (name, bytes) in [
        ("strokez.nii.gz", std::fs::read(images("strokez.nii.gz")).unwrap()),
        ("strokez.nii", nifti1.clone()),
        ("strokez2.nii", as_nifti2(&nifti1, true)),
    ] {
        let e = lineao_tracts::load_from_bytes(&bytes, name, &Default::default()).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::UnknownFormat(_)), "{e}");
        assert!(e.to_string().contains("a NIfTI volume, an image and not streamlines"), "{e}");
    }
}
