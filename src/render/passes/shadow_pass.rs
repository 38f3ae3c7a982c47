//! The light-space depth pass: position-only stream, depth clamp on, reversed-z (clear 0, GREATER),
//! depth bias pushing casters away from the light (negative factors under reversed-z).

use crate::gpu::barrier::Access;
use crate::gpu::context::{Context, GpuError};
use crate::gpu::shaders::{create_module, shadow as sh};
use crate::gpu::Image;
use crate::gpu::{Recorder, Uses};
use crate::plan::settings::{ShadowFormat, ShadowSettings};
use crate::plan::uniforms::ShadowImmediates;
use crate::plan::{CasterPlan, Viewpoint};
use crate::render::gpu_scene::{vertex_layout, GpuScene};
use crate::render::passes::shadow_cache::{split_moving, LayerKey, LayerWork, ShadowCache};
use crate::render::pipeline::texel_rect;
use crate::render::pipeline::{
    create_layout, create_pipeline, depth_clear_attachment, set_viewport, ColorBlend, Depth,
    PipelineDesc, Stencil,
};
use crate::render::targets::Attachment;
use ash::vk;
use glam::Mat4;
use std::sync::Arc;

/// Vulkan format of a shadow format (`Auto` is resolved by the plan before it gets here; taken
/// as D32 if not).
pub fn vk_format(f: ShadowFormat) -> vk::Format {
    match f {
        ShadowFormat::D32 | ShadowFormat::Auto => vk::Format::D32_SFLOAT,
        ShadowFormat::D16 => vk::Format::D16_UNORM,
    }
}

/// The pipeline of alpha-masked casters: it samples the material's base colour, so its layout
/// holds the scene's material set layout (set 0), and it is made for one scene.
struct MaskedPipeline {
    /// The scene's material set layout it was made with.
    material_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    format: vk::Format,
}

/// Creates a depth-only pipeline of the shadow pass: `masked` takes TEXCOORD_0 from the
/// attribute stream (binding 1, location 2, as in the camera pass) and runs `fs_masked`; otherwise positions only, no fragment stage.
fn depth_pipeline(
    ctx: &Context,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
    masked: bool,
    format: vk::Format,
) -> Result<vk::Pipeline, GpuError> {
    // Positions only, or positions and the attribute stream for TEXCOORD_0 (location 2),
    // COLOR_0 (location 4, whose alpha multiplies the base colour's) and TEXCOORD_1 (5).
    let (bindings, all) = vertex_layout();
    let attributes = [all[0], all[2], all[4], all[5]];
    let (n_bindings, n_attributes) = if masked { (2, 4) } else { (1, 1) };
    create_pipeline(
        ctx,
        &PipelineDesc {
            name: if masked {
                "shadow depth pipeline, alpha-masked"
            } else {
                "shadow depth pipeline"
            },
            layout,
            vertex: (
                module,
                if masked {
                    sh::ENTRY_VS_MASKED
                } else {
                    sh::ENTRY_VS_MAIN
                },
            ),
            fragment: masked.then_some((module, sh::ENTRY_FS_MASKED)),
            bindings: &bindings[..n_bindings],
            attributes: &attributes[..n_attributes],
            color_formats: &[],
            masked_targets: 0,
            depth_format: format,
            stencil: Stencil::Off,
            depth_clamp: true,
            depth_bias: true,
            depth: Depth::Test,
            blend: ColorBlend::Off,
            samples: 1,
        },
    )
}

/// The shadow depth pass and its map.
pub struct ShadowPass {
    ctx: Arc<Context>,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
    pipeline: vk::Pipeline,
    pipeline_format: vk::Format,
    masked: Option<MaskedPipeline>,
    /// The shadow map (None before the first `ensure_map`).
    pub map: Option<Image>,
    /// The map's attachment state (set with the map).
    map_at: Option<Attachment>,
    /// Reuse what layers hold across frames (`SceneOptions::shadow_cache`).
    caching: bool,
    /// The map was made with the usages the cache's copies need.
    map_copies: bool,
    /// What each layer of the map and of `cache` holds.
    layers: ShadowCache,
    /// The static casters' depth per layer, for frames with moving casters (made on first need).
    cache: Option<(Image, Attachment)>,
}

