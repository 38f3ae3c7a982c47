//! The scene's textures on the device: one image per (image, colour space) the materials use and
//! per packed (metallic-roughness, occlusion) pair, then the three defaults. A chain is made from
//! each image's first level (on the CPU, or blitted on the device), except for KTX2 images
//! (`Texture::ktx2`), which keep the file's own levels, transcoded to BC7 where
//! `SceneOptions::block_compressed` resolves on and to RGBA8 elsewhere.

use super::materials::{packed_occlusion, texture_jobs, TextureJob};
use crate::gpu::context::{Context, GpuError};
use crate::gpu::Image;
use crate::math::mips::{mip_chain, MipChain};
use crate::plan::settings::SceneOptions;
use crate::scene::gltf::compressed::{ktx2_levels, Ktx2Target};
use crate::scene::{Scene, Texture};
use ash::vk;
use std::collections::HashMap;
use std::sync::Arc;

/// What the scene's textures take on the device (the three 1×1 defaults not counted).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TextureStats {
    /// Images uploaded.
    pub images: usize,
    /// Of them, KTX2 images holding the file's own mip levels.
    pub file_mips: usize,
    /// Of them, BC7 images.
    pub bc7: usize,
    /// Bytes of every level of every image (a chain blitted on the device counted as made).
    pub bytes: u64,
}

/// What `upload_textures` made: the images, the image of each texture job, the index of the
/// first default texture, and the figures.
pub(super) type Uploaded = (Vec<Image>, HashMap<TextureJob, usize>, usize, TextureStats);

/// The levels a texture goes to the device with.
enum Levels {
    /// The file's own levels, in RGBA8 or BC7.
    File(MipChain, Ktx2Target),
    /// A chain made from the first level on the CPU, or `None`: blitted on the device.
    Made(Option<MipChain>),
}

/// The levels of texture `t` (read directly by a material slot when `direct`; packed textures
/// are made here and have no file).
fn levels_of(t: &Texture, srgb: bool, direct: bool, cpu_mips: bool, bc7: bool) -> Levels {
    if let Some(file) = t.ktx2.as_deref().filter(|_| direct) {
        let target = if bc7 {
            Ktx2Target::Bc7
        } else {
            Ktx2Target::Rgba8
        };
        // A file of one level keeps its image; its chain is made as any image's (a BC7 image
        // cannot be blitted). A file whose levels do not transcode (its first did, at load)
        // falls back the same way.
        match ktx2_levels(file, target) {
            Ok(c) if c.levels.len() > 1 => return Levels::File(c, target),
            _ => {}
        }
    }
    Levels::Made(cpu_mips.then(|| mip_chain(t.width, t.height, &t.rgba, srgb)))
}

/// The Vulkan format of file levels transcoded to `target` in the sRGB or linear colour space.
fn file_format(target: Ktx2Target, srgb: bool) -> vk::Format {
    match (target, srgb) {
        (Ktx2Target::Rgba8, true) => vk::Format::R8G8B8A8_SRGB,
        (Ktx2Target::Rgba8, false) => vk::Format::R8G8B8A8_UNORM,
        (Ktx2Target::Bc7, true) => vk::Format::BC7_SRGB_BLOCK,
        (Ktx2Target::Bc7, false) => vk::Format::BC7_UNORM_BLOCK,
    }
}

/// Uploads the textures the materials use: one per (image, colour space), one per packed
/// (metallic-roughness, occlusion) pair, then the three defaults (white sRGB, white linear, flat
/// normal) from the returned index on.
pub(super) fn upload_textures(
    ctx: &Arc<Context>,
    scene: &Scene,
    options: &SceneOptions,
) -> Result<Uploaded, GpuError> {
    let mut jobs: Vec<TextureJob> = scene
        .materials
        .iter()
        .flat_map(|m| texture_jobs(m, scene.textures.len()))
        .flatten()
        .collect();
    let mut seen = std::collections::HashSet::new();
    jobs.retain(|j| seen.insert(*j));
    // Levels made or transcoded here (`SceneOptions::cpu_mips`: by default on CPU devices), a
    // few textures at a time on all cores (a 2048² chain is 21 MiB, dropped once uploaded), or
    // blitted on the device.
    let facts = crate::render::device_facts(ctx);
    let cpu_mips = options.resolved_cpu_mips(&facts);
    let bc7 = options.resolved_block_compressed(&facts);
    let batch = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut textures: Vec<Image> = Vec::new();
    let mut tex_index: HashMap<TextureJob, usize> = HashMap::new();
    let mut stats = TextureStats::default();
    for part in jobs.chunks(batch.max(1)) {
        let done = crate::parallel::map(part, |j| {
            let (t, direct) = match *j {
                TextureJob::Image(i, _) => (std::borrow::Cow::Borrowed(&scene.textures[i]), true),
                TextureJob::Packed((mr, o)) => (
                    std::borrow::Cow::Owned(packed_occlusion(
                        &scene.textures[o],
                        mr.map(|i| &scene.textures[i]),
                    )),
                    false,
                ),
            };
            let srgb = matches!(j, TextureJob::Image(_, true));
            let levels = levels_of(&t, srgb, direct, cpu_mips, bc7);
            (t, levels, srgb)
        });
        for (j, (t, levels, srgb)) in part.iter().zip(done) {
            stats.images += 1;
            textures.push(match levels {
                Levels::File(c, target) => {
                    stats.file_mips += 1;
                    stats.bc7 += usize::from(target == Ktx2Target::Bc7);
                    stats.bytes += c.bytes.len() as u64;
                    Image::texture_levels(ctx, &t.name, &c, file_format(target, srgb))?
                }
                Levels::Made(Some(c)) => {
                    stats.bytes += c.bytes.len() as u64;
                    Image::texture_mips(ctx, &t.name, &c, srgb)?
                }
                Levels::Made(None) => {
                    stats.bytes += (t.rgba.len() as u64 * 4).div_ceil(3);
                    Image::texture_rgba8(ctx, &t.name, t.width, t.height, &t.rgba, srgb)?
                }
            });
            tex_index.insert(*j, textures.len() - 1);
        }
    }
    let white_srgb = Image::texture_rgba8(ctx, "default white sRGB", 1, 1, &[255; 4], true)?;
    let white_linear = Image::texture_rgba8(ctx, "default white", 1, 1, &[255; 4], false)?;
    let flat_normal = Image::texture_rgba8(
        ctx,
        "default flat normal",
        1,
        1,
        &[128, 128, 255, 255],
        false,
    )?;
    let defaults = textures.len();
    textures.extend([white_srgb, white_linear, flat_normal]);
    Ok((textures, tex_index, defaults, stats))
}
