//! The engine's GPU and loader tests, one test binary (one link, one process: the GPU tests take
//! turns on the device through `common::one_at_a_time`, the others run beside them). The soak
//! test runs alone in its own process (`tests/soak.rs`): it measures the process's memory.

mod common;

mod aov;
mod cascades;
mod compressed;
mod culling;
mod debug_views;
mod deferred;
mod degenerate_inputs;
mod gltf_corpus;
mod gpu_normal_map;
mod gpu_render;
mod gpu_shadows;
mod ktx2_levels;
mod loader_fuzz;
mod msaa;
mod receivers;
mod shadow_cache;
