// Exact hard shadows by an irregular z-buffer (Johnson et al. 2005; Wyman, Hoetzlein and Lefohn,
// "Frustum-traced raster shadows", 2015), for the frame's shadowed light (src/render/passes/exact.rs).
//
// 1. vs_receiver / fs_receiver: the camera's receivers (what casts and is judged: the shadow
//    pass's alpha cutoff) into two images, world position and face normal, one texel per pixel.
// 2. cs_build: each covered pixel is one sample: its shadow ray's origin (off the surface on the
//    light's side by its ray offset, as the CPU reference starts its rays) is projected
//    into the light's view and pushed onto that grid cell's list (a head per cell, a next per
//    sample).
// 3. vs_caster / fs_caster: every caster triangle, pulled from the scene's buffers, is drawn into
//    the grid as its light-view box grown by half a cell (so every cell it touches runs a
//    fragment; a dilated triangle's corners run away for slivers); each fragment walks its cell's
//    samples and intersects each one's shadow ray with the exact triangle (Moller-Trumbore; the
//    alpha texture at the hit for masked and blended casters), marking the samples it blocks. No
//    bias, no texels in the answer: the grid only sorts the work.
// Hybrid shadows (lib/hybrid.wgsl) keep the map's verdict in step 2 where it is certain, and
// draw in step 3 only the caster triangles near the samples left.
// The camera pass reads the result at its pixel where its fragment is the receiver (scene.wgsl).
// Contact shadows reuse step 1 and replace 2 and 3 by `cs_contact`.

#include "lib/material.wgsl"
#include "lib/hybrid.wgsl"

struct ExactFrame {
    // The grid: the shadowed light's view (clip space), or a point light's six cube faces, each
    // its own grid of g² cells (`counts.x` views).
    views: array<mat4x4<f32>, 6>,
    // xyz: the direction a directional light's rays travel, or a spot light's position;
    // w: LIGHT_DIRECTIONAL or LIGHT_SPOT.
    light: vec4<f32>,
    // x: contact shadows' margin (world units: rays start that far off their surface, and a step
    // counts that far behind one), y: grid side in cells, z: image width, w: image height.
    params: vec4<f32>,
    // The camera's clip from world, and its position (contact shadows).
    camera_clip: mat4x4<f32>,
    eye: vec4<f32>,
    // Contact shadows: x = how far a ray marches towards the light (world units; per unit of
    // distance to a spot or point light, whose texels grow with it), z = the thickness a surface
    // in the depth image is taken to have.
    contact: vec4<f32>,
    // x: the views (1, or 6 for a point light's cube).
    counts: vec4<f32>,
    // Hybrid shadows (x = 1; 0 for exact): y = the map's side in texels, z = a texel's world
    // size (per unit of distance for a spot light).
    hybrid: vec4<f32>,
    // The map's casters' lookup rectangle (texels x0, y0, x1, y1): nothing outside it casts.
    rect: vec4<f32>,
    // World from the map's clip space.
    world_from_map: mat4x4<f32>,
}

const LIGHT_DIRECTIONAL: f32 = 0.0;
// Any light with a position (spot, or point for contact shadows).
const LIGHT_SPOT: f32 = 2.0;
// Words per vertex of the scene's attribute stream (src/render/gpu_scene.rs VertexAttributes:
// normal 3, uv 2, tangent 4, colour 2 (four u16), uv1 2).
const ATTRIBUTE_WORDS: u32 = 13u;
// A sample whose shadow ray a caster blocks (`samples[i].w`); 1 is lit, -1 no surface.
const OCCLUDED: f32 = 0.0;
// Hybrid shadows: a traced sample's verdict, 2 + (1 lit, 0 blocked); 1 and 0 are the map's
// (the camera pass takes the verdict modulo 2, and its cascade view shows which).
const TRACED_LIT: f32 = 3.0;
const TRACED_OCCLUDED: f32 = 2.0;
// The certainty test's allowance for its own arithmetic, relative to the largest terms (2⁻²⁰:
// 8 steps of f32's 2⁻²³).
const ARITHMETIC_ERROR: f32 = 9.5367432e-7;
// A caster triangle whose smallest height in map texels is below this may fall between the
// texel centres of a 3×3 footprint: a triangle at least this high holds a disk one texel across
// (its inradius is at least a third of its smallest height), which holds a texel centre.
const THIN_TEXELS: f32 = 3.0;
// Cells per side of a tile of the hybrid method's culling grid (per tile: the farthest along the
// light of its traced samples' ray origins, `ordered`, 0 for none).
const TILE_CELLS: u32 = 4u;

