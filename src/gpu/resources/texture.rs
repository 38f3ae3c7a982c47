//! Textures: sampled images uploaded level by level through a staging buffer, and the linear
//! blit that filters one colour level onto another.

use super::{Buffer, Image};
use crate::gpu::barrier::{image_barrier, Access};
use crate::gpu::context::{Context, GpuError};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

impl Image {
    /// A sampled RGBA8 texture with the levels of `chain`, uploaded by one copy per level (no
    /// blits: lavapipe's blitter compiles its shaders afresh in every process). Left in
    /// `FragmentSampled` layout.
    pub fn texture_mips(
        ctx: &Arc<Context>,
        name: &str,
        chain: &crate::math::mips::MipChain,
        srgb: bool,
    ) -> Result<Self, GpuError> {
        Self::texture_levels(ctx, name, chain, rgba8_format(srgb))
    }

    /// A sampled texture of `format` (RGBA8 or a block-compressed format, whose levels hold
    /// whole blocks) with the levels of `chain`, one copy per level. Left in `FragmentSampled`
    /// layout.
    pub fn texture_levels(
        ctx: &Arc<Context>,
        name: &str,
        chain: &crate::math::mips::MipChain,
        format: vk::Format,
    ) -> Result<Self, GpuError> {
        let (width, height, _) = chain.levels.first().copied().unwrap_or((1, 1, 0));
        let mips = chain.levels.len().max(1) as u32;
        Self::upload_levels(
            ctx,
            name,
            format,
            (width, height, mips),
            &chain.bytes,
            &chain.levels,
            |d, cmd, img| {
                image_barrier(
                    d,
                    cmd,
                    img,
                    vk::ImageAspectFlags::COLOR,
                    0..mips,
                    Access::TransferDst,
                    Access::FragmentSampled,
                );
            },
        )
    }

    /// A sampled RGBA8 texture from its base level, the rest of its mip chain generated on the
    /// device by linear blits (a single level where the format cannot be blitted with linear
    /// filtering), for GPUs, where blits cost next to nothing; a 1×1 image has no other level.
    /// Left in `FragmentSampled` layout.
    pub fn texture_rgba8(
        ctx: &Arc<Context>,
        name: &str,
        width: u32,
        height: u32,
        rgba: &[u8],
        srgb: bool,
    ) -> Result<Self, GpuError> {
        let mips = if ctx.blits_linear(rgba8_format(srgb)) {
            crate::math::mip_levels(width, height)
        } else {
            1
        };
        let base = [(width, height, 0)];
        Self::upload_levels(
            ctx,
            name,
            rgba8_format(srgb),
            (width, height, mips),
            rgba,
            &base,
            |d, cmd, img| {
                let (mut w, mut h) = (width as i32, height as i32);
                for level in 1..mips {
                    image_barrier(
                        d,
                        cmd,
                        img,
                        vk::ImageAspectFlags::COLOR,
                        level - 1..level,
                        Access::TransferDst,
                        Access::TransferSrc,
                    );
                    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
                    blit_linear(d, cmd, (img, level - 1, w, h), (img, level, nw, nh));
                    image_barrier(
                        d,
                        cmd,
                        img,
                        vk::ImageAspectFlags::COLOR,
                        level - 1..level,
                        Access::TransferSrc,
                        Access::FragmentSampled,
                    );
                    (w, h) = (nw, nh);
                }
                image_barrier(
                    d,
                    cmd,
                    img,
                    vk::ImageAspectFlags::COLOR,
                    mips - 1..mips,
                    Access::TransferDst,
                    Access::FragmentSampled,
                );
            },
        )
    }

    /// Creates a sampled image of `format` and `size` = (width, height, mip levels) and, in one
    /// submission, copies `levels` (width, height, byte offset in `bytes`, level by level from 0)
    /// into it, all levels moved to `TransferDst` first; `then` records what follows the copies
    /// (their layout changes, blits) on the image. Only RGBA8 images are blit sources.
    fn upload_levels(
        ctx: &Arc<Context>,
        name: &str,
        format: vk::Format,
        size: (u32, u32, u32),
        bytes: &[u8],
        levels: &[(u32, u32, usize)],
        then: impl FnOnce(&ash::Device, vk::CommandBuffer, vk::Image),
    ) -> Result<Self, GpuError> {
        let (width, height, mips) = size;
        let blit_source = [true, false].map(rgba8_format).contains(&format);
        let img = Image::new(
            ctx,
            name,
            format,
            vk::Extent2D { width, height },
            mips,
            vk::ImageUsageFlags::SAMPLED
                | vk::ImageUsageFlags::TRANSFER_DST
                | if blit_source {
                    vk::ImageUsageFlags::TRANSFER_SRC
                } else {
                    vk::ImageUsageFlags::empty()
                },
        )?;
        let mut staging = Buffer::new(
            ctx,
            &format!("{name} staging"),
            bytes.len().max(4) as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.write(0, bytes)?;
        let regions: Vec<vk::BufferImageCopy> = levels
            .iter()
            .enumerate()
            .map(|(level, &(w, h, offset))| {
                vk::BufferImageCopy::default()
                    .buffer_offset(offset as u64)
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::COLOR,
                        mip_level: level as u32,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D {
                        width: w,
                        height: h,
                        depth: 1,
                    })
            })
            .collect();
        let d = &ctx.device;
        ctx.immediate(|cmd| unsafe {
            image_barrier(
                d,
                cmd,
                img.raw,
                vk::ImageAspectFlags::COLOR,
                0..mips,
                Access::Undefined,
                Access::TransferDst,
            );
            d.cmd_copy_buffer_to_image(
                cmd,
                staging.raw,
                img.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &regions,
            );
            then(d, cmd, img.raw);
        })?;
        Ok(img)
    }
}

/// A whole colour mip level: (image, mip, width, height).
pub type Level = (vk::Image, u32, i32, i32);

/// Records a linear-filtered blit of level `src` (in TRANSFER_SRC_OPTIMAL) onto level `dst` (in
/// TRANSFER_DST_OPTIMAL), each whole. At 2:1 it samples each destination texel's centre midway
/// between its four source texels: their mean, in linear light for sRGB formats (a blit filters
/// after the format's decode).
pub fn blit_linear(d: &ash::Device, cmd: vk::CommandBuffer, src: Level, dst: Level) {
    let layer = |mip_level| vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level,
        base_array_layer: 0,
        layer_count: 1,
    };
    let corner = |(_, _, x, y): Level| vk::Offset3D { x, y, z: 1 };
    let blit = [vk::ImageBlit::default()
        .src_subresource(layer(src.1))
        .src_offsets([vk::Offset3D::default(), corner(src)])
        .dst_subresource(layer(dst.1))
        .dst_offsets([vk::Offset3D::default(), corner(dst)])];
    unsafe {
        d.cmd_blit_image(
            cmd,
            src.0,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            dst.0,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &blit,
            vk::Filter::LINEAR,
        )
    };
}

/// The RGBA8 format of a texture in the sRGB or linear colour space.
fn rgba8_format(srgb: bool) -> vk::Format {
    if srgb {
        vk::Format::R8G8B8A8_SRGB
    } else {
        vk::Format::R8G8B8A8_UNORM
    }
}
