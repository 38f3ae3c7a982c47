//! What is in a glTF file, as a JSON document (`umbra inspect`; schema `umbra-inspect/1`,
//! documented in `docs/inspect-schema.json`): asset and resources, extensions and which umbra
//! supports, the scene tree, meshes and primitives with their accessor types, materials and how
//! umbra maps them to Blinn-Phong, textures with their GPU size, totals counted the way the
//! Khronos glTF-Validator counts them (every primitive of every mesh once) and as rendered (per
//! instance in the default scene), the scene's scale and its depth-precision consequence, and
//! findings with stable codes and JSON pointers (`scene::warning`).
//!
//! Read from the file's JSON (after `load_gltf` has validated it, so references are in range) and
//! from the loaded [`Scene`] (decoded image sizes, repaired geometry). The shadow plan is added by
//! the render layer (`render::frame::plan_report`).

use super::gltf::compressed::accessor_type;
use super::gltf::error::LoadError;
use super::gltf::input::json_part;
use super::warning::severity_of;
use super::{blinn_phong_params, Scene};
use crate::math::precision::{relative_gap, DepthMapping};
use serde_json::{json, Map, Value};
use std::path::Path;

/// Schema name and version of the report.
pub const SCHEMA: &str = "umbra-inspect/1";

/// Extensions umbra reads (others are ignored; required ones it does not read refuse the file).
/// Those whose decoder is a cargo feature are listed only when this build has it.
pub fn supported_extensions() -> Vec<&'static str> {
    super::gltf::compressed::supported_extensions()
}

fn finding(code: &str, pointer: String, message: String) -> Value {
    json!({"code": code, "severity": severity_of(code), "pointer": pointer, "message": message})
}

fn arr<'a>(v: &'a Value, key: &str) -> &'a [Value] {
    v[key].as_array().map(Vec::as_slice).unwrap_or(&[])
}

/// Triangles a primitive draws: TRIANGLES n/3, STRIP and FAN n−2 (n = indices, else vertices).
fn triangles_of(mode: u64, n: u64) -> u64 {
    match mode {
        4 => n / 3,
        5 | 6 => n.saturating_sub(2),
        _ => 0,
    }
}

fn mode_name(mode: u64) -> &'static str {
    match mode {
        0 => "POINTS",
        1 => "LINES",
        2 => "LINE_LOOP",
        3 => "LINE_STRIP",
        4 => "TRIANGLES",
        5 => "TRIANGLE_STRIP",
        6 => "TRIANGLE_FAN",
        _ => "?",
    }
}

/// Bytes of an RGBA8 texture with its full mip chain.
pub fn mip_chain_bytes(w: u32, h: u32) -> (u32, u64) {
    let levels = crate::math::mip_levels(w, h);
    let bytes = (0..levels)
        .map(|l| ((w >> l).max(1) as u64) * ((h >> l).max(1) as u64) * 4)
        .sum();
    (levels, bytes)
}

