// requires: ambient.wgsl
//
// kapaint's preview: per-fragment shading of the painted maps with the paper's hemispherical
// ambient term, k_a derived here from the sampled k_d, k_s and n (never stored):
//
//   I = I_a k_a + I_l [ k_d max(0, N.L) + k_s rho_s ]
//   rho_s = max(0, R.V)^n (Phong) or max(0, N.H)^n (Blinn-Phong), zero where N.L <= 0.
//
// Pipeline-overridable constants choose the model, the approximation and the view, and say
// what the scene doesn't need: a uniform map is a uniform value (no texture fetch), k_s == 0
// everywhere drops the specular work, data views skip the lighting. The CPU reference
// renderer (src/render/reference.rs) evaluates the same equation.

override MODEL: u32 = 0u;          // MODEL_PHONG or MODEL_BLINN
override APPROX: u32 = 2u;         // APPROX_*
override VIEW: u32 = 0u;           // VIEW_*
override KD_UNIFORM: bool = false;
override KS_UNIFORM: bool = false;
override N_UNIFORM: bool = false;
override HAS_SPECULAR: bool = true;

const VIEW_SHADED: u32 = 0u;
const VIEW_KA: u32 = 1u;
const VIEW_KD: u32 = 2u;
const VIEW_KS: u32 = 3u;
const VIEW_N: u32 = 4u;
const VIEW_DIFFUSE: u32 = 5u;
const VIEW_SPECULAR: u32 = 6u;
const VIEW_AMBIENT: u32 = 7u;
const VIEW_CHECKER: u32 = 8u;
const VIEW_N_FALSE_COLOUR: u32 = 9u;

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

struct Frame {
    view_proj: mat4x4<f32>,
    // xyz: eye position (object space)
    eye: vec4<f32>,
    // xyz: unit direction towards the light
    light: vec4<f32>,
    // x: I_a, y: I_l
    intensity: vec4<f32>,
    // uniform values of the maps (used where *_UNIFORM)
    kd: vec4<f32>,
    ks: vec4<f32>,
    // x: n
    n: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var kd_map: texture_2d<f32>;
@group(0) @binding(2) var ks_map: texture_2d<f32>;
@group(0) @binding(3) var n_map: texture_2d<f32>;
@group(0) @binding(4) var map_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = frame.view_proj * vec4<f32>(v.position, 1.0);
    out.position = v.position;
    out.normal = v.normal;
    // Mesh UVs have v up; texture rows run down.
    out.uv = vec2<f32>(v.uv.x, 1.0 - v.uv.y);
    return out;
}

// x^n for x in [0, 1] without pow's undefined cases: 0 for x <= 0, 1 for n == 0.
fn spec_pow(x: f32, n: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    return exp2(n * log2(min(x, 1.0)));
}

// Replaces a non-finite result by 0 (on the bits: compilers may assume finite floats).
fn finite_or_zero(c: vec3<f32>) -> vec3<f32> {
    let bits = bitcast<vec3<u32>>(c) & vec3<u32>(0x7fffffffu);
    return select(vec3<f32>(0.0), c, bits < vec3<u32>(0x7f800000u));
}

@fragment
fn fs_main(f: VertexOut) -> @location(0) vec4<f32> {
    var kd = frame.kd.xyz;
    if !KD_UNIFORM {
        kd = textureSample(kd_map, map_sampler, f.uv).xyz;
    }
    var ks = frame.ks.xyz;
    if !KS_UNIFORM {
        ks = textureSample(ks_map, map_sampler, f.uv).xyz;
    }
    var n = frame.n.x;
    if !N_UNIFORM {
        n = textureSample(n_map, map_sampler, f.uv).x;
    }
    kd = sanitize_k(kd);
    ks = sanitize_k(ks);
    n = sanitize_n(n);

    // Data views: no lighting at all.
    if VIEW == VIEW_KD {
        return vec4<f32>(kd, 1.0);
    }
    if VIEW == VIEW_KS {
        return vec4<f32>(ks, 1.0);
    }
    if VIEW == VIEW_N {
        return vec4<f32>(n, n, n, 1.0);
    }
    if VIEW == VIEW_N_FALSE_COLOUR {
        return vec4<f32>(n_false_colour(n), 1.0);
    }
    if VIEW == VIEW_CHECKER {
        let cell = vec2<i32>(floor(f.uv * 16.0));
        let odd = f32((cell.x + cell.y) & 1);
        return vec4<f32>(vec3<f32>(0.25 + 0.5 * odd), 1.0);
    }
    var ka = ambient_ka(MODEL, APPROX, kd, vec3<f32>(0.0), n);
    if HAS_SPECULAR {
        ka = ambient_ka(MODEL, APPROX, kd, ks, n);
    }
    if VIEW == VIEW_KA {
        return vec4<f32>(finite_or_zero(ka), 1.0);
    }
    let ambient = frame.intensity.x * ka;
    if VIEW == VIEW_AMBIENT {
        return vec4<f32>(finite_or_zero(ambient), 1.0);
    }

    let normal = normalize(f.normal);
    let l = frame.light.xyz;
    let v = normalize(frame.eye.xyz - f.position);
    let n_dot_l = dot(normal, l);
    let diffuse = frame.intensity.y * kd * max(0.0, n_dot_l);
    if VIEW == VIEW_DIFFUSE {
        return vec4<f32>(finite_or_zero(diffuse), 1.0);
    }
    var specular = vec3<f32>(0.0);
    if HAS_SPECULAR && n_dot_l > 0.0 {
        var cosine = 0.0;
        if MODEL == MODEL_PHONG {
            let r = 2.0 * n_dot_l * normal - l;
            cosine = dot(r, v);
        } else {
            cosine = dot(normal, normalize(l + v));
        }
        specular = frame.intensity.y * ks * spec_pow(cosine, n);
    }
    if VIEW == VIEW_SPECULAR {
        return vec4<f32>(finite_or_zero(specular), 1.0);
    }
    return vec4<f32>(clamp(finite_or_zero(ambient + diffuse + specular), vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
