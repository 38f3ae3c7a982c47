//! Checks on untrusted glTF input made before and while the gltf crate reads it: the GLB
//! container, index references, accessor bounds and component types, URIs (which must stay in the
//! model's folder) and image decoding limits. Several of these guard panics in gltf 1.4.1 that
//! mutation fuzzing found (see `tests/loader_fuzz.rs`).

use super::error::{corrupt, invalid, LoadError, MAX_TEXTURE_SIDE};
use base64::Engine as _;
use std::path::{Component, Path};

/// The JSON of a `.glb` (after checking its container: magic, version 2, declared length and
/// chunk lengths within the file), or the whole input for `.gltf`.
pub(in crate::scene) fn json_part<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a [u8], LoadError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(bytes);
    }
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]) as usize)
    };
    let bad = |what: &str| invalid(path, format!("GLB container: {what}"));
    let version = word(4).ok_or_else(|| bad("truncated header"))?;
    let length = word(8).ok_or_else(|| bad("truncated header"))?;
    if version != 2 {
        return Err(bad(&format!("version {version}, expected 2")));
    }
    if length < 20 || length > bytes.len() {
        return Err(bad(&format!(
            "declared length {length} but the file has {} bytes",
            bytes.len()
        )));
    }
    let mut at = 12;
    let mut json = None;
    while at < length {
        let (Some(n), Some(kind)) = (word(at), bytes.get(at + 4..at + 8)) else {
            return Err(bad("truncated chunk header"));
        };
        let end = at
            .checked_add(8)
            .and_then(|x| x.checked_add(n))
            .filter(|&e| e <= length)
            .ok_or_else(|| bad("chunk runs past the end"))?;
        if json.is_none() {
            if kind != b"JSON" {
                return Err(bad("first chunk is not JSON"));
            }
            json = Some(&bytes[at + 8..end]);
        }
        at = (end + 3) & !3;
    }
    json.ok_or_else(|| bad("no JSON chunk"))
}

/// Checks index references the gltf crate's own validation reads before checking them
/// (mesh primitive attributes, targets and indices must name existing accessors).
pub(super) fn check_references(path: &Path, json: &[u8]) -> Result<(), LoadError> {
    // Lossy: serde_json skips ignored strings without UTF-8 checks, so the gltf parser may accept
    // bytes a strict parse rejects. Still-invalid JSON is reported by the gltf parser itself.
    let text = String::from_utf8_lossy(json);
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Ok(());
    };
    let accessors = v
        .get("accessors")
        .and_then(|a| a.as_array())
        .map_or(0, |a| a.len()) as u64;
    let check = |value: &serde_json::Value, what: &str| -> Result<(), LoadError> {
        match value.as_u64() {
            Some(i) if i < accessors => Ok(()),
            _ => Err(corrupt(
                path,
                format!("{what} refers to accessor {value}, but there are {accessors}"),
            )),
        }
    };
    check_asset_version(path, &v)?;
    check_images_and_textures(path, &v)?;
    check_motion_references(path, &v, accessors)?;
    let meshes = v
        .get("meshes")
        .and_then(|m| m.as_array())
        .map(|m| m.as_slice())
        .unwrap_or(&[]);
    for (mi, mesh) in meshes.iter().enumerate() {
        let prims = mesh
            .get("primitives")
            .and_then(|p| p.as_array())
            .map(|p| p.as_slice())
            .unwrap_or(&[]);
        for (pi, prim) in prims.iter().enumerate() {
            let label = format!("mesh {mi} primitive {pi}");
            let mut maps: Vec<&serde_json::Value> = prim.get("attributes").into_iter().collect();
            maps.extend(
                prim.get("targets")
                    .and_then(|t| t.as_array())
                    .into_iter()
                    .flatten(),
            );
            for map in maps {
                for (name, value) in map.as_object().into_iter().flatten() {
                    check(value, &format!("{label} attribute {name}"))?;
                }
            }
            if let Some(i) = prim.get("indices") {
                check(i, &format!("{label} indices"))?;
            }
        }
    }
    Ok(())
}

