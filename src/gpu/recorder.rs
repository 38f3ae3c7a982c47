//! Recording commands: a command buffer with its device, one method per command the passes
//! record (the same arguments as `ash::Device::cmd_*` without the command buffer). The raw,
//! `unsafe` recording calls live here and nowhere above the GPU layer; the Vulkan rules each
//! command carries (valid handles, recording state, layouts) are the callers', and the Khronos
//! validation layer checks them in every GPU test.

use ash::vk;

/// A command buffer in the recording state and the device it belongs to.
#[derive(Clone, Copy)]
pub struct Recorder<'a> {
    d: &'a ash::Device,
    cmd: vk::CommandBuffer,
}

impl<'a> Recorder<'a> {
    /// Records into `cmd` (begun, not ended) of device `d`.
    pub fn new(d: &'a ash::Device, cmd: vk::CommandBuffer) -> Self {
        Self { d, cmd }
    }

    /// `vkCmdBindPipeline`.
    pub fn bind_pipeline(
        &self,
        pipeline_bind_point: vk::PipelineBindPoint,
        pipeline: vk::Pipeline,
    ) {
        unsafe {
            self.d
                .cmd_bind_pipeline(self.cmd, pipeline_bind_point, pipeline)
        }
    }

    /// `vkCmdEndRendering`.
    pub fn end_rendering(&self) {
        unsafe { self.d.cmd_end_rendering(self.cmd) }
    }

    /// `vkCmdSetScissor`.
    pub fn set_scissor(&self, first_scissor: u32, scissors: &[vk::Rect2D]) {
        unsafe { self.d.cmd_set_scissor(self.cmd, first_scissor, scissors) }
    }

    /// `vkCmdSetFrontFace`.
    pub fn set_front_face(&self, front_face: vk::FrontFace) {
        unsafe { self.d.cmd_set_front_face(self.cmd, front_face) }
    }

    /// `vkCmdSetCullMode`.
    pub fn set_cull_mode(&self, cull_mode: vk::CullModeFlags) {
        unsafe { self.d.cmd_set_cull_mode(self.cmd, cull_mode) }
    }

    /// `vkCmdBeginRendering`.
    pub fn begin_rendering(&self, rendering_info: &vk::RenderingInfo<'_>) {
        unsafe { self.d.cmd_begin_rendering(self.cmd, rendering_info) }
    }

    /// `vkCmdDraw`.
    pub fn draw(
        &self,
        vertex_count: u32,
        instance_count: u32,
        first_vertex: u32,
        first_instance: u32,
    ) {
        unsafe {
            self.d.cmd_draw(
                self.cmd,
                vertex_count,
                instance_count,
                first_vertex,
                first_instance,
            )
        }
    }

    /// `vkCmdBindDescriptorSets`.
    pub fn bind_descriptor_sets(
        &self,
        pipeline_bind_point: vk::PipelineBindPoint,
        layout: vk::PipelineLayout,
        first_set: u32,
        descriptor_sets: &[vk::DescriptorSet],
        dynamic_offsets: &[u32],
    ) {
        unsafe {
            self.d.cmd_bind_descriptor_sets(
                self.cmd,
                pipeline_bind_point,
                layout,
                first_set,
                descriptor_sets,
                dynamic_offsets,
            )
        }
    }

    /// `vkCmdWriteTimestamp2`.
    pub fn write_timestamp2(
        &self,
        stage: vk::PipelineStageFlags2,
        query_pool: vk::QueryPool,
        query: u32,
    ) {
        unsafe {
            self.d
                .cmd_write_timestamp2(self.cmd, stage, query_pool, query)
        }
    }

    /// `vkCmdDrawIndirect`.
    pub fn draw_indirect(
        &self,
        buffer: vk::Buffer,
        offset: vk::DeviceSize,
        draw_count: u32,
        stride: u32,
    ) {
        unsafe {
            self.d
                .cmd_draw_indirect(self.cmd, buffer, offset, draw_count, stride)
        }
    }

    /// `vkCmdPushConstants`.
    pub fn push_constants(
        &self,
        layout: vk::PipelineLayout,
        stage_flags: vk::ShaderStageFlags,
        offset: u32,
        constants: &[u8],
    ) {
        unsafe {
            self.d
                .cmd_push_constants(self.cmd, layout, stage_flags, offset, constants)
        }
    }

