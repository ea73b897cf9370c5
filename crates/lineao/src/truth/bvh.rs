//! A bounding volume hierarchy over rounded cones and triangles: binned SAH, built on all cores.
//!
//! Why our own and not a crate: the truth needs rounded cones next to triangles, any-hit and
//! nearest-hit rays with a per-pixel filter (a line never occludes its own surface), point
//! queries (is a point inside any primitive; which segment holds a pixel) and a flat node array
//! whose layout we fix, so the GPU ray tracer can upload the very same tree. The well-kept
//! crates (`bvh`, `obvhs`) each cover part of that, with their own node layouts.
//!
//! **Layout.** Nodes are 32 bytes in depth-first order: a box (min, max as f32) and two u32. An
//! inner node has `count = 0`; its left child is the next node and its right child is node
//! `first`. A leaf holds `refs[first .. first + count]`, each a primitive reference: a cone's
//! index, or a triangle's with bit 31 set. Memory: 40 bytes per cone, 36 per triangle, 4 per
//! reference and about 1.2 nodes per primitive (leaves of 1 to [`MAX_LEAF`]), so about 82
//! bytes per line segment ([`Bvh::bytes`] gives the exact figure, `lineao bench` prints it);
//! 11 M segments take about 0.9 GB.
//!
//! **Build.** Top-down: at each node the primitives' centroids are binned into [`BINS`] bins along
//! each axis, and the split with the lowest surface-area cost
//! (C = A_left·N_left + A_right·N_right over A_node, against N for a leaf) is taken. The two
//! halves of the first levels are built on separate threads.

use glam::{DVec3, Vec3};

use super::primitive::{RoundedCone, Triangle};

/// Bins per axis of the SAH sweep.
pub const BINS: usize = 16;
/// Most primitives in a leaf.
pub const MAX_LEAF: usize = 4;
/// Bit 31 of a primitive reference: a triangle.
pub const TRIANGLE_BIT: u32 = 1 << 31;

/// A node of the flattened tree (see the module doc for its layout).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Node {
    pub min: [f32; 3],
    /// Inner: the right child's index. Leaf: the first reference.
    pub first: u32,
    pub max: [f32; 3],
    /// 0 for an inner node; else the leaf's reference count.
    pub count: u32,
}

/// A primitive the tree points at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Prim {
    /// A rounded cone, by index.
    Cone(u32),
    /// A triangle, by index.
    Triangle(u32),
}

impl Prim {
    fn from_ref(r: u32) -> Prim {
        if r & TRIANGLE_BIT != 0 { Prim::Triangle(r & !TRIANGLE_BIT) } else { Prim::Cone(r) }
    }
}

/// What a leaf visitor tells the traversal.
enum Visit {
    Continue,
    Stop,
}

/// The tree with the primitives it holds.
pub struct Bvh {
    /// The nodes, the root first.
    pub nodes: Vec<Node>,
    /// The leaves' primitives, as [`Prim`]s packed in a `u32` each.
    pub refs: Vec<u32>,
    /// The rounded cones.
    pub cones: Vec<RoundedCone>,
    /// The triangles.
    pub triangles: Vec<Triangle>,
}

/// A primitive while building: its reference, box and centroid.
#[derive(Clone, Copy)]
struct Item {
    r: u32,
    lo: Vec3,
    hi: Vec3,
    c: Vec3,
}

#[derive(Clone, Copy)]
struct Aabb {
    lo: Vec3,
    hi: Vec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb { lo: Vec3::splat(f32::INFINITY), hi: Vec3::splat(f32::NEG_INFINITY) };