/// Skins' joints and inverse bind matrices, nodes' skins, and animations' samplers, targets,
/// paths and interpolations must name things that exist (the gltf crate unwraps them).
fn check_motion_references(
    path: &Path,
    v: &serde_json::Value,
    accessors: u64,
) -> Result<(), LoadError> {
    let list = |v: &'_ serde_json::Value, key: &str| -> Vec<serde_json::Value> {
        v.get(key)
            .and_then(|a| a.as_array())
            .cloned()
            .unwrap_or_default()
    };
    let nodes = count_of(v, "nodes");
    let skins = count_of(v, "skins");
    let index = |value: Option<&serde_json::Value>, n: u64, what: String| match value {
        None => Ok(()),
        Some(x) if x.as_u64().is_some_and(|i| i < n) => Ok(()),
        Some(x) => Err(corrupt(path, format!("{what} is {x}, but there are {n}"))),
    };
    for (i, node) in list(v, "nodes").iter().enumerate() {
        index(node.get("skin"), skins, format!("node {i}'s skin"))?;
    }
    for (i, skin) in list(v, "skins").iter().enumerate() {
        index(
            skin.get("inverseBindMatrices"),
            accessors,
            format!("skin {i}'s inverseBindMatrices"),
        )?;
        index(skin.get("skeleton"), nodes, format!("skin {i}'s skeleton"))?;
        for j in list(skin, "joints") {
            index(Some(&j), nodes, format!("a joint of skin {i}"))?;
        }
    }
    for (a, anim) in list(v, "animations").iter().enumerate() {
        let samplers = list(anim, "samplers");
        for (k, s) in samplers.iter().enumerate() {
            let what = format!("animation {a} sampler {k}");
            index(s.get("input"), accessors, format!("{what}'s input"))?;
            index(s.get("output"), accessors, format!("{what}'s output"))?;
            if let Some(m) = s.get("interpolation") {
                if !matches!(m.as_str(), Some("LINEAR" | "STEP" | "CUBICSPLINE")) {
                    return Err(corrupt(
                        path,
                        format!("{what}: interpolation {m} is not glTF's"),
                    ));
                }
            }
        }
        for (c, ch) in list(anim, "channels").iter().enumerate() {
            let what = format!("animation {a} channel {c}");
            index(
                ch.get("sampler"),
                samplers.len() as u64,
                format!("{what}'s sampler"),
            )?;
            let target = ch.get("target");
            index(
                target.and_then(|t| t.get("node")),
                nodes,
                format!("{what}'s node"),
            )?;
            let p = target.and_then(|t| t.get("path"));
            if !p
                .and_then(|p| p.as_str())
                .is_some_and(|p| matches!(p, "translation" | "rotation" | "scale" | "weights"))
            {
                return Err(corrupt(
                    path,
                    format!(
                        "{what}: target path {} is not glTF's",
                        p.unwrap_or(&serde_json::Value::Null)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// glTF 2.x only: `asset.version` must be present and of major version 2 (glTF 1.0 files parse
/// as JSON but mean something else).
fn check_asset_version(path: &Path, v: &serde_json::Value) -> Result<(), LoadError> {
    let version = v
        .get("asset")
        .and_then(|a| a.get("version"))
        .and_then(|x| x.as_str());
    match version {
        Some(ver) if ver.split('.').next() == Some("2") => Ok(()),
        Some(ver) => Err(invalid(
            path,
            format!("glTF version {ver} is not supported (glTF 2.0 only)"),
        )),
        None => Err(invalid(
            path,
            "asset.version is missing (not a glTF 2.0 file)",
        )),
    }
}

/// The number of entries of the top-level array `key`.
fn count_of(v: &serde_json::Value, key: &str) -> u64 {
    v.get(key)
        .and_then(|a| a.as_array())
        .map_or(0, |a| a.len() as u64)
}

/// Images must have exactly one source (`uri`, or `bufferView` with `mimeType`) naming something
/// that exists; textures must name existing images and samplers (gltf 1.4.1 unwraps these).
fn check_images_and_textures(path: &Path, v: &serde_json::Value) -> Result<(), LoadError> {
    let views = count_of(v, "bufferViews");
    let images = count_of(v, "images");
    let samplers = count_of(v, "samplers");
    let list = |key: &str| {
        v.get(key)
            .and_then(|a| a.as_array())
            .map(|a| a.as_slice())
            .unwrap_or(&[])
    };
    for (i, img) in list("images").iter().enumerate() {
        let uri = img.get("uri");
        let view = img.get("bufferView");
        let ok = match (uri, view) {
            (Some(u), None) => u.is_string(),
            (None, Some(b)) => {
                b.as_u64().is_some_and(|b| b < views)
                    && img.get("mimeType").is_some_and(|m| m.is_string())
            }
            _ => false,
        };
        if !ok {
            return Err(corrupt(
                path,
                format!(
                    "image {i} needs exactly one source: a uri, or a bufferView (of {views}) with a mimeType"
                ),
            ));
        }
    }
    for (i, t) in list("textures").iter().enumerate() {
        for (key, n) in [("source", images), ("sampler", samplers)] {
            if let Some(x) = t.get(key) {
                if x.as_u64().is_none_or(|x| x >= n) {
                    return Err(corrupt(
                        path,
                        format!("texture {i} {key} refers to {x}, but there are {n}"),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Largest accessor without a buffer view (all zeros, possibly with sparse values), in bytes: its
/// count is not bounded by any data in the file, and reading it allocates all of it.
pub(super) const MAX_VIEWLESS_ACCESSOR_BYTES: usize = 256 << 20;

pub(super) fn check_accessor(path: &Path, a: &gltf::Accessor) -> Result<(), LoadError> {
    let elem = a.size();
    let count = a.count();
    // glTF's minimum; the gltf crate's readers compute `count - 1`.
    if count == 0 {
        return Err(corrupt(
            path,
            format!(
                "accessor {} has count 0 (glTF requires 1 or more)",
                a.index()
            ),
        ));
    }
    if a.view().is_none() && count.saturating_mul(elem) > MAX_VIEWLESS_ACCESSOR_BYTES {
        return Err(corrupt(
            path,
            format!(
                "accessor {} has {count} elements and no buffer view (over the {} MiB limit)",
                a.index(),
                MAX_VIEWLESS_ACCESSOR_BYTES >> 20
            ),
        ));
    }
    if let Some(view) = a.view() {
        let stride = view.stride().unwrap_or(elem);
        let need = if count == 0 {
            0
        } else {
            stride
                .checked_mul(count - 1)
                .and_then(|x| x.checked_add(elem))
                .unwrap_or(usize::MAX)
        };
        let end = a.offset().checked_add(need);
        if end.is_none_or(|e| e > view.length()) || stride < elem {
            return Err(corrupt(
                path,
                format!(
                    "accessor {} reads past the end of buffer view {}",
                    a.index(),
                    view.index()
                ),
            ));
        }
    }
    if let Some(s) = a.sparse() {
        let n = s.count();
        let iv = s.indices().view();
        let isize = match s.indices().index_type() {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        if s.indices().offset() + n * isize > iv.length()
            || s.values().offset() + n * elem > s.values().view().length()
        {
            return Err(corrupt(
                path,
                format!(
                    "sparse accessor {} reads past the end of its buffer views",
                    a.index()
                ),
            ));
        }
    }
    Ok(())
}

/// Rejects attributes whose component type or dimensions glTF does not allow for their semantic
/// (the gltf crate's readers assume them and can panic otherwise).
pub(super) fn check_attribute_types(
    path: &Path,
    label: &str,
    prim: &gltf::Primitive,
) -> Result<(), LoadError> {
    use gltf::accessor::{DataType as T, Dimensions as D};
    use gltf::Semantic as S;
    let ok = |a: &gltf::Accessor, types: &[T], dims: &[D], what: &str| {
        if types.contains(&a.data_type()) && dims.contains(&a.dimensions()) {
            Ok(())
        } else {
            Err(corrupt(
                path,
                format!(
                    "{label}: {what} accessor {} is {:?} {:?}, which glTF does not allow",
                    a.index(),
                    a.data_type(),
                    a.dimensions()
                ),
            ))
        }
    };
    for (semantic, a) in prim.attributes() {
        match semantic {
            S::Positions => ok(&a, &[T::F32], &[D::Vec3], "POSITION")?,
            S::Normals => ok(&a, &[T::F32], &[D::Vec3], "NORMAL")?,
            S::Tangents => ok(&a, &[T::F32], &[D::Vec4], "TANGENT")?,
            S::TexCoords(_) => ok(&a, &[T::F32, T::U8, T::U16], &[D::Vec2], "TEXCOORD")?,
            S::Colors(_) => ok(&a, &[T::F32, T::U8, T::U16], &[D::Vec3, D::Vec4], "COLOR")?,
            S::Joints(_) => ok(&a, &[T::U8, T::U16], &[D::Vec4], "JOINTS")?,
            S::Weights(_) => ok(&a, &[T::F32, T::U8, T::U16], &[D::Vec4], "WEIGHTS")?,
            _ => {}
        }
    }
    if let Some(a) = prim.indices() {
        ok(&a, &[T::U8, T::U16, T::U32], &[D::Scalar], "indices")?;
    }
    // Morph target displacements: the readers take them as f32 vec3.
    for t in prim.morph_targets() {
        for a in [t.positions(), t.normals(), t.tangents()]
            .into_iter()
            .flatten()
        {
            ok(&a, &[T::F32], &[D::Vec3], "morph target")?;
        }
    }
    Ok(())
}

/// Resolves a buffer or image URI: a `data:` URI is decoded; anything else must be a relative path
/// that stays inside `base` (no absolute paths, no `..` escaping, no remote schemes).
pub(super) fn read_uri(
    path: &Path,
    base: &Path,
    uri: &str,
    what: &str,
) -> Result<Vec<u8>, LoadError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or_else(|| corrupt(path, format!("{what}: data URI is not base64")))?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload.trim())
            .map_err(|e| corrupt(path, format!("{what}: bad base64 in data URI: {e}")));
    }
    let refused = || LoadError::OutsideFolder {
        path: path.into(),
        what: what.into(),
        uri: uri.into(),
    };
    if uri.contains("://") || uri.starts_with('/') || uri.starts_with('\\') || uri.contains(':') {
        return Err(refused());
    }
    let decoded = percent_decode(uri);
    let rel = Path::new(&decoded);
    let mut depth = 0i32;
    for c in rel.components() {
        match c {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    return Err(refused());
                }
            }
            _ => return Err(refused()),
        }
    }
    let full = base.join(rel);
    // Symbolic links must not lead out either.
    if let (Ok(canon), Ok(canon_base)) = (full.canonicalize(), base.canonicalize()) {
        if !canon.starts_with(&canon_base) {
            return Err(refused());
        }
    }
    std::fs::read(&full).map_err(|e| LoadError::Io {
        path: full,
        cause: e,
    })
}

pub(super) fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let Ok(v) = u8::from_str_radix(&s[i + 1..i + 3], 16) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

pub(super) fn decode_image(data: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    let reader = image::ImageReader::new(std::io::Cursor::new(data))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    let (w, h) = reader.into_dimensions().map_err(|e| e.to_string())?;
    if w == 0 || h == 0 || w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
        return Err(format!("size {w}x{h} outside 1..={MAX_TEXTURE_SIDE}"));
    }
    let img = image::load_from_memory(data).map_err(|e| e.to_string())?;
    Ok((w, h, img.to_rgba8().into_raw()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.png"), "a b.png");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("%2e%2e/x"), "../x");
    }

    #[test]
    fn uri_escape_refused() {
        let dir = std::env::temp_dir();
        for uri in [
            "../secret.bin",
            "/etc/passwd",
            "a/../../x",
            "file:///etc/passwd",
            "http://x/y",
            "%2e%2e/x",
            "C:\\x",
        ] {
            let r = read_uri(Path::new("m.gltf"), &dir, uri, "buffer 0");
            assert!(
                matches!(r, Err(LoadError::OutsideFolder { .. })),
                "{uri}: {r:?}"
            );
        }
    }
}
