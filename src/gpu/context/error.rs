//! Errors from the GPU layer.

use ash::vk;

/// Errors from the GPU layer.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// The Vulkan loader library could not be opened.
    #[error(
        "no Vulkan loader found ({0}); install one: apt-get install libvulkan1 mesa-vulkan-drivers"
    )]
    NoLoader(String),
    /// No physical device qualifies.
    #[error("no suitable Vulkan device: {0}")]
    NoDevice(String),
    /// Validation was required but the Khronos layer is not installed.
    #[error("the Khronos validation layer (VK_LAYER_KHRONOS_validation) is not installed: apt-get install vulkan-validationlayers")]
    NoValidationLayer,
    /// A Vulkan call failed.
    #[error("Vulkan call {call} failed: {result:?}")]
    Vk {
        /// What was called.
        call: &'static str,
        /// The result code.
        result: vk::Result,
    },
    /// Memory allocation failed.
    #[error("GPU memory allocation failed for {name}: {message}")]
    Alloc {
        /// Allocation name.
        name: String,
        /// Allocator message.
        message: String,
    },
    /// A request outside what the device supports.
    #[error("{0}")]
    Unsupported(String),
}

/// Maps a `vk::Result` error to [`GpuError::Vk`] with the call's name.
pub trait VkCheck<T> {
    /// Attaches the call's name.
    fn vk(self, call: &'static str) -> Result<T, GpuError>;
}

impl<T> VkCheck<T> for Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> Result<T, GpuError> {
        self.map_err(|result| GpuError::Vk { call, result })
    }
}