    fn grow(&mut self, lo: Vec3, hi: Vec3) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }

    fn area(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// Subtrees bigger than this are built on a thread of their own, down to [`PARALLEL_DEPTH`].
const PARALLEL_MIN: usize = 16_384;
const PARALLEL_DEPTH: u32 = 3;

impl Bvh {
    /// Builds the tree over `cones` and `triangles`. Non-finite primitives are left out.
    pub fn build(cones: Vec<RoundedCone>, triangles: Vec<Triangle>) -> Bvh {
        Bvh::build_with_leaves(cones, triangles, 2)
    }

    /// [`Bvh::build`] where every node of at most `leaf` primitives is a leaf (the SAH decides
    /// above that): bigger leaves, fewer nodes, for the GPU tree whose memory is what counts
    /// (`RayScene`). `build` is `leaf` 2: the SAH decides down to pairs.
    pub fn build_with_leaves(cones: Vec<RoundedCone>, triangles: Vec<Triangle>, leaf: usize) -> Bvh {
        let finite = |lo: Vec3, hi: Vec3| lo.is_finite() && hi.is_finite();
        let mut items: Vec<Item> = Vec::with_capacity(cones.len() + triangles.len());
        for (i, cone) in cones.iter().enumerate() {
            let (lo, hi) = cone.bounds();
            if cone.a.is_finite() && cone.b.is_finite() && finite(lo, hi) && cone.ra.is_finite() && cone.rb.is_finite()
            {
                items.push(Item { r: i as u32, lo, hi, c: 0.5 * (lo + hi) });
            }
        }
        for (i, triangle) in triangles.iter().enumerate() {
            let (lo, hi) = triangle.bounds();
            if finite(lo, hi) {
                items.push(Item { r: i as u32 | TRIANGLE_BIT, lo, hi, c: 0.5 * (lo + hi) });
            }
        }
        let nodes = if items.is_empty() { Vec::new() } else { build_subtree(&mut items, 0, 0, leaf.max(1)) };
        let refs = items.iter().map(|item| item.r).collect();
        Bvh { nodes, refs, cones, triangles }
    }

    /// Bytes the tree and its primitives take.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * size_of::<Node>()
            + self.refs.len() * 4
            + self.cones.len() * size_of::<RoundedCone>()
            + self.triangles.len() * size_of::<Triangle>()
    }

    /// Bytes a tree over `cones` segments and `triangles` will take, before building it (an
    /// upper estimate: one node per primitive).
    pub fn estimated_bytes(cones: usize, triangles: usize) -> usize {
        let n = cones + triangles;
        // The build also holds a 40-byte item per primitive while it runs.
        cones * size_of::<RoundedCone>() + triangles * size_of::<Triangle>() + n * (4 + 40 + size_of::<Node>())
    }

    /// Whether it holds no primitive.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Visits the leaves whose boxes `enter` accepts, nearest-first by `enter`'s distance.
    fn traverse(&self, mut enter: impl FnMut(&Node) -> Option<f64>, mut leaf: impl FnMut(Prim) -> Visit) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; 64];
        let mut top = 0usize;
        let mut node = 0u32;
        if enter(&self.nodes[0]).is_none() {
            return;
        }
        loop {
            let n = &self.nodes[node as usize];
            if n.count > 0 {
                for &r in &self.refs[n.first as usize..(n.first + n.count) as usize] {
                    if let Visit::Stop = leaf(Prim::from_ref(r)) {
                        return;
                    }
                }
            } else {
                let (left, right) = (node + 1, n.first);
                let dl = enter(&self.nodes[left as usize]);
                let dr = enter(&self.nodes[right as usize]);
                match (dl, dr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b { (left, right) } else { (right, left) };
                        if top < stack.len() {
                            stack[top] = far;
                            top += 1;
                        }
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = left;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = right;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if top == 0 {
                return;
            }
            top -= 1;
            node = stack[top];
        }
    }

    /// The nearest hit of `ro + t rd` (unit `rd`) with t in (0, t_max) among the primitives
    /// `skip` does not exclude: (t, primitive).
    pub fn nearest_hit(&self, ro: DVec3, rd: DVec3, t_max: f64, skip: impl Fn(Prim) -> bool) -> Option<(f64, Prim)> {
        let inv = rd.recip();
        let best = std::cell::Cell::new((t_max, None));
        self.traverse(
            |n| slab(n, ro, inv, best.get().0),
            |p| {
                if !skip(p) {
                    let limit = best.get().0;
                    if let Some(t) = self.intersect(p, ro, rd, limit) {
                        best.set((t, Some(p)));
                    }
                }
                Visit::Continue
            },
        );
        let (t, p) = best.get();
        p.map(|p| (t, p))
    }

    /// Whether `ro + t rd` hits anything with t in (0, t_max) that `skip` does not exclude.
    pub fn any_hit(&self, ro: DVec3, rd: DVec3, t_max: f64, skip: impl Fn(Prim) -> bool) -> bool {
        let inv = rd.recip();
        let mut hit = false;
        self.traverse(
            |n| slab(n, ro, inv, t_max),
            |p| {
                if !skip(p) && self.intersect(p, ro, rd, t_max).is_some() {
                    hit = true;
                    return Visit::Stop;
                }
                Visit::Continue
            },
        );
        hit
    }

    /// The cones whose boxes, grown by `margin`, hold `p`.
    pub fn cones_near(&self, p: DVec3, margin: f64, mut f: impl FnMut(u32)) {
        self.traverse(
            |n| inside_box(n, p, margin).then_some(0.0),
            |prim| {
                if let Prim::Cone(i) = prim {
                    f(i);
                }
                Visit::Continue
            },
        );
    }

    /// Whether `p` lies inside a cone that `skip` does not exclude.
    pub fn inside_cone(&self, p: DVec3, skip: impl Fn(Prim) -> bool) -> bool {
        let mut inside = false;
        self.traverse(
            |n| inside_box(n, p, 0.0).then_some(0.0),
            |prim| match prim {
                Prim::Cone(i) if !skip(prim) && self.cones[i as usize].distance(p) < 0.0 => {
                    inside = true;
                    Visit::Stop
                }
                _ => Visit::Continue,
            },
        );
        inside
    }

    /// How many triangles the ray `ro + t rd`, t > 0, crosses: odd inside a closed surface.
    pub fn triangle_crossings(&self, ro: DVec3, rd: DVec3) -> u32 {
        let inv = rd.recip();
        let mut count = 0;
        self.traverse(
            |n| slab(n, ro, inv, f64::INFINITY),
            |prim| {
                if let Prim::Triangle(i) = prim
                    && self.triangles[i as usize].intersect(ro, rd, 0.0, f64::INFINITY).is_some()
                {
                    count += 1;
                }
                Visit::Continue
            },
        );
        count
    }

    fn intersect(&self, p: Prim, ro: DVec3, rd: DVec3, t_max: f64) -> Option<f64> {
        match p {
            Prim::Cone(i) => self.cones[i as usize].intersect(ro, rd, 0.0, t_max),
            Prim::Triangle(i) => self.triangles[i as usize].intersect(ro, rd, 0.0, t_max),
        }
    }
}

