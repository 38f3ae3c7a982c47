//! What the camera pass draws in a frame, decided before recording: the draw order, the
//! deferred split, each forward draw's receiver split and flat inputs.

use super::*;
use crate::gpu::context::Context;
use crate::plan::flat_hides_nothing;
use crate::render::gpu_scene::{AlphaDraw, GpuScene};
use crate::render::passes::cull::{CameraCull, Entry};
use crate::render::passes::deferred::{self, DeferPlan};
use crate::render::passes::receivers::{self, Split};
use crate::render::passes::screen::pixels_per_triangle;
use crate::render::targets::Attachment;
use ash::vk;

/// The draws the camera can see (unless culling is off), opaque ones first and front to back
/// (nearest bounds first, so llvmpipe's early depth test rejects more hidden fragments before
/// shading; flat draws that hide nothing from the eye, such as the ground, after the others),
/// then the alpha-masked ones, then the blended ones back to front (farthest bounds centre
/// first: each is blended over everything behind it).
fn draw_order(scene: &GpuScene, cull: &CameraCull) -> Vec<usize> {
    let mut v: Vec<((AlphaDraw, bool), f32, usize)> = scene
        .draws
        .iter()
        .enumerate()
        .filter(|(_, dr)| {
            !scene.frustum_culling || !dr.world_bounds.outside_clip_volume(&cull.clip_from_world)
        })
        .map(|(i, dr)| {
            let nearest = cull.eye.0.clamp(dr.world_bounds.min, dr.world_bounds.max);
            // A ground plane's nearest point is right under the eye, but it hides nothing: drawn
            // last, its fragments behind everything else fail the early depth test.
            let hides_nothing = dr
                .world_plane
                .is_some_and(|pl| flat_hides_nothing(pl, cull.viewpoint, &scene.bounds));
            let key = (dr.alpha, hides_nothing && dr.alpha != AlphaDraw::Blended);
            let distance = match dr.alpha {
                AlphaDraw::Blended => -dr.world_bounds.center().distance_squared(cull.eye.0),
                _ => nearest.distance_squared(cull.eye.0),
            };
            (key, distance, i)
        })
        .collect();
    v.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    v.into_iter().map(|(_, _, i)| i).collect()
}

/// An opaque forward draw on a CPU device reads its uniforms as flat inputs (`fs_main_flat`)
/// when its triangles cover at least this many pixels on average (`pixels_per_triangle`): a
/// uniform read costs llvmpipe a bounds-checked load per lane for every 8 pixels
/// (shaders/lib/uniforms.wgsl), a flat input costs its triangle setup 31 vec4 inputs. At one
/// 4×4 block per triangle the setup's cost is a fraction of what it saves.
pub const FLAT_FROM_PIXELS: f32 = 16.0;

/// Locations of `FlatOut` (shaders/lib/uniforms.wgsl: the varyings and the uniforms' values).
pub const FLAT_LOCATIONS: u32 = 31;

/// Whether the device passes `FLAT_LOCATIONS` vec4 from vertex to fragment shader (lavapipe and
/// desktop GPUs take 32; Vulkan guarantees 16).
pub(super) fn flat_inputs_fit(ctx: &Context) -> bool {
    let l = &ctx.properties.limits;
    FLAT_LOCATIONS * 4
        <= l.max_vertex_output_components
            .min(l.max_fragment_input_components)
}

/// What the camera pass records in one frame, decided before recording: its culling inputs, the
/// draws in order split between the G-buffer and the forward pass, and for each forward draw
/// whether it needs the shadow lookup everywhere, nowhere or in part (`receivers::split`) and
/// whether it reads its uniforms as flat inputs.
pub struct CameraFrame {
    /// The culling and variant inputs.
    pub cull: CameraCull,
    /// Draw the shadow map full-screen instead of the scene (the map debug view).
    pub shadow_map_view: bool,
    /// Draw the sky where no surface is (the lit image with `Background::Sky`).
    pub sky: bool,
    /// Deferred and forward draws.
    pub defer: DeferPlan,
    /// Per forward draw (`defer.forward`), its receiver split.
    pub splits: Vec<Split>,
    /// Per forward draw, whether it reads the uniforms as flat inputs (`FLAT_FROM_PIXELS`).
    pub flat: Vec<bool>,
    /// The pass also draws each pixel's instance id and world normal into two more targets
    /// (`CameraTargets::aovs`; lit images at one sample per pixel: `CameraPass::can_draw_aovs`).
    pub aovs: bool,
}

impl CameraFrame {
    /// The entry point of a forward draw treating alpha as `alpha`, `flat`: reading the uniforms
    /// as flat inputs.
    pub(super) fn entry(&self, alpha: AlphaDraw, flat: bool) -> Entry {
        let e = if flat {
            Entry::OpaqueFlat
        } else {
            Entry::of(alpha, self.cull.debug_view)
        };
        self.with_aovs(e)
    }

