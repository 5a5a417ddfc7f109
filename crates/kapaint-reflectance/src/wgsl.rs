//! The shader twins of the approximations (WGSL and GLSL), generated from the same constants as
//! the Rust code.
//!
//! `shaders/ambient.wgsl` is the output of [`ambient_wgsl`]; a test fails if the committed file
//! differs, and `cargo run --release --example gen_wgsl` rewrites it. [`ambient_glsl`] is the
//! same code in GLSL, written by the exporter into every set's `material.glsl` (it is not
//! committed, so it cannot go stale). Both share the constant tables below and sanitize their
//! inputs through bit patterns (shader compilers may assume no NaN), so every texel shades to
//! a finite value whatever the maps hold.

use std::fmt::Write as _;

use super::cook_torrance::fast::N_MAX as CT_N_MAX;
use super::cook_torrance::fast_coeffs as ct;
use super::fast_coeffs::{BLINN_OCTAVES, BLINN_TAIL, DEGREE, OCTAVES, PHONG_OCTAVES, PHONG_TAIL};
use super::{
    AmbientApprox, PAPER_TWO_OVER_PI, ShadingModel, TWO_OVER_PI, fast::TAIL_START_X,
    paper_constants,
};

/// A shading language kapaint writes its ambient code in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaderLanguage {
    /// WGSL, as wgpu and naga read it.
    Wgsl,
    /// GLSL 4.50, or GLSL ES 3.00 with high precision; no extensions.
    Glsl,
}

/// The type of a module-scope constant.
#[derive(Clone, Copy)]
enum ConstType {
    F32,
    U32,
    Vec3,
}

impl ShaderLanguage {
    /// `x` as a float literal of the language that parses back to the same bits, in its
    /// shortest decimal form (`2.0`, `3000.0`, `1.0e-7`; WGSL adds the `f` suffix).
    pub fn float(self, x: f32) -> String {
        self.finish_literal(format!("{x:?}"))
    }

    /// `x` in scientific notation (`6.3661975e-1`): the form of the generated tables.
    fn scientific(self, x: f32) -> String {
        self.finish_literal(format!("{x:e}"))
    }

    /// WGSL takes `3e0f` as it is; GLSL gets a fraction in the mantissa (`3.0e0`) so no parser
    /// can read an integer, and no suffix (not every GLSL version has one).
    fn finish_literal(self, text: String) -> String {
        match self {
            Self::Wgsl => format!("{text}f"),
            Self::Glsl => {
                let (mantissa, exponent) = text.split_at(text.find('e').unwrap_or(text.len()));
                if mantissa.contains('.') {
                    text
                } else {
                    format!("{mantissa}.0{exponent}")
                }
            }
        }
    }

    fn type_name(self, ty: ConstType) -> &'static str {
        match (self, ty) {
            (Self::Wgsl, ConstType::F32) => "f32",
            (Self::Wgsl, ConstType::U32) => "u32",
            (Self::Wgsl, ConstType::Vec3) => "vec3<f32>",
            (Self::Glsl, ConstType::F32) => "float",
            (Self::Glsl, ConstType::U32) => "uint",
            (Self::Glsl, ConstType::Vec3) => "vec3",
        }
    }

    /// A module-scope constant declaration, without a line break.
    fn constant(self, name: &str, ty: ConstType, value: &str) -> String {
        let ty = self.type_name(ty);
        match self {
            Self::Wgsl => format!("const {name}: {ty} = {value};"),
            Self::Glsl => format!("const {ty} {name} = {value};"),
        }
    }

    fn vec3(self, v: [f32; 3]) -> String {
        let [x, y, z] = v.map(|c| self.scientific(c));
        format!("{}({x}, {y}, {z})", self.type_name(ConstType::Vec3))
    }

    /// A constant table of floats indexed at run time (WGSL wants a private variable for
    /// that).
    fn table(self, name: &str, values: &[f32]) -> String {
        let count = values.len();
        let values: Vec<String> = values.iter().map(|&c| self.scientific(c)).collect();
        let values = values.join(",\n    ");
        match self {
            Self::Wgsl => format!(
                "var<private> {name}: array<f32, {count}> = array<f32, {count}>(\n    {values}\n);"
            ),
            Self::Glsl => {
                format!("const float {name}[{count}] = float[{count}](\n    {values}\n);")
            }
        }
    }
}

