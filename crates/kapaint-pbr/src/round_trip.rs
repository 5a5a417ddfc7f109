//! The round trip of a stored texel to glTF's 8-bit metallic-roughness values and back, with its
//! error: what the `gltf-pbr` export writes (`kapaint_pbr` converts, the export crate writes) and
//! what the canvas's PBR error view shows.
//!
//! Per texel: the inverse of the project's conversion ([`Conversion::pbr`]: roughness from
//! `n`, `F0 = k_s / height`, metallic and base colour from `k_d` and `F0`), all stored in 8
//! bits (base colour sRGB-encoded).
//!
//! The round-trip error is the import's measure ([`Conversion::error`]) taken against the
//! project's own values: per channel, the box average of the difference between the
//! Cook-Torrance shading of the exported (8-bit) PBR values and the project model's shading
//! of the texel's `k_d`, `k_s`, `n`, over the Cook-Torrance mean. It is the import's error of
//! the exported values plus what the texel drifted on the way (`k_d`, `k_s` and `n` against
//! what the exported values convert back to by the same mapping), added by the triangle
//! inequality: exact where the texel survives the round trip, an upper bound elsewhere.

use glam::Vec3;
use rayon::prelude::*;

use super::DIELECTRIC_F0;
use super::convert::{Conversion, ErrorStats};
use kapaint_model::provenance::{ErrorSummary, NMapping};
use kapaint_model::texel::{Texel, decode_n, linear_to_srgb8, srgb_to_linear};
use kapaint_reflectance::{AmbientApprox, ShadingModel, chi_parts_f32};

/// The exported images' texels and the round-trip error.
pub struct Converted {
    /// Base colour, sRGB-encoded, row-major.
    pub base: Vec<[u8; 3]>,
    /// 255, roughness, metallic (glTF's channels), row-major.
    pub metallic_roughness: Vec<[u8; 3]>,
    /// The round-trip error.
    pub error: ErrorSummary,
}

/// One model's round trip under one mapping, texel by texel: the tables that turn a stored
/// texel into its 8-bit PBR values and their round-trip error (built once per process, model
/// and mapping).
pub struct RoundTrip {
    conversion: &'static Conversion,
    /// Per stored `n` code: its roughness, that roughness' byte, the model's
    /// `[chi_1, chi_0]`, the lobe height and the dielectric's tolerance there.
    n_table: Vec<(f32, u8, [f32; 2], f32, f32)>,
    /// Per roughness byte, the lobe height it converts back with.
    height_of_byte: [f32; 256],
    /// A stored sRGB byte in linear light.
    srgb: [f32; 256],
    /// Per roughness byte, the `[chi_1, chi_0]` of the exponent it reads back as.
    chi_of_byte: [[f32; 2]; 256],
}

impl RoundTrip {
    /// The tables for `model` under `mapping` (built on first use, about 10 ms).
    pub fn for_model(model: ShadingModel, mapping: NMapping) -> &'static Self {
        const MODELS: usize = ShadingModel::ALL.len();
        static TABLES: [std::sync::OnceLock<RoundTrip>; 2 * MODELS] =
            [const { std::sync::OnceLock::new() }; 2 * MODELS];
        // A microfacet model has one mapping: one table, whichever is asked for.
        let fixed = mapping == NMapping::HeightFixed && !model.is_microfacet();
        let k = model.index() + if fixed { MODELS } else { 0 };
        TABLES[k].get_or_init(|| Self::build(model, mapping))
    }

    fn build(model: ShadingModel, mapping: NMapping) -> Self {
        let conversion = Conversion::for_model(model, mapping);
        let approx = AmbientApprox::Fast;
        Self {
            conversion,
            n_table: (0..=u16::MAX)
                .into_par_iter()
                .map(|bits| {
                    let n = decode_n(bits);
                    let r = conversion.roughness(n);
                    (
                        r,
                        (r * 255.0 + 0.5) as u8,
                        chi_parts_f32(model, approx, n),
                        conversion.height(r),
                        conversion.f0_tolerance(r),
                    )
                })
                .collect(),
            height_of_byte: std::array::from_fn(|r| conversion.height(r as f32 / 255.0)),
            srgb: std::array::from_fn(|c| srgb_to_linear(c as f32 / 255.0)),
            chi_of_byte: std::array::from_fn(|r| {
                chi_parts_f32(model, approx, conversion.n(r as f32 / 255.0))
            }),
        }
    }

    /// A stored texel's base colour (sRGB bytes), metallic-roughness bytes (255, roughness,
    /// metallic) and round-trip error (see the module docs).
    pub fn texel(&self, t: &Texel) -> ([u8; 3], [u8; 3], f32) {
        let v = t.decode();
        let (rough, r, chi, height, tolerance) = self.n_table[usize::from(t.n)];
        let p = self
            .conversion
            .pbr_with(v.kd, v.ks, rough, height, tolerance);
        let base = p.base.to_array().map(linear_to_srgb8);
        let mr = [255, r, (p.metallic * 255.0 + 0.5) as u8];
        // The texel as a consumer reads the files, and as this mapping converts that back.
        let (back_base, m) = (
            Vec3::from_array(base.map(|c| self.srgb[usize::from(c)])),
            f32::from(mr[2]) / 255.0,
        );
        let back_kd = back_base * (1.0 - m);
        let back_f0 = Vec3::splat(DIELECTRIC_F0).lerp(back_base, m);
        let rough_back = f32::from(r) / 255.0;
        let back_ks = self
            .conversion
            .ks_at(back_kd, back_f0, self.height_of_byte[usize::from(r)]);
        let chi_back = self.chi_of_byte[usize::from(r)];
        let parts = self.conversion.error_parts(back_kd, back_f0, rough_back);
        let mut worst = 0.0_f32;
        for (c, [numerator, mean]) in parts.into_iter().enumerate() {
            let drift = std::f32::consts::FRAC_2_PI * (v.kd[c] - back_kd[c]).abs()
                + (v.ks[c] - back_ks[c]).abs() * chi[0]
                + back_ks[c] * (chi[0] - chi_back[0]).abs()
                + (chi[1] - chi_back[1]).abs();
            if mean > 0.0 {
                worst = worst.max((numerator + drift) / mean);
            }
        }
        (base, mr, worst)
    }

    /// The round-trip error of one material value: what the texel loses as a glTF PBR
    /// material (the editor's "PBR error" canvas).
    pub fn error(&self, v: kapaint_model::texel::MaterialValue) -> f32 {
        self.texel(&Texel::encode(v)).2
    }
}

