//! What the offscreen renderer and the window share: the uploaded scene, the shadow and camera
//! passes, the frame plan, and GPU timestamps, with one slot per frame in flight. Both targets
//! record exactly the same commands, so the window and the capture give the same pixels.

use super::device::device_facts;
use super::gpu_scene::GpuScene;
use crate::gpu::barrier::Access;
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::{BufferAccess, Recorder, Uses};
use crate::math::shadow_fit::spot_near;
use crate::plan::settings::{PostAa, SceneOptions, ShadowFormat, ShadowSettings, ViewMode};
use crate::plan::view::{Background, View};
use crate::plan::ExactPlan;
use crate::plan::CLEAR_COLOR;
use crate::plan::{plan_frame, FramePlan, PlanScene, PlanTarget};
use crate::render::passes::camera::{
    AovTargets, CameraFrame, CameraPass, CameraTargets, Redrawn, Resolve,
};
use crate::render::passes::cull::CameraCull;
use crate::render::passes::exact::ExactPass;
use crate::render::passes::post_aa::PostAaPass;
use crate::render::passes::shadow_pass::ShadowPass;
use crate::render::targets::{Attachment, MsaaTargets};
use crate::scene::{Light, Scene};
use ash::vk;
use std::sync::Arc;

/// Scene + passes + per-slot uniforms and timestamps.
pub struct FrameCore {
    /// The context.
    pub ctx: Arc<Context>,
    /// The scene's own lights (the view may add the default sun or override the sun).
    pub lights: Vec<Light>,
    /// GPU scene.
    pub gpu: GpuScene,
    /// Shadow depth pass.
    pub shadow: ShadowPass,
    /// Camera pass.
    pub camera: CameraPass,
    /// Post-process anti-aliasing (`View::post_aa`).
    post: PostAaPass,
    /// Exact shadows (`ShadowMethod::Exact`), made by the first frame that asks for them.
    exact: Option<ExactPass>,
    /// Frames in flight (the exact pass's uniform slots).
    slots: usize,
    /// Samples per pixel of the camera pass (`SceneOptions::msaa` resolved for the device).
    pub samples: u32,
    query_pool: vk::QueryPool,
    timestamps_written: Vec<bool>,
    /// World bounds of every draw (the receivers cascades are split over).
    receiver_bounds: Vec<crate::math::Aabb>,
    /// Each draw's world plane where it is flat (index-aligned with `receiver_bounds`).
    receiver_planes: Vec<Option<glam::Vec4>>,
    /// What the GPU's world coordinates are relative to ([`Scene::render_origin`]): draws,
    /// lights and the planned matrices; views are rebased in [`FrameCore::prepare`].
    pub origin: glam::Vec3,
    /// Whether small receivers are drawn unshadowed beyond the casters' reach
    /// (`SceneOptions::receiver_split`).
    receiver_split: bool,
}