fn fast_table(
    out: &mut String,
    lang: ShaderLanguage,
    name: &str,
    rows: &[[f32; DEGREE + 1]; OCTAVES],
    tail: [f32; 3],
) {
    let values: Vec<f32> = rows.iter().flatten().copied().collect();
    let _ = writeln!(out, "{}", lang.table(&format!("{name}_FAST"), &values));
    let _ = writeln!(
        out,
        "{}\n",
        lang.constant(&format!("{name}_TAIL"), ConstType::Vec3, &lang.vec3(tail))
    );
}

/// The file of shader ids (`MODEL_*`, `APPROX_*`, `VIEW_*`) that shaders include; it is
/// generated from the Rust enums, never written by hand.
pub const IDS_FILE: &str = "ids.wgsl";

/// `NameLikeThis` as `NAME_LIKE_THIS`.
pub fn screaming_snake(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_uppercase());
    }
    out.replace('-', "_")
}

/// A value's shader id: its index in `all`, the enum's list in a fixed order.
pub fn shader_id<T: PartialEq>(all: &[T], value: &T) -> u32 {
    all.iter().position(|v| v == value).unwrap_or(0) as u32
}

/// The shader constant that names a shading model: `MODEL_` and its file name.
pub fn model_constant(model: ShadingModel) -> String {
    format!("MODEL_{}", screaming_snake(model.name()))
}

/// The shader constant that names an approximation: `APPROX_` and its variant name.
pub fn approx_constant(approx: AmbientApprox) -> String {
    format!("APPROX_{}", screaming_snake(&format!("{approx:?}")))
}

/// Every model's and approximation's shader constant with its id, from the enums.
pub fn model_and_approx_ids() -> Vec<(String, u32)> {
    let models = ShadingModel::ALL
        .iter()
        .map(|m| (model_constant(*m), shader_id(&ShadingModel::ALL, m)));
    let approxes = AmbientApprox::ALL
        .iter()
        .map(|a| (approx_constant(*a), shader_id(&AmbientApprox::ALL, a)));
    models.chain(approxes).collect()
}

/// [`ambient_wgsl`] with the ids written out instead of included: WGSL that stands alone,
/// for the exported `material.wgsl`.
pub fn ambient_wgsl_standalone() -> String {
    ambient_wgsl_with(false)
}

