//! What the camera pass is told per frame: which draws it records and with which fragment
//! entry point.

use crate::plan::ShadowReach;
use crate::plan::Viewpoint;
use crate::render::gpu_scene::AlphaDraw;
use crate::shader_consts::VariantKey;
use glam::{Mat4, Vec3};

/// What the camera pass needs per frame to do only the work the frame needs: the camera's world →
/// clip (draws whose bounds lie outside it are not recorded), its eye with the near plane's reach
/// (for `Draw::cull_mode`), and which shader variant and entry point to draw with.
pub struct CameraCull {
    /// The camera's world → clip.
    pub clip_from_world: Mat4,
    /// Eye position and the distance from it to the near plane's farthest corner.
    pub eye: (Vec3, f32),
    /// What faces are seen from: the eye (perspective) or the viewing direction (orthographic),
    /// for skipping clusters that face away and flat draws that hide nothing.
    pub viewpoint: Viewpoint,
    /// The frame's shader variant bits (`FramePlan::shader_variant`).
    pub frame_bits: VariantKey,
    /// A debug view's entry (`Entry::Debug` or `Entry::Overdraw`); `None` for the lit image.
    pub debug_view: Option<Entry>,
    /// The (instance, primitive) drawn tinted (`View::highlight`).
    pub highlight: Option<(usize, usize)>,
    /// Where the frame's single shadow view can shadow anything, when small receivers are
    /// drawn unshadowed beyond it (`crate::render::passes::receivers`).
    pub shadow_reach: Option<ShadowReach>,
}

/// The fragment entry point of a scene pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Entry {
    /// `fs_main`: opaque materials, lit image, no discard (early depth on llvmpipe).
    Opaque,
    /// `fs_main_flat`: `Opaque` with the uniforms as flat inputs (large triangles on CPU
    /// devices: `camera::FLAT_FROM_PIXELS`).
    OpaqueFlat,
    /// `fs_masked`: alpha-masked materials, lit image.
    Masked,
    /// `fs_debug`: the debug views (shadow visibility, normals, cascades, UV checker, …).
    Debug,
    /// `fs_debug` with additive blending and no depth test: the overdraw view.
    Overdraw,
    /// `fs_blend`: blended materials, lit image, blended over (no depth write).
    Blended,
    /// `fs_resolve` on a full-screen triangle: a deferred material's pixels (stencil equal to
    /// its mark), shaded from the G-buffer.
    Resolve,
    /// `fs_gbuffer`: a deferred draw's varyings into the G-buffer, its material's mark into the
    /// stencil (one pipeline per combination of texture slots: `deferred::gbuffer_variant`).
    GBuffer,
    /// `fs_aov`: an opaque material's instance ids and world normals into their own targets
    /// (`CameraPass::record_aov`; no texture read, no discard).
    Aov,
    /// `fs_aov_masked`: `Aov` for alpha-masked materials, discarding below the cutoff.
    AovMasked,
    /// `fs_main_aov`: `Opaque` in a camera pass that also draws the instance ids and normals as
    /// targets 1 and 2 (`CameraFrame::aovs`).
    OpaqueAov,
    /// `fs_main_flat_aov`: `OpaqueFlat` writing them too.
    OpaqueFlatAov,
    /// `fs_masked_aov`: `Masked` writing them too.
    MaskedAov,
    /// `fs_blend` in that pass: targets 1 and 2 left alone (blended surfaces have no id).
    BlendedAov,
    /// `fs_resolve` in that pass: targets 1 and 2 left alone (the G-buffer pass wrote them).
    ResolveAov,
    /// `fs_gbuffer_aov`: the ids and normals (targets 0 and 1) and the G-buffer (2 and 3).
    GBufferAov,
}

impl Entry {
    /// The entry point for a draw of a material treating alpha as `alpha` in a lit or debug view
    /// (debug views draw a blended material where it casts, alpha ≥ 0.5, as opaque: the receivers
    /// the reference judges).
    pub fn of(alpha: AlphaDraw, debug_view: Option<Entry>) -> Entry {
        match (debug_view, alpha) {
            (Some(e), _) => e,
            (None, AlphaDraw::Masked) => Entry::Masked,
            (None, AlphaDraw::Blended) => Entry::Blended,
            (None, AlphaDraw::Opaque) => Entry::Opaque,
        }
    }

    /// This entry's counterpart in a camera pass that also draws the instance ids and normals
    /// (itself where the pass has none: debug views never draw them).
    pub fn with_aovs(self) -> Entry {
        match self {
            Entry::Opaque => Entry::OpaqueAov,
            Entry::OpaqueFlat => Entry::OpaqueFlatAov,
            Entry::Masked => Entry::MaskedAov,
            Entry::Blended => Entry::BlendedAov,
            Entry::Resolve => Entry::ResolveAov,
            Entry::GBuffer => Entry::GBufferAov,
            e => e,
        }
    }

    /// The AOV pass's entry point for a draw of a material treating alpha as `alpha` (blended
    /// materials are not drawn there).
    pub fn aov(alpha: AlphaDraw) -> Entry {
        match alpha {
            AlphaDraw::Masked => Entry::AovMasked,
            _ => Entry::Aov,
        }
    }
}
