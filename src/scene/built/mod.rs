//! Scenes built in code, which the engine never uses itself: the demo, the `--synthetic` set
//! (`synthetic`), generated foliage, and the shapes they are made of (`shapes`, `open_shapes`:
//! boxes, spheres, grounds, open organic meshes).

pub mod demo;
pub mod foliage;
pub mod open_shapes;
pub mod shapes;
pub mod synthetic;
