//! Screen rectangles of draws and points: where a draw lands in pixels, and how large its
//! triangles are there.

use crate::render::gpu_scene::Draw;
use ash::vk;
use glam::{Mat4, Vec2, Vec3};

/// A pixel rectangle `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelRect {
    /// Left, top (inclusive).
    pub min: Vec2,
    /// Right, bottom (exclusive).
    pub max: Vec2,
}

impl PixelRect {
    /// The smallest rectangle holding both.
    pub fn union(self, o: PixelRect) -> PixelRect {
        PixelRect {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// Whole pixels covering the rectangle, as a scissor.
    pub fn scissor(&self) -> vk::Rect2D {
        let x0 = self.min.x.floor().max(0.0) as i32;
        let y0 = self.min.y.floor().max(0.0) as i32;
        let x1 = self.max.x.ceil().max(0.0) as i32;
        let y1 = self.max.y.ceil().max(0.0) as i32;
        vk::Rect2D {
            offset: vk::Offset2D { x: x0, y: y0 },
            extent: vk::Extent2D {
                width: (x1 - x0).max(0) as u32,
                height: (y1 - y0).max(0) as u32,
            },
        }
    }
}

/// The pixels of an `extent` image that `dr`'s world bounds project to (clamped to the image);
/// `None` when a corner lies behind the eye (the rectangle would be unbounded).
pub fn screen_rect(dr: &Draw, clip_from_world: &Mat4, extent: vk::Extent2D) -> Option<PixelRect> {
    points_rect(dr.world_bounds.corners(), clip_from_world, extent)
}

/// The pixels of an `extent` image that world points `points` project to (clamped to the
/// image); `None` when one lies at or behind the eye.
pub fn points_rect(
    points: impl IntoIterator<Item = Vec3>,
    clip_from_world: &Mat4,
    extent: vk::Extent2D,
) -> Option<PixelRect> {
    let size = Vec2::new(extent.width as f32, extent.height as f32);
    let mut min = Vec2::splat(f32::INFINITY);
    let mut max = Vec2::splat(f32::NEG_INFINITY);
    for c in points {
        let p = *clip_from_world * c.extend(1.0);
        if p.w <= 1e-6 {
            return None;
        }
        // Clip y is up, pixel rows go down.
        let px = Vec2::new(p.x / p.w * 0.5 + 0.5, 0.5 - p.y / p.w * 0.5) * size;
        min = min.min(px);
        max = max.max(px);
    }
    Some(PixelRect {
        min: min.clamp(Vec2::ZERO, size),
        max: max.clamp(Vec2::ZERO, size),
    })
}

/// The mean screen area in pixels of `dr`'s triangles that face the eye, estimated at its
/// bounds' centre: half the mean world area (the mean projection of a facing triangle)
/// times the pixels per world unit squared there (`extent`'s height over the view's height at
/// that depth). Infinite where the centre is at or behind the eye.
pub fn pixels_per_triangle(dr: &Draw, clip_from_world: &Mat4, extent: vk::Extent2D) -> f32 {
    let w = (*clip_from_world * dr.world_bounds.center().extend(1.0)).w;
    if w <= 1e-6 {
        return f32::INFINITY;
    }
    // Row 1 of projection × view is the projection's y scale times a unit row of the view.
    let scale_y = clip_from_world.row(1).truncate().length();
    let px_per_unit = 0.5 * extent.height as f32 * scale_y / w;
    0.5 * dr.mean_area * px_per_unit * px_per_unit
}
