// Camera pass: Blinn-Phong with tangent-space normal mapping and shadow-map visibility.
//
// L = ka*Ia + sum_i vis_i * [ kd*(I/r^2)*max(0,n.l) + ks*(I/r^2)*max(0,n.h)^p ]
// where vis_i is (geometric n.l > 0) times, for a light with shadow views, the filtered shadow-map
// comparison in its view. `--view shadow` writes exactly one light's vis_i (the shown light).
//
// Reversed-z everywhere: the shadow map stores the largest depth (closest to the light); a receiver
// is lit where its light-space depth >= the stored depth (compare op GREATER_OR_EQUAL).
// Y convention: clip space is Y-up, naga flips Y for Vulkan (build.rs); shadow UV v = 0.5 - 0.5*y.

const MAX_LIGHTS: u32 = 8u;
const MAX_SHADOW_VIEWS: i32 = 16;
const LIGHT_DIRECTIONAL: f32 = 0.0;
const LIGHT_POINT: f32 = 1.0;
const LIGHT_SPOT: f32 = 2.0;

// Specialisation (build.rs writes one SPIR-V per combination; the renderer picks per draw):
// which texture slots the material fills (an empty slot's default texture is white, a factor of 1,
// so leaving its fetch out gives the same value), whether the frame has exactly one light, and
// whether the frame samples a shadow map.
// The PCF kernel and the comparison path are per frame too: PCF_BIT0 + 2 * PCF_BIT1 selects 0, 1,
// 3 or 5 bilinear taps per side (none, 2x2, 3x3, 5x5); HW_COMPARE uses hardware filtering.
override HAS_BASE_TEX: bool = true;
override HAS_NORMAL_MAP: bool = true;
override HAS_OTHER_TEX: bool = true; // metallic-roughness, emissive or occlusion
override SINGLE_LIGHT: bool = false;
override SHADOWS: bool = true;
override HW_COMPARE: bool = false; // requires SHADOWS
override PCF_BIT0: bool = true; // requires SHADOWS
override PCF_BIT1: bool = false; // requires SHADOWS
// More than one shadow view (cascades, several shadowed lights, a point light's cube faces): each
// light reads its own views, chosen per pixel; without, the one shadowed light reads view 0.
override MANY_VIEWS: bool = true; // requires SHADOWS
// A shadowed light has a size (light.direction.w > 0): its lookups are PCSS soft shadows.
override SOFT: bool = true; // requires SHADOWS

// Bilinear taps per side of the PCF kernel (0 = one nearest comparison).
fn pcf_taps() -> i32 {
    if PCF_BIT1 {
        return select(3, 5, PCF_BIT0);
    }
    return select(0, 1, PCF_BIT0);
}

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
    // rgb: ambient intensity Ia
    ambient: vec4<f32>,
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
    // x: view mode, y: PCF kernel width in bilinear taps (0 = single nearest compare),
    // z: 1 if hardware linear comparison filtering is used, w: number of lights
    modes: vec4<u32>,
    // x: exposure (linear scale before tone mapping), y: tone-mapping operator (0 none, 1 Khronos
    // PBR Neutral, 2 ACES Hill)
    output: vec4<f32>,
    lights: array<Light, 8>,
    // Layer i of the shadow map belongs to view i.
    views: array<ShadowView, 16>,
}

struct Material {
    base_color: vec4<f32>,
    // rgb: emissive factor; w: normal-map scale
    emissive: vec4<f32>,
    // x: metallic, y: roughness, z: occlusion strength (0 without an occlusion texture; the
    // occlusion is the red channel of the metallic-roughness texture, packed at upload as glTF's
    // ORM layout), w: 1 if unlit
    params: vec4<f32>,
    // x: alpha cutoff of the camera pass (masked materials; 0 = none), y: alpha cutoff of the
    // shadow pass (masked: the same; blended: 0.5; 0 = opaque caster)
    extra: vec4<f32>,
    // KHR_texture_transform rows per slot (base colour, normal, metallic-roughness, emissive):
    // u' = dot(uv[2i].xyz, (u, v, 1)), v' = dot(uv[2i + 1].xyz, (u, v, 1)).
    uv: array<vec4<f32>, 8>,
}

// Texture coordinates of slot i (0 base colour, 1 normal, 2 metallic-roughness, 3 emissive).
// `uvs` holds TEXCOORD_0 (xy) and TEXCOORD_1 (zw); uv[2i].w says which set the slot reads.
fn slot_uv(i: u32, uvs: vec4<f32>) -> vec2<f32> {
    let p = vec3<f32>(select(uvs.xy, uvs.zw, material.uv[2u * i].w > 0.5), 1.0);
    return vec2<f32>(dot(material.uv[2u * i].xyz, p), dot(material.uv[2u * i + 1u].xyz, p));
}

