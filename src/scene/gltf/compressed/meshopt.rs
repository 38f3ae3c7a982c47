//! `EXT_meshopt_compression` and `KHR_meshopt_compression`: buffer views compressed by
//! meshoptimizer's vertex and index codecs, with its octahedral, quaternion, exponential and
//! colour filters, decoded by the `meshopt` crate's bindings to meshoptimizer's own decoders
//! (which are written to be safe on untrusted input). Each view is independent, so views are
//! decoded on all cores.

use super::{Rewrite, MAX_DECODED_BYTES};
use crate::scene::gltf::error::{corrupt, LoadError};
use serde_json::Value;
use std::path::Path;
use std::time::Instant;

const NAMES: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// One compressed view: where its stream is and what it decodes to.
struct Job {
    view: usize,
    extension: &'static str,
    source: (usize, usize, usize),
    stride: usize,
    count: usize,
    mode: String,
    filter: String,
}

/// Reads view `i`'s extension object into a job (its numbers checked against the buffers).
fn job(path: &Path, i: usize, v: &Value, buffers: &[Vec<u8>]) -> Result<Option<Job>, LoadError> {
    let Some((extension, ext)) = NAMES
        .iter()
        .find_map(|n| v["extensions"].get(*n).map(|e| (*n, e)))
    else {
        return Ok(None);
    };
    let at = format!("/bufferViews/{i}/extensions/{extension}");
    let num = |k: &str, default: Option<u64>| -> Result<usize, LoadError> {
        ext.get(k)
            .map_or(default, |x| x.as_u64())
            .map(|x| x as usize)
            .ok_or_else(|| corrupt(path, format!("{at}: `{k}` is missing or not a number")))
    };
    let buffer = num("buffer", None)?;
    let offset = num("byteOffset", Some(0))?;
    let length = num("byteLength", None)?;
    let data = buffers
        .get(buffer)
        .ok_or_else(|| corrupt(path, format!("{at}: buffer {buffer} does not exist")))?;
    if offset.checked_add(length).is_none_or(|e| e > data.len()) {
        return Err(corrupt(
            path,
            format!(
                "{at}: the stream ({length} bytes at {offset}) runs past the end of buffer \
                 {buffer} ({} bytes)",
                data.len()
            ),
        ));
    }
    let stride = num("byteStride", None)?;
    let count = num("count", None)?;
    let decoded = count.saturating_mul(stride);
    if decoded > MAX_DECODED_BYTES {
        return Err(corrupt(
            path,
            format!(
                "{at}: decodes to {count} × {stride} bytes, over the {} MiB limit",
                MAX_DECODED_BYTES >> 20
            ),
        ));
    }
    let view_length = v["byteLength"].as_u64().unwrap_or(0) as usize;
    if decoded != view_length {
        return Err(corrupt(
            path,
            format!(
                "{at}: decodes to {count} × {stride} = {decoded} bytes but the view declares \
                 {view_length}"
            ),
        ));
    }
    let text = |k: &str, default: &str| ext[k].as_str().unwrap_or(default).to_string();
    Ok(Some(Job {
        view: i,
        extension,
        source: (buffer, offset, length),
        stride,
        count,
        mode: text("mode", ""),
        filter: text("filter", "NONE"),
    }))
}

