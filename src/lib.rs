//! umbra: a real-time shadow-mapping raster engine on Vulkan.
//!
//! Layers, in one direction only: [`math`] → [`scene`] → [`gpu`] → [`render`].
//!
//! ```no_run
//! use std::sync::Arc;
//! use umbra::{gpu::{Context, ContextDesc}, render::{Renderer, View}, scene::demo::demo_scene};
//!
//! let scene = demo_scene();
//! let ctx = Context::new(&ContextDesc::default())?;
//! let mut renderer = Renderer::new(&ctx, &scene)?;
//! let view = View::new(scene.cameras[0]);
//! let frame = renderer.render(&view, 640, 360)?;
//! frame.image.save("demo.png")?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod app;
pub mod gpu;
pub mod math;
pub mod reference;
pub mod render;
pub mod scene;
