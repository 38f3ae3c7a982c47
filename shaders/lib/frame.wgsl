// The frame block the camera pass reads (src/plan/uniforms.rs is its Rust twin; build.rs checks
// the sizes and generates the constants below as Rust constants).

const MAX_LIGHTS: u32 = 8u;
const MAX_SHADOW_VIEWS: i32 = 16;
const LIGHT_DIRECTIONAL: f32 = 0.0;
const LIGHT_POINT: f32 = 1.0;
const LIGHT_SPOT: f32 = 2.0;

const VIEW_LIT: u32 = 0u;
const VIEW_SHADOW: u32 = 1u;
const VIEW_NORMALS: u32 = 2u;
const VIEW_CASCADES: u32 = 3u;
const VIEW_UV_CHECKER: u32 = 4u;
const VIEW_TANGENTS: u32 = 5u;
const VIEW_BITANGENTS: u32 = 6u;
const VIEW_BASE_COLOR: u32 = 7u;
const VIEW_METALLIC: u32 = 8u;
const VIEW_ROUGHNESS: u32 = 9u;
const VIEW_DEPTH: u32 = 10u;
const VIEW_TEXEL_DENSITY: u32 = 11u;
const VIEW_OVERDRAW: u32 = 12u;
// UV checker cells per unit of texture coordinate.
const CHECKER_CELLS: f32 = 8.0;
// Overdraw view: linear value each fragment adds (additive blending), so n layers read back as
// n / 16 after decoding the sRGB byte.
const OVERDRAW_STEP: f32 = 0.0625;

struct Light {
    // xyz: position (point, spot); w: kind (0 directional, 1 point, 2 spot)
    position: vec4<f32>,
    // xyz: unit direction the light travels (directional, spot); w: soft-shadow size, 0 for hard
    // shadows (directional: tan of half the angular diameter; point, spot: the radius)
    direction: vec4<f32>,
    // rgb: colour * intensity; w: unused
    color: vec4<f32>,
    // x: cos(inner cone), y: cos(outer cone), z: range (0: none)
    cone: vec4<f32>,
    // x: first shadow view (-1: casts none), y: its view count (cascades near to far; 6 cube
    // faces +x, -x, +y, -y, +z, -z for a point light)
    shadow: vec4<f32>,
}

// One layer of the shadow map.
struct ShadowView {
    // World -> light clip.
    clip: mat4x4<f32>,
    // Texel rectangle (x0, y0, x1, y1) outside which a lookup's footprint meets no caster: lit
    // there, without reading the map (the shadow pass clears only what it draws).
    rect: vec4<f32>,
    // x: view depth where this cascade ends, y: where blending into the next one starts,
    // z: world size of one texel (directional) or per unit distance (spot, point face),
    // w: its side in texels (it fills that square at the layer's origin; <= the map size).
    cascade: vec4<f32>,
}

struct Frame {
    clip_from_world: mat4x4<f32>,
    // Its inverse (the deferred resolve rebuilds world positions from depth).
    world_from_clip: mat4x4<f32>,
    // xyz: camera position in world
    camera_position: vec4<f32>,
    // rgb: ambient Ia of a surface facing up (the sky)
    ambient_sky: vec4<f32>,
    // rgb: ambient Ia of a surface facing down (the ground); between, mixed by the normal's y
    ambient_ground: vec4<f32>,
    // x: shadow-map size in texels, y: normal-offset bias in texels,
    // z: view depth that the depth view draws black (the scene's far end), w: 1 if shadows on
    shadow: vec4<f32>,
    // w: index of the light whose visibility `--view shadow` writes (MAX_LIGHTS + 1 when none);
    // xyz: the eye the cascades are split from (the shadow-fitting camera)
    shadow_light: vec4<f32>,
    // x: constant bias in shadow texels, applied towards the light
    bias: vec4<f32>,
    // xyz: the shadow-fitting camera's forward (view depth = dot(p - shadow_light.xyz, forward))
    camera_forward: vec4<f32>,
    // xyz: the view camera's forward; w: 1 for an orthographic camera (seen along xyz everywhere)
    eye_forward: vec4<f32>,
    // x: view mode, y: PCF kernel width in bilinear taps (0 = single nearest compare),
    // z: 1 if hardware linear comparison filtering is used, w: number of lights
    modes: vec4<u32>,
    // x: exposure (linear scale before tone mapping), y: tone-mapping operator (0 none, 1 Khronos
    // PBR Neutral, 2 ACES Hill), z: the scale of unlit colours, w: 1 when unlit colours are shown
    // as authored (times z, no tone curve), 0 when exposed and tone-mapped like lit ones
    output: vec4<f32>,
    lights: array<Light, 8>,
    // Layer i of the shadow map belongs to view i.
    views: array<ShadowView, 16>,
}