impl FrameCore {
    /// Uploads `scene` and creates the passes for `color_format` with `slots` frames in flight.
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        options: &SceneOptions,
        color_format: vk::Format,
        slots: usize,
    ) -> Result<Self, GpuError> {
        let origin = scene.render_origin();
        let gpu = GpuScene::new(ctx, scene, options, origin)?;
        let (receiver_bounds, receiver_planes) = gpu.plan_inputs();
        let mut shadow = ShadowPass::new(ctx)?;
        shadow.set_caching(options.shadow_cache);
        let device = device_facts(ctx);
        let samples = options.resolved_samples(&device);
        let camera = CameraPass::new(
            ctx,
            &gpu,
            color_format,
            samples,
            slots,
            options.resolved_deferred(&device),
        )?;
        let receiver_split = options.resolved_receiver_split(&device);
        let post = PostAaPass::new(ctx, color_format)?;
        let query_pool = unsafe {
            ctx.device.create_query_pool(
                &vk::QueryPoolCreateInfo::default()
                    .query_type(vk::QueryType::TIMESTAMP)
                    .query_count(3 * slots as u32),
                None,
            )
        }
        .vk("vkCreateQueryPool")?;
        Ok(Self {
            ctx: ctx.clone(),
            lights: scene.lights.iter().map(|l| l.rebased(origin)).collect(),
            origin,
            gpu,
            shadow,
            camera,
            post,
            exact: None,
            slots,
            samples,
            query_pool,
            timestamps_written: vec![false; slots],
            receiver_bounds,
            receiver_planes,
            receiver_split,
        })
    }

    /// Takes a new pose of the scene it was made from ([`GpuScene::update_pose`]): vertices,
    /// draws, bounds and the lights, which may hang on animated nodes. A caster the shadow cache takes as still (not `moving`) that this pose moved empties the
    /// cache.
    pub fn set_pose(&mut self, scene: &Scene) -> Result<(), GpuError> {
        if self.gpu.update_pose(scene)? {
            self.shadow.forget();
        }
        (self.receiver_bounds, self.receiver_planes) = self.gpu.plan_inputs();
        self.lights = scene
            .lights
            .iter()
            .map(|l| l.rebased(self.origin))
            .collect();
        Ok(())
    }

    /// The plan of `view` at `width`×`height` pixels (what `prepare` plans, without touching
    /// the device).
    pub fn plan(&self, view: &View, width: u32, height: u32) -> FramePlan {
        let mut v = view.rebased(self.origin);
        let scene = PlanScene {
            lights: &self.lights,
            bounds: &self.gpu.bounds,
            receivers: &self.receiver_bounds,
            planes: &self.receiver_planes,
            origin: self.origin,
        };
        // The image's pixel footprint: a supersampled frame's samples share their pixel's maps,
        // as MSAA's do.
        let target = |hw_compare| PlanTarget {
            aspect: width as f32 / height.max(1) as f32,
            height_px: height / view.supersample.max(1),
            hw_compare,
            exact_capable: self.ctx.fragment_stores,
            receiver_split: self.receiver_split,
        };
        // An automatic format is resolved by the plan; planned again in the rare case that the
        // chosen format filters differently from D32 (hardware comparison is a plan input).
        let first = match v.shadow.format {
            ShadowFormat::Auto => ShadowFormat::D32,
            f => f,
        };
        let mut hw = self.shadow.hardware_filtering(first);
        let mut plan = plan_frame(&scene, &v, &target(hw));
        let format = plan.shadow_format;
        if self.shadow.hardware_filtering(format) != hw {
            hw = !hw;
            v.shadow.format = format;
            plan = plan_frame(&scene, &v, &target(hw));
        }
        plan
    }

    /// Sizes the shadow map for `view`, plans the frame (with its casters and the camera pass's
    /// draw selection) and writes slot `slot`'s uniforms (the slot's previous frame must have
    /// completed). Recording then only does what the returned frame says.
    pub fn prepare(
        &mut self,
        slot: usize,
        view: &View,
        width: u32,
        height: u32,
    ) -> Result<Prepared, GpuError> {
        self.prepare_with(slot, view, (width, height), false)
    }

    /// `prepare`; with `aovs` the camera pass also draws each pixel's instance id and world
    /// normal into `Targets::aovs` where it can (a lit image, `CameraPass::can_draw_aovs`:
    /// `Prepared::draws_aovs` says whether it does).
    pub fn prepare_with(
        &mut self,
        slot: usize,
        view: &View,
        (width, height): (u32, u32),
        aovs: bool,
    ) -> Result<Prepared, GpuError> {
        let plan = self.plan(view, width, height);
        let format = plan.shadow_format;
        let hw = self.shadow.hardware_filtering(format);
        let layers = plan.shadow_views.len().max(1) as u32;
        // A frame without shadows (the AOV pass, a frame with shadows off) keeps the map it
        // finds, so that the next shadowed frame (and the shadow cache) finds it too.
        if plan.shadows_on || !self.shadow.holds(format) {
            self.shadow
                .ensure_map(plan.shadow_map_size(), format, layers)?;
        }
        self.shadow.ensure_masked(&self.gpu, format)?;
        let map_view = self.shadow.map.as_ref().map(|m| m.view).unwrap_or_default();
        let extent = vk::Extent2D { width, height };
        if let Some(e) = &plan.exact {
            self.prepare_exact(slot, e, extent)?;
        }
        let exact_samples = plan
            .exact
            .as_ref()
            .and(self.exact.as_ref().map(|e| e.samples()));
        self.camera
            .bind_shadow_map(slot, map_view, hw, exact_samples);
        self.camera.write_frame(slot, &plan.uniform)?;
        let cull = camera_cull(view, &plan);
        let sky = view.mode == ViewMode::Lit && plan.background == Background::Sky;
        let mut camera = self.camera.plan_frame(
            &self.gpu,
            cull,
            extent,
            view.mode == ViewMode::ShadowMap,
            sky,
        );
        camera.aovs = aovs && view.mode == ViewMode::Lit && self.camera.can_draw_aovs();
        self.camera.ensure_pipelines(&self.gpu, &camera, extent)?;
        let post_aa = view.mode == ViewMode::Lit && view.post_aa == PostAa::Fxaa;
        if post_aa {
            self.post.ensure(extent)?;
        }
        let shadow = ShadowSettings {
            slope_bias: plan.slope_bias,
            ..view.shadow
        };
        Ok(Prepared {
            post_aa,
            plan,
            camera,
            extent,
            slot,
            shadow,
            mode: view.mode,
        })
    }

    /// Makes the exact pass (once) and its targets at `extent`, and writes slot `slot`'s inputs
    /// from the plan's `exact`.
    fn prepare_exact(
        &mut self,
        slot: usize,
        exact: &ExactPlan,
        extent: vk::Extent2D,
    ) -> Result<(), GpuError> {
        if self.exact.is_none() {
            self.exact = Some(ExactPass::new(&self.ctx, &self.gpu, self.slots)?);
        }
        let map = self.shadow.map.as_ref().map(|m| m.view).unwrap_or_default();
        let pass = self.exact.as_mut().expect("made above");
        pass.ensure(&self.gpu, extent)?;
        pass.bind_map(slot, map);
        if exact.hybrid.is_some() {
            pass.ensure_culling(&self.gpu, exact)?;
        }
        pass.write_frame(slot, exact)
    }

    /// Records the shadow pass and the camera pass of a prepared frame with timestamps (the
    /// camera pass's time includes post-process anti-aliasing, which draws the camera pass's
    /// image into `targets.color` when the frame has it); leaves `targets.color` as a colour
    /// attachment and `targets.depth` as a depth attachment. Returns what was drawn.
    pub fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &Prepared,
        targets: Targets<'_>,
    ) -> PassCounts {
        let Prepared {
            plan,
            camera,
            extent,
            slot,
            ..
        } = frame;
        let (slot, extent) = (*slot, *extent);
        let Targets {
            color,
            depth,
            msaa,
            resolve_depth,
            aovs,
        } = targets;
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        let q = 3 * slot as u32;
        let timestamps = ctx.timestamp_valid_bits > 0;
        if timestamps {
            Recorder::new(d, cmd).reset_query_pool(self.query_pool, q, 3);
        }
        self.timestamp(cmd, vk::PipelineStageFlags2::TOP_OF_PIPE, q);
        let casters = self.record_shadows(cmd, frame);
        self.timestamp(cmd, vk::PipelineStageFlags2::ALL_COMMANDS, q + 1);
        // With post-process AA the camera pass draws into the pass's source image.
        let color_target: &mut Attachment = if frame.post_aa {
            self.post.source().expect("post AA source made by prepare")
        } else {
            &mut *color
        };
        let clear = clear_color(frame.mode, plan.background);
        // The camera pass reads the map and, on an exact or hybrid frame, the verdicts.
        let verdicts = match plan.exact {
            Some(_) => self.exact.as_mut().and_then(ExactPass::verdicts),
            None => None,
        };
        let inputs = Uses::new()
            .reads_some(self.shadow.map_input(), Access::DepthFragmentSampled)
            .reads_buffer_some(verdicts, BufferAccess::FragmentRead);
        let (targets, redrawn) = camera_targets(
            (d, cmd),
            inputs,
            (color_target, depth, msaa),
            aovs.filter(|_| camera.aovs),
            resolve_depth,
            (extent, clear),
        );
        let counts = self
            .camera
            .record(cmd, (slot, &self.gpu), (&targets, redrawn), camera);
        if frame.post_aa {
            self.post.record(cmd, color);
        }
        self.timestamp(cmd, vk::PipelineStageFlags2::ALL_COMMANDS, q + 2);
        self.timestamps_written[slot] = timestamps;
        PassCounts {
            casters,
            camera_draws: counts.drawn,
            deferred_draws: counts.deferred,
            unshadowed_draws: counts.unshadowed,
            flat_draws: counts.flat,
        }
    }

    /// Records the shadow pass and, on an exact or hybrid frame, the exact pass; casters drawn.
    fn record_shadows(&mut self, cmd: vk::CommandBuffer, frame: &Prepared) -> usize {
        let plan = &frame.plan;
        let views: Vec<_> = plan
            .shadow_views
            .iter()
            .map(|v| (v.light_clip_from_world, &v.casters))
            .collect();
        // How far from a point or spot light its projection's near plane reaches (near
        // distance × √(1 + 2·tan²) for the widest point face, tan ≤ 4/3).
        let near = 2.2 * spot_near(&self.gpu.bounds);
        let casters = self
            .shadow
            .record(cmd, &self.gpu, &frame.shadow, &views, near);
        // The map handed on to its samplers once drawn, in a dependency of its own (0.7–1.1 ms
        // a 1280×720 demo frame cheaper on lavapipe than in the camera pass's dependency).
        Uses::new()
            .reads_some(self.shadow.map_input(), Access::DepthFragmentSampled)
            .enter(&self.ctx.device, cmd);
        if let (Some(inputs), Some(pass)) = (&plan.exact, self.exact.as_mut()) {
            pass.record(
                cmd,
                (frame.slot, &self.gpu),
                inputs,
                self.shadow.map_input(),
            );
        }
        casters
    }

    /// Writes timestamp `query` after `stage`, where the device has timestamps.
    fn timestamp(&self, cmd: vk::CommandBuffer, stage: vk::PipelineStageFlags2, query: u32) {
        if self.ctx.timestamp_valid_bits > 0 {
            Recorder::new(&self.ctx.device, cmd).write_timestamp2(stage, self.query_pool, query);
        }
    }

    /// Records the AOV pass of a prepared frame (`CameraPass::record_aov`: instance ids, world
    /// normals, depth; one sample) into `ids`, `normals` and `depth`, making its pipelines first;
    /// leaves them as attachments. Returns the draws recorded.
    pub fn record_aov(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: &Prepared,
        (ids, normals, depth): (&mut Attachment, &mut Attachment, &mut Attachment),
    ) -> Result<usize, GpuError> {
        self.camera.ensure_aov_pipelines(&self.gpu, &frame.camera)?;
        Uses::new()
            .writes(ids, Access::ColorAttachment)
            .writes(normals, Access::ColorAttachment)
            .writes(depth, Access::DepthAttachment)
            .enter(&self.ctx.device, cmd);
        let targets = AovTargets {
            ids: ids.view,
            normals: normals.view,
            depth: depth.view,
            extent: frame.extent,
        };
        Ok(self
            .camera
            .record_aov(cmd, frame.slot, &self.gpu, &targets, &frame.camera))
    }

    /// The caster triangles slot `slot`'s frame (completed) drew into the exact method's grid,
    /// and its caster triangles ([`FrameStats::grid_triangles`](crate::render::FrameStats)).
    pub fn grid_triangles(&mut self, slot: usize, plan: &FramePlan) -> Option<(u64, u64)> {
        let (e, pass) = (plan.exact.as_ref()?, self.exact.as_mut()?);
        pass.grid_triangles(slot, &self.gpu, e)
    }

    /// GPU milliseconds (shadow pass, camera pass) of slot `slot`'s last frame, which must have
    /// completed.
    pub fn gpu_times(&self, slot: usize) -> Option<(f64, f64)> {
        if !self.timestamps_written[slot] {
            return None;
        }
        let mut t = [0u64; 3];
        unsafe {
            self.ctx
                .device
                .get_query_pool_results(
                    self.query_pool,
                    3 * slot as u32,
                    &mut t,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
                .ok()?;
        }
        let period = self.ctx.properties.limits.timestamp_period as f64 * 1e-6;
        Some((
            t[1].wrapping_sub(t[0]) as f64 * period,
            t[2].wrapping_sub(t[1]) as f64 * period,
        ))
    }
}

