//! What a pass reads and writes, declared where the pass (or one of its steps) begins. Each image
//! it uses is named with the access the pass needs: its inputs (sampled, a copy's source,
//! presentation) and its outputs (attachments, a copy's destination); so is each buffer that
//! passes share (storage written by one step and read by the next, indirect arguments,
//! readbacks). The barriers are derived from what each resource was last used for and recorded
//! as one dependency, so no pass places a barrier by hand, and none tracks a layout.
//!
//! Resources remember their last use across frames: command buffers are submitted in the order
//! they are recorded.

use crate::gpu::barrier::{barrier_info, record_dependency, Access};
use crate::gpu::{Buffer, Image};
use ash::vk;
use vk::AccessFlags2 as A;
use vk::PipelineStageFlags2 as S;

/// An image a pass renders into, reads or copies, with the access it was last used with.
pub struct Attachment {
    /// Image.
    pub image: vk::Image,
    /// View.
    pub view: vk::ImageView,
    /// Colour or depth.
    pub aspect: vk::ImageAspectFlags,
    /// Last access (`Access::Acquired` for a swapchain image just acquired).
    pub state: Access,
}

impl Attachment {
    /// An attachment for a not yet used `Image`.
    pub fn of(image: &Image) -> Self {
        Self {
            image: image.raw,
            view: image.view,
            aspect: image.aspect,
            state: Access::Undefined,
        }
    }
}

/// How a step uses a buffer that passes share.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BufferAccess {
    /// Filled, or copied into.
    TransferWrite,
    /// Copied from.
    TransferRead,
    /// Read by compute shaders.
    ComputeRead,
    /// Written, or read and written (atomics), by compute shaders.
    ComputeWrite,
    /// Read by vertex shaders.
    VertexRead,
    /// Read by fragment shaders.
    FragmentRead,
    /// Written, or read and written, by fragment shaders.
    FragmentWrite,
    /// Indirect draw arguments.
    Indirect,
    /// Read by the host once the frame's fence is signalled.
    HostRead,
}

impl BufferAccess {
    /// (stage, access, writes).
    fn info(self) -> (S, A, bool) {
        let rw = A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE;
        match self {
            Self::TransferWrite => (S::ALL_TRANSFER, A::TRANSFER_WRITE, true),
            Self::TransferRead => (S::ALL_TRANSFER, A::TRANSFER_READ, false),
            Self::ComputeRead => (S::COMPUTE_SHADER, A::SHADER_STORAGE_READ, false),
            Self::ComputeWrite => (S::COMPUTE_SHADER, rw, true),
            Self::VertexRead => (S::VERTEX_SHADER, A::SHADER_STORAGE_READ, false),
            Self::FragmentRead => (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ, false),
            Self::FragmentWrite => (S::FRAGMENT_SHADER, rw, true),
            Self::Indirect => (S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ, false),
            Self::HostRead => (S::HOST, A::HOST_READ, false),
        }
    }
}

/// A buffer passes share, and its last uses.
pub struct SharedBuffer {
    /// The buffer.
    pub buffer: Buffer,
    state: BufferState,
}

impl SharedBuffer {
    /// A buffer not yet used.
    pub fn new(buffer: Buffer) -> Self {
        Self {
            buffer,
            state: BufferState::default(),
        }
    }

    /// The Vulkan handle.
    pub fn raw(&self) -> vk::Buffer {
        self.buffer.raw
    }
}

/// A shared buffer's last write and the stages that read it since.
#[derive(Clone, Copy, Debug, Default)]
struct BufferState {
    /// The last write's stage and access.
    written: Option<(S, A)>,
    /// Stages that read it since (a later write waits for them).
    read_by: S,
    /// Stages the last write is visible to.
    visible_to: S,
}

impl BufferState {
    /// Adds what `to` must wait for to `dep` and remembers `to`.
    fn advance(&mut self, to: BufferAccess, dep: &mut Dependency) {
        let (stage, access, writes) = to.info();
        if writes {
            // After the last write (made available) and every read since (execution only).
            if let Some((ws, wa)) = self.written {
                dep.wait(ws, wa);
            }
            dep.wait(self.read_by, A::NONE);
            dep.before(stage, access);
            self.written = Some((stage, access & !read_accesses()));
            self.read_by = S::NONE;
            self.visible_to = S::NONE;
            return;
        }
        if let Some((ws, wa)) = self.written.filter(|_| !self.visible_to.contains(stage)) {
            dep.wait(ws, wa);
            dep.before(stage, access);
            self.visible_to |= stage;
        }
        // The host's reads are ordered by the frame's fence, not by a barrier.
        if to != BufferAccess::HostRead {
            self.read_by |= stage;
        }
    }
}

/// Every read access a buffer use can carry (left out of what a write makes available).
fn read_accesses() -> A {
    A::SHADER_STORAGE_READ | A::TRANSFER_READ | A::INDIRECT_COMMAND_READ | A::HOST_READ
}

