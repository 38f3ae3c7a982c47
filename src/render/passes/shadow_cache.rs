//! Shadow caching: what a shadow-map layer holds, so a frame whose view of the light is the
//! same as the last one's redraws only what moved. Per layer the pass keeps the key of what
//! the map holds and of what its static cache holds:
//! - no moving caster in the layer and the map already holds its static casters from the same
//!   light matrix, area, bias and caster list: the layer is not touched at all (a still scene
//!   costs nothing in the shadow pass after its first frame);
//! - moving casters and a cache of the same static casters: the frame's caster area of the
//!   cache is copied into the map and only the moving casters are drawn over it;
//! - otherwise the static casters are drawn over the view's whole square (the caster area moves
//!   with the moving casters, the cache must not), copied into the cache, and the moving ones
//!   drawn on top.
//!
//! A depth buffer keeps the nearest depth of everything drawn into it, whatever the order, so
//! the map is the same to the bit as the uncached pass's (`tests/shadow_cache.rs`).

use crate::plan::{CasterPlan, Viewpoint};
use crate::render::gpu_scene::GpuScene;
use ash::vk;
use glam::Mat4;

/// What one layer of the map (or of the cache) holds: the static casters drawn with this light
/// matrix, area, viewport, bias and near distance.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerKey {
    matrix: [u32; 16],
    area: (i32, i32, u32, u32),
    size: u32,
    slope_bias: u32,
    eye_near: u32,
    light: [u32; 4],
    statics: Vec<usize>,
}

impl LayerKey {
    /// The key of `statics` drawn into `area` of a layer with this light and plan.
    pub fn new(
        light_clip_from_world: &Mat4,
        casters: &CasterPlan,
        area: vk::Rect2D,
        (slope_bias, eye_near): (f32, f32),
        statics: Vec<usize>,
    ) -> Self {
        let a = area;
        let light = match casters.light {
            Viewpoint::Eye(p) => [0, p.x.to_bits(), p.y.to_bits(), p.z.to_bits()],
            Viewpoint::Along(d) => [1, d.x.to_bits(), d.y.to_bits(), d.z.to_bits()],
        };
        Self {
            matrix: light_clip_from_world.to_cols_array().map(f32::to_bits),
            area: (a.offset.x, a.offset.y, a.extent.width, a.extent.height),
            size: casters.size,
            slope_bias: slope_bias.to_bits(),
            eye_near: eye_near.to_bits(),
            light,
            statics,
        }
    }
}

/// What the pass does with one layer this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerWork {
    /// Nothing: the map already holds this frame's layer.
    Keep,
    /// Clear and draw the static casters (no moving ones).
    DrawStatic,
    /// Copy the cache into the map, then draw the moving casters.
    FromCache,
    /// Clear and draw the static casters, copy them into the cache, then draw the moving ones.
    FillCache,
}

/// The cache state of every layer.
#[derive(Debug, Default)]
pub struct ShadowCache {
    /// What each layer of the map holds (None: unknown, or moving casters drawn into it).
    map: Vec<Option<LayerKey>>,
    /// What each layer of the cache image holds.
    cache: Vec<Option<LayerKey>>,
}

impl ShadowCache {
    /// Forgets everything (a new map, a new scene).
    pub fn clear(&mut self) {
        self.map.clear();
        self.cache.clear();
    }

    /// Decides layer `layer`'s work for `key` with or without moving casters, and records what
    /// the map and cache will hold after it.
    pub fn plan(&mut self, layer: usize, key: LayerKey, moving: bool) -> LayerWork {
        if self.map.len() <= layer {
            self.map.resize(layer + 1, None);
            self.cache.resize(layer + 1, None);
        }
        if !moving {
            if self.map[layer].as_ref() == Some(&key) {
                return LayerWork::Keep;
            }
            self.map[layer] = Some(key);
            return LayerWork::DrawStatic;
        }
        self.map[layer] = None;
        if self.cache[layer].as_ref() == Some(&key) {
            LayerWork::FromCache
        } else {
            self.cache[layer] = Some(key);
            LayerWork::FillCache
        }
    }
}

/// The casters of a layer split into static and moving ones (`Draw::moving`), each in plan
/// order.
pub fn split_moving(scene: &GpuScene, draws: &[usize]) -> (Vec<usize>, Vec<usize>) {
    draws.iter().partition(|&&i| !scene.draws[i].moving)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(x: f32, statics: Vec<usize>) -> LayerKey {
        let plan = CasterPlan::default();
        LayerKey::new(
            &Mat4::from_translation(glam::Vec3::new(x, 0.0, 0.0)),
            &plan,
            crate::render::pipeline::texel_rect(plan.area),
            (1.0, 0.1),
            statics,
        )
    }

    #[test]
    fn a_still_layer_is_kept_and_any_change_redraws_it() {
        let mut c = ShadowCache::default();
        assert_eq!(
            c.plan(0, key(0.0, vec![1, 2]), false),
            LayerWork::DrawStatic
        );
        assert_eq!(c.plan(0, key(0.0, vec![1, 2]), false), LayerWork::Keep);
        // Another light matrix, another caster list: drawn again.
        assert_eq!(
            c.plan(0, key(0.5, vec![1, 2]), false),
            LayerWork::DrawStatic
        );
        assert_eq!(c.plan(0, key(0.5, vec![1]), false), LayerWork::DrawStatic);
        assert_eq!(c.plan(1, key(0.5, vec![1]), false), LayerWork::DrawStatic);
        c.clear();
        assert_eq!(c.plan(0, key(0.5, vec![1]), false), LayerWork::DrawStatic);
    }

    #[test]
    fn moving_casters_reuse_the_static_cache() {
        let mut c = ShadowCache::default();
        assert_eq!(c.plan(0, key(0.0, vec![1]), true), LayerWork::FillCache);
        assert_eq!(c.plan(0, key(0.0, vec![1]), true), LayerWork::FromCache);
        // Once movers were drawn the map no longer holds the static layer alone.
        assert_eq!(c.plan(0, key(0.0, vec![1]), false), LayerWork::DrawStatic);
        assert_eq!(c.plan(0, key(0.0, vec![1]), true), LayerWork::FromCache);
        assert_eq!(c.plan(0, key(1.0, vec![1]), true), LayerWork::FillCache);
    }
}
