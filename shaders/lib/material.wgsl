// A material block and its texture-coordinate transform, shared by the camera pass (group 1) and
// the masked shadow pipeline (group 0). Each shader declares the `material` variable itself.

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
