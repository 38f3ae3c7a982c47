//! Reads a glTF accessor straight from the JSON and the buffers' bytes, as `f32` components (each
//! integer converted as glTF says: normalised ones divided, others as they are), with every
//! offset checked: this runs before the gltf crate has validated anything.

use serde_json::Value;

/// Bytes of one component of `component_type`, or `None` for a type glTF does not have.
pub(super) fn component_size(component_type: u64) -> Option<usize> {
    match component_type {
        5120 | 5121 => Some(1),
        5122 | 5123 => Some(2),
        5125 | 5126 => Some(4),
        _ => None,
    }
}

/// Components per element of an accessor `type`.
pub(super) fn components(kind: &str) -> Option<usize> {
    Some(match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

/// The divisor glTF normalises an integer component type by (`None` for float and u32).
pub(super) fn norm_divisor(component_type: u64) -> Option<f32> {
    match component_type {
        5120 => Some(127.0),
        5121 => Some(255.0),
        5122 => Some(32767.0),
        5123 => Some(65535.0),
        _ => None,
    }
}

/// One component's value (little-endian) as glTF reads it.
pub(super) fn to_f32(bytes: &[u8], component_type: u64, normalized: bool) -> f32 {
    let x = match component_type {
        5120 => bytes[0] as i8 as f32,
        5121 => bytes[0] as f32,
        5122 => i16::from_le_bytes([bytes[0], bytes[1]]) as f32,
        5123 => u16::from_le_bytes([bytes[0], bytes[1]]) as f32,
        5125 => return u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f32,
        _ => return f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
    };
    match norm_divisor(component_type) {
        Some(d) if normalized => (x / d).max(-1.0),
        _ => x,
    }
}

/// The file's buffers and the bytes decoded so far (the buffer that will follow them).
pub(super) struct Sources<'a> {
    pub file: &'a [Vec<u8>],
    pub decoded: &'a [u8],
}

impl<'a> Sources<'a> {
    fn buffer(&self, i: usize) -> Option<&'a [u8]> {
        match self.file.get(i) {
            Some(b) => Some(b),
            None => (i == self.file.len()).then_some(self.decoded),
        }
    }
}

/// The bytes of buffer view `index` (`None` if it or its buffer range does not exist).
fn view_bytes<'a>(
    json: &Value,
    buffers: &'a Sources<'a>,
    index: &Value,
) -> Option<(&'a [u8], usize)> {
    let view = &json["bufferViews"][index.as_u64()? as usize];
    let buffer = buffers.buffer(view["buffer"].as_u64()? as usize)?;
    let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let length = view["byteLength"].as_u64()? as usize;
    let bytes = buffer.get(offset..offset.checked_add(length)?)?;
    Some((bytes, view["byteStride"].as_u64().unwrap_or(0) as usize))
}

/// Reads `count × n` components from `bytes` at `offset` with `stride` (0: tightly packed).
fn read_dense(
    bytes: &[u8],
    offset: usize,
    stride: usize,
    (count, n, ct, normalized): (usize, usize, u64, bool),
) -> Option<Vec<f32>> {
    let size = component_size(ct)?;
    let elem = size * n;
    let stride = if stride == 0 { elem } else { stride };
    if stride < elem {
        return None;
    }
    if count > 0 {
        let end = offset.checked_add(stride.checked_mul(count - 1)?.checked_add(elem)?)?;
        if end > bytes.len() {
            return None;
        }
    }
    let mut out = Vec::with_capacity(count * n);
    for i in 0..count {
        let at = offset + i * stride;
        for c in 0..n {
            out.push(to_f32(&bytes[at + c * size..], ct, normalized));
        }
    }
    Some(out)
}

/// Accessor `a`'s components as `f32` (sparse values applied), or why it cannot be read.
pub(super) fn read_f32(json: &Value, buffers: &Sources, a: &Value) -> Result<Vec<f32>, String> {
    let ct = a["componentType"].as_u64().unwrap_or(0);
    let normalized = a["normalized"].as_bool().unwrap_or(false);
    let n = components(a["type"].as_str().unwrap_or("")).ok_or("unknown type")?;
    let count = a["count"].as_u64().ok_or("no count")? as usize;
    let size = component_size(ct).ok_or("unknown componentType")?;
    if count.saturating_mul(n * size) > super::MAX_DECODED_BYTES {
        return Err(format!("{count} elements, over the decoding limit"));
    }
    let shape = (count, n, ct, normalized);
    let mut values = match a.get("bufferView") {
        Some(v) => {
            let (bytes, stride) =
                view_bytes(json, buffers, v).ok_or("its buffer view is out of range")?;
            let offset = a["byteOffset"].as_u64().unwrap_or(0) as usize;
            read_dense(bytes, offset, stride, shape).ok_or("it reads past its buffer view")?
        }
        None => vec![0.0; count * n],
    };
    if let Some(s) = a.get("sparse") {
        apply_sparse(json, buffers, s, shape, &mut values)
            .ok_or("its sparse values are out of range")?;
    }
    Ok(values)
}

/// Replaces the elements a sparse accessor names with its values.
fn apply_sparse(
    json: &Value,
    buffers: &Sources,
    s: &Value,
    (count, n, ct, normalized): (usize, usize, u64, bool),
    values: &mut [f32],
) -> Option<()> {
    let k = s["count"].as_u64()? as usize;
    let (ib, _) = view_bytes(json, buffers, &s["indices"]["bufferView"])?;
    let ict = s["indices"]["componentType"].as_u64()?;
    let ioff = s["indices"]["byteOffset"].as_u64().unwrap_or(0) as usize;
    let idx = read_dense(ib, ioff, 0, (k, 1, ict, false))?;
    let (vb, _) = view_bytes(json, buffers, &s["values"]["bufferView"])?;
    let voff = s["values"]["byteOffset"].as_u64().unwrap_or(0) as usize;
    let vals = read_dense(vb, voff, 0, (k, n, ct, normalized))?;
    for (j, i) in idx.iter().enumerate() {
        let i = *i as usize;
        if i >= count {
            return None;
        }
        values[i * n..(i + 1) * n].copy_from_slice(&vals[j * n..(j + 1) * n]);
    }
    Some(())
}

/// `f32x3`, `u16_normx2`: an accessor's component type and shape, as `inspect` prints it.
pub fn accessor_type(a: &Value) -> String {
    let comp = match a["componentType"].as_u64().unwrap_or(0) {
        5120 => "i8",
        5121 => "u8",
        5122 => "i16",
        5123 => "u16",
        5125 => "u32",
        5126 => "f32",
        _ => "?",
    };
    let norm = if a["normalized"].as_bool().unwrap_or(false) {
        "_norm"
    } else {
        ""
    };
    let n = match a["type"].as_str().unwrap_or("") {
        "SCALAR" => "",
        "VEC2" => "x2",
        "VEC3" => "x3",
        "VEC4" => "x4",
        "MAT2" => "x2x2",
        "MAT3" => "x3x3",
        "MAT4" => "x4x4",
        _ => "?",
    };
    format!("{comp}{norm}{n}")
}