/// The report of the glTF file at `path`, already loaded as `scene` (by `load_gltf`).
pub fn document_report(path: &Path, scene: &Scene) -> Result<Value, LoadError> {
    let io = |e| LoadError::Io {
        path: path.into(),
        cause: e,
    };
    let bytes = std::fs::read(path).map_err(io)?;
    let doc: Value = serde_json::from_slice(json_part(path, &bytes)?)
        .map_err(|e| super::gltf::error::invalid(path, e))?;
    let mut findings: Vec<Value> = Vec::new();
    for w in &scene.warnings {
        findings.push(finding(w.code, w.pointer.clone(), w.message.clone()));
    }
    let glb = bytes.starts_with(b"glTF");
    let (buffers, images) = resources(&doc, scene, glb);
    let (used, required, supported) = extensions(&doc, &mut findings);
    let Tree {
        scene_index,
        roots,
        instances,
        seen,
    } = scene_tree(&doc);
    let (node_list, cameras, lights) = tree_lists(&doc, &seen);
    let mesh = mesh_report(&doc, &instances, &mut findings);
    let [tris, verts, draws, r_tris, r_verts, r_draws] = mesh.totals;
    let (material_list, texture_used, srgb) =
        material_report(&doc, scene, &mesh.material_used, &mut findings);
    let (texture_list, texture_bytes) =
        texture_report(&doc, scene, (&texture_used, &srgb), &mut findings);
    // Geometry as uploaded: 48 bytes per vertex (position, normal, uv, tangent) + 4 per index.
    let geometry_bytes: u64 = scene
        .meshes
        .iter()
        .flat_map(|m| &m.primitives)
        .map(|p| p.positions.len() as u64 * 48 + p.indices.len() as u64 * 4)
        .sum();

    let scale = scale_report(scene);
    let (nodes, meshes, textures_doc) = (
        arr(&doc, "nodes"),
        arr(&doc, "meshes"),
        arr(&doc, "textures"),
    );
    let meta = std::fs::metadata(path).map_err(io)?;
    Ok(json!({
        "schema": SCHEMA,
        "file": {"path": path.display().to_string(), "bytes": meta.len(), "container": if glb { "glb" } else { "gltf" }},
        "asset": {"version": doc["asset"]["version"], "min_version": doc["asset"]["minVersion"],
                  "generator": doc["asset"]["generator"], "copyright": doc["asset"]["copyright"]},
        "resources": {"buffers": buffers, "images": images},
        "extensions": {"used": used, "required": required, "supported": supported},
        "compression": scene.compression.to_json(),
        "scene_tree": {"scene": scene_index, "roots": roots, "nodes": node_list,
                       "cameras": cameras, "lights": lights},
        "meshes": mesh.list,
        "materials": material_list,
        "textures": texture_list,
        "totals": {"triangles": tris, "vertices": verts, "draw_calls": draws,
                   "rendered": {"triangles": r_tris, "vertices": r_verts, "draw_calls": r_draws},
                   "meshes": meshes.len(), "materials": arr(&doc, "materials").len(),
                   "textures": textures_doc.len(), "images": arr(&doc, "images").len(),
                   "nodes": nodes.len(), "extensions_used": used.len(),
                   "gpu_bytes": {"geometry": geometry_bytes, "textures": texture_bytes}},
        "scale": scale,
        "motion": super::anim::report::motion_report(&doc, scene),
        "findings": findings,
    }))
}

/// The buffers and images of `doc` (a GLB's chunk when `glb`), images with what loading made of
/// them.
fn resources(doc: &Value, scene: &Scene, glb: bool) -> (Vec<Value>, Vec<Value>) {
    let buffers: Vec<Value> = arr(doc, "buffers")
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let uri = b["uri"].as_str();
            let source = match uri {
                None if glb => "glb",
                None => "none",
                Some(u) if u.starts_with("data:") => "data-uri",
                Some(_) => "external",
            };
            json!({"index": i, "bytes": b["byteLength"], "source": source,
                   "uri": uri.filter(|u| !u.starts_with("data:"))})
        })
        .collect();
    let images: Vec<Value> = arr(doc, "images")
        .iter()
        .enumerate()
        .map(|(i, im)| {
            let uri = im["uri"].as_str();
            let source = match uri {
                None => "buffer-view",
                Some(u) if u.starts_with("data:") => "data-uri",
                Some(_) => "external",
            };
            let t = scene.image_textures.get(i).copied().flatten();
            let tex = t.and_then(|t| scene.textures.get(t));
            json!({"index": i, "name": im["name"], "source": source, "mime": im["mimeType"],
                   "uri": uri.filter(|u| !u.starts_with("data:")),
                   "width": tex.map(|t| t.width), "height": tex.map(|t| t.height),
                   "loaded": tex.is_some()})
        })
        .collect();
    (buffers, images)
}

/// The extensions used, required, and whether umbra supports each (a finding for each it
/// ignores).
fn extensions(
    doc: &Value,
    findings: &mut Vec<Value>,
) -> (Vec<String>, Vec<String>, Map<String, Value>) {
    let used: Vec<String> = arr(doc, "extensionsUsed")
        .iter()
        .filter_map(|v| v.as_str().map(String::from))
        .collect();
    let required: Vec<String> = arr(doc, "extensionsRequired")
        .iter()
        .filter_map(|v| v.as_str().map(String::from))
        .collect();
    let mut supported = Map::new();
    let known = supported_extensions();
    for e in &used {
        let ok = known.contains(&e.as_str());
        supported.insert(e.clone(), json!(ok));
        if !ok {
            findings.push(finding(
                "EXTENSION_UNSUPPORTED",
                "/extensionsUsed".into(),
                format!("{e} is used and ignored by umbra"),
            ));
        }
    }
    (used, required, supported)
}

