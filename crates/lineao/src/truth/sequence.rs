//! The rays' sample sequence: the first two dimensions of Sobol', Owen-scrambled per pixel with
//! Burley's hash-based nested uniform scramble ("Practical Hash-based Owen Scrambling", JCGT
//! 2020). Any power-of-two prefix of the sequence puts exactly one point in each elementary
//! interval of that size (it is *stratified*), and the scramble keeps that property while making
//! every pixel's points an independent random draw, so the estimate is unbiased and its error
//! shrinks faster than 1/√N. Everything is 32-bit integer arithmetic: the GPU ray tracer
//! reproduces the same rays bit for bit, with a frame index continuing the sequence.

use glam::DVec3;

/// A small integer hash (PCG's output permutation, as in Jarzynski & Olano, JCGT 2020).
pub fn hash(x: u32) -> u32 {
    let state = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The seed of pixel (x, y) — coordinates relative to the visible viewport's top-left, so the
/// guard band does not move the rays — for the run's `seed`.
pub fn pixel_seed(x: i32, y: i32, seed: u32) -> u32 {
    hash(seed ^ hash((x as u32).wrapping_add(hash(y as u32))))
}

/// Laine and Karras' permutation: flips each bit depending only on the bits below it.
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen's nested uniform scramble of a 32-bit fraction: each bit flipped depending on the bits
/// above it.
fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// Sobol' points 0 and 1 of `index` as 32-bit fractions: dimension 0 is the radical inverse in
/// base 2, dimension 1 uses the direction numbers of the polynomial x + 1 (v_k = v_{k−1} ⊕
/// v_{k−1} ≫ 1).
fn sobol_2d(index: u32) -> (u32, u32) {
    let mut y = 0u32;
    let mut v = 1u32 << 31;
    let mut i = index;
    while i != 0 {
        if i & 1 != 0 {
            y ^= v;
        }
        v ^= v >> 1;
        i >>= 1;
    }
    (index.reverse_bits(), y)
}

/// The `index`-th point of the pixel's scrambled sequence in [0, 1)².
pub fn sample_2d(index: u32, pixel_seed: u32) -> [f64; 2] {
    let (x, y) = sobol_2d(index);
    let sx = hash(pixel_seed);
    let sy = hash(sx);
    let scale = 1.0 / 4_294_967_296.0;
    [nested_uniform_scramble(x, sx) as f64 * scale, nested_uniform_scramble(y, sy) as f64 * scale]
}

/// A third dimension for the VO truth's radii: the radical inverse, scrambled with a seed of
/// its own (independent of [`sample_2d`]'s).
pub fn sample_1d(index: u32, pixel_seed: u32) -> f64 {
    let seed = hash(hash(hash(pixel_seed)));
    nested_uniform_scramble(index.reverse_bits(), seed) as f64 / 4_294_967_296.0
}

/// An orthonormal basis (t, b) around the unit `n` without branches (Duff et al., JCGT 2017).
pub fn basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), DVec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// Shirley and Chiu's concentric map of the unit square onto the unit disk (area-preserving,
/// so strata stay strata).
pub fn concentric_disk(u: [f64; 2]) -> [f64; 2] {
    let (a, b) = (2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    if a == 0.0 && b == 0.0 {
        return [0.0, 0.0];
    }
    let quarter = std::f64::consts::FRAC_PI_4;
    let (r, phi) = if a.abs() > b.abs() { (a, quarter * (b / a)) } else { (b, 2.0 * quarter - quarter * (a / b)) };
    [r * phi.cos(), r * phi.sin()]
}

/// A cosine-weighted direction about the unit normal `n` (Malley's method: the disk lifted to
/// the hemisphere).
pub fn cosine_direction(u: [f64; 2], n: DVec3) -> DVec3 {
    let [x, y] = concentric_disk(u);
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    let (t, b) = basis(n);
    (t * x + b * y + n * z).normalize()
}

/// A uniformly distributed direction on the sphere, or on the hemisphere about `n` when `half`.
pub fn uniform_direction(u: [f64; 2], n: DVec3, half: bool) -> DVec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u[1];
    let d = DVec3::new(r * phi.cos(), r * phi.sin(), z);
    if half && d.dot(n) < 0.0 { -d } else { d }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_of_two_prefixes_are_stratified() {
        // 256 points: one in each cell of the 16 × 16 grid, and of 256 × 1 and 1 × 256 strips
        // (the (0, 2)-net property), for several pixels.
        for seed in [0, 1, 12345] {
            let points: Vec<[f64; 2]> = (0..256).map(|i| sample_2d(i, pixel_seed(3, seed, 9))).collect();
            for (nx, ny) in [(16, 16), (256, 1), (1, 256), (2, 128), (128, 2)] {
                let mut cells = vec![0; nx * ny];
                for p in &points {
                    cells[(p[1] * ny as f64) as usize * nx + (p[0] * nx as f64) as usize] += 1;
                }
                assert!(cells.iter().all(|&c| c == 1), "{nx} x {ny}, seed {seed}");
            }
        }
    }

    #[test]
    fn pixels_get_different_points() {
        let a = sample_2d(0, pixel_seed(0, 0, 1));
        let b = sample_2d(0, pixel_seed(1, 0, 1));
        let c = sample_2d(0, pixel_seed(0, 0, 2));
        assert!(a != b && a != c);
    }

    #[test]
    fn cosine_weighting_has_the_right_moments() {
        // E[cos θ] = 2/3 under the cosine-weighted density; every direction in the hemisphere.
        let n = DVec3::new(0.3, -0.5, 0.8).normalize();
        let count = 4096;
        let mean: f64 = (0..count)
            .map(|i| {
                let d = cosine_direction(sample_2d(i, 77), n);
                assert!((d.length() - 1.0).abs() < 1e-12 && d.dot(n) >= 0.0);
                d.dot(n)
            })
            .sum::<f64>()
            / count as f64;
        assert!((mean - 2.0 / 3.0).abs() < 1e-3, "{mean}");
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [DVec3::Z, -DVec3::Z, DVec3::X, DVec3::new(1.0, 2.0, -3.0).normalize()] {
            let (t, b) = basis(n);
            for (u, v) in [(t, b), (t, n), (b, n)] {
                assert!(u.dot(v).abs() < 1e-12);
            }
            assert!((t.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
        }
    }
}
