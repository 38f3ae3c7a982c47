//! glTF 2.0 import (`.gltf` with external or data-URI resources, and `.glb`) into a [`Scene`].
//!
//! Untrusted input: every accessor is bounds-checked against its buffer view and buffer before it
//! is read, indices are checked against the vertex count, external files must resolve inside the
//! model's folder, and any remaining panic inside the parser is turned into an error.

use super::error::LoadError;
use super::error::{corrupt, invalid, MAX_FILE_BYTES};
use super::input::{check_accessor, check_references, decode_image, json_part, read_uri};
use crate::scene::anim::load::{check_joint_ranges, read_rig};
use crate::scene::{Material, Mesh, Scene, Texture};
use std::path::{Path, PathBuf};

/// Loads a `.gltf` or `.glb` file into a scene.
pub fn load_gltf(path: &Path) -> Result<Scene, LoadError> {
    let meta = std::fs::metadata(path).map_err(|e| LoadError::Io {
        path: path.into(),
        cause: e,
    })?;
    if meta.is_dir() {
        return Err(LoadError::Io {
            path: path.into(),
            cause: std::io::Error::other("is a directory, not a glTF file"),
        });
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(LoadError::Corrupt {
            path: path.into(),
            message: format!("file is {} bytes, over the limit", meta.len()),
        });
    }
    let bytes = std::fs::read(path).map_err(|e| LoadError::Io {
        path: path.into(),
        cause: e,
    })?;
    if bytes.is_empty() {
        return Err(LoadError::Empty(path.into()));
    }
    let p = path.to_path_buf();
    // The gltf crate is trusted not to panic, but a user's file must never crash us.
    match std::panic::catch_unwind(|| load_bytes(&p, &bytes)) {
        Ok(r) => r,
        Err(_) => Err(LoadError::Corrupt {
            path: path.into(),
            message: "malformed data (parser failure)".into(),
        }),
    }
}

fn load_bytes(path: &Path, bytes: &[u8]) -> Result<Scene, LoadError> {
    check_references(path, json_part(path, bytes)?)?;
    let base = path
        .parent()
        .map(|p| p.to_path_buf())
        .unwrap_or_else(|| PathBuf::from("."));
    let base = if base.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        base
    };
    // Compressed and quantized data decoded, required extensions resolved: plain glTF from here.
    let prepared = super::compressed::prepare(path, bytes, &base)?;
    let root: gltf::json::Root =
        serde_json::from_value(prepared.json).map_err(|e| invalid(path, e))?;
    let gltf = gltf::Gltf {
        document: gltf::Document::from_json(root).map_err(|e| invalid(path, e))?,
        blob: None,
    };
    let buffers = check_buffers(path, &gltf, prepared.buffers)?;
    let mut scene = Scene {
        name: path
            .file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default(),
        compression: prepared.report,
        ..Default::default()
    };

    let image_slots = read_images(path, &gltf, &buffers, &base, &mut scene)?;
    super::material::read_materials(&gltf, &image_slots, &mut scene);
    let default_material = scene.materials.len();
    scene.materials.push(Material::default());

    // Meshes.
    for mesh in gltf.meshes() {
        let mut out = Mesh {
            name: mesh.name().unwrap_or("").to_string(),
            primitives: Vec::new(),
        };
        for prim in mesh.primitives() {
            if let Some(p) = super::primitive::read_primitive(
                path,
                &mut scene,
                &buffers,
                &mesh,
                &prim,
                default_material,
            )? {
                out.primitives.push(p);
            }
        }
        scene.meshes.push(out);
    }

    let walk = super::nodes::walk_nodes(path, &gltf, &mut scene)?;
    let rig = read_rig(
        &mut scene,
        &gltf,
        &buffers,
        &walk.parents,
        walk.light_nodes,
        walk.camera_nodes,
    );
    if let Some(rig) = rig {
        rest_pose(&mut scene, rig);
    }
    if scene.instances.is_empty() {
        scene.warn("SCENE_EMPTY", "", "the scene has no mesh instances");
    }
    Ok(scene)
}

/// Checks every buffer view and accessor against the buffers' bytes.
fn check_buffers(
    path: &Path,
    gltf: &gltf::Gltf,
    buffers: Vec<Vec<u8>>,
) -> Result<Vec<Vec<u8>>, LoadError> {
    for v in gltf.views() {
        let end = v.offset().checked_add(v.length());
        let data = buffers.get(v.buffer().index()).map_or(0, |b| b.len());
        if end.is_none_or(|e| e > data) {
            return Err(corrupt(
                path,
                format!(
                    "buffer view {} reads past the end of buffer {}",
                    v.index(),
                    v.buffer().index()
                ),
            ));
        }
    }
    for a in gltf.accessors() {
        check_accessor(path, &a)?;
    }
    Ok(buffers)
}

