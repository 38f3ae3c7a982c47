// Shadow-map visibility: nearest, bilinear and PCF comparisons, cascade and cube-face choice,
// and PCSS soft shadows. Reads `frame`, `shadow_map` and `shadow_sampler` and the overrides.

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
        c += select(0, 1, k + 1 < n && d > frame_block.views[min(first + k, MAX_SHADOW_VIEWS - 1)].cascade.x);
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
    let v = frame_block.views[min(first + c, MAX_SHADOW_VIEWS - 1)].cascade;
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
    let view = view_at(layer);
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
// Widest penumbra radius filtered, in texels (generated as shaders::scene::SOFT_MAX_TEXELS).
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
