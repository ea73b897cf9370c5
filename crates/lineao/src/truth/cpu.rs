//! The ground truth's ray tracer on the CPU (feature `truth`): the frame's primitives, the
//! rays from each geometry pixel, and the VO truth ([`super`] explains what and why).

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use glam::{DVec3, Mat4, Vec3};

use super::{Bvh, EPSILON_PER_DISTANCE, Falloff, Prim, Reach, RoundedCone, Triangle, TruthSettings, VoBall, sequence};
use crate::Error;
use crate::camera::FrameView;
use crate::image::{Image, NdImage};

impl Reach {
    /// A ray's value for a first hit at `t` (none: no hit within any reach traced).
    fn value(self, t: Option<f64>) -> f64 {
        let distance = self.distance_world as f64;
        match (t, self.falloff) {
            (Some(t), Falloff::None) if t <= distance => 1.0,
            (Some(t), Falloff::Linear) if t <= distance => 1.0 - t / distance,
            _ => 0.0,
        }
    }
}

/// How the frame draws its streamlines, which decides their volumes.
#[derive(Clone, Copy, Debug)]
pub enum LineShape<'a> {
    /// Fixed-width lines of this many pixels.
    Lines {
        /// The width in pixels.
        width_px: f32,
    },
    /// Tubes of this radius, per vertex from `radii` where it has a positive value.
    Tubes {
        /// The radius, world units.
        radius_world: f32,
        /// Per vertex, where positive.
        radii: Option<&'a [f32]>,
    },
}

/// The sphere-swept segments of fixed-width lines in `view`: radius (w/2)·(−z_view)/f_px at
/// each vertex (orthographic: (w/2)/f_px). Segments with a non-finite end are left out.
pub fn line_cones(positions: &[[f32; 3]], offsets: &[u64], view: &FrameView, width_px: f32) -> Vec<RoundedCone> {
    let half = 0.5 * width_px / view.f_px;
    // Behind or at the camera a line has no finite on-screen width; the depth range's near
    // plane bounds everything the frame shows.
    let radius = |p: Vec3| {
        if view.orthographic { half } else { half * (-view.view.transform_point3(p).z).max(view.near) }
    };
    segments(positions, offsets, |_, p| radius(p))
}

/// The rounded cones of tubes: `radii[v]` where positive and finite, else `radius_world`.
pub fn tube_cones(
    positions: &[[f32; 3]],
    offsets: &[u64],
    radius_world: f32,
    radii: Option<&[f32]>,
) -> Vec<RoundedCone> {
    segments(positions, offsets, |v, _| match radii.and_then(|r| r.get(v)) {
        Some(&r) if r > 0.0 && r.is_finite() => r,
        _ => radius_world,
    })
}

fn segments(positions: &[[f32; 3]], offsets: &[u64], radius: impl Fn(usize, Vec3) -> f32) -> Vec<RoundedCone> {
    let mut cones = Vec::with_capacity(positions.len());
    for (s, range) in offsets.windows(2).enumerate() {
        let (start, end) = (range[0] as usize, (range[1] as usize).min(positions.len()));
        for v in start..end.saturating_sub(1) {
            let (a, b) = (Vec3::from(positions[v]), Vec3::from(positions[v + 1]));
            if !(a.is_finite() && b.is_finite()) {
                continue;
            }
            let (ra, rb) = (radius(v, a), radius(v + 1, b));
            cones.push(RoundedCone { a, b, ra, rb, streamline: s as u32, segment: (v - start) as u32 });
        }
    }
    cones
}

/// The triangles of a mesh.
pub fn mesh_triangles(positions: &[[f32; 3]], indices: &[u32]) -> Vec<Triangle> {
    indices
        .chunks_exact(3)
        .filter_map(|t| {
            let v = [positions.get(t[0] as usize)?, positions.get(t[1] as usize)?, positions.get(t[2] as usize)?];
            Some(Triangle { v: v.map(|p| Vec3::from(*p)) })
        })
        .collect()
}

/// The truth over one G-buffer, at its (guard-banded) size.
#[derive(Clone, Debug)]
pub struct Truth {
    /// AO (or obscurance) per pixel; 0 on background.
    pub ao: Image<f32>,
    /// Its standard error; 0 on background and on buried pixels.
    pub stderr: Image<f32>,
    /// The VO truth when asked for.
    pub vo: Option<Image<f32>>,
    /// The second estimate ([`TruthSettings::second`]) when asked for; 1 on buried pixels too.
    pub second: Option<Image<f32>>,
    /// Geometry pixels, and those whose origin was buried in another primitive.
    pub geometry_pixels: usize,
    /// Geometry pixels whose origin was buried in another primitive.
    pub buried: usize,
    /// Rays traced (and VO points tested).
    pub rays: u64,
}

