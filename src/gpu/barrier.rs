//! Image barriers from a small table of named accesses (synchronization2).

use ash::vk;

/// How an image is about to be (or was last) used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// Contents undefined (first use, or discard).
    Undefined,
    /// Copy/blit source.
    TransferSrc,
    /// Copy/blit/clear destination.
    TransferDst,
    /// Colour attachment write.
    ColorAttachment,
    /// Depth attachment read/write (tests and writes).
    DepthAttachment,
    /// The single-sample target of a depth resolve: the spec synchronises resolves at colour
    /// attachment output with colour attachment access, whatever the aspect.
    DepthResolve,
    /// Sampled in a fragment shader (colour textures).
    FragmentSampled,
    /// A depth image sampled in a fragment or compute shader (shadow map lookups; the hybrid
    /// method's certainty test).
    DepthFragmentSampled,
    /// Sampled (read with `textureLoad`) in a compute shader.
    ComputeSampled,
    /// A swapchain image just acquired: its old contents are not needed, and the first use must
    /// wait at colour-attachment output, the stage the acquire semaphore is waited at.
    #[cfg_attr(not(feature = "viewer"), allow(dead_code))]
    Acquired,
    /// Handed to presentation.
    #[cfg_attr(not(feature = "viewer"), allow(dead_code))]
    Present,
}

impl Access {
    /// Whether the access writes the image (a pass's output).
    pub fn writes(self) -> bool {
        matches!(
            self,
            Access::TransferDst
                | Access::ColorAttachment
                | Access::DepthAttachment
                | Access::DepthResolve
        )
    }

    /// Whether the access only reads the image (a pass's input); presentation counts as one.
    pub fn reads(self) -> bool {
        matches!(
            self,
            Access::TransferSrc
                | Access::FragmentSampled
                | Access::DepthFragmentSampled
                | Access::ComputeSampled
                | Access::Present
        )
    }
}

/// (stage, access, layout) for an access.
pub fn access_info(a: Access) -> (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout) {
    use vk::AccessFlags2 as A;
    use vk::PipelineStageFlags2 as S;
    match a {
        Access::Undefined => (S::NONE, A::NONE, vk::ImageLayout::UNDEFINED),
        Access::TransferSrc => (
            S::ALL_TRANSFER,
            A::TRANSFER_READ,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        ),
        Access::TransferDst => (
            S::ALL_TRANSFER,
            A::TRANSFER_WRITE,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        ),
        Access::ColorAttachment => (
            S::COLOR_ATTACHMENT_OUTPUT,
            A::COLOR_ATTACHMENT_WRITE | A::COLOR_ATTACHMENT_READ,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        ),
        Access::DepthAttachment => (
            S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
            A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        ),
        Access::DepthResolve => (
            S::COLOR_ATTACHMENT_OUTPUT,
            A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        ),
        Access::FragmentSampled => (
            S::FRAGMENT_SHADER,
            A::SHADER_SAMPLED_READ,
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        ),
        Access::DepthFragmentSampled => (
            S::FRAGMENT_SHADER | S::COMPUTE_SHADER,
            A::SHADER_SAMPLED_READ,
            vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
        ),
        Access::ComputeSampled => (
            S::COMPUTE_SHADER,
            A::SHADER_SAMPLED_READ,
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        ),
        Access::Acquired => (
            S::COLOR_ATTACHMENT_OUTPUT,
            A::NONE,
            vk::ImageLayout::UNDEFINED,
        ),
        Access::Present => (S::NONE, A::NONE, vk::ImageLayout::PRESENT_SRC_KHR),
    }
}

/// The layout covering depth and stencil for a depth-only layout (others unchanged).
fn with_stencil(l: vk::ImageLayout) -> vk::ImageLayout {
    match l {
        vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL => {
            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL
        }
        vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL => {
            vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL
        }
        other => other,
    }
}

/// Records one image barrier from `from` to `to` over the given mip levels; stages, accesses and
/// layouts all come from `access_info`.
pub fn image_barrier(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    mips: std::ops::Range<u32>,
    from: Access,
    to: Access,
) {
    record_dependency(
        device,
        cmd,
        &[],
        &[barrier_info(image, aspect, mips, from, to)],
    );
}

/// The barrier taking mip levels `mips` of `image` from access `from` to `to` (every layer).
pub fn barrier_info(
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    mips: std::ops::Range<u32>,
    from: Access,
    to: Access,
) -> vk::ImageMemoryBarrier2<'static> {
    let (src_stage, src_access, old_layout) = access_info(from);
    let (dst_stage, dst_access, new_layout) = access_info(to);
    // A depth-stencil image moves both aspects together, in the combined layouts.
    let (old_layout, new_layout) = if aspect.contains(vk::ImageAspectFlags::STENCIL) {
        (with_stencil(old_layout), with_stencil(new_layout))
    } else {
        (old_layout, new_layout)
    };
    // Reads need no availability; only writes are made available.
    let src_access = src_access
        & (vk::AccessFlags2::TRANSFER_WRITE
            | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE
            | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE);
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .old_layout(old_layout)
        .new_layout(new_layout)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: aspect,
            base_mip_level: mips.start,
            level_count: mips.end - mips.start,
            base_array_layer: 0,
            layer_count: vk::REMAINING_ARRAY_LAYERS,
        })
}

/// Records global memory barriers and image barriers as one dependency (nothing when there are
/// none).
pub fn record_dependency(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    memory: &[vk::MemoryBarrier2<'_>],
    images: &[vk::ImageMemoryBarrier2<'_>],
) {
    if memory.is_empty() && images.is_empty() {
        return;
    }
    let dep = vk::DependencyInfo::default()
        .memory_barriers(memory)
        .image_memory_barriers(images);
    unsafe { device.cmd_pipeline_barrier2(cmd, &dep) };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_layouts_and_stages() {
        assert_eq!(access_info(Access::Undefined).2, vk::ImageLayout::UNDEFINED);
        // An acquired swapchain image discards its contents and waits where the acquire
        // semaphore is waited at.
        let acquired = access_info(Access::Acquired);
        assert_eq!(acquired.2, vk::ImageLayout::UNDEFINED);
        assert_eq!(acquired.0, vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(
            access_info(Access::Present).2,
            vk::ImageLayout::PRESENT_SRC_KHR
        );
        assert_eq!(
            access_info(Access::DepthFragmentSampled).2,
            vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL
        );
        assert!(access_info(Access::DepthAttachment)
            .0
            .contains(vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS));
        assert!(access_info(Access::FragmentSampled)
            .1
            .contains(vk::AccessFlags2::SHADER_SAMPLED_READ));
        for a in [
            Access::TransferDst,
            Access::ColorAttachment,
            Access::DepthAttachment,
        ] {
            assert_ne!(
                access_info(a).1,
                vk::AccessFlags2::NONE,
                "{a:?} must carry an access"
            );
        }
    }
}
