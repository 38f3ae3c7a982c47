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
    /// Quantized attribute accessors: `{accessor, semantic, stored}` (`stored`: `i16_normx3`).
    pub quantized: Vec<Value>,
    /// Nodes placing meshes with quantized positions, with their transforms.
    pub transforms: Vec<Value>,
    /// Each quantized integer accessor's step (one over its normalising divisor): the rounding
    /// a unit vector stored in it carries.
    steps: BTreeMap<usize, f32>,
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
        let ext = if super::sniff::is_ktx2(stored) {
            "KHR_texture_basisu"
        } else if super::sniff::is_webp(stored) {
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
        let ct = accessor["componentType"].as_u64().unwrap_or(0);
        let size = super::accessor::component_size(ct).unwrap_or(4) as u64;
        let n = super::accessor::components(accessor["type"].as_str().unwrap_or("")).unwrap_or(1);
        let count = accessor["count"].as_u64().unwrap_or(0);
        let e = self
            .extensions
            .entry("KHR_mesh_quantization".into())
            .or_default();
        e.covers.push(format!("/accessors/{index}"));
        e.bytes_stored += count * n as u64 * size;
        e.bytes_decoded += count * n as u64 * 4;
        if let Some(d) = super::accessor::norm_divisor(ct) {
            self.steps.insert(index, 1.0 / d);
        }
        self.quantized.push(json!({
            "accessor": format!("/accessors/{index}"),
            "semantic": semantic,
            "stored": super::accessor::accessor_type(accessor),
        }));
    }

    /// How far from unit length a unit vector stored in quantized accessor `index` may be by
    /// rounding alone (half a step on each of three components; 0 for an accessor not quantized).
    pub fn unit_slack(&self, index: usize) -> f32 {
        0.5 * self.steps.get(&index).copied().unwrap_or(0.0) * 3f32.sqrt()
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
