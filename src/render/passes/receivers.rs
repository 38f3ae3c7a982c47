//! Receivers beyond the casters' reach.
//!
//! A shadow lookup whose point projects outside the casters' rectangle in the light's view
//! (`CasterPlan::lookup`) is lit without a read, but llvmpipe runs both sides of every branch:
//! every fragment of a shadowed variant pays the projection and the gathered comparison, on a
//! ground plane that mostly lies where no caster can shadow it as on the object above it. So on
//! CPU devices a small draw (`SPLIT_MAX_TRIANGLES`, such as a ground) that lies partly inside
//! the reach is drawn twice, scissored: with the shadowed shader over the screen rectangle of
//! the part of its bounds a lookup can reach (`ShadowReach::clip`), and with the same material's
//! unshadowed variant over the rest of the image (up to four bands). A draw wholly outside the
//! reach is drawn unshadowed. The image is the same: outside the reach the shadowed shader's
//! visibility is exactly 1.
//!
//! Only frames with one shadow view use it (a single map of a directional light or a spot
//! light's; cascades and cube faces keep the shadowed shader everywhere).

use crate::plan::ShadowReach;
use crate::render::gpu_scene::Draw;
use crate::render::passes::screen::{points_rect, screen_rect, PixelRect};
use crate::shader_consts::VariantKey;
use ash::vk;
use glam::{Mat4, Vec2};

/// Draws of more triangles keep the shadowed shader everywhere: each split draws the geometry
/// again for every scissor (up to five times) on llvmpipe's single geometry thread (~11 ms per
/// 100 k triangles there, so at most ~0.5 ms for four more passes over 1,024). Not swept: the
/// draws the benchmarks split are grounds of 2 triangles.
pub const SPLIT_MAX_TRIANGLES: u32 = 1024;

/// How one draw is shaded against the reach.
#[derive(Clone, Debug, PartialEq)]
pub enum Split {
    /// The shadowed shader everywhere.
    Shadowed,
    /// The unshadowed shader everywhere (no point of the draw can be shadowed).
    Unshadowed,
    /// The shadowed shader in `inside`, the unshadowed one in each of `outside` (the rest of
    /// the draw's screen rectangle; together they hold every pixel once).
    Both {
        /// Scissor of the reach's screen rectangle.
        inside: vk::Rect2D,
        /// Scissors of the bands around it.
        outside: Vec<vk::Rect2D>,
    },
}

/// How `dr`, seen through `clip_from_world` at `extent`, is drawn against `reach`.
pub fn split(
    reach: &ShadowReach,
    dr: &Draw,
    clip_from_world: &Mat4,
    extent: vk::Extent2D,
) -> Split {
    let Some(corners) = reach.clip(&dr.world_bounds) else {
        return Split::Unshadowed;
    };
    if dr.index_count / 3 > SPLIT_MAX_TRIANGLES {
        return Split::Shadowed;
    }
    // Part of the reach at or behind the eye: its screen rectangle is unbounded.
    let Some(r) = points_rect(corners, clip_from_world, extent) else {
        return Split::Shadowed;
    };
    // A pixel of slack for rasterisation rules.
    let size = Vec2::new(extent.width as f32, extent.height as f32);
    let inside = PixelRect {
        min: (r.min - Vec2::ONE).max(Vec2::ZERO),
        max: (r.max + Vec2::ONE).min(size),
    }
    .scissor();
    let outer = screen_rect(dr, clip_from_world, extent)
        .map(|r| r.scissor())
        .unwrap_or(rect(0, 0, extent.width as i32, extent.height as i32));
    let inner = intersect(inside, outer);
    if inner.extent.width == 0 || inner.extent.height == 0 {
        return Split::Unshadowed;
    }
    if inner == outer {
        return Split::Shadowed;
    }
    Split::Both {
        inside: inner,
        outside: bands(outer, inner),
    }
}

/// The shader variant of `bits` without shadows: the SHADOWS override and those that mean
/// nothing without it off (the canonical index of that SPIR-V).
pub fn unshadowed(bits: VariantKey) -> VariantKey {
    bits - VariantKey::WITH_SHADOWS
}

fn intersect(a: vk::Rect2D, b: vk::Rect2D) -> vk::Rect2D {
    let x0 = a.offset.x.max(b.offset.x);
    let y0 = a.offset.y.max(b.offset.y);
    let x1 = (a.offset.x + a.extent.width as i32).min(b.offset.x + b.extent.width as i32);
    let y1 = (a.offset.y + a.extent.height as i32).min(b.offset.y + b.extent.height as i32);
    rect(x0, y0, x1, y1)
}

fn rect(x0: i32, y0: i32, x1: i32, y1: i32) -> vk::Rect2D {
    vk::Rect2D {
        offset: vk::Offset2D { x: x0, y: y0 },
        extent: vk::Extent2D {
            width: (x1 - x0).max(0) as u32,
            height: (y1 - y0).max(0) as u32,
        },
    }
}

