// Camera pass: Blinn-Phong with tangent-space normal mapping and shadow-map visibility.
//
// L = ka*Ia + sum_i vis_i * [ kd*(I/r^2)*max(0,n.l) + ks*(I/r^2)*max(0,n.h)^p ]
// where vis_i is (geometric n.l > 0) times, for a light with shadow views, the filtered shadow-map
// comparison in its view. `--view shadow` writes exactly one light's vis_i (the shown light).
//
// Reversed-z everywhere: the shadow map stores the largest depth (closest to the light); a receiver
// is lit where its light-space depth >= the stored depth (compare op GREATER_OR_EQUAL).
// Y convention: clip space is Y-up, naga flips Y for Vulkan (build.rs); shadow UV v = 0.5 - 0.5*y.

#include "lib/frame.wgsl"
#include "lib/material.wgsl"

// Specialisation (build.rs writes one SPIR-V per combination; the renderer picks per draw):
// which texture slots the material fills (an empty slot's default texture is white, a factor of 1,
// so leaving its fetch out gives the same value), whether the frame has exactly one light, and
// whether the frame samples a shadow map.
// The PCF kernel and the comparison path are per frame too: PCF_BIT0 + 2 * PCF_BIT1 selects 0, 1,
// 3 or 5 bilinear taps per side (none, 2x2, 3x3, 5x5); HW_COMPARE uses hardware filtering.
override HAS_BASE_TEX: bool = true;
override HAS_NORMAL_MAP: bool = true;
override HAS_OTHER_TEX: bool = true; // metallic-roughness, emissive or occlusion
override ONE_SUN: bool = false; // the frame's only light is directional
override SHADOWS: bool = true;
override HW_COMPARE: bool = false; // requires SHADOWS
override PCF_BIT0: bool = true; // requires SHADOWS
override PCF_BIT1: bool = false; // requires SHADOWS
// More than one shadow view (cascades, several shadowed lights, a point light's cube faces): each
// light reads its own views, chosen per pixel; without, the one shadowed light reads view 0.
override MANY_VIEWS: bool = true; // requires SHADOWS
// A shadowed light has a size (light.direction.w > 0): its lookups are PCSS soft shadows.
override SOFT: bool = true; // requires SHADOWS
// A per-pixel verdict on the shadowed light (shaders/exact.wgsl: exact shadows, or contact
// shadows) where this fragment is the receiver it was made for; the maps elsewhere (blended
// layers over it, MSAA edge samples) and where the verdict is -1.
override EXACT: bool = false; // requires SHADOWS; excludes SOFT

// Bilinear taps per side of the PCF kernel (0 = one nearest comparison).
fn pcf_taps() -> i32 {
    if PCF_BIT1 {
        return select(3, 5, PCF_BIT0);
    }
    return select(0, 1, PCF_BIT0);
}

struct Immediates {
    world_from_model: mat4x4<f32>,
    // columns of the normal matrix (inverse transpose of the upper 3x3); normal_x.w = sign of det,
    // normal_y.w = 1 to tint the draw orange (the viewer's picked primitive), normal_z.w = the
    // draw's instance + 1 in the AOV pass
    normal_x: vec4<f32>,
    normal_y: vec4<f32>,
    normal_z: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame_block: Frame;
@group(0) @binding(1) var shadow_map: texture_depth_2d_array;
@group(0) @binding(2) var shadow_sampler: sampler_comparison;
// Written by the exact pass (shaders/exact.wgsl `samples`): element 0 is (width, height, 0, 0),
// element 1 + pixel the receiver's world position and verdict (1 lit, 0 blocked, -1 none).
@group(0) @binding(3) var<storage, read> exact_samples: array<vec4<f32>>;

@group(1) @binding(0) var<uniform> material_block: Material;
@group(1) @binding(1) var base_color_tex: texture_2d<f32>;
@group(1) @binding(2) var normal_tex: texture_2d<f32>;
@group(1) @binding(3) var metal_rough_tex: texture_2d<f32>;
@group(1) @binding(4) var emissive_tex: texture_2d<f32>;
// One sampler per texture slot: the glTF texture's own filters and wrap modes.
@group(1) @binding(5) var base_color_sampler: sampler;
@group(1) @binding(6) var normal_sampler: sampler;
@group(1) @binding(7) var metal_rough_sampler: sampler;
@group(1) @binding(8) var emissive_sampler: sampler;

var<immediate> pc_block: Immediates;

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
    load_frame();
    load_immediates();
    return transform(v);
}

