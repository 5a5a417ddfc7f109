//! glTF's textures as Basis Universal (`KHR_texture_basisu`), for `export --preset gltf-pbr
//! --glb --basisu`: each texture a KTX2 file with a full mip chain, embedded in the `.glb` with
//! no PNG fallback (the extension is then required, as it states for a texture without a
//! `source`). The metallic-roughness and normal textures are UASTC, their levels
//! supercompressed by zstd ([`ZSTD_LEVEL`]); the base colour is ETC1S with BasisLZ (a fraction
//! of UASTC's bytes) where that meets the budget, else UASTC.
//!
//! **What decides the settings.** The preset's budget, measured on the `k_a` the textures
//! give after transcoding: the base colour and metallic-roughness textures as a runtime
//! decodes them (the BC7 transcode, the worse of its two targets) are read back through the
//! conversion `import-pbr` uses, and each texel's `k_a` is compared with the one the lossless
//! values give, in levels of 8-bit sRGB (the budget's p99.9 and mean). Efforts run cheapest in
//! bytes first (UASTC's level and RDO, [`crate::codec::uastc_settings_of`]; ETC1S's quality,
//! [`crate::codec::etc1s::quality_of`], tried for the base colour before UASTC at each) until
//! one is within, or until more effort, at the rate the last step improved, could not reach it
//! (the set's rule); the normal map is UASTC level 3 without RDO ([`NORMAL_EFFORT`]). What this adds comes on top of the
//! round trip's own error, which the manifest reports beside it.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::blocks::Coder;
use crate::codec::etc1s::{Etc1sCodec, Etc1sLevels};
use crate::codec::{Codec, Effort, Uastc};
use crate::file_kind::ColourSpace;
use crate::ktx::{self, Compressed, Space};
use crate::preset::BlockBudget;
use crate::set::perceptual::{SrgbError, SrgbLevels, SrgbStats};
use kapaint_base::task::Progress;
use kapaint_model::provenance::NMapping;
use kapaint_model::texel::srgb_to_linear;
use kapaint_pbr::Pbr;
use kapaint_pbr::convert::Conversion;
use kapaint_reflectance::{AmbientApprox, ShadingModel};

/// The zstd level of the textures' levels (gltf-transform's default for UASTC).
pub const ZSTD_LEVEL: u8 = 18;

/// The normal map's effort: UASTC level 3 without RDO, whatever the search chose for the
/// material. RDO trades a normal's direction for bytes, and on a noisy 1024^2 normal map it
/// was the slower too: 13 to 17 s with RDO (at level 3: the crate's level 1 ran as 3 then),
/// 8.8 s without.
pub const NORMAL_EFFORT: Effort = Effort::Slow;

/// One texture's texels: 8-bit RGB, row major.
#[derive(Clone, Copy)]
pub struct Rgb<'a> {
    /// `width * height * 3` bytes.
    pub texels: &'a [u8],
    /// Size in texels.
    pub size: (u32, u32),
}

/// How the material's `k_a` is computed: the project's model, the mapping its glTF values
/// were made with and its ambient approximation.
#[derive(Clone, Copy, Debug)]
pub struct Reading {
    /// The shading model.
    pub model: ShadingModel,
    /// How roughness and `F0` become `n` and `k_s`.
    pub mapping: NMapping,
    /// The ambient approximation.
    pub approx: AmbientApprox,
}

/// One KTX2 texture in the `.glb`, as the manifest lists it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BasisuTexture {
    /// The glTF image's name (`base_color`, `metallic_roughness`, `normal`).
    pub name: String,
    /// Its blocks: `ETC1S` (BasisLZ) or `UASTC` (with zstd).
    pub codec: String,
    /// Their settings: "quality 128", "level 2, RDO 1.0".
    pub settings: String,
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// Mip levels.
    pub levels: u32,
    /// How its colour is encoded.
    pub colour_space: ColourSpace,
    /// The KTX2 file's bytes.
    pub bytes: u64,
}