@group(0) @binding(0) var<uniform> xf: ExactFrame;
// Cells 0..n (n = views × g²): each cell's list head (sample + 1, 0 for none); n..2n: the
// farthest of its samples' shadow ray origins from a directional light (`ordered` light depth, 0
// for none).
@group(0) @binding(1) var<storage, read_write> heads: array<atomic<u32>>;
@group(0) @binding(2) var<storage, read_write> next: array<u32>;
// Element 0: (width, height, 0, 0); element 1 + i: pixel i's (world position, verdict).
@group(0) @binding(3) var<storage, read_write> samples: array<vec4<f32>>;
// Per sample: (shadow ray origin, farthest hit distance).
@group(0) @binding(4) var<storage, read_write> rays: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> positions: array<f32>;
@group(0) @binding(6) var<storage, read> indices: array<u32>;
@group(0) @binding(7) var<storage, read> attributes: array<u32>;
@group(0) @binding(8) var receiver_position: texture_2d<f32>;
@group(0) @binding(9) var receiver_normal: texture_2d<f32>;
// Hybrid shadows: the map (layer 0), and per tile of `TILE_CELLS`² cells the farthest ray origin
// of its traced samples (written by cs_build, read by cs_cull through `tiles_read`).
@group(0) @binding(10) var shadow_map: texture_depth_2d_array;
@group(0) @binding(11) var<storage, read_write> tiles: array<atomic<u32>>;
@group(0) @binding(12) var<storage, read> tiles_read: array<u32>;
// Hybrid shadows: the caster triangles cs_cull keeps (each draw's from `pc.extra[1].x`), and each
// draw's indirect arguments (vertex count, instance count, first vertex, first instance) at
// `pc.extra[1].y`; vs_caster reads the kept triangles through `kept_read`.
@group(0) @binding(13) var<storage, read_write> kept: array<u32>;
@group(0) @binding(14) var<storage, read_write> draw_args: array<atomic<u32>>;
@group(0) @binding(15) var<storage, read> kept_read: array<u32>;
// Hybrid shadows: a bit per map texel, set where a caster triangle thinner than `THIN_TEXELS`
// (or alpha-tested: its holes and edges are the texture's) comes within half a texel (cs_thin):
// there a texel centre can miss it, and the map proves nothing.
@group(0) @binding(16) var<storage, read_write> thin: array<atomic<u32>>;

@group(1) @binding(0) var<uniform> material: Material;
@group(1) @binding(1) var base_color_tex: texture_2d<f32>;
@group(1) @binding(5) var base_color_sampler: sampler;

// 128 bytes: the model transform, and what the pass needs of its draw.
struct ExactImmediates {
    world_from_model: mat4x4<f32>,
    // Receiver pass: x = the ray offset's factors (`math::ray::ray_offset`): xyz the draw's
    // coordinate magnitudes times the relative offset, w the relative offset. Caster
    // pass: x = first index, y = vertex offset (bit-cast i32), z = 1 when the caster's alpha is
    // tested, w = the view (cube face); hybrid culling, y (bit-cast u32): x = the draw's first
    // kept triangle, y = its indirect arguments' index, z = its triangles.
    extra: mat4x4<f32>,
}

var<immediate> pc: ExactImmediates;

// ---- 1. Receivers ----

struct ReceiverIn {
    @location(0) position: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(4) color: vec4<f32>,
    @location(5) uv1: vec2<f32>,
}

