// Hybrid shadows (included by exact.wgsl; docs/exact-shadows.md, "Hybrid"): the map's verdict
// where its texels prove it (map_verdict, in cs_build), the thin casters that can fall between
// texel centres (cs_thin, before binning), and the caster triangles kept for the traced samples
// (cs_cull, before the caster pass). Uses exact.wgsl's bindings and helpers.
// ---- Hybrid: the map's verdict where it is certain ----

// The map's verdict on the receiver at `p` (unit face normal `n` on the light's side; shadow
// ray from `origin`, `offset` off the surface) where the map proves it, else -1. Each of the 3×3
// texels around the origin's holds the first caster its light ray meets (no slope bias: the
// map is drawn without it for hybrid frames); with h that point's height above the receiver's
// plane, every h below the origin means no caster reaches above it near the ray (lit), every h
// a texel or more above it means casters cover the ray all round (blocked: a texel is more than
// a curved receiver's own surface can rise within the footprint). Anything between, or a
// footprint leaving the map, is traced. What no texel centre sees (a caster or a gap under a
// texel and a half across) is what the method can miss.
fn map_verdict(p: vec3<f32>, n: vec3<f32>, origin: vec3<f32>, offset: f32, reach: f32) -> f32 {
    let c = xf.views[0] * vec4<f32>(origin, 1.0);
    if c.w <= 0.0 {
        return -1.0;
    }
    let size = xf.hybrid.y;
    let ndc = c.xy / c.w;
    let t = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * size;
    if any(t < xf.rect.xy) || any(t > xf.rect.zw) {
        // No caster's texel within the footprint: nothing casts here.
        return 1.0;
    }
    var texel = xf.hybrid.z;
    if xf.light.w == LIGHT_SPOT {
        texel = texel * reach;
    }
    let margin = texel + offset;
    let base = vec2<i32>(floor(t));
    if any(base < vec2<i32>(1)) || any(base >= vec2<i32>(i32(size) - 1)) {
        return -1.0;
    }
    // A thin or alpha-tested caster near the footprint: the texel centres may miss it.
    for (var ty = base.y - 1; ty <= base.y + 1; ty++) {
        let row = u32(ty) * u32(size);
        let first = row + u32(base.x - 1);
        let last = row + u32(base.x + 1);
        if (atomicLoad(&thin[first / 32u]) & (1u << (first % 32u))) != 0u
            || (atomicLoad(&thin[(first + 1u) / 32u]) & (1u << ((first + 1u) % 32u))) != 0u
            || (atomicLoad(&thin[last / 32u]) & (1u << (last % 32u))) != 0u {
            return -1.0;
        }
    }
    // The world point of texel base + (dx, dy) at map depth z is (q0 + dx·cx + dy·cy + z·cz)
    // divided by its w: the map's clip-to-world transform taken apart.
    let m = xf.world_from_map;
    let uv = (vec2<f32>(base) + 0.5) / size;
    let q0 = m * vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    let cx = m[0] * (2.0 / size);
    let cy = m[1] * (-2.0 / size);
    let cz = m[2];
    // What the world points' arithmetic can err by: a few dozen f32 steps of the largest terms
    // (a 2 km light view's depth range against a receiver near the origin, whose own offset is
    // far smaller).
    let err = (max_abs(q0.xyz) + max_abs(cz.xyz) + max_abs(p)) * ARITHMETIC_ERROR;
    var lit = true;
    var blocked = true;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let stored = textureLoad(shadow_map, base + vec2<i32>(dx, dy), 0, 0);
            let q = q0 + f32(dx) * cx + f32(dy) * cy + stored * cz;
            let h = dot(n, q.xyz / q.w - p);
            lit = lit && h < offset + err;
            blocked = blocked && h >= margin;
            if !lit && !blocked {
                return -1.0;
            }
        }
    }
    if lit {
        return 1.0;
    }
    if blocked {
        return OCCLUDED;
    }
    return -1.0;
}