    /// `e`, or its counterpart writing the ids and normals when the frame draws them.
    pub(super) fn with_aovs(&self, e: Entry) -> Entry {
        if self.aovs {
            e.with_aovs()
        } else {
            e
        }
    }
}

impl CameraPass {
    /// Whether this pass can draw the instance ids and normals as extra targets of the lit
    /// image (`CameraFrame::aovs`): at one sample per pixel (an id is never a blend of samples,
    /// and the depth read with them is the pixel centre's), on a device whose targets can be
    /// left alone one by one (independent blend; lavapipe and desktop GPUs have it).
    pub fn can_draw_aovs(&self) -> bool {
        self.samples == 1 && self.ctx.independent_blend
    }

    /// Decides what the camera pass draws for `cull` at `extent`: the draw order, the deferred
    /// split (`deferred::plan`) and each forward draw's receiver split; `sky`: the background is
    /// the sky (not drawn with the shadow-map view).
    pub fn plan_frame(
        &self,
        scene: &GpuScene,
        cull: CameraCull,
        extent: vk::Extent2D,
        shadow_map_view: bool,
        sky: bool,
    ) -> CameraFrame {
        let order = if shadow_map_view {
            Vec::new()
        } else {
            draw_order(scene, &cull)
        };
        let defer = deferred::plan(order, &scene.draws, &cull, extent, self.deferred);
        let splits = defer
            .forward
            .iter()
            .map(|&i| {
                cull.shadow_reach.as_ref().map_or(Split::Shadowed, |r| {
                    receivers::split(r, &scene.draws[i], &cull.clip_from_world, extent)
                })
            })
            .collect();
        let flat = defer
            .forward
            .iter()
            .map(|&i| {
                let dr = &scene.draws[i];
                self.flat_forward
                    && Entry::of(dr.alpha, cull.debug_view) == Entry::Opaque
                    && pixels_per_triangle(dr, &cull.clip_from_world, extent) >= FLAT_FROM_PIXELS
            })
            .collect();
        CameraFrame {
            cull,
            shadow_map_view,
            sky: sky && !shadow_map_view,
            defer,
            splits,
            flat,
            aovs: false,
        }
    }
}

/// Draws one camera pass recorded.
#[derive(Clone, Copy, Debug)]
pub struct CameraCounts {
    /// Draws recorded (deferred ones included).
    pub drawn: usize,
    /// Of those, draws shaded deferred.
    pub deferred: usize,
    /// Of those, draws drawn wholly or in part without the shadow lookup.
    pub unshadowed: usize,
    /// Of those, forward draws reading the uniforms as flat inputs (`FLAT_FROM_PIXELS`).
    pub flat: usize,
}

/// The attachments a camera pass draws into (already in attachment layouts), where it resolves
/// to, its size and its clear colour.
#[derive(Clone, Copy, Debug)]
pub struct CameraTargets {
    /// The colour attachment (multisampled with MSAA).
    pub color: vk::ImageView,
    /// The depth attachment (multisampled with MSAA).
    pub depth: vk::ImageView,
    /// The single-sample images MSAA resolves into.
    pub resolve: Resolve,
    /// The image size.
    pub extent: vk::Extent2D,
    /// The linear clear colour.
    pub clear: [f32; 4],
    /// The instance-id and normal targets (`AOV_FORMATS`, one sample, in attachment layouts)
    /// of a frame that draws them (`CameraFrame::aovs`).
    pub aovs: Option<[vk::ImageView; 2]>,
}

/// The attachments the G-buffer rendering writes and the forward rendering after it draws on
/// (same layouts): the depth and stencil drawn into (multisampled with MSAA), and the ids and
/// normals asked for. The camera pass declares them written again between the two renderings.
pub struct Redrawn<'a> {
    /// The depth (and stencil) attachment.
    pub depth: &'a mut Attachment,
    /// The instance-id and normal targets asked for.
    pub aovs: Vec<&'a mut Attachment>,
}

/// Where a multisampled camera pass resolves to (both None without MSAA).
#[derive(Clone, Copy, Debug, Default)]
pub struct Resolve {
    /// The single-sample colour image the samples are averaged into.
    pub color: Option<vk::ImageView>,
    /// The single-sample depth image sample 0 is copied into (for depth readback).
    pub depth: Option<vk::ImageView>,
}

#[cfg(test)]
mod tests {
    /// `FLAT_LOCATIONS` counts `FlatOut` (checked against the device's limits).
    #[test]
    fn flat_locations_match_the_shader() {
        let source = include_str!("../../../../shaders/lib/uniforms.wgsl");
        let start = source
            .find("struct FlatOut {")
            .expect("FlatOut in uniforms.wgsl");
        let end = start + source[start..].find('}').expect("its end");
        let locations = source[start..end].matches("@location(").count();
        assert_eq!(locations as u32, super::FLAT_LOCATIONS);
    }
}