/// One global memory barrier, built from the buffers' uses.
#[derive(Default, Debug, PartialEq)]
struct Dependency {
    src: (S, A),
    dst: (S, A),
}

impl Dependency {
    fn wait(&mut self, stage: S, access: A) {
        self.src = (self.src.0 | stage, self.src.1 | access);
    }

    fn before(&mut self, stage: S, access: A) {
        self.dst = (self.dst.0 | stage, self.dst.1 | access);
    }

    /// The barrier, where there is something to wait for.
    fn barrier(&self) -> Option<vk::MemoryBarrier2<'static>> {
        (self.src.0 != S::NONE).then(|| {
            vk::MemoryBarrier2::default()
                .src_stage_mask(self.src.0)
                .src_access_mask(self.src.1)
                .dst_stage_mask(self.dst.0)
                .dst_access_mask(self.dst.1)
        })
    }
}

/// The images and buffers one pass (or one step of a pass) uses, each with its access.
#[derive(Default)]
#[must_use = "a pass's uses take effect when entered"]
pub struct Uses<'a> {
    images: Vec<(&'a mut Attachment, Access)>,
    buffers: Vec<(&'a mut BufferState, BufferAccess)>,
}

impl<'a> Uses<'a> {
    /// Nothing yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// An input: `image` read with `access`.
    pub fn reads(mut self, image: &'a mut Attachment, access: Access) -> Self {
        debug_assert!(access.reads(), "{access:?} is not a read");
        self.images.push((image, access));
        self
    }

    /// An input that may be absent (a map not made yet, a pass not run this frame).
    pub fn reads_some(self, image: Option<&'a mut Attachment>, access: Access) -> Self {
        match image {
            Some(image) => self.reads(image, access),
            None => self,
        }
    }

    /// An output: `image` written with `access`.
    pub fn writes(mut self, image: &'a mut Attachment, access: Access) -> Self {
        debug_assert!(access.writes(), "{access:?} is not a write");
        self.images.push((image, access));
        self
    }

    /// An output that may be absent (an output not asked for).
    pub fn writes_some(self, image: Option<&'a mut Attachment>, access: Access) -> Self {
        match image {
            Some(image) => self.writes(image, access),
            None => self,
        }
    }

    /// Outputs: each of `images` written with `access`.
    pub fn writes_each(
        self,
        images: impl IntoIterator<Item = &'a mut Attachment>,
        access: Access,
    ) -> Self {
        images.into_iter().fold(self, |u, i| u.writes(i, access))
    }

    /// Inputs: each of `images` read with `access`.
    pub fn reads_each(
        self,
        images: impl IntoIterator<Item = &'a mut Attachment>,
        access: Access,
    ) -> Self {
        images.into_iter().fold(self, |u, i| u.reads(i, access))
    }

    /// A shared buffer read (`access` a read).
    pub fn reads_buffer(mut self, buffer: &'a mut SharedBuffer, access: BufferAccess) -> Self {
        debug_assert!(!access.info().2, "{access:?} is not a read");
        self.buffers.push((&mut buffer.state, access));
        self
    }

    /// A shared buffer read that may be absent.
    pub fn reads_buffer_some(
        self,
        buffer: Option<&'a mut SharedBuffer>,
        access: BufferAccess,
    ) -> Self {
        match buffer {
            Some(buffer) => self.reads_buffer(buffer, access),
            None => self,
        }
    }

    /// A shared buffer written (`access` a write).
    pub fn writes_buffer(mut self, buffer: &'a mut SharedBuffer, access: BufferAccess) -> Self {
        debug_assert!(access.info().2, "{access:?} is not a write");
        self.buffers.push((&mut buffer.state, access));
        self
    }

    /// The barriers, each resource's last use advanced to the declared one. An image written
    /// always gets a barrier (a later write waits for the earlier one); one read gets one only
    /// where its last access differs. A buffer's uses fold into one global memory barrier: a
    /// write waits for the last write and the reads since, a read for a write not yet visible
    /// to its stage.
    fn barriers(
        self,
    ) -> (
        Option<vk::MemoryBarrier2<'static>>,
        Vec<vk::ImageMemoryBarrier2<'static>>,
    ) {
        let mut images = Vec::with_capacity(self.images.len());
        for (image, to) in self.images {
            if to.writes() || image.state != to {
                images.push(barrier_info(
                    image.image,
                    image.aspect,
                    0..1,
                    image.state,
                    to,
                ));
            }
            image.state = to;
        }
        let mut dep = Dependency::default();
        for (buffer, to) in self.buffers {
            buffer.advance(to, &mut dep);
        }
        (dep.barrier(), images)
    }

    /// Records the barriers into `cmd` as one dependency and remembers each resource's new use.
    pub fn enter(self, device: &ash::Device, cmd: vk::CommandBuffer) {
        let (memory, images) = self.barriers();
        record_dependency(device, cmd, memory.as_slice(), &images);
    }
}

#[cfg(test)]
mod tests;