/// The ray's entry into the node's box if it is before `t_max`.
fn slab(n: &Node, ro: DVec3, inv: DVec3, t_max: f64) -> Option<f64> {
    let lo = (Vec3::from(n.min).as_dvec3() - ro) * inv;
    let hi = (Vec3::from(n.max).as_dvec3() - ro) * inv;
    // NaN (0 · ∞ for a ray in a face's plane) drops out of min/max as the other operand.
    let t0 = lo.min(hi).max_element().max(0.0);
    let t1 = lo.max(hi).min_element().min(t_max);
    (t0 <= t1).then_some(t0)
}

fn inside_box(n: &Node, p: DVec3, margin: f64) -> bool {
    let lo = Vec3::from(n.min).as_dvec3() - DVec3::splat(margin);
    let hi = Vec3::from(n.max).as_dvec3() + DVec3::splat(margin);
    p.cmpge(lo).all() && p.cmple(hi).all()
}

/// Builds the subtree over `items` (depth-first, child indices relative to its root; leaves
/// point into `items` as positions from `base`), reordering `items` in place.
fn build_subtree(items: &mut [Item], base: u32, depth: u32, leaf: usize) -> Vec<Node> {
    let mut nodes = Vec::with_capacity(items.len() / 2 + 1);
    build_node(items, base, depth, leaf, &mut nodes);
    nodes
}

fn build_node(items: &mut [Item], base: u32, depth: u32, leaf: usize, nodes: &mut Vec<Node>) {
    let mut bounds = Aabb::EMPTY;
    let mut centroids = Aabb::EMPTY;
    for item in items.iter() {
        bounds.grow(item.lo, item.hi);
        centroids.grow(item.c, item.c);
    }
    let me = nodes.len();
    nodes.push(Node { min: bounds.lo.into(), first: base, max: bounds.hi.into(), count: items.len() as u32 });
    let Some(mid) = split(items, &bounds, &centroids, leaf) else { return };
    // A web page has no threads: there the tree is built on the page's own.
    let parallel = items.len() >= PARALLEL_MIN && depth < PARALLEL_DEPTH && !cfg!(target_arch = "wasm32");
    let (left, right) = items.split_at_mut(mid);
    if parallel {
        let right_base = base + mid as u32;
        let right_nodes = std::thread::scope(|scope| {
            let handle = scope.spawn(|| build_subtree(right, right_base, depth + 1, leaf));
            build_node(left, base, depth + 1, leaf, nodes);
            handle.join().expect("a BVH build thread panicked")
        });
        let offset = nodes.len() as u32;
        nodes[me].first = offset;
        nodes.extend(right_nodes.into_iter().map(|mut n| {
            if n.count == 0 {
                n.first += offset;
            }
            n
        }));
    } else {
        build_node(left, base, depth + 1, leaf, nodes);
        nodes[me].first = nodes.len() as u32;
        build_node(right, base + mid as u32, depth + 1, leaf, nodes);
    }
    nodes[me].count = 0;
}