/// The constants and `Fast` tables both languages start with; the model and approximation
/// ids written out, or (`include_ids`, WGSL for the renderer) included from [`IDS_FILE`],
/// which the renderer's shaders share.
fn constants(out: &mut String, lang: ShaderLanguage, include_ids: bool) {
    use ConstType::{F32, U32};
    if include_ids {
        let _ = writeln!(out, "#include \"{IDS_FILE}\"");
    } else {
        for (name, value) in model_and_approx_ids() {
            let _ = writeln!(out, "{}", lang.constant(&name, U32, &format!("{value}u")));
        }
    }
    out.push('\n');
    // f32::MAX as the shaders have always spelt it (nine digits; it rounds to the same bits).
    let max = lang.finish_literal("3.40282347e38".to_owned());
    for (name, ty, value) in [
        ("TWO_OVER_PI", F32, lang.scientific(TWO_OVER_PI as f32)),
        (
            "PAPER_TWO_OVER_PI",
            F32,
            lang.scientific(PAPER_TWO_OVER_PI as f32),
        ),
        ("FAST_DEGREE", U32, format!("{DEGREE}u")),
        ("FAST_TAIL_START_X", F32, lang.scientific(TAIL_START_X)),
        ("CT_DEGREE", U32, format!("{}u", ct::DEGREE)),
        ("CT_N_MAX", F32, lang.scientific(CT_N_MAX)),
        ("F32_MAX", F32, max),
    ] {
        let _ = writeln!(out, "{}", lang.constant(name, ty, &value));
    }
    out.push('\n');
    for model in ShadingModel::PAPER {
        for approx in [AmbientApprox::PaperPrinted, AmbientApprox::PaperCorrected] {
            let Some((a, b, c)) = paper_constants(model, approx) else {
                continue;
            };
            let name = format!(
                "{}_{}",
                model.name().to_uppercase(),
                approx.name().to_uppercase().replace('-', "_")
            );
            let value = lang.vec3([a as f32, b as f32, c as f32]);
            let _ = writeln!(out, "{}", lang.constant(&name, ConstType::Vec3, &value));
        }
    }
    out.push('\n');
    fast_table(out, lang, "PHONG", &PHONG_OCTAVES, PHONG_TAIL);
    fast_table(out, lang, "BLINN", &BLINN_OCTAVES, BLINN_TAIL);
    // Cook-Torrance: per octave and power of s, chi_1 and chi_0 side by side.
    let pairs: Vec<f32> = ct::CHI_OCTAVES
        .iter()
        .flatten()
        .flatten()
        .copied()
        .collect();
    let _ = writeln!(out, "{}\n", lang.table("CT_FAST", &pairs));
}

/// The WGSL source of `shaders/ambient.wgsl`.
pub fn ambient_wgsl() -> String {
    ambient_wgsl_with(true)
}

/// The WGSL of `k_a`, its ids included from [`IDS_FILE`] or written out.
fn ambient_wgsl_with(include_ids: bool) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// Generated by kapaint (src/reflectance/wgsl.rs) from src/reflectance/fast_coeffs.rs.\n\
         // Do not edit: run `cargo run --release --example gen_wgsl`.\n\
         //\n\
         // k_a = (2/pi) k_d + k_s chi(n): eq. (6) of the paper, with chi by eq. (8)/(11) as\n\
         // printed, with the corrected Blinn exponent, or by kapaint's Fast approximation;\n\
         // k_a = (2/pi) k_d + k_s chi_1(n) + chi_0(n) for Cook-Torrance (GGX).\n"
    );
    constants(&mut out, ShaderLanguage::Wgsl, include_ids);
    out.push_str(BODY_WGSL);
    out
}

/// The GLSL twin of [`ambient_wgsl`]: the same constants and functions, line for line, for
/// GLSL 4.50 or GLSL ES 3.00 (it declares high precision; `floatBitsToUint` needs 3.30 / ES
/// 3.00). No `#version` line, so it can be pasted into any shader stage.
pub fn ambient_glsl() -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// Generated by kapaint (src/reflectance/wgsl.rs) from src/reflectance/fast_coeffs.rs,\n\
         // the GLSL twin of shaders/ambient.wgsl. GLSL 4.50 or GLSL ES 3.00, no extensions.\n\
         //\n\
         // k_a = (2/pi) k_d + k_s chi(n): eq. (6) of the paper, with chi by eq. (8)/(11) as\n\
         // printed, with the corrected Blinn exponent, or by kapaint's Fast approximation;\n\
         // k_a = (2/pi) k_d + k_s chi_1(n) + chi_0(n) for Cook-Torrance (GGX).\n\n\
         // The bit tricks and the tables need 32-bit floats and ints (a no-op on desktop GL).\n\
         precision highp float;\nprecision highp int;\n"
    );
    constants(&mut out, ShaderLanguage::Glsl, false);
    out.push_str(BODY_GLSL);
    out
}

