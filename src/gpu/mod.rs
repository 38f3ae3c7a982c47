//! The thin, safe layer over ash: context (instance, device, allocator, validation), resources that
//! free themselves, named barriers, and shader modules with reflected bindings. Only the context
//! and its options are public.

pub(crate) mod barrier;
pub(crate) mod context;
pub(crate) mod graph;
mod heap;
pub mod pipeline_cache;
pub(crate) mod pipeline_store;
pub(crate) mod recorder;
pub(crate) mod resources;
pub(crate) mod shaders;

pub use context::{Context, ContextDesc, GpuError, RawVulkan, Validation, ValidationLog};
pub(crate) use graph::{Attachment, BufferAccess, SharedBuffer, Uses};
pub(crate) use recorder::Recorder;
pub(crate) use resources::{Buffer, Image};
