//! Rendering: one module per pass, the per-frame plan, and the offscreen renderer.

pub mod camera_pass;
pub mod core;
pub mod frame;
pub mod gpu_scene;
pub mod pipeline;
pub mod renderer;
pub mod settings;
pub mod shadow_pass;
pub mod swapchain;
pub mod uniforms;
pub mod window;

pub use renderer::{FrameStats, RenderedFrame, Renderer};
pub use settings::{Pcf, SceneOptions, ShadowFit, ShadowFormat, ShadowSettings, View, ViewMode};