struct Immediates {
    world_from_model: mat4x4<f32>,
    // columns of the normal matrix (inverse transpose of the upper 3x3); normal_x.w = sign of det,
    // normal_y.w = 1 to tint the draw orange (the viewer's picked primitive)
    normal_x: vec4<f32>,
    normal_y: vec4<f32>,
    normal_z: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var shadow_map: texture_depth_2d_array;
@group(0) @binding(2) var shadow_sampler: sampler_comparison;

@group(1) @binding(0) var<uniform> material: Material;
@group(1) @binding(1) var base_color_tex: texture_2d<f32>;
@group(1) @binding(2) var normal_tex: texture_2d<f32>;
@group(1) @binding(3) var metal_rough_tex: texture_2d<f32>;
@group(1) @binding(4) var emissive_tex: texture_2d<f32>;
// One sampler per texture slot: the glTF texture's own filters and wrap modes.
@group(1) @binding(5) var base_color_sampler: sampler;
@group(1) @binding(6) var normal_sampler: sampler;
@group(1) @binding(7) var metal_rough_sampler: sampler;
@group(1) @binding(8) var emissive_sampler: sampler;

var<immediate> pc: Immediates;

struct VsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
    // COLOR_0 (white without one), multiplying the base colour.
    @location(4) color: vec4<f32>,
    // TEXCOORD_1 (TEXCOORD_0 without one).
    @location(5) uv1: vec2<f32>,
}

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    // Centroid: with MSAA a pixel on a silhouette is shaded at a point inside the triangle, so
    // its shadow lookup and lighting never use a position extrapolated past the edge (without
    // MSAA the centroid is the pixel centre).
    @location(0) @interpolate(perspective, centroid) world_position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // xy: TEXCOORD_0, zw: TEXCOORD_1.
    @location(2) uv: vec4<f32>,
    @location(3) tangent: vec4<f32>,
    @location(4) color: vec4<f32>,
}

@vertex
fn vs_main(v: VsIn) -> VsOut {
    var out: VsOut;
    let world = pc.world_from_model * vec4<f32>(v.position, 1.0);
    out.world_position = world.xyz;
    out.clip = frame.clip_from_world * world;
    let normal_matrix = mat3x3<f32>(pc.normal_x.xyz, pc.normal_y.xyz, pc.normal_z.xyz);
    out.normal = normal_matrix * v.normal;
    let m3 = mat3x3<f32>(pc.world_from_model[0].xyz, pc.world_from_model[1].xyz, pc.world_from_model[2].xyz);
    // A mirroring transform flips the bitangent.
    out.tangent = vec4<f32>(m3 * v.tangent.xyz, v.tangent.w * pc.normal_x.w);
    out.uv = vec4<f32>(v.uv, v.uv1);
    out.color = v.color;
    return out;
}

// One depth comparison against texel `c` (clamped to the map): 1 = lit.
fn compare_texel(c: vec2<i32>, layer: i32, depth: f32, size: i32) -> f32 {
    let cc = clamp(c, vec2<i32>(0), vec2<i32>(size - 1));
    let stored = textureLoad(shadow_map, cc, layer, 0);
    return select(0.0, 1.0, depth >= stored);
}

// Bilinearly weighted 2x2 comparison at a position given in texel units (texel centres at +0.5)
// of a view `size` texels wide.
fn bilinear_compare(p: vec2<f32>, layer: i32, depth: f32, size: i32) -> f32 {
    if HW_COMPARE {
        return textureSampleCompareLevel(shadow_map, shadow_sampler, p / frame.shadow.x, layer, depth);
    }
    let t = p - vec2<f32>(0.5);
    let i = vec2<i32>(floor(t));
    let f = t - floor(t);
    let c00 = compare_texel(i, layer, depth, size);
    let c10 = compare_texel(i + vec2<i32>(1, 0), layer, depth, size);
    let c01 = compare_texel(i + vec2<i32>(0, 1), layer, depth, size);
    let c11 = compare_texel(i + vec2<i32>(1, 1), layer, depth, size);
    return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}

// View depth of world point `p` along the shadow-fitting camera's forward axis.
fn view_depth(p: vec3<f32>) -> f32 {
    return dot(p - frame.shadow_light.xyz, frame.camera_forward.xyz);
}

// The cascade (of the `n` views from `first`) holding world point `p` by view depth alone (no
// dither; the texel-density view reads it directly); relative to `first`.
fn cascade_of(p: vec3<f32>, first: i32, n: i32) -> i32 {
    let d = view_depth(p);
    var c = 0;
    for (var k = 0; k < 3; k++) {
        c += select(0, 1, k + 1 < n && d > frame.views[min(first + k, MAX_SHADOW_VIEWS - 1)].cascade.x);
    }
    return c;
}

// The cascade (relative to `first`) for world point `p` seen at pixel `pixel`: the cascade holding
// its view depth; within the blend band at a cascade's end, the next cascade for a share of pixels
// growing from 0 to 1 across the band (interleaved-gradient dither: no seam line, and every
// lookup stays a single exact one, which llvmpipe, running both sides of every branch, pays once).
fn cascade_index(p: vec3<f32>, pixel: vec2<f32>, first: i32, n: i32) -> i32 {
    let d = view_depth(p);
    let c = cascade_of(p, first, n);
    let v = frame.views[min(first + c, MAX_SHADOW_VIEWS - 1)].cascade;
    let start = v.y;
    let t = clamp((d - start) / max(v.x - start, 1e-20), 0.0, 1.0);
    let noise = fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
    return select(c, c + 1, c + 1 < n && noise < t);
}

// The cube face of direction `d` from a point light (+x, -x, +y, -y, +z, -z): its major axis.
fn cube_face(d: vec3<f32>) -> i32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1, 0, d.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3, 2, d.y >= 0.0);
    }
    return select(5, 4, d.z >= 0.0);
}

// The shadow view of `light` (first view `first`, `n` views) for world point `p` at `pixel`.
fn light_view(light: Light, p: vec3<f32>, pixel: vec2<f32>, first: i32, n: i32) -> i32 {
    if light.position.w == LIGHT_POINT {
        return first + cube_face(p - light.position.xyz);
    }
    return first + cascade_index(p, pixel, first, n);
}

