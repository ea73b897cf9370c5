//! The VO paper's generator of the sample sets (feature `reference`): Poisson starts relaxed
//! by 1/d⁴ repulsion, the set with the most even Voronoi volumes kept. The checked-in tables
//! (`tables.rs`) come from it (`examples/gen_vo_samples.rs`).

use crate::noise;

const STREAM: u32 = 7;

type Point<const D: usize> = [f64; D];

fn distance_sq<const D: usize>(a: &Point<D>, b: &Point<D>) -> f64 {
    (0..D).map(|k| (a[k] - b[k]).powi(2)).sum()
}

fn length<const D: usize>(a: &Point<D>) -> f64 {
    a.iter().map(|c| c * c).sum::<f64>().sqrt()
}

/// Centres of the cells of a `res`^D grid over [−1, 1]^D that fall inside the unit ball, each
/// with the volume it stands for: the sphere's z extent 2√(1 − r²) over a disk cell (the disk
/// is the sphere seen along z), 1 for a cell of the ball itself.
fn ball_cells<const D: usize>(res: usize) -> Vec<(Point<D>, f64)> {
    let mut cells = Vec::new();
    for index in 0..res.pow(D as u32) {
        let mut rest = index;
        let p: Point<D> = std::array::from_fn(|_| {
            let i = rest % res;
            rest /= res;
            -1.0 + (i as f64 + 0.5) * 2.0 / res as f64
        });
        let r2: f64 = p.iter().map(|c| c * c).sum();
        if r2 < 1.0 {
            cells.push((p, if D == 2 { 2.0 * (1.0 - r2).sqrt() } else { 1.0 }));
        }
    }
    cells
}

/// Each sample's Voronoi volume and weighted centroid, from a discrete diagram.
fn voronoi<const D: usize>(points: &[Point<D>], cells: &[(Point<D>, f64)]) -> (Vec<f64>, Vec<Point<D>>) {
    let mut volume = vec![0.0; points.len()];
    let mut centroid = vec![[0.0; D]; points.len()];
    for (c, w) in cells {
        let nearest = (0..points.len())
            .min_by(|&a, &b| distance_sq(&points[a], c).total_cmp(&distance_sq(&points[b], c)))
            .expect("at least one point");
        volume[nearest] += w;
        for k in 0..D {
            centroid[nearest][k] += w * c[k];
        }
    }
    for (c, v) in centroid.iter_mut().zip(&volume) {
        if *v > 0.0 {
            *c = c.map(|ck| ck / v);
        }
    }
    (volume, centroid)
}

/// How far a set is from the goal: the relative spread of the Voronoi volumes, plus the mean
/// distance of each point from its region's weighted centroid in units of the point spacing
/// (equal volumes alone are met by pie slices with every point on the rim, where a line sample
/// has no chord; the centroid term is what the paper's boundary charge and centroid pushes
/// enforce).
fn error<const D: usize>(points: &[Point<D>], cells: &[(Point<D>, f64)]) -> f64 {
    let (volume, centroid) = voronoi(points, cells);
    let n = volume.len() as f64;
    let spacing = n.powf(-1.0 / D as f64);
    let off_centre = points.iter().zip(&centroid).map(|(p, c)| distance_sq(p, c).sqrt()).sum::<f64>() / n;
    volume_spread(&volume) + off_centre / spacing
}

