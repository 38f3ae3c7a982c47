//! Framing a model: the view a model without a camera is seen from, and the distance at which
//! its bounds fill a given share of the image.

use crate::math::Aabb;
use crate::scene::Camera;
use glam::Vec3;

/// How far above the horizontal the default view looks down (degrees): slightly above, so a
/// ground under the model shows and a board facing +Z is seen within 20° of its normal.
pub const DEFAULT_ELEVATION_DEG: f32 = 15.0;

/// The share of the shorter image side the framed bounds fill (the larger of their projected
/// width and height).
pub const FILL: f32 = 0.85;

/// Vertical field of view of framed cameras (degrees).
pub const FOV_Y_DEG: f32 = 45.0;

/// The direction from a model's centre towards the default eye: the front (+Z), raised by
/// [`DEFAULT_ELEVATION_DEG`] (the Khronos Sample Viewer's and three.js editor's front view).
pub fn default_direction() -> Vec3 {
    let e = DEFAULT_ELEVATION_DEG.to_radians();
    Vec3::new(0.0, e.sin(), e.cos())
}

/// Where a framed camera stands: its eye and the point it looks at (the box's centre moved
/// across the view so that the projected box is centred), and the view depth of the box's
/// nearest corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Framing {
    /// The eye.
    pub eye: Vec3,
    /// The point looked at.
    pub target: Vec3,
    /// View depth of the nearest corner of the box.
    pub nearest: f32,
}

/// The view of `bounds` from direction `towards_eye` (unit, from the box towards the eye) in
/// which a perspective camera (field of view `fov_y`, image `aspect`) sees the box's corners
/// centred and spanning `fill` of the shorter image side (the larger of their projected width
/// and height): exact for the box, not a bounding sphere, so a flat board or a thin pole fills
/// the frame. The projected extent shrinks as the eye backs away, so the distance is found by
/// bisection; the aim then moves across the view to centre the projection, three times over.
pub fn fit_box(bounds: &Aabb, towards_eye: Vec3, fov_y: f32, aspect: f32, fill: f32) -> Framing {
    let dir = towards_eye.normalize_or(Vec3::Z);
    let forward = -dir;
    let up_hint = if forward.cross(Vec3::Y).length_squared() < 1e-8 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let right = forward.cross(up_hint).normalize();
    let up = right.cross(forward);
    let aspect = aspect.max(1e-3);
    let t = (fov_y * 0.5).tan();
    let fill = fill.clamp(1e-3, 1.0);
    let centre = bounds.center();
    // Corners relative to the centre: across (x, y) and along the eye's direction.
    let corners: Vec<Vec3> = bounds
        .corners()
        .iter()
        .map(|&c| {
            let o = c - centre;
            Vec3::new(o.dot(right), o.dot(up), o.dot(dir))
        })
        .collect();
    let farthest_along = corners.iter().map(|c| c.z).fold(f32::MIN, f32::max);
    let size = corners
        .iter()
        .map(|c| c.length())
        .fold(0.0, f32::max)
        .max(1e-6);
    // NDC box (x0, y0, x1, y1) of the corners seen from distance `d`, aim shifted by `s`.
    let ndc_box = |d: f32, s: glam::Vec2| {
        let (mut lo, mut hi) = (glam::Vec2::MAX, glam::Vec2::MIN);
        for c in &corners {
            let z = (d - c.z).max(1e-9);
            let p = glam::Vec2::new((c.x - s.x) / (z * t * aspect), (c.y - s.y) / (z * t));
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo, hi)
    };
    // The larger projected side over the shorter image side.
    let short = aspect.min(1.0);
    let share = |d: f32, s: glam::Vec2| {
        let (lo, hi) = ndc_box(d, s);
        let span = (hi - lo) * 0.5;
        (span.x * aspect).max(span.y) / short
    };
    let mut shift = glam::Vec2::ZERO;
    let mut d = farthest_along + size;
    for round in 0..4 {
        let (mut near, mut far) = (farthest_along + size * 1e-4, farthest_along + size * 1e4);
        for _ in 0..64 {
            let mid = 0.5 * (near + far);
            if share(mid, shift) > fill {
                near = mid;
            } else {
                far = mid;
            }
        }
        d = far;
        if round == 3 {
            break;
        }
        // Centre the projected box: move the aim across by its NDC centre at its mean depth.
        let (lo, hi) = ndc_box(d, shift);
        let c = (lo + hi) * 0.5;
        shift += glam::Vec2::new(c.x * d * t * aspect, c.y * d * t);
    }
    let target = centre + right * shift.x + up * shift.y;
    Framing {
        eye: target + dir * d,
        target,
        nearest: (d - farthest_along).max(d * 1e-3),
    }
}

