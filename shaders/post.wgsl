// Post-process anti-aliasing of the finished lit image: FXAA, the published "quality" algorithm
// (T. Lottes, "FXAA", NVIDIA white paper, 2009; version 3.11's edge search), written here from
// its description.
//
// Two passes, so that a CPU device shades only the pixels on edges. `fs_mark` copies every
// pixel and marks those whose luma range over the pixel and its four neighbours makes an edge
// (in the depth attachment: 0.25 on edges, 1 elsewhere); `fs_fxaa` runs where the mark is
// (a triangle at depth 0.5 tested GREATER: llvmpipe's early depth test skips whole blocks
// without an edge). Flat pixels are therefore copied bit for bit.
//
// On an edge pixel, the edge's orientation comes from the 3×3 neighbourhood's second
// differences, the search walks along the edge in both directions (sampling halfway between the
// pixel's row and its neighbour's, where bilinear filtering averages the two) until the luma
// leaves the edge's, and the pixel is resampled across the edge by the coverage that the nearer
// end implies; a sub-pixel term smooths lone bright or dark pixels. Luma is perceptual: the
// square root of linear luminance.
//
// The source is the sRGB image itself: sampling decodes to linear light, so filtering blends in
// linear light, and the sRGB attachment re-encodes.

struct PostImmediates {
    // 1 / width, 1 / height of the image.
    rcp_extent: vec2<f32>,
}

var<immediate> pc: PostImmediates;

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var source_sampler: sampler;

// An edge needs a local luma range of at least this much...
const EDGE_THRESHOLD_MIN: f32 = 0.0312;
// ...and of at least this fraction of the neighbourhood's brightest luma.
const EDGE_THRESHOLD: f32 = 0.125;
// Weight of the sub-pixel term (FXAA's default 0.75).
const SUBPIX: f32 = 0.75;
// Edge-search steps in pixels after the first (FXAA 3.11 quality preset 12: five samples each
// way).
const SEARCH_STEPS: u32 = 4u;

// Depth `fs_mark` writes on edge pixels and elsewhere, and the depth `vs_edges` draws at.
const MARK_EDGE: f32 = 0.25;
const MARK_FLAT: f32 = 1.0;
const EDGES_DEPTH: f32 = 0.5;

struct FullscreenOut {
    @builtin(position) clip: vec4<f32>,
}

fn fullscreen(index: u32, z: f32) -> FullscreenOut {
    var out: FullscreenOut;
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    out.clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, z, 1.0);
    return out;
}

@vertex
fn vs_mark(@builtin(vertex_index) index: u32) -> FullscreenOut {
    return fullscreen(index, 0.0);
}

@vertex
fn vs_edges(@builtin(vertex_index) index: u32) -> FullscreenOut {
    return fullscreen(index, EDGES_DEPTH);
}

fn luma(c: vec3<f32>) -> f32 {
    return sqrt(dot(c, vec3<f32>(0.299, 0.587, 0.114)));
}

fn luma_at(p: vec2<i32>, size: vec2<i32>) -> f32 {
    return luma(textureLoad(source, clamp(p, vec2<i32>(0), size - vec2<i32>(1)), 0).rgb);
}

fn luma_uv(uv: vec2<f32>) -> f32 {
    return luma(textureSampleLevel(source, source_sampler, uv, 0.0).rgb);
}

// A pixel's luma and its four neighbours'.
struct Cross {
    m: f32,
    n: f32,
    s: f32,
    w: f32,
    e: f32,
}

fn cross_at(p: vec2<i32>, size: vec2<i32>, center: vec3<f32>) -> Cross {
    // Rows go down: north is y - 1.
    return Cross(
        luma(center),
        luma_at(p + vec2<i32>(0, -1), size),
        luma_at(p + vec2<i32>(0, 1), size),
        luma_at(p + vec2<i32>(-1, 0), size),
        luma_at(p + vec2<i32>(1, 0), size),
    );
}

fn cross_range(c: Cross) -> vec2<f32> {
    let lo = min(c.m, min(min(c.n, c.s), min(c.w, c.e)));
    let hi = max(c.m, max(max(c.n, c.s), max(c.w, c.e)));
    return vec2<f32>(hi - lo, hi);
}

fn is_edge(c: Cross) -> bool {
    let r = cross_range(c);
    return r.x >= max(EDGE_THRESHOLD_MIN, r.y * EDGE_THRESHOLD);
}

struct MarkOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// Pass 1: the pixel as drawn, and whether it is on an edge.
@fragment
fn fs_mark(full: FullscreenOut) -> MarkOut {
    let size = vec2<i32>(textureDimensions(source));
    let p = vec2<i32>(full.clip.xy);
    let center = textureLoad(source, p, 0);
    var out: MarkOut;
    out.color = center;
    out.depth = select(MARK_FLAT, MARK_EDGE, is_edge(cross_at(p, size, center.rgb)));
    return out;
}