/// What a layer is drawn with: the map's view of the layer, the frame's light matrix and
/// casters, and a point or spot light's near distance.
struct LayerTarget<'a> {
    view: vk::ImageView,
    light_clip_from_world: &'a Mat4,
    casters: &'a CasterPlan,
    eye_near: f32,
    /// The texels cleared and drawn (the casters' area, or the view's whole square).
    area: vk::Rect2D,
}

impl ShadowPass {
    /// Creates the pass (the map is created by `ensure_map`).
    pub fn new(ctx: &Arc<Context>) -> Result<Self, GpuError> {
        let layout = create_layout(ctx, &[], sh::IMMEDIATE_SIZE, "shadow pipeline layout")?;
        let module = create_module(ctx, &sh::spirv()?, "shadow.wgsl")?;
        Ok(Self {
            ctx: ctx.clone(),
            layout,
            module,
            pipeline: vk::Pipeline::null(),
            pipeline_format: vk::Format::UNDEFINED,
            masked: None,
            map: None,
            map_at: None,
            caching: false,
            map_copies: false,
            layers: ShadowCache::default(),
            cache: None,
        })
    }

    /// Whether a map of `format` exists (of whatever size).
    pub fn holds(&self, format: ShadowFormat) -> bool {
        self.map
            .as_ref()
            .is_some_and(|m| m.format == vk_format(format))
    }

    /// Forgets what the map and the cache hold (a caster taken as still has moved).
    pub fn forget(&mut self) {
        self.layers.clear();
    }

    /// Whether unchanged layers are reused across frames.
    pub fn caching(&self) -> bool {
        self.caching
    }

    /// Turns reuse of unchanged layers across frames on or off (`shadow_cache`).
    pub fn set_caching(&mut self, on: bool) {
        self.caching = on;
        self.layers.clear();
    }

    /// Makes sure the map has this size and format and at least `layers` layers (one per shadow
    /// view); returns true if it was (re)created.
    pub fn ensure_map(
        &mut self,
        size: u32,
        format: ShadowFormat,
        layers: u32,
    ) -> Result<bool, GpuError> {
        let fmt = vk_format(format);
        if self.pipeline_format != fmt {
            self.pipeline = depth_pipeline(&self.ctx, self.layout, self.module, false, fmt)?;
            self.pipeline_format = fmt;
        }
        // The plan settled the size (`plan_frame`): clamped into `ShadowSettings::MAP_SIZES`.
        debug_assert!((1..=*ShadowSettings::MAP_SIZES.end()).contains(&size));
        // More layers than needed are kept: a frame that needs fewer cascades (the automatic
        // count changes as the camera moves) reuses the map.
        // A map made while the cache was off cannot be copied from or into.
        if self.map.as_ref().is_some_and(|m| {
            m.extent.width == size
                && m.format == fmt
                && m.layer_views.len() >= layers as usize
                && (self.map_copies || !self.caching)
        }) {
            return Ok(false);
        }
        if self.map.is_some() {
            unsafe {
                let _ = self.ctx.device.device_wait_idle();
            }
        }
        let copies = if self.caching {
            vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST
        } else {
            vk::ImageUsageFlags::empty()
        };
        self.map = Some(Image::new_array(
            &self.ctx,
            "shadow map",
            fmt,
            vk::Extent2D {
                width: size,
                height: size,
            },
            layers,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED | copies,
        )?);
        self.map_at = self.map.as_ref().map(Attachment::of);
        self.map_copies = self.caching;
        self.layers.clear();
        self.cache = None;
        Ok(true)
    }