impl Truth {
    /// The share of geometry pixels whose origin was buried.
    pub fn buried_share(&self) -> f64 {
        if self.geometry_pixels == 0 { 0.0 } else { self.buried as f64 / self.geometry_pixels as f64 }
    }
}

/// What a traced pixel needs of the frame.
pub struct Frame<'a> {
    /// The ND map (level 0, guard-banded).
    pub nd: &'a NdImage,
    /// The view it was drawn with.
    pub view: &'a FrameView,
    /// Whether the streamlines are fixed-width lines (their pixels lie inside their volume).
    pub lines: bool,
}

/// Where one pixel's rays start and what they ignore.
struct Origin {
    /// On the surface; rays leave from `surface + ε n`.
    surface: DVec3,
    normal: DVec3,
    /// The pixel's own segment (lines): its streamline, index and axis point.
    own: Option<(u32, u32, DVec3)>,
}

impl Origin {
    fn skips(&self, bvh: &Bvh, prim: Prim) -> bool {
        match (self.own, prim) {
            (Some((streamline, segment, c)), Prim::Cone(i)) => {
                let cone = &bvh.cones[i as usize];
                cone.streamline == streamline && (cone.segment.abs_diff(segment) <= 1 || cone.distance(c) < 0.0)
            }
            _ => false,
        }
    }
}

/// Computes the truth of `frame` against `bvh`. `progress(done, total)` is called after each row
/// (from worker threads); `cancel` stops the work between rows with [`Error::Cancelled`].
pub fn compute(
    bvh: &Bvh,
    frame: &Frame,
    settings: &TruthSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &AtomicBool,
) -> Result<Truth, Error> {
    settings.validate()?;
    let (width, height) = (frame.nd.width, frame.nd.height);
    let threads = match settings.threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    };
    let tracer = Tracer::new(bvh, frame, settings);
    let next_row = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let rows: Mutex<Vec<Option<Row>>> = Mutex::new(vec![None; height]);
    std::thread::scope(|scope| {
        for _ in 0..threads.min(height.max(1)) {
            scope.spawn(|| {
                loop {
                    if cancel.load(Ordering::Relaxed) {
                        return;
                    }
                    let y = next_row.fetch_add(1, Ordering::Relaxed);
                    if y >= height {
                        return;
                    }
                    let row = tracer.row(y);
                    rows.lock().expect("a truth worker panicked")[y] = Some(row);
                    progress(done.fetch_add(1, Ordering::Relaxed) + 1, height);
                }
            });
        }
    });
    if cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    let rows = rows.into_inner().expect("a truth worker panicked");
    let mut truth = Truth {
        ao: Image::filled(width, height, 0.0),
        stderr: Image::filled(width, height, 0.0),
        vo: settings.vo.map(|_| Image::filled(width, height, 0.0)),
        second: settings.second.map(|_| Image::filled(width, height, 0.0)),
        geometry_pixels: 0,
        buried: 0,
        rays: 0,
    };
    for (y, row) in rows.into_iter().enumerate() {
        let row = row.ok_or(Error::Cancelled)?;
        let span = y * width..(y + 1) * width;
        truth.ao.data[span.clone()].copy_from_slice(&row.ao);
        truth.stderr.data[span.clone()].copy_from_slice(&row.stderr);
        if let Some(vo) = &mut truth.vo {
            vo.data[span.clone()].copy_from_slice(&row.vo);
        }
        if let Some(second) = &mut truth.second {
            second.data[span].copy_from_slice(&row.second);
        }
        truth.geometry_pixels += row.geometry;
        truth.buried += row.buried;
        truth.rays += row.rays;
    }
    Ok(truth)
}

#[derive(Clone)]
struct Row {
    ao: Vec<f32>,
    stderr: Vec<f32>,
    vo: Vec<f32>,
    second: Vec<f32>,
    geometry: usize,
    buried: usize,
    rays: u64,
}

/// One frame's rays: the camera's inverse matrices and the settings.
struct Tracer<'a> {
    bvh: &'a Bvh,
    frame: &'a Frame<'a>,
    settings: &'a TruthSettings,
    inv_proj: Mat4,
    inv_view: glam::DMat4,
    epsilon: f64,
}