/// Reads and decodes every image; returns the texture index of each glTF image (`None` where it
/// could not be loaded: a warning, and the material slot falls back).
fn read_images(
    path: &Path,
    gltf: &gltf::Gltf,
    buffers: &[Vec<u8>],
    base: &Path,
    scene: &mut Scene,
) -> Result<Vec<Option<usize>>, LoadError> {
    // Images (decoded once; a broken image becomes a warning and the material slot falls back).
    // Read in order, then decoded in parallel (PNG/JPEG decoding dominates loading textured
    // models), then recorded in order so warnings and texture indices do not depend on timing.
    let mut sources: Vec<ImageSource> = Vec::new();
    for img in gltf.images() {
        let what = format!("image {}", img.index());
        let data = match img.source() {
            gltf::image::Source::View { view, .. } => {
                let buf = &buffers[view.buffer().index()];
                Ok(buf[view.offset()..view.offset() + view.length()].to_vec())
            }
            gltf::image::Source::Uri { uri, .. } => read_uri(path, base, uri, &what),
        };
        if let Err(e @ LoadError::OutsideFolder { .. }) = data {
            return Err(e);
        }
        sources.push((img.name().unwrap_or(&what).to_string(), what, data));
    }
    let decoded = decode_all(&sources);
    let mut image_slots: Vec<Option<usize>> = Vec::new();
    for (i, ((name, what, data), (result, seconds))) in sources.iter().zip(decoded).enumerate() {
        if let (Ok(d), Ok((w, h, _))) = (data, &result) {
            let pixels = *w as usize * *h as usize * 4;
            scene.compression.add_image(i, d, pixels, seconds);
        }
        let image = format!("/images/{i}");
        match (data, result) {
            (Err(e), _) => {
                scene.warn(
                    "IMAGE_NOT_LOADED",
                    image,
                    format!("{what} not loaded ({e}); using a default"),
                );
                image_slots.push(None);
            }
            (Ok(d), Ok((w, h, rgba))) => {
                scene.textures.push(Texture {
                    name: name.clone(),
                    width: w,
                    height: h,
                    rgba,
                    ktx2: super::compressed::is_ktx2(d).then(|| d.as_slice().into()),
                });
                image_slots.push(Some(scene.textures.len() - 1));
            }
            (Ok(_), Err(msg)) => {
                scene.warn(
                    "IMAGE_NOT_LOADED",
                    image,
                    format!("{what} could not be decoded ({msg}); using a default"),
                );
                image_slots.push(None);
            }
        }
    }
    scene.image_textures = image_slots.clone();
    Ok(image_slots)
}

/// Gives each instance of a deforming mesh past the first its own copy (each is posed on its
/// own), checks joint ranges, and poses the scene at rest: skins applied and default morph
/// weights, node transforms as the walk computed them.
fn rest_pose(scene: &mut Scene, rig: crate::scene::anim::Rig) {
    let mut used = vec![false; scene.meshes.len()];
    for i in 0..scene.instances.len() {
        let m = scene.instances[i].mesh;
        let deforms = scene.meshes[m]
            .primitives
            .iter()
            .any(|p| p.deform.is_some());
        if deforms && std::mem::replace(&mut used[m], true) {
            scene.meshes.push(scene.meshes[m].clone());
            scene.instances[i].mesh = scene.meshes.len() - 1;
        }
    }
    check_joint_ranges(scene, &rig);
    let pose = rig.pose(&crate::scene::anim::Playing::Rest, 0.0);
    scene.apply_pose(&rig, &pose, false);
    scene.rig = Some(std::sync::Arc::new(rig));
}

/// An image's name, its label for messages ("image 3") and its encoded bytes (or why not).
type ImageSource = (String, String, Result<Vec<u8>, LoadError>);
/// A decoded image (width, height, RGBA8) or why it could not be decoded.
type Decoded = Result<(u32, u32, Vec<u8>), String>;

/// Decodes every readable image, on as many threads as the machine has (in order), each with
/// the seconds it took.
fn decode_all(sources: &[ImageSource]) -> Vec<(Decoded, f64)> {
    crate::parallel::map(sources, |(_, _, data)| {
        let start = std::time::Instant::now();
        let r = match data {
            Ok(d) if super::compressed::is_ktx2(d) => super::compressed::decode_ktx2(d),
            Ok(d) => decode_image(d),
            Err(_) => Err(String::new()),
        };
        (r, start.elapsed().as_secs_f64())
    })
}

#[cfg(test)]
mod tests {
    use super::super::nodes::light_size_extra;

    #[test]
    fn light_size_comes_from_the_lights_extras() {
        assert_eq!(light_size_extra(None), Ok(0.0));
        assert_eq!(light_size_extra(Some(r#"{"other": 1}"#)), Ok(0.0));
        assert_eq!(light_size_extra(Some(r#"{"light_size": 0.53}"#)), Ok(0.53));
        assert!(light_size_extra(Some(r#"{"light_size": -1}"#)).is_err());
        assert!(light_size_extra(Some(r#"{"light_size": "big"}"#)).is_err());
    }
}
