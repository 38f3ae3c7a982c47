//! Planning a frame on the CPU, with no GPU: from a posed scene, a view and its settings to an
//! immutable [`FramePlan`] (the lights, every shadow view with its casters, the camera, metering
//! and exposure, the frame's uniform block). The passes in [`crate::render`] record what a plan
//! says; the ray-cast reference reads the same plan.
//!
//! In one direction: `settings`, `input`, `camera`, `batch` → `views` (shadow views) → `lights`
//! (shading lights, metering, their uniforms) → `frame` (the plan) ; `casters` and `uniforms`
//! are the data the plan carries.

pub(crate) mod batch;
pub(crate) mod camera;
pub(crate) mod casters;
pub(crate) mod exact;
pub(crate) mod frame;
pub(crate) mod input;
pub(crate) mod lights;
pub(crate) mod reach;
pub mod report;
pub(crate) mod settings;
pub(crate) mod sight;
pub(crate) mod uniforms;
pub(crate) mod view;
pub(crate) mod views;

pub use batch::ShadowBatch;
pub use camera::{camera_projection, fitting_frustum};
pub use casters::{flat_hides_nothing, CasterPlan, TexelRect, Viewpoint};
pub use exact::{ExactMode, ExactPlan, CONTACT_TEXELS, CONTACT_THICKNESS};
pub use frame::{plan_frame, resolve_format, FramePlan, ScenePlanner, CLEAR_COLOR};
pub use input::{PlanScene, PlanTarget};
pub use lights::{effective_lights, exposure_scale, metered_illuminance};
pub use reach::ShadowReach;
pub use settings::{
    DeviceFacts, Pcf, PostAa, SceneOptions, ShadowFit, ShadowFormat, ShadowMethod, ShadowSettings,
    Tonemap, ViewMode, MAX_CASCADES,
};
pub use sight::Sight;
pub use uniforms::{MAX_LIGHTS, MAX_SHADOW_VIEWS};
pub use view::{
    Ambient, Background, Exposure, HeldLight, ShadowHold, View, AUTO_GROUND, AUTO_SKY, GROUND_TINT,
    SKY_TINT, SUPERSAMPLE_FACTORS, UNIT_AMBIENT,
};
pub use views::{lookup_reach, soft_size, ShadowView};
