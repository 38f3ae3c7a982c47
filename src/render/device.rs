//! The device's facts the plan reads, taken from a Vulkan context.

use crate::gpu::Context;
use crate::plan::DeviceFacts;
use ash::vk;

/// What `ctx`'s device can do, as the plan's plain inputs.
pub fn device_facts(ctx: &Context) -> DeviceFacts {
    use vk::{Format, FormatFeatureFlags as F};
    let has = |format, features| {
        let p = unsafe {
            ctx.instance
                .get_physical_device_format_properties(ctx.physical, format)
        };
        p.optimal_tiling_features.contains(features)
    };
    let l = &ctx.properties.limits;
    DeviceFacts {
        cpu: ctx.is_cpu(),
        sample_counts: (l.framebuffer_color_sample_counts & l.framebuffer_depth_sample_counts)
            .as_raw(),
        deferred_formats: has(Format::D32_SFLOAT_S8_UINT, F::DEPTH_STENCIL_ATTACHMENT)
            && has(
                Format::R32G32B32A32_SFLOAT,
                F::COLOR_ATTACHMENT | F::SAMPLED_IMAGE,
            ),
        max_anisotropy: ctx.anisotropy.then_some(l.max_sampler_anisotropy),
        bc7: ctx.texture_compression_bc
            && [Format::BC7_SRGB_BLOCK, Format::BC7_UNORM_BLOCK]
                .into_iter()
                .all(|f| {
                    has(
                        f,
                        F::SAMPLED_IMAGE | F::SAMPLED_IMAGE_FILTER_LINEAR | F::TRANSFER_DST,
                    )
                }),
    }
}
