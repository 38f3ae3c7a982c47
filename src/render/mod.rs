//! Rendering: one module per pass, the per-frame plan, and the offscreen renderer. Passes,
//! pipelines and uniform layouts are internal; the public types are re-exported here.

pub(crate) mod camera_pass;
pub(crate) mod core;
pub(crate) mod deferred;
pub(crate) mod frame;
pub(crate) mod gpu_scene;
pub(crate) mod pipeline;
pub(crate) mod receivers;
pub(crate) mod renderer;
pub mod report;
pub(crate) mod samplers;
pub(crate) mod settings;
pub(crate) mod shadow_cache;
pub(crate) mod shadow_pass;
#[cfg(feature = "viewer")]
pub(crate) mod swapchain;
pub(crate) mod uniforms;
#[cfg(feature = "viewer")]
pub(crate) mod window;

pub use frame::{effective_lights, metered_illuminance, FramePlan, ScenePlanner, ShadowView};
pub use renderer::{FrameStats, RenderedFrame, Renderer, MAX_SIDE};
pub use settings::{
    Exposure, HeldLight, Pcf, SceneOptions, ShadowFit, ShadowFormat, ShadowHold, ShadowSettings,
    Tonemap, View, ViewMode, AUTO_AMBIENT, MAX_CASCADES, UNIT_AMBIENT,
};
pub use uniforms::{MAX_LIGHTS, MAX_SHADOW_VIEWS};
#[cfg(feature = "viewer")]
pub use window::{surface_extensions, DrawResult, WindowRenderer};
