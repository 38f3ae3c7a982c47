//! CPU ground truth: a BVH over the scene's triangles, exact shadow visibility by ray casting,
//! a Blinn-Phong reference image with the same material constants as the GPU, and metrics that
//! compare a GPU frame with it.

pub mod bvh;
pub mod metrics;
pub mod raycast;

pub use bvh::{Bvh, Hit};
pub use metrics::{
    classify, compare, edge_band, flip, misclassified_by_depth, psnr, summarise, Classified,
    DepthBin, Metrics, PixelClass,
};
pub use raycast::{Pick, Probe, ReferenceFrame, ReferenceScene};
