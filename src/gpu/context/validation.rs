//! The Khronos validation layer: whether to enable it, and the messages it sent.

use ash::vk;
use std::ffi::{c_void, CStr};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Whether to enable the Khronos validation layer (with synchronization validation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Validation {
    /// Never.
    Off,
    /// When the layer is installed.
    IfAvailable,
    /// Always; creating the context fails without the layer.
    Required,
}

impl Validation {
    /// `Required` when `on`, else `Off` (a command line's `--validation`).
    pub fn required_if(on: bool) -> Self {
        if on {
            Validation::Required
        } else {
            Validation::Off
        }
    }
}

/// Validation messages received, counted by severity.
#[derive(Default, Debug)]
pub struct ValidationLog {
    warnings: AtomicUsize,
    errors: AtomicUsize,
    messages: Mutex<Vec<String>>,
}

impl ValidationLog {
    /// Number of warning-or-error messages so far.
    pub fn problem_count(&self) -> usize {
        self.warnings.load(Ordering::SeqCst) + self.errors.load(Ordering::SeqCst)
    }

    /// The warning and error messages so far.
    pub fn messages(&self) -> Vec<String> {
        self.messages.lock().map(|m| m.clone()).unwrap_or_default()
    }
}

pub(super) unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    let msg = if data.is_null() || (*data).p_message.is_null() {
        String::from("(no message)")
    } else {
        CStr::from_ptr((*data).p_message)
            .to_string_lossy()
            .into_owned()
    };
    let log = user as *const ValidationLog;
    let problem = severity.intersects(
        vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
            | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
    );
    // Loader chatter (GENERAL only) goes to debug: the error it leads to is reported on its own.
    let general_only = kind == vk::DebugUtilsMessageTypeFlagsEXT::GENERAL;
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        if general_only {
            log::debug!("vulkan {kind:?}: {msg}");
        } else {
            log::error!("vulkan {kind:?}: {msg}");
        }
        if !log.is_null() {
            (*log).errors.fetch_add(1, Ordering::SeqCst);
        }
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        if general_only {
            log::debug!("vulkan {kind:?}: {msg}");
        } else {
            log::warn!("vulkan {kind:?}: {msg}");
        }
        if !log.is_null() {
            (*log).warnings.fetch_add(1, Ordering::SeqCst);
        }
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::INFO) {
        log::debug!("vulkan {kind:?}: {msg}");
    } else {
        log::trace!("vulkan {kind:?}: {msg}");
    }
    if problem && !log.is_null() {
        if let Ok(mut m) = (*log).messages.lock() {
            m.push(msg);
        }
    }
    vk::FALSE
}
