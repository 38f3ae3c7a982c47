//! umbra: a real-time shadow-mapping raster engine on Vulkan.
//!
//! Layers, in one direction only: [`math`] → [`scene`] → [`gpu`] → [`render`].
//!
//! Render a frame offscreen (this example runs in the test suite, on lavapipe, with validation):
//!
//! ```
//! use umbra::{gpu::{Context, ContextDesc, Validation}, render::{Renderer, View}, scene::demo::demo_scene};
//!
//! let scene = demo_scene();
//! let ctx = Context::new(&ContextDesc { validation: Validation::Required, ..Default::default() })?;
//! let mut renderer = Renderer::new(&ctx, &scene)?;
//! let frame = renderer.render(&View::new(scene.cameras[0]), 64, 36)?;
//! assert_eq!(frame.image.dimensions(), (64, 36));
//! assert!(frame.stats.casters_drawn > 0);
//! assert_eq!(ctx.validation_log.problem_count(), 0);
//! frame.image.save(std::env::temp_dir().join("umbra-doc-demo.png"))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod app;
pub mod gpu;
pub mod math;
pub mod reference;
pub mod render;
pub mod scene;
