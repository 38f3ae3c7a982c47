// The deferred path's G-buffer encoding (fs_gbuffer writes it, fs_resolve reads it).

// Deferred shading of draws whose triangles are smaller than llvmpipe's 4x4 shading block (the
// renderer's `deferred::plan`, CPU devices only). llvmpipe shades every 4x4 block a triangle
// touches, so a helmet of 1.5-pixel triangles runs the material shader several times per pixel
// it keeps; these draws instead store what `shade` reads from their varyings (fs_gbuffer: no
// texture reads, no lighting), and fs_resolve shades each covered pixel once, per material,
// where the stencil holds that material's mark. Two RGBA32UI targets:
//   a: depth (f32 bits: the world position is rebuilt from it), the normal (octahedral,
//      2 x snorm16), flags (1 tangent sign >= 0, 2 front face, 4 tangent non-zero),
//      TEXCOORD_0.x (f32 bits)
//   b: TEXCOORD_0.y (f32 bits), d(uv)/dx and d(uv)/dy (2 x f16 each), the tangent (octahedral)
// An untextured material needs only the depth, normal and front face: its draws write target a
// alone (b masked in its pipeline: half the colour bytes per fragment), and its
// resolve reads a alone.
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

// The derivative of slot i's coordinates for a change `d` of TEXCOORD_0 (the transform's linear
// part).
fn slot_grad(i: u32, d: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(dot(material.uv[2u * i].xy, d), dot(material.uv[2u * i + 1u].xy, d));
}

// Whether the material reads any texture (and so needs TEXCOORD_0, its derivatives and target b).
fn textured() -> bool {
    return HAS_BASE_TEX || HAS_NORMAL_MAP || HAS_OTHER_TEX;
}