// The vertex `v` in world and clip space (after `load_frame` and `load_immediates`).
fn transform(v: VsIn) -> VsOut {
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

#include "lib/uniforms.wgsl"

@vertex
fn vs_main_flat(v: VsIn) -> FlatOut {
    load_uniforms();
    var out = with_material(flat_out(transform(v)));
    out.normal_y = pc.normal_y;
    return out;
}

// The full-screen triangle (uv (0,0) at the top-left of the image, in FlatOut.uv.xy) with the
// uniforms as flat inputs.
@vertex
fn vs_fullscreen_flat(@builtin(vertex_index) index: u32) -> FlatOut {
    load_frame();
    load_material();
    return with_material(fullscreen_flat(index));
}

// vs_fullscreen_flat without a material (`fs_sky_flat`'s).
@vertex
fn vs_sky(@builtin(vertex_index) index: u32) -> FlatOut {
    load_frame();
    return fullscreen_flat(index);
}

fn fullscreen_flat(index: u32) -> FlatOut {
    let full = fullscreen(index);
    var v: VsOut;
    v.clip = full.clip;
    v.world_position = vec3<f32>(0.0);
    v.normal = vec3<f32>(0.0);
    v.uv = vec4<f32>(full.uv, full.uv);
    v.tangent = vec4<f32>(0.0);
    v.color = vec4<f32>(0.0);
    return flat_out(v);
}

#include "lib/shadow_lookup.wgsl"
#include "lib/shading.wgsl"
#include "lib/tonemap.wgsl"
#include "lib/gbuffer.wgsl"


// Three entry points, so that each pipeline carries only what it needs (llvmpipe runs every
// branch of a shader, taken or not):
// - fs_main, opaque materials, the lit image. No discard: a discard anywhere in a fragment shader
//   makes llvmpipe test depth after shading, so hidden fragments would be shaded too.
// - fs_masked, alpha-masked materials: discard below the cutoff, then shade.
// - fs_debug, the shadow-visibility and normals views, for every material.
@fragment
fn fs_main(in: VsOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    load_uniforms();
    return lit_opaque(in, front_facing);
}

// fs_main with the uniforms as flat inputs (draws of large triangles on CPU devices).
@fragment
fn fs_main_flat(in: FlatOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    load_flat_material(in);
    return lit_opaque(load_flat(in), front_facing);
}

fn lit_opaque(in: VsOut, front_facing: bool) -> vec4<f32> {
    return vec4<f32>(highlight(display_surface(shade(in, front_facing, base_color(in.uv, in.color)).color)), 1.0);
}

@fragment
fn fs_gbuffer(in: VsOut, @builtin(front_facing) front_facing: bool) -> GBuffer {
    return gbuffer_of(in, front_facing);
}

fn gbuffer_of(in: VsOut, front_facing: bool) -> GBuffer {
    var out: GBuffer;
    out.a = vec4<u32>(bitcast<u32>(in.clip.z), pack2x16snorm(oct_encode(in.normal)), select(0u, 2u, front_facing), 0u);
    // What only texture reads and normal mapping use (fs_resolve reads it under the same
    // conditions): an untextured material's pipeline leaves it out, interpolates no uv or
    // tangent, and masks target b.
    if textured() {
        let dx = dpdx(in.uv.xy);
        let dy = dpdy(in.uv.xy);
        out.a.w = bitcast<u32>(in.uv.x);
        out.b = vec4<u32>(bitcast<u32>(in.uv.y), pack_grad(dx), pack_grad(dy), 0u);
    }
    if HAS_NORMAL_MAP {
        out.b.w = pack2x16snorm(oct_encode(in.tangent.xyz));
        out.a.z |= select(0u, 1u, in.tangent.w >= 0.0) | select(0u, 4u, dot(in.tangent.xyz, in.tangent.xyz) > 0.0);
    }
    return out;
}

@group(2) @binding(0) var gbuffer_a: texture_2d<u32>;
@group(2) @binding(1) var gbuffer_b: texture_2d<u32>;

// Drawn on the full-screen triangle (`vs_fullscreen_flat`; the pixel is the fragment's position).
@fragment
fn fs_resolve(inputs: FlatOut) -> @location(0) vec4<f32> {
    load_flat_material(inputs);
    let frag = load_flat(inputs).clip;
    let c = vec2<i32>(frag.xy);
    let a = textureLoad(gbuffer_a, c, 0);
    var b = vec4<u32>(0u);
    if textured() {
        b = textureLoad(gbuffer_b, c, 0);
    }
    let size = vec2<f32>(textureDimensions(gbuffer_a));
    // The pixel centre at the stored depth, back to world space (clip y is up, rows go down).
    let ndc = vec4<f32>(frag.x / size.x * 2.0 - 1.0, 1.0 - frag.y / size.y * 2.0, bitcast<f32>(a.x), 1.0);
    let world = frame.world_from_clip * ndc;
    let flags = a.z;
    var in: VsOut;
    in.clip = frag;
    in.world_position = world.xyz / world.w;
    in.normal = oct_decode(unpack2x16snorm(a.y));
    let uv = vec2<f32>(bitcast<f32>(a.w), bitcast<f32>(b.x));
    in.uv = vec4<f32>(uv, uv);
    let tangent = select(vec3<f32>(0.0), oct_decode(unpack2x16snorm(b.w)), (flags & 4u) != 0u);
    in.tangent = vec4<f32>(tangent, select(-1.0, 1.0, (flags & 1u) != 0u));
    in.color = vec4<f32>(1.0);
    let front_facing = (flags & 2u) != 0u;
    let dx = unpack2x16float(b.y);
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
    return vec4<f32>(display_surface(shade_texels(in, front_facing, base, t).color), 1.0);
}

// Blended materials: the lit colour with the base colour's alpha, blended over what lies behind
// (src-alpha, one-minus-src-alpha; no depth write). Tone-mapped before blending, as the layers
// behind it were (three.js does the same): exact where the curve is linear.
@fragment
fn fs_blend(in: VsOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    load_uniforms();
    let base = base_color(in.uv, in.color);
    return vec4<f32>(highlight(display_surface(shade(in, front_facing, base).color)), clamp(base.a, 0.0, 1.0));
}

@fragment
fn fs_masked(in: VsOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    load_uniforms();
    let base = base_color(in.uv, in.color);
    if base.a < material.extra.x {
        discard;
    }
    return vec4<f32>(highlight(display_surface(shade(in, front_facing, base).color)), 1.0);
}

// Per-pixel outputs for image tests and datasets (the Python package's `segmentation` and
// `normals`): the draw's instance + 1 (pc.normal_z.w holds it as a float, exact below 2^24) and
// the interpolated world normal, turned to face the viewer as shading turns it. Two entry points,
// as for the lit image: fs_aov for opaque materials reads no texture and never discards (so
// llvmpipe tests depth first and hidden fragments cost nothing), fs_aov_masked discards below the
// cutoff as fs_masked does. Blended materials are not drawn.
struct Aov {
    @location(0) id: u32,
    @location(1) normal: vec4<f32>,
}

fn aov_of(in: VsOut, front_facing: bool) -> Aov {
    let n = normalize(in.normal);
    var out: Aov;
    out.id = u32(pc_block.normal_z.w + 0.5);
    out.normal = vec4<f32>(select(-n, n, front_facing), 1.0);
    return out;
}

@fragment
fn fs_aov(in: VsOut, @builtin(front_facing) front_facing: bool) -> Aov {
    return aov_of(in, front_facing);
}

@fragment
fn fs_aov_masked(in: VsOut, @builtin(front_facing) front_facing: bool) -> Aov {
    load_uniforms();
    if base_color(in.uv, in.color).a < material.extra.x {
        discard;
    }
    return aov_of(in, front_facing);
}

// The lit entry points that also write the per-pixel outputs, for a camera pass that draws them
// as extra targets (one sample per pixel): the colour as fs_main, fs_main_flat and fs_masked
// write it, the id and normal as fs_aov writes them. fs_gbuffer_aov writes the G-buffer and
// both; its targets come first so that the G-buffer's unused target stays the last one.
struct LitAov {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
    @location(2) normal: vec4<f32>,
}

fn lit_aov(color: vec4<f32>, aov: Aov) -> LitAov {
    return LitAov(color, aov.id, aov.normal);
}

@fragment
fn fs_main_aov(in: VsOut, @builtin(front_facing) front_facing: bool) -> LitAov {
    load_uniforms();
    return lit_aov(lit_opaque(in, front_facing), aov_of(in, front_facing));
}

@fragment
fn fs_main_flat_aov(in: FlatOut, @builtin(front_facing) front_facing: bool) -> LitAov {
    load_flat_material(in);
    let v = load_flat(in);
    return lit_aov(lit_opaque(v, front_facing), aov_of(v, front_facing));
}

@fragment
fn fs_masked_aov(in: VsOut, @builtin(front_facing) front_facing: bool) -> LitAov {
    load_uniforms();
    let base = base_color(in.uv, in.color);
    if base.a < material.extra.x {
        discard;
    }
    let color = vec4<f32>(highlight(display_surface(shade(in, front_facing, base).color)), 1.0);
    return lit_aov(color, aov_of(in, front_facing));
}

struct GBufferAov {
    @location(0) id: u32,
    @location(1) normal: vec4<f32>,
    @location(2) a: vec4<u32>,
    @location(3) b: vec4<u32>,
}

@fragment
fn fs_gbuffer_aov(in: VsOut, @builtin(front_facing) front_facing: bool) -> GBufferAov {
    let g = gbuffer_of(in, front_facing);
    let aov = aov_of(in, front_facing);
    return GBufferAov(aov.id, aov.normal, g.a, g.b);
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
    load_uniforms();
    let base = base_color(in.uv, in.color);
    // The surfaces that cast and receive (the shadow pass's cutoff: a masked material's own, 0.5
    // on a blended one, none on an opaque one): what lies behind a blended texel below the cutoff
    // is judged, as the reference's receivers are.
    if base.a < material.extra.y {
        discard;
    }
    let mode = frame.modes.x;
    // Shadow-map texels per screen pixel (derivatives first: uniform control flow), in the shown
    // light's cascade (or face).
    let shown = frame_block.lights[min(u32(frame.shadow_light.w), MAX_LIGHTS - 1u)];
    let first = max(i32(shown.shadow.x), 0);
    let n = i32(shown.shadow.y);
    var layer = first + cascade_of(in.world_position, first, n);
    if shown.position.w == LIGHT_POINT {
        layer = first + cube_face(in.world_position - shown.position.xyz);
    }
    let lc = frame_block.views[clamp(layer, 0, MAX_SHADOW_VIEWS - 1)].clip * vec4<f32>(in.world_position, 1.0);
    let res = frame_block.views[clamp(layer, 0, MAX_SHADOW_VIEWS - 1)].cascade.w;
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
        // Linear view depth (1 / w of the fragment; under an orthographic camera, where w is 1,
        // the distance along the view), white at the eye, black at the scene's far end.
        let along = dot(in.world_position - frame.camera_position.xyz, frame.eye_forward.xyz);
        let d = select(1.0 / max(in.clip.w, 1e-30), along, frame.eye_forward.w > 0.5);
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

// Full-screen triangle for the shadow-map debug view.
struct FullscreenOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOut {
    return fullscreen(index);
}

fn fullscreen(index: u32) -> FullscreenOut {
    var out: FullscreenOut;
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    // uv (0,0) is the top-left of the image (clip y = +1 is the top).
    out.clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}

// The background where no surface was drawn (depth still 0): the ambient hemisphere seen along
// the pixel's view direction, exposed and tone-mapped (the reference's background too).
@fragment
fn fs_sky(full: FullscreenOut) -> @location(0) vec4<f32> {
    load_frame();
    return sky(full.uv);
}

// fs_sky with the uniforms as flat inputs (`vs_sky`; CPU devices).
@fragment
fn fs_sky_flat(inputs: FlatOut) -> @location(0) vec4<f32> {
    return sky(load_flat(inputs).uv.xy);
}

// The sky at `uv` ((0, 0) the image's top-left corner).
fn sky(uv: vec2<f32>) -> vec4<f32> {
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let near = frame.world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    let mid = frame.world_from_clip * vec4<f32>(ndc, 0.5, 1.0);
    let dir = normalize(mid.xyz / mid.w - near.xyz / near.w);
    return vec4<f32>(display(ambient_at(dir)), 1.0);
}

// The shadow map itself: grey = stored depth (reversed-z: white is nearest the light), row 0 on top.
@fragment
fn fs_shadow_map(in: FullscreenOut) -> @location(0) vec4<f32> {
    load_frame();
    let size = i32(frame.shadow.x);
    let c = clamp(vec2<i32>(in.uv * f32(size)), vec2<i32>(0), vec2<i32>(size - 1));
    let d = textureLoad(shadow_map, c, 0, 0);
    return vec4<f32>(srgb_to_linear(vec3<f32>(d)), 1.0);
}
