//! The command line's and the viewer's tests, one test binary: one link, one process.

#[path = "../../tests/common/mod.rs"]
mod common;
mod xvfb;

mod cli_errors;
#[cfg(feature = "reference")]
mod exposure;
mod inspect;
#[cfg(feature = "sweep")]
mod sweep_cli;
#[cfg(all(feature = "viewer", feature = "reference"))]
mod viewer;
mod viewer_panel;
mod views;