fn search_step(i: u32) -> f32 {
    switch i {
        case 0u: { return 1.5; }
        case 1u: { return 2.0; }
        case 2u: { return 4.0; }
        default: { return 12.0; }
    }
}

// Pass 2, on the pixels `fs_mark` marked.
@fragment
fn fs_fxaa(full: FullscreenOut) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(source));
    let p = vec2<i32>(full.clip.xy);
    let center = textureLoad(source, p, 0);
    let c = cross_at(p, size, center.rgb);
    let l_m = c.m;
    let l_n = c.n;
    let l_s = c.s;
    let l_w = c.w;
    let l_e = c.e;
    let range = cross_range(c).x;
    let l_nw = luma_at(p + vec2<i32>(-1, -1), size);
    let l_ne = luma_at(p + vec2<i32>(1, -1), size);
    let l_sw = luma_at(p + vec2<i32>(-1, 1), size);
    let l_se = luma_at(p + vec2<i32>(1, 1), size);

    // Sub-pixel aliasing: how far the pixel stands out from its neighbourhood's low-pass.
    let average = (2.0 * (l_n + l_s + l_w + l_e) + l_nw + l_ne + l_sw + l_se) / 12.0;
    let sub = clamp(abs(average - l_m) / range, 0.0, 1.0);
    let sub_smooth = smoothstep(0.0, 1.0, sub);
    let sub_offset = sub_smooth * sub_smooth * SUBPIX;

    // A horizontal edge changes luma from row to row.
    let horizontal = abs(l_nw - 2.0 * l_w + l_sw) + 2.0 * abs(l_n - 2.0 * l_m + l_s)
        + abs(l_ne - 2.0 * l_e + l_se);
    let vertical = abs(l_nw - 2.0 * l_n + l_ne) + 2.0 * abs(l_w - 2.0 * l_m + l_e)
        + abs(l_sw - 2.0 * l_s + l_se);
    let is_horizontal = horizontal >= vertical;

    // The neighbour across the edge: the side with the steeper gradient.
    let l_1 = select(l_w, l_n, is_horizontal);
    let l_2 = select(l_e, l_s, is_horizontal);
    let g_1 = l_1 - l_m;
    let g_2 = l_2 - l_m;
    let steeper_1 = abs(g_1) >= abs(g_2);
    let gradient_scaled = 0.25 * max(abs(g_1), abs(g_2));
    var step = select(pc.rcp_extent.x, pc.rcp_extent.y, is_horizontal);
    var edge_luma = 0.5 * (l_2 + l_m);
    if steeper_1 {
        step = -step;
        edge_luma = 0.5 * (l_1 + l_m);
    }

    // Walk along the edge, halfway between the pixel and that neighbour.
    let uv = (vec2<f32>(p) + vec2<f32>(0.5)) * pc.rcp_extent;
    var start = uv;
    var along = vec2<f32>(pc.rcp_extent.x, 0.0);
    if is_horizontal {
        start.y += 0.5 * step;
    } else {
        start.x += 0.5 * step;
        along = vec2<f32>(0.0, pc.rcp_extent.y);
    }
    var uv_1 = start - along;
    var uv_2 = start + along;
    var end_1 = luma_uv(uv_1) - edge_luma;
    var end_2 = luma_uv(uv_2) - edge_luma;
    var done_1 = abs(end_1) >= gradient_scaled;
    var done_2 = abs(end_2) >= gradient_scaled;
    for (var i = 0u; i < SEARCH_STEPS; i++) {
        if done_1 && done_2 {
            break;
        }
        if !done_1 {
            uv_1 -= along * search_step(i);
            end_1 = luma_uv(uv_1) - edge_luma;
            done_1 = abs(end_1) >= gradient_scaled;
        }
        if !done_2 {
            uv_2 += along * search_step(i);
            end_2 = luma_uv(uv_2) - edge_luma;
            done_2 = abs(end_2) >= gradient_scaled;
        }
    }
    let d_1 = select(uv.y - uv_1.y, uv.x - uv_1.x, is_horizontal);
    let d_2 = select(uv_2.y - uv.y, uv_2.x - uv.x, is_horizontal);
    let nearer_1 = d_1 < d_2;
    let d = min(d_1, d_2);
    let edge_length = d_1 + d_2;
    // Blend only when the nearer end's luma varies the other way from the centre's (the pixel
    // lies on the side of the edge that the end's step crosses).
    let end = select(end_2, end_1, nearer_1);
    let center_darker = l_m < edge_luma;
    var offset = 0.0;
    if (end < 0.0) != center_darker {
        offset = 0.5 - d / edge_length;
    }
    offset = max(offset, sub_offset);
    var at = uv;
    if is_horizontal {
        at.y += offset * step;
    } else {
        at.x += offset * step;
    }
    return textureSampleLevel(source, source_sampler, at, 0.0);
}