/// A perspective camera ([`FOV_Y_DEG`]) looking at `bounds` from direction `towards_eye` with
/// the box centred and filling [`FILL`] of the shorter side of an image of `aspect`
/// ([`fit_box`]); its near plane at half the nearest corner's depth.
pub fn framed_camera(bounds: &Aabb, towards_eye: Vec3, aspect: f32) -> Camera {
    let fov_y = FOV_Y_DEG.to_radians();
    let b = if bounds.is_empty() {
        Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
    } else {
        *bounds
    };
    let f = fit_box(&b, towards_eye, fov_y, aspect, FILL);
    Camera::look_at(f.eye, f.target, fov_y, f.nearest * 0.5)
}

impl crate::scene::Scene {
    /// The camera a model without one is seen through: from the front (+Z, looking towards
    /// −Z) [`DEFAULT_ELEVATION_DEG`] above the horizontal, at the centre of
    /// its bounds (`framing`, else `bounds()`), at the distance where the bounds' corners fill
    /// [`FILL`] of the shorter image side ([`framed_camera`]).
    pub fn default_camera(&self, aspect: f32) -> Camera {
        let b = self.framing.unwrap_or_else(|| self.bounds());
        framed_camera(&b, default_direction(), aspect)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::projection::ndc_to_pixel;
    use crate::plan::camera_projection;

    /// The projected pixel box of `b`'s corners through `cam` in a `w`×`h` image.
    fn pixel_box(cam: &Camera, b: &Aabb, w: u32, h: u32) -> (f32, f32, f32, f32) {
        let m = camera_projection(cam, w as f32 / h as f32) * cam.view_from_world();
        let (mut x0, mut y0, mut x1, mut y1) = (f32::MAX, f32::MAX, f32::MIN, f32::MIN);
        for c in b.corners() {
            let p = m * c.extend(1.0);
            let (x, y) = ndc_to_pixel(p.truncate().truncate() / p.w, w, h);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
        (x0, y0, x1, y1)
    }

    #[test]
    fn framed_boxes_fill_the_share_of_the_shorter_side() {
        // A flat board, a tall pole, a wide slab, one far from the origin; wide and tall images.
        let boxes = [
            Aabb::new(Vec3::new(-1.0, -1.0, -0.01), Vec3::new(1.0, 1.0, 0.01)),
            Aabb::new(Vec3::new(-0.1, 0.0, -0.1), Vec3::new(0.1, 5.0, 0.1)),
            Aabb::new(Vec3::new(-4.0, 0.0, -1.0), Vec3::new(4.0, 0.3, 1.0)),
            Aabb::new(
                Vec3::new(1e4, 20.0, -3e3),
                Vec3::new(1e4 + 2.0, 23.0, -3e3 + 1.0),
            ),
        ];
        for b in boxes {
            for (w, h) in [(640u32, 360u32), (300, 500), (256, 256)] {
                let cam = framed_camera(&b, default_direction(), w as f32 / h as f32);
                let (x0, y0, x1, y1) = pixel_box(&cam, &b, w, h);
                let short = w.min(h) as f32;
                let fill = (x1 - x0).max(y1 - y0) / short;
                assert!((fill - FILL).abs() < 2e-3, "{b:?} {w}x{h}: fill {fill}");
                // Centred: within a pixel.
                let (cx, cy) = ((x0 + x1) * 0.5, (y0 + y1) * 0.5);
                assert!((cx - w as f32 * 0.5).abs() < 1.0, "{b:?} {w}x{h}: x {cx}");
                assert!((cy - h as f32 * 0.5).abs() < 1.0, "{b:?} {w}x{h}: y {cy}");
                // Every corner in front of the near plane.
                let view = cam.view_from_world();
                for c in b.corners() {
                    assert!(-view.transform_point3(c).z > cam.near);
                }
            }
        }
    }

    #[test]
    fn the_default_view_looks_at_the_front_from_slightly_above() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let cam = framed_camera(&b, default_direction(), 1.5);
        let f = cam.forward();
        assert!(f.z < -0.9 && f.x.abs() < 1e-6, "{f}");
        let down = (-f.y).asin().to_degrees();
        assert!((down - DEFAULT_ELEVATION_DEG).abs() < 1e-3, "{down}");
    }
}
