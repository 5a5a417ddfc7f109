//! `material.wgsl`, shipped in every set: a self-contained decode of the set's `n` codes and
//! the `k_a` of eq. (8)/(11) exactly as kapaint computes it (the same generated constants as
//! `shaders/ambient.wgsl`), so an engine can use the set without kapaint.

use std::fmt::Write as _;

use super::encoding::NCurve;
use super::set::Manifest;
use crate::reflectance::{AmbientApprox, ShadingModel};

/// The WGSL snippet for a set.
pub fn wgsl(manifest: &Manifest) -> String {
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
    s += include_str!("../../shaders/ambient.wgsl");
    let model = match manifest.model {
        ShadingModel::Phong => "MODEL_PHONG",
        ShadingModel::BlinnPhong => "MODEL_BLINN",
    };
    let approx = match manifest.approximation.name.as_str() {
        "paper" => AmbientApprox::PaperPrinted,
        "paper-corrected" => AmbientApprox::PaperCorrected,
        _ => AmbientApprox::Fast,
    };
    let approx = match approx {
        AmbientApprox::PaperPrinted => "APPROX_PAPER_PRINTED",
        AmbientApprox::PaperCorrected => "APPROX_PAPER_CORRECTED",
        AmbientApprox::Fast => "APPROX_FAST",
    };
    let _ = writeln!(s, "\nconst KAPAINT_MODEL: u32 = {model};");
    let _ = writeln!(s, "const KAPAINT_APPROX: u32 = {approx};\n");
    match (manifest.n_encoding, manifest.constants.n) {
        (_, Some(n)) => {
            let _ = writeln!(
                s,
                "// n is the same everywhere in this set.\nfn kapaint_decode_n(stored: f32) -> f32 {{\n    return {n:?}f;\n}}"
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
                 fn kapaint_n_forward(x: f32) -> f32 {{\n    return {forward};\n}}\n\n\
                 fn kapaint_decode_n(stored: f32) -> f32 {{\n    \
                 let a = kapaint_n_forward({:?}f);\n    \
                 let b = kapaint_n_forward({:?}f);\n    \
                 let v = a + clamp(stored, 0.0, 1.0) * (b - a);\n    \
                 return max({inverse}, 0.0);\n}}",
                e.curve, e.lo, e.hi, e.bits, e.lo, e.hi
            );
        }
        (None, None) => {
            s += "// n is stored as its own value (float).\nfn kapaint_decode_n(stored: f32) -> f32 {\n    return stored;\n}\n";
        }
    }
    s += "\nfn kapaint_ka(kd: vec3<f32>, ks: vec3<f32>, n: f32) -> vec3<f32> {\n    \
          return ambient_ka(KAPAINT_MODEL, KAPAINT_APPROX, kd, ks, n);\n}\n";
    s
}