    /// Makes sure alpha-masked and blended casters of `scene` (whose alpha the shadow pass
    /// tests) have their pipeline (made once per scene and map format, only for scenes with such
    /// materials).
    pub fn ensure_masked(
        &mut self,
        scene: &GpuScene,
        format: ShadowFormat,
    ) -> Result<(), GpuError> {
        let fmt = vk_format(format);
        if !scene.draws.iter().any(|d| d.alpha.tests_alpha_in_shadow())
            || self
                .masked
                .as_ref()
                .is_some_and(|m| m.material_layout == scene.material_layout && m.format == fmt)
        {
            return Ok(());
        }
        self.drop_masked();
        let layout = create_layout(
            &self.ctx,
            &[scene.material_layout],
            sh::IMMEDIATE_SIZE,
            "shadow pipeline layout, alpha-masked",
        )?;
        let pipeline = match depth_pipeline(&self.ctx, layout, self.module, true, fmt) {
            Ok(p) => p,
            Err(e) => {
                unsafe { self.ctx.device.destroy_pipeline_layout(layout, None) };
                return Err(e);
            }
        };
        self.masked = Some(MaskedPipeline {
            material_layout: scene.material_layout,
            layout,
            pipeline,
            format: fmt,
        });
        Ok(())
    }

    fn drop_masked(&mut self) {
        if let Some(m) = self.masked.take() {
            unsafe {
                let d = &self.ctx.device;
                let _ = d.device_wait_idle();
                d.destroy_pipeline_layout(m.layout, None);
            }
        }
    }

