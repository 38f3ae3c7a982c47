//! `KHR_mesh_quantization`: integer vertex attributes become dense `f32` accessors with the same
//! values. Positions stay in the mesh's quantized space: the node transform the encoder wrote
//! (gltfpack's scale and offset) dequantizes them, as it would on any device, and the rest of the
//! loader never meets an integer position.

use super::accessor::{read_f32, Sources};
use super::Rewrite;
use crate::scene::gltf::error::{corrupt, LoadError};
use serde_json::{json, Value};
use std::collections::BTreeMap;

const EXTENSION: &str = "KHR_mesh_quantization";

/// Semantics the extension widens (glTF core already allows integer colours, joints, weights).
fn widened(semantic: &str) -> bool {
    matches!(semantic, "POSITION" | "NORMAL" | "TANGENT") || semantic.starts_with("TEXCOORD_")
}

fn declared(json: &Value) -> bool {
    ["extensionsUsed", "extensionsRequired"].iter().any(|k| {
        json[k]
            .as_array()
            .is_some_and(|l| l.iter().any(|e| e == EXTENSION))
    })
}

/// Each quantized accessor a primitive or morph target uses, with its semantic (first seen).
fn quantized_accessors(json: &Value) -> BTreeMap<usize, String> {
    let mut out = BTreeMap::new();
    for mesh in json["meshes"].as_array().into_iter().flatten() {
        for prim in mesh["primitives"].as_array().into_iter().flatten() {
            let mut maps = vec![&prim["attributes"]];
            maps.extend(prim["targets"].as_array().into_iter().flatten());
            for map in maps {
                for (semantic, a) in map.as_object().into_iter().flatten() {
                    let Some(i) = a.as_u64().map(|i| i as usize) else {
                        continue;
                    };
                    let ct = json["accessors"][i]["componentType"].as_u64();
                    if widened(semantic) && ct.is_some_and(|c| c != 5126) {
                        out.entry(i).or_insert_with(|| semantic.clone());
                    }
                }
            }
        }
    }
    out
}

/// `/nodes/i` and its transform, for each node that places a mesh with quantized positions: the
/// transforms that dequantize them.
fn dequantizing_nodes(json: &Value, positions: &[usize]) -> Vec<Value> {
    let mut out = Vec::new();
    for (i, node) in json["nodes"].as_array().into_iter().flatten().enumerate() {
        let Some(m) = node["mesh"].as_u64() else {
            continue;
        };
        let quantized = json["meshes"][m as usize]["primitives"]
            .as_array()
            .into_iter()
            .flatten()
            .any(|p| {
                p["attributes"]["POSITION"]
                    .as_u64()
                    .is_some_and(|a| positions.contains(&(a as usize)))
            });
        if quantized {
            let mut t = json!({"node": format!("/nodes/{i}")});
            for k in ["matrix", "translation", "rotation", "scale"] {
                if let Some(v) = node.get(k) {
                    t[k] = v.clone();
                }
            }
            out.push(t);
        }
    }
    out
}

/// Rewrites every quantized attribute accessor as `f32` data in `out`.
pub(super) fn dequantize(r: &mut Rewrite) -> Result<(), LoadError> {
    let (path, buffers) = (r.path, r.buffers);
    let (json, out, report) = (&mut r.json, &mut r.out, &mut r.report);
    if !declared(json) {
        return Ok(());
    }
    let list = quantized_accessors(json);
    let start = std::time::Instant::now();
    // Views appended so far are readable too (Draco's accessors point at them).
    let mut lookup = json.clone();
    if let Some(l) = lookup["bufferViews"].as_array_mut() {
        l.extend(out.views.iter().cloned());
    }
    let sources = Sources {
        file: buffers,
        decoded: &out.bytes,
    };
    let mut read = Vec::with_capacity(list.len());
    for (&i, semantic) in &list {
        let values = read_f32(&lookup, &sources, &json["accessors"][i])
            .map_err(|e| corrupt(path, format!("/accessors/{i} ({semantic}, quantized): {e}")))?;
        read.push(values);
    }
    let mut positions = Vec::new();
    for ((&i, semantic), values) in list.iter().zip(read) {
        let a = json["accessors"][i].clone();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = out.add(&bytes);
        let acc = &mut json["accessors"][i];
        report.quantized(i, semantic, &a);
        if semantic == "POSITION" {
            positions.push(i);
        }
        acc["componentType"] = json!(5126);
        acc["bufferView"] = json!(view);
        acc["byteOffset"] = json!(0);
        let obj = acc.as_object_mut().expect("an accessor is an object");
        obj.remove("normalized");
        obj.remove("sparse");
        let normalized = a["normalized"].as_bool().unwrap_or(false);
        let ct = a["componentType"].as_u64().unwrap_or(0);
        for k in ["min", "max"] {
            if let Some(l) = a[k].as_array() {
                let conv: Vec<Value> = l.iter().map(|x| json!(bound(x, ct, normalized))).collect();
                obj.insert(k.into(), Value::Array(conv));
            }
        }
    }
    if !list.is_empty() {
        report.add_seconds(EXTENSION, start.elapsed().as_secs_f64());
        report.transforms = dequantizing_nodes(json, &positions);
    }
    Ok(())
}

/// A declared min or max in the units of the `f32` data (normalised integers divided).
fn bound(x: &Value, ct: u64, normalized: bool) -> f64 {
    let v = x.as_f64().unwrap_or(0.0);
    match super::accessor::norm_divisor(ct) {
        Some(d) if normalized => (v / d as f64).max(-1.0),
        _ => v,
    }
}
