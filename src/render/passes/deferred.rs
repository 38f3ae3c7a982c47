//! Deferred shading of draws made of triangles smaller than llvmpipe's shading block, and of
//! draws that hide their own triangles (open meshes drawn on both faces, [`overdraws_itself`]).
//!
//! llvmpipe rasterises in 4×4-pixel blocks and runs the fragment shader on every block a
//! triangle touches (on 8 lanes at a time), so a mesh whose triangles cover a pixel or two on
//! screen runs the whole material shader several times per pixel it keeps: FlightHelmet's
//! 95 k triangles average 1.5 pixels at 1280×720. Those draws (`plan`) instead write what the
//! shader reads from their varyings into a G-buffer (`fs_gbuffer`: no texture reads, no
//! lighting) and mark their material in the stencil; then one full-screen triangle per such
//! material, limited to its draws' screen rectangle, shades each marked pixel once
//! (`fs_resolve`: the same textures, read with the G-buffer's derivatives, and the same
//! `shade_texels`). Everything else is drawn forward, after the resolve, into the same depth.
//!
//! On by default on CPU devices at one sample per pixel (`SceneOptions::deferred`); GPUs shade
//! 2×2 quads in hardware and keep the forward pass.

use crate::gpu::context::{Context, GpuError};
use crate::gpu::shaders::{allocate_sets, scene as sh, write_sampled_images, ReflectedBinding};
use crate::gpu::{Attachment, Image};
use crate::render::gpu_scene::{AlphaDraw, Draw};
use crate::render::passes::cull::CameraCull;
use crate::render::passes::screen::{pixels_per_triangle, screen_rect, PixelRect};
use crate::shader_consts::VariantKey;
use ash::vk;
use glam::Mat4;
use std::collections::{HashMap, HashSet};
use std::sync::Arc;

/// A draw is deferred when its triangles' estimated mean area on screen (`pixels_per_triangle`)
/// is below this many pixels. Chosen by a sweep (CHANGELOG, milestone 15): at 4, 8, 12 and
/// 16 FlightHelmet + ground took 46.9, 43.0, 39.6 and 40.0 ms a frame (its helmet draws are
/// 1.4, 1.6, 5.2, 5.9 and 9.5 pixels a triangle: even at 9.5 a triangle touches about twice the
/// lanes it keeps). Milestone 13's sweep had found 4 best (8: +1.0 ms, 16: +3.4 ms), before
/// milestone 14 stopped llvmpipe's memory being paged out and in again every frame.
pub const DEFER_BELOW_PIXELS: f32 = 16.0;

/// Draws of fewer triangles stay forward: a small draw saves little shading and would still
/// cost its material a resolve (not measured finely; every benchmark draw that defers has
/// over 1,000 triangles).
pub const DEFER_MIN_TRIANGLES: u32 = 256;

/// A frame defers nothing unless its candidates hold at least this many triangles: the
/// G-buffer pass and the resolves cost about a millisecond whatever they hold (the demo's one
/// candidate, 2,208 triangles of 11 pixels, made its frame 1.1–2.0 ms slower deferred, three
/// rounds; `--synthetic spheres:2`, four spheres of 1,200 triangles of 9–12 pixels, came out
/// even; `spheres:3`, nine of 5–7 pixels, 0.5 ms faster).
pub const DEFER_MIN_FRAME_TRIANGLES: u32 = 4096;

/// Format of the G-buffer targets (`GBuffer` in scene.wgsl: 32-bit depth and texture
/// coordinates, packed directions and derivatives).
pub const GBUFFER_FORMAT: vk::Format = vk::Format::R32G32B32A32_UINT;

/// Number of G-buffer targets.
pub const GBUFFER_TARGETS: usize = 2;

/// The shader variant of `fs_gbuffer` for a draw of material variant `material_bits`: its
/// texture slots only (the G-buffer pass reads no light, shadow or frame setting).
pub fn gbuffer_variant(material_bits: VariantKey) -> VariantKey {
    material_bits & VariantKey::TEXTURES
}

/// The G-buffer targets, from the last, that `fs_gbuffer`'s variant `gbuffer_variant` leaves
/// alone: an untextured material's depth, normal and flags fit target a, so b is masked.
pub fn gbuffer_targets_masked(gbuffer_variant: VariantKey) -> usize {
    usize::from(gbuffer_variant.is_empty())
}

