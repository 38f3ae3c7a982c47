//! Bounding volume hierarchy: binned SAH build, iterative nearest-child-first traversal,
//! Möller–Trumbore triangles and slab box tests.

use glam::Vec3;
use umbra::math::ray::{ray_triangle_edges, Ray};
use umbra::math::Aabb;

const BINS: usize = 12;
const LEAF_MAX: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Leaf: first triangle; inner: index of the left child (the right one follows it).
    first: u32,
    /// Triangles in a leaf; 0 for an inner node.
    count: u32,
}

#[derive(Clone, Copy, Debug)]
struct Tri {
    a: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// |e1 × e2| (twice the area): the parallel-ray threshold's scale.
    scale: f32,
}

/// A ray hit: distance, triangle (index into the build's input) and barycentrics of vertices 1, 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter.
    pub t: f32,
    /// Input triangle index.
    pub triangle: u32,
    /// Barycentric weight of vertex 1.
    pub u: f32,
    /// Barycentric weight of vertex 2.
    pub v: f32,
}

/// A BVH over a triangle soup.
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
    ids: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over `triangles` (each three world-space vertices). Triangles with
    /// non-finite vertices are left out.
    pub fn build(triangles: &[[Vec3; 3]]) -> Self {
        let mut ids: Vec<u32> = (0..triangles.len() as u32)
            .filter(|&i| triangles[i as usize].iter().all(|v| v.is_finite()))
            .collect();
        let centroids: Vec<Vec3> = triangles
            .iter()
            .map(|t| (t[0] + t[1] + t[2]) / 3.0)
            .collect();
        let bounds: Vec<Aabb> = triangles
            .iter()
            .map(|t| Aabb::from_points(t.iter().copied()))
            .collect();
        let mut nodes = vec![Node {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
            first: 0,
            count: ids.len() as u32,
        }];
        nodes.reserve(ids.len() * 2);
        let mut stack = vec![0usize];
        while let Some(ni) = stack.pop() {
            let (first, count) = (nodes[ni].first as usize, nodes[ni].count as usize);
            let slice = &mut ids[first..first + count];
            let mut nb = Aabb::EMPTY;
            let mut cb = Aabb::EMPTY;
            for &i in slice.iter() {
                nb = nb.union(&bounds[i as usize]);
                cb.grow(centroids[i as usize]);
            }
            nodes[ni].min = nb.min;
            nodes[ni].max = nb.max;
            if count <= LEAF_MAX {
                continue;
            }
            // Binned SAH over the longest centroid axis... over all three axes, cheapest wins.
            let leaf_cost = count as f32 * half_area(&nb);
            let mut best: Option<(f32, usize, f32)> = None; // (cost, axis, split position)
            #[allow(clippy::needless_range_loop)]
            for axis in 0..3 {
                let (lo, hi) = (cb.min[axis], cb.max[axis]);
                if hi - lo <= 1e-12 * (1.0 + lo.abs().max(hi.abs())) {
                    continue;
                }
                let k = BINS as f32 / (hi - lo);
                let mut bin_box = [Aabb::EMPTY; BINS];
                let mut bin_n = [0usize; BINS];
                for &i in slice.iter() {
                    let b = (((centroids[i as usize][axis] - lo) * k) as usize).min(BINS - 1);
                    bin_box[b] = bin_box[b].union(&bounds[i as usize]);
                    bin_n[b] += 1;
                }
                let mut right_area = [0.0f32; BINS];
                let mut right_n = [0usize; BINS];
                let (mut acc, mut n) = (Aabb::EMPTY, 0);
                for b in (1..BINS).rev() {
                    acc = acc.union(&bin_box[b]);
                    n += bin_n[b];
                    right_area[b] = half_area(&acc);
                    right_n[b] = n;
                }
                let (mut acc, mut n) = (Aabb::EMPTY, 0);
                for b in 0..BINS - 1 {
                    acc = acc.union(&bin_box[b]);
                    n += bin_n[b];
                    if n == 0 || right_n[b + 1] == 0 {
                        continue;
                    }
                    let cost =
                        n as f32 * half_area(&acc) + right_n[b + 1] as f32 * right_area[b + 1];
                    if best.is_none_or(|(c, _, _)| cost < c) {
                        best = Some((cost, axis, lo + (b + 1) as f32 / k));
                    }
                }
            }
            let Some((cost, axis, split)) = best else {
                continue;
            };
            if cost >= leaf_cost && count <= 16 {
                continue;
            }
            // Partition in place.
            let (mut i, mut j) = (0usize, count);
            while i < j {
                if centroids[slice[i] as usize][axis] < split {
                    i += 1;
                } else {
                    j -= 1;
                    slice.swap(i, j);
                }
            }
            if i == 0 || i == count {
                continue;
            }
            let left = nodes.len();
            nodes.push(Node {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
                first: first as u32,
                count: i as u32,
            });
            nodes.push(Node {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
                first: (first + i) as u32,
                count: (count - i) as u32,
            });
            nodes[ni].first = left as u32;
            nodes[ni].count = 0;
            stack.push(left);
            stack.push(left + 1);
        }
        let tris = ids
            .iter()
            .map(|&i| {
                let t = triangles[i as usize];
                let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
                Tri {
                    a: t[0],
                    e1,
                    e2,
                    scale: e1.cross(e2).length(),
                }
            })
            .collect();
        Self { nodes, tris, ids }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    #[inline]
    fn slab(&self, n: &Node, ray: &Ray, t_max: f32) -> Option<f32> {
        let t0 = (n.min - ray.origin) * ray.inv_dir;
        let t1 = (n.max - ray.origin) * ray.inv_dir;
        let lo = t0.min(t1);
        let hi = t0.max(t1);
        // NaN (0·∞ on a flat box in a parallel slab) must not reject: max/min skip NaN operands.
        let enter = lo.x.max(lo.y).max(lo.z).max(0.0);
        let exit = hi.x.min(hi.y).min(hi.z).min(t_max);
        (enter <= exit).then_some(enter)
    }

    /// The nearest hit with t in (t_min, t_max).
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        self.traverse(ray, t_min, t_max, false, &|_: &Hit| true)
    }

    /// True when anything is hit with t in (t_min, t_max) (shadow rays).
    pub fn occluded(&self, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        self.traverse(ray, t_min, t_max, true, &|_: &Hit| true)
            .is_some()
    }

    /// The nearest hit with t in (t_min, t_max) that `accept` keeps (an any-hit filter: an
    /// alpha-masked texel lets the ray through).
    pub fn intersect_where(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        accept: &impl Fn(&Hit) -> bool,
    ) -> Option<Hit> {
        self.traverse(ray, t_min, t_max, false, accept)
    }

    /// True when a hit that `accept` keeps lies in (t_min, t_max).
    pub fn occluded_where(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        accept: &impl Fn(&Hit) -> bool,
    ) -> bool {
        self.traverse(ray, t_min, t_max, true, accept).is_some()
    }

    fn traverse(
        &self,
        ray: &Ray,
        t_min: f32,
        mut t_max: f32,
        any: bool,
        accept: &impl Fn(&Hit) -> bool,
    ) -> Option<Hit> {
        if self.tris.is_empty() {
            return None;
        }
        let mut best: Option<Hit> = None;
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        self.slab(&self.nodes[0], ray, t_max)?;
        stack[sp] = 0;
        sp += 1;
        while sp > 0 {
            sp -= 1;
            let n = &self.nodes[stack[sp] as usize];
            if n.count > 0 {
                let mut found = Found { t_max, best };
                let stop = self.test_range(
                    n.first as usize..(n.first + n.count) as usize,
                    ray,
                    t_min,
                    any,
                    accept,
                    &mut found,
                );
                (t_max, best) = (found.t_max, found.best);
                if stop {
                    return best;
                }
                continue;
            }
            let (l, r) = (n.first, n.first + 1);
            let tl = self.slab(&self.nodes[l as usize], ray, t_max);
            let tr = self.slab(&self.nodes[r as usize], ray, t_max);
            // Push the farther child first so the nearer one is visited next.
            match (tl, tr) {
                (Some(a), Some(b)) => {
                    let (near, far) = if a <= b { (l, r) } else { (r, l) };
                    if sp + 2 > stack.len() {
                        return self.brute(ray, t_min, t_max, any, accept).or(best);
                    }
                    stack[sp] = far;
                    stack[sp + 1] = near;
                    sp += 2;
                }
                (Some(_), None) | (None, Some(_)) => {
                    if sp + 1 > stack.len() {
                        return self.brute(ray, t_min, t_max, any, accept).or(best);
                    }
                    stack[sp] = if tl.is_some() { l } else { r };
                    sp += 1;
                }
                (None, None) => {}
            }
        }
        best
    }

    fn brute(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        any: bool,
        accept: &impl Fn(&Hit) -> bool,
    ) -> Option<Hit> {
        let mut found = Found { t_max, best: None };
        self.test_range(0..self.tris.len(), ray, t_min, any, accept, &mut found);
        found.best
    }

    /// Tests triangles `range` (in BVH order), keeping the nearest hit that `accept` keeps in
    /// `found.best` and shrinking `found.t_max`; returns true when `any` is set and something
    /// was hit.
    fn test_range(
        &self,
        range: std::ops::Range<usize>,
        ray: &Ray,
        t_min: f32,
        any: bool,
        accept: &impl Fn(&Hit) -> bool,
        found: &mut Found,
    ) -> bool {
        let Found { t_max, best } = found;
        let len = ray.dir.length();
        for k in range {
            let t = &self.tris[k];
            if let Some(h) = ray_triangle_edges(ray, t.a, t.e1, t.e2, t.scale * len, t_min, *t_max)
            {
                let hit = Hit {
                    t: h.t,
                    triangle: self.ids[k],
                    u: h.u,
                    v: h.v,
                };
                if !accept(&hit) {
                    continue;
                }
                *t_max = h.t;
                *best = Some(hit);
                if any {
                    return true;
                }
            }
        }
        false
    }

    /// Brute force over every triangle (for testing the hierarchy).
    pub fn intersect_brute_force(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        self.brute(ray, t_min, t_max, false, &|_: &Hit| true)
    }
}