struct ReceiverOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) uv: vec4<f32>,
    @location(2) alpha: f32,
}

// The camera pass's vs_main transform, operation for operation, so the positions agree.
@vertex
fn vs_receiver(v: ReceiverIn) -> ReceiverOut {
    var out: ReceiverOut;
    let world = pc.world_from_model * vec4<f32>(v.position, 1.0);
    out.world_position = world.xyz;
    out.clip = xf.camera_clip * world;
    out.uv = vec4<f32>(v.uv, v.uv1);
    out.alpha = v.color.a;
    return out;
}

struct ReceiverTargets {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
}

@fragment
fn fs_receiver(in: ReceiverOut) -> ReceiverTargets {
    // The face's normal: the gradient of the interpolated position across the triangle.
    let ng = normalize(cross(dpdx(in.world_position), dpdy(in.world_position)));
    // The camera pass's base colour alpha (mipmapped), against the shadow cutoff (fs_debug).
    let alpha = in.alpha * material.base_color.a * textureSample(base_color_tex, base_color_sampler, slot_uv(0u, in.uv)).a;
    if alpha < material.extra.y {
        discard;
    }
    var out: ReceiverTargets;
    out.position = vec4<f32>(in.world_position, 1.0);
    // w: how far this surface's shadow rays start off it (`math::ray::ray_offset`).
    let p = abs(in.world_position);
    let offset = dot(abs(ng), pc.extra[0].xyz) + max(p.x, max(p.y, p.z)) * pc.extra[0].w;
    out.normal = vec4<f32>(ng, offset);
    return out;
}

// ---- 2. Binning ----

// A light depth as an unsigned integer of the same order (atomicMax on floats).
fn ordered(f: f32) -> u32 {
    let b = bitcast<u32>(f);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

// All the grids' cells.
fn cell_count() -> u32 {
    let g = u32(xf.params.y);
    return u32(xf.counts.x) * g * g;
}

// The cube face a point light's ray towards `d` (from the light) leaves by: +x, -x, +y, -y, +z,
// -z (the shadow maps' order, shaders/lib/shadow_lookup.wgsl).
fn cube_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}

// The grid cell of world point `p`, or `cell_count()` (none) outside the light's views.
fn cell_of(p: vec3<f32>) -> u32 {
    let g = u32(xf.params.y);
    var view = 0u;
    if xf.counts.x > 1.5 {
        view = cube_face(p - xf.light.xyz);
    }
    let c = xf.views[view] * vec4<f32>(p, 1.0);
    if c.w <= 0.0 {
        return cell_count();
    }
    let ndc = c.xy / c.w;
    if abs(ndc.x) > 1.0 || abs(ndc.y) > 1.0 {
        return cell_count();
    }
    // Framebuffer rows run down (naga flips clip y on the way out of a vertex shader).
    let t = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * f32(g);
    let cell = min(vec2<u32>(t), vec2<u32>(g - 1u));
    return view * g * g + cell.y * g + cell.x;
}

// The receiver at a compute invocation: its pixel's index and world position (`position.w` >
// 0: a surface).
struct Receiver {
    index: u32,
    position: vec4<f32>,
}

// The receiver of invocation `id`; writes the sample list's header, and "no verdict" for a pixel
// without a surface. None (`position.w` = 0) outside the image.
fn receiver_at(id: vec3<u32>) -> Receiver {
    let w = u32(xf.params.z);
    let h = u32(xf.params.w);
    if id.x >= w || id.y >= h {
        return Receiver(0u, vec4<f32>(0.0));
    }
    let i = id.y * w + id.x;
    if i == 0u {
        samples[0] = vec4<f32>(f32(w), f32(h), 0.0, 0.0);
    }
    let position = textureLoad(receiver_position, vec2<i32>(id.xy), 0);
    if position.w <= 0.0 {
        samples[i + 1u] = vec4<f32>(position.xyz, -1.0);
    }
    return Receiver(i, position);
}

