//! A small glTF 2.0 writer for the test corpus: buffers, accessors (dense and sparse), meshes,
//! materials, textures, nodes, cameras and lights, written as `.gltf` + external `.bin` and PNG
//! files, as `.glb` with embedded images, or as `.gltf` with data-URI buffers and images.

use base64::Engine as _;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// How a model's binary data and images are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    /// `NAME.gltf` + `NAME.bin` + one PNG file per image.
    External,
    /// `NAME.glb`: JSON and binary chunks, images in buffer views.
    Glb,
    /// `NAME.gltf` alone: buffer and images as base64 data URIs.
    DataUri,
}

/// glTF component types.
pub const U8: u32 = 5121;
/// Unsigned short.
pub const U16: u32 = 5123;
/// Unsigned int.
pub const U32: u32 = 5125;
/// Float.
pub const F32: u32 = 5126;

/// Builds one glTF document.
#[derive(Default)]
pub struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    textures: Vec<Value>,
    images: Vec<Vec<u8>>,
    samplers: Vec<Value>,
    nodes: Vec<Value>,
    roots: Vec<usize>,
    cameras: Vec<Value>,
    lights: Vec<Value>,
    skins: Vec<Value>,
    animations: Vec<Value>,
    extensions_used: Vec<&'static str>,
}

fn pad4(v: &mut Vec<u8>, byte: u8) {
    while v.len() & 3 != 0 {
        v.push(byte);
    }
}

