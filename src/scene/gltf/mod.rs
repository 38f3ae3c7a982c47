//! Reading glTF 2.0: the file checked and its references resolved (`input`), compressed and
//! quantized data made plain first (`compressed`), then nodes, materials and primitives read into
//! the scene model (`load`, `nodes`, `material`, `primitive`); errors and limits in `error`.

pub mod compressed;
pub(crate) mod error;
pub(crate) mod input;
pub(crate) mod load;
mod material;
mod nodes;
mod primitive;

pub use error::{LoadError, MAX_FILE_BYTES, MAX_TEXTURE_SIDE};
pub use load::load_gltf;
