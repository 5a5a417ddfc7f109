//! `material.wgsl` and `material.glsl`, shipped in every set: a self-contained decode of the
//! set's `n` codes and the `k_a` of eq. (8)/(11) exactly as kapaint computes it (the same
//! generated constants as `shaders/ambient.wgsl`), so an engine can use the set without kapaint.
//!
//! Both snippets are written by one function per part, told the language; only the code that
//! comes from `reflectance::wgsl` differs in more than syntax.

use std::fmt::Write as _;

use super::encoding::NCurve;
use crate::set::manifest::Manifest;
use kapaint_reflectance::wgsl::{
    ShaderLanguage, ambient_glsl, ambient_wgsl_standalone, approx_constant, model_constant,
};

/// The WGSL snippet for a set (`material.wgsl`).
pub fn wgsl(manifest: &Manifest) -> String {
    snippet(manifest, ShaderLanguage::Wgsl)
}

/// The GLSL snippet for a set (`material.glsl`): the same functions as [`wgsl`], for GLSL 4.50
/// or GLSL ES 3.00 without extensions and without a `#version` line, so it can be pasted into
/// any stage: `vec3 kapaint_ka(vec3 kd, vec3 ks, float n)` and `float kapaint_decode_n(float
/// stored)`.
pub fn glsl(manifest: &Manifest) -> String {
    snippet(manifest, ShaderLanguage::Glsl)
}

fn snippet(manifest: &Manifest, lang: ShaderLanguage) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "// kapaint material decode, generated for a {}x{} set (preset {:?}).",
        manifest.width, manifest.height, manifest.preset
    );
    let _ = writeln!(
        s,
        "// Sample each file's components as material.json lists them, decode n with\n\
         // kapaint_decode_n (the value the texture returns in [0, 1]), then\n\
         // k_a = kapaint_ka(k_d, k_s, n). k_d and k_s are linear after the sampler's sRGB\n\
         // decode (use an sRGB texture format for files whose colour_space is \"srgb\").\n"
    );
    match lang {
        ShaderLanguage::Wgsl => s += &ambient_wgsl_standalone(),
        ShaderLanguage::Glsl => s += &ambient_glsl(),
    }
    let model = model_constant(manifest.model);
    let approx = approx_constant(manifest.approximation.name);
    match lang {
        ShaderLanguage::Wgsl => {
            let _ = writeln!(s, "\nconst KAPAINT_MODEL: u32 = {model};");
            let _ = writeln!(s, "const KAPAINT_APPROX: u32 = {approx};\n");
        }
        ShaderLanguage::Glsl => {
            let _ = writeln!(s, "\nconst uint KAPAINT_MODEL = {model};");
            let _ = writeln!(s, "const uint KAPAINT_APPROX = {approx};\n");
        }
    }
    decode_n(&mut s, manifest, lang);
    s += match lang {
        ShaderLanguage::Wgsl => {
            "\nfn kapaint_ka(kd: vec3<f32>, ks: vec3<f32>, n: f32) -> vec3<f32> {\n    \
             return ambient_ka(KAPAINT_MODEL, KAPAINT_APPROX, kd, ks, n);\n}\n"
        }
        ShaderLanguage::Glsl => {
            "\nvec3 kapaint_ka(vec3 kd, vec3 ks, float n) {\n    \
             return ambient_ka(KAPAINT_MODEL, KAPAINT_APPROX, kd, ks, n);\n}\n"
        }
    };
    s
}

/// `kapaint_decode_n` for the set's `n`: constant, on its encoding's curve, or as stored.
fn decode_n(s: &mut String, manifest: &Manifest, lang: ShaderLanguage) {
    // `fn name(x: f32) -> f32` or `float name(float x)`, and `let` or `float` for locals.
    let (float_fn, local): (fn(&str, &str) -> String, &str) = match lang {
        ShaderLanguage::Wgsl => (
            |name: &str, arg: &str| format!("fn {name}({arg}: f32) -> f32"),
            "let",
        ),
        ShaderLanguage::Glsl => (
            |name: &str, arg: &str| format!("float {name}(float {arg})"),
            "float",
        ),
    };
    let decode = float_fn("kapaint_decode_n", "stored");
    match (manifest.n_encoding, manifest.constants.n) {
        (_, Some(n)) => {
            let _ = writeln!(
                s,
                "// n is the same everywhere in this set.\n{decode} {{\n    return {};\n}}",
                lang.float(n)
            );
        }
        (Some(e), None) => {
            let (forward, inverse) = match e.curve {
                NCurve::Linear => ("x", "v"),
                NCurve::Sqrt => ("sqrt(x)", "v * v"),
                NCurve::Log => ("log(1.0 + x)", "exp(v) - 1.0"),
            };
            let _ = writeln!(
                s,
                "// n is stored on a {:?} curve over [{:?}, {:?}] in {} bits.\n\
                 {} {{\n    return {forward};\n}}\n\n\
                 {decode} {{\n    \
                 {local} a = kapaint_n_forward({});\n    \
                 {local} b = kapaint_n_forward({});\n    \
                 {local} v = a + clamp(stored, 0.0, 1.0) * (b - a);\n    \
                 return max({inverse}, 0.0);\n}}",
                e.curve,
                e.lo,
                e.hi,
                e.bits,
                float_fn("kapaint_n_forward", "x"),
                lang.float(e.lo),
                lang.float(e.hi)
            );
        }
        (None, None) => {
            let _ = writeln!(
                s,
                "// n is stored as its own value (float).\n{decode} {{\n    return stored;\n}}"
            );
        }
    }
}
