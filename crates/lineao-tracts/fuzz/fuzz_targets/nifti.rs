#![no_main]
// NIfTI-1 and NIfTI-2 volumes (gzip-wrapped or not): whatever comes back is consistent — a value
// for every voxel, an affine that inverts — and sampling it at its first voxel's centre and at
// points the input picks neither panics nor reads outside it. Inflating is capped so the
// fuzzer's memory stays bounded.
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(volume) = lineao_tracts::Volume::from_bytes(data, 16 << 20) else {
        return;
    };
    assert_eq!(volume.values.len(), volume.dims.iter().product::<usize>(), "a value for every voxel");
    assert!(volume.affine.is_finite() && volume.affine.determinant() != 0.0, "an affine that inverts");
    let first = volume.affine.w_axis.truncate().as_vec3().to_array();
    let mut points: Vec<[f32; 3]> = data
        .chunks_exact(12)
        .take(64)
        .map(|c| std::array::from_fn(|k| f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap())))
        .collect();
    points.push(first);
    assert_eq!(volume.sample_points(&points).len(), points.len());
});