impl<'a> Tracer<'a> {
    fn new(bvh: &'a Bvh, frame: &'a Frame<'a>, settings: &'a TruthSettings) -> Self {
        Tracer {
            bvh,
            frame,
            settings,
            inv_proj: frame.view.proj.inverse(),
            inv_view: frame.view.view.as_dmat4().inverse(),
            epsilon: EPSILON_PER_DISTANCE * settings.distance_world as f64,
        }
    }

    fn row(&self, y: usize) -> Row {
        let width = self.frame.nd.width;
        let vo = self.settings.vo.is_some();
        let mut row = Row {
            ao: vec![0.0; width],
            stderr: vec![0.0; width],
            vo: if vo { vec![0.0; width] } else { Vec::new() },
            second: if self.settings.second.is_some() { vec![0.0; width] } else { Vec::new() },
            geometry: 0,
            buried: 0,
            rays: 0,
        };
        for x in 0..width {
            let texel = self.frame.nd.get(x, y);
            if texel[0] == 0.0 && texel[1] == 0.0 && texel[2] == 0.0 {
                continue;
            }
            row.geometry += 1;
            let origin = self.origin(x, y, texel);
            let guard = self.frame.view.guard as i32;
            let seed = sequence::pixel_seed(x as i32 - guard, y as i32 - guard, self.settings.seed);
            if let Some(ball) = self.settings.vo {
                row.vo[x] = vo_at(self.bvh, origin.surface, origin.normal, self.settings, seed, ball) as f32;
                row.rays += self.settings.rays as u64;
            }
            let start = origin.surface + self.epsilon * origin.normal;
            if self.bvh.inside_cone(start, |p| origin.skips(self.bvh, p)) {
                row.ao[x] = 1.0;
                if let Some(second) = row.second.get_mut(x) {
                    *second = 1.0;
                }
                row.buried += 1;
                continue;
            }
            let skip = |p| origin.skips(self.bvh, p);
            let (mean, stderr) = match self.settings.second {
                Some(reach) => {
                    let (mean, stderr, second) =
                        two_reaches_at(self.bvh, start, origin.normal, self.settings, reach, seed, skip);
                    row.second[x] = second as f32;
                    (mean, stderr)
                }
                None => ao_at(self.bvh, start, origin.normal, self.settings, seed, skip),
            };
            row.ao[x] = mean as f32;
            row.stderr[x] = stderr as f32;
            row.rays += self.settings.rays as u64;
        }
        row
    }

    /// The pixel's world position and normal, and for a line pixel its own segment.
    fn origin(&self, x: usize, y: usize, texel: [f32; 4]) -> Origin {
        let view = self.frame.view;
        let (ray_o, ray_d) = crate::reference::tubes::pixel_ray(view, self.inv_proj, [x as u32, y as u32]);
        let z_view = -(view.near as f64 + texel[3] as f64 * (view.far as f64 - view.near as f64));
        let (ray_o, ray_d) = (ray_o.as_dvec3(), ray_d.as_dvec3());
        let p_view = ray_o + ray_d * ((z_view - ray_o.z) / ray_d.z);
        let p = self.inv_view.transform_point3(p_view);
        let normal =
            self.inv_view.transform_vector3(DVec3::new(texel[0] as f64, texel[1] as f64, texel[2] as f64)).normalize();
        if !self.frame.lines {
            return Origin { surface: p, normal, own: None };
        }
        // The segment holding p most deeply, within a pixel's footprint of its surface.
        let footprint = if view.orthographic { 1.0 } else { -z_view } / view.f_px as f64;
        let mut own: Option<(f64, u32)> = None;
        self.bvh.cones_near(p, footprint, |i| {
            let d = self.bvh.cones[i as usize].distance(p);
            if d < footprint && own.is_none_or(|(best, _)| d < best) {
                own = Some((d, i));
            }
        });
        match own {
            Some((_, i)) => {
                let cone = &self.bvh.cones[i as usize];
                let (c, r) = cone.axis_point(cone.axis_parameter(p));
                Origin { surface: c + r * normal, normal, own: Some((cone.streamline, cone.segment, c)) }
            }
            // Not a line's pixel: a surface's.
            None => Origin { surface: p, normal, own: None },
        }
    }
}

