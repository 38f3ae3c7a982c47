//! The cameras of a batch whose views share their shadow maps ([`super::View::shadow_batch`]),
//! with what the shared fit needs from all of them worked out once for the batch: each
//! directional light's receiver box over every frustum of the batch. Found anew for each view,
//! it made a batch's planning quadratic in its size (1,600 poses: 4.8 ms a pose against 0.6
//! fitted per view).

use super::fitting_frustum;
use crate::math::shadow_fit::batch_receivers;
use crate::math::Aabb;
use crate::scene::Camera;
use glam::Vec3;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// A batch's cameras, in world coordinates, and the receiver boxes found for them.
pub struct ShadowBatch {
    cameras: Arc<[Camera]>,
    /// [`ShadowBatch::receivers`] already found, by what they depend on (as bits): the render
    /// origin, the light's direction, the scene's bounds and the image's aspect.
    found: Mutex<HashMap<[u32; 13], Aabb>>,
}

impl ShadowBatch {
    /// The batch of `cameras` (world coordinates).
    pub fn new(cameras: Arc<[Camera]>) -> Self {
        Self {
            cameras,
            found: Mutex::new(HashMap::new()),
        }
    }

    /// The cameras.
    pub fn cameras(&self) -> &[Camera] {
        &self.cameras
    }

    /// Where the batch's frusta (for an image of `aspect`, relative to `origin`) meet the scene
    /// of `bounds` (relative to `origin`), as a box in the view space of a light travelling along
    /// `direction` ([`batch_receivers`]); found once for each set of these.
    pub(crate) fn receivers(
        &self,
        origin: Vec3,
        direction: Vec3,
        bounds: &Aabb,
        aspect: f32,
    ) -> Aabb {
        let mut key = [0u32; 13];
        let values = [origin, direction, bounds.min, bounds.max];
        for (k, v) in key.chunks_exact_mut(3).zip(values) {
            k.copy_from_slice(&v.to_array().map(f32::to_bits));
        }
        key[12] = aspect.to_bits();
        let mut found = self.found.lock().unwrap_or_else(|p| p.into_inner());
        *found.entry(key).or_insert_with(|| {
            let frusta: Vec<_> = self
                .cameras
                .iter()
                .map(|c| fitting_frustum(&c.rebased(origin), aspect, bounds))
                .collect();
            batch_receivers(&frusta, bounds, direction)
        })
    }
}

impl std::fmt::Debug for ShadowBatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ShadowBatch({} cameras)", self.cameras.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl ShadowBatch {
        fn found_count(&self) -> usize {
            self.found.lock().unwrap().len()
        }
    }

    #[test]
    fn receivers_are_found_once_per_light_as_the_batch_clipped_afresh() {
        // Eight cameras seeing 5 units, in a ring 10⁵ out, over a scene 100 across whose
        // bounds are relative to that origin: the batch sees a small part of it.
        let origin = Vec3::new(1e5, 0.0, -2e5);
        let cameras: Arc<[Camera]> = (0..8)
            .map(|i| {
                let a = i as f32 * 0.785;
                let eye = origin + Vec3::new(3.0 * a.cos(), 1.5, 3.0 * a.sin());
                Camera {
                    far: Some(5.0),
                    ..Camera::look_at(eye, origin, 1.0, 0.05)
                }
            })
            .collect();
        let bounds = Aabb::new(Vec3::new(-50.0, -0.1, -50.0), Vec3::new(50.0, 1.0, 50.0));
        let sun = Vec3::new(0.3, -1.0, 0.2).normalize();
        let batch = ShadowBatch::new(cameras.clone());
        let got = batch.receivers(origin, sun, &bounds, 1.5);
        let frusta: Vec<_> = cameras
            .iter()
            .map(|c| fitting_frustum(&c.rebased(origin), 1.5, &bounds))
            .collect();
        assert_eq!(got, batch_receivers(&frusta, &bounds, sun));
        assert!(!got.is_empty(), "the rebased frusta meet the scene");
        let side = (got.max - got.min).max_element();
        assert!(side > 5.0 && side < 20.0, "{side}: the ring, not the scene");
        for _ in 0..63 {
            assert_eq!(batch.receivers(origin, sun, &bounds, 1.5), got);
        }
        assert_eq!(batch.found_count(), 1);
        // Another light, another box, found once more.
        assert_ne!(batch.receivers(origin, Vec3::NEG_Y, &bounds, 1.5), got);
        assert_eq!(batch.found_count(), 2);
    }
}