/// The SAH split of `items` (partitioned in place): the left half's length, or `None` for a leaf
/// (always at most `leaf` items).
fn split(items: &mut [Item], bounds: &Aabb, centroids: &Aabb, leaf: usize) -> Option<usize> {
    let n = items.len();
    if n <= leaf.max(1) {
        return None;
    }
    let extent = centroids.hi - centroids.lo;
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let bin_of = |c: Vec3| (((c[axis] - centroids.lo[axis]) * scale) as usize).min(BINS - 1);
        let mut boxes = [Aabb::EMPTY; BINS];
        let mut counts = [0usize; BINS];
        for item in items.iter() {
            let b = bin_of(item.c);
            boxes[b].grow(item.lo, item.hi);
            counts[b] += 1;
        }
        // Sweep from the right for the right halves' areas and counts.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Aabb::EMPTY;
        let mut count = 0;
        for b in (1..BINS).rev() {
            acc.grow(boxes[b].lo, boxes[b].hi);
            count += counts[b];
            right_area[b] = acc.area();
            right_count[b] = count;
        }
        let mut acc = Aabb::EMPTY;
        let mut count = 0;
        for b in 0..BINS - 1 {
            acc.grow(boxes[b].lo, boxes[b].hi);
            count += counts[b];
            if count == 0 || right_count[b + 1] == 0 {
                continue;
            }
            let cost = acc.area() * count as f32 + right_area[b + 1] * right_count[b + 1] as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    // Costs in units of one primitive test over the node's area; a box test of the two
    // children costs about one primitive test.
    let leaf_cost = bounds.area() * n as f32;
    if n <= 2 {
        return None;
    }
    let (cost, axis, bin) = match best {
        Some(b) => b,
        // Every centroid in one place: split in the middle if the leaf would be too big.
        None if n > MAX_LEAF.max(leaf) => return Some(n / 2),
        None => return None,
    };
    if n <= MAX_LEAF.max(leaf) && cost + bounds.area() >= leaf_cost {
        return None;
    }
    let scale = BINS as f32 / extent[axis];
    let lo = centroids.lo[axis];
    let mid = partition(items, |item| ((((item.c[axis] - lo) * scale) as usize).min(BINS - 1)) <= bin);
    Some(mid.clamp(1, n - 1))
}

/// Moves the items where `left` holds to the front; returns how many there are.
fn partition(items: &mut [Item], left: impl Fn(&Item) -> bool) -> usize {
    let mut i = 0;
    let mut j = items.len();
    while i < j {
        if left(&items[i]) {
            i += 1;
        } else {
            j -= 1;
            items.swap(i, j);
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Rng(u64);
    impl Rng {
        fn f(&mut self) -> f32 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((self.0 >> 40) as f32) / (1u64 << 24) as f32
        }
        fn v(&mut self) -> Vec3 {
            Vec3::new(self.f(), self.f(), self.f())
        }
    }

    fn random_scene(rng: &mut Rng, cones: usize, triangles: usize) -> Bvh {
        let cones = (0..cones)
            .map(|i| {
                let a = rng.v() * 100.0;
                RoundedCone {
                    a,
                    b: a + (rng.v() - 0.5) * 6.0,
                    ra: 0.05 + rng.f() * 0.5,
                    rb: 0.05 + rng.f() * 0.5,
                    streamline: i as u32 / 10,
                    segment: i as u32 % 10,
                }
            })
            .collect();
        let triangles = (0..triangles)
            .map(|_| {
                let a = rng.v() * 100.0;
                Triangle { v: [a, a + (rng.v() - 0.5) * 8.0, a + (rng.v() - 0.5) * 8.0] }
            })
            .collect();
        Bvh::build(cones, triangles)
    }

    /// Every primitive is reached exactly once, every box holds what is below it.
    #[test]
    fn the_tree_holds_every_primitive_once() {
        let bvh = random_scene(&mut Rng(3), 30_000, 2_000);
        let mut seen = vec![0u8; bvh.refs.len()];
        for &r in &bvh.refs {
            let i = if r & TRIANGLE_BIT != 0 { 30_000 + (r & !TRIANGLE_BIT) as usize } else { r as usize };
            seen[i] += 1;
        }
        assert!(seen.iter().all(|&s| s == 1));
        fn check(bvh: &Bvh, node: usize) -> (Vec3, Vec3) {
            let n = bvh.nodes[node];
            let (lo, hi) = if n.count > 0 {
                bvh.refs[n.first as usize..(n.first + n.count) as usize].iter().fold(
                    (Vec3::INFINITY, Vec3::NEG_INFINITY),
                    |(lo, hi), &r| {
                        let (a, b) = match Prim::from_ref(r) {
                            Prim::Cone(i) => bvh.cones[i as usize].bounds(),
                            Prim::Triangle(i) => bvh.triangles[i as usize].bounds(),
                        };
                        (lo.min(a), hi.max(b))
                    },
                )
            } else {
                let (a, b) = (check(bvh, node + 1), check(bvh, n.first as usize));
                (a.0.min(b.0), a.1.max(b.1))
            };
            assert!(Vec3::from(n.min).cmple(lo).all() && Vec3::from(n.max).cmpge(hi).all());
            (lo, hi)
        }
        check(&bvh, 0);
        let per_primitive = bvh.nodes.len() as f64 / bvh.refs.len() as f64;
        assert!(per_primitive < 1.3, "{} nodes for {} primitives", bvh.nodes.len(), bvh.refs.len());
    }

    /// The nearest hit and any-hit agree with brute force on 10 k primitives and 100 k rays.
    #[test]
    fn traversal_equals_brute_force() {
        let mut rng = Rng(7);
        let bvh = random_scene(&mut rng, 9_000, 1_000);
        let skip = |p: Prim| matches!(p, Prim::Cone(i) if i % 97 == 0);
        let mut hits = 0;
        for _ in 0..100_000 {
            let ro = (rng.v() * 120.0 - Vec3::splat(10.0)).as_dvec3();
            let rd = (rng.v() - 0.5).as_dvec3().normalize();
            let t_max = 5.0 + rng.f() as f64 * 60.0;
            let mut brute: Option<(f64, Prim)> = None;
            let all =
                (0..bvh.cones.len() as u32).map(Prim::Cone).chain((0..bvh.triangles.len() as u32).map(Prim::Triangle));
            for p in all.filter(|&p| !skip(p)) {
                let limit = brute.map_or(t_max, |b| b.0);
                let (lo, hi) = match p {
                    Prim::Cone(i) => bvh.cones[i as usize].bounds(),
                    Prim::Triangle(i) => bvh.triangles[i as usize].bounds(),
                };
                let node = Node { min: lo.into(), first: 0, max: hi.into(), count: 1 };
                if slab(&node, ro, rd.recip(), limit).is_none() {
                    continue;
                }
                if let Some(t) = bvh.intersect(p, ro, rd, limit) {
                    brute = Some((t, p));
                }
            }
            let fast = bvh.nearest_hit(ro, rd, t_max, skip);
            assert_eq!(fast, brute, "ray {ro} {rd}");
            assert_eq!(bvh.any_hit(ro, rd, t_max, skip), brute.is_some());
            hits += brute.is_some() as usize;
        }
        assert!(hits > 5_000, "{hits}");
    }

    #[test]
    fn point_queries_equal_brute_force() {
        let mut rng = Rng(11);
        let bvh = random_scene(&mut rng, 5_000, 0);
        for _ in 0..20_000 {
            let p = (rng.v() * 100.0).as_dvec3();
            let brute = bvh.cones.iter().any(|c| c.distance(p) < 0.0);
            assert_eq!(bvh.inside_cone(p, |_| false), brute);
        }
    }

    #[test]
    fn empty_and_degenerate_inputs() {
        let empty = Bvh::build(Vec::new(), Vec::new());
        assert!(empty.is_empty());
        assert!(!empty.any_hit(DVec3::ZERO, DVec3::X, 1.0, |_| false));
        // Many primitives at one place, and a non-finite one left out.
        let same = RoundedCone { a: Vec3::ZERO, b: Vec3::ZERO, ra: 1.0, rb: 1.0, streamline: 0, segment: 0 };
        let mut cones = vec![same; 100];
        cones.push(RoundedCone { a: Vec3::NAN, ..same });
        let bvh = Bvh::build(cones, Vec::new());
        assert_eq!(bvh.refs.len(), 100);
        let (t, _) = bvh.nearest_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, 10.0, |_| false).unwrap();
        assert!((t - 4.0).abs() < 1e-12);
    }
}
