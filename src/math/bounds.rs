//! Axis-aligned bounding boxes.

use glam::{Mat4, Vec3};

/// An axis-aligned box. `Aabb::EMPTY` has min > max and contains nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (the identity of `union`).
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// A box from two corners.
    pub fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    /// The smallest box around `points` (empty for no points; non-finite points are skipped).
    pub fn from_points<I: IntoIterator<Item = Vec3>>(points: I) -> Self {
        let mut b = Self::EMPTY;
        for p in points {
            if p.is_finite() {
                b.grow(p);
            }
        }
        b
    }

    /// True when the box holds no point.
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// Extends the box to hold `p`.
    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// True when `p` is inside the box grown by `margin` on every side.
    pub fn contains(&self, p: Vec3, margin: f32) -> bool {
        p.cmpge(self.min - Vec3::splat(margin)).all()
            && p.cmple(self.max + Vec3::splat(margin)).all()
    }

    /// The smallest box holding both.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// The overlap of two boxes (may be empty).
    pub fn intersection(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.max(o.min),
            max: self.max.min(o.max),
        }
    }

    /// Centre point.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Size along each axis.
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Length of the diagonal (0 for an empty box).
    pub fn diagonal(&self) -> f32 {
        if self.is_empty() {
            0.0
        } else {
            self.extent().length()
        }
    }

    /// Centre and radius of the sphere through the corners; the unit sphere at the origin for
    /// an empty box (so framing an empty scene still gives a usable camera).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        if self.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            (self.center(), (self.diagonal() * 0.5).max(1e-6))
        }
    }

    /// The 8 corners.
    pub fn corners(&self) -> [Vec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            Vec3::new(a.x, a.y, a.z),
            Vec3::new(b.x, a.y, a.z),
            Vec3::new(a.x, b.y, a.z),
            Vec3::new(b.x, b.y, a.z),
            Vec3::new(a.x, a.y, b.z),
            Vec3::new(b.x, a.y, b.z),
            Vec3::new(a.x, b.y, b.z),
            Vec3::new(b.x, b.y, b.z),
        ]
    }

    /// The box around this box's corners after an affine transform.
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        Aabb::from_points(self.corners().iter().map(|c| m.transform_point3(*c)))
    }

    /// True when the box lies wholly outside one plane of the clip volume of `clip_from_world`
    /// (Vulkan clip space: −w ≤ x, y ≤ w, 0 ≤ z ≤ w). Conservative: a box that is not reported
    /// outside may still be invisible. Works for perspective (also infinite, reversed-z) and
    /// orthographic matrices, and for boxes behind the eye.
    pub fn outside_clip_volume(&self, clip_from_world: &Mat4) -> bool {
        let r = clip_from_world.transpose(); // rows of the matrix as columns
        let (r0, r1, r2, r3) = (r.x_axis, r.y_axis, r.z_axis, r.w_axis);
        let planes = [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2];
        planes.iter().any(|p| {
            let n = p.truncate();
            // The box corner farthest along the plane's normal.
            let v = Vec3::select(n.cmpge(Vec3::ZERO), self.max, self.min);
            n.dot(v) + p.w < 0.0
        })
    }

    /// True when the boxes overlap (touching counts).
    pub fn overlaps(&self, o: &Aabb) -> bool {
        !self.intersection(o).is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_union_and_intersection() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let b = Aabb::new(Vec3::splat(0.5), Vec3::splat(2.0));
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.union(&a), a);
        assert_eq!(a.intersection(&b), Aabb::new(Vec3::splat(0.5), Vec3::ONE));
        assert!(a
            .intersection(&Aabb::new(Vec3::splat(3.0), Vec3::splat(4.0)))
            .is_empty());
        assert!(a.overlaps(&b));
        // A flat box is not empty.
        assert!(!Aabb::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0)).is_empty());
    }

    #[test]
    fn outside_clip_volume_culls_only_invisible_boxes() {
        use crate::math::projection::perspective_infinite_reversed;
        let view = Mat4::look_at_rh(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y);
        let clip = perspective_infinite_reversed(60f32.to_radians(), 1.5, 0.1) * view;
        let unit = |c: Vec3| Aabb::new(c - Vec3::splat(0.5), c + Vec3::splat(0.5));
        assert!(!unit(Vec3::new(0.0, 0.0, -5.0)).outside_clip_volume(&clip)); // ahead
        assert!(!unit(Vec3::new(0.0, 0.0, -1e6)).outside_clip_volume(&clip)); // far (infinite)
        assert!(!unit(Vec3::new(0.0, 0.0, 0.0)).outside_clip_volume(&clip)); // around the eye
        assert!(unit(Vec3::new(0.0, 0.0, 5.0)).outside_clip_volume(&clip)); // behind
        assert!(unit(Vec3::new(20.0, 0.0, -5.0)).outside_clip_volume(&clip)); // right
        assert!(unit(Vec3::new(0.0, -20.0, -5.0)).outside_clip_volume(&clip)); // below
                                                                               // Straddling the left plane: kept.
        assert!(!unit(Vec3::new(-4.6, 0.0, -5.0)).outside_clip_volume(&clip));
        // Orthographic (the shadow fit's kind): [-1,1]² × [0,1] box of the light.
        let ortho = Mat4::orthographic_rh(-1.0, 1.0, -1.0, 1.0, 0.0, 10.0);
        assert!(!unit(Vec3::new(0.0, 0.0, -3.0)).outside_clip_volume(&ortho));
        assert!(unit(Vec3::new(3.0, 0.0, -3.0)).outside_clip_volume(&ortho));
        assert!(unit(Vec3::new(0.0, 0.0, 3.0)).outside_clip_volume(&ortho));
    }

    #[test]
    fn transform_rotated_box() {
        let a = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let m = Mat4::from_rotation_y(std::f32::consts::FRAC_PI_4);
        let t = a.transformed(&m);
        assert!((t.max.x - 2f32.sqrt()).abs() < 1e-5);
        assert!((t.max.y - 1.0).abs() < 1e-6);
        let s = Aabb::from_points([Vec3::ONE, Vec3::NAN, -Vec3::ONE]);
        assert_eq!(s, a);
    }
}
