//! Rays: Möller–Trumbore ray–triangle and slab ray–AABB intersection, and how far a shadow ray
//! starts off the surface it leaves.

use super::Aabb;
use glam::{Mat4, Vec3};

/// A shadow ray's start off its surface, relative to the coordinates that made the surface
/// point: 2⁻¹⁶ (see [`ray_offset`]).
pub const RAY_OFFSET_RELATIVE: f32 = 1.0 / 65_536.0;

/// The largest absolute world coordinate, per axis, that a draw's f32 arithmetic meets: its world
/// bounds' and its transform's translation (a vertex far out in model space brought back by the
/// transform keeps the rounding of the large numbers).
pub fn coordinate_magnitudes(world_bounds: &Aabb, world_from_model: &Mat4) -> Vec3 {
    let t = world_from_model.w_axis.truncate().abs();
    if world_bounds.is_empty() {
        return t;
    }
    world_bounds.min.abs().max(world_bounds.max.abs()).max(t)
}

/// How far a shadow ray starts off surface point `p` (unit face normal `n`) of a draw whose
/// coordinates reach `magnitudes` per axis: [`RAY_OFFSET_RELATIVE`] of |n|·magnitudes + |p|∞.
///
/// A surface point computed in f32 (a vertex transformed, then interpolated across a triangle by
/// the rasteriser, or weighted by a ray hit's barycentrics) lies off its exact plane by a small
/// multiple of the units in the last place of the coordinates that made it, each axis by its own
/// (the ground's height is exact however far the ground reaches); a ray–triangle test against its
/// own triangle errs by as much. The offset outweighs both and nothing else: it follows the
/// surface, not the scene, so the same bench gets the same offset in a room and in a 2 km town,
/// and a millimetre model a thousandth of a metre one's. 2⁻¹⁶ leaves lavapipe's interpolated
/// positions at a sphere's silhouette no self-shadowing (of the draw's largest coordinate alone,
/// 2⁻²⁰ left 11 pixels of the demo, 2⁻¹⁸ one, 2⁻¹⁶ none). See docs/architecture.md, "Where a
/// shadow ray starts".
pub fn ray_offset(magnitudes: Vec3, n: Vec3, p: Vec3) -> f32 {
    RAY_OFFSET_RELATIVE * (n.abs().dot(magnitudes) + p.abs().max_element())
}

/// A ray `origin + t * dir`. `inv_dir` is cached for slab tests (±∞ for zero components).
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction (need not be unit length; t is in units of it).
    pub dir: Vec3,
    /// Component-wise 1 / dir.
    pub inv_dir: Vec3,
}

impl Ray {
    /// A ray from `origin` along `dir`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir,
            inv_dir: Vec3::ONE / dir,
        }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// A ray–triangle hit: distance parameter and barycentric (u, v) of vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Barycentric weight of the second vertex.
    pub u: f32,
    /// Barycentric weight of the third vertex.
    pub v: f32,
}

