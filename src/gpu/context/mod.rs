//! The Vulkan context. Drop order, written down: wait idle → stored pipelines → allocator →
//! command pool → device → debug messenger → instance.
//!
//! `error` holds the error type, `validation` the validation layer's log, `startup` the creation
//! of the instance and the device.

mod error;
mod startup;
mod validation;

pub use error::{GpuError, VkCheck};
pub use validation::{Validation, ValidationLog};

use startup::{create_device, create_instance, pick_device, DeviceOwner, InstanceOwner};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::CString;
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

/// How to create a context.
#[derive(Clone, Debug)]
pub struct ContextDesc {
    /// Validation layer policy. `UMBRA_VALIDATION=1` turns `Off` into `Required`.
    pub validation: Validation,
    /// Substring of the device name to pick (case-insensitive); `UMBRA_DEVICE` is used when `None`.
    pub device: Option<String>,
    /// Extra instance extensions (surface extensions for a window).
    pub instance_extensions: Vec<CString>,
    /// Enable VK_KHR_swapchain on the device.
    pub swapchain: bool,
    /// A file that keeps the Vulkan pipeline cache between processes (read at creation when it
    /// belongs to this device, written back when the context is dropped); None keeps it in
    /// memory only. See `gpu::pipeline_cache::default_path`.
    pub pipeline_cache: Option<std::path::PathBuf>,
    /// On a CPU device (lavapipe) with glibc, keep the driver's per-frame working memory mapped
    /// between frames: raises glibc's `M_TRIM_THRESHOLD` to 64 MiB and fixes `M_MMAP_THRESHOLD`
    /// at 32 MiB, process-wide, once (`mallopt`). Without it llvmpipe returns its memory to the
    /// kernel at the end of every frame and faults it back in on the next (a FlightHelmet frame
    /// at 128×72: 29–36 → 21–23 ms). The cost: up to 64 MiB of freed memory kept per malloc arena.
    /// Default true; false leaves the allocator as the process set it.
    pub keep_driver_heap: bool,
}

impl Default for ContextDesc {
    fn default() -> Self {
        Self {
            validation: Validation::Off,
            device: None,
            instance_extensions: Vec::new(),
            swapchain: false,
            pipeline_cache: None,
            keep_driver_heap: true,
        }
    }
}

/// Owns the Vulkan instance, device, queue and allocator. Share it as `Arc<Context>`.
pub struct Context {
    /// The chosen physical device.
    pub(crate) physical: vk::PhysicalDevice,
    /// The graphics queue (also used for transfers).
    pub(crate) queue: vk::Queue,
    /// Its family index.
    pub(crate) queue_family: u32,
    /// Device properties.
    pub(crate) properties: vk::PhysicalDeviceProperties,
    /// Device name.
    pub device_name: String,
    /// Whether sampler anisotropy is enabled.
    pub anisotropy: bool,
    /// Whether the BC block-compressed formats are enabled (`textureCompressionBC`).
    pub texture_compression_bc: bool,
    /// Valid bits of timestamps on the queue (0 = no timestamps).
    pub timestamp_valid_bits: u32,
    /// Whether fragment shaders may write storage buffers (`fragmentStoresAndAtomics`, enabled
    /// when the device has it): the exact shadow method needs it.
    pub fragment_stores: bool,
    /// Whether colour attachments may blend and mask differently (`independentBlend`, enabled
    /// when the device has it): without it a pipeline writes all its targets.
    pub independent_blend: bool,
    /// Validation messages (all zero when validation is off). Keep a clone to read the messages
    /// sent while the context is destroyed (leaks, destroy-time errors).
    pub validation_log: Arc<ValidationLog>,
    /// Whether the validation layer is on.
    pub validation_enabled: bool,
    /// The pipeline cache every pipeline is created with.
    pub(crate) pipeline_cache: vk::PipelineCache,
    pipeline_cache_path: Option<std::path::PathBuf>,
    /// Every pipeline made on this context, by what it is made from (destroyed with it).
    pub(crate) pipelines: super::pipeline_store::PipelineStore,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    command_pool: Mutex<vk::CommandPool>,
    debug_device: Option<ash::ext::debug_utils::Device>,
    // Dropped in this order, after `Drop::drop` has freed the allocator and the command pool.
    /// The logical device.
    pub(crate) device: DeviceOwner,
    /// The instance (and loader).
    pub(crate) instance: InstanceOwner,
}

/// The raw Vulkan objects of a [`Context`] ([`Context::raw`]).
pub struct RawVulkan<'a> {
    /// The instance.
    pub instance: &'a ash::Instance,
    /// The physical device.
    pub physical: vk::PhysicalDevice,
    /// The logical device.
    pub device: &'a ash::Device,
    /// The graphics queue every frame is submitted to.
    pub queue: vk::Queue,
    /// Its family index.
    pub queue_family: u32,
}