// The unit direction from `p` towards the light, and how far the light is (3e38 for a
// directional light).
fn towards_light(p: vec3<f32>) -> vec4<f32> {
    if xf.light.w == LIGHT_SPOT {
        let d = xf.light.xyz - p;
        let dist = length(d);
        return vec4<f32>(d / max(dist, 1e-20), dist);
    }
    return vec4<f32>(-xf.light.xyz, 3.0e38);
}

// Where the shadow ray of the receiver at invocation `id`, point `p`, towards `dir` starts: off
// the surface by `offset`, on the light's side of the face.
fn ray_origin(id: vec3<u32>, p: vec3<f32>, dir: vec3<f32>, offset: f32) -> vec3<f32> {
    let ng = textureLoad(receiver_normal, vec2<i32>(id.xy), 0).xyz;
    return p + select(-ng, ng, dot(ng, dir) >= 0.0) * offset;
}

@compute @workgroup_size(8, 8)
fn cs_build(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = receiver_at(id);
    if r.position.w <= 0.0 {
        return;
    }
    let i = r.index;
    let p = r.position.xyz;
    let to_light = towards_light(p);
    let dir = to_light.xyz;
    let reach = to_light.w;
    // Off the surface by its ray offset (the receiver pass's normal.w), as the reference's.
    let offset = textureLoad(receiver_normal, vec2<i32>(id.xy), 0).w;
    let origin = ray_origin(id, p, dir, offset);
    var unjudged = 1.0;
    if xf.hybrid.x > 0.5 {
        let ng = textureLoad(receiver_normal, vec2<i32>(id.xy), 0).xyz;
        let certain = map_verdict(p, select(-ng, ng, dot(ng, dir) >= 0.0), origin, offset, reach);
        if certain >= 0.0 {
            samples[i + 1u] = vec4<f32>(p, certain);
            return;
        }
        unjudged = TRACED_LIT;
    }
    samples[i + 1u] = vec4<f32>(p, unjudged);
    rays[i] = vec4<f32>(origin, reach - offset);
    let cell = cell_of(origin);
    let n = cell_count();
    if cell < n {
        next[i] = atomicExchange(&heads[cell], i + 1u);
        if xf.light.w == LIGHT_DIRECTIONAL {
            atomicMax(&heads[n + cell], ordered(dot(origin, xf.light.xyz)));
        }
        if xf.hybrid.x > 0.5 {
            let g = u32(xf.params.y);
            let t = vec2<u32>(cell % g, cell / g) / TILE_CELLS;
            atomicMax(&tiles[t.y * (g / TILE_CELLS) + t.x], ordered(light_depth(origin)));
        }
    }
}

// ---- Contact shadows (instead of 2 and 3) ----

// Steps of a contact ray.
const CONTACT_STEPS: u32 = 8u;

// Each covered pixel's shadow ray marched a short way towards the light through the receiver
// image as a depth buffer: a step behind what the camera sees there, by less than the thickness,
// is blocked (verdict 0); else -1, the maps decide. It sees only what the camera sees: a caster
// hidden behind another surface casts nothing, and a surface in front of the ray by less than the
// thickness casts where nothing does (the false shadows `compare` counts).
@compute @workgroup_size(8, 8)
fn cs_contact(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = receiver_at(id);
    if r.position.w <= 0.0 {
        return;
    }
    let i = r.index;
    let p = r.position.xyz;
    let to_light = towards_light(p);
    let dir = to_light.xyz;
    var length = xf.contact.x;
    if xf.light.w == LIGHT_SPOT {
        // A spot or point light: the length is per unit of distance, as its texels are.
        length = min(length * to_light.w, 0.5 * to_light.w);
    }
    let origin = ray_origin(id, p, dir, xf.params.x);
    let size = xf.params.zw;
    var verdict = -1.0;
    for (var k = 1u; k <= CONTACT_STEPS; k++) {
        let q = origin + dir * (length * f32(k) / f32(CONTACT_STEPS));
        let c = xf.camera_clip * vec4<f32>(q, 1.0);
        if c.w <= 0.0 {
            break;
        }
        let ndc = c.xy / c.w;
        if abs(ndc.x) >= 1.0 || abs(ndc.y) >= 1.0 {
            break;
        }
        let px = vec2<i32>(vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * size);
        let seen = textureLoad(receiver_position, px, 0);
        if seen.w <= 0.0 {
            continue;
        }
        // How far q lies behind the surface seen there, along the camera's ray through q: the
        // surface taken as the plane of the pixel's face (the pixel centre's own depth would be
        // off by its footprint, which on a surface seen at a grazing angle shadows the surface
        // itself).
        let eye = xf.eye.xyz;
        let v = normalize(q - eye);
        let n = textureLoad(receiver_normal, px, 0).xyz;
        let facing = dot(n, v);
        var depth = distance(seen.xyz, eye);
        if abs(facing) > 1e-4 {
            depth = dot(n, seen.xyz - eye) / facing;
        }
        let behind = distance(q, eye) - depth;
        if behind > xf.params.x && behind < xf.contact.z {
            verdict = 0.0;
            break;
        }
    }
    samples[i + 1u] = vec4<f32>(p, verdict);
}

