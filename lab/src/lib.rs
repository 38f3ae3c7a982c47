//! umbra's lab: the measurements the engine is judged by, kept out of the engine crate so that a
//! user's test pays only for the renderer.
//!
//! - [`reference`]: the CPU ground truth (a BVH over the posed scene, exact shadow visibility by
//!   ray casting, a Blinn-Phong reference image) and the metrics that compare a GPU frame with it.
//!   It reads the engine's [`umbra::plan`] (the frame plan both sides shade from), never its
//!   renderer.
//! - [`analysis`] (feature `sweep`): speed against accuracy (the configuration sweep, its Pareto
//!   front and charts), the error-budget chooser, and the stability suite.
//! - [`score`]: renders a view with the engine and scores it against the reference.
//! - [`report`]: one self-contained HTML page of failed goldens, `compare`, `sweep` and
//!   `stability` outputs under a folder (`umbra report DIR`).

#[cfg(feature = "sweep")]
pub mod analysis;
pub mod reference;
pub mod report;
pub mod score;
pub mod table;

pub use score::{score, Scored};