impl Builder {
    /// A buffer view over `bytes` (target 34962 vertices / 34963 indices, or none).
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        pad4(&mut self.bin, 0);
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// A float accessor of `ty` ("VEC3", …) over `data` (with min/max for VEC3 positions).
    pub fn floats(&mut self, data: &[f32], comps: usize, ty: &str) -> usize {
        let view = self.view(bytemuck::cast_slice(data), Some(34962));
        let mut a = json!({"bufferView": view, "componentType": F32, "count": data.len() / comps, "type": ty});
        if ty == "VEC3" {
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for p in data.chunks_exact(3) {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// The JSON of accessor `i`, to break on purpose.
    pub fn accessor_mut(&mut self, i: usize) -> &mut Value {
        &mut self.accessors[i]
    }

    /// An index accessor of component type `ctype` (U8, U16 or U32).
    pub fn indices(&mut self, idx: &[u32], ctype: u32) -> usize {
        let bytes: Vec<u8> = match ctype {
            U8 => idx.iter().map(|&i| i as u8).collect(),
            U16 => idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
            _ => idx.iter().flat_map(|&i| i.to_le_bytes()).collect(),
        };
        let view = self.view(&bytes, Some(34963));
        self.accessors.push(
            json!({"bufferView": view, "componentType": ctype, "count": idx.len(), "type": "SCALAR"}),
        );
        self.accessors.len() - 1
    }

    /// A VEC3 float accessor: `base` (None = all zeros, no buffer view) with the elements at
    /// `sparse` indices replaced by the given values (u16 sparse indices).
    pub fn sparse_vec3(
        &mut self,
        count: usize,
        base: Option<&[f32]>,
        sparse: &[(u16, [f32; 3])],
    ) -> usize {
        let mut full: Vec<f32> = base.map_or(vec![0.0; count * 3], |b| b.to_vec());
        for (i, v) in sparse {
            full[*i as usize * 3..*i as usize * 3 + 3].copy_from_slice(v);
        }
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in full.chunks_exact(3) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let idx: Vec<u8> = sparse.iter().flat_map(|(i, _)| i.to_le_bytes()).collect();
        let vals: Vec<f32> = sparse.iter().flat_map(|(_, v)| *v).collect();
        let iv = self.view(&idx, None);
        let vv = self.view(bytemuck::cast_slice(&vals), None);
        let mut a = json!({
            "componentType": F32, "count": count, "type": "VEC3", "min": lo, "max": hi,
            "sparse": {"count": sparse.len(),
                       "indices": {"bufferView": iv, "componentType": U16},
                       "values": {"bufferView": vv}}
        });
        if let Some(b) = base {
            a["bufferView"] = json!(self.view(bytemuck::cast_slice(b), Some(34962)));
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// A PNG image; returns the image index.
    pub fn image(&mut self, png: Vec<u8>) -> usize {
        self.images.push(png);
        self.images.len() - 1
    }

    /// A sampler (glTF filter and wrap enums).
    pub fn sampler(&mut self, mag: u32, min: u32, wrap_s: u32, wrap_t: u32) -> usize {
        self.samplers
            .push(json!({"magFilter": mag, "minFilter": min, "wrapS": wrap_s, "wrapT": wrap_t}));
        self.samplers.len() - 1
    }

    /// A texture of `image` with `sampler`.
    pub fn texture(&mut self, image: usize, sampler: Option<usize>) -> usize {
        let mut t = json!({"source": image});
        if let Some(s) = sampler {
            t["sampler"] = json!(s);
        }
        self.textures.push(t);
        self.textures.len() - 1
    }

    /// A material from its JSON object.
    pub fn material(&mut self, m: Value) -> usize {
        self.materials.push(m);
        self.materials.len() - 1
    }

    /// A mesh from its primitives' JSON objects.
    pub fn mesh(&mut self, name: &str, primitives: Vec<Value>) -> usize {
        self.meshes
            .push(json!({"name": name, "primitives": primitives}));
        self.meshes.len() - 1
    }

    /// The JSON of mesh `i` (to add `weights`, say).
    pub fn mesh_mut(&mut self, i: usize) -> &mut Value {
        &mut self.meshes[i]
    }

    /// A node from its JSON object; `root` nodes are listed in the scene.
    pub fn node(&mut self, n: Value, root: bool) -> usize {
        self.nodes.push(n);
        if root {
            self.roots.push(self.nodes.len() - 1);
        }
        self.nodes.len() - 1
    }

    /// A skin from its JSON object (`joints`, `inverseBindMatrices`).
    pub fn skin(&mut self, s: Value) -> usize {
        self.skins.push(s);
        self.skins.len() - 1
    }

    /// An animation from its JSON object (`channels`, `samplers`).
    pub fn animation(&mut self, a: Value) -> usize {
        self.animations.push(a);
        self.animations.len() - 1
    }

    /// A JOINTS_0 accessor (u16 VEC4) over `joints`.
    pub fn joints(&mut self, joints: &[[u16; 4]]) -> usize {
        let view = self.view(bytemuck::cast_slice(joints), Some(34962));
        self.accessors.push(
            json!({"bufferView": view, "componentType": U16, "count": joints.len(), "type": "VEC4"}),
        );
        self.accessors.len() - 1
    }

    /// A float accessor without a vertex target (animation inputs and outputs, inverse bind
    /// matrices), with min/max for scalars (glTF requires them on animation inputs).
    pub fn data(&mut self, data: &[f32], comps: usize, ty: &str) -> usize {
        let view = self.view(bytemuck::cast_slice(data), None);
        let mut a = json!({"bufferView": view, "componentType": F32, "count": data.len() / comps, "type": ty});
        if ty == "SCALAR" && !data.is_empty() {
            let lo = data.iter().copied().fold(f32::MAX, f32::min);
            let hi = data.iter().copied().fold(f32::MIN, f32::max);
            a["min"] = json!([lo]);
            a["max"] = json!([hi]);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// A perspective camera.
    pub fn camera(&mut self, yfov: f32, znear: f32, zfar: Option<f32>) -> usize {
        let mut p = json!({"yfov": yfov, "znear": znear});
        if let Some(f) = zfar {
            p["zfar"] = json!(f);
        }
        self.cameras
            .push(json!({"type": "perspective", "perspective": p}));
        self.cameras.len() - 1
    }

    /// An orthographic camera.
    pub fn camera_orthographic(&mut self, xmag: f32, ymag: f32, znear: f32, zfar: f32) -> usize {
        self.cameras.push(json!({"type": "orthographic",
            "orthographic": {"xmag": xmag, "ymag": ymag, "znear": znear, "zfar": zfar}}));
        self.cameras.len() - 1
    }

    /// A mesh `name` of one `w`×`h` quad in the XY plane facing +Z, centred on its node, with
    /// texture coordinates (v down the image) and `material`: triangle 0 its lower-right half,
    /// triangle 1 its upper-left.
    pub fn quad(&mut self, name: &str, w: f32, h: f32, material: usize) -> usize {
        let (x, y) = (w * 0.5, h * 0.5);
        let p = self.floats(&[-x, -y, 0.0, x, -y, 0.0, x, y, 0.0, -x, y, 0.0], 3, "VEC3");
        let n = self.floats(&[0.0, 0.0, 1.0].repeat(4), 3, "VEC3");
        let uv = self.floats(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0], 2, "VEC2");
        let i = self.indices(&[0, 1, 2, 0, 2, 3], U16);
        self.mesh(
            name,
            vec![
                json!({"attributes": {"POSITION": p, "NORMAL": n, "TEXCOORD_0": uv},
                        "indices": i, "material": material}),
            ],
        )
    }

    /// A KHR_lights_punctual light from its JSON object.
    pub fn light(&mut self, l: Value) -> usize {
        self.use_extension("KHR_lights_punctual");
        self.lights.push(l);
        self.lights.len() - 1
    }

    /// Lists an extension in `extensionsUsed`.
    pub fn use_extension(&mut self, name: &'static str) {
        if !self.extensions_used.contains(&name) {
            self.extensions_used.push(name);
        }
    }

    /// Writes the model into `dir` as `name` in `container`; returns the main file's path.
    pub fn write(mut self, dir: &Path, name: &str, container: Container) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let mut images = Vec::new();
        for (i, png) in std::mem::take(&mut self.images).into_iter().enumerate() {
            images.push(match container {
                Container::Glb => {
                    let v = self.view(&png, None);
                    json!({"bufferView": v, "mimeType": "image/png"})
                }
                Container::DataUri => json!({"uri": format!(
                    "data:image/png;base64,{}",
                    base64::engine::general_purpose::STANDARD.encode(&png)
                )}),
                Container::External => {
                    let file = format!("{name}_image{i}.png");
                    write_atomic(&dir.join(&file), &png);
                    json!({"uri": file})
                }
            });
        }
        pad4(&mut self.bin, 0);
        let buffer = match container {
            Container::Glb => json!({"byteLength": self.bin.len()}),
            Container::DataUri => json!({"byteLength": self.bin.len(), "uri": format!(
                "data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&self.bin)
            )}),
            Container::External => {
                let file = format!("{name}.bin");
                write_atomic(&dir.join(&file), &self.bin);
                json!({"byteLength": self.bin.len(), "uri": file})
            }
        };
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "umbra test corpus"},
            "scene": 0,
            "scenes": [{"nodes": self.roots}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [buffer],
        });
        for (key, v) in [
            ("materials", self.materials),
            ("textures", self.textures),
            ("samplers", self.samplers),
            ("cameras", self.cameras),
            ("images", images),
            ("skins", self.skins),
            ("animations", self.animations),
        ] {
            if !v.is_empty() {
                doc[key] = Value::Array(v);
            }
        }
        if !self.lights.is_empty() {
            doc["extensions"] = json!({"KHR_lights_punctual": {"lights": self.lights}});
        }
        if !self.extensions_used.is_empty() {
            doc["extensionsUsed"] = json!(self.extensions_used);
        }
        let text = serde_json::to_vec_pretty(&doc).unwrap();
        match container {
            Container::Glb => {
                let mut j = text;
                pad4(&mut j, b' ');
                let total = 12 + 8 + j.len() + 8 + self.bin.len();
                let mut out = Vec::with_capacity(total);
                out.extend_from_slice(b"glTF");
                out.extend_from_slice(&2u32.to_le_bytes());
                out.extend_from_slice(&(total as u32).to_le_bytes());
                out.extend_from_slice(&(j.len() as u32).to_le_bytes());
                out.extend_from_slice(b"JSON");
                out.extend_from_slice(&j);
                out.extend_from_slice(&(self.bin.len() as u32).to_le_bytes());
                out.extend_from_slice(b"BIN\0");
                out.extend_from_slice(&self.bin);
                let p = dir.join(format!("{name}.glb"));
                write_atomic(&p, &out);
                p
            }
            _ => {
                let p = dir.join(format!("{name}.gltf"));
                write_atomic(&p, &text);
                p
            }
        }
    }
}

/// Writes `bytes` to `path` through a uniquely named file and a rename, so a test that reads
/// `path` while another test (run in parallel) writes the same model sees the old file or the
/// new one, never a truncated one.
fn write_atomic(path: &Path, bytes: &[u8]) {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let tmp = path.with_extension(format!("tmp{}-{n}", std::process::id()));
    std::fs::write(&tmp, bytes).unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

/// PNG bytes of an RGBA image.
pub fn png(img: &image::RgbaImage) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}