/// The default scene's roots, and walking from them which nodes are in the scene and how many
/// instances each mesh has.
struct Tree {
    scene_index: usize,
    roots: Vec<usize>,
    instances: Vec<u64>,
    seen: Vec<bool>,
}

fn scene_tree(doc: &Value) -> Tree {
    let nodes = arr(doc, "nodes");
    let scene_index = doc["scene"].as_u64().unwrap_or(0) as usize;
    let roots: Vec<usize> = match arr(doc, "scenes").get(scene_index) {
        Some(s) => arr(s, "nodes")
            .iter()
            .filter_map(|n| n.as_u64().map(|n| n as usize))
            .collect(),
        None => {
            let mut child = vec![false; nodes.len()];
            for n in nodes {
                for c in arr(n, "children") {
                    if let Some(c) = c.as_u64() {
                        if let Some(x) = child.get_mut(c as usize) {
                            *x = true;
                        }
                    }
                }
            }
            (0..nodes.len()).filter(|&i| !child[i]).collect()
        }
    };
    let mut instances = vec![0u64; arr(doc, "meshes").len()];
    let mut stack = roots.clone();
    let mut seen = vec![false; nodes.len()];
    while let Some(n) = stack.pop() {
        if n >= nodes.len() || seen[n] {
            continue;
        }
        seen[n] = true;
        if let Some(m) = nodes[n]["mesh"].as_u64() {
            if let Some(x) = instances.get_mut(m as usize) {
                *x += 1;
            }
        }
        for c in arr(&nodes[n], "children") {
            if let Some(c) = c.as_u64() {
                stack.push(c as usize);
            }
        }
    }
    Tree {
        scene_index,
        roots,
        instances,
        seen,
    }
}

/// The nodes (with whether each is in the scene), cameras and lights of `doc`.
fn tree_lists(doc: &Value, seen: &[bool]) -> (Vec<Value>, Vec<Value>, Vec<Value>) {
    let nodes = arr(doc, "nodes");
    let node_list: Vec<Value> = nodes
        .iter()
        .enumerate()
        .map(|(i, n)| {
            json!({"index": i, "name": n["name"], "in_scene": seen[i],
                   "translation": n["translation"], "rotation": n["rotation"], "scale": n["scale"],
                   "matrix": n["matrix"], "mesh": n["mesh"], "camera": n["camera"],
                   "light": n["extensions"]["KHR_lights_punctual"]["light"],
                   "children": n["children"]})
        })
        .collect();
    let cameras: Vec<Value> = arr(doc, "cameras")
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let t = c["type"].as_str().unwrap_or("");
            json!({"index": i, "name": c["name"], "type": t, "yfov": c[t]["yfov"],
                   "xmag": c[t]["xmag"], "ymag": c[t]["ymag"],
                   "znear": c[t]["znear"], "zfar": c[t]["zfar"], "aspect": c[t]["aspectRatio"]})
        })
        .collect();
    let lights: Vec<Value> = arr(&doc["extensions"]["KHR_lights_punctual"], "lights")
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let t = l["type"].as_str().unwrap_or("");
            let unit = if t == "directional" { "lux" } else { "candela" };
            json!({"index": i, "name": l["name"], "type": t,
                   "color": l.get("color").cloned().unwrap_or(json!([1.0, 1.0, 1.0])),
                   "intensity": l.get("intensity").cloned().unwrap_or(json!(1.0)),
                   "intensity_unit": unit, "range": l["range"],
                   "inner_cone": l["spot"]["innerConeAngle"], "outer_cone": l["spot"]["outerConeAngle"]})
        })
        .collect();
    (node_list, cameras, lights)
}

/// The meshes and their primitives, with totals counted as glTF-Validator counts them and as
/// rendered, and which materials a drawn primitive uses.
struct MeshReport {
    list: Vec<Value>,
    material_used: Vec<bool>,
    /// Triangles, vertices, draws in the file; then as rendered.
    totals: [u64; 6],
}

