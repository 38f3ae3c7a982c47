//! Speed against accuracy (feature `sweep`): a grid of shadow configurations timed on the GPU and
//! scored against the ray-cast reference ([`sweep`]), the Pareto front of the results
//! ([`pareto`]), its charts ([`chart`]), and settings chosen for an error budget ([`budget`]).
//!
//! Layered above [`umbra::render`] and [`crate::reference`]; the command line is a thin shell over
//! these functions.

pub mod budget;
pub mod campaign;
pub mod chart;
pub mod coeffs;
pub mod grid;
pub mod lines;
pub mod model;
pub mod pareto;
pub mod stability;
pub mod sweep;

pub use grid::{sweep_views, Config, Grid};
pub use pareto::pareto_front;
pub use sweep::{
    mean_by_config, read_csv, run_view, write_json, CsvAppender, Row, Sink, SweepOptions, SweepView,
};