/// The device's memory allocator (gpu-allocator).
fn new_allocator(
    instance: &InstanceOwner,
    device: &DeviceOwner,
    physical: vk::PhysicalDevice,
) -> Result<Allocator, GpuError> {
    Allocator::new(&AllocatorCreateDesc {
        instance: instance.raw.clone(),
        device: device.0.clone(),
        physical_device: physical,
        debug_settings: Default::default(),
        buffer_device_address: false,
        allocation_sizes: Default::default(),
    })
    .map_err(|e| GpuError::Alloc {
        name: "allocator".into(),
        message: e.to_string(),
    })
}

/// The pipeline cache, seeded from `desc.pipeline_cache`'s file where it holds one for this
/// device (`command_pool` is destroyed on failure).
fn new_pipeline_cache(
    device: &DeviceOwner,
    desc: &ContextDesc,
    properties: &vk::PhysicalDeviceProperties,
    command_pool: vk::CommandPool,
) -> Result<vk::PipelineCache, GpuError> {
    let initial = desc
        .pipeline_cache
        .as_deref()
        .map(|p| super::pipeline_cache::load(p, properties))
        .unwrap_or_default();
    let cache_info = vk::PipelineCacheCreateInfo::default().initial_data(&initial);
    unsafe { device.create_pipeline_cache(&cache_info, None) }.map_err(|e| {
        unsafe { device.destroy_command_pool(command_pool, None) };
        GpuError::Vk {
            call: "vkCreatePipelineCache",
            result: e,
        }
    })
}

impl Context {
    /// Whether the device is a CPU implementation (lavapipe: llvmpipe's trade-offs apply).
    pub fn is_cpu(&self) -> bool {
        self.properties.device_type == vk::PhysicalDeviceType::CPU
    }

    /// Creates a context: loads Vulkan, picks a device (explicit choice, then discrete > integrated
    /// > CPU), enables dynamic rendering, synchronization2 and depth clamp.
    pub fn new(desc: &ContextDesc) -> Result<Arc<Context>, GpuError> {
        let entry = unsafe { ash::Entry::load() }.map_err(|e| GpuError::NoLoader(e.to_string()))?;
        let log = Arc::new(ValidationLog::default());
        let (instance, enable_validation) = create_instance(entry, desc, &log)?;
        let (physical, queue_family, anisotropy) = pick_device(&instance, desc)?;
        let properties = unsafe { instance.get_physical_device_properties(physical) };
        let device_name = properties
            .device_name_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if desc.keep_driver_heap && properties.device_type == vk::PhysicalDeviceType::CPU {
            let kept = super::heap::keep_freed_memory();
            log::info!(
                "CPU device: glibc trim threshold raised to keep the driver's memory: {kept}"
            );
        }
        let qf_props = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let timestamp_valid_bits = qf_props[queue_family as usize].timestamp_valid_bits;
        let features = unsafe { instance.get_physical_device_features(physical) };
        let fragment_stores = features.fragment_stores_and_atomics == vk::TRUE;
        let independent_blend = features.independent_blend == vk::TRUE;
        let texture_compression_bc = features.texture_compression_bc == vk::TRUE;
        let device = create_device(
            &instance,
            physical,
            queue_family,
            (
                anisotropy,
                fragment_stores,
                independent_blend,
                texture_compression_bc,
            ),
            desc.swapchain,
        )?;
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let allocator = new_allocator(&instance, &device, physical)?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let command_pool =
            unsafe { device.create_command_pool(&pool_info, None) }.vk("vkCreateCommandPool")?;
        let pipeline_cache = new_pipeline_cache(&device, desc, &properties, command_pool)?;
        let debug_device = instance
            .debug_utils
            .as_ref()
            .map(|_| ash::ext::debug_utils::Device::new(&instance, &device));
        log::info!(
            "Vulkan device: {device_name} (validation {})",
            if enable_validation { "on" } else { "off" }
        );
        Ok(Arc::new(Context {
            physical,
            queue,
            queue_family,
            properties,
            device_name,
            anisotropy,
            texture_compression_bc,
            timestamp_valid_bits,
            fragment_stores,
            independent_blend,
            validation_log: log,
            validation_enabled: enable_validation,
            pipeline_cache,
            pipeline_cache_path: desc.pipeline_cache.clone(),
            pipelines: Default::default(),
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            command_pool: Mutex::new(command_pool),
            debug_device,
            device,
            instance,
        }))
    }

