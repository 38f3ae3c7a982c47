//! Work on meshes: normals and tangents (`tangents`, `mikk`), closedness and planes
//! (`topology`), clusters of large primitives (`clusters`), cutout cards cut to their alpha
//! (`trim`), and framing a model's bounds (`framing`).

pub mod clusters;
pub mod framing;
pub mod mikk;
pub mod tangents;
pub mod topology;
pub mod trim;