/// How the `.glb`'s textures were encoded: the manifest's `basisu`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BasisuReport {
    /// The zstd level of the UASTC files' levels.
    pub zstd_level: u8,
    /// The `k_a` error the transcoded textures add, in levels of 8-bit sRGB.
    pub ka_error_srgb: SrgbError,
    /// Whether that is within the preset's budget (else the best settings were kept).
    pub within_budget: bool,
    /// The textures.
    pub textures: Vec<BasisuTexture>,
}

impl BasisuReport {
    /// In the words the CLI and the editor use: "base_color ETC1S quality 128,
    /// metallic_roughness UASTC level 1, RDO 3.0 (zstd 18): k_a within 0.42 levels of the
    /// lossless textures' for 99.9 % of texels (mean 0.031) after transcoding, within the
    /// budget; 2 KTX2 textures, 123456 bytes".
    pub fn summary(&self) -> String {
        let each: Vec<String> = self
            .textures
            .iter()
            .map(|t| format!("{} {} {}", t.name, t.codec, t.settings))
            .collect();
        format!(
            "{} (zstd {} for UASTC): k_a within {:.2} levels of the lossless textures' for 99.9 % of texels (mean {:.3}) after transcoding, {}; {} KTX2 textures, {} bytes",
            each.join(", "),
            self.zstd_level,
            self.ka_error_srgb.p999,
            self.ka_error_srgb.mean,
            if self.within_budget {
                "within the budget"
            } else {
                "over the budget (the nearest kept: more effort would not reach it)"
            },
            self.textures.len(),
            self.textures.iter().map(|t| t.bytes).sum::<u64>()
        )
    }
}

/// The textures as KTX2 files, and how.
pub struct Encoded {
    /// Base colour, sRGB.
    pub base_color: Vec<u8>,
    /// Metallic-roughness, linear.
    pub metallic_roughness: Vec<u8>,
    /// The normal map, linear, where given.
    pub normal: Option<Vec<u8>>,
    /// What the manifest says.
    pub report: BasisuReport,
}

/// The base colour as the search left it: an ETC1S file made whole (with the mips every
/// texture has), or UASTC's level 0.
enum Base {
    Etc1s(Etc1sLevels),
    Uastc(Compressed),
}

impl Base {
    /// Level 0's RGB as a runtime decodes it.
    fn decoded(&self) -> &[u8] {
        match self {
            Self::Etc1s(f) => f.decoded.first().map_or(&[], Vec::as_slice),
            Self::Uastc(c) => &c.decoded,
        }
    }
}

/// One step of the search: the effort, the base colour, the metallic-roughness level 0, and
/// the `k_a` error they give.
struct Step {
    effort: Effort,
    base: Base,
    mr: Compressed,
    error: SrgbError,
}

/// Whether more effort may still meet `budget`: each measure over its limit, improving by the
/// factor the last step improved it (`before` to `now`), reaches the limit within the `left`
/// steps there are (the set's rule, `set::budget`). A step that bought nothing ends the search.
fn may_reach(before: SrgbError, now: SrgbError, budget: &BlockBudget, left: usize) -> bool {
    let steps = i32::try_from(left).unwrap_or(i32::MAX);
    [
        (before.p999, now.p999, budget.ka_error_srgb_p999),
        (before.mean, now.mean, budget.ka_error_srgb_mean),
    ]
    .into_iter()
    .all(|(before, now, limit)| {
        now <= limit || (before > 0.0 && now < before && now * (now / before).powi(steps) <= limit)
    })
}

fn step(effort: Effort, base: Base, mr: Compressed, error: SrgbError) -> Step {
    Step {
        effort,
        base,
        mr,
        error,
    }
}

