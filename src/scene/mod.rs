//! The renderer-agnostic CPU scene: meshes, materials, textures, lights, cameras and instances,
//! loaded from glTF 2.0 or built in code. Repairs (normals, tangents) happen here, with warnings.
//!
//! The model (`types`, `material`, `sampler`, `warning`, `pose` for cameras placed by a matrix,
//! and `anim` for motion) at the centre, with three wings around it: `gltf` reads files into it,
//! `mesh` works on its meshes, `built` makes scenes in code. `inspect` reports on a file and its
//! scene.

pub mod anim;
pub mod built;
pub mod gltf;
pub mod inspect;
pub mod material;
pub mod mesh;
mod pose;
pub mod sampler;
mod types;
pub mod warning;

pub use material::{blinn_phong_params, shade_blinn_phong, BlinnPhong};
pub use sampler::{Filter, Sampler, UvTransform, Wrap};
pub use types::*;
pub use warning::Warning;
