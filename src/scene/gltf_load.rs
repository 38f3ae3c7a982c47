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
use super::{
    AlphaMode, Camera, Instance, Light, LightKind, Material, Mesh, Primitive, Sampler, Scene,
    Texture, TextureRef, UvTransform,
};
use glam::{Mat4, Vec2, Vec3, Vec4};
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

    // Buffers.
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
                read_uri(path, &base, uri, &format!("buffer {}", b.index()))?
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
            gltf::image::Source::Uri { uri, .. } => read_uri(path, &base, uri, &what),
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
    let tex_ref = |t: gltf::Texture, transform: UvTransform, tex_coord: u32| {
        image_slots
            .get(t.source().index())
            .copied()
            .flatten()
            .map(|texture| TextureRef {
                texture,
                sampler: Sampler::from_gltf(&t.sampler()),
                transform,
                tex_coord,
            })
    };
    const EXT_TRANSFORM: &str = "KHR_texture_transform";
    let json_transform =
        |v: Option<&serde_json::Value>| v.map(UvTransform::from_json).unwrap_or_default();
    // The transform's texCoord override (JSON), else the textureInfo's own set.
    let json_set = |v: Option<&serde_json::Value>, own: u32| {
        v.and_then(|v| v.get("texCoord"))
            .and_then(|c| c.as_u64())
            .map_or(own, |c| c.min(u32::MAX as u64) as u32)
    };
    // A textureInfo's KHR_texture_transform (identity without one).
    let info_ref = |i: gltf::texture::Info| {
        let transform = i
            .texture_transform()
            .map(|x| UvTransform {
                offset: Vec2::from_array(x.offset()),
                rotation: x.rotation(),
                scale: Vec2::from_array(x.scale()),
            })
            .filter(|x| x.offset.is_finite() && x.rotation.is_finite() && x.scale.is_finite())
            .unwrap_or_default();
        let set = i
            .texture_transform()
            .and_then(|x| x.tex_coord())
            .unwrap_or(i.tex_coord());
        tex_ref(i.texture(), transform, set)
    };

    // Materials (index = glTF index; the default material goes last).
    for m in gltf.materials() {
        let pbr = m.pbr_metallic_roughness();
        let mut mat = Material {
            name: m.name().unwrap_or("").to_string(),
            base_color: Vec4::from_array(pbr.base_color_factor()),
            base_color_texture: pbr.base_color_texture().and_then(info_ref),
            metallic: pbr.metallic_factor(),
            roughness: pbr.roughness_factor(),
            metallic_roughness_texture: pbr.metallic_roughness_texture().and_then(info_ref),
            // gltf 1.4 types the extension on textureInfo only: normal and occlusion textureInfos
            // carry it as JSON.
            normal_texture: m.normal_texture().and_then(|t| {
                let ext = t.extension_value(EXT_TRANSFORM);
                tex_ref(
                    t.texture(),
                    json_transform(ext),
                    json_set(ext, t.tex_coord()),
                )
            }),
            normal_scale: m.normal_texture().map(|t| t.scale()).unwrap_or(1.0),
            // KHR_materials_emissive_strength scales the factor (finite, >= 0; else 1).
            emissive: Vec3::from_array(m.emissive_factor())
                * m.emissive_strength()
                    .filter(|s| s.is_finite() && *s >= 0.0)
                    .unwrap_or(1.0),
            emissive_texture: m.emissive_texture().and_then(info_ref),
            occlusion_texture: m.occlusion_texture().and_then(|t| {
                let ext = t.extension_value(EXT_TRANSFORM);
                tex_ref(
                    t.texture(),
                    json_transform(ext),
                    json_set(ext, t.tex_coord()),
                )
            }),
            occlusion_strength: m
                .occlusion_texture()
                .map(|t| t.strength())
                .filter(|s| s.is_finite())
                .unwrap_or(1.0)
                .clamp(0.0, 1.0),
            alpha_mode: match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
                gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            },
            double_sided: m.double_sided(),
            unlit: m.unlit(),
        };
        if mat.alpha_mode == AlphaMode::Blend {
            let i = m.index().unwrap_or(0);
            scene.warn(
                "MATERIAL_ALPHA_BLEND",
                format!("/materials/{i}"),
                format!(
                    "material {i} '{}': alpha-blended, sorted per draw (not per triangle), \
                     casts where alpha >= 0.5",
                    mat.name
                ),
            );
        }
        if !mat.base_color.is_finite() {
            mat.base_color = Vec4::ONE;
        }
        // TEXCOORD_0 and _1 are loaded; a slot reading another set reads set 0.
        let i = m.index().unwrap_or(0);
        let name = mat.name.clone();
        for (slot, t) in [
            (
                "pbrMetallicRoughness/baseColorTexture",
                &mut mat.base_color_texture,
            ),
            ("normalTexture", &mut mat.normal_texture),
            (
                "pbrMetallicRoughness/metallicRoughnessTexture",
                &mut mat.metallic_roughness_texture,
            ),
            ("emissiveTexture", &mut mat.emissive_texture),
            ("occlusionTexture", &mut mat.occlusion_texture),
        ] {
            if let Some(t) = t.as_mut().filter(|t| t.tex_coord > 1) {
                scene.warn(
                    "TEXCOORD_FALLBACK",
                    format!("/materials/{i}/{slot}"),
                    format!(
                        "material {i} '{name}': {slot} reads TEXCOORD_{}; only sets 0 and 1 \
                         are loaded, set 0 read instead",
                        t.tex_coord
                    ),
                );
                t.tex_coord = 0;
            }
        }
        // Occlusion is drawn from the metallic-roughness texture's red channel (glTF's ORM
        // packing; a separate image is packed in at upload), so it must be sampled alike.
        if let (Some(o), Some(mr)) = (mat.occlusion_texture, mat.metallic_roughness_texture) {
            let size = |t: usize| scene.textures.get(t).map(|t| (t.width, t.height));
            if o.sampler != mr.sampler
                || o.transform != mr.transform
                || o.tex_coord != mr.tex_coord
                || size(o.texture) != size(mr.texture)
            {
                let i = m.index().unwrap_or(0);
                scene.warn(
                    "MATERIAL_OCCLUSION_IGNORED",
                    format!("/materials/{i}/occlusionTexture"),
                    format!(
                        "material {i} '{}': occlusion texture differs from metallic-roughness in \
                         size, sampler, transform or TEXCOORD set; ignored",
                        mat.name
                    ),
                );
                mat.occlusion_texture = None;
            }
        }
        scene.materials.push(mat);
    }
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

    // Node hierarchy.
    scene.node_names = gltf
        .nodes()
        .map(|n| n.name().unwrap_or_default().to_string())
        .collect();
    let roots: Vec<gltf::Node> = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => {
            let mut is_child = vec![false; gltf.nodes().len()];
            for n in gltf.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            gltf.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    let mut stack: Vec<(gltf::Node, Mat4, usize)> =
        roots.into_iter().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    let mut visited = 0usize;
    // What motion needs from the walk: each node's parent, and the nodes lights and cameras
    // hang on.
    let mut parents: Vec<Option<usize>> = vec![None; gltf.nodes().len()];
    let (mut light_nodes, mut camera_nodes) = (Vec::new(), Vec::new());
    while let Some((node, parent, depth)) = stack.pop() {
        visited += 1;
        if depth > 256 || visited > 1_000_000 {
            return Err(corrupt(path, "node hierarchy too deep or cyclic".into()));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            scene.warn(
                "NODE_NONFINITE_TRANSFORM",
                format!("/nodes/{}", node.index()),
                format!("node {} has a non-finite transform; skipped", node.index()),
            );
            continue;
        }
        if let Some(m) = node.mesh() {
            scene.instances.push(Instance {
                mesh: m.index(),
                world_from_model: world,
                node: Some(node.index()),
            });
        }
        if let Some(c) = node.camera() {
            match c.projection() {
                gltf::camera::Projection::Perspective(p) => {
                    // Remove scale from the camera transform.
                    let (_, rot, pos) = world.to_scale_rotation_translation();
                    camera_nodes.push(node.index());
                    scene.cameras.push(Camera {
                        world_from_view: Mat4::from_rotation_translation(rot, pos),
                        fov_y: p.yfov().clamp(0.01, 3.1),
                        near: p.znear().max(1e-6),
                        far: p.zfar(),
                    });
                }
                gltf::camera::Projection::Orthographic(_) => {
                    scene.warn(
                        "CAMERA_ORTHOGRAPHIC",
                        format!("/cameras/{}", c.index()),
                        format!(
                            "camera {} is orthographic; not supported, skipped",
                            c.index()
                        ),
                    );
                }
            }
        }
        if let Some(l) = node.light() {
            let (_, rot, pos) = world.to_scale_rotation_translation();
            let dir = (rot * -Vec3::Z).normalize_or_zero();
            let kind = match l.kind() {
                gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
                gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
                gltf::khr_lights_punctual::Kind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => LightKind::Spot {
                    inner: inner_cone_angle,
                    outer: outer_cone_angle.max(inner_cone_angle + 1e-4),
                },
            };
            let size =
                light_size_extra(l.extras().as_deref().map(|r| r.get())).unwrap_or_else(|e| {
                    scene.warn(
                        "LIGHT_SIZE_INVALID",
                        format!(
                            "/extensions/KHR_lights_punctual/lights/{}/extras",
                            l.index()
                        ),
                        format!("light {}: {e}; the light casts hard shadows", l.index()),
                    );
                    0.0
                });
            light_nodes.push(node.index());
            scene.lights.push(Light {
                kind,
                position: pos,
                direction: dir,
                color: Vec3::from_array(l.color()),
                intensity: l.intensity().max(0.0),
                casts_shadows: true,
                range: l.range().filter(|r| r.is_finite() && *r > 0.0),
                size: if kind == LightKind::Directional {
                    size.to_radians()
                } else {
                    size
                },
            });
        }
        for c in node.children() {
            parents[c.index()] = Some(node.index());
            stack.push((c, world, depth + 1));
        }
    }
    let rig = read_rig(
        &mut scene,
        &gltf,
        &buffers,
        &parents,
        light_nodes,
        camera_nodes,
    );
    if let Some(rig) = rig {
        rest_pose(&mut scene, rig);
    }
    if scene.instances.is_empty() {
        scene.warn("SCENE_EMPTY", "", "the scene has no mesh instances");
    }
    Ok(scene)
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

/// The emitter size in a glTF light's `extras` (`{"light_size": S}`: degrees of angular
/// diameter for a directional light, scene units of radius otherwise); 0 without one.
fn light_size_extra(extras: Option<&str>) -> Result<f32, String> {
    let Some(json) = extras else {
        return Ok(0.0);
    };
    let v: serde_json::Value =
        serde_json::from_str(json).map_err(|e| format!("extras are not JSON: {e}"))?;
    match v.get("light_size") {
        None => Ok(0.0),
        Some(s) => match s.as_f64() {
            Some(x) if x.is_finite() && (0.0..=1e6).contains(&x) => Ok(x as f32),
            _ => Err(format!("extras.light_size {s} is not a number in 0..1e6")),
        },
    }
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
    use super::light_size_extra;

    #[test]
    fn light_size_comes_from_the_lights_extras() {
        assert_eq!(light_size_extra(None), Ok(0.0));
        assert_eq!(light_size_extra(Some(r#"{"other": 1}"#)), Ok(0.0));
        assert_eq!(light_size_extra(Some(r#"{"light_size": 0.53}"#)), Ok(0.53));
        assert!(light_size_extra(Some(r#"{"light_size": -1}"#)).is_err());
        assert!(light_size_extra(Some(r#"{"light_size": "big"}"#)).is_err());
    }
}
