// Exposure, tone curves and the picked primitive's tint: the end of every lit entry point.

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

// The displayed colour of a surface of the draw's material: an unlit one as authored at the
// automatic exposure (output.w = 1: times output.z, clamped; no tone curve), else `display`.
fn display_surface(c: vec3<f32>) -> vec3<f32> {
    if material.params.w > 0.5 && frame.output.w > 0.5 {
        return clamp(c * frame.output.z, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    return display(c);
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
