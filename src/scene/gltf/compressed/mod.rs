//! The one place where the glTF the world ships becomes the glTF the rest of the loader reads.
//!
//! Optimisers (gltfpack, gltf-pipeline, the Basis Universal encoder) write files that require
//! extensions the `gltf` crate does not know, and it refuses any file whose `extensionsRequired`
//! names one. So before the crate sees a file, [`prepare`] rewrites its JSON into plain glTF 2.0:
//!
//! - `EXT_meshopt_compression` / `KHR_meshopt_compression`: each compressed buffer view is decoded
//!   (meshoptimizer's decoders and filters, on all cores) into a buffer appended to the file's,
//!   and the view is pointed at it; fallback buffers are never read.
//! - `KHR_draco_mesh_compression`: each compressed primitive is decoded and its accessors are
//!   pointed at the decoded data (with the `draco` feature).
//! - `KHR_mesh_quantization`: integer positions, normals, tangents, texture coordinates and morph
//!   displacements become `f32` accessors holding the same values (normalised ones divided as
//!   glTF says); the node transforms that dequantize them are left as they are, so bounds,
//!   culling, shadow fitting, skinning, the CPU reference and picking all see the same floats.
//! - `KHR_texture_basisu` / `EXT_texture_webp`: a texture's `source` becomes the extension's
//!   image, decoded later with the other images (with the `ktx2` / `webp` features).
//!
//! The rewritten JSON is then parsed and validated by the `gltf` crate as any other file. What was
//! decoded, from how many bytes, in how long, is kept in a [`CompressionReport`] for `inspect`.

mod accessor;
#[cfg(feature = "draco")]
mod draco;
mod meshopt;
mod quantized;
mod report;
mod sniff;
mod textures;

pub use accessor::accessor_type;
pub use report::{CompressionReport, ExtensionUse};
pub(super) use sniff::is_ktx2;
pub(super) use textures::decode_ktx2;
pub use textures::{ktx2_levels, Ktx2Target};

use super::error::{corrupt, invalid, LoadError};
use super::input::read_uri;
use serde_json::{json, Value};
use std::path::Path;

/// Extensions the gltf crate reads itself (its features are on).
const KNOWN_TO_GLTF: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "KHR_lights_punctual",
    "KHR_texture_transform",
];

/// Extensions decoded here in every build.
const DECODED: &[&str] = &[
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
];

/// Extensions whose decoder is a cargo feature of this crate, with the feature's name.
const BY_FEATURE: &[(&str, &str, bool)] = &[
    (
        "KHR_draco_mesh_compression",
        "draco",
        cfg!(feature = "draco"),
    ),
    ("KHR_texture_basisu", "ktx2", cfg!(feature = "ktx2")),
    ("EXT_texture_webp", "webp", cfg!(feature = "webp")),
];

/// Every extension umbra reads, for `inspect` (those of a feature this build lacks excluded).
pub fn supported_extensions() -> Vec<&'static str> {
    let mut v: Vec<&str> = [KNOWN_TO_GLTF, DECODED].concat();
    v.extend(BY_FEATURE.iter().filter(|f| f.2).map(|f| f.0));
    v
}

thread_local! {
    static IN_DECODER: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether this thread is inside a third-party decoder (Draco, Basis Universal) right now: a panic
/// hook can tell a decoder's own failure on a broken stream (caught, and the file's or image's
/// one-line error) from umbra's.
pub fn in_third_party_decoder() -> bool {
    IN_DECODER.with(|c| c.get())
}

/// Runs a third-party decoder on untrusted bytes: a panic in it becomes `Err(what)`.
#[cfg_attr(not(any(feature = "draco", feature = "ktx2")), allow(dead_code))]
pub(super) fn contained<T>(what: &str, f: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    IN_DECODER.with(|c| c.set(true));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    IN_DECODER.with(|c| c.set(false));
    r.unwrap_or_else(|_| Err(format!("{what} (the decoder failed on it)")))
}

/// Largest decoded size of one compressed buffer view or Draco attribute, in bytes: the sizes
/// come from the file and are not bounded by its data.
pub(super) const MAX_DECODED_BYTES: usize = 1 << 30;

/// A file made plain: its JSON (decoded views and dense `f32` accessors in place of compressed and
/// quantized ones) and its buffers' bytes, one per JSON buffer (fallback buffers empty).
pub(super) struct Prepared {
    pub json: Value,
    pub buffers: Vec<Vec<u8>>,
    pub report: CompressionReport,
}

/// What each decoding step works on: the file being rewritten (its JSON), its buffers' bytes, the
/// decoded bytes appended so far and the report.
pub(super) struct Rewrite<'a> {
    pub path: &'a Path,
    pub json: Value,
    pub buffers: &'a [Vec<u8>],
    pub out: Appended,
    pub report: CompressionReport,
}

