//! umbra: a real-time shadow-mapping raster engine on Vulkan.
//!
//! Layers, in one direction only: [`math`] → [`scene`] → [`gpu`] → [`render`].

pub mod math;
pub mod scene;
