//! `KHR_texture_basisu` (KTX2 with Basis Universal ETC1S or UASTC payloads, Zstd-supercompressed
//! or not) and `EXT_texture_webp`: a texture's `source` becomes the extension's image when this
//! build decodes it (else the texture keeps its fallback `source`, or, with none, the extension's
//! image, which then fails to decode with a warning and the material slot falls back). KTX2 is
//! transcoded by the `basisu` crate, a pure-Rust port of the reference transcoder, to RGBA8;
//! WebP is decoded by the `image` crate.

use super::report::CompressionReport;
use serde_json::{json, Value};

/// Points each texture with an image extension this build decodes at that image.
pub(super) fn use_extension_sources(json: &mut Value, report: &mut CompressionReport) {
    let decodes = [
        ("KHR_texture_basisu", cfg!(feature = "ktx2")),
        ("EXT_texture_webp", cfg!(feature = "webp")),
    ];
    let Some(textures) = json.get_mut("textures").and_then(|t| t.as_array_mut()) else {
        return;
    };
    for (i, t) in textures.iter_mut().enumerate() {
        for (ext, built) in decodes {
            let Some(src) = t["extensions"][ext]["source"].as_u64() else {
                continue;
            };
            if built || t.get("source").is_none() {
                t["source"] = json!(src);
                report.add(ext, "textures", i, 0, 0);
            }
        }
    }
}

/// Checks a KTX2 file's index against its length before a transcoder reads it: the header, the
/// level index, and every range it names (levels, data format descriptor, key/value data,
/// supercompression global data) inside the file; at most 32 levels.
fn check_ktx2_layout(data: &[u8]) -> Result<(), String> {
    let rd32 = |at: usize| {
        data.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64)
    };
    let rd64 = |at: usize| {
        data.get(at..at + 8)
            .map(|b| u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
    };
    let short = || "KTX2: the file is shorter than its header".to_string();
    let levels = rd32(40).ok_or_else(short)?.max(1);
    if levels > 32 {
        return Err(format!("KTX2: {levels} levels"));
    }
    let within = |what: &str, off: u64, len: u64| {
        if off.checked_add(len).is_some_and(|e| e <= data.len() as u64) {
            Ok(())
        } else {
            Err(format!(
                "KTX2: the {what} ({len} bytes at {off}) overruns the file ({} bytes)",
                data.len()
            ))
        }
    };
    let (w, h) = (rd32(20).ok_or_else(short)?, rd32(24).ok_or_else(short)?);
    let max = crate::scene::gltf::MAX_TEXTURE_SIDE as u64;
    let depth = rd32(28).ok_or_else(short)?;
    let (layers, faces) = (rd32(32).ok_or_else(short)?, rd32(36).ok_or_else(short)?);
    // KHR_texture_basisu: a 2D image (no depth, no array layers, one face).
    if w == 0 || h == 0 || w > max || h > max || depth > 1 || layers > 1 || faces != 1 {
        return Err(format!(
            "KTX2: {w}x{h}, depth {depth}, {layers} layers, {faces} faces: not a 2D image of at \
             most {max} a side"
        ));
    }
    within("level index", 80, levels * 24)?;
    for l in 0..levels as usize {
        let at = 80 + l * 24;
        within(
            &format!("level {l}"),
            rd64(at).ok_or_else(short)?,
            rd64(at + 8).ok_or_else(short)?,
        )?;
        // What a supercompressed level inflates to: at most 16 bytes a 4×4 block (UASTC's).
        let blocks = (w >> l).max(1).div_ceil(4) * (h >> l).max(1).div_ceil(4);
        let inflated = rd64(at + 16).ok_or_else(short)?;
        if inflated > blocks * 16 {
            return Err(format!(
                "KTX2: level {l} inflates to {inflated} bytes, over {}",
                blocks * 16
            ));
        }
    }
    within(
        "data format descriptor",
        rd32(48).ok_or_else(short)?,
        rd32(52).ok_or_else(short)?,
    )?;
    within(
        "key/value data",
        rd32(56).ok_or_else(short)?,
        rd32(60).ok_or_else(short)?,
    )?;
    within(
        "global data",
        rd64(64).ok_or_else(short)?,
        rd64(72).ok_or_else(short)?,
    )
}

/// Transcodes a KTX2 Basis Universal image's first level to RGBA8 (width, height, pixels).
#[cfg(feature = "ktx2")]
pub(in crate::scene) fn decode_ktx2(data: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    check_ktx2_layout(data)?;
    // The layout check keeps the transcoder in bounds; a panic left in it is still this image's
    // warning, not the file's failure.
    super::contained("KTX2: the image does not transcode", || transcode(data))
}