// How far along the light a point lies: along a directional light's rays, or from a spot light.
fn light_depth(p: vec3<f32>) -> f32 {
    if xf.light.w == LIGHT_SPOT {
        return distance(p, xf.light.xyz);
    }
    return dot(p, xf.light.xyz);
}

// The largest absolute coordinate of `v`.
fn max_abs(v: vec3<f32>) -> f32 {
    let a = abs(v);
    return max(a.x, max(a.y, a.z));
}

// Whether any tile of the cells `cells` (x0, y0, x1, y1, inclusive) holds a traced sample whose
// ray starts farther along the light than `nearest` (the nearest a caster comes).
fn tiles_traced(cells: vec4<f32>, nearest: f32) -> bool {
    let g = u32(xf.params.y);
    let side = g / TILE_CELLS;
    let lo = vec2<u32>(clamp(cells.xy, vec2<f32>(0.0), vec2<f32>(f32(g - 1u)))) / TILE_CELLS;
    let hi = vec2<u32>(clamp(cells.zw, vec2<f32>(0.0), vec2<f32>(f32(g - 1u)))) / TILE_CELLS;
    let near = ordered(nearest);
    for (var ty = lo.y; ty <= hi.y; ty++) {
        for (var tx = lo.x; tx <= hi.x; tx++) {
            let far = tiles_read[ty * side + tx];
            if far != 0u && near <= far {
                return true;
            }
        }
    }
    return false;
}

// ---- Culling and thin casters ----

// Hybrid shadows: keeps the caster triangles of the draw in `pc` whose cells (vs_caster's box,
// in the one light view) meet a tile holding a traced sample, and counts six vertices each into
// the draw's indirect arguments. Triangles wholly behind a spot light are dropped, those
// crossing its plane kept (vs_caster tests them against the whole grid).
@compute @workgroup_size(64)
fn cs_cull(@builtin(global_invocation_id) id: vec3<u32>) {
    let args = 4u * bitcast<u32>(pc.extra[1].y);
    if id.x == 0u {
        atomicStore(&draw_args[args + 1u], 1u);
    }
    let tri = id.x;
    if tri >= bitcast<u32>(pc.extra[1].z) {
        return;
    }
    let c = light_clip_triangle(tri);
    let c0 = c[0];
    let c1 = c[1];
    let c2 = c[2];
    if max(c0.w, max(c1.w, c2.w)) <= 1e-6 {
        return;
    }
    if min(c0.w, min(c1.w, c2.w)) > 1e-6 {
        let p0 = c0.xy / c0.w;
        let p1 = c1.xy / c1.w;
        let p2 = c2.xy / c2.w;
        let lo = min(p0, min(p1, p2));
        let hi = max(p0, max(p1, p2));
        // The nearest the triangle comes along a directional light's rays (a spot light: 0).
        var nearest = 0.0;
        if xf.light.w == LIGHT_DIRECTIONAL {
            let v0 = world_vertex(vertex_index_of(tri, 0u));
            let v1 = world_vertex(vertex_index_of(tri, 1u));
            let v2 = world_vertex(vertex_index_of(tri, 2u));
            nearest = min(light_depth(v0), min(light_depth(v1), light_depth(v2)));
        }
        if !tiles_traced(box_cells(lo, hi), nearest) {
            return;
        }
    }
    let at = atomicAdd(&draw_args[args], 6u) / 6u;
    kept[bitcast<u32>(pc.extra[1].x) + at] = tri;
}

// Triangle `tri` of the draw in `pc`, in the clip space of the light's (one) view.
fn light_clip_triangle(tri: u32) -> array<vec4<f32>, 3> {
    let view = xf.views[0];
    return array<vec4<f32>, 3>(
        view * vec4<f32>(world_vertex(vertex_index_of(tri, 0u)), 1.0),
        view * vec4<f32>(world_vertex(vertex_index_of(tri, 1u)), 1.0),
        view * vec4<f32>(world_vertex(vertex_index_of(tri, 2u)), 1.0),
    );
}