fn mesh_report(doc: &Value, instances: &[u64], findings: &mut Vec<Value>) -> MeshReport {
    let accessors = arr(doc, "accessors");
    let meshes = arr(doc, "meshes");
    let mut material_used = vec![false; arr(doc, "materials").len()];
    // Counted as glTF-Validator's info block counts them (every primitive of every mesh once,
    // whether or not a node uses it: what the file holds) and as rendered (triangle primitives
    // per instance in the default scene: what umbra draws).
    let (mut tris, mut verts, mut draws) = (0u64, 0u64, 0u64);
    let (mut r_tris, mut r_verts, mut r_draws) = (0u64, 0u64, 0u64);
    let mut mesh_list = Vec::new();
    for (mi, m) in meshes.iter().enumerate() {
        if instances[mi] == 0 {
            findings.push(finding(
                "UNUSED_MESH",
                format!("/meshes/{mi}"),
                format!("mesh {mi} is not instanced by the rendered scene"),
            ));
        }
        let mut prims = Vec::new();
        for (pi, p) in arr(m, "primitives").iter().enumerate() {
            let mode = p["mode"].as_u64().unwrap_or(4);
            let attrs = p["attributes"].as_object().cloned().unwrap_or_default();
            let pos = attrs
                .get("POSITION")
                .and_then(Value::as_u64)
                .and_then(|a| accessors.get(a as usize));
            let vcount = pos.and_then(|a| a["count"].as_u64()).unwrap_or(0);
            let idx = p["indices"]
                .as_u64()
                .and_then(|a| accessors.get(a as usize));
            let icount = idx.and_then(|a| a["count"].as_u64());
            let t = triangles_of(mode, icount.unwrap_or(vcount));
            if let Some(mat) = p["material"].as_u64() {
                if let Some(u) = material_used.get_mut(mat as usize) {
                    *u |= instances[mi] > 0;
                }
            }
            let mut names: Vec<&String> = attrs.keys().collect();
            names.sort();
            let attributes: Vec<String> = names
                .iter()
                .map(|k| {
                    let a = attrs[*k]
                        .as_u64()
                        .and_then(|a| accessors.get(a as usize))
                        .unwrap_or(&Value::Null);
                    format!("{k}:{}", accessor_type(a))
                })
                .collect();
            let n = instances[mi];
            tris += t;
            verts += vcount;
            draws += 1;
            if mode >= 4 {
                r_tris += t * n;
                r_verts += vcount * n;
                r_draws += n;
            }
            prims.push(
                json!({"index": pi, "mode": mode_name(mode), "vertices": vcount,
                "indices": icount, "index_type": idx.map(accessor_type),
                "attributes": attributes, "material": p["material"], "triangles": t,
                "bounds": pos.map(|a| json!({"min": a["min"], "max": a["max"]}))}),
            );
        }
        mesh_list.push(
            json!({"index": mi, "name": m["name"], "instances": instances[mi],
                              "primitives": prims}),
        );
    }
    MeshReport {
        list: mesh_list,
        material_used,
        totals: [tris, verts, draws, r_tris, r_verts, r_draws],
    }
}