/// Stencil marks are 8 bits; mark 0 is "not deferred".
const MAX_MARKS: usize = 255;

/// Where `dr` is on screen, and its pixels per triangle, if it is shaded deferred in a frame
/// seen through `clip_from_world` at `extent`: deferrable, at least `DEFER_MIN_TRIANGLES`,
/// triangles under `DEFER_BELOW_PIXELS` each or [`overdraws_itself`], and wholly in front of the
/// eye.
fn is_micro(dr: &Draw, clip_from_world: &Mat4, extent: vk::Extent2D) -> Option<(PixelRect, f32)> {
    let triangles = dr.index_count / 3;
    if !dr.deferrable || dr.alpha != AlphaDraw::Opaque || triangles < DEFER_MIN_TRIANGLES {
        return None;
    }
    let ppt = pixels_per_triangle(dr, clip_from_world, extent);
    if ppt >= DEFER_BELOW_PIXELS && !overdraws_itself(dr) {
        return None;
    }
    Some((screen_rect(dr, clip_from_world, extent)?, ppt))
}

/// Whether a draw's own triangles hide one another wherever it is seen from, so that forward
/// shading runs the material shader about twice for the pixels it keeps: both faces drawn
/// (double-sided) of a mesh that is neither closed (whose back faces are culled) nor flat. An
/// open vase's inside and outside, a bent leaf: the triangle order inside one draw is not
/// front to back, so early depth rejects only part of the hidden fragments. On
/// `--synthetic close-up` (11 such models of 4,608 triangles, 50-pixel triangles, 2.1 fragments
/// per covered pixel) deferring them took the camera pass from 62 to 54 ms.
fn overdraws_itself(dr: &Draw) -> bool {
    dr.double_sided && !dr.closed && dr.world_plane.is_none()
}

/// With candidates of more materials than stencil marks, the `MAX_MARKS` materials whose draws
/// cover the most pixels (triangles × pixels per triangle, summed) keep theirs; the others'
/// draws stay forward. On the 32×32 sphere grid (1,024 materials, triangles of 0.09–0.29
/// pixels) keeping the nearest spheres' measured 103–107 ms camera pass against 109–111 ms for
/// the farthest (smallest triangles): a sub-pixel triangle that holds no pixel centre costs no
/// shading at all.
fn keep_largest_materials(order: &[&Draw], micro: &mut [Option<(PixelRect, f32)>]) {
    let mut covered: HashMap<usize, f32> = HashMap::new();
    for (dr, m) in order.iter().zip(micro.iter()) {
        if let Some((_, ppt)) = m {
            *covered.entry(dr.material).or_default() += (dr.index_count / 3) as f32 * ppt;
        }
    }
    if covered.len() <= MAX_MARKS {
        return;
    }
    let mut pixels: Vec<(usize, f32)> = covered.into_iter().collect();
    // Ties (and the hash map's order) broken by material index, so the choice is deterministic.
    pixels.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let kept: HashSet<usize> = pixels[..MAX_MARKS].iter().map(|e| e.0).collect();
    for (dr, m) in order.iter().zip(micro.iter_mut()) {
        if !kept.contains(&dr.material) {
            *m = None;
        }
    }
}

/// One material resolved full-screen: its index, stencil mark, shader variant bits and the
/// screen rectangle of its deferred draws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolved {
    /// Material index (descriptor set).
    pub material: usize,
    /// Stencil value its deferred draws write (1–255).
    pub mark: u32,
    /// `Draw::material_bits`.
    pub material_bits: VariantKey,
    /// Where its deferred draws can be on screen.
    pub rect: PixelRect,
}

/// How a frame's draws split between the G-buffer and the forward pass (draws as indices into
/// `GpuScene::draws`).
#[derive(Clone, Debug, Default)]
pub struct DeferPlan {
    /// Draws into the G-buffer, each with its material's stencil mark, in the given order.
    pub deferred: Vec<(usize, u32)>,
    /// The materials to resolve.
    pub resolved: Vec<Resolved>,
    /// The rest, drawn forward after the resolve, in the given order.
    pub forward: Vec<usize>,
}

