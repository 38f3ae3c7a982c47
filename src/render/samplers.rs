//! Vulkan samplers for glTF samplers: one per distinct (filters, wrap modes) combination a scene
//! uses, made on first use and destroyed with the cache.

use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::scene::{Filter, Sampler, Wrap};
use ash::vk;
use std::collections::HashMap;
use std::sync::Arc;

fn filter(f: Filter) -> vk::Filter {
    match f {
        Filter::Nearest => vk::Filter::NEAREST,
        Filter::Linear => vk::Filter::LINEAR,
    }
}

fn address(w: Wrap) -> vk::SamplerAddressMode {
    match w {
        Wrap::Repeat => vk::SamplerAddressMode::REPEAT,
        Wrap::MirroredRepeat => vk::SamplerAddressMode::MIRRORED_REPEAT,
        Wrap::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
    }
}

/// The create info of `s`. Without mipmaps (glTF's NEAREST / LINEAR min filters) the LOD is
/// clamped to 0.25 with nearest mip selection: the base level only, while λ > 0 still picks the
/// minification filter (the Vulkan spec's recommended emulation). Anisotropy only where every
/// filter is linear.
pub fn create_info(s: &Sampler, anisotropy: f32) -> vk::SamplerCreateInfo<'static> {
    let trilinear =
        s.mag == Filter::Linear && s.min == Filter::Linear && s.mipmap == Some(Filter::Linear);
    let aniso = trilinear && anisotropy > 1.0;
    vk::SamplerCreateInfo::default()
        .mag_filter(filter(s.mag))
        .min_filter(filter(s.min))
        .mipmap_mode(match s.mipmap {
            Some(Filter::Linear) => vk::SamplerMipmapMode::LINEAR,
            _ => vk::SamplerMipmapMode::NEAREST,
        })
        .address_mode_u(address(s.wrap_u))
        .address_mode_v(address(s.wrap_v))
        .address_mode_w(vk::SamplerAddressMode::REPEAT)
        .anisotropy_enable(aniso)
        .max_anisotropy(if aniso { anisotropy } else { 1.0 })
        .max_lod(if s.mipmap.is_some() {
            vk::LOD_CLAMP_NONE
        } else {
            0.25
        })
}

/// The samplers of one scene.
pub struct SamplerCache {
    ctx: Arc<Context>,
    anisotropy: f32,
    made: HashMap<Sampler, vk::Sampler>,
}

impl SamplerCache {
    /// An empty cache; samplers get `anisotropy` (1 = off) where they filter linearly throughout.
    pub fn new(ctx: &Arc<Context>, anisotropy: f32) -> Self {
        Self {
            ctx: ctx.clone(),
            anisotropy,
            made: HashMap::new(),
        }
    }

    /// The Vulkan sampler of `s`.
    pub fn get(&mut self, s: Sampler) -> Result<vk::Sampler, GpuError> {
        if let Some(&v) = self.made.get(&s) {
            return Ok(v);
        }
        let info = create_info(&s, self.anisotropy);
        let v = unsafe { self.ctx.device.create_sampler(&info, None) }.vk("vkCreateSampler")?;
        self.ctx.set_name(
            v,
            &format!(
                "material sampler {:?}/{:?}/{:?} {:?}×{:?}",
                s.mag, s.min, s.mipmap, s.wrap_u, s.wrap_v
            ),
        );
        self.made.insert(s, v);
        Ok(v)
    }
}

impl Drop for SamplerCache {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
            for (_, s) in self.made.drain() {
                self.ctx.device.destroy_sampler(s, None);
            }
        }
    }
}
