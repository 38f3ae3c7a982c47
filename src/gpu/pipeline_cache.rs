//! A Vulkan pipeline cache, optionally kept on disk between processes so that a second run does
//! not compile its pipelines again. The library writes nothing unless `ContextDesc::pipeline_cache`
//! names a file; the `umbra` binary names one under the user's cache directory.

use ash::vk;
use std::path::{Path, PathBuf};

/// Size of the Vulkan pipeline cache header (version one).
const HEADER_LEN: usize = 32;

/// True when `data` starts with a version-one header written by this device (vendor, device and
/// pipeline cache UUID): data from another device or driver is not handed to the driver.
pub fn header_matches(data: &[u8], props: &vk::PhysicalDeviceProperties) -> bool {
    if data.len() < HEADER_LEN {
        return false;
    }
    let word = |i: usize| u32::from_le_bytes([data[i], data[i + 1], data[i + 2], data[i + 3]]);
    word(0) as usize >= HEADER_LEN
        && word(4) == vk::PipelineCacheHeaderVersion::ONE.as_raw() as u32
        && word(8) == props.vendor_id
        && word(12) == props.device_id
        && data[16..32] == props.pipeline_cache_uuid
}

/// The initial data for a cache at `path`: its contents when they belong to this device, else
/// nothing (missing, unreadable or foreign files are ignored; the cache starts empty).
pub fn load(path: &Path, props: &vk::PhysicalDeviceProperties) -> Vec<u8> {
    match std::fs::read(path) {
        Ok(data) if header_matches(&data, props) => data,
        Ok(_) => {
            log::info!(
                "pipeline cache {} is from another device; starting empty",
                path.display()
            );
            Vec::new()
        }
        Err(_) => Vec::new(),
    }
}

/// Writes `data` to `path` atomically (a temporary file renamed over it), creating the folder.
pub fn store(path: &Path, data: &[u8]) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&tmp, data)?;
    std::fs::rename(&tmp, path)
}

/// The default cache file: `$XDG_CACHE_HOME/umbra/pipelines.bin`, else
/// `$HOME/.cache/umbra/pipelines.bin`; None when neither is set.
pub fn default_path() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .filter(|v| !v.is_empty())
                .map(|h| PathBuf::from(h).join(".cache"))
        })?;
    Some(base.join("umbra").join("pipelines.bin"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn props() -> vk::PhysicalDeviceProperties {
        vk::PhysicalDeviceProperties {
            vendor_id: 0x10005,
            device_id: 7,
            pipeline_cache_uuid: [3; 16],
            ..Default::default()
        }
    }

    fn header(p: &vk::PhysicalDeviceProperties) -> Vec<u8> {
        let mut h = Vec::new();
        h.extend(32u32.to_le_bytes());
        h.extend(1u32.to_le_bytes());
        h.extend(p.vendor_id.to_le_bytes());
        h.extend(p.device_id.to_le_bytes());
        h.extend(p.pipeline_cache_uuid);
        h
    }

    #[test]
    fn only_this_devices_data_is_loaded() {
        let p = props();
        let mut data = header(&p);
        data.extend([9u8; 100]);
        assert!(header_matches(&data, &p));
        let mut other = p;
        other.pipeline_cache_uuid[15] = 4;
        assert!(!header_matches(&data, &other), "another driver build");
        other = p;
        other.device_id = 8;
        assert!(!header_matches(&data, &other), "another device");
        assert!(!header_matches(&data[..31], &p), "truncated");
        let dir = std::env::temp_dir().join(format!("umbra-pc-{}", std::process::id()));
        let path = dir.join("sub").join("pipelines.bin");
        assert!(load(&path, &p).is_empty(), "missing file");
        store(&path, &data).unwrap();
        assert_eq!(load(&path, &p), data);
        store(&path, b"garbage").unwrap();
        assert!(load(&path, &p).is_empty(), "foreign contents");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
