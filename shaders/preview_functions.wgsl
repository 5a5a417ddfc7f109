// The preview's functions that need no bindings: the false-colour scale of n, the guard
// against non-finite results and the normal map (the lobes are in lobes.wgsl).

#include "lobes.wgsl"

// n's false-colour scale: ln(1 + n) / ln(1 + 16384) through five colours (dark blue, blue,
// teal, green, yellow; linear RGB), as `render::N_RAMP`.
const N_LOG_SPAN: f32 = 9.704121561132915f;
const N_RAMP = array<vec3<f32>, 5>(
    vec3<f32>(0.0331, 0.0006, 0.0622),
    vec3<f32>(0.0482, 0.0785, 0.3712),
    vec3<f32>(0.0123, 0.3016, 0.2756),
    vec3<f32>(0.1946, 0.6172, 0.0284),
    vec3<f32>(0.9473, 0.7991, 0.0091),
);

fn n_false_colour(n: f32) -> vec3<f32> {
    let t = clamp(log(1.0 + n) / N_LOG_SPAN, 0.0, 1.0) * 4.0;
    let i = min(u32(t), 3u);
    return mix(N_RAMP[i], N_RAMP[i + 1u], t - f32(i));
}

// Replaces a non-finite result by 0 (on the bits: compilers may assume finite floats).
fn finite_or_zero(c: vec3<f32>) -> vec3<f32> {
    let bits = bitcast<vec3<u32>>(c) & vec3<u32>(0x7fffffffu);
    return select(vec3<f32>(0.0), c, bits < vec3<u32>(0x7f800000u));
}

// The shading normal of a tangent-space normal-map texel `texel` (RGB in [0, 1], glTF's
// convention: +Y along the bitangent) in the frame of the unit geometric normal `n` and the
// MikkTSpace tangent `t` (bitangent `sign(t.w) n x t`). The geometric normal where the
// tangent is missing.
fn mapped_normal(n: vec3<f32>, t: vec4<f32>, texel: vec3<f32>) -> vec3<f32> {
    let along = t.xyz - n * dot(n, t.xyz);
    if dot(along, along) < 1e-12 {
        return n;
    }
    let tangent = normalize(along);
    let bitangent = select(-1.0, 1.0, t.w >= 0.0) * cross(n, tangent);
    let m = texel * 2.0 - vec3<f32>(1.0);
    let mapped = m.x * tangent + m.y * bitangent + m.z * n;
    if dot(mapped, mapped) < 1e-12 {
        return n;
    }
    return normalize(mapped);
}
