//! glibc's allocator and llvmpipe. A CPU Vulkan driver allocates its per-frame working memory
//! (vertex outputs, binned triangles) on its own threads, in glibc arenas that hand memory back
//! to the kernel as soon as more than `M_TRIM_THRESHOLD` of it lies free at an arena's top
//! (`madvise(MADV_DONTNEED)`, the threshold adjusted from 128 KiB by the sizes seen so far). On
//! FlightHelmet that is 13.5 MB returned and page-faulted back in every frame: about a third of a
//! 128×72 frame's CPU time in the kernel. Raising the threshold keeps that memory mapped between
//! frames.

/// The free memory an arena keeps at its top before returning it to the kernel.
const TRIM_THRESHOLD: i32 = 64 << 20;
/// Allocations from this size up get their own mapping (glibc's largest dynamic threshold on
/// 64-bit targets; fixing the trim threshold stops the dynamic adjustment, so it is set too).
const MMAP_THRESHOLD: i32 = 32 << 20;

/// Raises glibc's trim threshold to 64 MiB and fixes its mmap threshold at 32 MiB, process-wide,
/// once. Returns whether the thresholds are now set (false off glibc or where `mallopt` refused).
pub(crate) fn keep_freed_memory() -> bool {
    static DONE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *DONE.get_or_init(set_thresholds)
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn set_thresholds() -> bool {
    // SAFETY: mallopt only sets the allocator's parameters; glibc serialises it with allocation.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1
            && libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn set_thresholds() -> bool {
    let _ = (TRIM_THRESHOLD, MMAP_THRESHOLD);
    false
}
