//! The thin, safe layer over ash: context (instance, device, allocator, validation), resources that
//! free themselves, named barriers, and shader modules with reflected bindings.

pub mod barrier;
pub mod context;
pub mod resources;
pub mod shaders;

pub use context::{Context, ContextDesc, GpuError, Validation, ValidationLog};
pub use resources::{Buffer, Image};