/// Splits `order` (the camera pass's draw order) for `cull`'s frame at `extent`; with `enabled`
/// false (or a debug view), or candidates of fewer than `DEFER_MIN_FRAME_TRIANGLES` triangles in
/// all, everything is forward. The viewer's highlighted draw stays forward (its tint is a
/// forward-shader immediate), and past 255 candidate materials those covering the fewest
/// pixels too (`keep_largest_materials`).
pub fn plan(
    order: Vec<usize>,
    draws: &[Draw],
    cull: &CameraCull,
    extent: vk::Extent2D,
    enabled: bool,
) -> DeferPlan {
    let refs: Vec<&Draw> = order.iter().map(|&i| &draws[i]).collect();
    let mut p = DeferPlan {
        deferred: Vec::new(),
        resolved: Vec::new(),
        forward: Vec::new(),
    };
    let mut micro: Vec<Option<(PixelRect, f32)>> = refs
        .iter()
        .map(|dr| {
            (enabled && cull.debug_view.is_none() && cull.highlight != Some(dr.source))
                .then(|| is_micro(dr, &cull.clip_from_world, extent))
                .flatten()
        })
        .collect();
    keep_largest_materials(&refs, &mut micro);
    let candidates: u32 = refs
        .iter()
        .zip(&micro)
        .filter(|(_, m)| m.is_some())
        .map(|(dr, _)| dr.index_count / 3)
        .sum();
    let worth_a_pass = candidates >= DEFER_MIN_FRAME_TRIANGLES;
    for ((&i, dr), micro) in order.iter().zip(refs).zip(micro) {
        let Some((rect, _)) = micro.filter(|_| worth_a_pass) else {
            p.forward.push(i);
            continue;
        };
        let known = p.resolved.iter().position(|r| r.material == dr.material);
        let mark = match known {
            Some(i) => {
                let r = &mut p.resolved[i];
                r.rect = r.rect.union(rect);
                r.mark
            }
            None => {
                let mark = p.resolved.len() as u32 + 1;
                p.resolved.push(Resolved {
                    material: dr.material,
                    mark,
                    material_bits: dr.material_bits,
                    rect,
                });
                mark
            }
        };
        p.deferred.push((i, mark));
    }
    p
}

/// The G-buffer targets of one size, and their descriptor set (set 2 of the camera layout).
pub struct GBuffer {
    _images: Vec<Image>,
    /// The targets, in location order, each with its last access.
    pub targets: Vec<Attachment>,
    /// Their size.
    pub extent: vk::Extent2D,
    pool: vk::DescriptorPool,
    /// Set 2: the four targets, read with `textureLoad` by `fs_resolve`.
    pub set: vk::DescriptorSet,
    ctx: Arc<Context>,
}

impl GBuffer {
    /// The targets at `extent`, and their set (layout `set_layout`), every binding written.
    pub fn new(
        ctx: &Arc<Context>,
        extent: vk::Extent2D,
        set_layout: vk::DescriptorSetLayout,
    ) -> Result<Self, GpuError> {
        let mut images = Vec::new();
        for i in 0..GBUFFER_TARGETS {
            images.push(Image::new(
                ctx,
                &format!("G-buffer {i}"),
                GBUFFER_FORMAT,
                extent,
                1,
                vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            )?);
        }
        let (pool, sets) = allocate_sets(ctx, sh::BINDINGS, 2, set_layout, 1)?;
        let set = sets[0];
        let bindings: [&ReflectedBinding; GBUFFER_TARGETS] = [&sh::GBUFFER_A, &sh::GBUFFER_B];
        let targets: Vec<_> = bindings
            .into_iter()
            .zip(images.iter().map(|im| im.view))
            .collect();
        write_sampled_images(&ctx.device, set, &targets);
        Ok(Self {
            targets: images.iter().map(Attachment::of).collect(),
            _images: images,
            extent,
            pool,
            set,
            ctx: ctx.clone(),
        })
    }

    /// The targets' views, in location order.
    pub fn views(&self) -> Vec<vk::ImageView> {
        self.targets.iter().map(|t| t.view).collect()
    }
}

