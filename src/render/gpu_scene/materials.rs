//! Materials on the GPU: the textures they sample (uploaded with mipmaps), their uniform blocks
//! and descriptor sets, and their shader variant bits.

use crate::gpu::context::{Context, GpuError};
use crate::gpu::shaders::scene as sh;
use crate::gpu::{Buffer, Image};
use crate::plan::uniforms::MaterialUniform;
use crate::render::samplers::SamplerCache;
use crate::scene::{AlphaMode, Material, TextureRef, BLEND_SHADOW_CUTOFF};
use crate::shader_consts::VariantKey;
use ash::vk;
use glam::Vec4;
use std::collections::HashMap;
use std::sync::Arc;

/// The texture-transform rows of a material's four slots (identity for an empty slot).
pub(super) fn uv_rows(slots: [Option<crate::scene::TextureRef>; 4]) -> [Vec4; 8] {
    let mut rows = [Vec4::ZERO; 8];
    for (i, t) in slots.iter().enumerate() {
        let (r0, r1) = t.map(|t| t.transform).unwrap_or_default().rows();
        // w: the TEXCOORD set the slot reads.
        rows[2 * i] = r0.extend(t.map_or(0.0, |t| t.tex_coord as f32));
        rows[2 * i + 1] = r1.extend(0.0);
    }
    rows
}

/// The metallic-roughness slot of material `m` with its occlusion texture folded into the red
/// channel (glTF's ORM layout; the loader keeps an occlusion texture only where its sampler and
/// transform are the metallic-roughness texture's and its size too): the reference to sample, and
/// the (metallic-roughness, occlusion) image pair to merge when they are different images.
pub(super) fn orm_slot(
    m: &crate::scene::Material,
    textures: usize,
) -> (
    Option<crate::scene::TextureRef>,
    Option<(Option<usize>, usize)>,
) {
    let mr = m
        .metallic_roughness_texture
        .filter(|t| t.texture < textures);
    match (mr, m.occlusion_texture.filter(|t| t.texture < textures)) {
        (mr, None) => (mr, None),
        (Some(mr), Some(o)) if mr.texture == o.texture => (Some(mr), None),
        (mr, Some(o)) => (
            Some(mr.unwrap_or(o)),
            Some((mr.map(|t| t.texture), o.texture)),
        ),
    }
}

/// An RGBA image with the red channel of `occlusion` and the green and blue channels of
/// `metallic_roughness` (white without one; the loader guarantees equal sizes).
pub(super) fn packed_occlusion(
    occlusion: &crate::scene::Texture,
    metallic_roughness: Option<&crate::scene::Texture>,
) -> crate::scene::Texture {
    let mut rgba = match metallic_roughness {
        Some(t) if t.width == occlusion.width && t.height == occlusion.height => t.rgba.clone(),
        _ => vec![255; occlusion.rgba.len()],
    };
    for (d, s) in rgba.chunks_exact_mut(4).zip(occlusion.rgba.chunks_exact(4)) {
        d[0] = s[0];
    }
    crate::scene::Texture {
        name: format!("{} (occlusion packed)", occlusion.name),
        width: occlusion.width,
        height: occlusion.height,
        rgba,
        ktx2: None,
    }
}

/// A texture the materials use: an image in a colour space (sRGB: true), or an occlusion image
/// packed with a metallic-roughness one (`packed_occlusion`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum TextureJob {
    Image(usize, bool),
    Packed((Option<usize>, usize)),
}

/// The textures material `m` samples in its four slots (base colour and emissive in sRGB;
/// normal, metallic-roughness with occlusion packed in), None where a slot is empty (the shader
/// reads `DEFAULT_TEXTURES` there); `textures`: how many the scene has.
pub(super) fn texture_jobs(m: &crate::scene::Material, textures: usize) -> [Option<TextureJob>; 4] {
    let (orm_ref, orm_merged) = orm_slot(m, textures);
    let image = |t: Option<crate::scene::TextureRef>, srgb| {
        t.filter(|t| t.texture < textures)
            .map(|t| TextureJob::Image(t.texture, srgb))
    };
    [
        image(m.base_color_texture, true),
        image(m.normal_texture, false),
        orm_merged
            .map(TextureJob::Packed)
            .or_else(|| image(orm_ref, false)),
        image(m.emissive_texture, true),
    ]
}

/// Per slot of `texture_jobs`, the default texture an empty slot reads (index into the defaults:
/// white sRGB, white linear, flat normal): white for colours and factors, a flat normal.
pub(super) const DEFAULT_TEXTURES: [usize; 4] = [0, 2, 1, 0];

/// Whether every texture of `m` reads TEXCOORD_0.
pub(super) fn reads_texcoord0_only(m: &crate::scene::Material) -> bool {
    [
        m.base_color_texture,
        m.normal_texture,
        m.metallic_roughness_texture,
        m.emissive_texture,
        m.occlusion_texture,
    ]
    .iter()
    .flatten()
    .all(|t| t.tex_coord == 0)
}