/// The AO at `start` (already offset from the surface) with normal `n`: the mean and standard
/// error of N ray values (module doc), ignoring what `skip` names.
pub fn ao_at(
    bvh: &Bvh,
    start: DVec3,
    n: DVec3,
    settings: &TruthSettings,
    seed: u32,
    skip: impl Fn(Prim) -> bool + Copy,
) -> (f64, f64) {
    let distance = settings.distance_world as f64;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for i in 0..settings.rays {
        let d = sequence::cosine_direction(sequence::sample_2d(i, seed), n);
        let value = match settings.falloff {
            Falloff::None => bvh.any_hit(start, d, distance, skip) as u32 as f64,
            Falloff::Linear => bvh.nearest_hit(start, d, distance, skip).map_or(0.0, |(t, _)| 1.0 - t / distance),
        };
        sum += value;
        sum2 += value * value;
    }
    mean_and_stderr(sum, sum2, settings.rays)
}

/// The mean of `count` values and its standard error s/√N (s the sample standard deviation),
/// from their sum and the sum of their squares.
fn mean_and_stderr(sum: f64, sum2: f64, count: u32) -> (f64, f64) {
    let count = count as f64;
    let mean = sum / count;
    let variance = if count > 1.0 { ((sum2 - count * mean * mean) / (count - 1.0)).max(0.0) } else { 0.0 };
    (mean, (variance / count).sqrt())
}

/// [`ao_at`] and, from the same rays, the mean of the second estimate `second`: each ray traced
/// once to the larger reach, both values from its first hit.
fn two_reaches_at(
    bvh: &Bvh,
    start: DVec3,
    n: DVec3,
    settings: &TruthSettings,
    second: Reach,
    seed: u32,
    skip: impl Fn(Prim) -> bool + Copy,
) -> (f64, f64, f64) {
    let first = Reach { distance_world: settings.distance_world, falloff: settings.falloff };
    let reach = first.distance_world.max(second.distance_world) as f64;
    let (mut sum, mut sum2, mut sum_second) = (0.0, 0.0, 0.0);
    for i in 0..settings.rays {
        let d = sequence::cosine_direction(sequence::sample_2d(i, seed), n);
        let t = bvh.nearest_hit(start, d, reach, skip).map(|(t, _)| t);
        let value = first.value(t);
        sum += value;
        sum2 += value * value;
        sum_second += second.value(t);
    }
    let (mean, stderr) = mean_and_stderr(sum, sum2, settings.rays);
    (mean, stderr, sum_second / settings.rays as f64)
}