    /// `vkCmdSetStencilReference`.
    pub fn set_stencil_reference(&self, face_mask: vk::StencilFaceFlags, reference: u32) {
        unsafe {
            self.d
                .cmd_set_stencil_reference(self.cmd, face_mask, reference)
        }
    }

    /// `vkCmdPipelineBarrier2`.
    pub fn pipeline_barrier2(&self, dependency_info: &vk::DependencyInfo<'_>) {
        unsafe { self.d.cmd_pipeline_barrier2(self.cmd, dependency_info) }
    }

    /// `vkCmdDispatch`.
    pub fn dispatch(&self, group_count_x: u32, group_count_y: u32, group_count_z: u32) {
        unsafe {
            self.d
                .cmd_dispatch(self.cmd, group_count_x, group_count_y, group_count_z)
        }
    }

    /// `vkCmdBindVertexBuffers`.
    pub fn bind_vertex_buffers(
        &self,
        first_binding: u32,
        buffers: &[vk::Buffer],
        offsets: &[vk::DeviceSize],
    ) {
        unsafe {
            self.d
                .cmd_bind_vertex_buffers(self.cmd, first_binding, buffers, offsets)
        }
    }

    /// `vkCmdBindIndexBuffer`.
    pub fn bind_index_buffer(
        &self,
        buffer: vk::Buffer,
        offset: vk::DeviceSize,
        index_type: vk::IndexType,
    ) {
        unsafe {
            self.d
                .cmd_bind_index_buffer(self.cmd, buffer, offset, index_type)
        }
    }

    /// `vkCmdSetViewport`.
    pub fn set_viewport(&self, first_viewport: u32, viewports: &[vk::Viewport]) {
        unsafe { self.d.cmd_set_viewport(self.cmd, first_viewport, viewports) }
    }

    /// `vkCmdSetDepthBias`.
    pub fn set_depth_bias(&self, constant_factor: f32, clamp: f32, slope_factor: f32) {
        unsafe {
            self.d
                .cmd_set_depth_bias(self.cmd, constant_factor, clamp, slope_factor)
        }
    }

    /// `vkCmdResetQueryPool`.
    pub fn reset_query_pool(&self, pool: vk::QueryPool, first_query: u32, query_count: u32) {
        unsafe {
            self.d
                .cmd_reset_query_pool(self.cmd, pool, first_query, query_count)
        }
    }

    /// `vkCmdFillBuffer`.
    pub fn fill_buffer(
        &self,
        buffer: vk::Buffer,
        offset: vk::DeviceSize,
        size: vk::DeviceSize,
        data: u32,
    ) {
        unsafe { self.d.cmd_fill_buffer(self.cmd, buffer, offset, size, data) }
    }

    /// `vkCmdCopyBuffer`.
    pub fn copy_buffer(&self, src: vk::Buffer, dst: vk::Buffer, regions: &[vk::BufferCopy]) {
        unsafe { self.d.cmd_copy_buffer(self.cmd, src, dst, regions) }
    }

    /// `vkCmdDrawIndexed`.
    pub fn draw_indexed(
        &self,
        index_count: u32,
        instance_count: u32,
        first_index: u32,
        vertex_offset: i32,
        first_instance: u32,
    ) {
        unsafe {
            self.d.cmd_draw_indexed(
                self.cmd,
                index_count,
                instance_count,
                first_index,
                vertex_offset,
                first_instance,
            )
        }
    }

    /// `vkCmdCopyImageToBuffer`.
    pub fn copy_image_to_buffer(
        &self,
        src_image: vk::Image,
        src_image_layout: vk::ImageLayout,
        dst_buffer: vk::Buffer,
        regions: &[vk::BufferImageCopy],
    ) {
        unsafe {
            self.d.cmd_copy_image_to_buffer(
                self.cmd,
                src_image,
                src_image_layout,
                dst_buffer,
                regions,
            )
        }
    }

    /// `vkCmdCopyImage`.
    pub fn copy_image(
        &self,
        src_image: vk::Image,
        src_image_layout: vk::ImageLayout,
        dst_image: vk::Image,
        dst_image_layout: vk::ImageLayout,
        regions: &[vk::ImageCopy],
    ) {
        unsafe {
            self.d.cmd_copy_image(
                self.cmd,
                src_image,
                src_image_layout,
                dst_image,
                dst_image_layout,
                regions,
            )
        }
    }
}
