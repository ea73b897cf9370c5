//! CPU reference of `shaders/volume_ao.wgsl` (`lineao::passes::volume_ao`).

use glam::{Mat3, Vec3};

use super::{Image, NdImage};
use crate::volume::OctantVisibility;
use crate::volume::geometry_term::{GeometryTable, weighted_visibility};

/// The eight octant visibilities of a texel of the `octants` target (`pack4x8unorm` of octants
/// 0–3 and 4–7, x in the low byte).
pub fn unpack_octants(packed: [u32; 2]) -> OctantVisibility {
    std::array::from_fn(|o| (packed[o / 4] >> (8 * (o % 4)) & 0xff) as f32 / 255.0)
}

/// ao = 1 − Σ_o w_o V_o G_o(N) / Σ_o G_o(N) per pixel, N the ND map's normal rotated to world
/// space by `view_to_world`; background 0.
pub fn volume_ao(
    nd: &NdImage,
    octants: &Image<[u32; 2]>,
    table: &GeometryTable,
    view_to_world: Mat3,
    weights: [f32; 8],
) -> Image<f32> {
    Image::from_fn(nd.width, nd.height, |x, y| {
        let [nx, ny, nz, _] = nd.get(x, y);
        if [nx, ny, nz] == [0.0; 3] {
            return 0.0;
        }
        let n = view_to_world * Vec3::new(nx, ny, nz);
        let v = unpack_octants(octants.get(x, y));
        1.0 - weighted_visibility(&v, &table.lookup(n), &weights)
    })
}
