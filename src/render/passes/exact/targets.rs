//! The exact pass's images and buffers at one image size (re-made when it changes).

use super::*;
use crate::gpu::context::{GpuError, VkCheck};
use crate::gpu::resources::Buffer;
use crate::gpu::shaders::{exact as sh, write_buffers, write_sampled_images};
use crate::gpu::{Image, SharedBuffer};
use crate::render::gpu_scene::GpuScene;
use crate::render::targets::Attachment;
use ash::vk;
use gpu_allocator::MemoryLocation;

impl ExactPass {
    /// Makes the images and buffers for `extent` (and writes every slot's set), if not made yet.
    pub fn ensure(&mut self, scene: &GpuScene, extent: vk::Extent2D) -> Result<(), GpuError> {
        if self.targets.as_ref().is_some_and(|t| t.extent == extent) {
            return Ok(());
        }
        if let Some(old) = self.targets.take() {
            // A new image size: the frames in flight may still read the old targets and sets.
            unsafe { self.ctx.device.device_wait_idle() }.vk("vkDeviceWaitIdle")?;
            drop(old);
        }
        let ctx = &self.ctx;
        let image = |name: &str, format, usage| Image::new(ctx, name, format, extent, 1, usage);
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let position = image("exact receiver positions", POSITION_FORMAT, color)?;
        let normal = image("exact receiver normals", POSITION_FORMAT, color)?;
        let depth = image(
            "exact receiver depth",
            DEPTH_FORMAT,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        )?;
        let pixels = (extent.width * extent.height) as u64;
        let storage = |name: &str, size: u64| {
            Buffer::new(
                ctx,
                name,
                size,
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )
            .map(SharedBuffer::new)
        };
        let t = Targets {
            extent,
            position: Attachment::of(&position),
            normal: Attachment::of(&normal),
            depth: Attachment::of(&depth),
            _position: position,
            _normal: normal,
            _depth: depth,
            heads: storage("exact grid heads", 2 * MAX_CELLS * 4)?,
            next: storage("exact sample links", pixels * 4)?,
            samples: storage("exact samples", (pixels + 1) * 16)?,
            rays: storage("exact shadow rays", pixels * 16)?,
            tiles: storage("hybrid traced tiles", TILE_WORDS * 4)?,
        };
        for (slot, &set) in self.sets.iter().enumerate() {
            self.write_set(scene, &t, slot, set);
        }
        // A new set of targets: every slot's map binding is written again (`bind_map`).
        self.bound_map.fill(vk::ImageView::null());
        self.targets = Some(t);
        Ok(())
    }

    /// Writes slot `slot`'s descriptor set: its uniforms, `t`'s buffers and images, the scene's
    /// geometry and the culling's bindings.
    fn write_set(&self, scene: &GpuScene, t: &Targets, slot: usize, set: vk::DescriptorSet) {
        let d = &self.ctx.device;
        write_buffers(
            d,
            set,
            &[
                (&sh::XF, self.uniforms[slot].raw),
                (&sh::HEADS, t.heads.raw()),
                (&sh::NEXT, t.next.raw()),
                (&sh::SAMPLES, t.samples.raw()),
                (&sh::RAYS, t.rays.raw()),
                (&sh::TILES, t.tiles.raw()),
                (&sh::TILES_READ, t.tiles.raw()),
                (&sh::POSITIONS, scene.positions.raw),
                (&sh::INDICES, scene.indices.raw),
                (&sh::ATTRIBUTES, scene.attributes.raw),
            ],
        );
        write_buffers(d, set, &self.culling.bindings());
        write_sampled_images(
            d,
            set,
            &[
                (&sh::RECEIVER_POSITION, t.position.view),
                (&sh::RECEIVER_NORMAL, t.normal.view),
            ],
        );
    }
}