const BODY_WGSL: &str = r"// NaN and negative n -> 0, +inf -> the largest float; decided on the bits, since a
// compiler may assume floats are never NaN.
fn sanitize_n(n: f32) -> f32 {
    let bits = bitcast<u32>(n);
    let magnitude = bits & 0x7fffffffu;
    if magnitude > 0x7f800000u || (bits & 0x80000000u) != 0u {
        return 0.0;
    }
    if magnitude == 0x7f800000u {
        return F32_MAX;
    }
    return n;
}

// k_d and k_s components: NaN -> 0, then clamped into [0, 1].
fn sanitize_k(k: vec3<f32>) -> vec3<f32> {
    let bits = bitcast<vec3<u32>>(k) & vec3<u32>(0x7fffffffu);
    let finite_or_inf = bits <= vec3<u32>(0x7f800000u);
    return clamp(select(vec3<f32>(0.0), k, finite_or_inf), vec3<f32>(0.0), vec3<f32>(1.0));
}

fn chi_fast(model: u32, n: f32) -> f32 {
    let x = n + 1.0;
    if x >= FAST_TAIL_START_X {
        var tail = PHONG_TAIL;
        if model == MODEL_BLINN {
            tail = BLINN_TAIL;
        }
        return (tail.x * log(x) + tail.y + tail.z * inverseSqrt(x)) / x;
    }
    let bits = bitcast<u32>(x);
    let octave = (bits >> 23u) - 127u;
    let s = 2.0 * bitcast<f32>((bits & 0x007fffffu) | 0x3f800000u) - 3.0;
    let base = octave * (FAST_DEGREE + 1u);
    var g = 0.0;
    for (var k = 0u; k <= FAST_DEGREE; k++) {
        let index = base + FAST_DEGREE - k;
        var c = PHONG_FAST[index];
        if model == MODEL_BLINN {
            c = BLINN_FAST[index];
        }
        g = g * s + c;
    }
    return g / x;
}

// [chi_1(n), chi_0(n)] of Cook-Torrance for a sanitized n: a vec2 Horner chain per octave.
fn chi_cook_torrance(n: f32) -> vec2<f32> {
    let x = min(n, CT_N_MAX) + 1.0;
    let bits = bitcast<u32>(x);
    let octave = (bits >> 23u) - 127u;
    let s = 2.0 * bitcast<f32>((bits & 0x007fffffu) | 0x3f800000u) - 3.0;
    let base = octave * (CT_DEGREE + 1u);
    var g = vec2<f32>(0.0);
    for (var k = 0u; k <= CT_DEGREE; k++) {
        let index = 2u * (base + CT_DEGREE - k);
        g = g * s + vec2<f32>(CT_FAST[index], CT_FAST[index + 1u]);
    }
    return g;
}

fn paper_constants(model: u32, approx: u32) -> vec3<f32> {
    if model == MODEL_PHONG {
        if approx == APPROX_PAPER_CORRECTED {
            return PHONG_PAPER_CORRECTED;
        }
        return PHONG_PAPER;
    }
    if approx == APPROX_PAPER_CORRECTED {
        return BLINN_PAPER_CORRECTED;
    }
    return BLINN_PAPER;
}

// chi(n), the specular part of k_a per unit k_s (chi_1 for Cook-Torrance).
fn chi(model: u32, approx: u32, n_raw: f32) -> f32 {
    let n = sanitize_n(n_raw);
    if model == MODEL_COOK_TORRANCE {
        return chi_cook_torrance(n).x;
    }
    if approx == APPROX_FAST {
        return chi_fast(model, n);
    }
    // Eq. (8) / (11): a (n + b)^c.
    let abc = paper_constants(model, approx);
    return abc.x * pow(n + abc.y, abc.z);
}

