//! The binary's front end: argument types and scene/view setup (clap), and the windowed viewer
//! (winit) with its input logic. Not part of the library.

#[cfg(feature = "viewer")]
pub mod actions;
pub mod cli;
#[cfg(feature = "viewer")]
pub mod controller;
#[cfg(feature = "viewer")]
pub mod viewer;