/// Standard deviation of the volumes over their mean.
fn volume_spread(volume: &[f64]) -> f64 {
    let n = volume.len() as f64;
    let mean = volume.iter().sum::<f64>() / n;
    (volume.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt() / mean
}

/// A uniformly distributed point of the unit ball from the hash stream at `index`.
fn ball_point<const D: usize>(start: u32, index: u32) -> Point<D> {
    let u = |k: u32| noise::uniform(start, STREAM, index + k) as f64;
    let phi = std::f64::consts::TAU * u(1);
    let mut p = [0.0; D];
    if D == 2 {
        let r = u(0).sqrt();
        (p[0], p[1]) = (r * phi.cos(), r * phi.sin());
    } else {
        let (r, z) = (u(0).cbrt(), 1.0 - 2.0 * u(2));
        let ring = (1.0 - z * z).max(0.0).sqrt();
        (p[0], p[1], p[2]) = (r * ring * phi.cos(), r * ring * phi.sin(), r * z);
    }
    p
}

/// Poisson-disk dart throwing in the unit ball (minimum distance relaxed until n fit).
fn poisson<const D: usize>(n: u32, start: u32) -> Vec<Point<D>> {
    let mut radius = 1.6 / (n as f64).powf(1.0 / D as f64);
    let mut index = 0u32;
    loop {
        let mut points: Vec<Point<D>> = Vec::new();
        for _ in 0..2000 {
            let p = ball_point::<D>(start, index);
            index += D as u32;
            if points.iter().all(|q| distance_sq(q, &p).sqrt() >= radius) {
                points.push(p);
                if points.len() == n as usize {
                    return points;
                }
            }
        }
        radius *= 0.9;
    }
}

/// One repulsion step of size `step`: 1/d⁴ forces, points kept inside the ball.
fn repel<const D: usize>(points: &[Point<D>], step: f64) -> Vec<Point<D>> {
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut f = [0.0; D];
            for (j, q) in points.iter().enumerate() {
                if i != j {
                    let d: Point<D> = std::array::from_fn(|k| p[k] - q[k]);
                    let scale = 1.0 / length(&d).max(1e-9).powi(5); // |F| = 1/d⁴ along d/|d|
                    for k in 0..D {
                        f[k] += d[k] * scale;
                    }
                }
            }
            let norm = length(&f).max(1e-12);
            let moved: Point<D> = std::array::from_fn(|k| p[k] + step * f[k] / norm);
            let r = length(&moved);
            if r > 0.999 { moved.map(|c| c * 0.999 / r) } else { moved }
        })
        .collect()
}

/// The paper's optimisation on a coarse discrete Voronoi diagram: the best of 12 Poisson starts,
/// each relaxed by 60 steps of repulsion with a centroid push every tenth.
fn optimise<const D: usize>(n: u32, coarse: &[(Point<D>, f64)]) -> Vec<Point<D>> {
    let mut best: Option<(f64, Vec<Point<D>>)> = None;
    for start in 0..12 {
        let mut points = poisson::<D>(n, start);
        let mut err = error(&points, coarse);
        let mut step = 0.05;
        for iteration in 0..60 {
            let candidate = if iteration % 10 == 9 {
                voronoi(&points, coarse).1 // the periodic push to the weighted centroids
            } else {
                repel(&points, step)
            };
            let candidate_err = error(&candidate, coarse);
            if candidate_err < err {
                (points, err) = (candidate, candidate_err);
                step *= 1.2;
            } else {
                step *= 0.5;
            }
        }
        if best.as_ref().is_none_or(|(e, _)| err < *e) {
            best = Some((err, points));
        }
    }
    best.expect("at least one start").1
}

/// Generates the N-sample disk set: (x, y, A_i).
pub fn generate_vo_disk_samples(n: u32) -> Vec<[f32; 3]> {
    let points = optimise::<2>(n, &ball_cells(128));
    let (volume, _) = voronoi(&points, &ball_cells(512));
    let chord = |p: Point<2>| 2.0 * (1.0 - p[0] * p[0] - p[1] * p[1]).max(0.0).sqrt();
    let raw: Vec<f64> = points.iter().zip(&volume).map(|(p, v)| v / chord(*p)).collect();
    let total: f64 = points.iter().zip(&raw).map(|(p, a)| a * chord(*p)).sum();
    let normalize = 4.0 / 3.0 * std::f64::consts::PI / total;
    points.iter().zip(raw).map(|(p, a)| [p[0] as f32, p[1] as f32, (a * normalize) as f32]).collect()
}

/// Generates the N-point sphere set (§4.5's point samples), optimised on a 32³ diagram; every
/// point stands for an equal share of the ball, so the points carry no weights.
pub fn generate_vo_sphere_samples(n: u32) -> Vec<[f32; 3]> {
    optimise::<3>(n, &ball_cells(32)).iter().map(|p| p.map(|c| c as f32)).collect()
}

/// Relative spread (standard deviation over mean) of the Voronoi volumes of `points` in the
/// unit ball, on a `res`³ diagram: how evenly a point set shares the sphere.
pub fn sphere_volume_spread(points: &[[f32; 3]], res: usize) -> f64 {
    let points: Vec<Point<3>> = points.iter().map(|p| p.map(f64::from)).collect();
    volume_spread(&voronoi(&points, &ball_cells(res)).0)
}
