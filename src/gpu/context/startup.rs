//! Creating the instance (with the validation layer when asked), picking the physical device
//! and creating the logical device; the owners that destroy them in order.

use super::validation::debug_callback;
use super::*;
use ash::vk;
use std::ffi::{c_void, CStr};
use std::sync::Arc;

/// The instance and its debug messenger, destroyed on drop (messenger, then instance, then the
/// loader library): the first RAII stage of a context, so a failure later in `Context::new`
/// cleans up what exists.
pub(crate) struct InstanceOwner {
    pub(super) raw: ash::Instance,
    pub(super) debug_utils: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Loader entry points (after `raw`, so the library outlives the instance).
    pub(crate) entry: ash::Entry,
}

impl std::ops::Deref for InstanceOwner {
    type Target = ash::Instance;
    fn deref(&self) -> &ash::Instance {
        &self.raw
    }
}

impl Drop for InstanceOwner {
    fn drop(&mut self) {
        unsafe {
            if let Some((du, m)) = &self.debug_utils {
                du.destroy_debug_utils_messenger(*m, None);
            }
            self.raw.destroy_instance(None);
        }
    }
}

/// The logical device, destroyed on drop (after waiting for it to idle): the second RAII stage.
pub(crate) struct DeviceOwner(pub(super) ash::Device);

impl std::ops::Deref for DeviceOwner {
    type Target = ash::Device;
    fn deref(&self) -> &ash::Device {
        &self.0
    }
}

impl Drop for DeviceOwner {
    fn drop(&mut self) {
        unsafe {
            let _ = self.0.device_wait_idle();
            self.0.destroy_device(None);
        }
    }
}

pub(super) const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

pub(super) fn score(kind: vk::PhysicalDeviceType) -> u32 {
    match kind {
        vk::PhysicalDeviceType::DISCRETE_GPU => 4,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 3,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 1,
        _ => 0,
    }
}

/// Whether the instance gets the validation layer: as `desc` asks (or `UMBRA_VALIDATION=1`), an
/// error where it is required and not installed.
fn validation_enabled(entry: &ash::Entry, desc: &ContextDesc) -> Result<bool, GpuError> {
    let mut validation = desc.validation;
    if validation == Validation::Off && std::env::var("UMBRA_VALIDATION").is_ok_and(|v| v == "1") {
        validation = Validation::Required;
    }
    let layers = unsafe { entry.enumerate_instance_layer_properties() }
        .vk("vkEnumerateInstanceLayerProperties")?;
    let has_layer = layers
        .iter()
        .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER));
    Ok(match validation {
        Validation::Off => false,
        Validation::IfAvailable => has_layer,
        Validation::Required if !has_layer => return Err(GpuError::NoValidationLayer),
        Validation::Required => true,
    })
}

/// The instance extensions `desc` asks for (an error naming one the driver lacks), with
/// VK_EXT_debug_utils added where the driver has it; and whether it does.
fn instance_extensions(
    entry: &ash::Entry,
    desc: &ContextDesc,
) -> Result<(Vec<*const i8>, bool), GpuError> {
    let exts = unsafe { entry.enumerate_instance_extension_properties(None) }
        .vk("vkEnumerateInstanceExtensionProperties")?;
    let has_ext = |name: &CStr| {
        exts.iter()
            .any(|e| e.extension_name_as_c_str().is_ok_and(|n| n == name))
    };
    let has_debug_utils = has_ext(ash::ext::debug_utils::NAME);
    let mut ext_names: Vec<*const i8> = desc
        .instance_extensions
        .iter()
        .map(|e| e.as_ptr())
        .collect();
    if let Some(e) = desc.instance_extensions.iter().find(|e| !has_ext(e)) {
        return Err(GpuError::Unsupported(format!(
            "instance extension {} is not available",
            e.to_string_lossy()
        )));
    }
    if has_debug_utils {
        ext_names.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    Ok((ext_names, has_debug_utils))
}

/// Creates the instance (with the validation layer and synchronization validation when asked
/// for) and its debug messenger; returns it owned, and whether validation is on.
pub(super) fn create_instance(
    entry: ash::Entry,
    desc: &ContextDesc,
    log: &Arc<ValidationLog>,
) -> Result<(InstanceOwner, bool), GpuError> {
    let enable_validation = validation_enabled(&entry, desc)?;
    let (ext_names, has_debug_utils) = instance_extensions(&entry, desc)?;
    let layer_names: Vec<*const i8> = if enable_validation {
        vec![VALIDATION_LAYER.as_ptr()]
    } else {
        vec![]
    };
    let app = vk::ApplicationInfo::default()
        .application_name(c"umbra")
        .engine_name(c"umbra")
        .api_version(vk::API_VERSION_1_3);
    let enabled_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut validation_features =
        vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);
    let messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                | vk::DebugUtilsMessageSeverityFlagsEXT::INFO,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(debug_callback))
        .user_data(Arc::as_ptr(log) as *mut c_void);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_extension_names(&ext_names)
        .enabled_layer_names(&layer_names);
    if enable_validation {
        info = info.push_next(&mut validation_features);
    }
    // A copy for the instance's pNext chain (push_next rewrites its pNext), so that messages
    // from instance creation and destruction are caught too. The log outlives the instance: the
    // context keeps it, and callers keep clones of it.
    let mut chained_messenger_info = messenger_info;
    if has_debug_utils {
        info = info.push_next(&mut chained_messenger_info);
    }
    let raw = match unsafe { entry.create_instance(&info, None) } {
        Ok(i) => i,
        Err(vk::Result::ERROR_INCOMPATIBLE_DRIVER) => {
            return Err(GpuError::NoDevice(
                "no Vulkan driver found; install one (apt-get install mesa-vulkan-drivers for lavapipe)".into(),
            ))
        }
        Err(e) => return Err(GpuError::Vk { call: "vkCreateInstance", result: e }),
    };
    let mut owner = InstanceOwner {
        raw,
        debug_utils: None,
        entry,
    };
    if has_debug_utils {
        let du = ash::ext::debug_utils::Instance::new(&owner.entry, &owner.raw);
        let m = unsafe { du.create_debug_utils_messenger(&messenger_info, None) }
            .vk("vkCreateDebugUtilsMessengerEXT")?;
        owner.debug_utils = Some((du, m));
    }
    Ok((owner, enable_validation))
}

