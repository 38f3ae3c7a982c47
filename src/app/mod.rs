//! Command-line front end helpers shared by the subcommands: argument types and scene/view setup.

pub mod actions;
pub mod cli;
pub mod controller;
pub mod viewer;
