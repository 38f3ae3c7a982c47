//! glTF 2.0 import (`.gltf` with external or data-URI resources, and `.glb`) into a [`Scene`].
//!
//! Untrusted input: every accessor is bounds-checked against its buffer view and buffer before it
//! is read, indices are checked against the vertex count, external files must resolve inside the
//! model's folder, and any remaining panic inside the parser is turned into an error.

use super::anim::load::{check_joint_ranges, read_rig};
use super::gltf_input::{
    check_accessor, check_attribute_types, check_references, decode_image, json_part, read_uri,
};
use super::load_error::{corrupt, invalid, MAX_FILE_BYTES};
pub use super::load_error::{LoadError, MAX_TEXTURE_SIDE};
use super::tangents::{
    compute_smooth_normals, count_degenerate, fallback_tangent, generate_mikktspace,
};
use super::{Material, Mesh, Primitive, Scene, Texture};
use glam::{Vec2, Vec3, Vec4};
use std::path::{Path, PathBuf};

/// Extensions that may appear in `extensionsRequired`.
const SUPPORTED_REQUIRED: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "KHR_lights_punctual",
    "KHR_texture_transform",
];

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
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| invalid(path, e))?;
    for ext in gltf.extensions_required() {
        if !SUPPORTED_REQUIRED.contains(&ext) {
            return Err(LoadError::UnsupportedExtension {
                path: path.into(),
                extension: ext.to_string(),
            });
        }
    }
    let base = path
        .parent()
        .map(|p| p.to_path_buf())
        .unwrap_or_else(|| PathBuf::from("."));
    let base = if base.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        base
    };
    let mut scene = Scene {
        name: path
            .file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default(),
        ..Default::default()
    };

    let buffers = read_buffers(path, &gltf, &base)?;
    let image_slots = read_images(path, &gltf, &buffers, &base, &mut scene)?;
    super::gltf_material::read_materials(&gltf, &image_slots, &mut scene);
    let default_material = scene.materials.len();
    scene.materials.push(Material::default());

    // Meshes.
    for mesh in gltf.meshes() {
        let mut out = Mesh {
            name: mesh.name().unwrap_or("").to_string(),
            primitives: Vec::new(),
        };
        for prim in mesh.primitives() {
            if let Some(p) =
                read_primitive(path, &mut scene, &buffers, &mesh, &prim, default_material)?
            {
                out.primitives.push(p);
            }
        }
        scene.meshes.push(out);
    }

    let walk = super::gltf_nodes::walk_nodes(path, &gltf, &mut scene)?;
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