// Where clip position `c` of the map's view falls in the map, in texels (rows down).
fn map_texels(c: vec4<f32>) -> vec2<f32> {
    return vec2<f32>(c.x / c.w * 0.5 + 0.5, 0.5 - c.y / c.w * 0.5) * xf.hybrid.y;
}

// Hybrid shadows: marks the map texels (`thin`) within half a texel of each triangle of the draw
// in `pc` that is thinner than `THIN_TEXELS` texels, or alpha-tested.
@compute @workgroup_size(64)
fn cs_thin(@builtin(global_invocation_id) id: vec3<u32>) {
    let tri = id.x;
    if tri >= bitcast<u32>(pc.extra[1].z) {
        return;
    }
    let c = light_clip_triangle(tri);
    let c0 = c[0];
    let c1 = c[1];
    let c2 = c[2];
    if min(c0.w, min(c1.w, c2.w)) <= 1e-6 {
        // At or behind a spot light's plane: no texel of the map holds it.
        return;
    }
    let size = xf.hybrid.y;
    let p0 = map_texels(c0);
    let p1 = map_texels(c1);
    let p2 = map_texels(c2);
    let e = array<vec2<f32>, 3>(p1 - p0, p2 - p1, p0 - p2);
    let longest = max(length(e[0]), max(length(e[1]), length(e[2])));
    let area2 = abs(e[0].x * e[2].y - e[0].y * e[2].x);
    let tested = pc.extra[0].z > 0.5;
    if !tested && area2 >= THIN_TEXELS * longest {
        return;
    }
    let lo = clamp(vec2<i32>(floor(min(p0, min(p1, p2)) - 0.5)), vec2<i32>(0), vec2<i32>(i32(size) - 1));
    let hi = clamp(vec2<i32>(floor(max(p0, max(p1, p2)) + 0.5)), vec2<i32>(0), vec2<i32>(i32(size) - 1));
    let p = array<vec2<f32>, 3>(p0, p1, p2);
    for (var ty = lo.y; ty <= hi.y; ty++) {
        for (var tx = lo.x; tx <= hi.x; tx++) {
            // The texel grown by half a texel, against the triangle itself (a sliver's box can be
            // most of the map); a footprint's 3×3 texels then reach what is within a texel and a
            // half of its origin's texel.
            let t = vec2<f32>(f32(tx), f32(ty));
            if box_meets_triangle(t - 0.5, t + 1.5, p) {
                let bit = u32(ty) * u32(size) + u32(tx);
                atomicOr(&thin[bit / 32u], 1u << (bit % 32u));
            }
        }
    }
}

// Whether the box lo..hi meets triangle `p` (its box is assumed to): no edge's line has the
// whole box outside it (a degenerate triangle, a segment: on one side of its line).
fn box_meets_triangle(lo: vec2<f32>, hi: vec2<f32>, p: array<vec2<f32>, 3>) -> bool {
    let corners = array<vec2<f32>, 4>(lo, vec2<f32>(hi.x, lo.y), hi, vec2<f32>(lo.x, hi.y));
    for (var k = 0u; k < 3u; k++) {
        let a = p[k];
        let b = p[(k + 1u) % 3u];
        let n = vec2<f32>(b.y - a.y, a.x - b.x);
        let inside = dot(n, p[(k + 2u) % 3u] - a);
        var least = 3.0e38;
        var most = -3.0e38;
        for (var c = 0u; c < 4u; c++) {
            let d = dot(n, corners[c] - a);
            least = min(least, d);
            most = max(most, d);
        }
        if inside > 0.0 && most < 0.0 || inside < 0.0 && least > 0.0 {
            return false;
        }
        if inside == 0.0 && (least > 0.0 || most < 0.0) {
            return false;
        }
    }
    return true;
}