/// `outer` less `inner` (which lies inside it) as up to four rectangles: full-width bands above
/// and below, and the two sides between them.
fn bands(outer: vk::Rect2D, inner: vk::Rect2D) -> Vec<vk::Rect2D> {
    let (ox0, oy0) = (outer.offset.x, outer.offset.y);
    let (ox1, oy1) = (
        ox0 + outer.extent.width as i32,
        oy0 + outer.extent.height as i32,
    );
    let (ix0, iy0) = (inner.offset.x, inner.offset.y);
    let (ix1, iy1) = (
        ix0 + inner.extent.width as i32,
        iy0 + inner.extent.height as i32,
    );
    [
        rect(ox0, oy0, ox1, iy0),
        rect(ox0, iy1, ox1, oy1),
        rect(ox0, iy0, ix0, iy1),
        rect(ix1, iy0, ox1, iy1),
    ]
    .into_iter()
    .filter(|r| r.extent.width > 0 && r.extent.height > 0)
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Aabb;
    use glam::{Vec3, Vec4};

    /// A sun straight down (-y), its ortho view ±10 units: x → ndc x, z → ndc y.
    fn sun_down() -> Mat4 {
        let view = Mat4::look_to_rh(Vec3::new(0.0, 20.0, 0.0), Vec3::NEG_Y, Vec3::NEG_Z);
        Mat4::orthographic_rh(-10.0, 10.0, -10.0, 10.0, 0.1, 40.0) * view
    }

    #[test]
    fn ground_is_clipped_to_the_casters_columns() {
        // Casters' rectangle: the middle fifth of a 100-texel map (texels 40..60), 0.2 units
        // a texel; no offset beyond the slack (1 texel = 0.2 units).
        let reach = ShadowReach::new(
            &sun_down(),
            Vec4::new(40.0, 40.0, 60.0, 60.0),
            100.0,
            0.0,
            0.2,
            None,
        );
        let ground = Aabb::new(Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 0.0, 10.0));
        let c = reach
            .clip(&ground)
            .expect("the middle of the ground is in reach");
        let b = Aabb::from_points(c);
        // Texels 40..60 are x in [-2, 2], grown by 0.2.
        assert!(
            (b.min.x + 2.2).abs() < 1e-4 && (b.max.x - 2.2).abs() < 1e-4,
            "{b:?}"
        );
        assert!(
            (b.min.z + 2.2).abs() < 1e-4 && (b.max.z - 2.2).abs() < 1e-4,
            "{b:?}"
        );
        // A box off to the side: out of reach.
        let far = Aabb::new(Vec3::new(5.0, 0.0, 5.0), Vec3::new(6.0, 3.0, 6.0));
        assert!(reach.clip(&far).is_none());
        // An empty casters' rectangle reaches nothing.
        let none = ShadowReach::new(
            &sun_down(),
            Vec4::new(1.0, 1.0, -1.0, -1.0),
            100.0,
            0.0,
            0.2,
            None,
        );
        assert!(none.clip(&ground).is_none());
    }

    #[test]
    fn spot_apex_inside_the_box_is_kept() {
        // A spot at the origin looking down -y with a 90° cone; the box holds the light.
        let view = Mat4::look_to_rh(Vec3::ZERO, Vec3::NEG_Y, Vec3::NEG_Z);
        let m = Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, 0.1, 50.0) * view;
        let reach = ShadowReach::new(
            &m,
            Vec4::new(0.0, 0.0, 64.0, 64.0),
            64.0,
            0.0,
            0.0,
            Some(Vec3::ZERO),
        );
        let room = Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0));
        let c = reach.clip(&room).expect("below the light is in reach");
        let b = Aabb::from_points(c.iter().copied());
        // The cone below the light: y from the floor up to the apex, |x| up to 5 at the floor.
        assert!(
            (b.max.y - 0.0).abs() < 1e-4 && (b.min.y + 5.0).abs() < 1e-4,
            "{b:?}"
        );
        assert!(c.contains(&Vec3::ZERO));
        // Above the light nothing is lit by it through the map.
        let attic = Aabb::new(Vec3::new(-5.0, 1.0, -5.0), Vec3::new(5.0, 5.0, 5.0));
        assert!(reach.clip(&attic).is_none());
    }

    #[test]
    fn bands_cover_the_rest_once() {
        let outer = rect(0, 0, 100, 50);
        let inner = rect(30, 10, 60, 40);
        let b = bands(outer, inner);
        assert_eq!(b.len(), 4);
        let area = |r: &vk::Rect2D| r.extent.width * r.extent.height;
        assert_eq!(b.iter().map(area).sum::<u32>() + area(&inner), area(&outer));
        // Every pixel in exactly one rectangle.
        for y in 0..50 {
            for x in 0..100 {
                let hits = b
                    .iter()
                    .chain([&inner])
                    .filter(|r| {
                        x >= r.offset.x
                            && x < r.offset.x + r.extent.width as i32
                            && y >= r.offset.y
                            && y < r.offset.y + r.extent.height as i32
                    })
                    .count();
                assert_eq!(hits, 1, "pixel {x},{y}");
            }
        }
        // Touching an edge leaves fewer bands.
        assert_eq!(bands(outer, rect(0, 0, 60, 50)).len(), 1);
    }

    #[test]
    fn unshadowed_variant_clears_the_shadow_bits() {
        let bits =
            VariantKey::ONE_SUN | VariantKey::SHADOWS | VariantKey::PCF_BIT0 | VariantKey::SOFT;
        assert_eq!(unshadowed(bits), VariantKey::ONE_SUN);
    }
}