/// Decodes one stream into `count × stride` bytes, or says why not.
fn decode(job: &Job, buffers: &[Vec<u8>]) -> Result<Vec<u8>, String> {
    let (b, off, len) = job.source;
    let src = &buffers[b][off..off + len];
    let (count, stride) = (job.count, job.stride);
    let mut out = vec![0u8; count * stride];
    let bad_stride = || format!("mode {} with byteStride {stride}", job.mode);
    let code = match job.mode.as_str() {
        "ATTRIBUTES" => {
            if stride == 0 || stride % 4 != 0 || stride > 256 {
                return Err(bad_stride());
            }
            // SAFETY: `out` holds count × stride bytes, the decoder writes no more.
            unsafe {
                ::meshopt::ffi::meshopt_decodeVertexBuffer(
                    out.as_mut_ptr().cast(),
                    count,
                    stride,
                    src.as_ptr(),
                    src.len(),
                )
            }
        }
        "TRIANGLES" | "INDICES" => {
            if stride != 2 && stride != 4 {
                return Err(bad_stride());
            }
            if job.mode == "TRIANGLES" && count % 3 != 0 {
                return Err(format!("TRIANGLES with count {count}, not a multiple of 3"));
            }
            // SAFETY: as above, count indices of `stride` bytes each.
            unsafe {
                if job.mode == "TRIANGLES" {
                    ::meshopt::ffi::meshopt_decodeIndexBuffer(
                        out.as_mut_ptr().cast(),
                        count,
                        stride,
                        src.as_ptr(),
                        src.len(),
                    )
                } else {
                    ::meshopt::ffi::meshopt_decodeIndexSequence(
                        out.as_mut_ptr().cast(),
                        count,
                        stride,
                        src.as_ptr(),
                        src.len(),
                    )
                }
            }
        }
        m => {
            return Err(format!(
                "mode `{m}` is not ATTRIBUTES, TRIANGLES or INDICES"
            ))
        }
    };
    if code != 0 {
        return Err(format!(
            "the {} stream does not decode (meshopt error {code})",
            job.mode
        ));
    }
    filter(job, &mut out)?;
    Ok(out)
}

/// Applies the view's filter in place (the filters' stride rules are checked first: the
/// decoders assume them).
fn filter(job: &Job, out: &mut [u8]) -> Result<(), String> {
    let (count, stride) = (job.count, job.stride);
    if job.filter != "NONE" && job.mode != "ATTRIBUTES" {
        return Err(format!("filter {} on mode {}", job.filter, job.mode));
    }
    let ok = match job.filter.as_str() {
        "NONE" => return Ok(()),
        "OCTAHEDRAL" | "COLOR" => stride == 4 || stride == 8,
        "QUATERNION" => stride == 8,
        "EXPONENTIAL" => stride % 4 == 0,
        f => return Err(format!("filter `{f}` is not meshopt's")),
    };
    if !ok || (job.filter == "COLOR" && job.extension != NAMES[1]) {
        return Err(format!(
            "filter {} with byteStride {stride} in {}",
            job.filter, job.extension
        ));
    }
    let p = out.as_mut_ptr().cast();
    // SAFETY: `out` holds count elements of `stride` bytes, the sizes each filter takes.
    unsafe {
        match job.filter.as_str() {
            "OCTAHEDRAL" => ::meshopt::ffi::meshopt_decodeFilterOct(p, count, stride),
            "QUATERNION" => ::meshopt::ffi::meshopt_decodeFilterQuat(p, count, stride),
            "EXPONENTIAL" => ::meshopt::ffi::meshopt_decodeFilterExp(p, count, stride),
            _ => ::meshopt::ffi::meshopt_decodeFilterColor(p, count, stride),
        }
    }
    Ok(())
}

/// Decodes every compressed buffer view into `out` and points the view at its decoded bytes.
pub(super) fn decode_views(r: &mut Rewrite) -> Result<(), LoadError> {
    let (path, buffers) = (r.path, r.buffers);
    let (json, out, report) = (&mut r.json, &mut r.out, &mut r.report);
    let views = json["bufferViews"].as_array().cloned().unwrap_or_default();
    let mut jobs = Vec::new();
    for (i, v) in views.iter().enumerate() {
        if let Some(j) = job(path, i, v, buffers)? {
            jobs.push(j);
        }
    }
    if jobs.is_empty() {
        return Ok(());
    }
    let start = Instant::now();
    let decoded = crate::parallel::map(&jobs, |j| decode(j, buffers));
    let seconds = start.elapsed().as_secs_f64();
    for (j, d) in jobs.iter().zip(decoded) {
        let data = d.map_err(|e| {
            corrupt(
                path,
                format!("/bufferViews/{}/extensions/{}: {e}", j.view, j.extension),
            )
        })?;
        // The view keeps its index (accessors name it) and now reads the decoded bytes.
        let mut plain = out.place(&data, views[j.view]["byteStride"].as_u64());
        if let Some(t) = views[j.view].get("target") {
            plain["target"] = t.clone();
        }
        json["bufferViews"][j.view] = plain;
        report.add(j.extension, "bufferViews", j.view, j.source.2, data.len());
    }
    for ext in NAMES {
        if jobs.iter().any(|j| j.extension == ext) {
            report.add_seconds(ext, seconds);
        }
    }
    Ok(())
}