// ---- 3. Casters ----

struct CasterOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) v0: vec3<f32>,
    @location(1) @interpolate(flat) v1: vec3<f32>,
    @location(2) @interpolate(flat) v2: vec3<f32>,
    // The triangle's cells (x0, y0, x1, y1), inclusive: fragments of the dilated triangle
    // outside them have nothing to test.
    @location(3) @interpolate(flat) cells: vec4<f32>,
    @location(4) @interpolate(flat) uv0: vec4<f32>,
    @location(5) @interpolate(flat) uv1: vec4<f32>,
    @location(6) @interpolate(flat) uv2: vec4<f32>,
    @location(7) @interpolate(flat) alpha: vec3<f32>,
    // The nearest the triangle comes to a directional light, along its rays.
    @location(8) @interpolate(flat) depth: f32,
}

fn vertex_index_of(tri: u32, k: u32) -> u32 {
    let first = bitcast<u32>(pc.extra[0].x);
    let offset = bitcast<i32>(pc.extra[0].y);
    return u32(i32(indices[first + tri * 3u + k]) + offset);
}

fn world_vertex(v: u32) -> vec3<f32> {
    let p = vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
    return (pc.world_from_model * vec4<f32>(p, 1.0)).xyz;
}

// TEXCOORD_0 and TEXCOORD_1 of vertex `v`.
fn vertex_uvs(v: u32) -> vec4<f32> {
    let a = ATTRIBUTE_WORDS * v;
    return vec4<f32>(
        bitcast<f32>(attributes[a + 3u]),
        bitcast<f32>(attributes[a + 4u]),
        bitcast<f32>(attributes[a + 11u]),
        bitcast<f32>(attributes[a + 12u]),
    );
}

// COLOR_0's alpha of vertex `v` (the high 16 bits of the colour's second word, unorm).
fn vertex_alpha(v: u32) -> f32 {
    return f32(attributes[ATTRIBUTE_WORDS * v + 10u] >> 16u) / 65535.0;
}

// Corners of a grown triangle farther than this many cells from the triangle's own: a sliver.
const MITER_CELLS: f32 = 4.0;

// Edge `e` of triangle `p` (signed area `area`) as the line n·x = d moved outwards by `half`
// cell's support along its unit normal n: (n, d).
fn grown_line(p: array<vec2<f32>, 3>, e: u32, area: f32, half: f32) -> vec3<f32> {
    let a = p[e];
    let b = p[(e + 1u) % 3u];
    let n = normalize(vec2<f32>(b.y - a.y, a.x - b.x)) * select(-1.0, 1.0, area > 0.0);
    return vec3<f32>(n, dot(n, a) + half * (abs(n.x) + abs(n.y)));
}

