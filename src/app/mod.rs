//! Command-line front end helpers shared by the subcommands: argument types and scene/view setup.

pub mod cli;