/// Decoded bytes appended to the file as one more buffer; `add` returns a new buffer view.
pub(super) struct Appended {
    /// Index the appended buffer will have.
    pub buffer: usize,
    pub bytes: Vec<u8>,
    /// Buffer views to add to the JSON (their indices follow the file's own).
    pub views: Vec<Value>,
    pub first_view: usize,
}

impl Appended {
    /// Appends `data` (4-byte aligned) and returns a buffer view of it, with a stride if given.
    pub fn place(&mut self, data: &[u8], stride: Option<u64>) -> Value {
        while self.bytes.len() % 4 != 0 {
            self.bytes.push(0);
        }
        let mut view = json!({
            "buffer": self.buffer,
            "byteOffset": self.bytes.len(),
            "byteLength": data.len().max(1),
        });
        if let Some(s) = stride {
            view["byteStride"] = json!(s);
        }
        self.bytes.extend_from_slice(data);
        if data.is_empty() {
            self.bytes.push(0);
        }
        view
    }

    /// Appends `data` as a new buffer view (tightly packed); the view's index.
    pub fn add(&mut self, data: &[u8]) -> usize {
        let view = self.place(data, None);
        self.views.push(view);
        self.first_view + self.views.len() - 1
    }
}

/// Splits `bytes` into the JSON document and the GLB binary chunk (if any).
fn split(path: &Path, bytes: &[u8]) -> Result<(Value, Option<Vec<u8>>), LoadError> {
    let json_bytes = super::input::json_part(path, bytes)?;
    let text = String::from_utf8_lossy(json_bytes);
    let json: Value = serde_json::from_str(&text).map_err(|e| invalid(path, e))?;
    let blob = if bytes.starts_with(b"glTF") {
        gltf::Glb::from_slice(bytes)
            .map_err(|e| invalid(path, e))?
            .bin
            .map(|b| b.into_owned())
    } else {
        None
    };
    Ok((json, blob))
}

/// Refuses a file that requires an extension umbra cannot read: one line naming it, and the
/// cargo feature that would read it where one exists.
fn check_required(path: &Path, json: &Value) -> Result<(), LoadError> {
    check_required_with(path, json, BY_FEATURE)
}

/// `check_required` against a table of decoders by feature (`(extension, feature, built)`).
fn check_required_with(
    path: &Path,
    json: &Value,
    by_feature: &[(&str, &str, bool)],
) -> Result<(), LoadError> {
    let required = json["extensionsRequired"].as_array().cloned();
    for ext in required.unwrap_or_default() {
        let name = ext.as_str().unwrap_or("");
        if KNOWN_TO_GLTF.contains(&name) || DECODED.contains(&name) {
            continue;
        }
        match by_feature.iter().find(|f| f.0 == name) {
            Some((_, _, true)) => {}
            Some((_, feature, false)) => {
                return Err(LoadError::UnsupportedExtension {
                    path: path.into(),
                    extension: format!(
                    "{name} (its decoder is umbra's cargo feature `{feature}`, not in this build)"
                ),
                })
            }
            None => {
                return Err(LoadError::UnsupportedExtension {
                    path: path.into(),
                    extension: name.to_string(),
                })
            }
        }
    }
    Ok(())
}

/// Whether buffer `b` is a meshopt fallback buffer (its data is never needed).
fn is_fallback(b: &Value) -> bool {
    ["EXT_meshopt_compression", "KHR_meshopt_compression"]
        .iter()
        .any(|e| b["extensions"][e]["fallback"].as_bool() == Some(true))
}