/// The camera pass's inputs (`inputs`, from the passes before it) and outputs, declared as one
/// step, and its targets named: the colour target (or with MSAA the
/// multisampled colour and depth, resolving into the colour target and, with `resolve_depth`,
/// into `depth`), the depth, and the instance ids and normals asked for (`aovs`). An AOV target
/// not asked for is left unbound (a null view): the draws' writes to it are discarded, which
/// spares llvmpipe a 16-byte normal per pixel when only ids are read.
fn camera_targets<'a>(
    (d, cmd): (&ash::Device, vk::CommandBuffer),
    inputs: Uses<'a>,
    (color_target, depth, msaa): (
        &'a mut Attachment,
        &'a mut Attachment,
        Option<&'a mut MsaaTargets>,
    ),
    aovs: Option<(Option<&'a mut Attachment>, Option<&'a mut Attachment>)>,
    resolve_depth: bool,
    (extent, clear): (vk::Extent2D, [f32; 4]),
) -> (CameraTargets, Redrawn<'a>) {
    let (color_view, depth_view) = (color_target.view, depth.view);
    let (msaa_color, drawn_depth, resolved_depth, resolve) = match msaa {
        Some(MsaaTargets {
            color,
            depth: drawn,
            ..
        }) => {
            let resolve = Resolve {
                color: Some(color_view),
                depth: resolve_depth.then_some(depth_view),
            };
            (Some(color), drawn, resolve_depth.then_some(depth), resolve)
        }
        None => (None, depth, None, Resolve::default()),
    };
    let draw_color = msaa_color.as_ref().map_or(color_view, |c| c.view);
    let view = |a: &Option<&mut Attachment>| a.as_ref().map_or(vk::ImageView::null(), |a| a.view);
    let (aov_views, mut aovs) = match aovs {
        Some((ids, normals)) => (Some([view(&ids), view(&normals)]), vec![ids, normals]),
        None => (None, vec![]),
    };
    inputs
        .writes(color_target, Access::ColorAttachment)
        .writes_some(msaa_color, Access::ColorAttachment)
        .writes(&mut *drawn_depth, Access::DepthAttachment)
        .writes_some(resolved_depth, Access::DepthResolve)
        .writes_each(
            aovs.iter_mut().flatten().map(|a| &mut **a),
            Access::ColorAttachment,
        )
        .enter(d, cmd);
    let targets = CameraTargets {
        color: draw_color,
        depth: drawn_depth.view,
        resolve,
        extent,
        clear,
        aovs: aov_views,
    };
    let redrawn = Redrawn {
        depth: drawn_depth,
        aovs: aovs.into_iter().flatten().collect(),
    };
    (targets, redrawn)
}

