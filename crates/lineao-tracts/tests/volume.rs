//! NIfTI volumes (`lineao_tracts::Volume`) against what nibabel reads of the shared ones
//! (`../shared/data/FACTS.txt`): shape, affine (sform; the z-map's x axis flipped), value range
//! and a voxel at a stated RAS+ position; and bad files as typed errors.

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