@vertex
fn vs_caster(@builtin(vertex_index) vi: u32) -> CasterOut {
    var out: CasterOut;
    // Six vertices a triangle: two triangles over the cells its light-view box touches.
    var tri = vi / 6u;
    if xf.hybrid.x > 0.5 {
        tri = kept_read[bitcast<u32>(pc.extra[1].x) + tri];
    }
    let corner = vi % 6u;
    let i0 = vertex_index_of(tri, 0u);
    let i1 = vertex_index_of(tri, 1u);
    let i2 = vertex_index_of(tri, 2u);
    out.v0 = world_vertex(i0);
    out.v1 = world_vertex(i1);
    out.v2 = world_vertex(i2);
    out.uv0 = vertex_uvs(i0);
    out.uv1 = vertex_uvs(i1);
    out.uv2 = vertex_uvs(i2);
    out.alpha = vec3<f32>(vertex_alpha(i0), vertex_alpha(i1), vertex_alpha(i2));
    let g = xf.params.y;
    // The box's corners: (0, 0) (1, 0) (1, 1), (0, 0) (1, 1) (0, 1) of (low, high).
    let pick = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    )[corner];
    let view = xf.views[u32(pc.extra[0].w)];
    let c0 = view * vec4<f32>(out.v0, 1.0);
    let c1 = view * vec4<f32>(out.v1, 1.0);
    let c2 = view * vec4<f32>(out.v2, 1.0);
    if max(c0.w, max(c1.w, c2.w)) <= 1e-6 {
        // Wholly behind a spot light's or cube face's plane: a ray from a sample of this view
        // (in front of it) to the light never reaches it.
        out.clip = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        return out;
    }
    if min(c0.w, min(c1.w, c2.w)) <= 1e-6 {
        // Crossing that plane: the box of its part in front (the triangle clipped at w = 1e-6,
        // projected), within the grid, tests it.
        let c = array<vec4<f32>, 3>(c0, c1, c2);
        var lo = vec2<f32>(3.0e38);
        var hi = vec2<f32>(-3.0e38);
        for (var k = 0u; k < 3u; k++) {
            let a = c[k];
            let b = c[(k + 1u) % 3u];
            if a.w > 1e-6 {
                lo = min(lo, a.xy / a.w);
                hi = max(hi, a.xy / a.w);
            }
            if (a.w - 1e-6) * (b.w - 1e-6) < 0.0 {
                let q = mix(a, b, (1e-6 - a.w) / (b.w - a.w));
                lo = min(lo, q.xy / 1e-6);
                hi = max(hi, q.xy / 1e-6);
            }
        }
        let half = vec2<f32>(1.0 / g);
        lo = clamp(lo - half, vec2<f32>(-1.0), vec2<f32>(1.0));
        hi = clamp(hi + half, vec2<f32>(-1.0), vec2<f32>(1.0));
        out.clip = vec4<f32>(mix(lo, hi, pick), 0.5, 1.0);
        out.cells = vec4<f32>(0.0, 0.0, g - 1.0, g - 1.0);
        out.depth = -3.0e38;
        return out;
    }
    let p0 = c0.xy / c0.w;
    let p1 = c1.xy / c1.w;
    let p2 = c2.xy / c2.w;
    // The box grown by half a cell (a cell is 2/g in NDC): every cell the triangle touches has its
    // centre inside.
    let lo = min(p0, min(p1, p2));
    let hi = max(p0, max(p1, p2));
    let half = vec2<f32>(1.0 / g);
    out.clip = vec4<f32>(mix(lo - half, hi + half, pick), 0.5, 1.0);
    // A well-shaped triangle is drawn as itself grown by half a cell (fewer cells than its box,
    // a diagonal card's half): its edges' lines moved out by a cell's support along their
    // normals, each corner where two of them meet; the second three vertices then draw nothing.
    // A sliver, whose grown corners would run more than `MITER_CELLS` away, keeps its box.
    let p = array<vec2<f32>, 3>(p0, p1, p2);
    let area = (p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x);
    var grown: array<vec2<f32>, 3>;
    var shaped = abs(area) > 0.0;
    for (var k = 0u; k < 3u; k++) {
        let prev = grown_line(p, (k + 2u) % 3u, area, half.x);
        let next = grown_line(p, k, area, half.x);
        let det = prev.x * next.y - prev.y * next.x;
        grown[k] = vec2<f32>(prev.z * next.y - next.z * prev.y, prev.x * next.z - next.x * prev.z) / det;
        shaped = shaped && abs(det) > 1e-6 && distance(grown[k], p[k]) <= MITER_CELLS * 2.0 * half.x;
    }
    if shaped {
        out.clip = vec4<f32>(grown[min(corner, 2u)], 0.5, 1.0);
        if corner >= 3u {
            out.clip = vec4<f32>(grown[0], 0.5, 1.0);
        }
    }
    out.cells = box_cells(lo, hi);
    // The nearest any point of the triangle comes to a directional light.
    out.depth = min(dot(out.v0, xf.light.xyz), min(dot(out.v1, xf.light.xyz), dot(out.v2, xf.light.xyz)));
    return out;
}

