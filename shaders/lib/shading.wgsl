// Blinn-Phong with normal mapping and shadows: the base colour, and `shade` / `shade_texels`, which
// every lit entry point calls.

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

// The ambient hemisphere's Ia for unit normal (or view direction) `n`: the ground's facing
// down, the sky's facing up, mixed by the up component (src/plan/settings.rs `Ambient::at`).
fn ambient_at(n: vec3<f32>) -> vec3<f32> {
    return mix(frame.ambient_ground.rgb, frame.ambient_sky.rgb, clamp(0.5 + 0.5 * n.y, 0.0, 1.0));
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

// The verdict on the shadowed light at the pixel `frag` (1 lit, 0 blocked, plus 2 where hybrid
// shadows traced it; -1 none: the maps decide) when the point `p` shaded there is the receiver it was made for (the same position: the
// camera pass and the receiver pass transform alike); -1 otherwise.
fn exact_verdict(p: vec3<f32>, frag: vec2<f32>) -> f32 {
    let size = exact_samples[0].xy;
    let px = vec2<u32>(clamp(frag, vec2<f32>(0.0), max(size - vec2<f32>(1.0), vec2<f32>(0.0))));
    let s = exact_samples[1u + px.y * u32(size.x) + px.x];
    let tolerance = 1e-5 * distance(p, frame.camera_position.xyz) + 1e-7;
    return select(-1.0, s.w, s.w >= 0.0 && distance(s.xyz, p) <= tolerance);
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
    // Towards the eye, or against the viewing direction under an orthographic camera.
    let v = select(normalize(frame.camera_position.xyz - p), -frame.eye_forward.xyz, frame.eye_forward.w > 0.5);
    // Occlusion (mr.r) scales the ambient term only: 1 + strength * (occlusion - 1).
    let occlusion = 1.0 + material.params.z * (mr.r - 1.0);
    var color = ka * ambient_at(n) * occlusion + emissive;
    var shadow_term = 1.0;
    var cascade = -1;
    // One sun: a constant trip count the driver unrolls (a uniform count costs a real loop), and
    // no point or spot code (llvmpipe runs both sides of a branch, masked, on every pixel).
    let count = select(min(frame.modes.w, MAX_LIGHTS), 1u, ONE_SUN);
    for (var i = 0u; i < count; i++) {
        let light = light_at(i);
        var l: vec3<f32>;
        var radiance = light.color.rgb;
        if ONE_SUN || light.position.w == LIGHT_DIRECTIONAL {
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
            // The per-pixel verdict on the shown light where this fragment is the receiver it was
            // made for (`exact_verdict`): the exact pass's, or contact shadows' where they found
            // a caster; the maps elsewhere.
            var verdict = -1.0;
            if EXACT && shown {
                verdict = exact_verdict(p, in.clip.xy);
            }
            if verdict >= 0.0 {
                // Hybrid shadows mark traced verdicts 2 + verdict: the cascade view shows them
                // as view 1, the map's as view 0.
                vis *= verdict % 2.0;
                cascade = select(0, 1, verdict >= 2.0);
            } else if MANY_VIEWS {
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
