//! `KHR_draco_mesh_compression`: each compressed primitive is decoded by `draco-oxide-decoder`, a
//! pure-Rust Draco decoder (memory-safe on untrusted streams; a panic in it is caught and becomes
//! the file's one-line error), on all cores. Its triangles become a `u32` index accessor and each
//! attribute the extension maps (by Draco unique id) becomes the data of the accessor the
//! primitive names for it, in the type Draco decoded it to (quantized attributes come out
//! dequantized, as the extension says).

use super::{Appended, Rewrite, MAX_DECODED_BYTES};
use crate::scene::gltf::error::{corrupt, LoadError};
use draco_oxide_core::attribute::{Attribute, ComponentDataType as C};
use serde_json::{json, Value};
use std::path::Path;

const EXTENSION: &str = "KHR_draco_mesh_compression";

/// One compressed primitive: where it is and its stream's bytes.
struct Job<'a> {
    mesh: usize,
    prim: usize,
    stream: &'a [u8],
}

/// A decoded primitive: its indices and, per attribute unique id, the per-point bytes with their
/// glTF component type and component count.
struct Decoded {
    indices: Vec<u32>,
    points: usize,
    attributes: Vec<(usize, u64, usize, Vec<u8>)>,
}

fn component_type(c: C) -> Option<u64> {
    Some(match c {
        C::I8 => 5120,
        C::U8 => 5121,
        C::I16 => 5122,
        C::U16 => 5123,
        C::U32 => 5125,
        C::F32 => 5126,
        _ => return None,
    })
}

/// An attribute's values in point order (through its point-to-value map, if any).
fn per_point(a: &Attribute) -> Result<(u64, usize, Vec<u8>), String> {
    let ct = a.get_component_type();
    let glt = component_type(ct).ok_or_else(|| format!("component type {ct:?} is not glTF's"))?;
    let n = a.get_num_components();
    let elem = n * ct.size();
    let data = a.get_data_as_bytes();
    let points = a.len();
    if points.saturating_mul(elem) > MAX_DECODED_BYTES {
        return Err(format!(
            "{points} points × {elem} bytes, over the decoding limit"
        ));
    }
    let mut out = Vec::with_capacity(points * elem);
    match a.point_map_as_slice() {
        Some(map) => {
            for v in map {
                let at = usize::from(*v) * elem;
                let value = data
                    .get(at..at + elem)
                    .ok_or("a point names a missing value")?;
                out.extend_from_slice(value);
            }
        }
        None => out.extend_from_slice(data.get(..points * elem).ok_or("values missing")?),
    }
    Ok((glt, n, out))
}

fn decode(stream: &[u8]) -> Result<Decoded, String> {
    let mesh = super::contained("the Draco stream does not decode", || {
        draco_oxide_decoder::decode_mesh(stream)
            .map_err(|e| format!("the Draco stream does not decode ({e})"))
    })?;
    let points = mesh.attributes.first().map_or(0, |a| a.len());
    let mut indices = Vec::with_capacity(mesh.faces.len() * 3);
    for f in &mesh.faces {
        for p in f {
            let i = usize::from(*p);
            if i >= points {
                return Err(format!("a triangle names point {i} of {points}"));
            }
            indices.push(i as u32);
        }
    }
    let mut attributes = Vec::new();
    for a in &mesh.attributes {
        if a.len() != points {
            return Err(format!("attributes cover {} and {points} points", a.len()));
        }
        let (ct, n, bytes) = per_point(a)?;
        attributes.push((a.get_id().as_usize(), ct, n, bytes));
    }
    Ok(Decoded {
        indices,
        points,
        attributes,
    })
}

/// The compressed primitives and their streams (bounds checked).
fn jobs<'a>(path: &Path, json: &Value, buffers: &'a [Vec<u8>]) -> Result<Vec<Job<'a>>, LoadError> {
    let mut out = Vec::new();
    for (m, mesh) in json["meshes"].as_array().into_iter().flatten().enumerate() {
        for (p, prim) in mesh["primitives"]
            .as_array()
            .into_iter()
            .flatten()
            .enumerate()
        {
            let ext = &prim["extensions"][EXTENSION];
            if ext.is_null() {
                continue;
            }
            let at = format!("/meshes/{m}/primitives/{p}/extensions/{EXTENSION}");
            let bad = |what: &str| corrupt(path, format!("{at}: {what}"));
            let view = &json["bufferViews"][ext["bufferView"]
                .as_u64()
                .ok_or_else(|| bad("no bufferView"))?
                as usize];
            let buffer = buffers
                .get(view["buffer"].as_u64().unwrap_or(u64::MAX) as usize)
                .ok_or_else(|| bad("its buffer view does not exist"))?;
            let off = view["byteOffset"].as_u64().unwrap_or(0) as usize;
            let len = view["byteLength"].as_u64().unwrap_or(0) as usize;
            let stream = off
                .checked_add(len)
                .and_then(|end| buffer.get(off..end))
                .ok_or_else(|| bad("its buffer view runs past its buffer"))?;
            out.push(Job {
                mesh: m,
                prim: p,
                stream,
            });
        }
    }
    Ok(out)
}