/// The scene shader's variant bits for a material: which texture slots it fills (the shader
/// leaves out the fetch of an empty slot, whose default texture is white, a factor of 1, so the
/// result is the same) and whether it is normal-mapped.
pub fn material_variant_bits(m: &crate::scene::Material) -> VariantKey {
    let mut bits = VariantKey::empty();
    for (filled, bit) in [
        (m.base_color_texture.is_some(), VariantKey::HAS_BASE_TEX),
        (m.normal_texture.is_some(), VariantKey::HAS_NORMAL_MAP),
        (
            m.metallic_roughness_texture.is_some()
                || m.emissive_texture.is_some()
                || m.occlusion_texture.is_some(),
            VariantKey::HAS_OTHER_TEX,
        ),
    ] {
        if filled {
            bits |= bit;
        }
    }
    bits
}

/// Material `m`'s uniform block; `orm_ref` is the texture its metallic-roughness slot reads.
pub(super) fn material_uniform(m: &Material, orm_ref: Option<TextureRef>) -> MaterialUniform {
    MaterialUniform {
        base_color: m.base_color,
        emissive: m.emissive.extend(m.normal_scale),
        params: Vec4::new(
            m.metallic,
            m.roughness,
            if m.occlusion_texture.is_some() {
                m.occlusion_strength
            } else {
                0.0
            },
            m.unlit as u32 as f32,
        ),
        extra: match m.alpha_mode {
            AlphaMode::Mask(c) => Vec4::new(c.max(1e-6), c.max(1e-6), 0.0, 0.0),
            AlphaMode::Blend => Vec4::new(0.0, BLEND_SHADOW_CUTOFF, 0.0, 0.0),
            AlphaMode::Opaque => Vec4::ZERO,
        },
        uv: uv_rows([
            m.base_color_texture,
            m.normal_texture,
            orm_ref,
            m.emissive_texture,
        ]),
    }
}

/// The uploaded textures, where each texture job landed, where the defaults start, and the
/// scene's texture count (which texture references are valid).
pub(super) struct TextureViews<'a> {
    pub(super) scene_textures: usize,
    pub(super) textures: &'a [Image],
    pub(super) index: &'a HashMap<TextureJob, usize>,
    pub(super) defaults: usize,
}

/// Writes material `m`'s descriptor set: its uniform buffer `buf`, its four textures (a default
/// where a slot is empty) and their samplers.
pub(super) fn write_material_set(
    ctx: &Arc<Context>,
    set: vk::DescriptorSet,
    buf: &Buffer,
    m: &Material,
    views: &TextureViews,
    samplers: &mut SamplerCache,
) -> Result<(), GpuError> {
    let (orm_ref, _) = orm_slot(m, views.scene_textures);
    let jobs = texture_jobs(m, views.scene_textures);
    let [base, normal, mr, emissive]: [vk::ImageView; 4] = std::array::from_fn(|k| {
        views.textures[jobs[k].map_or(views.defaults + DEFAULT_TEXTURES[k], |j| views.index[&j])]
            .view
    });
    let buf_info = [vk::DescriptorBufferInfo {
        buffer: buf.raw,
        offset: 0,
        range: vk::WHOLE_SIZE,
    }];
    let img = |v| {
        [vk::DescriptorImageInfo {
            sampler: vk::Sampler::null(),
            image_view: v,
            image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        }]
    };
    let (i_base, i_normal, i_mr, i_em) = (img(base), img(normal), img(mr), img(emissive));
    let mut samp = |t: Option<TextureRef>| -> Result<_, GpuError> {
        Ok([vk::DescriptorImageInfo {
            sampler: samplers.get(t.map(|t| t.sampler).unwrap_or_default())?,
            image_view: vk::ImageView::null(),
            image_layout: vk::ImageLayout::UNDEFINED,
        }])
    };
    let s_base = samp(m.base_color_texture)?;
    let s_normal = samp(m.normal_texture)?;
    let s_mr = samp(orm_ref)?;
    let s_em = samp(m.emissive_texture)?;
    let w = |b: &crate::gpu::shaders::ReflectedBinding| b.write(set);
    let writes = [
        w(&sh::MATERIAL_BLOCK).buffer_info(&buf_info),
        w(&sh::BASE_COLOR_TEX).image_info(&i_base),
        w(&sh::NORMAL_TEX).image_info(&i_normal),
        w(&sh::METAL_ROUGH_TEX).image_info(&i_mr),
        w(&sh::EMISSIVE_TEX).image_info(&i_em),
        w(&sh::BASE_COLOR_SAMPLER).image_info(&s_base),
        w(&sh::NORMAL_SAMPLER).image_info(&s_normal),
        w(&sh::METAL_ROUGH_SAMPLER).image_info(&s_mr),
        w(&sh::EMISSIVE_SAMPLER).image_info(&s_em),
    ];
    unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
    Ok(())
}
