//! Batches: many views of one scene, rendered one after another, with their shadow maps shared
//! while the lights and the casters hold still (a dataset's camera poses around a model).

use super::{RenderedFrame, Renderer};
use crate::gpu::context::GpuError;
use crate::plan::view::View;
use crate::plan::FramePlan;
use crate::scene::{Camera, LightKind};
use std::sync::Arc;

/// The largest side a shared map grows to (`BatchShadows::Shared`): 8192² D32 texels are 256 MiB.
pub const SHARED_MAP_MAX: u32 = 8192;

/// How the views of a batch get their shadow maps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BatchShadows {
    /// Each view's maps fitted to it alone, as [`Renderer::render`] fits them (a view whose
    /// fit is the one before's still skips the shadow pass: the shadow cache).
    PerView,
    /// Each directional light gets one map fitted to every view of the batch
    /// ([`View::shadow_batch`]), its side doubled from the views' `map_size` (up to
    /// [`SHARED_MAP_MAX`]) until its texels are as fine as the finest any view's own fit has:
    /// the same map in every view, drawn once for the batch. Spot and point lights' maps never
    /// depend on the camera, and are drawn once either way.
    #[default]
    Shared,
}

impl Renderer {
    /// Renders each of `views` at `width`×`height` (as [`Renderer::render`] does), their shadow
    /// maps fitted as `shadows` says, with the shadow cache on (a map the next view plans the
    /// same is not drawn again). A frame of a shared batch is the same to the byte as
    /// `render` of that view from [`Renderer::shared_views`].
    pub fn render_batch(
        &mut self,
        views: &[View],
        width: u32,
        height: u32,
        shadows: BatchShadows,
    ) -> Result<Vec<RenderedFrame>, GpuError> {
        let views = match shadows {
            BatchShadows::PerView => views.to_vec(),
            BatchShadows::Shared => self.shared_views(views, width, height),
        };
        // The cache keeps a map the next view plans the same (every view of a shared batch).
        let was = self.shadow_cache();
        self.set_shadow_cache(true);
        let frames = views
            .iter()
            .map(|v| self.render(v, width, height))
            .collect();
        self.set_shadow_cache(was);
        frames
    }

    /// `views` set to share their shadow maps ([`BatchShadows::Shared`]).
    pub fn shared_views(&self, views: &[View], width: u32, height: u32) -> Vec<View> {
        let Some(first) = views.first() else {
            return Vec::new();
        };
        let plan = |v: &View| {
            let s = v.supersample.max(1);
            self.core
                .plan(v, width.saturating_mul(s), height.saturating_mul(s))
        };
        let cameras: Arc<[Camera]> = views.iter().map(|v| v.camera).collect();
        let share = |v: &View, size: u32| {
            let mut v = v.clone();
            v.shadow_batch = Some(cameras.clone());
            v.shadow.map_size = size;
            v
        };
        let need = views
            .iter()
            .map(|v| finest_directional_texel(&plan(v)))
            .fold(f32::INFINITY, f32::min);
        let base = first.shadow.clamped_map_size();
        let mut size = base;
        if need.is_finite() {
            let got = finest_directional_texel(&plan(&share(first, base)));
            // Snapped extents step by 2^(1/8): within one step counts as as fine.
            while size < SHARED_MAP_MAX && got * base as f32 / size as f32 > need * 1.09 {
                size *= 2;
            }
        }
        views.iter().map(|v| share(v, size)).collect()
    }
}

/// The world size of the finest texel of `plan`'s directional shadow views (infinite without).
fn finest_directional_texel(plan: &FramePlan) -> f32 {
    plan.shadow_views
        .iter()
        .filter(|v| {
            plan.lights
                .get(v.light)
                .is_some_and(|l| l.kind == LightKind::Directional)
        })
        .map(|v| v.texel_world)
        .fold(f32::INFINITY, f32::min)
}