    /// Whether `format` supports hardware linear filtering of comparisons.
    pub fn hardware_filtering(&self, format: ShadowFormat) -> bool {
        self.ctx
            .format_features(vk_format(format))
            .contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR)
    }

    /// Records the pass; leaves the map ready for fragment-shader sampling. Returns casters drawn.
    pub fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        s: &ShadowSettings,
        views: &[(Mat4, &CasterPlan)],
        eye_near: f32,
    ) -> usize {
        if self.map.is_none() || self.map_at.is_none() {
            return 0;
        }
        if self.caching && scene.draws.iter().any(|d| d.moving) && self.ensure_cache().is_err() {
            // No memory for the cache: draw every layer in full.
            self.caching = false;
        }
        // Without shadow views (shadows off) one texel of layer 0 is still cleared, so that the
        // map debug view reads defined values.
        let none = CasterPlan::default();
        let fallback = [(Mat4::IDENTITY, &none)];
        let views = if views.is_empty() {
            &fallback[..]
        } else {
            views
        };
        let layer_side = self.map.as_ref().map_or(1, |m| m.extent.width);
        self.ctx.begin_label(cmd, "shadow depth pass");
        self.declare_drawn(cmd);
        let mut drawn = 0;
        for (layer, (light_clip_from_world, casters)) in views.iter().enumerate() {
            let Some(view) = self
                .map
                .as_ref()
                .and_then(|m| m.layer_views.get(layer).copied())
            else {
                break;
            };
            let t = LayerTarget {
                view,
                light_clip_from_world,
                casters,
                eye_near,
                area: texel_rect(casters.area),
            };
            if !self.caching {
                drawn += self.draw_layer(cmd, scene, s, &t, &casters.draws, true);
                continue;
            }
            drawn += self.record_cached_layer(cmd, scene, s, layer, t, layer_side);
        }
        self.ctx.end_label(cmd);
        drawn
    }

    /// Records layer `layer` (target `t`, layers `layer_side` texels across) with the static
    /// casters' cache: kept, drawn, copied from the cache or filled into it
    /// (`ShadowCache::plan`). Returns casters drawn.
    fn record_cached_layer(
        &mut self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        s: &ShadowSettings,
        layer: usize,
        t: LayerTarget<'_>,
        layer_side: u32,
    ) -> usize {
        let (light_clip_from_world, casters) = (t.light_clip_from_world, t.casters);
        let mut drawn = 0;
        let (statics, moving) = split_moving(scene, &casters.draws);
        // With moving casters the static layer is cached over the whole square: the caster
        // area follows the movers, the cache must not.
        let side = casters.size.min(layer_side);
        let square = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: vk::Extent2D {
                width: side,
                height: side,
            },
        };
        let cached_area = if moving.is_empty() { t.area } else { square };
        let biases = (s.slope_bias, t.eye_near);
        let key = LayerKey::new(
            light_clip_from_world,
            casters,
            cached_area,
            biases,
            statics.clone(),
        );
        match self.layers.plan(layer, key, !moving.is_empty()) {
            LayerWork::Keep => {}
            LayerWork::DrawStatic => {
                drawn += self.draw_layer(cmd, scene, s, &t, &casters.draws, true);
            }
            LayerWork::FromCache => {
                self.copy_layer(cmd, layer, t.area, false);
                drawn += self.draw_layer(cmd, scene, s, &t, &moving, false);
            }
            LayerWork::FillCache => {
                let whole = LayerTarget { area: square, ..t };
                drawn += self.draw_layer(cmd, scene, s, &whole, &statics, true);
                self.copy_layer(cmd, layer, square, true);
                drawn += self.draw_layer(cmd, scene, s, &t, &moving, false);
            }
        }
        drawn
    }

    /// The map as the pass's output, before it draws; its samplers declare their reads.
    fn declare_drawn(&mut self, cmd: vk::CommandBuffer) {
        if let Some(at) = self.map_at.as_mut() {
            Uses::new()
                .writes(at, Access::DepthAttachment)
                .enter(&self.ctx.device, cmd);
        }
    }

    /// The map, an input of the passes that sample it (exact, camera); `None` before one exists.
    pub fn map_input(&mut self) -> Option<&mut Attachment> {
        self.map_at.as_mut()
    }

    /// Makes the static-caster cache (same size, format and layers as the map).
    fn ensure_cache(&mut self) -> Result<(), GpuError> {
        let Some(map) = &self.map else { return Ok(()) };
        if self.cache.is_some() {
            return Ok(());
        }
        let image = Image::new_array(
            &self.ctx,
            "shadow cache",
            map.format,
            map.extent,
            map.layer_views.len() as u32,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                | vk::ImageUsageFlags::TRANSFER_SRC
                | vk::ImageUsageFlags::TRANSFER_DST,
        )?;
        let at = Attachment::of(&image);
        self.cache = Some((image, at));
        Ok(())
    }

    /// Copies `area` of layer `layer` from the map into the cache (`to_cache`) or back, and
    /// leaves the map a depth attachment again.
    fn copy_layer(
        &mut self,
        cmd: vk::CommandBuffer,
        layer: usize,
        area: vk::Rect2D,
        to_cache: bool,
    ) {
        let (Some(map), Some(map_at), Some((cache, cache_at))) =
            (&self.map, self.map_at.as_mut(), self.cache.as_mut())
        else {
            return;
        };
        let d = &self.ctx.device;
        let (src, dst) = if to_cache {
            Uses::new()
                .reads(map_at, Access::TransferSrc)
                .writes(cache_at, Access::TransferDst)
                .enter(d, cmd);
            (map.raw, cache.raw)
        } else {
            Uses::new()
                .reads(cache_at, Access::TransferSrc)
                .writes(map_at, Access::TransferDst)
                .enter(d, cmd);
            (cache.raw, map.raw)
        };
        let sub = vk::ImageSubresourceLayers {
            aspect_mask: map.aspect,
            mip_level: 0,
            base_array_layer: layer as u32,
            layer_count: 1,
        };
        let at = vk::Offset3D {
            x: area.offset.x,
            y: area.offset.y,
            z: 0,
        };
        let region = [vk::ImageCopy {
            src_subresource: sub,
            src_offset: at,
            dst_subresource: sub,
            dst_offset: at,
            extent: vk::Extent3D {
                width: area.extent.width,
                height: area.extent.height,
                depth: 1,
            },
        }];
        Recorder::new(d, cmd).copy_image(
            src,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            dst,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &region,
        );
        Uses::new()
            .writes(map_at, Access::DepthAttachment)
            .enter(d, cmd);
    }

    /// Draws `draws` of one layer into the map within the casters' area (cleared first when
    /// `clear`, else drawn over what it holds): opaque casters first, with the depth-only
    /// pipeline, then the alpha-masked and blended ones. Returns the draws recorded.
    fn draw_layer(
        &self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        s: &ShadowSettings,
        t: &LayerTarget,
        draws: &[usize],
        clear: bool,
    ) -> usize {
        let Some(map) = &self.map else { return 0 };
        let d = &self.ctx.device;
        let casters = t.casters;
        let mut depth_attachment = depth_clear_attachment(t.view, false);
        if !clear {
            depth_attachment = depth_attachment.load_op(vk::AttachmentLoadOp::LOAD);
        }
        // Only the casters' area is cleared and drawn: lookups elsewhere never read the map.
        let area = t.area;
        let rendering = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .depth_attachment(&depth_attachment);
        let mut drawn = 0;
        Recorder::new(d, cmd).begin_rendering(&rendering);
        if !draws.is_empty() {
            let side = casters.size.min(map.extent.width);
            set_viewport(
                &self.ctx,
                cmd,
                vk::Extent2D {
                    width: side,
                    height: side,
                },
            );
            Recorder::new(d, cmd).set_scissor(0, &[area]);
            Recorder::new(d, cmd).bind_index_buffer(scene.indices.raw, 0, vk::IndexType::UINT32);
            drawn = self.draw_casters(cmd, scene, s, t, draws);
        }
        Recorder::new(d, cmd).end_rendering();
        drawn
    }

    /// Records `draws` into the layer's rendering begun by [`Self::draw_layer`]: opaque casters
    /// with the depth-only pipeline, then the alpha-masked and blended ones. Returns the draws
    /// recorded.
    fn draw_casters(
        &self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        s: &ShadowSettings,
        t: &LayerTarget,
        draws: &[usize],
    ) -> usize {
        let d = &self.ctx.device;
        let from = t.casters.light;
        // A point or spot light's eye and its projection's near distance (clusters wholly
        // nearer are not drawn); none for a directional light (outside everything).
        let eye = match from {
            Viewpoint::Eye(p) => Some((p, t.eye_near)),
            Viewpoint::Along(_) => None,
        };
        let mut drawn = 0;
        for masked in [false, true] {
            let (pipeline, layout) = match (&self.masked, masked) {
                (_, false) => (self.pipeline, self.layout),
                (Some(m), true) => (m.pipeline, m.layout),
                // No masked pipeline: no masked draws (`ensure_masked`).
                (None, true) => break,
            };
            let mut bound = false;
            for dr in draws.iter().map(|&i| scene.draws[i].shadow_caster()) {
                if dr.alpha.tests_alpha_in_shadow() != masked {
                    continue;
                }
                if !bound {
                    Recorder::new(d, cmd).bind_pipeline(vk::PipelineBindPoint::GRAPHICS, pipeline);
                    // Reversed-z: "away from the light" is towards smaller depth, so
                    // the factor is negated. The constant bias is applied on the
                    // receiver side, in texels.
                    Recorder::new(d, cmd).set_depth_bias(0.0, 0.0, -s.slope_bias);
                    let buffers = [scene.positions.raw, scene.attributes.raw];
                    let n = if masked { 2 } else { 1 };
                    Recorder::new(d, cmd).bind_vertex_buffers(0, &buffers[..n], &[0, 0][..n]);
                    bound = true;
                }
                if masked {
                    scene.bind_material(d, cmd, layout, 0, dr.material);
                }
                let pc = ShadowImmediates {
                    light_clip_from_world: *t.light_clip_from_world,
                    world_from_model: dr.world_from_model,
                };
                let pc = bytemuck::bytes_of(&pc);
                scene.record_draw(cmd, layout, &dr, eye, from, pc);
                drawn += 1;
            }
        }
        drawn
    }
}

impl Drop for ShadowPass {
    fn drop(&mut self) {
        self.drop_masked();
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            d.destroy_shader_module(self.module, None);
            d.destroy_pipeline_layout(self.layout, None);
        }
    }
}