// Filtered shadow-map visibility of world point `p` with geometric normal `ng`, in shadow view
// `layer` of light `light` whose direction at `p` is `l` (call only when shadows are on).
fn shadow_visibility(p: vec3<f32>, ng: vec3<f32>, l: vec3<f32>, light: Light, layer: i32, pixel: vec2<f32>) -> f32 {
    let view = frame.views[layer];
    var texel_world = view.cascade.z;
    if light.position.w != LIGHT_DIRECTIONAL {
        texel_world = texel_world * distance(light.position.xyz, p);
    }
    // Normal offset: move the lookup point off the surface by a number of shadow texels, more at
    // grazing angles where acne appears.
    let cos_theta = clamp(dot(ng, l), 0.0, 1.0);
    let sin_theta = sqrt(1.0 - cos_theta * cos_theta);
    // Constant bias: towards the light by a number of texels (so it scales with texel size).
    let offset = ng * (frame.shadow.y * texel_world * sin_theta) + l * (frame.bias.x * texel_world);
    let lc = view.clip * vec4<f32>(p + offset, 1.0);
    if lc.w <= 0.0 {
        return 1.0;
    }
    let ndc = lc.xyz / lc.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let p_texel = uv * view.cascade.w;
    // Outside the casters' rectangle (which lies inside the map) nothing is in shadow.
    let rect = view.rect;
    if any(p_texel < rect.xy) || any(p_texel > rect.zw) {
        return 1.0;
    }
    // Depth clamp is on in the shadow pass, so receivers are clamped the same way.
    let depth = clamp(ndc.z, 0.0, 1.0);
    let size = i32(view.cascade.w);
    if SOFT && light.direction.w > 0.0 {
        let grad = receiver_gradient(view, p + offset, ng, texel_world);
        return soft_visibility(view, light, layer, p_texel, depth, grad, texel_world, pixel);
    }
    let kernel = pcf_taps();
    if kernel == 0 {
        return compare_texel(vec2<i32>(floor(p_texel)), layer, depth, size);
    }
    let half = (kernel - 1) / 2;
    var sum = 0.0;
    if HW_COMPARE {
        // Hardware bilinear comparisons, one per tap.
        for (var y = -half; y <= half; y++) {
            for (var x = -half; x <= half; x++) {
                sum += bilinear_compare(p_texel + vec2<f32>(f32(x), f32(y)), layer, depth, size);
            }
        }
        return sum / f32(kernel * kernel);
    }
    // By hand: the kernel x kernel bilinear taps at one-texel spacing cover (kernel+1)^2 texels;
    // each texel's weight is separable, wx[i] = (1-fx)[i < kernel] + fx[i > 0], so every texel is
    // compared once. kernel + 1 is even, so the texels come in 2x2 blocks, one gathered comparison
    // each (the nearest comparison sampler clamps to the edge like the texel clamp above).
    let t = p_texel - vec2<f32>(0.5);
    let base = floor(t) - vec2<f32>(f32(half));
    let f = t - floor(t);
    let inv = 1.0 / frame.shadow.x;
    for (var bj = 0; bj <= kernel; bj += 2) {
        let wy0 = select(0.0, 1.0 - f.y, bj < kernel) + select(0.0, f.y, bj > 0);
        let wy1 = select(0.0, 1.0 - f.y, bj + 1 < kernel) + f.y;
        for (var bi = 0; bi <= kernel; bi += 2) {
            let wx0 = select(0.0, 1.0 - f.x, bi < kernel) + select(0.0, f.x, bi > 0);
            let wx1 = select(0.0, 1.0 - f.x, bi + 1 < kernel) + f.x;
            // Sampling at the corner shared by the block's four texels gathers exactly them:
            // x = (i0, j1), y = (i1, j1), z = (i1, j0), w = (i0, j0).
            let corner = (base + vec2<f32>(f32(bi) + 1.0, f32(bj) + 1.0)) * inv;
            let g = textureGatherCompare(shadow_map, shadow_sampler, corner, layer, depth);
            sum += wy0 * (wx0 * g.w + wx1 * g.z) + wy1 * (wx0 * g.x + wx1 * g.y);
        }
    }
    return sum / f32(kernel * kernel);
}

// PCSS (percentage-closer soft shadows, Fernando 2005) for a light of size light.direction.w:
// a blocker search over the widest penumbra this receiver can have, then a filter whose radius is
// the penumbra the average blocker casts by similar triangles: (d_receiver - d_blocker) * tan(half
// angle) for a directional light, radius * (d_receiver - d_blocker) / d_blocker for a point or
// spot light. Both on a golden-angle spiral turned per pixel (interleaved-gradient noise), so
// the filter's banding becomes fine noise; each tap compares against the receiver's plane
// (`grad`), so a wide kernel does not shadow the sloped surface it lies on.
const SOFT_TAPS: i32 = 16;
// Widest penumbra radius filtered, in texels (render::frame::SOFT_MAX_TEXELS).
const SOFT_MAX_TEXELS: f32 = 32.0;

// Tap k of the unit disk's area-uniform golden-angle spiral, r = sqrt((k + 0.5) / SOFT_TAPS),
// whose direction `dir` the caller turns by the golden angle from tap to tap (no trigonometry
// or table per tap: both cost more than the taps' arithmetic on llvmpipe).
fn spiral(k: i32, dir: vec2<f32>) -> vec2<f32> {
    return sqrt((f32(k) + 0.5) / f32(SOFT_TAPS)) * dir;
}

// `d` turned by the golden angle, 2.39996323 rad.
fn golden_turn(d: vec2<f32>) -> vec2<f32> {
    let c = -0.737369;
    let s = 0.675490;
    return vec2<f32>(d.x * c - d.y * s, d.x * s + d.y * c);
}

