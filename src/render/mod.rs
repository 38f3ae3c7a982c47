//! Rendering, in rooms by job: the passes (`passes/`), the images they draw into (`targets/`),
//! pipelines and samplers, the scene's GPU copy (`gpu_scene`), the frame scheduler (`core`:
//! prepare, then record) and the offscreen and window renderers. The passes record what a
//! [`crate::plan::FramePlan`] says. Passes, pipelines and uniform layouts are internal; the
//! plan's types (`View`, `SceneOptions`, …) are spelled `umbra::plan::…`, the renderers' here.

pub(crate) mod core;
mod device;
pub(crate) mod gpu_scene;
pub(crate) mod passes;
pub(crate) mod pipeline;
pub(crate) mod renderer;
pub(crate) mod samplers;
pub(crate) mod targets;
#[cfg(feature = "viewer")]
pub(crate) mod window;

pub use device::device_facts;
pub use gpu_scene::TextureStats;
pub use renderer::{
    view_axis_depths, AovSet, Aovs, BatchShadows, FrameStats, RenderedFrame, Renderer, Sink,
    MAX_SIDE, RING, SHARED_MAP_MAX,
};
#[cfg(feature = "viewer")]
pub use window::{
    surface_extensions, Capture, DrawResult, FrameSummary, Overlay, WindowRenderer,
    FRAMES_IN_FLIGHT,
};