/// Reads every buffer: the GLB chunk or a URI inside the model's folder; fallback buffers empty.
fn read_buffers(
    path: &Path,
    json: &Value,
    blob: Option<Vec<u8>>,
    base: &Path,
) -> Result<Vec<Vec<u8>>, LoadError> {
    let mut blob = blob;
    let list = json["buffers"].as_array().cloned().unwrap_or_default();
    let mut out = Vec::with_capacity(list.len());
    for (i, b) in list.iter().enumerate() {
        let length = b["byteLength"].as_u64().unwrap_or(0) as usize;
        if is_fallback(b) {
            out.push(Vec::new());
            continue;
        }
        let data = match b["uri"].as_str() {
            Some(uri) => read_uri(path, base, uri, &format!("buffer {i}"))?,
            None => blob.take().ok_or_else(|| {
                corrupt(
                    path,
                    format!("buffer {i} refers to a GLB binary chunk that is missing"),
                )
            })?,
        };
        if data.len() < length {
            return Err(corrupt(
                path,
                format!(
                    "buffer {i} holds {} bytes but declares {length}",
                    data.len()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// Makes the file at `path` (its `bytes`, resources under `base`) plain glTF: see the module.
pub(super) fn prepare(path: &Path, bytes: &[u8], base: &Path) -> Result<Prepared, LoadError> {
    let (json, blob) = split(path, bytes)?;
    check_required(path, &json)?;
    let buffers = read_buffers(path, &json, blob, base)?;
    let out = Appended {
        buffer: buffers.len(),
        bytes: Vec::new(),
        views: Vec::new(),
        first_view: json["bufferViews"].as_array().map_or(0, |v| v.len()),
    };
    let mut r = Rewrite {
        path,
        json,
        buffers: &buffers,
        out,
        report: CompressionReport::default(),
    };
    meshopt::decode_views(&mut r)?;
    #[cfg(feature = "draco")]
    draco::decode_primitives(&mut r)?;
    #[cfg(not(feature = "draco"))]
    strip_draco(&mut r.json);
    check_fallback_unused(path, &r.json)?;
    quantized::dequantize(&mut r)?;
    textures::use_extension_sources(&mut r.json, &mut r.report);
    let Rewrite {
        mut json,
        out,
        report,
        ..
    } = r;
    strip_required(&mut json);
    let mut buffers = buffers;
    if !out.views.is_empty() {
        let list = json.get_mut("bufferViews").and_then(|l| l.as_array_mut());
        match list {
            Some(l) => l.extend(out.views),
            None => json["bufferViews"] = Value::Array(out.views),
        }
        let entry = json!({"byteLength": out.bytes.len()});
        match json.get_mut("buffers").and_then(|l| l.as_array_mut()) {
            Some(l) => l.push(entry),
            None => json["buffers"] = json!([entry]),
        }
        buffers.push(out.bytes);
    }
    Ok(Prepared {
        json,
        buffers,
        report,
    })
}

/// Without a Draco decoder, a primitive that also has plain accessors is read from them (glTF's
/// fallback); its extension object is dropped so nothing points at the compressed view.
#[cfg(not(feature = "draco"))]
fn strip_draco(json: &mut Value) {
    for mesh in json
        .get_mut("meshes")
        .and_then(|m| m.as_array_mut())
        .into_iter()
        .flatten()
    {
        let prims = mesh.get_mut("primitives").and_then(|p| p.as_array_mut());
        for prim in prims.into_iter().flatten() {
            if let Some(ext) = prim.get_mut("extensions").and_then(|e| e.as_object_mut()) {
                ext.remove("KHR_draco_mesh_compression");
            }
        }
    }
}

/// No buffer view left may read a meshopt fallback buffer (it holds no data).
fn check_fallback_unused(path: &Path, json: &Value) -> Result<(), LoadError> {
    let buffers = json["buffers"].as_array().cloned().unwrap_or_default();
    for (i, v) in json["bufferViews"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        let b = v["buffer"].as_u64().unwrap_or(u64::MAX) as usize;
        if buffers.get(b).is_some_and(is_fallback) {
            return Err(corrupt(
                path,
                format!(
                    "buffer view {i} reads buffer {b}, a meshopt fallback buffer, without a \
                     compression extension (/bufferViews/{i})"
                ),
            ));
        }
    }
    Ok(())
}

/// The extensions the rewrite resolved are no longer required (the gltf crate refuses them).
fn strip_required(json: &mut Value) {
    if let Some(list) = json
        .get_mut("extensionsRequired")
        .and_then(|l| l.as_array_mut())
    {
        list.retain(|e| {
            let name = e.as_str().unwrap_or("");
            !DECODED.contains(&name) && !BY_FEATURE.iter().any(|f| f.0 == name)
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_decoder_left_out_of_the_build_is_named_with_its_feature() {
        let json =
            json!({"extensionsRequired": ["KHR_mesh_quantization", "KHR_draco_mesh_compression"]});
        let p = Path::new("m.glb");
        let off = [("KHR_draco_mesh_compression", "draco", false)];
        let e = check_required_with(p, &json, &off).unwrap_err().to_string();
        assert_eq!(
            e,
            "m.glb: requires unsupported extension KHR_draco_mesh_compression (its decoder is \
             umbra's cargo feature `draco`, not in this build)"
        );
        let on = [("KHR_draco_mesh_compression", "draco", true)];
        assert!(check_required_with(p, &json, &on).is_ok());
        let unknown = json!({"extensionsRequired": ["EXT_made_up"]});
        let e = check_required_with(p, &unknown, &on)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "m.glb: requires unsupported extension EXT_made_up");
    }

    #[test]
    fn resolved_extensions_leave_extensions_required() {
        let mut json = json!({"extensionsRequired": [
            "KHR_mesh_quantization", "EXT_meshopt_compression", "KHR_texture_transform",
            "KHR_texture_basisu", "KHR_draco_mesh_compression"]});
        strip_required(&mut json);
        assert_eq!(json["extensionsRequired"], json!(["KHR_texture_transform"]));
    }
}
