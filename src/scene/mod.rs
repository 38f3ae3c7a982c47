//! The renderer-agnostic CPU scene: meshes, materials, textures, lights, cameras and instances,
//! loaded from glTF 2.0 or built in code. Repairs (normals, tangents) happen here, with warnings.

pub mod anim;
pub mod clusters;
pub mod compressed;
pub mod demo;
pub mod foliage;
pub mod framing;
mod gltf_input;
pub mod gltf_load;
mod gltf_material;
mod gltf_nodes;
mod gltf_primitive;
pub mod inspect;
pub mod load_error;
pub mod material;
pub mod mikk;
pub mod open_shapes;
pub mod sampler;
pub mod shapes;
pub mod synthetic;
pub mod tangents;
pub mod topology;
pub mod trim;
mod types;
pub mod warning;

pub use gltf_load::load_gltf;
pub use load_error::LoadError;
pub use material::{blinn_phong_params, shade_blinn_phong, BlinnPhong};
pub use sampler::{Filter, Sampler, UvTransform, Wrap};
pub use types::*;
pub use warning::Warning;
