//! Batches: many views of one scene, rendered one after another, with their shadow maps shared
//! while the lights and the casters hold still (a dataset's camera poses around a model).

use super::aov::{aovs_of, AovSet, Aovs};
use super::submit::Pending;
use super::{RenderedFrame, Renderer};
use crate::gpu::context::GpuError;
use crate::plan::settings::ViewMode;
use crate::plan::view::View;
use crate::plan::{FramePlan, ShadowBatch};
use crate::scene::{Camera, LightKind};
use std::collections::VecDeque;
use std::sync::Arc;

pub use super::ring::RING;

/// What [`Renderer::render_each`] hands over per view: its index, the frame, and its AOVs when
/// asked for.
pub type Sink<'a> = dyn FnMut(usize, RenderedFrame, Option<Aovs>) + 'a;

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
        let mut frames = Vec::with_capacity(views.len());
        let r = self.render_each(&views, width, height, None, &mut |_, f, _| frames.push(f));
        self.set_shadow_cache(was);
        r.map(|()| frames)
    }

    /// Renders each of `views` at `width`×`height` as [`Renderer::render`] does (with `aovs`, as
    /// [`Renderer::render_with_aovs`] does) and hands each frame to `sink` in order, as it is
    /// read back. Up to [`RING`] frames are in flight: the next view is recorded and drawn while
    /// the last one is read back and `sink` works on it (lit views at one sample per pixel,
    /// shadow maps, no depth measuring pass; other batches go one view at a time). The frames
    /// are the same to the byte either way, as tests check.
    pub fn render_each(
        &mut self,
        views: &[View],
        width: u32,
        height: u32,
        aovs: Option<AovSet>,
        sink: &mut Sink<'_>,
    ) -> Result<(), GpuError> {
        if !self.keeps_in_flight(views, aovs) {
            for (i, v) in views.iter().enumerate() {
                match aovs {
                    Some(set) => {
                        let (f, a) = self.render_with_aovs(v, width, height, set)?;
                        sink(i, f, Some(a));
                    }
                    None => sink(i, self.render(v, width, height)?, None),
                }
            }
            return Ok(());
        }
        let keep_depth = self.read_depth;
        self.read_depth = keep_depth || aovs.is_some_and(|s| s.depth);
        let r = self.render_ring(views, (width, height), aovs, keep_depth, sink);
        self.read_depth = keep_depth;
        r
    }

    /// Whether [`Renderer::render_each`] keeps several of `views` in flight: each renders in
    /// one submission (no depth-measuring frame, no exact shadows' per-frame buffers, no
    /// supersampling), and the AOVs asked for come from the camera pass itself.
    pub fn keeps_in_flight(&self, views: &[View], aovs: Option<AovSet>) -> bool {
        let targets = aovs.is_some_and(|s| s.instance || s.normal);
        let depth = aovs.is_some_and(|s| s.depth);
        let aovs_fit = !(targets || depth)
            || self.core.samples == 1 && (!targets || self.core.camera.can_draw_aovs());
        aovs_fit
            && views.iter().all(|v| {
                !self.measures_depths(v)
                    && !v.shadow.method.traces()
                    && v.supersample <= 1
                    && (aovs.is_none() || v.mode == ViewMode::Lit)
            })
    }

    /// `render_each`'s ring: submits view i in slot i mod [`RING`] once the frame that used the
    /// slot has been read back and handed to `sink`.
    fn render_ring(
        &mut self,
        views: &[View],
        size: (u32, u32),
        aovs: Option<AovSet>,
        keep_depth: bool,
        sink: &mut Sink<'_>,
    ) -> Result<(), GpuError> {
        let targets = aovs.filter(|s| s.instance || s.normal);
        let mut pending: VecDeque<(usize, Pending)> = VecDeque::with_capacity(RING);
        let mut result = Ok(());
        for (i, v) in views.iter().enumerate() {
            if pending.len() == RING {
                let (k, p) = pending.pop_front().expect("RING in flight");
                result = self.hand_over(&views[k], k, p, (size, aovs, keep_depth), sink);
                if result.is_err() {
                    break;
                }
            }
            match self.submit_frame(i % RING, v, size, targets) {
                Ok(p) => pending.push_back((i, p)),
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
        // What is still in flight is read back (and, after an error, dropped).
        while let Some((k, p)) = pending.pop_front() {
            if result.is_ok() {
                result = self.hand_over(&views[k], k, p, (size, aovs, keep_depth), sink);
            } else {
                let _ = self.finish_frame(p);
            }
        }
        result
    }

    /// Reads back view `k`'s frame `p` and hands it, with its AOVs, to `sink`.
    fn hand_over(
        &mut self,
        view: &View,
        k: usize,
        p: Pending,
        (size, aovs, keep_depth): ((u32, u32), Option<AovSet>, bool),
        sink: &mut Sink<'_>,
    ) -> Result<(), GpuError> {
        let (mut frame, drawn) = self.finish_frame(p)?;
        let aovs = aovs.map(|set| {
            let (ids, normals) = drawn.unwrap_or_default();
            let depth = frame.depth.as_deref().filter(|_| set.depth).unwrap_or(&[]);
            aovs_of(view, size, (ids, normals, depth), frame.plan.clone())
        });
        if !keep_depth {
            frame.depth = None;
        }
        sink(k, frame, aovs);
        Ok(())
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
        let batch = Arc::new(ShadowBatch::new(cameras));
        let share = |v: &View, size: u32| {
            let mut v = v.clone();
            v.shadow_batch = Some(batch.clone());
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
