//! One GPU frame scored against the exact reference: what `umbra compare`, the sweep and the
//! error budget's checks all measure.

use crate::reference::metrics::{classify, summarise, Classified, Metrics};
use crate::reference::raycast::{ReferenceFrame, ReferenceScene};
use umbra::gpu::GpuError;
use umbra::plan::{View, ViewMode};
use umbra::render::{RenderedFrame, Renderer};

/// A scored frame.
pub struct Scored {
    /// Shadow and image error.
    pub metrics: Metrics,
    /// Reference in grey, false shadow red, false light blue.
    pub diff: image::RgbaImage,
    /// The lit GPU frame (image, plan, timings).
    pub lit: RenderedFrame,
    /// The GPU's shadow view (the shown light's visibility, grey).
    pub shadow: image::RgbaImage,
    /// Every pixel's classification (false shadow, false light, edge band).
    pub classified: Classified,
    /// Time spent ray-casting the reference in this call (ms; 0 when `exact` was given).
    pub reference_ms: f64,
}

/// Renders `view` lit and as shadow visibility (with depth) at `w`×`h` and compares them with the
/// exact reference, which is ray-cast into `exact` when it is empty (the reference depends on the
/// camera and lights, sizes included, not on shadow settings, so one serves every configuration
/// of a view that keeps its lights).
pub fn score(
    renderer: &mut Renderer,
    reference: &ReferenceScene,
    view: &View,
    (w, h): (u32, u32),
    exact: &mut Option<ReferenceFrame>,
) -> Result<Scored, GpuError> {
    let mut v = view.clone();
    v.mode = ViewMode::Lit;
    renderer.set_read_depth(false);
    let lit = renderer.render(&v, w, h)?;
    v.mode = ViewMode::Shadow;
    renderer.set_read_depth(true);
    let shadow = renderer.render(&v, w, h);
    renderer.set_read_depth(false);
    let shadow = shadow?;
    let t0 = std::time::Instant::now();
    let frame = exact.get_or_insert_with(|| reference.render(&lit.plan, w, h, lit.plan.ambient));
    let reference_ms = t0.elapsed().as_secs_f64() * 1e3;
    let depth = shadow.depth.as_deref().unwrap_or(&[]);
    let classified = classify(&shadow.image, depth, &lit.plan, frame);
    let (mut metrics, diff) = summarise(&classified, &lit.image, frame);
    metrics.visibility_flip = Some(crate::reference::metrics::flip(
        &frame.coverage_image(),
        &shadow.image,
    ));
    Ok(Scored {
        metrics,
        classified,
        diff,
        lit,
        shadow: shadow.image,
        reference_ms,
    })
}