/// The cheapest step within `budget`, else the last tried (the best): at each effort, the
/// data in UASTC and the base colour in ETC1S, then (if that misses) in UASTC; the search ends
/// early where more effort, at the rate the last step improved, cannot meet the budget.
fn search(
    (base, mr): (Rgb<'_>, Rgb<'_>),
    reading: Reading,
    budget: &BlockBudget,
    progress: &Progress,
) -> Result<(Step, bool), String> {
    let (base_codec, data_codec) = (Uastc::new(3, true), Uastc::new(3, false));
    let exact = ka_of(base.texels, mr.texels, reading);
    // ETC1S's trials encode the whole file, with the mips every texture has.
    let mips = with_source(base, Space::Srgb, ktx::mips);
    let levels: Vec<((u32, u32), &[u8])> = std::iter::once((base.size, base.texels))
        .chain(mips.iter().map(|(size, t)| (*size, &t[..])))
        .collect();
    let etc1s = Etc1sCodec::new(3, true);
    let mut last: Option<Step> = None;
    // ETC1S is tried while it may still win: once UASTC at the same effort does better, more
    // quality in ETC1S will not overtake UASTC's next step.
    let mut etc1s_alive = true;
    let mut before: Option<SrgbError> = None;
    for (i, effort) in Effort::ALL.into_iter().enumerate() {
        progress.check().map_err(|_| "cancelled".to_string())?;
        let m = level0(&data_codec, effort, mr)?;
        let measure = |b: &Base| ka_error(&exact, &ka_of(b.decoded(), &m.decoded, reading));
        let mut etc1s_error = None;
        if etc1s_alive {
            let etc = Base::Etc1s(etc1s.encode(&levels, effort).map_err(|e| e.to_string())?);
            let error = measure(&etc);
            if error.over(budget) == (false, false) {
                return Ok((step(effort, etc, m, error), true));
            }
            etc1s_error = Some(error);
        }
        let uastc = Base::Uastc(level0(&base_codec, effort, base)?);
        let error = measure(&uastc);
        if error.over(budget) == (false, false) {
            return Ok((step(effort, uastc, m, error), true));
        }
        if etc1s_error.is_some_and(|e| e.p999 > error.p999 && e.mean > error.mean) {
            etc1s_alive = false;
        }
        last = Some(step(effort, uastc, m, error));
        let left = Effort::ALL.len() - i - 1;
        if before.is_some_and(|b| !may_reach(b, error, budget, left)) {
            break;
        }
        before = Some(error);
    }
    Ok((last.ok_or("no effort was tried")?, false))
}

/// The base colour, metallic-roughness and (optional) normal textures as Basis Universal KTX2
/// files, at the cheapest settings whose `k_a` is within `budget` (see the module).
///
/// # Errors
/// The encoder's failure, textures of different sizes, or cancelled (`"cancelled"`).
pub fn encode(
    textures: [Option<Rgb<'_>>; 3],
    reading: Reading,
    budget: &BlockBudget,
    progress: &Progress,
) -> Result<Encoded, String> {
    let [Some(base), Some(mr), normal] = textures else {
        return Err("the base colour and metallic-roughness textures are needed".into());
    };
    if base.size != mr.size || base.texels.len() != mr.texels.len() {
        return Err("the base colour and metallic-roughness textures differ in size".into());
    }
    let (step, within) = search((base, mr), reading, budget, progress)?;
    progress.check().map_err(|_| "cancelled".to_string())?;
    let (base_codec, data_codec) = (Uastc::new(3, true), Uastc::new(3, false));
    let effort = step.effort;
    let uastc_settings = data_codec.effort_name(effort).to_string();
    let (base_file, base_how) = match step.base {
        Base::Etc1s(f) => (
            ktx::etc1s_file(&f.image, true),
            ("ETC1S", format!("quality {}", f.quality)),
        ),
        Base::Uastc(c) => (
            file(&base_codec, effort, base, Space::Srgb, Some(c), progress),
            ("UASTC", uastc_settings.clone()),
        ),
    };
    let mr_file = file(
        &data_codec,
        effort,
        mr,
        Space::Linear,
        Some(step.mr),
        progress,
    )?;
    let normal_file = normal
        .map(|n| file(&data_codec, NORMAL_EFFORT, n, Space::Linear, None, progress))
        .transpose()?;
    let base_file = base_file?;
    let entry = |name: &str, rgb: Rgb<'_>, how: (&str, String), bytes: &[u8]| BasisuTexture {
        name: name.into(),
        codec: how.0.into(),
        settings: how.1,
        width: rgb.size.0,
        height: rgb.size.1,
        levels: ktx::level_count(rgb.size.0, rgb.size.1),
        colour_space: if name == "base_color" {
            ColourSpace::Srgb
        } else {
            ColourSpace::Linear
        },
        bytes: bytes.len() as u64,
    };
    let uastc = || ("UASTC", uastc_settings.clone());
    let mut listed = vec![
        entry("base_color", base, base_how, &base_file),
        entry("metallic_roughness", mr, uastc(), &mr_file),
    ];
    if let (Some(n), Some(bytes)) = (normal, &normal_file) {
        let how = ("UASTC", data_codec.effort_name(NORMAL_EFFORT).to_string());
        listed.push(entry("normal", n, how, bytes));
    }
    Ok(Encoded {
        base_color: base_file,
        metallic_roughness: mr_file,
        normal: normal_file,
        report: BasisuReport {
            zstd_level: ZSTD_LEVEL,
            ka_error_srgb: step.error,
            within_budget: within,
            textures: listed,
        },
    })
}