    /// The raw Vulkan objects, for a front end that records its own drawing into a window's
    /// frames (an on-screen panel: `render::Overlay`). Objects it makes from them must be
    /// destroyed before the context.
    pub fn raw(&self) -> RawVulkan<'_> {
        RawVulkan {
            instance: &self.instance,
            physical: self.physical,
            device: &self.device,
            queue: self.queue,
            queue_family: self.queue_family,
        }
    }

    /// How many pipelines this context holds: every distinct one its renderers have asked for,
    /// made once and kept until the context is dropped (`gpu::pipeline_store`).
    pub fn stored_pipelines(&self) -> usize {
        self.pipelines.len()
    }

    /// The memory allocator.
    pub fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Gives a Vulkan object a debug name (no-op without debug utils).
    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(d) = &self.debug_device {
            if let Ok(c) = CString::new(name) {
                let info = vk::DebugUtilsObjectNameInfoEXT::default()
                    .object_handle(handle)
                    .object_name(&c);
                unsafe {
                    let _ = d.set_debug_utils_object_name(&info);
                }
            }
        }
    }

    /// Removes a debug name before the object is destroyed. The validation layer keeps names of
    /// destroyed objects otherwise (measured: +0.47 MB per 1,000 recreated render targets).
    pub fn clear_name<H: vk::Handle>(&self, handle: H) {
        if let Some(d) = &self.debug_device {
            // A null name removes the entry (an empty string would store "").
            let mut info = vk::DebugUtilsObjectNameInfoEXT::default().object_handle(handle);
            info.p_object_name = std::ptr::null();
            unsafe {
                let _ = d.set_debug_utils_object_name(&info);
            }
        }
    }

    /// Opens a labelled region in a command buffer (no-op without debug utils).
    pub fn begin_label(&self, cmd: vk::CommandBuffer, name: &str) {
        if let (Some(d), Ok(c)) = (&self.debug_device, CString::new(name)) {
            let label = vk::DebugUtilsLabelEXT::default().label_name(&c);
            unsafe { d.cmd_begin_debug_utils_label(cmd, &label) };
        }
    }

    /// Closes the region opened by `begin_label`.
    pub fn end_label(&self, cmd: vk::CommandBuffer) {
        if let Some(d) = &self.debug_device {
            unsafe { d.cmd_end_debug_utils_label(cmd) };
        }
    }

    /// Allocates a primary command buffer from the context's pool.
    pub fn allocate_command_buffer(&self) -> Result<vk::CommandBuffer, GpuError> {
        let pool = self.command_pool.lock().unwrap_or_else(|e| e.into_inner());
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(*pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        Ok(
            unsafe { self.device.allocate_command_buffers(&info) }
                .vk("vkAllocateCommandBuffers")?[0],
        )
    }

    /// Frees a command buffer from `allocate_command_buffer` (it must not be in flight).
    pub fn free_command_buffer(&self, cmd: vk::CommandBuffer) {
        let pool = self.command_pool.lock().unwrap_or_else(|e| e.into_inner());
        unsafe { self.device.free_command_buffers(*pool, &[cmd]) };
    }

    /// Resets `cmd` and begins recording it for one submission.
    pub fn begin_one_time(&self, cmd: vk::CommandBuffer) -> Result<(), GpuError> {
        unsafe {
            self.device
                .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .vk("vkResetCommandBuffer")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            self.device
                .begin_command_buffer(cmd, &begin)
                .vk("vkBeginCommandBuffer")
        }
    }

    /// Records `f` into a one-time command buffer, submits it and waits for it to finish.
    pub fn immediate<R>(&self, f: impl FnOnce(vk::CommandBuffer) -> R) -> Result<R, GpuError> {
        let cmd = self.allocate_command_buffer()?;
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        let result = unsafe {
            self.device
                .begin_command_buffer(cmd, &begin)
                .vk("vkBeginCommandBuffer")?;
            let r = f(cmd);
            self.device
                .end_command_buffer(cmd)
                .vk("vkEndCommandBuffer")?;
            self.submit_and_wait(cmd)?;
            r
        };
        self.free_command_buffer(cmd);
        Ok(result)
    }

    /// Submits one command buffer and blocks until it completes (with a temporary fence).
    pub fn submit_and_wait(&self, cmd: vk::CommandBuffer) -> Result<(), GpuError> {
        let fence = unsafe {
            self.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .vk("vkCreateFence")?;
        let r = self.submit_and_wait_with(cmd, fence);
        unsafe { self.device.destroy_fence(fence, None) };
        r
    }

    /// Submits one command buffer, signalling the unsignalled `fence`, waits for it and resets it.
    pub fn submit_and_wait_with(
        &self,
        cmd: vk::CommandBuffer,
        fence: vk::Fence,
    ) -> Result<(), GpuError> {
        self.submit_with(cmd, fence)?;
        self.wait_and_reset(fence)
    }

    /// Submits one command buffer, signalling the unsignalled `fence` (`wait_and_reset` waits
    /// for it).
    pub fn submit_with(&self, cmd: vk::CommandBuffer, fence: vk::Fence) -> Result<(), GpuError> {
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
        unsafe {
            self.device
                .queue_submit2(self.queue, &submit, fence)
                .vk("vkQueueSubmit2")
        }
    }

    /// Waits for `fence` and resets it.
    pub fn wait_and_reset(&self, fence: vk::Fence) -> Result<(), GpuError> {
        unsafe {
            self.device
                .wait_for_fences(&[fence], true, u64::MAX)
                .vk("vkWaitForFences")?;
            self.device.reset_fences(&[fence]).vk("vkResetFences")
        }
    }

    /// Format features (optimal tiling) of `format`.
    pub fn format_features(&self, format: vk::Format) -> vk::FormatFeatureFlags {
        unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical, format)
        }
        .optimal_tiling_features
    }

    /// Whether `format` (optimal tiling) can be both ends of a linear-filtered blit
    /// (`resources::blit_linear`: mip chains, the supersampled frame's filter).
    pub fn blits_linear(&self, format: vk::Format) -> bool {
        self.format_features(format).contains(
            vk::FormatFeatureFlags::BLIT_SRC
                | vk::FormatFeatureFlags::BLIT_DST
                | vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR,
        )
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            self.pipelines.destroy(&self.device);
            ManuallyDrop::drop(&mut self.allocator);
            let pool = *self.command_pool.lock().unwrap_or_else(|e| e.into_inner());
            self.device.destroy_command_pool(pool, None);
            if let Some(path) = &self.pipeline_cache_path {
                match self.device.get_pipeline_cache_data(self.pipeline_cache) {
                    Ok(data) => {
                        if let Err(e) = super::pipeline_cache::store(path, &data) {
                            log::warn!("pipeline cache not saved to {}: {e}", path.display());
                        }
                    }
                    Err(e) => log::warn!("pipeline cache not read back: {e}"),
                }
            }
            self.device
                .destroy_pipeline_cache(self.pipeline_cache, None);
        }
        // Then the fields: `device` (DeviceOwner), then `instance` (messenger, instance, loader).
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Mutex, MutexGuard, PoisonError};

    /// These two tests' contexts live one at a time: the Khronos layer (1.3.239) can crash when
    /// one thread creates or destroys a device while another uses its own
    /// (KhronosGroup/Vulkan-ValidationLayers#4391; tests/common's `one_at_a_time`).
    fn turn() -> MutexGuard<'static, ()> {
        static TURN: Mutex<()> = Mutex::new(());
        TURN.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn validated() -> Arc<Context> {
        Context::new(&ContextDesc {
            validation: Validation::Required,
            ..Default::default()
        })
        .expect("a validated context (lavapipe + Khronos layer)")
    }

    /// Positive control: a deliberately invalid call (a sampler with maxLod < minLod) must reach
    /// the messenger and be counted, so a silently absent messenger fails the suite.
    #[test]
    fn messenger_reports_invalid_usage() {
        let _turn = turn();
        let ctx = validated();
        assert_eq!(ctx.validation_log.problem_count(), 0);
        let info = vk::SamplerCreateInfo::default().min_lod(2.0).max_lod(1.0);
        if let Ok(s) = unsafe { ctx.device.create_sampler(&info, None) } {
            unsafe { ctx.device.destroy_sampler(s, None) };
        }
        assert!(
            ctx.validation_log.problem_count() >= 1,
            "the validation layer's message did not reach the log"
        );
        assert!(
            ctx.validation_log
                .messages()
                .iter()
                .any(|m| m.contains("VUID-VkSamplerCreateInfo-maxLod-01973")),
            "{:?}",
            ctx.validation_log.messages()
        );
    }

    /// Messages sent while a context is destroyed (here: a leaked fence, reported by
    /// vkDestroyDevice) reach a log kept past the context.
    #[test]
    fn leaks_are_counted_after_the_context_is_dropped() {
        let _turn = turn();
        let ctx = validated();
        let log = ctx.validation_log.clone();
        let _leaked = unsafe {
            ctx.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        };
        assert_eq!(log.problem_count(), 0);
        drop(ctx);
        assert!(
            log.messages().iter().any(|m| m.contains("VkFence")),
            "the leaked fence was not reported at destruction: {:?}",
            log.messages()
        );
    }
}