// k_a = (2/pi) k_d + k_s chi(n) (eq. 6; 0.637 for the paper's forms), and
// (2/pi) k_d + k_s chi_1(n) + chi_0(n) for Cook-Torrance (which has no paper form).
fn ambient_ka(model: u32, approx: u32, kd: vec3<f32>, ks: vec3<f32>, n: f32) -> vec3<f32> {
    if model == MODEL_COOK_TORRANCE {
        let parts = chi_cook_torrance(sanitize_n(n));
        return TWO_OVER_PI * sanitize_k(kd) + sanitize_k(ks) * parts.x + parts.y;
    }
    var diffuse = TWO_OVER_PI;
    if approx != APPROX_FAST {
        diffuse = PAPER_TWO_OVER_PI;
    }
    return diffuse * sanitize_k(kd) + sanitize_k(ks) * chi(model, approx, n);
}
";

/// The functions of [`BODY_WGSL`] in GLSL, in the same order (GLSL declares before use).
const BODY_GLSL: &str = r"// NaN and negative n -> 0, +inf -> the largest float; decided on the bits, since a
// compiler may assume floats are never NaN.
float sanitize_n(float n) {
    uint bits = floatBitsToUint(n);
    uint magnitude = bits & 0x7fffffffu;
    if (magnitude > 0x7f800000u || (bits & 0x80000000u) != 0u) {
        return 0.0;
    }
    if (magnitude == 0x7f800000u) {
        return F32_MAX;
    }
    return n;
}

// k_d and k_s components: NaN -> 0, then clamped into [0, 1].
vec3 sanitize_k(vec3 k) {
    uvec3 bits = floatBitsToUint(k) & uvec3(0x7fffffffu);
    bvec3 finite_or_inf = lessThanEqual(bits, uvec3(0x7f800000u));
    return clamp(mix(vec3(0.0), k, finite_or_inf), vec3(0.0), vec3(1.0));
}

float chi_fast(uint model, float n) {
    float x = n + 1.0;
    if (x >= FAST_TAIL_START_X) {
        vec3 tail = PHONG_TAIL;
        if (model == MODEL_BLINN) {
            tail = BLINN_TAIL;
        }
        return (tail.x * log(x) + tail.y + tail.z * inversesqrt(x)) / x;
    }
    uint bits = floatBitsToUint(x);
    uint octave = (bits >> 23u) - 127u;
    float s = 2.0 * uintBitsToFloat((bits & 0x007fffffu) | 0x3f800000u) - 3.0;
    uint base = octave * (FAST_DEGREE + 1u);
    float g = 0.0;
    for (uint k = 0u; k <= FAST_DEGREE; k++) {
        uint index = base + FAST_DEGREE - k;
        float c = PHONG_FAST[index];
        if (model == MODEL_BLINN) {
            c = BLINN_FAST[index];
        }
        g = g * s + c;
    }
    return g / x;
}

// [chi_1(n), chi_0(n)] of Cook-Torrance for a sanitized n: a vec2 Horner chain per octave.
vec2 chi_cook_torrance(float n) {
    float x = min(n, CT_N_MAX) + 1.0;
    uint bits = floatBitsToUint(x);
    uint octave = (bits >> 23u) - 127u;
    float s = 2.0 * uintBitsToFloat((bits & 0x007fffffu) | 0x3f800000u) - 3.0;
    uint base = octave * (CT_DEGREE + 1u);
    vec2 g = vec2(0.0);
    for (uint k = 0u; k <= CT_DEGREE; k++) {
        uint index = 2u * (base + CT_DEGREE - k);
        g = g * s + vec2(CT_FAST[index], CT_FAST[index + 1u]);
    }
    return g;
}

vec3 paper_constants(uint model, uint approx) {
    if (model == MODEL_PHONG) {
        if (approx == APPROX_PAPER_CORRECTED) {
            return PHONG_PAPER_CORRECTED;
        }
        return PHONG_PAPER;
    }
    if (approx == APPROX_PAPER_CORRECTED) {
        return BLINN_PAPER_CORRECTED;
    }
    return BLINN_PAPER;
}