/// The nearest accepted hit so far and the distance a nearer one must beat.
struct Found {
    t_max: f32,
    best: Option<Hit>,
}

fn half_area(b: &Aabb) -> f32 {
    if b.is_empty() {
        return 0.0;
    }
    let e = b.extent();
    e.x * e.y + e.y * e.z + e.z * e.x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift) for repeatable random tests.
    pub struct Rng(u64);
    impl Rng {
        pub fn f(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        pub fn v(&mut self, s: f32) -> Vec3 {
            Vec3::new(
                self.f() * 2.0 - 1.0,
                self.f() * 2.0 - 1.0,
                self.f() * 2.0 - 1.0,
            ) * s
        }
    }

    #[test]
    fn matches_brute_force_on_random_soup_and_flat_geometry() {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        let mut tris = Vec::new();
        for _ in 0..3000 {
            let c = rng.v(10.0);
            tris.push([c + rng.v(0.7), c + rng.v(0.7), c + rng.v(0.7)]);
        }
        // A flat floor (all boxes flat in y) and a degenerate triangle.
        for i in 0..20 {
            let x = i as f32 - 10.0;
            tris.push([
                Vec3::new(x, -11.0, -10.0),
                Vec3::new(x + 1.0, -11.0, -10.0),
                Vec3::new(x, -11.0, 10.0),
            ]);
        }
        tris.push([Vec3::ONE, Vec3::ONE, Vec3::ONE]);
        let bvh = Bvh::build(&tris);
        assert!(bvh.node_count() > 100);
        for _ in 0..10_000 {
            let o = rng.v(15.0);
            let d = (rng.v(1.0) + Vec3::new(0.0, -0.3, 0.0)).normalize_or(Vec3::X);
            let r = Ray::new(o, d);
            let a = bvh.intersect(&r, 0.0, f32::INFINITY);
            let b = bvh.intersect_brute_force(&r, 0.0, f32::INFINITY);
            assert_eq!(a.map(|h| h.t), b.map(|h| h.t), "ray {o} {d}");
            assert_eq!(a.is_some(), bvh.occluded(&r, 0.0, f32::INFINITY));
        }
        // Axis-parallel rays hit the flat floor (flat node boxes: t_enter == t_exit is a hit).
        let r = Ray::new(Vec3::new(0.2, 0.0, 0.0), -Vec3::Y);
        let h = bvh.intersect_brute_force(
            &Ray::new(Vec3::new(0.2, -10.5, 0.0), -Vec3::Y),
            0.0,
            f32::INFINITY,
        );
        assert!(h.is_some());
        let h2 = bvh.intersect(
            &Ray::new(Vec3::new(0.2, -10.5, 0.0), -Vec3::Y),
            0.0,
            f32::INFINITY,
        );
        assert_eq!(h.map(|h| h.t), h2.map(|h| h.t));
        let _ = r;
    }

    #[test]
    fn empty_and_single() {
        let empty = Bvh::build(&[]);
        assert!(empty
            .intersect(&Ray::new(Vec3::ZERO, Vec3::X), 0.0, 1.0)
            .is_none());
        let one = Bvh::build(&[[
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
        ]]);
        let h = one
            .intersect(&Ray::new(Vec3::ZERO, Vec3::X), 0.0, 10.0)
            .unwrap();
        assert!((h.t - 1.0).abs() < 1e-6);
        assert_eq!(h.triangle, 0);
    }
}