/// The occupied share of the ball (or half ball above the tangent plane of `n`) of radius R
/// around the surface point `centre`, from N uniformly distributed points.
pub fn vo_at(bvh: &Bvh, centre: DVec3, n: DVec3, settings: &TruthSettings, seed: u32, ball: VoBall) -> f64 {
    let distance = settings.distance_world as f64;
    let closed_surfaces = !bvh.triangles.is_empty();
    let mut occupied = 0u32;
    for i in 0..settings.rays {
        let d = sequence::uniform_direction(sequence::sample_2d(i, seed), n, ball == VoBall::Half);
        let q = centre + d * (distance * sequence::sample_1d(i, seed).cbrt());
        let inside = bvh.inside_cone(q, |_| false) || (closed_surfaces && bvh.triangle_crossings(q, DVec3::X) % 2 == 1);
        occupied += inside as u32;
    }
    occupied as f64 / settings.rays as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 12 triangles of the box [lo, hi].
    fn cuboid(lo: Vec3, hi: Vec3) -> Vec<Triangle> {
        let c = |i: usize| Vec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][(i >> 1) & 1], [lo.z, hi.z][i >> 2]);
        let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
        faces
            .iter()
            .flat_map(|f| [Triangle { v: [c(f[0]), c(f[1]), c(f[2])] }, Triangle { v: [c(f[0]), c(f[2]), c(f[3])] }])
            .collect()
    }

    fn settings(rays: u32) -> TruthSettings {
        TruthSettings { rays, distance_world: 1.0, ..TruthSettings::default() }
    }

    fn ao(bvh: &Bvh, surface: DVec3, n: DVec3, rays: u32, seed: u32) -> (f64, f64) {
        let s = settings(rays);
        let start = surface + EPSILON_PER_DISTANCE * s.distance_world as f64 * n;
        ao_at(bvh, start, n, &s, seed, |_| false)
    }

    const BIG: f32 = 1000.0;

    #[test]
    fn facing_a_wall_binary_ao_is_one_minus_h_over_r_squared() {
        // A wall at z = h above a point whose normal faces it: rays at angle θ hit within R iff
        // cos θ > h / R, which the cosine-weighted density gives with probability 1 − (h/R)².
        for h in [0.2f32, 0.5, 0.8] {
            let wall = Bvh::build(Vec::new(), cuboid(Vec3::new(-BIG, -BIG, h), Vec3::new(BIG, BIG, h + 10.0)));
            let (mean, stderr) = ao(&wall, DVec3::ZERO, DVec3::Z, 4096, 5);
            let h = h as f64 - EPSILON_PER_DISTANCE;
            let expected = 1.0 - h * h;
            assert!((mean - expected).abs() < 3.0 * stderr, "h {h}: {mean} vs {expected} ± {stderr}");
            // The standard error shrinks as 1/√N.
            let (_, coarse) = ao(&wall, DVec3::ZERO, DVec3::Z, 256, 5);
            let ratio = coarse / stderr;
            assert!((ratio - 4.0).abs() < 0.4, "h {h}: stderr ratio {ratio} for 16 × the rays");
        }
    }

    #[test]
    fn the_foot_of_a_right_angle_crease_is_half_occluded_and_an_open_plane_not_at_all() {
        let floor = cuboid(Vec3::new(-BIG, -BIG, -10.0), Vec3::new(BIG, BIG, 0.0));
        let wall = cuboid(Vec3::new(-10.0, -BIG, -10.0), Vec3::new(0.0, BIG, BIG));
        let crease = Bvh::build(Vec::new(), [floor.clone(), wall].concat());
        // On the floor, a hair from the wall, the normal up: the wall blocks the half of the
        // hemisphere toward it.
        let (mean, stderr) = ao(&crease, DVec3::new(1e-4, 0.3, 0.0), DVec3::Z, 4096, 9);
        assert!((mean - 0.5).abs() < 3.0 * stderr, "{mean} ± {stderr}");
        let plane = Bvh::build(Vec::new(), floor);
        assert_eq!(ao(&plane, DVec3::new(0.1, 0.2, 0.0), DVec3::Z, 4096, 9), (0.0, 0.0));
    }

    #[test]
    fn the_vo_truth_of_a_plane_is_half_the_ball_and_none_of_the_half_above() {
        let plane = Bvh::build(Vec::new(), cuboid(Vec3::new(-BIG, -BIG, -10.0), Vec3::new(BIG, BIG, 0.0)));
        let s = settings(4096);
        let whole = vo_at(&plane, DVec3::new(0.3, 0.1, 0.0), DVec3::Z, &s, 3, VoBall::Whole);
        let stderr = (0.25f64 / 4096.0).sqrt();
        assert!((whole - 0.5).abs() < 3.0 * stderr, "{whole}");
        assert_eq!(vo_at(&plane, DVec3::new(0.3, 0.1, 0.0), DVec3::Z, &s, 3, VoBall::Half), 0.0);
    }

    #[test]
    fn linear_falloff_of_a_wall_follows_its_integral() {
        // Obscurance: E[1 − t/R] over rays that hit, t = h / cos θ. With u = cos² θ uniform on
        // [0, 1] (cosine weighting): ∫_{h²}^{1} (1 − h/√u) du = 1 − h² − 2h(1 − h) = (1 − h)².
        let h = 0.4f32;
        let wall = Bvh::build(Vec::new(), cuboid(Vec3::new(-BIG, -BIG, h), Vec3::new(BIG, BIG, h + 10.0)));
        let s = TruthSettings { falloff: Falloff::Linear, ..settings(4096) };
        let start = DVec3::new(0.0, 0.0, EPSILON_PER_DISTANCE);
        let (mean, stderr) = ao_at(&wall, start, DVec3::Z, &s, 2, |_| false);
        let h = h as f64 - EPSILON_PER_DISTANCE;
        assert!((mean - (1.0 - h) * (1.0 - h)).abs() < 3.0 * stderr, "{mean} ± {stderr}");
    }

    #[test]
    fn bad_settings_are_refused() {
        for bad in [
            TruthSettings { rays: 0, ..TruthSettings::default() },
            TruthSettings { distance_world: -1.0, ..TruthSettings::default() },
            TruthSettings { distance_world: f32::NAN, ..TruthSettings::default() },
            TruthSettings { distance_world: f32::INFINITY, ..TruthSettings::default() },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
    }
}
