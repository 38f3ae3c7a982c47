//! The lab's tests (the reference, the metrics, the sweep, the budget chooser, the stability
//! suite, and the engine judged by them), one test binary: one link, one process.

#[path = "../../tests/common/mod.rs"]
mod common;

mod animation;
mod batch;
#[cfg(feature = "sweep")]
mod budget;
mod depth_fit;
mod exact_shadows;
mod first_look;
mod foliage;
mod golden;
mod lights;
mod masked_shadows;
mod material_inputs;
mod multi_light_shadows;
mod reference;
mod scale;
mod soft_shadows;
#[cfg(feature = "sweep")]
mod stability;
mod texture_sampling;
mod transparency;
