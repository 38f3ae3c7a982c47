// Light-space depth pass: position-only vertex stream, no fragment shader output.
// Depth is reversed-z (near the light -> 1, far -> 0); see src/math/projection.rs.
//
// Alpha-masked casters (glTF alphaMode MASK) have their own pipeline: vs_masked passes
// TEXCOORD_0 on and fs_masked discards where the base colour's alpha (factor x texture) is below
// the cutoff, exactly the test of the camera pass's fs_masked. Opaque casters keep the depth-only
// pipeline (no fragment shader at all).

struct ShadowImmediates {
    light_clip_from_world: mat4x4<f32>,
    world_from_model: mat4x4<f32>,
}

var<immediate> pc: ShadowImmediates;

// The camera pass's material block (shaders/lib/material.wgsl): the masked pipeline binds the same
// descriptor set, at set 0 of its layout, and a unit test (src/gpu/shaders.rs) checks every
// binding here against its twin there.
#include "lib/material.wgsl"

@group(0) @binding(0) var<uniform> material: Material;
@group(0) @binding(1) var base_color_tex: texture_2d<f32>;
@group(0) @binding(5) var base_color_sampler: sampler;

@vertex
fn vs_main(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return pc.light_clip_from_world * (pc.world_from_model * vec4<f32>(position, 1.0));
}

struct MaskedOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec4<f32>,
    @location(1) alpha: f32,
}

@vertex
fn vs_masked(
    @location(0) position: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(4) color: vec4<f32>,
    @location(5) uv1: vec2<f32>,
) -> MaskedOut {
    var out: MaskedOut;
    out.clip = pc.light_clip_from_world * (pc.world_from_model * vec4<f32>(position, 1.0));
    out.uv = vec4<f32>(uv, uv1);
    // COLOR_0's alpha multiplies the base colour's, as in the camera pass.
    out.alpha = color.a;
    return out;
}

@fragment
fn fs_masked(in: MaskedOut) {
    // Mip 0, as the reference's shadow rays read it: a shadow texel's footprint on the caster has
    // nothing to do with the camera's, and a mip averaged across the cutoff would grow or eat the
    // pattern (FlightHelmet's lenses: alpha 0.14-0.74 around the 0.5 cutoff).
    let alpha = in.alpha * material.base_color.a * textureSampleLevel(base_color_tex, base_color_sampler, slot_uv(0u, in.uv), 0.0).a;
    if alpha < material.extra.y {
        discard;
    }
}