/// The camera pass's clear colour in view mode `mode` against `background`.
fn clear_color(mode: ViewMode, background: Background) -> [f32; 4] {
    match (mode, background) {
        (ViewMode::Overdraw, _) => [0.0, 0.0, 0.0, 1.0],
        (ViewMode::Lit, Background::Color(c)) => c.extend(1.0).to_array(),
        _ => CLEAR_COLOR,
    }
}

/// What the camera pass culls and draws with for `view` planned as `plan` (its sight).
fn camera_cull(view: &View, plan: &FramePlan) -> CameraCull {
    CameraCull {
        shadow_reach: plan.sight.shadow_reach.clone(),
        clip_from_world: plan.clip_from_world,
        eye: plan.sight.eye,
        viewpoint: plan.sight.viewpoint,
        frame_bits: plan.shader_variant,
        debug_view: is_debug_view(view.mode),
        highlight: view.highlight,
    }
}

/// The debug entry `mode` draws with (`None`: the lit image, or the shadow map full-screen).
fn is_debug_view(mode: ViewMode) -> Option<crate::render::passes::cull::Entry> {
    use crate::render::passes::cull::Entry;
    match mode {
        ViewMode::Lit | ViewMode::ShadowMap => None,
        ViewMode::Overdraw => Some(Entry::Overdraw),
        _ => Some(Entry::Debug),
    }
}

