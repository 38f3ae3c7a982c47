//! umbra: a real-time shadow-mapping raster engine on Vulkan.
//!
//! Layers, in one direction only: [`math`] → [`scene`] → [`gpu`] → [`plan`] → [`render`]. The
//! CPU ray-cast reference, the metrics and the sweep live in the `umbra-lab` crate beside it, and
//! the command line and viewer in `umbra-cli`; this crate depends on neither.
//!
//! The crate root re-exports what an offscreen image test needs. Feature `viewer` (off by
//! default) adds the window renderer.
//!
//! Render a frame offscreen (this example runs in the test suite, on lavapipe, with validation):
//!
//! ```
//! use umbra::{demo_scene, Context, ContextDesc, Renderer, Validation, View};
//!
//! let scene = demo_scene();
//! let ctx = Context::new(&ContextDesc { validation: Validation::Required, ..Default::default() })?;
//! let log = ctx.validation_log.clone();
//! let mut renderer = Renderer::new(&ctx, &scene)?;
//! let frame = renderer.render(&View::new(scene.cameras[0]), 64, 36)?;
//! assert_eq!(frame.image.dimensions(), (64, 36));
//! assert!(frame.stats.casters_drawn > 0);
//! frame.image.save(std::env::temp_dir().join("umbra-doc-demo.png"))?;
//! // Count validation messages after everything is destroyed (leaks are reported then).
//! drop(renderer);
//! drop(ctx);
//! assert_eq!(log.problem_count(), 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#[cfg(feature = "golden")]
pub mod golden;
pub mod gpu;
pub mod math;
pub(crate) mod parallel;
pub mod plan;
pub mod render;
pub mod scene;
pub(crate) mod shader_consts;

pub use gpu::{Context, ContextDesc, GpuError, Validation, ValidationLog};
pub use plan::{
    FramePlan, Pcf, SceneOptions, ShadowFit, ShadowFormat, ShadowHold, ShadowMethod,
    ShadowSettings, View, ViewMode,
};
pub use render::{FrameStats, RenderedFrame, Renderer};
pub use scene::{
    built::demo::demo_scene, gltf::load_gltf, gltf::LoadError, Camera, Light, LightKind, Scene,
};
