//! Pure maths: rotations, reversed-z projections, bounds, rays, interpolation, Bézier paths,
//! light-frustum fitting and tone-mapping curves. No Vulkan here; everything is unit-tested.

pub mod bezier;
pub mod bounds;
pub mod interp;
pub mod mips;
pub mod precision;
pub mod projection;
pub mod ray;
pub mod rotation;
pub mod shadow_fit;
pub mod tonemap;

pub use bounds::Aabb;
pub use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

/// Levels of a full mip chain for a `w`×`h` image (down to 1×1).
pub fn mip_levels(w: u32, h: u32) -> u32 {
    32 - w.max(h).max(1).leading_zeros()
}

#[cfg(test)]
mod tests {
    #[test]
    fn mip_levels_of_a_full_chain() {
        assert_eq!(super::mip_levels(1, 1), 1);
        assert_eq!(super::mip_levels(4, 1), 3);
        assert_eq!(super::mip_levels(512, 300), 10);
        assert_eq!(super::mip_levels(0, 0), 1);
    }
}
