//! The random vectors of LineAO's Monte-Carlo sampling (paper §3.4, docs/reference.md "Noise").
//!
//! R1 is a 64 × 64 tile of unit vectors repeated over the image (indexed by the pixel's position
//! relative to the visible viewport's top-left corner), R2 a table `samples[j][i]` of unit vectors
//! per hemisphere j and sample i. The sampling direction is ω = reflect(R1(P), `R2[j][i]`), so
//! neighbouring pixels and different hemispheres never share a direction.
//!
//! Both come from a PCG hash of (seed, stream, index) in our own code, never from an RNG crate's
//! stream, so that outside tools can regenerate them from `noise_seed` and the values never
//! change with a dependency update.

/// Side of the R1 tile.
pub const NOISE_SIZE: usize = 64;

/// One round of the PCG-RXS-M-XS 32-bit permutation (O'Neill 2014), used as a hash.
pub fn pcg_hash(input: u32) -> u32 {
    let state = input.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// A uniform number in [0, 1) for (seed, stream, index), with 24 bits of resolution.
pub fn uniform(seed: u32, stream: u32, index: u32) -> f32 {
    let h = pcg_hash(seed.wrapping_mul(0x9E37_79B9) ^ pcg_hash(stream ^ pcg_hash(index)));
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// A unit vector uniformly distributed on the sphere (Archimedes: z uniform in [-1, 1]).
pub fn unit_vector(seed: u32, stream: u32, index: u32) -> [f32; 3] {
    let z = 1.0 - 2.0 * uniform(seed, stream, 2 * index);
    let phi = std::f32::consts::TAU * uniform(seed, stream, 2 * index + 1);
    let r = (1.0 - z * z).max(0.0).sqrt();
    [r * phi.cos(), r * phi.sin(), z]
}

const STREAM_R1: u32 = 1;
const STREAM_R2: u32 = 2;

/// R1: `noise[y * 64 + x]`.
pub fn noise_tile(seed: u32) -> Vec<[f32; 3]> {
    (0..(NOISE_SIZE * NOISE_SIZE) as u32).map(|i| unit_vector(seed, STREAM_R1, i)).collect()
}

/// R2: `samples[j * s_h + i]` for j < s_r, i < s_h. Only i < `count(j)` is used (⌈s_h/(j+1)⌉ for
/// the paper, s_h for the authors' code); the rest are zero so that the table reads the same as
/// docs/reference.md's zero-padded `samples.npy`.
pub fn sample_table(seed: u32, s_r: u32, s_h: u32, count: impl Fn(u32) -> u32) -> Vec<[f32; 3]> {
    let mut table = vec![[0.0; 3]; (s_r * s_h) as usize];
    for j in 0..s_r {
        for i in 0..count(j).min(s_h) {
            let index = j * s_h + i;
            table[index as usize] = unit_vector(seed, STREAM_R2, index);
        }
    }
    table
}

const STREAM_SSAO_KERNEL: u32 = 3;
const STREAM_SSAO_NOISE: u32 = 4;
/// Side of the SSAO rotation tile (Crytek's 4 × 4, matched by its 4 × 4 blur).
pub const SSAO_NOISE_SIZE: usize = 4;

/// The SSAO kernel: `n` points inside the unit sphere, directions uniform, lengths
/// 0.1 + 0.9 (i/n)² so that more samples sit near the centre, where occluders matter most.
pub fn ssao_kernel(seed: u32, n: u32) -> Vec<[f32; 3]> {
    (0..n)
        .map(|i| {
            let t = (i + 1) as f32 / n as f32;
            let scale = 0.1 + 0.9 * t * t;
            unit_vector(seed, STREAM_SSAO_KERNEL, i).map(|c| c * scale)
        })
        .collect()
}

/// The 4 × 4 rotation tile, `noise[y * 4 + x]`: unit vectors the kernel is reflected about.
pub fn ssao_noise(seed: u32) -> Vec<[f32; 3]> {
    (0..(SSAO_NOISE_SIZE * SSAO_NOISE_SIZE) as u32).map(|i| unit_vector(seed, STREAM_SSAO_NOISE, i)).collect()
}

const STREAM_VO_NOISE: u32 = 5;

/// VO's 4 × 4 tile of unit 2D directions, `noise[y * 4 + x]`: each pixel reflects its disk
/// samples about its direction (§4.5: "a reflection about a random direction in 2D").
pub fn vo_noise(seed: u32) -> Vec<[f32; 2]> {
    (0..(SSAO_NOISE_SIZE * SSAO_NOISE_SIZE) as u32)
        .map(|i| {
            let phi = std::f32::consts::TAU * uniform(seed, STREAM_VO_NOISE, i);
            [phi.cos(), phi.sin()]
        })
        .collect()
}

/// n_j = ⌈s_h / (j + 1)⌉ (Eq. 7): the harmonic series of samples per hemisphere.
pub fn samples_on_hemisphere(s_h: u32, j: u32) -> u32 {
    s_h.div_ceil(j + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_vectors_are_unit_and_cover_the_sphere() {
        let tile = noise_tile(1);
        let mut mean = [0.0f64; 3];
        for v in &tile {
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-5, "{v:?}");
            for k in 0..3 {
                mean[k] += v[k] as f64 / tile.len() as f64;
            }
        }
        // 4096 uniform unit vectors: each mean coordinate has sd 1/sqrt(3 * 4096) ≈ 0.009.
        assert!(mean.iter().all(|m| m.abs() < 0.04), "{mean:?}");
    }

    #[test]
    fn default_counts_are_the_papers_59_samples() {
        let total: u32 = (0..3).map(|j| samples_on_hemisphere(32, j)).sum();
        assert_eq!(total, 32 + 16 + 11);
        // Computed as the program runs (an argument the compiler could see might be folded into
        // constants with the compiler's own cos and sin, an ulp from the library's).
        let seed = std::hint::black_box(1);
        let table = sample_table(seed, 3, 32, |j| samples_on_hemisphere(32, j));
        assert_eq!(table[32 + 15], unit_vector(seed, STREAM_R2, 32 + 15));
        assert_eq!(table[32 + 16], [0.0; 3]);
        let full = sample_table(seed, 3, 32, |_| 32);
        assert_eq!(full[..32 + 16], table[..32 + 16]);
        assert_eq!(full[32 + 16], unit_vector(seed, STREAM_R2, 32 + 16));
    }

    #[test]
    fn seeds_differ() {
        assert_ne!(noise_tile(1)[0], noise_tile(2)[0]);
        assert_eq!(noise_tile(7), noise_tile(7));
    }
}