// Distance from the light (directional: from the view's near plane) of NDC depth `z` in `view`.
fn light_distance(view: ShadowView, z: f32, directional: bool) -> f32 {
    if directional {
        // Orthographic, reversed: depth falls by 1 over 1 / |z row| world units from the near plane.
        let row = vec3<f32>(view.clip[0].z, view.clip[1].z, view.clip[2].z);
        return (1.0 - z) / max(length(row), 1e-30);
    }
    // Reversed-z infinite perspective: z = near / d.
    return view.clip[3].z / max(z, 1e-30);
}

// Penumbra radius in texels at a receiver `d_r` from the light behind a blocker at `d_b` (depths
// along the view's axis; `tw`: the receiver's texel in world units).
fn penumbra_texels(light: Light, d_r: f32, d_b: f32, tw: f32) -> f32 {
    let w = max(d_r - d_b, 0.0) * light.direction.w / max(tw, 1e-30);
    return select(w / max(d_b, 1e-30), w, light.position.w == LIGHT_DIRECTIONAL);
}

// Texel position and NDC depth of world point `q` in `view`.
fn to_texels(view: ShadowView, q: vec3<f32>) -> vec3<f32> {
    let c = view.clip * vec4<f32>(q, 1.0);
    let n = c.xyz / c.w;
    return vec3<f32>(vec2<f32>(n.x * 0.5 + 0.5, 0.5 - n.y * 0.5) * view.cascade.w, n.z);
}

// The depth change per texel across the receiver's plane (normal `ng`, through `q`), so that a
// tap `o` texels away compares at depth + dot(grad, o). Limited to 8 texels' worth of depth per
// texel, which a plane seen edge-on from the light would exceed.
fn receiver_gradient(view: ShadowView, q: vec3<f32>, ng: vec3<f32>, tw: f32) -> vec2<f32> {
    let a = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(ng.x) > 0.7);
    let t1 = normalize(cross(ng, a)) * tw;
    let t2 = normalize(cross(ng, t1)) * tw;
    let c0 = to_texels(view, q);
    let e1 = to_texels(view, q + t1) - c0;
    let e2 = to_texels(view, q + t2) - c0;
    let det = e1.x * e2.y - e1.y * e2.x;
    if abs(det) < 1e-6 {
        return vec2<f32>(0.0);
    }
    let g = vec2<f32>(e1.z * e2.y - e1.y * e2.z, e1.x * e2.z - e2.x * e1.z) / det;
    // Depth of one texel's world size along the light (orthographic) as the scale of the limit.
    let row = vec3<f32>(view.clip[0].z, view.clip[1].z, view.clip[2].z);
    let limit = 8.0 * max(length(row) * tw, abs(c0.z) * 0.05);
    let m = length(g);
    return select(g, g * (limit / m), m > limit);
}

// Bilinearly weighted 2x2 comparison at texel position `q` (one gather, or the hardware's
// filtered comparison).
fn gathered_compare(q: vec2<f32>, layer: i32, depth: f32) -> f32 {
    let inv = 1.0 / frame.shadow.x;
    if HW_COMPARE {
        return textureSampleCompareLevel(shadow_map, shadow_sampler, q * inv, layer, depth);
    }
    let t = q - vec2<f32>(0.5);
    let f = t - floor(t);
    // x = (i0, j1), y = (i1, j1), z = (i1, j0), w = (i0, j0).
    let g = textureGatherCompare(shadow_map, shadow_sampler, (floor(t) + vec2<f32>(1.0)) * inv, layer, depth);
    return mix(mix(g.w, g.z, f.x), mix(g.x, g.y, f.x), f.y);
}

