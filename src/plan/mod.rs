//! Planning a frame on the CPU, with no GPU: from a posed scene, a view and its settings to an
//! immutable [`FramePlan`] (the lights, every shadow view with its casters, the camera, metering
//! and exposure, the frame's uniform block). The passes in [`crate::render`] record what a plan
//! says; the ray-cast reference reads the same plan.

pub(crate) mod casters;
pub(crate) mod frame;
pub(crate) mod settings;
pub(crate) mod uniforms;

pub use casters::{flat_hides_nothing, CasterPlan, Viewpoint};
pub use frame::{
    camera_projection, effective_lights, exposure_scale, lookup_reach, metered_illuminance,
    soft_size, FramePlan, ScenePlanner, ShadowView, CLEAR_COLOR,
};
pub use settings::{
    Exposure, HeldLight, Pcf, SceneOptions, ShadowFit, ShadowFormat, ShadowHold, ShadowSettings,
    Tonemap, View, ViewMode, AUTO_AMBIENT, MAX_CASCADES, UNIT_AMBIENT,
};
pub use uniforms::{MAX_LIGHTS, MAX_SHADOW_VIEWS};