// The cells (x0, y0, x1, y1, inclusive; rows down, as cell_of) of the light-view box lo..hi (NDC).
fn box_cells(lo: vec2<f32>, hi: vec2<f32>) -> vec4<f32> {
    let g = xf.params.y;
    return vec4<f32>(
        floor((lo.x * 0.5 + 0.5) * g),
        floor((0.5 - hi.y * 0.5) * g),
        floor((hi.x * 0.5 + 0.5) * g),
        floor((0.5 - lo.y * 0.5) * g),
    );
}

@fragment
fn fs_caster(in: CasterOut) {
    let nearest = in.depth;
    let g = u32(xf.params.y);
    let cell = vec2<f32>(floor(in.clip.xy));
    if cell.x < in.cells.x || cell.y < in.cells.y || cell.x > in.cells.z || cell.y > in.cells.w {
        return;
    }
    let c = u32(pc.extra[0].w) * g * g + u32(cell.y) * g + u32(cell.x);
    // Behind every sample of the cell (farther from the light): it blocks none of their rays.
    if xf.light.w == LIGHT_DIRECTIONAL && ordered(nearest) > atomicLoad(&heads[cell_count() + c]) {
        return;
    }
    let e1 = in.v1 - in.v0;
    let e2 = in.v2 - in.v0;
    let tested = pc.extra[0].z > 0.5;
    let blocked_verdict = select(OCCLUDED, TRACED_OCCLUDED, xf.hybrid.x > 0.5);
    var s = atomicLoad(&heads[c]);
    loop {
        if s == 0u {
            break;
        }
        let i = s - 1u;
        s = next[i];
        if samples[i + 1u].w == blocked_verdict {
            continue;
        }
        let ray = rays[i];
        var dir = -xf.light.xyz;
        if xf.light.w == LIGHT_SPOT {
            dir = normalize(xf.light.xyz - ray.xyz);
        }
        // Moller-Trumbore, as the reference's BVH intersects.
        let pv = cross(dir, e2);
        let det = dot(e1, pv);
        if abs(det) < 1e-20 {
            continue;
        }
        let inv = 1.0 / det;
        let tv = ray.xyz - in.v0;
        let u = dot(tv, pv) * inv;
        if u < 0.0 || u > 1.0 {
            continue;
        }
        let qv = cross(tv, e1);
        let v = dot(dir, qv) * inv;
        if v < 0.0 || u + v > 1.0 {
            continue;
        }
        let t = dot(e2, qv) * inv;
        // The origin is off the surface: its own triangle lies behind it (t < 0).
        if t <= 0.0 || t >= ray.w {
            continue;
        }
        if tested {
            let w0 = 1.0 - u - v;
            let uv = in.uv0 * w0 + in.uv1 * u + in.uv2 * v;
            let a = (in.alpha.x * w0 + in.alpha.y * u + in.alpha.z * v) * material.base_color.a
                * textureSampleLevel(base_color_tex, base_color_sampler, slot_uv(0u, uv), 0.0).a;
            if a < material.extra.y {
                continue;
            }
        }
        samples[i + 1u].w = blocked_verdict;
    }
}
