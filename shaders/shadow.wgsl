// Light-space depth pass: position-only vertex stream, no fragment shader output.
// Depth is reversed-z (near the light -> 1, far -> 0); see src/math/projection.rs.

struct ShadowImmediates {
    light_clip_from_world: mat4x4<f32>,
    world_from_model: mat4x4<f32>,
}

var<immediate> pc: ShadowImmediates;

@vertex
fn vs_main(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return pc.light_clip_from_world * (pc.world_from_model * vec4<f32>(position, 1.0));
}