/// Creates the logical device with dynamic rendering, synchronization2 and depth clamp (and the
/// swapchain extension when asked for), and with sampler anisotropy, fragment-shader stores,
/// independent blend and BC texture compression where `optional` says the device has them.
pub(super) fn create_device(
    instance: &InstanceOwner,
    physical: vk::PhysicalDevice,
    queue_family: u32,
    optional: (bool, bool, bool, bool),
    swapchain: bool,
) -> Result<DeviceOwner, GpuError> {
    let (anisotropy, fragment_stores, independent_blend, bc) = optional;
    let priorities = [1.0f32];
    let queue_info = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(queue_family)
        .queue_priorities(&priorities)];
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
        .dynamic_rendering(true)
        .synchronization2(true);
    let core = vk::PhysicalDeviceFeatures::default()
        .depth_clamp(true)
        .sampler_anisotropy(anisotropy)
        .fragment_stores_and_atomics(fragment_stores)
        .independent_blend(independent_blend)
        .texture_compression_bc(bc);
    let mut device_exts: Vec<*const i8> = Vec::new();
    if swapchain {
        device_exts.push(ash::khr::swapchain::NAME.as_ptr());
    }
    let dinfo = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_info)
        .enabled_features(&core)
        .enabled_extension_names(&device_exts)
        .push_next(&mut f13);
    let raw = unsafe { instance.create_device(physical, &dinfo, None) }.vk("vkCreateDevice")?;
    Ok(DeviceOwner(raw))
}

/// What device `pd` lacks of what umbra needs (Vulkan 1.3, dynamic rendering, synchronization2,
/// depth clamp, a graphics queue, sampled D32 depth, and the swapchain extension when asked for);
/// its graphics queue family; whether it has sampler anisotropy.
fn requirements(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    props: &vk::PhysicalDeviceProperties,
    swapchain: bool,
) -> (Vec<String>, Option<usize>, bool) {
    let mut missing = Vec::new();
    if props.api_version < vk::API_VERSION_1_3 {
        missing.push("Vulkan 1.3".to_string());
    }
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f13);
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    let core = f2.features;
    if f13.dynamic_rendering == vk::FALSE {
        missing.push("dynamicRendering".into());
    }
    if f13.synchronization2 == vk::FALSE {
        missing.push("synchronization2".into());
    }
    if core.depth_clamp == vk::FALSE {
        missing.push("depthClamp".into());
    }
    let qf = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    let family = qf
        .iter()
        .position(|q| q.queue_flags.contains(vk::QueueFlags::GRAPHICS));
    if family.is_none() {
        missing.push("a graphics queue".into());
    }
    let d32 = unsafe { instance.get_physical_device_format_properties(pd, vk::Format::D32_SFLOAT) }
        .optimal_tiling_features;
    if !d32.contains(
        vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::SAMPLED_IMAGE,
    ) {
        missing.push("D32_SFLOAT depth attachment + sampling".into());
    }
    if swapchain {
        let exts =
            unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default();
        if !exts.iter().any(|e| {
            e.extension_name_as_c_str()
                .is_ok_and(|n| n == ash::khr::swapchain::NAME)
        }) {
            missing.push("VK_KHR_swapchain".into());
        }
    }
    (missing, family, core.sampler_anisotropy == vk::TRUE)
}

/// The device to use: the one `desc.device` (or `UMBRA_DEVICE`) names, else the best scored (a
/// discrete GPU first) of those with what umbra needs; with its graphics queue family and whether
/// it has anisotropy. The error says why each device was passed over.
pub(super) fn pick_device(
    instance: &ash::Instance,
    desc: &ContextDesc,
) -> Result<(vk::PhysicalDevice, u32, bool), GpuError> {
    let devices =
        unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    if devices.is_empty() {
        return Err(GpuError::NoDevice(
            "the Vulkan loader found no device; install a driver (apt-get install mesa-vulkan-drivers for lavapipe)".into(),
        ));
    }
    let wanted = desc
        .device
        .clone()
        .or_else(|| std::env::var("UMBRA_DEVICE").ok().filter(|s| !s.is_empty()));
    let mut reasons = Vec::new();
    let mut best: Option<(u32, vk::PhysicalDevice, u32, bool)> = None;
    for pd in devices {
        let props = unsafe { instance.get_physical_device_properties(pd) };
        let name = props
            .device_name_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if let Some(w) = &wanted {
            if !name.to_lowercase().contains(&w.to_lowercase()) {
                reasons.push(format!("{name}: not matching '{w}'"));
                continue;
            }
        }
        let (missing, family, anisotropy) = requirements(instance, pd, &props, desc.swapchain);
        if !missing.is_empty() {
            reasons.push(format!("{name}: missing {}", missing.join(", ")));
            continue;
        }
        let s = score(props.device_type);
        if best.as_ref().is_none_or(|b| s > b.0) {
            best = Some((s, pd, family.unwrap_or(0) as u32, anisotropy));
        }
    }
    best.map(|(_, pd, f, a)| (pd, f, a))
        .ok_or_else(|| GpuError::NoDevice(reasons.join("; ")))
}
