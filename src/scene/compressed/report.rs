//! What the loader decoded: per extension, the buffer views, meshes or textures it covered, the
//! bytes stored against the bytes decoded and the time taken; the quantized attributes and the
//! node transforms that dequantize them. `inspect` prints it (`compression` in its JSON).

use serde_json::{json, Value};
use std::collections::BTreeMap;

/// One extension's share of the decoding.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExtensionUse {
    /// JSON pointers of what it covered (`/bufferViews/3`, `/meshes/0/primitives/1`).
    pub covers: Vec<String>,
    /// Compressed bytes read.
    pub bytes_stored: u64,
    /// Bytes they decoded to.
    pub bytes_decoded: u64,
    /// Wall time spent decoding, in seconds.
    pub seconds: f64,
}

/// What the loader decoded from a file (empty for a plain one).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CompressionReport {
    /// By extension name.
    pub extensions: BTreeMap<String, ExtensionUse>,
    /// Quantized attribute accessors: `{accessor, semantic, stored}` (`stored`: `i16_norm x3`).
    pub quantized: Vec<Value>,
    /// Nodes placing meshes with quantized positions, with their transforms.
    pub transforms: Vec<Value>,
}

impl CompressionReport {
    /// Records that `ext` covered `/{what}/{index}`, from `stored` bytes to `decoded`.
    pub(super) fn add(
        &mut self,
        ext: &str,
        what: &str,
        index: usize,
        stored: usize,
        decoded: usize,
    ) {
        let e = self.extensions.entry(ext.to_string()).or_default();
        e.covers.push(format!("/{what}/{index}"));
        e.bytes_stored += stored as u64;
        e.bytes_decoded += decoded as u64;
    }

    /// Records image `index` decoded from `stored` bytes to `pixels` bytes in `seconds`, under
    /// KHR_texture_basisu when it is KTX2 and EXT_texture_webp when it is WebP (other formats
    /// are not this report's).
    pub(in crate::scene) fn add_image(
        &mut self,
        index: usize,
        stored: &[u8],
        pixels: usize,
        seconds: f64,
    ) {
        let ext = if super::is_ktx2(stored) {
            "KHR_texture_basisu"
        } else if stored.len() >= 12 && &stored[0..4] == b"RIFF" && &stored[8..12] == b"WEBP" {
            "EXT_texture_webp"
        } else {
            return;
        };
        self.add(ext, "images", index, stored.len(), pixels);
        self.add_seconds(ext, seconds);
    }

    /// Adds decoding time to `ext`.
    pub(super) fn add_seconds(&mut self, ext: &str, seconds: f64) {
        self.extensions.entry(ext.to_string()).or_default().seconds += seconds;
    }

    /// Records a quantized accessor (as stored, before it was widened).
    pub(super) fn quantized(&mut self, index: usize, semantic: &str, accessor: &Value) {
        let ct = match accessor["componentType"].as_u64().unwrap_or(0) {
            5120 => "i8",
            5121 => "u8",
            5122 => "i16",
            5123 => "u16",
            5125 => "u32",
            _ => "?",
        };
        let norm = if accessor["normalized"].as_bool() == Some(true) {
            "_norm"
        } else {
            ""
        };
        let n = accessor["type"]
            .as_str()
            .unwrap_or("")
            .trim_start_matches("VEC");
        let stored = format!("{ct}{norm} x{n}");
        let e = self
            .extensions
            .entry("KHR_mesh_quantization".into())
            .or_default();
        e.covers.push(format!("/accessors/{index}"));
        let count = accessor["count"].as_u64().unwrap_or(0);
        let n: u64 = n.parse().unwrap_or(1);
        let size = match ct {
            "i8" | "u8" => 1,
            "i16" | "u16" => 2,
            _ => 4,
        };
        e.bytes_stored += count * n * size;
        e.bytes_decoded += count * n * 4;
        self.quantized.push(json!({
            "accessor": format!("/accessors/{index}"),
            "semantic": semantic,
            "stored": stored,
        }));
    }

    /// How far from unit length a unit vector stored in quantized accessor `index` may be by
    /// rounding alone (half a step on each of three components; 0 for an accessor not quantized).
    pub fn unit_slack(&self, index: usize) -> f32 {
        let at = format!("/accessors/{index}");
        let stored = self
            .quantized
            .iter()
            .find(|q| q["accessor"] == at.as_str())
            .and_then(|q| q["stored"].as_str());
        let step = match stored.map(|s| s.split(['_', ' ']).next().unwrap_or("")) {
            Some("i8") => 1.0 / 127.0,
            Some("u8") => 1.0 / 255.0,
            Some("i16") => 1.0 / 32767.0,
            Some("u16") => 1.0 / 65535.0,
            _ => 0.0,
        };
        0.5 * step * 3f32.sqrt()
    }

    /// Whether nothing was decoded.
    pub fn is_empty(&self) -> bool {
        self.extensions.is_empty()
    }

    /// The report as `inspect`'s `compression` object.
    pub fn to_json(&self) -> Value {
        let extensions: serde_json::Map<String, Value> = self
            .extensions
            .iter()
            .map(|(k, e)| {
                (
                    k.clone(),
                    json!({
                        "covers": e.covers,
                        "bytes_stored": e.bytes_stored,
                        "bytes_decoded": e.bytes_decoded,
                        "decode_ms": (e.seconds * 1e6).round() / 1e3,
                    }),
                )
            })
            .collect();
        json!({
            "extensions": extensions,
            "quantized_attributes": self.quantized,
            "dequantizing_transforms": self.transforms,
        })
    }
}
