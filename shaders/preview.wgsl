// kapaint's preview, the entry file: per-fragment shading of the painted maps with the
// paper's hemispherical ambient term, k_a derived here from the sampled k_d, k_s and n
// (never stored):
//
//   I = I_a k_a + I_l [ k_d max(0, N.L) + k_s rho_s ]
//   rho_s = max(0, R.V)^n (Phong) or max(0, N.H)^n (Blinn-Phong), zero where N.L <= 0;
//   for Cook-Torrance, I_l rho_s with rho_s = D G2 F / (4 N.V) and k_s as Fresnel's F0.
//
// Pipeline-overridable constants choose the model, the approximation and the view, and say
// what the scene doesn't need: a uniform map is a uniform value (no texture fetch), k_s == 0
// everywhere drops the specular work, data views skip the lighting. The CPU reference
// renderer (src/render/reference.rs) evaluates the same equation.

#include "ids.wgsl"
#include "ambient.wgsl"
#include "preview_bindings.wgsl"
#include "preview_functions.wgsl"
#include "ambient_view.wgsl"
#include "heat.wgsl"

override MODEL: u32 = 0u;          // MODEL_*
override APPROX: u32 = 2u;         // APPROX_*
override VIEW: u32 = 0u;           // VIEW_*
override KD_UNIFORM: bool = false;
override KS_UNIFORM: bool = false;
override N_UNIFORM: bool = false;
override HAS_SPECULAR: bool = true;
// The material has a tangent-space normal map: the lighting (never k_a) uses its normal.
override NORMAL_MAP: bool = false;

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = frame.view_proj * vec4<f32>(v.position, 1.0);
    out.position = v.position;
    out.normal = v.normal;
    out.tangent = v.tangent;
    // Mesh UVs have v up; texture rows run down.
    out.uv = vec2<f32>(v.uv.x, 1.0 - v.uv.y);
    return out;
}

@fragment
fn fs_main(f: VertexOut) -> @location(0) vec4<f32> {
    var kd = frame.kd;
    if !KD_UNIFORM {
        kd = textureSample(kd_map, map_sampler, f.uv).xyz;
    }
    var ks = frame.ks;
    if !KS_UNIFORM {
        ks = textureSample(ks_map, map_sampler, f.uv).xyz;
    }
    var n = frame.n;
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
    if VIEW == VIEW_KA_VIEW || VIEW == VIEW_KA_VIEW_ERROR {
        // The geometric normal's view angle: like k_a, never the normal map's.
        let to_eye = normalize(frame.eye - f.position);
        let phi = acos(clamp(dot(normalize(f.normal), to_eye), 0.0, 1.0));
        let per_view = finite_or_zero(ambient_ka_view(MODEL, kd, ks, n, phi));
        if VIEW == VIEW_KA_VIEW {
            return vec4<f32>(per_view, 1.0);
        }
        return vec4<f32>(heat_ramp(relative_error(finite_or_zero(ka), per_view) / VIEW_ERROR_TOP), 1.0);
    }
    let ambient = frame.ambient_intensity * ka;
    if VIEW == VIEW_AMBIENT {
        return vec4<f32>(finite_or_zero(ambient), 1.0);
    }

    // k_a is done: from here on the shading normal may come from the normal map.
    var normal = normalize(f.normal);
    if NORMAL_MAP {
        normal = mapped_normal(normal, f.tangent, textureSample(normal_map, map_sampler, f.uv).xyz);
    }
    let l = frame.light;
    let v = normalize(frame.eye - f.position);
    let n_dot_l = dot(normal, l);
    let diffuse = frame.light_intensity * kd * max(0.0, n_dot_l);
    if VIEW == VIEW_DIFFUSE {
        return vec4<f32>(finite_or_zero(diffuse), 1.0);
    }
    var specular = vec3<f32>(0.0);
    if HAS_SPECULAR {
        let lobe = specular_lobe(MODEL, normal, l, v, n);
        specular = frame.light_intensity * (ks * lobe.x + vec3<f32>(lobe.y));
    }
    if VIEW == VIEW_SPECULAR {
        return vec4<f32>(finite_or_zero(specular), 1.0);
    }
    return vec4<f32>(clamp(finite_or_zero(ambient + diffuse + specular), vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