/// Möller–Trumbore: the hit of `ray` with triangle (a, b, c) for t in (t_min, t_max), both faces.
/// Rays parallel to the triangle's plane (|det| below a relative epsilon) miss. Edges count as hits.
pub fn ray_triangle(
    ray: &Ray,
    a: Vec3,
    b: Vec3,
    c: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<TriangleHit> {
    let e1 = b - a;
    let e2 = c - a;
    ray_triangle_edges(
        ray,
        a,
        e1,
        e2,
        e1.cross(e2).length() * ray.dir.length(),
        t_min,
        t_max,
    )
}

/// Möller–Trumbore with precomputed edges e1 = b − a, e2 = c − a and `scale` = |e1 × e2|·|dir|
/// (the largest |det| can be); |det| ≤ 1e-7·scale counts as parallel (a miss), as does scale 0.
#[inline]
pub fn ray_triangle_edges(
    ray: &Ray,
    a: Vec3,
    e1: Vec3,
    e2: Vec3,
    scale: f32,
    t_min: f32,
    t_max: f32,
) -> Option<TriangleHit> {
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() <= 1e-7 * scale || scale == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = ray.dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    if t > t_min && t < t_max {
        Some(TriangleHit { t, u, v })
    } else {
        None
    }
}

/// Slab test: the parameter interval [t_enter, t_exit] where `ray` is inside `b`, clipped to
/// [t_min, t_max]. A flat box (t_enter == t_exit) is a hit; t_exit < t_min is a miss. A ray that
/// starts inside the box enters at t_min.
pub fn ray_aabb(ray: &Ray, b: &Aabb, t_min: f32, t_max: f32) -> Option<(f32, f32)> {
    let mut t0 = t_min;
    let mut t1 = t_max;
    for axis in 0..3 {
        let o = ray.origin[axis];
        let inv = ray.inv_dir[axis];
        let (lo, hi) = (b.min[axis], b.max[axis]);
        if inv.is_infinite() {
            // Parallel to this slab: inside it or never.
            if o < lo || o > hi {
                return None;
            }
            continue;
        }
        let mut ta = (lo - o) * inv;
        let mut tb = (hi - o) * inv;
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        // max/min written so NaN (0 * inf) never widens the interval.
        t0 = if ta > t0 { ta } else { t0 };
        t1 = if tb < t1 { tb } else { t1 };
        if t0 > t1 {
            return None;
        }
    }
    Some((t0, t1))
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    const B: Vec3 = Vec3::new(1.0, 0.0, 0.0);
    const C: Vec3 = Vec3::new(0.0, 1.0, 0.0);

    #[test]
    fn through_centroid() {
        let centroid = (A + B + C) / 3.0;
        let r = Ray::new(centroid + Vec3::Z * 2.0, -Vec3::Z);
        let h = ray_triangle(&r, A, B, C, 0.0, f32::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        assert!((h.u - 1.0 / 3.0).abs() < 1e-6 && (h.v - 1.0 / 3.0).abs() < 1e-6);
        // From below too (both faces).
        let r = Ray::new(centroid - Vec3::Z, Vec3::Z);
        assert!(ray_triangle(&r, A, B, C, 0.0, f32::INFINITY).is_some());
    }

    #[test]
    fn along_edge_and_outside() {
        // Hits exactly on the edge AB count.
        let r = Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z);
        let h = ray_triangle(&r, A, B, C, 0.0, f32::INFINITY).unwrap();
        assert!(h.v.abs() < 1e-7 && (h.u - 0.5).abs() < 1e-6);
        let r = Ray::new(Vec3::new(0.6, 0.6, 1.0), -Vec3::Z);
        assert!(ray_triangle(&r, A, B, C, 0.0, f32::INFINITY).is_none());
    }

    #[test]
    fn parallel_and_behind() {
        let r = Ray::new(Vec3::new(0.2, 0.2, 0.0), Vec3::X);
        assert!(
            ray_triangle(&r, A, B, C, 0.0, f32::INFINITY).is_none(),
            "in-plane ray"
        );
        let r = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::X);
        assert!(
            ray_triangle(&r, A, B, C, 0.0, f32::INFINITY).is_none(),
            "parallel above"
        );
        let r = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::Z);
        assert!(
            ray_triangle(&r, A, B, C, 0.0, f32::INFINITY).is_none(),
            "behind origin"
        );
        // Limited range.
        let r = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        assert!(ray_triangle(&r, A, B, C, 0.0, 0.5).is_none());
        // Degenerate triangle.
        assert!(ray_triangle(&r, A, B, B, 0.0, 10.0).is_none());
    }

    #[test]
    fn aabb_hits_misses_inside_and_flat() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let r = Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
        assert_eq!(ray_aabb(&r, &b, 0.0, f32::INFINITY), Some((1.0, 2.0)));
        // Starting inside: enters at t_min.
        let r = Ray::new(Vec3::splat(0.5), Vec3::X);
        assert_eq!(ray_aabb(&r, &b, 0.0, f32::INFINITY), Some((0.0, 0.5)));
        // Box entirely behind: t_exit < 0 is a miss.
        let r = Ray::new(Vec3::new(0.5, 0.5, 3.0), Vec3::Z);
        assert_eq!(ray_aabb(&r, &b, 0.0, f32::INFINITY), None);
        // A flat box (zero thickness in y) hit straight on: t_enter == t_exit is a hit.
        let flat = Aabb::new(Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 1.0));
        let r = Ray::new(Vec3::new(0.5, 3.0, 0.5), -Vec3::Y);
        assert_eq!(ray_aabb(&r, &flat, 0.0, f32::INFINITY), Some((2.0, 2.0)));
        // Grazing the flat box inside its plane.
        let r = Ray::new(Vec3::new(-1.0, 1.0, 0.5), Vec3::X);
        assert_eq!(ray_aabb(&r, &flat, 0.0, f32::INFINITY), Some((1.0, 2.0)));
        // Parallel, outside the slab.
        let r = Ray::new(Vec3::new(-1.0, 1.5, 0.5), Vec3::X);
        assert_eq!(ray_aabb(&r, &flat, 0.0, f32::INFINITY), None);
        // Through a corner exactly.
        let r = Ray::new(Vec3::new(-1.0, -1.0, 0.5), Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(ray_aabb(&r, &b, 0.0, f32::INFINITY), Some((1.0, 2.0)));
    }

    #[test]
    fn ray_offsets_follow_the_surface_not_the_scene() {
        // A 2 km ground at y = 0, seen 6 m from the origin: its height is exact, so the offset is
        // 2⁻¹⁶ of the distance from the origin, not of the ground's kilometre.
        let ground = Aabb::new(
            Vec3::new(-1000.0, 0.0, -1000.0),
            Vec3::new(1000.0, 0.0, 1000.0),
        );
        let m = coordinate_magnitudes(&ground, &Mat4::IDENTITY);
        assert_eq!(m, Vec3::new(1000.0, 0.0, 1000.0));
        let p = Vec3::new(0.5, 0.0, -6.0);
        assert_eq!(ray_offset(m, Vec3::Y, p), 6.0 / 65_536.0);
        // A tilted face weighs each axis's magnitude by its normal's share.
        let n = Vec3::new(0.6, 0.8, 0.0);
        assert!((ray_offset(m, n, p) - (600.0 + 6.0) / 65_536.0).abs() < 1e-9);
        // Scaled by a power of two, every offset scales exactly; a model far out in model space
        // brought back by its transform keeps the translation's size.
        for s in [1.0 / 1024.0, 1024.0] {
            assert_eq!(ray_offset(m * s, n, p * s), ray_offset(m, n, p) * s);
        }
        let back = Mat4::from_translation(Vec3::new(5000.0, 0.0, 0.0));
        let near_origin = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        assert_eq!(coordinate_magnitudes(&near_origin, &back).x, 5000.0);
    }
}
