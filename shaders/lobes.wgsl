// The specular lobes, one function per model, as `[rho_1, rho_0]` (rho_s = k_s rho_1 + rho_0
// per colour channel): the shader twins of each model's `lobe` in
// crates/kapaint-reflectance/src/model/<model>/, operation for operation. The GPU tests
// evaluate `specular_lobe` at 10^4 points against `ShadingModel::specular`.

#include "ambient.wgsl"

const PI: f32 = 3.14159265f;

// The cosines of unit `normal`, `l` (towards the light) and `v` (towards the eye), as
// `Cosines::of`: N.L, N.V, R.V, N.H, |N x H|^2, V.H, and whether the half vector exists.
struct Cosines {
    nl: f32,
    nv: f32,
    rv: f32,
    nh: f32,
    cross2: f32,
    vh: f32,
    has_half: bool,
}

fn cosines_of(normal: vec3<f32>, l: vec3<f32>, v: vec3<f32>) -> Cosines {
    let nl = dot(normal, l);
    let nv = dot(normal, v);
    let rv = dot(2.0 * nl * normal - l, v);
    let sum = l + v;
    let len2 = dot(sum, sum);
    if len2 > 0.0 {
        let h = sum / sqrt(len2);
        let c = cross(normal, h);
        return Cosines(nl, nv, rv, dot(normal, h), dot(c, c), dot(v, h), true);
    }
    return Cosines(nl, nv, rv, 0.0, 1.0, 0.0, false);
}

// max(0, c)^n as exp2(n log2 c), c capped at 1: 0 for c <= 0 (and NaN), 1 for n == 0.
fn lobe_power(c: f32, n: f32) -> f32 {
    if !(c > 0.0) {
        return 0.0;
    }
    return exp2(n * log2(min(c, 1.0)));
}

// Original Phong: max(0, R.V)^n where N.L > 0.
fn phong_lobe(c: Cosines, n: f32) -> vec2<f32> {
    if !(c.nl > 0.0) {
        return vec2<f32>(0.0);
    }
    return vec2<f32>(lobe_power(c.rv, n), 0.0);
}

// Blinn-Phong: max(0, N.H)^n where N.L > 0 and H exists.
fn blinn_lobe(c: Cosines, n: f32) -> vec2<f32> {
    if !(c.nl > 0.0 && c.has_half) {
        return vec2<f32>(0.0);
    }
    return vec2<f32>(lobe_power(c.nh, n), 0.0);
}

// Cook-Torrance: D G2 F / (4 N.V) split by Schlick's F as F0 * rho_1 + rho_0, alpha^2 =
// 2 / (n + 2); written without cancellation (1 - (N.H)^2 as |N x H|^2, G2 / (4 N.L N.V) in the
// form finite at grazing angles). Zero where N.L <= 0, N.V <= 0 or H does not exist.
fn cook_torrance_lobe(c: Cosines, n: f32) -> vec2<f32> {
    if !(c.nl > 0.0 && c.nv > 0.0 && c.has_half) {
        return vec2<f32>(0.0);
    }
    let a2 = 2.0 / (n + 2.0);
    let m = 1.0 - clamp(c.vh, 0.0, 1.0);
    let q = a2 + (1.0 - a2) * c.cross2;
    let d = a2 / (PI * q * q);
    let smith = c.nv * sqrt(c.nl * c.nl * (1.0 - a2) + a2) + c.nl * sqrt(c.nv * c.nv * (1.0 - a2) + a2);
    if !(smith > 0.0) {
        return vec2<f32>(0.0);
    }
    let base = d * c.nl / (2.0 * smith);
    let m2 = m * m;
    let s = m2 * m2 * m;
    return vec2<f32>(base * (1.0 - s), base * s);
}

// The model's lobe for a sanitized `n` (Cook-Torrance's capped at CT_N_MAX, as
// `ShadingModel::n_max`).
fn specular_lobe(model: u32, normal: vec3<f32>, l: vec3<f32>, v: vec3<f32>, n: f32) -> vec2<f32> {
    let c = cosines_of(normal, l, v);
    if model == MODEL_PHONG {
        return phong_lobe(c, n);
    }
    if model == MODEL_BLINN {
        return blinn_lobe(c, n);
    }
    if model == MODEL_COOK_TORRANCE {
        return cook_torrance_lobe(c, min(n, CT_N_MAX));
    }
    return vec2<f32>(0.0);
}