/// A frame planned and ready to record ([`FrameCore::prepare`]): the plan, the camera pass's draw
/// selection made from it once, and the settings recording reads.
pub struct Prepared {
    /// The frame's plan (returned to the caller with the image).
    pub plan: FramePlan,
    /// What the camera pass draws: its culling inputs, deferred split and receiver splits.
    camera: CameraFrame,
    /// The image size.
    extent: vk::Extent2D,
    /// The uniform and timestamp slot the frame was prepared in.
    slot: usize,
    /// The view's shadow settings (the shadow pass's bias and cache switches).
    shadow: ShadowSettings,
    /// The view mode (clear colour, the map view).
    mode: ViewMode,
    /// FXAA after the camera pass (`View::post_aa`, lit images only).
    post_aa: bool,
}

impl Prepared {
    /// Whether the camera pass draws the instance ids and normals too
    /// (`FrameCore::prepare_with`).
    pub fn draws_aovs(&self) -> bool {
        self.camera.aovs
    }
}

/// The images one frame is recorded into. With `msaa` the camera pass draws into its
/// multisampled images and resolves colour into `color` (and depth, sample 0, into `depth` when
/// `resolve_depth`).
pub struct Targets<'a> {
    /// The single-sample colour image.
    pub color: &'a mut Attachment,
    /// The single-sample depth image.
    pub depth: &'a mut Attachment,
    /// The multisampled images, when MSAA is on.
    pub msaa: Option<&'a mut MsaaTargets>,
    /// Resolve depth too (for depth readback).
    pub resolve_depth: bool,
    /// The instance-id and normal targets (`AOV_FORMATS`, one sample) of a frame prepared with
    /// them (`FrameCore::prepare_with`); left alone by a frame that does not draw them.
    /// Each `None` is an output not asked for: its writes are discarded.
    pub aovs: Option<(Option<&'a mut Attachment>, Option<&'a mut Attachment>)>,
}

/// Draws recorded in one frame, after culling.
#[derive(Clone, Copy, Debug)]
pub struct PassCounts {
    /// Casters drawn into the shadow map.
    pub casters: usize,
    /// Draws in the camera pass.
    pub camera_draws: usize,
    /// Of those, draws shaded deferred (`crate::render::passes::deferred`).
    pub deferred_draws: usize,
    /// Draws drawn, wholly or in part, without the shadow lookup (`crate::render::passes::receivers`).
    pub unshadowed_draws: usize,
    /// Forward draws reading the uniforms as flat inputs (`camera::FLAT_FROM_PIXELS`).
    pub flat_draws: usize,
}

impl Drop for FrameCore {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
            self.ctx.device.destroy_query_pool(self.query_pool, None);
        }
    }
}