// chi(n), the specular part of k_a per unit k_s (chi_1 for Cook-Torrance).
float chi(uint model, uint approx, float n_raw) {
    float n = sanitize_n(n_raw);
    if (model == MODEL_COOK_TORRANCE) {
        return chi_cook_torrance(n).x;
    }
    if (approx == APPROX_FAST) {
        return chi_fast(model, n);
    }
    // Eq. (8) / (11): a (n + b)^c.
    vec3 abc = paper_constants(model, approx);
    return abc.x * pow(n + abc.y, abc.z);
}

// k_a = (2/pi) k_d + k_s chi(n) (eq. 6; 0.637 for the paper's forms), and
// (2/pi) k_d + k_s chi_1(n) + chi_0(n) for Cook-Torrance (which has no paper form).
vec3 ambient_ka(uint model, uint approx, vec3 kd, vec3 ks, float n) {
    if (model == MODEL_COOK_TORRANCE) {
        vec2 parts = chi_cook_torrance(sanitize_n(n));
        return TWO_OVER_PI * sanitize_k(kd) + sanitize_k(ks) * parts.x + parts.y;
    }
    float diffuse = TWO_OVER_PI;
    if (approx != APPROX_FAST) {
        diffuse = PAPER_TWO_OVER_PI;
    }
    return diffuse * sanitize_k(kd) + sanitize_k(ks) * chi(model, approx, n);
}
";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn committed_shader_is_generated_from_the_rust_constants() {
        let committed = include_str!("../../../shaders/ambient.wgsl");
        assert!(
            committed == ambient_wgsl(),
            "shaders/ambient.wgsl is stale: run `cargo run --release --example gen_wgsl`"
        );
    }

    #[test]
    fn literals_round_trip() {
        for x in [
            0.637_f32,
            TWO_OVER_PI as f32,
            -0.858,
            1.0e-7,
            32768.0,
            3.0,
            f32::MAX,
        ] {
            for lang in [ShaderLanguage::Wgsl, ShaderLanguage::Glsl] {
                for text in [lang.float(x), lang.scientific(x)] {
                    let parsed: f32 = text.trim_end_matches('f').parse().unwrap_or(f32::NAN);
                    assert_eq!(parsed.to_bits(), x.to_bits(), "{text}");
                    // GLSL literals always carry a fraction and never a suffix.
                    if lang == ShaderLanguage::Glsl {
                        assert!(text.contains('.') && !text.ends_with('f'), "{text}");
                    }
                }
            }
        }
    }

    /// The names a module declares: functions, and module-scope constants and variables
    /// (WGSL keeps its run-time indexed tables in private variables, GLSL in constants).
    fn declared_names(module: &naga::Module) -> Vec<String> {
        let mut names: Vec<String> = module
            .functions
            .iter()
            .filter_map(|(_, f)| f.name.clone())
            .chain(module.constants.iter().filter_map(|(_, c)| c.name.clone()))
            .chain(
                module
                    .global_variables
                    .iter()
                    .filter_map(|(_, v)| v.name.clone()),
            )
            .collect();
        names.sort();
        names
    }

    #[test]
    fn glsl_twin_validates_and_declares_what_the_wgsl_does() {
        let wgsl = naga::front::wgsl::parse_str(&ambient_wgsl_standalone()).expect("WGSL parses");
        // GLSL needs an entry point: an empty compute one.
        let source = format!(
            "#version 450\n{}\nlayout(local_size_x = 1) in;\nvoid main() {{}}\n",
            ambient_glsl()
        );
        let glsl = naga::front::glsl::Frontend::default()
            .parse(&naga::ShaderStage::Compute.into(), &source)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&glsl)
        .unwrap_or_else(|e| panic!("{e:?}"));
        let names = declared_names(&wgsl);
        assert!(names.len() > 20, "{names:?}");
        // naga keeps GLSL's `main` as a function too.
        let mut glsl_names = declared_names(&glsl);
        glsl_names.retain(|n| n != "main");
        assert_eq!(glsl_names, names);
    }
}