/// Level 0 of `rgb` encoded by `codec` at `effort`, and decoded as a runtime would.
fn level0(codec: &Uastc, effort: Effort, rgb: Rgb<'_>) -> Result<Compressed, String> {
    ktx::compress_level(
        Coder::Portable,
        (codec, effort),
        rgb.texels,
        rgb.size,
        3,
        None,
    )
    .map_err(|e| e.to_string())
}

/// The KTX2 file of `rgb` (components in `space`) with its full mip chain, level 0 given
/// where the search encoded it, supercompressed by zstd.
fn file(
    codec: &Uastc,
    effort: Effort,
    rgb: Rgb<'_>,
    space: Space,
    level0: Option<Compressed>,
    progress: &Progress,
) -> Result<Vec<u8>, String> {
    let written = with_source(rgb, space, |source| {
        ktx::encode(
            source,
            Some((Coder::Portable, codec, effort)),
            level0,
            progress,
        )
    })
    .map_err(|e| e.to_string())?;
    ktx::supercompress(&written.bytes, ZSTD_LEVEL)
}

/// `f` of `rgb` as the KTX2 writer takes it (components in `space`, averaged for mips in
/// linear light where sRGB).
fn with_source<R>(rgb: Rgb<'_>, space: Space, f: impl FnOnce(&ktx::Source<'_>) -> R) -> R {
    let spaces = [space; 3];
    let value = |i: usize, k: usize| {
        let byte = f32::from(rgb.texels[i * 3 + k]) / 255.0;
        if space == Space::Srgb {
            srgb_to_linear(byte)
        } else {
            byte
        }
    };
    f(&ktx::Source {
        width: rgb.size.0,
        height: rgb.size.1,
        spaces: &spaces,
        level0: rgb.texels,
        value: &value,
    })
}

/// Each texel's `k_a` from glTF's 8-bit base colour (sRGB) and metallic-roughness (G
/// roughness, B metallic), read as `import-pbr` reads them.
fn ka_of(base: &[u8], mr: &[u8], reading: Reading) -> Vec<[f32; 3]> {
    let conversion = Conversion::for_model(reading.model, reading.mapping);
    base.par_chunks_exact(3)
        .zip(mr.par_chunks_exact(3))
        .map(|(b, m)| {
            let pbr = Pbr {
                base: glam::Vec3::new(
                    srgb_to_linear(f32::from(b[0]) / 255.0),
                    srgb_to_linear(f32::from(b[1]) / 255.0),
                    srgb_to_linear(f32::from(b[2]) / 255.0),
                ),
                metallic: f32::from(m[2]) / 255.0,
                roughness: f32::from(m[1]) / 255.0,
            };
            let v = conversion.material(pbr);
            kapaint_reflectance::ka(reading.model, reading.approx, v.kd, v.ks, v.n).to_array()
        })
        .collect()
}

/// The sRGB-level error of `got` against `exact`, texel by texel.
fn ka_error(exact: &[[f32; 3]], got: &[[f32; 3]]) -> SrgbError {
    let levels = SrgbLevels::new();
    exact
        .par_chunks(1 << 14)
        .zip(got.par_chunks(1 << 14))
        .map(|(e, g)| {
            let mut stats = SrgbStats::new();
            for (e, g) in e.iter().zip(g) {
                stats.add(levels.distance(*e, *g));
            }
            stats
        })
        .reduce(SrgbStats::new, |a, b| a.merge(&b))
        .summary()
}