#[cfg(feature = "ktx2")]
fn transcode(data: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    use basisu::{DecodeFlags, TargetFormat, Transcoder};
    let t = Transcoder::new(data).map_err(|e| format!("KTX2: {e:?}"))?;
    let info = t.image_level_info(0).map_err(|e| format!("KTX2: {e:?}"))?;
    let max = crate::scene::gltf::MAX_TEXTURE_SIDE;
    if info.width == 0 || info.height == 0 || info.width > max || info.height > max {
        return Err(format!(
            "KTX2: size {}x{} outside 1..={max}",
            info.width, info.height
        ));
    }
    let rgba = t
        .transcode(0, TargetFormat::Rgba32, DecodeFlags::NONE)
        .map_err(|e| format!("KTX2: {e:?}"))?;
    let need = info.width as usize * info.height as usize * 4;
    if rgba.len() < need {
        return Err(format!(
            "KTX2: transcoded {} bytes, expected {need}",
            rgba.len()
        ));
    }
    Ok((info.width, info.height, rgba[..need].to_vec()))
}

/// What a KTX2 image's levels are transcoded to for the device.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Ktx2Target {
    /// 4 bytes a texel, row by row.
    Rgba8,
    /// BC7: 16 bytes a 4×4 block, blocks row by row (a level under 4 texels a side is one
    /// block row or column, padded).
    Bc7,
}

impl Ktx2Target {
    /// Bytes of a `w`×`h` level.
    pub fn level_bytes(self, w: u32, h: u32) -> usize {
        match self {
            Ktx2Target::Rgba8 => w as usize * h as usize * 4,
            Ktx2Target::Bc7 => w.div_ceil(4) as usize * h.div_ceil(4) as usize * 16,
        }
    }
}

/// Every level of a KTX2 Basis Universal image, the file's own mip chain, transcoded to
/// `target`. Level l must be max(1, w >> l) × max(1, h >> l) and the chain no longer than a full
/// one; anything else is an error (the caller then makes its own chain from level 0).
pub fn ktx2_levels(data: &[u8], target: Ktx2Target) -> Result<crate::math::mips::MipChain, String> {
    check_ktx2_layout(data)?;
    #[cfg(feature = "ktx2")]
    {
        super::contained("KTX2: the levels do not transcode", || {
            transcode_levels(data, target)
        })
    }
    #[cfg(not(feature = "ktx2"))]
    {
        let _ = target;
        Err("KTX2 needs umbra's cargo feature `ktx2`, not in this build".into())
    }
}

#[cfg(feature = "ktx2")]
fn transcode_levels(
    data: &[u8],
    target: Ktx2Target,
) -> Result<crate::math::mips::MipChain, String> {
    use basisu::{DecodeFlags, TargetFormat, Transcoder};
    let t = Transcoder::new(data).map_err(|e| format!("KTX2: {e:?}"))?;
    let (w0, h0) = t.base_dimensions();
    let count = t.level_count().max(1);
    if count > crate::math::mip_levels(w0, h0) {
        return Err(format!("KTX2: {count} levels for {w0}x{h0}"));
    }
    let format = match target {
        Ktx2Target::Rgba8 => TargetFormat::Rgba32,
        Ktx2Target::Bc7 => TargetFormat::Bc7Rgba,
    };
    let mut chain = crate::math::mips::MipChain {
        levels: Vec::with_capacity(count as usize),
        bytes: Vec::new(),
    };
    for level in 0..count {
        let info = t
            .image_level_info(level)
            .map_err(|e| format!("KTX2: {e:?}"))?;
        let (w, h) = ((w0 >> level).max(1), (h0 >> level).max(1));
        if (info.width, info.height) != (w, h) {
            return Err(format!(
                "KTX2: level {level} is {}x{}, not {w}x{h}",
                info.width, info.height
            ));
        }
        let out = t
            .transcode(level, format, DecodeFlags::NONE)
            .map_err(|e| format!("KTX2: level {level}: {e:?}"))?;
        let need = target.level_bytes(w, h);
        if out.len() < need {
            return Err(format!(
                "KTX2: level {level} transcoded to {} bytes, expected {need}",
                out.len()
            ));
        }
        chain.levels.push((w, h, chain.bytes.len()));
        chain.bytes.extend_from_slice(&out[..need]);
    }
    Ok(chain)
}

/// Without the `ktx2` feature a KTX2 image is not decoded (a warning; the slot falls back).
#[cfg(not(feature = "ktx2"))]
pub(in crate::scene) fn decode_ktx2(data: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    check_ktx2_layout(data)?;
    Err("KTX2 needs umbra's cargo feature `ktx2`, not in this build".into())
}
