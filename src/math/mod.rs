//! Pure maths: rotations, reversed-z projections, bounds, rays, interpolation, Bézier paths and
//! light-frustum fitting. No Vulkan here; everything is unit-tested.

pub mod bezier;
pub mod bounds;
pub mod interp;
pub mod precision;
pub mod projection;
pub mod ray;
pub mod rotation;
pub mod shadow_fit;

pub use bounds::Aabb;
pub use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
