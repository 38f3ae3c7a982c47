//! The binary's front end: argument types and scene/view setup (clap), and the windowed viewer
//! (winit) with its input logic. Not part of the library.

#[cfg(feature = "viewer")]
pub mod actions;
pub mod bench;
#[cfg(all(feature = "viewer", feature = "sweep"))]
pub mod budget_worker;
pub mod cli;
#[cfg(feature = "viewer")]
pub mod controller;
pub mod inspect_view;
#[cfg(feature = "reference")]
pub mod lab_commands;
#[cfg(feature = "viewer")]
pub mod overlay;
#[cfg(feature = "viewer")]
pub mod panel;
pub mod parse;
#[cfg(all(feature = "viewer", feature = "reference"))]
pub mod pick;
#[cfg(feature = "viewer")]
pub mod player;
#[cfg(feature = "viewer")]
pub mod reload;
#[cfg(feature = "viewer")]
pub mod scene_tree;
#[cfg(feature = "viewer")]
pub mod script;
#[cfg(feature = "viewer")]
pub mod viewer;
pub mod views;

/// The binary's pipeline cache file: `UMBRA_PIPELINE_CACHE` (a path, or `off`), else the user's
/// cache directory (`umbra::gpu::pipeline_cache::default_path`).
pub fn pipeline_cache_path() -> Option<std::path::PathBuf> {
    match std::env::var_os("UMBRA_PIPELINE_CACHE") {
        Some(v) if v == "off" || v == "0" => None,
        Some(v) if !v.is_empty() => Some(v.into()),
        _ => umbra::gpu::pipeline_cache::default_path(),
    }
}