impl Drop for GBuffer {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
            self.ctx.device.destroy_descriptor_pool(self.pool, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::projection::perspective_infinite_reversed;
    use crate::math::Aabb;
    use crate::plan::uniforms::SceneImmediates;
    use glam::Vec3;

    /// A deferrable opaque draw of `triangles` triangles of mean world area `mean_area` in a unit
    /// box centred at `center`.
    fn draw(material: usize, triangles: u32, mean_area: f32, center: Vec3) -> Draw {
        let m = Mat4::from_translation(center);
        Draw {
            first_index: 0,
            index_count: 3 * triangles,
            vertex_offset: 0,
            material,
            source: (material, 0),
            world_from_model: m,
            model_from_world: m.inverse(),
            clusters: (0, 0),
            immediates: SceneImmediates::new(m),
            world_bounds: Aabb::new(center - Vec3::splat(0.5), center + Vec3::splat(0.5)),
            magnitudes: Vec3::ZERO,
            world_plane: None,
            double_sided: false,
            mirrored: false,
            alpha: AlphaDraw::Opaque,
            material_bits: VariantKey::empty(),
            closed: true,
            deferrable: true,
            mean_area,
            moving: false,
            shadow_range: None,
        }
    }

    /// A 90° camera at the origin looking down −z, 100×100 pixels.
    fn cull() -> (CameraCull, vk::Extent2D) {
        let c = CameraCull {
            clip_from_world: perspective_infinite_reversed(90f32.to_radians(), 1.0, 0.1),
            eye: (Vec3::ZERO, 0.1),
            viewpoint: crate::plan::Viewpoint::Eye(Vec3::ZERO),
            frame_bits: VariantKey::empty(),
            debug_view: None,
            highlight: None,
            shadow_reach: None,
        };
        (
            c,
            vk::Extent2D {
                width: 100,
                height: 100,
            },
        )
    }

    #[test]
    fn pixels_per_triangle_is_half_the_projected_mean_area() {
        let (c, extent) = cull();
        // At 10 units a 90° view 100 pixels tall spans 20 units: 5 pixels per unit, so a
        // triangle of 0.1 square units covers 0.5 · 0.1 · 25 = 1.25 pixels facing the eye.
        let d = draw(0, 1000, 0.1, Vec3::new(0.0, 0.0, -10.0));
        let ppt = pixels_per_triangle(&d, &c.clip_from_world, extent);
        assert!((ppt - 1.25).abs() < 1e-4, "{ppt}");
        // Twice as far, a quarter of the pixels; behind the eye, never deferred.
        let far = draw(0, 1000, 0.1, Vec3::new(0.0, 0.0, -20.0));
        let ppt_far = pixels_per_triangle(&far, &c.clip_from_world, extent);
        assert!((ppt_far - 0.3125).abs() < 1e-4, "{ppt_far}");
        let behind = draw(0, 1000, 0.1, Vec3::new(0.0, 0.0, 10.0));
        assert_eq!(
            pixels_per_triangle(&behind, &c.clip_from_world, extent),
            f32::INFINITY
        );
    }

    #[test]
    fn plan_marks_each_deferred_material_once_and_keeps_the_rest_forward() {
        let (mut c, extent) = cull();
        let draws = [
            draw(3, 2500, 0.01, Vec3::new(-1.0, 0.0, -10.0)),
            Draw {
                source: (3, 1),
                ..draw(3, 2500, 0.01, Vec3::new(1.0, 0.0, -10.0))
            },
            draw(5, 2500, 0.01, Vec3::new(0.0, 1.0, -10.0)),
            // Large triangles, too few triangles, not deferrable: forward.
            draw(6, 1000, 10.0, Vec3::new(0.0, -1.0, -10.0)),
            draw(7, 100, 0.01, Vec3::new(0.0, -2.0, -10.0)),
            Draw {
                deferrable: false,
                ..draw(8, 1000, 0.01, Vec3::new(2.0, 0.0, -10.0))
            },
        ];
        let p = plan((0..draws.len()).collect(), &draws, &c, extent, true);
        let marks: Vec<(usize, u32)> = p
            .deferred
            .iter()
            .map(|&(d, m)| (draws[d].material, m))
            .collect();
        assert_eq!(marks, [(3, 1), (3, 1), (5, 2)]);
        assert_eq!(p.resolved.len(), 2);
        // Material 3's rectangle covers both of its draws' boxes.
        let r = p.resolved[0].rect;
        let a = screen_rect(&draws[0], &c.clip_from_world, extent).unwrap();
        let b = screen_rect(&draws[1], &c.clip_from_world, extent).unwrap();
        assert_eq!(r, a.union(b));
        let forward: Vec<usize> = p.forward.iter().map(|&d| draws[d].material).collect();
        assert_eq!(forward, [6, 7, 8]);
        // Off, in a debug view, or for the highlighted draw: forward.
        assert!(plan((0..draws.len()).collect(), &draws, &c, extent, false)
            .deferred
            .is_empty());
        c.highlight = Some((3, 1));
        let p = plan((0..draws.len()).collect(), &draws, &c, extent, true);
        let sources: Vec<(usize, usize)> =
            p.deferred.iter().map(|&(d, _)| draws[d].source).collect();
        assert_eq!(sources, [(3, 0), (5, 0)]);
        assert_eq!(draws[p.forward[0]].source, (3, 1));
        c.highlight = None;
        c.debug_view = Some(crate::render::passes::cull::Entry::Debug);
        assert!(plan((0..draws.len()).collect(), &draws, &c, extent, true)
            .deferred
            .is_empty());
    }

    #[test]
    fn open_double_sided_meshes_defer_at_any_triangle_size() {
        let (c, extent) = cull();
        // Large triangles (40 pixels each at 10 units): forward, unless both faces of an open,
        // curved mesh are drawn.
        let big = |material, x| draw(material, 2500, 3.2, Vec3::new(x, 0.0, -10.0));
        let open = Draw {
            double_sided: true,
            closed: false,
            ..big(1, -2.0)
        };
        let closed = Draw {
            double_sided: true,
            ..big(2, -1.0)
        };
        let flat = Draw {
            world_plane: Some(glam::Vec4::new(0.0, 1.0, 0.0, 0.0)),
            ..open
        };
        let single = Draw {
            closed: false,
            ..big(4, 1.0)
        };
        let open_too = Draw {
            material: 5,
            source: (5, 0),
            ..open
        };
        assert!(pixels_per_triangle(&closed, &c.clip_from_world, extent) > DEFER_BELOW_PIXELS);
        let draws = [open, closed, flat, single, open_too];
        let p = plan((0..draws.len()).collect(), &draws, &c, extent, true);
        let deferred: Vec<usize> = p.deferred.iter().map(|&(d, _)| d).collect();
        assert_eq!(deferred, [0, 4]);
        assert_eq!(p.forward, [1, 2, 3]);
    }

    #[test]
    fn a_frame_with_few_candidate_triangles_defers_nothing() {
        let (c, extent) = cull();
        // Two candidates of 2,000 triangles: under DEFER_MIN_FRAME_TRIANGLES, both forward, in
        // order; a third makes 6,000 and all three defer.
        let draws = [
            draw(1, 2000, 0.01, Vec3::new(-1.0, 0.0, -10.0)),
            draw(2, 1000, 10.0, Vec3::new(0.0, -1.0, -10.0)),
            draw(3, 2000, 0.01, Vec3::new(1.0, 0.0, -10.0)),
            draw(4, 2000, 0.01, Vec3::new(0.0, 1.0, -10.0)),
        ];
        let p = plan((0..3).collect(), &draws, &c, extent, true);
        assert!(p.deferred.is_empty() && p.resolved.is_empty());
        let forward: Vec<usize> = p.forward.iter().map(|&d| draws[d].material).collect();
        assert_eq!(forward, [1, 2, 3]);
        let p = plan((0..draws.len()).collect(), &draws, &c, extent, true);
        let deferred: Vec<usize> = p.deferred.iter().map(|&(d, _)| draws[d].material).collect();
        assert_eq!(deferred, [1, 3, 4]);
        assert_eq!(p.forward.len(), 1);
    }

    #[test]
    fn past_255_materials_those_covering_the_most_pixels_defer() {
        let (c, extent) = cull();
        // 300 materials, one draw each, triangles shrinking with the index (all under
        // DEFER_BELOW_PIXELS); the last one's are the largest of all.
        let draws: Vec<Draw> = (0..300)
            .map(|i| {
                let area = if i == 299 {
                    0.1
                } else {
                    0.05 - 0.0001 * i as f32
                };
                draw(i, 1000, area, Vec3::new(0.0, 0.0, -10.0))
            })
            .collect();
        let p = plan((0..draws.len()).collect(), &draws, &c, extent, true);
        assert_eq!(p.resolved.len(), MAX_MARKS);
        let deferred: Vec<usize> = p.deferred.iter().map(|&(d, _)| draws[d].material).collect();
        let mut expected: Vec<usize> = (0..254).collect();
        expected.push(299);
        assert_eq!(deferred, expected);
        let forward: Vec<usize> = p.forward.iter().map(|&d| draws[d].material).collect();
        assert_eq!(forward, (254..299).collect::<Vec<_>>());
    }
}