/// One chunk's base colours, metallic-roughness texels and error statistics.
type Chunk = (Vec<[u8; 3]>, Vec<[u8; 3]>, ErrorStats);

/// Converts texels (row-major) read in `model`'s terms under `mapping` to 8-bit PBR values,
/// with the round-trip error (see the module docs).
pub fn convert(texels: &[Texel], model: ShadingModel, mapping: NMapping) -> Converted {
    let round_trip = RoundTrip::for_model(model, mapping);
    let texel = |t: &Texel| round_trip.texel(t);
    let chunks: Vec<Chunk> = texels
        .par_chunks(1 << 16)
        .map(|chunk| {
            let mut stats = ErrorStats::new();
            let (mut base, mut mr) = (Vec::with_capacity(chunk.len()), Vec::new());
            mr.reserve(chunk.len());
            for t in chunk {
                let (b, m, e) = texel(t);
                base.push(b);
                mr.push(m);
                stats.add(e);
            }
            (base, mr, stats)
        })
        .collect();
    let mut stats = ErrorStats::new();
    let (mut base, mut metallic_roughness) = (
        Vec::with_capacity(texels.len()),
        Vec::with_capacity(texels.len()),
    );
    for (b, m, s) in chunks {
        base.extend(b);
        metallic_roughness.extend(m);
        stats = stats.merge(&s);
    }
    Converted {
        base,
        metallic_roughness,
        error: stats.summary(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Pbr;
    use kapaint_model::texel::MaterialValue;

    #[test]
    fn the_round_trip_error_is_the_imports_where_the_texel_survives_and_more_where_not() {
        for (model, mapping) in crate::fit::TARGETS
            .into_iter()
            .flat_map(|m| NMapping::ALL.map(|n| (m, n)))
        {
            let c = Conversion::for_model(model, mapping);
            let p = Pbr {
                base: Vec3::new(0.6, 0.3, 0.1),
                metallic: 0.0,
                roughness: 0.3,
            };
            let made = Texel::encode(c.material(p));
            let out = convert(&[made], model, mapping);
            let import = c.error(p);
            // The 8-bit roughness moves the exponent a little (0.5 % for Cook-Torrance here).
            assert!(
                (out.error.max - import).abs() <= 0.01 + 0.02 * import,
                "{model:?} {mapping:?}: {} vs the import's {import}",
                out.error.max
            );
            // An exponent no roughness gives (a mirror for Phong's flat end, or far off the
            // curve) drifts, and the drift is counted.
            let off = Texel::encode(MaterialValue::new(p.base, Vec3::splat(0.04), 0.5));
            let drifted = convert(&[off], model, mapping);
            let honest = c.error_of(p.base, Vec3::splat(0.04), c.roughness(0.5));
            assert!(
                drifted.error.max > honest,
                "{model:?} {mapping:?}: {} vs {honest}",
                drifted.error.max
            );
        }
    }
}
