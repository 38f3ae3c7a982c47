//! The scene pipelines a frame needs, made once each (compiled in parallel) and kept by
//! (variant, entry point).

use super::*;
use crate::gpu::context::{Context, GpuError};
use crate::gpu::shaders::{create_module, scene as sh};
use crate::render::gpu_scene::{vertex_layout, GpuScene};
use crate::render::passes::cull::Entry;
use crate::render::passes::deferred::{self, GBuffer, GBUFFER_FORMAT, GBUFFER_TARGETS};
use crate::render::passes::receivers::{self, Split};
use crate::render::pipeline::{create_pipeline, ColorBlend, Depth, PipelineDesc, Stencil};
use crate::shader_consts::VariantKey;
use ash::vk;

impl CameraPass {
    /// Creates the scene pipelines this frame (`cull`, at `extent`) needs (once each): for every
    /// (material variant, alpha-masked) pair of the scene's draws, specialised by the frame's
    /// bits (`frame_bits`: one light, shadows), and when it shades draws deferred, the G-buffer
    /// pipeline, targets and its materials' resolve pipelines. Creation compiles the shader, so
    /// it happens here, not per draw.
    pub fn ensure_pipelines(
        &mut self,
        scene: &GpuScene,
        frame: &CameraFrame,
        extent: vk::Extent2D,
    ) -> Result<(), GpuError> {
        let cull = &frame.cull;
        let (frame_bits, debug_view) = (cull.frame_bits, cull.debug_view);
        let mut keys: Vec<(VariantKey, Entry)> = scene
            .pipeline_keys
            .iter()
            .map(|&(bits, alpha)| {
                (
                    bits | frame_bits,
                    frame.with_aovs(Entry::of(alpha, debug_view)),
                )
            })
            .collect();
        let defer = &frame.defer;
        // The unshadowed variants of receivers drawn (partly) beyond the casters' reach, and the
        // flat-input pipelines of large-triangle draws.
        for ((&i, split), &flat) in defer.forward.iter().zip(&frame.splits).zip(&frame.flat) {
            let dr = &scene.draws[i];
            let entry = frame.entry(dr.alpha, flat);
            let bits = dr.material_bits | frame_bits;
            if flat {
                keys.push((bits, entry));
            }
            if *split != Split::Shadowed {
                keys.push((receivers::unshadowed(bits), entry));
            }
        }
        if !defer.deferred.is_empty() {
            // Per resolved material its resolve, and the G-buffer pipeline of its texture slots.
            keys.extend(defer.resolved.iter().flat_map(|r| {
                [
                    (
                        r.material_bits | frame_bits,
                        frame.with_aovs(Entry::Resolve),
                    ),
                    (
                        deferred::gbuffer_variant(r.material_bits),
                        frame.with_aovs(Entry::GBuffer),
                    ),
                ]
            }));
            self.ensure_gbuffer(extent)?;
        }
        if frame.aovs && self.sky_aovs.is_none() {
            self.sky_aovs = Some(super::sky_pipeline(
                &self.ctx,
                self.layout,
                self.module,
                &[self.color_format, AOV_FORMATS[0], AOV_FORMATS[1]],
                (self.depth_format, self.samples),
                self.flat_forward,
            )?);
        }
        self.build_pipelines(keys)
    }

    /// Creates the AOV pipelines (`fs_aov`) `frame`'s opaque and masked draws need: one per
    /// material variant (the frame's bits mean nothing to it).
    pub fn ensure_aov_pipelines(
        &mut self,
        scene: &GpuScene,
        frame: &CameraFrame,
    ) -> Result<(), GpuError> {
        let keys = aov_draws(scene, frame)
            .map(|i| {
                let dr = &scene.draws[i];
                (dr.material_bits, Entry::aov(dr.alpha))
            })
            .collect();
        self.build_pipelines(keys)
    }

    /// Creates the pipelines of `keys` (variant, entry) not made yet.
    fn build_pipelines(&mut self, keys: Vec<(VariantKey, Entry)>) -> Result<(), GpuError> {
        // Modules first (cheap), then the missing pipelines compiled in parallel: on lavapipe
        // each is an LLVM compile of its shaders, the largest part of a cold first frame.
        let mut missing: Vec<(VariantKey, Entry, vk::ShaderModule)> = Vec::new();
        for (variant, entry) in keys {
            if self.pipelines.contains_key(&(variant, entry))
                || missing.iter().any(|m| (m.0, m.1) == (variant, entry))
            {
                continue;
            }
            let module = match self.variant_modules.get(&variant) {
                Some(&m) => m,
                None => {
                    let m = create_module(
                        &self.ctx,
                        &sh::variant(variant.bits())?,
                        &format!("scene.wgsl variant {}", variant.bits()),
                    )?;
                    self.variant_modules.insert(variant, m);
                    m
                }
            };
            missing.push((variant, entry, module));
        }
        let formats = Formats {
            color: self.color_format,
            depth: self.depth_format,
            samples: self.samples,
        };
        let (ctx, layout) = (&self.ctx, self.layout);
        let built: Vec<Result<vk::Pipeline, GpuError>> = std::thread::scope(|s| {
            let threads: Vec<_> = missing
                .iter()
                .map(|&(variant, entry, module)| {
                    s.spawn(move || scene_pipeline(ctx, layout, formats, variant, entry, module))
                })
                .collect();
            threads
                .into_iter()
                .map(|t| {
                    t.join().unwrap_or(Err(GpuError::Vk {
                        call: "vkCreateGraphicsPipelines (thread panicked)",
                        result: vk::Result::ERROR_UNKNOWN,
                    }))
                })
                .collect()
        });
        let mut first_error = None;
        for (&(variant, entry, _), result) in missing.iter().zip(built) {
            match result {
                Ok(p) => {
                    self.pipelines.insert((variant, entry), p);
                }
                Err(e) => first_error = first_error.or(Some(e)),
            }
        }
        first_error.map_or(Ok(()), Err)
    }