/// The materials (their texture slots, tangents and Blinn-Phong constants), and which textures
/// they use and which of those hold colour (sRGB).
fn material_report(
    doc: &Value,
    scene: &Scene,
    material_used: &[bool],
    findings: &mut Vec<Value>,
) -> (Vec<Value>, Vec<bool>, Vec<bool>) {
    let meshes = arr(doc, "meshes");
    let textures_doc = arr(doc, "textures");
    let mut texture_used = vec![false; textures_doc.len()];
    let slots = [
        ("baseColor", "/pbrMetallicRoughness/baseColorTexture"),
        (
            "metallicRoughness",
            "/pbrMetallicRoughness/metallicRoughnessTexture",
        ),
        ("normal", "/normalTexture"),
        ("occlusion", "/occlusionTexture"),
        ("emissive", "/emissiveTexture"),
    ];
    let mut srgb = vec![false; textures_doc.len()];
    let mut material_list = Vec::new();
    for (i, m) in arr(doc, "materials").iter().enumerate() {
        if !material_used[i] {
            findings.push(finding(
                "UNUSED_MATERIAL",
                format!("/materials/{i}"),
                format!("material {i} is used by no drawn primitive"),
            ));
        }
        let mut tex = Vec::new();
        for (slot, ptr) in slots {
            let t = m.pointer(ptr);
            if let Some(t) = t.filter(|t| t.is_object()) {
                let ti = t["index"].as_u64().unwrap_or(0) as usize;
                if let Some(u) = texture_used.get_mut(ti) {
                    *u = true;
                }
                if slot == "baseColor" || slot == "emissive" {
                    if let Some(s) = srgb.get_mut(ti) {
                        *s = true;
                    }
                }
                tex.push(json!({"slot": slot, "texture": ti,
                    "tex_coord": t.get("texCoord").cloned().unwrap_or(json!(0)),
                    "transform": t["extensions"].get("KHR_texture_transform").is_some()}));
            }
        }
        let sm = scene.materials.get(i);
        let bp = sm.map(|s| blinn_phong_params(s.base_color.truncate(), s.metallic, s.roughness));
        let normal_mapped = m.get("normalTexture").is_some();
        let stored_tangents = meshes.iter().any(|me| {
            arr(me, "primitives").iter().any(|p| {
                p["material"].as_u64() == Some(i as u64) && p["attributes"].get("TANGENT").is_some()
            })
        });
        material_list.push(json!({"index": i, "name": m["name"],
            "alpha_mode": m.get("alphaMode").cloned().unwrap_or(json!("OPAQUE")),
            "alpha_cutoff": m.get("alphaCutoff").cloned().unwrap_or(json!(0.5)),
            "double_sided": m["doubleSided"].as_bool().unwrap_or(false),
            "unlit": m["extensions"].get("KHR_materials_unlit").is_some(),
            "textures": tex,
            "tangents": if !normal_mapped { "not needed" } else if stored_tangents { "stored" } else { "generated (MikkTSpace)" },
            "blinn_phong": bp.map(|b| json!({"kd": b.kd.to_array(), "ks": b.ks.to_array(), "shininess": b.p}))}));
    }
    (material_list, texture_used, srgb)
}

/// The textures with their GPU format, colour space and mip-chain bytes (the sum over used
/// textures returned too).
fn texture_report(
    doc: &Value,
    scene: &Scene,
    (texture_used, srgb): (&[bool], &[bool]),
    findings: &mut Vec<Value>,
) -> (Vec<Value>, u64) {
    let textures_doc = arr(doc, "textures");
    let mut texture_list = Vec::new();
    let mut texture_bytes = 0u64;
    for (i, t) in textures_doc.iter().enumerate() {
        if !texture_used[i] {
            findings.push(finding(
                "UNUSED_TEXTURE",
                format!("/textures/{i}"),
                format!("texture {i} is used by no material"),
            ));
        }
        let src = t["source"].as_u64().map(|s| s as usize);
        let tex = src
            .and_then(|s| scene.image_textures.get(s).copied().flatten())
            .and_then(|t| scene.textures.get(t));
        let (levels, bytes) = tex.map_or((0, 0), |t| mip_chain_bytes(t.width, t.height));
        if texture_used[i] {
            texture_bytes += bytes;
        }
        texture_list.push(json!({"index": i, "image": src, "sampler": t["sampler"],
            "width": tex.map(|t| t.width), "height": tex.map(|t| t.height),
            "format": "RGBA8", "color_space": if srgb[i] { "sRGB" } else { "linear" },
            "mip_levels": levels, "gpu_bytes": bytes}));
    }
    (texture_list, texture_bytes)
}

/// The scene's scale and the reversed-z depth precision at its far corner.
fn scale_report(scene: &Scene) -> Value {
    let b = scene.bounds();
    if b.is_empty() {
        Value::Null
    } else {
        let far = b.center().length() as f64 + b.diagonal() as f64 * 0.5;
        let near = (b.diagonal() as f64 * 1e-4).max(1e-4);
        json!({"bounds": {"min": b.min.to_array(), "max": b.max.to_array()},
               "diagonal": b.diagonal(),
               "distance_from_origin": b.center().length(),
               "reversed_z_relative_step_at_far_corner": relative_gap(DepthMapping::ReversedInfiniteF32, near, far.max(near)),
               "near_plane_assumed": near})
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mip_chain_sizes() {
        assert_eq!(mip_chain_bytes(1, 1), (1, 4));
        assert_eq!(mip_chain_bytes(4, 4), (3, (16 + 4 + 1) * 4));
        assert_eq!(mip_chain_bytes(4, 1), (3, (4 + 2 + 1) * 4));
        assert_eq!(triangles_of(4, 9), 3);
        assert_eq!(triangles_of(5, 5), 3);
        assert_eq!(triangles_of(1, 6), 0);
    }
}
