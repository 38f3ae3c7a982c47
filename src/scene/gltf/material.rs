//! glTF materials into the scene's: factors, textures with their KHR_texture_transform and
//! texture-coordinate set, alpha modes, and the findings a material can raise.

use crate::scene::{AlphaMode, Material, Sampler, Scene, TextureRef, UvTransform};
use glam::{Vec2, Vec3, Vec4};

const EXT_TRANSFORM: &str = "KHR_texture_transform";

/// Appends a material per glTF material (index = glTF index), textures resolved through
/// `image_slots` (`read_images`).
pub(super) fn read_materials(gltf: &gltf::Gltf, image_slots: &[Option<usize>], scene: &mut Scene) {
    for m in gltf.materials() {
        let mut mat = read_material(&m, image_slots);
        let i = m.index().unwrap_or(0);
        if mat.alpha_mode == AlphaMode::Blend {
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
        texcoord_fallback(scene, i, &mut mat);
        check_occlusion(scene, i, &mut mat);
        scene.materials.push(mat);
    }
}

/// The material's factors and texture references as the file states them.
fn read_material(m: &gltf::Material, slots: &[Option<usize>]) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let info = |i: gltf::texture::Info| info_ref(slots, i);
    Material {
        name: m.name().unwrap_or("").to_string(),
        base_color: Vec4::from_array(pbr.base_color_factor()),
        base_color_texture: pbr.base_color_texture().and_then(info),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        metallic_roughness_texture: pbr.metallic_roughness_texture().and_then(info),
        // gltf 1.4 types the extension on textureInfo only: normal and occlusion textureInfos
        // carry it as JSON.
        normal_texture: m.normal_texture().and_then(|t| {
            json_ref(
                slots,
                t.texture(),
                t.extension_value(EXT_TRANSFORM),
                t.tex_coord(),
            )
        }),
        normal_scale: m.normal_texture().map(|t| t.scale()).unwrap_or(1.0),
        // KHR_materials_emissive_strength scales the factor (finite, >= 0; else 1).
        emissive: Vec3::from_array(m.emissive_factor())
            * m.emissive_strength()
                .filter(|s| s.is_finite() && *s >= 0.0)
                .unwrap_or(1.0),
        emissive_texture: m.emissive_texture().and_then(info),
        occlusion_texture: m.occlusion_texture().and_then(|t| {
            json_ref(
                slots,
                t.texture(),
                t.extension_value(EXT_TRANSFORM),
                t.tex_coord(),
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
    }
}

/// Texture `t` through `slots` (none where its image was not loaded).
fn tex_ref(
    slots: &[Option<usize>],
    t: gltf::Texture,
    transform: UvTransform,
    tex_coord: u32,
) -> Option<TextureRef> {
    slots
        .get(t.source().index())
        .copied()
        .flatten()
        .map(|texture| TextureRef {
            texture,
            sampler: Sampler::from_gltf(&t.sampler()),
            transform,
            tex_coord,
        })
}

/// A textureInfo with its typed KHR_texture_transform (identity without one).
fn info_ref(slots: &[Option<usize>], i: gltf::texture::Info) -> Option<TextureRef> {
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
    tex_ref(slots, i.texture(), transform, set)
}

/// A texture whose KHR_texture_transform is JSON `ext`: its transform, and its texCoord
/// override, else the textureInfo's own set `own`.
fn json_ref(
    slots: &[Option<usize>],
    t: gltf::Texture,
    ext: Option<&serde_json::Value>,
    own: u32,
) -> Option<TextureRef> {
    let transform = ext.map(UvTransform::from_json).unwrap_or_default();
    let set = ext
        .and_then(|v| v.get("texCoord"))
        .and_then(|c| c.as_u64())
        .map_or(own, |c| c.min(u32::MAX as u64) as u32);
    tex_ref(slots, t, transform, set)
}

/// TEXCOORD_0 and _1 are loaded; a slot of material `i` reading another set reads set 0.
fn texcoord_fallback(scene: &mut Scene, i: usize, mat: &mut Material) {
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
}

/// Occlusion is drawn from the metallic-roughness texture's red channel (glTF's ORM packing; a
/// separate image is packed in at upload), so it must be sampled alike: material `i`'s occlusion
/// texture is dropped, with a warning, where it is not.
fn check_occlusion(scene: &mut Scene, i: usize, mat: &mut Material) {
    let (Some(o), Some(mr)) = (mat.occlusion_texture, mat.metallic_roughness_texture) else {
        return;
    };
    let size = |t: usize| scene.textures.get(t).map(|t| (t.width, t.height));
    if o.sampler != mr.sampler
        || o.transform != mr.transform
        || o.tex_coord != mr.tex_coord
        || size(o.texture) != size(mr.texture)
    {
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