fn soft_visibility(
    view: ShadowView,
    light: Light,
    layer: i32,
    p_texel: vec2<f32>,
    depth: f32,
    grad: vec2<f32>,
    tw_dir: f32,
    pixel: vec2<f32>,
) -> f32 {
    let directional = light.position.w == LIGHT_DIRECTIONAL;
    let size = i32(view.cascade.w);
    let d_r = light_distance(view, depth, directional);
    // Texel size across the view at the receiver: a perspective view's grows with the depth
    // along its axis (not the distance: off-axis the two part by the angle's cosine).
    let tw = select(view.cascade.z * d_r, tw_dir, directional);
    // The widest penumbra here: a blocker at the view's near plane.
    let search = clamp(penumbra_texels(light, d_r, light_distance(view, 1.0, directional), tw), 1.0, SOFT_MAX_TEXELS);
    let phi = 6.2831853 * fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
    let rot = vec2<f32>(cos(phi), sin(phi));
    // The filter's spiral is turned a further radian from the search's.
    let rot2 = vec2<f32>(rot.x * 0.540302 - rot.y * 0.841471, rot.x * 0.841471 + rot.y * 0.540302);
    var blockers = 0.0;
    var sum = 0.0;
    var dir = rot;
    for (var k = 0; k < SOFT_TAPS; k++) {
        let o = spiral(k, dir) * search;
        dir = golden_turn(dir);
        let c = clamp(vec2<i32>(floor(p_texel + o)), vec2<i32>(0), vec2<i32>(size - 1));
        let stored = textureLoad(shadow_map, c, layer, 0);
        let nearer = stored > depth + dot(grad, o);
        blockers += select(0.0, 1.0, nearer);
        sum += select(0.0, stored, nearer);
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let d_b = light_distance(view, sum / blockers, directional);
    let radius = clamp(penumbra_texels(light, d_r, d_b, tw), 0.5, SOFT_MAX_TEXELS);
    var vis = 0.0;
    dir = rot2;
    for (var k = 0; k < SOFT_TAPS; k++) {
        let o = spiral(k, dir) * radius;
        dir = golden_turn(dir);
        vis += gathered_compare(p_texel + o, layer, depth + dot(grad, o));
    }
    return vis / f32(SOFT_TAPS);
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + vec3<f32>(0.055)) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

// The material's base colour at `uv`, times the vertex colour `color`.
fn base_color(uv: vec4<f32>, color: vec4<f32>) -> vec4<f32> {
    var base = material.base_color * color;
    if HAS_BASE_TEX {
        base *= textureSample(base_color_tex, base_color_sampler, slot_uv(0u, uv));
    }
    return base;
}

// Three entry points, so that each pipeline carries only what it needs (llvmpipe runs every
// branch of a shader, taken or not):
// - fs_main, opaque materials, the lit image. No discard: a discard anywhere in a fragment shader
//   makes llvmpipe test depth after shading, so hidden fragments would be shaded too.
// - fs_masked, alpha-masked materials: discard below the cutoff, then shade.
// - fs_debug, the shadow-visibility and normals views, for every material.
@fragment
fn fs_main(in: VsOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    return vec4<f32>(highlight(display(shade(in, front_facing, base_color(in.uv, in.color)).color)), 1.0);
}

// Deferred shading of draws whose triangles are smaller than llvmpipe's 4x4 shading block (the
// renderer's `deferred::plan`, CPU devices only). llvmpipe shades every 4x4 block a triangle
// touches, so a helmet of 1.5-pixel triangles runs the material shader several times per pixel
// it keeps; these draws instead store what `shade` reads from their varyings (fs_gbuffer: no
// texture reads, no lighting), and fs_resolve shades each covered pixel once, per material,
// where the stencil holds that material's mark. Two RGBA32UI targets:
//   a: depth (f32 bits: the world position is rebuilt from it), TEXCOORD_0 (f32 bits),
//      d(uv)/dx (2 x f16)
//   b: normal and tangent (octahedral, 2 x snorm16 each), d(uv)/dy (2 x f16), flags: 1 tangent
//      sign >= 0, 2 front face, 4 tangent non-zero
// Deferred draws have no vertex colours and read TEXCOORD_0 only.
struct GBuffer {
    @location(0) a: vec4<u32>,
    @location(1) b: vec4<u32>,
}

// Octahedral encoding of direction `v` (any length > 0) in [-1, 1]^2.
fn oct_encode(v: vec3<f32>) -> vec2<f32> {
    let p = v.xy / max(abs(v.x) + abs(v.y) + abs(v.z), 1e-30);
    let folded = (vec2<f32>(1.0) - abs(p.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
    return select(p, folded, v.z < 0.0);
}

// The unit direction `oct_encode` encoded.
fn oct_decode(e: vec2<f32>) -> vec3<f32> {
    var v = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    let t = max(-v.z, 0.0);
    v.x += select(t, -t, v.x >= 0.0);
    v.y += select(t, -t, v.y >= 0.0);
    return normalize(v);
}

// Two derivatives as f16 (clamped to its range).
fn pack_grad(d: vec2<f32>) -> u32 {
    return pack2x16float(clamp(d, vec2<f32>(-65504.0), vec2<f32>(65504.0)));
}

@fragment
fn fs_gbuffer(in: VsOut, @builtin(front_facing) front_facing: bool) -> GBuffer {
    let dx = dpdx(in.uv.xy);
    let dy = dpdy(in.uv.xy);
    let flags = select(0u, 1u, in.tangent.w >= 0.0) | select(0u, 2u, front_facing)
        | select(0u, 4u, dot(in.tangent.xyz, in.tangent.xyz) > 0.0);
    var out: GBuffer;
    out.a = vec4<u32>(bitcast<u32>(in.clip.z), bitcast<u32>(in.uv.x), bitcast<u32>(in.uv.y), pack_grad(dx));
    out.b = vec4<u32>(
        pack2x16snorm(oct_encode(in.normal)),
        pack2x16snorm(oct_encode(in.tangent.xyz)),
        pack_grad(dy),
        flags,
    );
    return out;
}

@group(2) @binding(0) var gbuffer_a: texture_2d<u32>;
@group(2) @binding(1) var gbuffer_b: texture_2d<u32>;

// The derivative of slot i's coordinates for a change `d` of TEXCOORD_0 (the transform's linear
// part).
fn slot_grad(i: u32, d: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(dot(material.uv[2u * i].xy, d), dot(material.uv[2u * i + 1u].xy, d));
}

// Drawn on the full-screen triangle (its uv unused: the pixel is the fragment's position).
@fragment
fn fs_resolve(full: FullscreenOut) -> @location(0) vec4<f32> {
    let frag = full.clip;
    let c = vec2<i32>(frag.xy);
    let a = textureLoad(gbuffer_a, c, 0);
    let b = textureLoad(gbuffer_b, c, 0);
    let size = vec2<f32>(textureDimensions(gbuffer_a));
    // The pixel centre at the stored depth, back to world space (clip y is up, rows go down).
    let ndc = vec4<f32>(frag.x / size.x * 2.0 - 1.0, 1.0 - frag.y / size.y * 2.0, bitcast<f32>(a.x), 1.0);
    let world = frame.world_from_clip * ndc;
    let flags = b.w;
    var in: VsOut;
    in.clip = frag;
    in.world_position = world.xyz / world.w;
    in.normal = oct_decode(unpack2x16snorm(b.x));
    let uv = vec2<f32>(bitcast<f32>(a.y), bitcast<f32>(a.z));
    in.uv = vec4<f32>(uv, uv);
    let tangent = select(vec3<f32>(0.0), oct_decode(unpack2x16snorm(b.y)), (flags & 4u) != 0u);
    in.tangent = vec4<f32>(tangent, select(-1.0, 1.0, (flags & 1u) != 0u));
    in.color = vec4<f32>(1.0);
    let front_facing = (flags & 2u) != 0u;
    let dx = unpack2x16float(a.w);
    let dy = unpack2x16float(b.z);
    var base = material.base_color;
    if HAS_BASE_TEX {
        base *= textureSampleGrad(base_color_tex, base_color_sampler, slot_uv(0u, in.uv), slot_grad(0u, dx), slot_grad(0u, dy));
    }
    var t = Texels(vec3<f32>(0.5, 0.5, 1.0), vec4<f32>(1.0), vec3<f32>(1.0));
    if HAS_NORMAL_MAP {
        t.normal = textureSampleGrad(normal_tex, normal_sampler, slot_uv(1u, in.uv), slot_grad(1u, dx), slot_grad(1u, dy)).xyz;
    }
    if HAS_OTHER_TEX {
        t.mr = textureSampleGrad(metal_rough_tex, metal_rough_sampler, slot_uv(2u, in.uv), slot_grad(2u, dx), slot_grad(2u, dy));
        t.emissive = textureSampleGrad(emissive_tex, emissive_sampler, slot_uv(3u, in.uv), slot_grad(3u, dx), slot_grad(3u, dy)).rgb;
    }
    return vec4<f32>(display(shade_texels(in, front_facing, base, t).color), 1.0);
}

// Exposure and tone mapping, folded into the lit image's output (no HDR target: nothing else
// reads one). The same curves as src/math/tonemap.rs. The sRGB attachment encodes the result.
fn display(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c * frame.output.x, vec3<f32>(0.0), vec3<f32>(65504.0));
    let op = u32(frame.output.y);
    if op == 1u {
        return pbr_neutral(x);
    }
    if op == 2u {
        return aces_hill(x / 0.6);
    }
    return clamp(x, vec3<f32>(0.0), vec3<f32>(1.0));
}

// Khronos PBR Neutral.
fn pbr_neutral(c_in: vec3<f32>) -> vec3<f32> {
    let start = 0.76;
    let x = min(c_in.r, min(c_in.g, c_in.b));
    let offset = select(0.04, x - 6.25 * x * x, x < 0.08);
    let c = c_in - offset;
    let peak = max(c.r, max(c.g, c.b));
    if peak < start {
        return c;
    }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    let g = 1.0 - 1.0 / (0.15 * (peak - new_peak) + 1.0);
    return clamp(mix(c * (new_peak / peak), vec3<f32>(new_peak), g), vec3<f32>(0.0), vec3<f32>(1.0));
}

// ACES filmic, Stephen Hill's fit of the RRT + ODT.
fn aces_hill(c: vec3<f32>) -> vec3<f32> {
    let input = mat3x3<f32>(
        vec3<f32>(0.59719, 0.07600, 0.02840),
        vec3<f32>(0.35458, 0.90834, 0.13383),
        vec3<f32>(0.04823, 0.01566, 0.83777),
    );
    let output = mat3x3<f32>(
        vec3<f32>(1.60475, -0.10208, -0.00327),
        vec3<f32>(-0.53108, 1.10813, -0.07276),
        vec3<f32>(-0.07367, -0.00605, 1.07602),
    );
    let v = input * c;
    let a = v * (v + 0.0245786) - 0.000090537;
    let b = v * (0.983729 * v + 0.432951) + 0.238081;
    return clamp(output * (a / b), vec3<f32>(0.0), vec3<f32>(1.0));
}

// The picked primitive's tint (pc.normal_y.w = 1), none otherwise: one mix per fragment.
fn highlight(c: vec3<f32>) -> vec3<f32> {
    return mix(c, vec3<f32>(1.0, 0.35, 0.0), 0.5 * pc.normal_y.w);
}

// Blended materials: the lit colour with the base colour's alpha, blended over what lies behind
// (src-alpha, one-minus-src-alpha; no depth write). Tone-mapped before blending, as the layers
// behind it were (three.js does the same): exact where the curve is linear.
@fragment
fn fs_blend(in: VsOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let base = base_color(in.uv, in.color);
    return vec4<f32>(highlight(display(shade(in, front_facing, base).color)), clamp(base.a, 0.0, 1.0));
}

@fragment
fn fs_masked(in: VsOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let base = base_color(in.uv, in.color);
    if base.a < material.extra.x {
        discard;
    }
    return vec4<f32>(highlight(display(shade(in, front_facing, base).color)), 1.0);
}

// A colour ramp of rising brightness: dark blue, teal, yellow, white over t in [0, 1].
fn heat(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0) * 3.0;
    let c0 = vec3<f32>(0.05, 0.05, 0.4);
    let c1 = vec3<f32>(0.1, 0.6, 0.6);
    let c2 = vec3<f32>(0.9, 0.9, 0.2);
    let c3 = vec3<f32>(1.0, 1.0, 1.0);
    if x < 1.0 {
        return mix(c0, c1, x);
    }
    if x < 2.0 {
        return mix(c1, c2, x - 1.0);
    }
    return mix(c2, c3, x - 2.0);
}

@fragment
fn fs_debug(in: VsOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let base = base_color(in.uv, in.color);
    if material.extra.x > 0.0 && base.a < material.extra.x {
        discard;
    }
    let mode = frame.modes.x;
    // Shadow-map texels per screen pixel (derivatives first: uniform control flow), in the shown
    // light's cascade (or face).
    let shown = frame.lights[min(u32(frame.shadow_light.w), MAX_LIGHTS - 1u)];
    let first = max(i32(shown.shadow.x), 0);
    let n = i32(shown.shadow.y);
    var layer = first + cascade_of(in.world_position, first, n);
    if shown.position.w == LIGHT_POINT {
        layer = first + cube_face(in.world_position - shown.position.xyz);
    }
    let lc = frame.views[clamp(layer, 0, MAX_SHADOW_VIEWS - 1)].clip * vec4<f32>(in.world_position, 1.0);
    let res = frame.views[clamp(layer, 0, MAX_SHADOW_VIEWS - 1)].cascade.w;
    let st = vec2<f32>(lc.x, -lc.y) / max(abs(lc.w), 1e-20) * (0.5 * res);
    let jx = dpdx(st);
    let jy = dpdy(st);
    let texels_per_pixel = sqrt(abs(jx.x * jy.y - jx.y * jy.x));
    // Debug views write values that the sRGB target stores unchanged as bytes.
    if mode == VIEW_OVERDRAW {
        return vec4<f32>(vec3<f32>(OVERDRAW_STEP), 1.0);
    }
    if mode == VIEW_UV_CHECKER {
        let cell = floor(in.uv.xy * CHECKER_CELLS);
        let odd = (i32(cell.x) + i32(cell.y)) & 1;
        return vec4<f32>(srgb_to_linear(vec3<f32>(select(0.15, 0.85, odd == 1))), 1.0);
    }
    if mode == VIEW_BASE_COLOR {
        return vec4<f32>(base.rgb, 1.0);
    }
    if mode == VIEW_METALLIC || mode == VIEW_ROUGHNESS {
        var mr = vec4<f32>(1.0);
        if HAS_OTHER_TEX {
            mr = textureSample(metal_rough_tex, metal_rough_sampler, slot_uv(2u, in.uv));
        }
        let v = select(material.params.y * mr.g, material.params.x * mr.b, mode == VIEW_METALLIC);
        return vec4<f32>(srgb_to_linear(vec3<f32>(clamp(v, 0.0, 1.0))), 1.0);
    }
    if mode == VIEW_DEPTH {
        // Linear view depth (1 / w of the fragment), white at the eye, black at the scene's far end.
        let d = 1.0 / max(in.clip.w, 1e-30);
        return vec4<f32>(srgb_to_linear(vec3<f32>(1.0 - clamp(d / frame.shadow.z, 0.0, 1.0))), 1.0);
    }
    if mode == VIEW_TEXEL_DENSITY {
        if frame.shadow.w == 0.0 || n < 1 {
            return vec4<f32>(srgb_to_linear(vec3<f32>(0.5)), 1.0);
        }
        // Screen pixels per shadow texel, log2 over [1/16, 16]: dark blue where texels are finer
        // than pixels (wasted), teal-yellow near 1:1, white where one texel spans many pixels.
        let ppt = 1.0 / max(texels_per_pixel, 1e-20);
        return vec4<f32>(srgb_to_linear(heat(log2(ppt) / 8.0 + 0.5)), 1.0);
    }
    if mode == VIEW_TANGENTS || mode == VIEW_BITANGENTS {
        var n = normalize(in.normal);
        let t_raw = in.tangent.xyz - n * dot(n, in.tangent.xyz);
        var t = vec3<f32>(0.0);
        if dot(t_raw, t_raw) > 1e-12 {
            t = normalize(t_raw);
        }
        var v = t;
        if mode == VIEW_BITANGENTS {
            v = cross(n, t) * select(-1.0, 1.0, in.tangent.w >= 0.0);
        }
        return vec4<f32>(srgb_to_linear(v * 0.5 + vec3<f32>(0.5)), 1.0);
    }
    let s = shade(in, front_facing, base);
    if mode == VIEW_SHADOW {
        return vec4<f32>(srgb_to_linear(vec3<f32>(s.shadow_term)), 1.0);
    }
    if mode == VIEW_CASCADES {
        var tint = vec3<f32>(0.5);
        switch s.cascade {
            case 0: { tint = vec3<f32>(1.0, 0.25, 0.2); }
            case 1: { tint = vec3<f32>(0.25, 0.9, 0.25); }
            case 2: { tint = vec3<f32>(0.25, 0.4, 1.0); }
            case 3: { tint = vec3<f32>(1.0, 0.9, 0.2); }
            default: {}
        }
        return vec4<f32>(srgb_to_linear(tint * (0.35 + 0.65 * s.shadow_term)), 1.0);
    }
    return vec4<f32>(srgb_to_linear(s.normal * 0.5 + vec3<f32>(0.5)), 1.0);
}

struct Shaded {
    color: vec3<f32>,
    // The shading normal (after normal mapping, facing the viewer).
    normal: vec3<f32>,
    // The shown light's visibility (1 without one).
    shadow_term: f32,
    // The shown light's shadow view (cascade or cube face) read, relative to its first; -1 for
    // none.
    cascade: i32,
}

// What a fragment reads from the material's textures besides the base colour (white where a slot
// is empty): the normal map's texel, metallic-roughness (occlusion in r) and emissive.
struct Texels {
    normal: vec3<f32>,
    mr: vec4<f32>,
    emissive: vec3<f32>,
}

// Blinn-Phong with normal mapping and shadows for the fragment `in` of base colour `base`.
fn shade(in: VsOut, front_facing: bool, base: vec4<f32>) -> Shaded {
    var t = Texels(vec3<f32>(0.5, 0.5, 1.0), vec4<f32>(1.0), vec3<f32>(1.0));
    if HAS_NORMAL_MAP {
        t.normal = textureSample(normal_tex, normal_sampler, slot_uv(1u, in.uv)).xyz;
    }
    if HAS_OTHER_TEX {
        t.mr = textureSample(metal_rough_tex, metal_rough_sampler, slot_uv(2u, in.uv));
        t.emissive = textureSample(emissive_tex, emissive_sampler, slot_uv(3u, in.uv)).rgb;
    }
    return shade_texels(in, front_facing, base, t);
}

// `shade` once the textures are read (the deferred resolve reads them with explicit gradients).
fn shade_texels(in: VsOut, front_facing: bool, base: vec4<f32>, texels: Texels) -> Shaded {
    var n_geo = normalize(in.normal);
    var n = n_geo;
    if HAS_NORMAL_MAP {
        let normal_sample = texels.normal;
        let t_raw = in.tangent.xyz - n_geo * dot(n_geo, in.tangent.xyz);
        if dot(t_raw, t_raw) > 1e-12 {
            let t = normalize(t_raw);
            let b = cross(n_geo, t) * select(-1.0, 1.0, in.tangent.w >= 0.0);
            var tn = normal_sample * 2.0 - vec3<f32>(1.0);
            tn = vec3<f32>(tn.xy * material.emissive.w, tn.z);
            n = normalize(t * tn.x + b * tn.y + n_geo * tn.z);
        }
    }
    if !front_facing {
        n_geo = -n_geo;
        n = -n;
    }
    let mr = texels.mr;
    let metallic = clamp(material.params.x * mr.b, 0.0, 1.0);
    let roughness = clamp(material.params.y * mr.g, 0.03, 1.0);
    // glTF metallic-roughness -> Blinn-Phong (same mapping as src/scene/material.rs).
    let kd = base.rgb * (1.0 - metallic);
    let ks = mix(vec3<f32>(0.04), base.rgb, metallic);
    let alpha = roughness * roughness;
    let shininess = clamp(2.0 / (alpha * alpha) - 2.0, 1.0, 2048.0);
    let ka = base.rgb;
    var emissive = material.emissive.rgb;
    if HAS_OTHER_TEX {
        emissive *= texels.emissive;
    }

    let p = in.world_position;
    let v = normalize(frame.camera_position.xyz - p);
    // Occlusion (mr.r) scales the ambient term only: 1 + strength * (occlusion - 1).
    let occlusion = 1.0 + material.params.z * (mr.r - 1.0);
    var color = ka * frame.ambient.rgb * occlusion + emissive;
    var shadow_term = 1.0;
    var cascade = -1;
    // One light: a constant trip count the driver unrolls (a uniform count costs a real loop).
    let count = select(min(frame.modes.w, MAX_LIGHTS), 1u, SINGLE_LIGHT);
    for (var i = 0u; i < count; i++) {
        let light = frame.lights[i];
        var l: vec3<f32>;
        var radiance = light.color.rgb;
        if light.position.w == LIGHT_DIRECTIONAL {
            l = -light.direction.xyz;
        } else {
            let d = light.position.xyz - p;
            let r2 = max(dot(d, d), 1e-8);
            l = d * inverseSqrt(r2);
            // Inverse square, windowed to zero at the range (KHR_lights_punctual):
            // clamp(1 - (d / range)^4, 0, 1); cone.z = 0 means no range.
            let range2 = light.cone.z * light.cone.z;
            let q = r2 / max(range2, 1e-30);
            let window = select(1.0, clamp(1.0 - q * q, 0.0, 1.0), light.cone.z > 0.0);
            radiance = radiance * (window / r2);
            if light.position.w == LIGHT_SPOT {
                let cd = dot(-l, light.direction.xyz);
                // KHR_lights_punctual's cone: t^2, t linear between the outer and inner cosines.
                let t = clamp((cd - light.cone.y) / max(light.cone.x - light.cone.y, 0.001), 0.0, 1.0);
                radiance *= t * t;
            }
        }
        var vis = select(0.0, 1.0, dot(n_geo, l) > 0.0);
        let shown = u32(frame.shadow_light.w) == i;
        if SHADOWS && frame.shadow.w > 0.5 {
            if MANY_VIEWS {
                // Each light its own views.
                let first = i32(light.shadow.x);
                if first >= 0 {
                    let view = light_view(light, p, in.clip.xy, first, i32(light.shadow.y));
                    vis *= shadow_visibility(p, n_geo, l, light, view, in.clip.xy);
                    if shown {
                        cascade = view - first;
                    }
                }
            } else if shown {
                // The one shadowed light, view 0.
                vis *= shadow_visibility(p, n_geo, l, light, 0, in.clip.xy);
                cascade = 0;
            }
        }
        if shown {
            shadow_term = vis;
        }
        let h = normalize(l + v);
        let ndl = max(dot(n, l), 0.0);
        let ndh = max(dot(n, h), 0.0);
        color += vis * radiance * (kd * ndl + ks * pow(ndh, shininess));
    }
    if material.params.w > 0.5 {
        color = base.rgb;
    }
    return Shaded(color, n, shadow_term, cascade);
}

// Full-screen triangle for the shadow-map debug view.
struct FullscreenOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOut {
    var out: FullscreenOut;
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    // uv (0,0) is the top-left of the image (clip y = +1 is the top).
    out.clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}

// The shadow map itself: grey = stored depth (reversed-z: white is nearest the light), row 0 on top.
@fragment
fn fs_shadow_map(in: FullscreenOut) -> @location(0) vec4<f32> {
    let size = i32(frame.shadow.x);
    let c = clamp(vec2<i32>(in.uv * f32(size)), vec2<i32>(0), vec2<i32>(size - 1));
    let d = textureLoad(shadow_map, c, 0, 0);
    return vec4<f32>(srgb_to_linear(vec3<f32>(d)), 1.0);
}