/// Reads every buffer (the GLB chunk or a URI inside the model's folder) and checks every
/// buffer view and accessor against them.
fn read_buffers(path: &Path, gltf: &gltf::Gltf, base: &Path) -> Result<Vec<Vec<u8>>, LoadError> {
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for b in gltf.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                corrupt(
                    path,
                    format!(
                        "buffer {} refers to a GLB binary chunk that is missing",
                        b.index()
                    ),
                )
            })?,
            gltf::buffer::Source::Uri(uri) => {
                read_uri(path, base, uri, &format!("buffer {}", b.index()))?
            }
        };
        if data.len() < b.length() {
            return Err(corrupt(
                path,
                format!(
                    "buffer {} holds {} bytes but declares {}",
                    b.index(),
                    data.len(),
                    b.length()
                ),
            ));
        }
        buffers.push(data);
    }
    for v in gltf.views() {
        let end = v.offset().checked_add(v.length());
        if end.is_none_or(|e| e > buffers[v.buffer().index()].len()) {
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
    for (i, ((name, what, data), result)) in sources.iter().zip(decoded).enumerate() {
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
            (Ok(_), Ok((w, h, rgba))) => {
                scene.textures.push(Texture {
                    name: name.clone(),
                    width: w,
                    height: h,
                    rgba,
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

/// Decodes every readable image, on as many threads as the machine has (in order).
fn decode_all(sources: &[ImageSource]) -> Vec<Decoded> {
    crate::parallel::map(sources, |(_, _, data)| match data {
        Ok(d) => decode_image(d),
        Err(_) => Err(String::new()),
    })
}

/// How far from 1 a stored normal's or tangent's length may be (glTF-Validator allows 4e-3;
/// quantised normals land within it).
const UNIT_TOLERANCE: f32 = 4e-3;

/// Whether a stored vector's length is 1 within `UNIT_TOLERANCE` (NaN is not).
fn unit_length(len: f32) -> bool {
    (len - 1.0).abs() <= UNIT_TOLERANCE
}

/// Warns when a POSITION accessor's declared min/max (required by glTF) differ from its data.
fn check_min_max(scene: &mut Scene, acc: &gltf::Accessor, positions: &[Vec3]) {
    let declared = |v: Option<gltf::json::Value>| -> Option<Vec3> {
        let a = v?
            .as_array()?
            .iter()
            .map(|x| x.as_f64())
            .collect::<Option<Vec<f64>>>()?;
        (a.len() == 3).then(|| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32))
    };
    let (Some(lo), Some(hi)) = (declared(acc.min()), declared(acc.max())) else {
        return;
    };
    let finite = positions.iter().filter(|p| p.is_finite());
    let (dlo, dhi) = finite.fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(a, b), p| (a.min(*p), b.max(*p)),
    );
    if dlo.x > dhi.x {
        return;
    }
    // Declared values are decimal text: allow a relative 1e-5 of the extent.
    let tol = ((dhi - dlo).max_element() * 1e-5).max(1e-6);
    let off = (lo - dlo).abs().max((hi - dhi).abs()).max_element();
    if off > tol {
        scene.warn(
            "ACCESSOR_MIN_MAX_MISMATCH",
            format!("/accessors/{}", acc.index()),
            format!(
                "accessor {}: declared POSITION bounds [{lo}, {hi}] differ from the data's \
                 [{dlo}, {dhi}] (by {off:.3e}); umbra uses the data",
                acc.index()
            ),
        );
    }
}

fn read_primitive(
    path: &Path,
    scene: &mut Scene,
    buffers: &[Vec<u8>],
    mesh: &gltf::Mesh,
    prim: &gltf::Primitive,
    default_material: usize,
) -> Result<Option<Primitive>, LoadError> {
    use gltf::mesh::Mode;
    let label = format!("mesh {} primitive {}", mesh.index(), prim.index());
    let at = format!("/meshes/{}/primitives/{}", mesh.index(), prim.index());
    check_attribute_types(path, &label, prim)?;
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
    let Some(positions) = reader.read_positions() else {
        scene.warn(
            "MESH_NO_POSITION",
            at,
            format!("{label} has no POSITION; skipped"),
        );
        return Ok(None);
    };
    let positions: Vec<Vec3> = positions.map(Vec3::from_array).collect();
    let n = positions.len();
    if let Some(acc) = prim.get(&gltf::Semantic::Positions) {
        check_min_max(scene, &acc, &positions);
    }
    if prim.attributes().any(|(_, a)| a.count() != n) {
        return Err(corrupt(path, format!("{label}: attribute counts differ")));
    }
    let raw_indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if let Some(bad) = raw_indices.iter().find(|&&i| i as usize >= n) {
        return Err(corrupt(
            path,
            format!("{label}: index {bad} out of range (vertex count {n})"),
        ));
    }
    let indices: Vec<u32> = match prim.mode() {
        Mode::Triangles => raw_indices.chunks_exact(3).flatten().copied().collect(),
        Mode::TriangleStrip => (2..raw_indices.len())
            .flat_map(|i| {
                if i % 2 == 0 {
                    [raw_indices[i - 2], raw_indices[i - 1], raw_indices[i]]
                } else {
                    [raw_indices[i - 1], raw_indices[i - 2], raw_indices[i]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..raw_indices.len())
            .flat_map(|i| [raw_indices[0], raw_indices[i - 1], raw_indices[i]])
            .collect(),
        other => {
            scene.warn(
                "MESH_UNSUPPORTED_MODE",
                at,
                format!("{label}: mode {other:?} is not drawn (triangles only)"),
            );
            return Ok(None);
        }
    };
    // Drop triangles touching non-finite positions.
    let before = indices.len() / 3;
    let indices: Vec<u32> = indices
        .chunks_exact(3)
        .filter(|t| t.iter().all(|&i| positions[i as usize].is_finite()))
        .flatten()
        .copied()
        .collect();
    if indices.len() / 3 != before {
        scene.warn(
            "MESH_NONFINITE_POSITIONS",
            at.clone(),
            format!(
                "{label}: {} triangles with non-finite positions dropped",
                before - indices.len() / 3
            ),
        );
    }
    let degenerate = count_degenerate(&positions, &indices);
    if degenerate > 0 {
        scene.warn(
            "MESH_DEGENERATE_TRIANGLES",
            at.clone(),
            format!("{label}: {degenerate} zero-area triangles"),
        );
    }
    let has_normals = prim.get(&gltf::Semantic::Normals).is_some();
    let normals: Vec<Vec3> = match reader.read_normals() {
        Some(it) => {
            let mut off_unit = 0usize;
            let normals = it
                .map(|v| {
                    let v = Vec3::from_array(v);
                    if !unit_length(v.length()) {
                        off_unit += 1;
                    }
                    v.try_normalize().unwrap_or(Vec3::Y)
                })
                .collect();
            if off_unit > 0 {
                scene.warn(
                    "MESH_NORMALS_NOT_UNIT",
                    format!("{at}/attributes/NORMAL"),
                    format!(
                        "{label}: {off_unit} of {n} normals are not unit length (|n| off 1 by \
                         more than {UNIT_TOLERANCE}); normalised"
                    ),
                );
            }
            normals
        }
        None => {
            scene.warn(
                "MESH_NORMALS_MISSING",
                at.clone(),
                format!("{label}: no normals; computed smooth normals"),
            );
            compute_smooth_normals(&positions, &indices)
        }
    };
    let (uvs, has_uvs): (Vec<Vec2>, bool) = match reader.read_tex_coords(0) {
        Some(it) => (
            it.into_f32()
                .map(|v| {
                    let v = Vec2::from_array(v);
                    if v.is_finite() {
                        v
                    } else {
                        Vec2::ZERO
                    }
                })
                .collect(),
            true,
        ),
        None => (vec![Vec2::ZERO; n], false),
    };
    // TEXCOORD_1, for slots that read it (non-finite values read as 0).
    let uvs1: Vec<Vec2> = match reader.read_tex_coords(1) {
        Some(it) => it
            .into_f32()
            .map(Vec2::from_array)
            .map(|v| if v.is_finite() { v } else { Vec2::ZERO })
            .collect(),
        None => Vec::new(),
    };
    let uvs1 = if uvs1.is_empty() || uvs1.len() == n {
        uvs1
    } else {
        scene.warn(
            "TEXCOORD_FALLBACK",
            at.clone(),
            format!(
                "{label}: TEXCOORD_1 has {} values for {n} vertices; set 0 read instead",
                uvs1.len()
            ),
        );
        Vec::new()
    };
    // COLOR_0 multiplies the base colour (RGB gets alpha 1); NaN reads as white.
    let colors: Vec<Vec4> = match reader.read_colors(0) {
        Some(c) => {
            let c: Vec<Vec4> = c
                .into_rgba_f32()
                .map(|c| Vec4::from_array(c).clamp(Vec4::ZERO, Vec4::ONE))
                .map(|c| if c.is_nan() { Vec4::ONE } else { c })
                .collect();
            if c.len() == n {
                c
            } else {
                scene.warn(
                    "MESH_COLORS_IGNORED",
                    at.clone(),
                    format!(
                        "{label}: COLOR_0 has {} values for {n} vertices, ignored",
                        c.len()
                    ),
                );
                Vec::new()
            }
        }
        None => Vec::new(),
    };
    let deform = super::anim::load::read_deform(scene, &reader, n, &at, &label);
    let material = prim.material().index().unwrap_or(default_material);
    let mut p = Primitive {
        positions,
        normals,
        uvs,
        tangents: Vec::new(),
        indices,
        material,
        has_uvs,
        colors,
        uvs1,
        deform: deform.map(Box::new),
    };
    let wants_normal_map = scene.materials[material].normal_texture.is_some();
    match reader.read_tangents() {
        Some(it) => {
            let (mut bad_w, mut off_unit) = (0usize, 0usize);
            p.tangents = it
                .map(|t| {
                    let t = Vec4::from_array(t);
                    bad_w += (t.w != 1.0 && t.w != -1.0) as usize;
                    off_unit += !unit_length(t.truncate().length()) as usize;
                    if t.is_finite() && t.truncate().length_squared() > 1e-12 {
                        t.truncate()
                            .normalize()
                            .extend(if t.w < 0.0 { -1.0 } else { 1.0 })
                    } else {
                        Vec4::new(1.0, 0.0, 0.0, 1.0)
                    }
                })
                .collect();
            if bad_w > 0 || off_unit > 0 {
                scene.warn(
                    "MESH_TANGENTS_INVALID",
                    format!("{at}/attributes/TANGENT"),
                    format!(
                        "{label}: of {n} tangents, {bad_w} have w other than ±1 (the sign is \
                         kept) and {off_unit} xyz not of unit length (normalised)"
                    ),
                );
            }
        }
        None if wants_normal_map && has_uvs => {
            if !generate_mikktspace(&mut p) {
                scene.warn(
                    "MESH_TANGENTS_FAILED",
                    at.clone(),
                    format!(
                        "{label}: MikkTSpace tangent generation failed; normal map may be wrong"
                    ),
                );
            }
        }
        None => p.tangents = p.normals.iter().map(|n| fallback_tangent(*n)).collect(),
    }
    if wants_normal_map && !has_uvs {
        scene.warn(
            "NORMAL_MAP_WITHOUT_UVS",
            at,
            format!("{label}: normal map ignored: the primitive has no TEXCOORD_0"),
        );
        let mut m = scene.materials[material].clone();
        m.normal_texture = None;
        m.name = format!("{} (no UVs)", m.name);
        scene.materials.push(m);
        p.material = scene.materials.len() - 1;
    }
    if let Some(d) = p.deform.as_deref_mut() {
        d.positions = p.positions.clone();
        d.normals = p.normals.clone();
        d.tangents = p.tangents.clone();
        d.normals_computed = !has_normals;
    }
    Ok(Some(p))
}

#[cfg(test)]
mod tests {
    use super::super::gltf_nodes::light_size_extra;

    #[test]
    fn light_size_comes_from_the_lights_extras() {
        assert_eq!(light_size_extra(None), Ok(0.0));
        assert_eq!(light_size_extra(Some(r#"{"other": 1}"#)), Ok(0.0));
        assert_eq!(light_size_extra(Some(r#"{"light_size": 0.53}"#)), Ok(0.53));
        assert!(light_size_extra(Some(r#"{"light_size": -1}"#)).is_err());
        assert!(light_size_extra(Some(r#"{"light_size": "big"}"#)).is_err());
    }
}