/// Decodes every compressed primitive and points its accessors at the decoded data.
pub(super) fn decode_primitives(r: &mut Rewrite) -> Result<(), LoadError> {
    let (path, buffers) = (r.path, r.buffers);
    let (json, out, report) = (&mut r.json, &mut r.out, &mut r.report);
    let jobs = jobs(path, json, buffers)?;
    if jobs.is_empty() {
        return Ok(());
    }
    let start = std::time::Instant::now();
    let decoded = crate::parallel::map(&jobs, |j| decode(j.stream));
    report.add_seconds(EXTENSION, start.elapsed().as_secs_f64());
    for (j, d) in jobs.iter().zip(decoded) {
        let at = format!("/meshes/{}/primitives/{}", j.mesh, j.prim);
        let d = d.map_err(|e| corrupt(path, format!("{at}/extensions/{EXTENSION}: {e}")))?;
        let bytes = place(path, json, &at, (j.mesh, j.prim), d, out)?;
        report.add(
            EXTENSION,
            &format!("meshes/{}/primitives", j.mesh),
            j.prim,
            j.stream.len(),
            bytes,
        );
    }
    Ok(())
}

/// Writes a decoded primitive into `out` and rewrites its accessors; the bytes written.
fn place(
    path: &Path,
    json: &mut Value,
    at: &str,
    (m, p): (usize, usize),
    d: Decoded,
    out: &mut Appended,
) -> Result<usize, LoadError> {
    let prim = json["meshes"][m]["primitives"][p].clone();
    let ext = &prim["extensions"][EXTENSION];
    let bad = |what: String| corrupt(path, format!("{at}: {what}"));
    let index_bytes: Vec<u8> = d.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    let view = out.add(&index_bytes);
    let mut written = index_bytes.len();
    let indices = json!({"bufferView": view, "componentType": 5125, "count": d.indices.len(), "type": "SCALAR"});
    match prim["indices"].as_u64() {
        Some(a) => {
            let declared = json["accessors"][a as usize]["count"].as_u64().unwrap_or(0);
            if declared != d.indices.len() as u64 {
                return Err(bad(format!(
                    "Draco decoded {} indices but accessor {a} declares {declared}",
                    d.indices.len()
                )));
            }
            json["accessors"][a as usize] = indices;
        }
        None => {
            let list = json["accessors"].as_array_mut();
            let n = list.as_ref().map_or(0, |l| l.len());
            match list {
                Some(l) => l.push(indices),
                None => json["accessors"] = json!([indices]),
            }
            json["meshes"][m]["primitives"][p]["indices"] = json!(n);
        }
    }
    for (semantic, uid) in ext["attributes"].as_object().into_iter().flatten() {
        let uid = uid.as_u64().unwrap_or(u64::MAX) as usize;
        let (_, ct, n, bytes) = d.attributes.iter().find(|a| a.0 == uid).ok_or_else(|| {
            bad(format!(
                "{semantic}: Draco attribute {uid} is not in the stream"
            ))
        })?;
        let a = prim["attributes"][semantic]
            .as_u64()
            .ok_or_else(|| bad(format!("{semantic} is mapped but not an attribute")))?
            as usize;
        let acc = &json["accessors"][a];
        let kind_n = super::accessor::components(acc["type"].as_str().unwrap_or(""));
        let declared = acc["count"].as_u64().unwrap_or(0);
        if kind_n != Some(*n) || declared != d.points as u64 {
            return Err(bad(format!(
                "{semantic}: Draco decoded {} points of {n} components but accessor {a} \
                 declares {declared} of type {}",
                d.points, acc["type"]
            )));
        }
        let view = out.add(bytes);
        written += bytes.len();
        let mut plain = json!({"bufferView": view, "componentType": ct, "count": declared, "type": acc["type"]});
        if let Some(v) = acc.get("name") {
            plain["name"] = v.clone();
        }
        // glTF requires POSITION bounds: those of the decoded data (Draco's declared ones are its
        // quantization grid's).
        if semantic == "POSITION" && *ct == 5126 {
            let (lo, hi) = float_bounds(bytes, *n);
            plain["min"] = json!(lo);
            plain["max"] = json!(hi);
        }
        if *ct != 5126 && acc["normalized"].as_bool() == Some(true) {
            plain["normalized"] = json!(true);
        }
        json["accessors"][a] = plain;
    }
    if let Some(e) = json["meshes"][m]["primitives"][p]["extensions"].as_object_mut() {
        e.remove(EXTENSION);
    }
    Ok(written)
}

/// Per-component minimum and maximum of `n`-component `f32` data.
fn float_bounds(bytes: &[u8], n: usize) -> (Vec<f32>, Vec<f32>) {
    let mut lo = vec![f32::MAX; n];
    let mut hi = vec![f32::MIN; n];
    for (i, c) in bytes.chunks_exact(4).enumerate() {
        let x = f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
        if x.is_finite() {
            lo[i % n] = lo[i % n].min(x);
            hi[i % n] = hi[i % n].max(x);
        }
    }
    if lo.first().is_some_and(|l| *l > hi[0]) {
        return (vec![0.0; n], vec![0.0; n]);
    }
    (lo, hi)
}