    /// The G-buffer targets at `extent` (re-made when the size changes).
    fn ensure_gbuffer(&mut self, extent: vk::Extent2D) -> Result<(), GpuError> {
        if self.gbuffer.as_ref().is_none_or(|g| g.extent != extent) {
            // The old targets (if any) are dropped first: a window's resize.
            self.gbuffer = None;
            self.gbuffer = Some(GBuffer::new(&self.ctx, extent, self.gbuffer_layout)?);
        }
        Ok(())
    }
}

/// The attachment formats and sample count every camera pipeline is made for.
#[derive(Clone, Copy)]
pub(super) struct Formats {
    pub(super) color: vk::Format,
    pub(super) depth: vk::Format,
    pub(super) samples: u32,
}

/// Creates the scene pipeline of shader `variant` (in `module`) with fragment entry `entry`.
fn scene_pipeline(
    ctx: &Context,
    layout: vk::PipelineLayout,
    formats: Formats,
    variant: VariantKey,
    entry: Entry,
    module: vk::ShaderModule,
) -> Result<vk::Pipeline, GpuError> {
    let (bindings, attributes) = vertex_layout();
    let name = format!("camera pipeline variant {} {entry:?}", variant.bits());
    let resolve = matches!(entry, Entry::Resolve | Entry::ResolveAov);
    let aov = matches!(entry, Entry::Aov | Entry::AovMasked);
    // A camera pass drawing the ids and normals too: its colour and those two.
    let lit_aovs = [formats.color, AOV_FORMATS[0], AOV_FORMATS[1]];
    let gbuffer_aovs = [
        AOV_FORMATS[0],
        AOV_FORMATS[1],
        GBUFFER_FORMAT,
        GBUFFER_FORMAT,
    ];
    create_pipeline(
        ctx,
        &PipelineDesc {
            name: &name,
            layout,
            vertex: (module, vertex_entry(entry)),
            fragment: Some((module, fragment_entry(entry))),
            bindings: if resolve { &[] } else { &bindings },
            attributes: if resolve { &[] } else { &attributes },
            color_formats: match entry {
                Entry::GBuffer => &[GBUFFER_FORMAT; GBUFFER_TARGETS],
                Entry::GBufferAov => &gbuffer_aovs,
                Entry::Aov | Entry::AovMasked => &AOV_FORMATS,
                Entry::OpaqueAov
                | Entry::OpaqueFlatAov
                | Entry::MaskedAov
                | Entry::BlendedAov
                | Entry::ResolveAov => &lit_aovs,
                _ => std::slice::from_ref(&formats.color),
            },
            masked_targets: match entry {
                Entry::GBuffer | Entry::GBufferAov => deferred::gbuffer_targets_masked(variant),
                // Blended surfaces have no id; the resolve's pixels got theirs in the G-buffer pass.
                Entry::BlendedAov | Entry::ResolveAov => 2,
                _ => 0,
            },
            depth_format: formats.depth,
            stencil: match entry {
                Entry::Resolve | Entry::ResolveAov => Stencil::Equal,
                Entry::GBuffer | Entry::GBufferAov => Stencil::Mark,
                _ => Stencil::Off,
            },
            depth_clamp: false,
            depth_bias: false,
            depth: if entry == Entry::Overdraw || resolve {
                Depth::Off
            } else {
                Depth::Test
            },
            blend: match entry {
                Entry::Overdraw => ColorBlend::Additive,
                Entry::Blended | Entry::BlendedAov => ColorBlend::Over,
                _ => ColorBlend::Off,
            },
            // The AOV pass draws one sample per pixel whatever the camera pass's MSAA.
            samples: if aov { 1 } else { formats.samples },
        },
    )
}

/// The vertex shader entry point of camera pipeline `entry`.
fn vertex_entry(entry: Entry) -> &'static std::ffi::CStr {
    match entry {
        Entry::Resolve | Entry::ResolveAov => sh::ENTRY_VS_FULLSCREEN_FLAT,
        Entry::OpaqueFlat | Entry::OpaqueFlatAov => sh::ENTRY_VS_MAIN_FLAT,
        _ => sh::ENTRY_VS_MAIN,
    }
}

/// The fragment shader entry point of camera pipeline `entry`.
fn fragment_entry(entry: Entry) -> &'static std::ffi::CStr {
    match entry {
        Entry::Opaque => sh::ENTRY_FS_MAIN,
        Entry::OpaqueFlat => sh::ENTRY_FS_MAIN_FLAT,
        Entry::Masked => sh::ENTRY_FS_MASKED,
        Entry::Blended | Entry::BlendedAov => sh::ENTRY_FS_BLEND,
        Entry::Debug | Entry::Overdraw => sh::ENTRY_FS_DEBUG,
        Entry::Resolve | Entry::ResolveAov => sh::ENTRY_FS_RESOLVE,
        Entry::GBuffer => sh::ENTRY_FS_GBUFFER,
        Entry::OpaqueAov => sh::ENTRY_FS_MAIN_AOV,
        Entry::OpaqueFlatAov => sh::ENTRY_FS_MAIN_FLAT_AOV,
        Entry::MaskedAov => sh::ENTRY_FS_MASKED_AOV,
        Entry::GBufferAov => sh::ENTRY_FS_GBUFFER_AOV,
        Entry::Aov => sh::ENTRY_FS_AOV,
        Entry::AovMasked => sh::ENTRY_FS_AOV_MASKED,
    }
}
