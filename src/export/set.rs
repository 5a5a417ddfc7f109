//! Writing and reading texture sets: images plus `material.json`.
//!
//! A set is written into a temporary folder beside the target and renamed into place at the
//! end, so a half-written set is never left where the target should be.

use std::path::{Path, PathBuf};

use glam::Vec3;
use image::ExtendedColorType as C;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::encoding::{KaError, NEncoding, rank_encodings};
use super::preset::{ExportPreset, Format, Layout};
use crate::mesh::bake::Coverage;
use crate::model::texel::{
    MaterialValue, Texel, decode_n, decode_unorm, linear_to_srgb, srgb_to_linear,
};
use crate::model::tile::Plane;
use crate::model::{Document, DocumentSettings, MaterialMaps};
use crate::reflectance::{self, AmbientApprox, ShadingModel};
use crate::task::Progress;

/// Manifest format name and version.
pub const MANIFEST_FORMAT: &str = "kapaint-material";
/// Manifest version written.
pub const MANIFEST_VERSION: u32 = 1;

/// One image of a set.
///
/// Read from a manifest only through its checks (`FileEntryFile`): a plain file name in
/// the set's folder whose extension matches the compression, one to four known components,
/// a known colour space, and a bit depth the format has.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "FileEntryFile")]
pub struct FileEntry {
    /// File name inside the set's folder.
    pub path: String,
    /// What each component holds, in order: `kd.r`, `kd.g`, `kd.b`, `ks` (monochrome), `ks.r`,
    /// ..., `n`, `ka.r`, ...
    pub layout: Vec<String>,
    /// `srgb` (colour components of 8-bit PNGs) or `linear`.
    pub colour_space: String,
    /// Bits per component (8, 16, or 32 for float EXR).
    pub bit_depth: u32,
    /// `png` (deflate) or `exr`.
    pub compression: String,
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// File size.
    pub bytes: u64,
    /// Mip levels (KTX2 files hold a full chain; images have one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mip_levels: Option<u32>,
    /// For block-compressed files: PSNR (dB) per component of the decoded level 0 against
    /// the same components uncompressed; `null` where a component is exact.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub psnr: Option<Vec<Option<f64>>>,
}

/// A file entry as a manifest spells it, before it is checked.
#[derive(Deserialize)]
struct FileEntryFile {
    path: String,
    layout: Vec<String>,
    colour_space: String,
    bit_depth: u32,
    compression: String,
    width: u32,
    height: u32,
    bytes: u64,
    #[serde(default)]
    mip_levels: Option<u32>,
    #[serde(default)]
    psnr: Option<Vec<Option<f64>>>,
}

/// The compressions a set's files can have, with their extension and bit depths.
const COMPRESSIONS: [(&str, &str, &[u32]); 6] = [
    ("png", "png", &[8, 16]),
    ("exr", "exr", &[32]),
    ("ktx2", "ktx2", &[8]),
    ("ktx2-bc4", "ktx2", &[8]),
    ("ktx2-bc5", "ktx2", &[8]),
    ("ktx2-bc7", "ktx2", &[8]),
];

impl TryFrom<FileEntryFile> for FileEntry {
    type Error = String;

    fn try_from(f: FileEntryFile) -> Result<Self, String> {
        let name = &f.path;
        crate::model::check::bounded_text("a file name", name, 255)?;
        if name.is_empty() || name.contains(['/', '\\', ':']) || name.starts_with('.') {
            return Err(format!(
                "file name {name:?} must be a plain name inside the set's folder"
            ));
        }
        let (_, ext, depths) = COMPRESSIONS
            .iter()
            .find(|(c, _, _)| *c == f.compression)
            .ok_or_else(|| {
                format!(
                    "{name}: unknown compression {:?} (known: png, exr, ktx2, ktx2-bc4, ktx2-bc5, ktx2-bc7)",
                    f.compression
                )
            })?;
        if !Path::new(name)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
        {
            return Err(format!(
                "{name}: a {} file must end in .{ext}",
                f.compression
            ));
        }
        if !depths.contains(&f.bit_depth) {
            return Err(format!(
                "{name}: bit_depth {} is not one a {} file has ({depths:?})",
                f.bit_depth, f.compression
            ));
        }
        if !matches!(f.colour_space.as_str(), "srgb" | "linear") {
            return Err(format!(
                "{name}: colour_space must be srgb or linear, got {:?}",
                f.colour_space
            ));
        }
        if f.layout.is_empty() || f.layout.len() > 4 {
            return Err(format!(
                "{name}: layout must list 1 to 4 components, got {}",
                f.layout.len()
            ));
        }
        let mut seen = Vec::new();
        for c in &f.layout {
            let comp = Comp::parse(c).ok_or_else(|| format!("{name}: unknown component {c:?}"))?;
            if seen.contains(&comp) {
                return Err(format!("{name}: component {c:?} is listed twice"));
            }
            seen.push(comp);
        }
        Ok(Self {
            path: f.path,
            layout: f.layout,
            colour_space: f.colour_space,
            bit_depth: f.bit_depth,
            compression: f.compression,
            width: f.width,
            height: f.height,
            bytes: f.bytes,
            mip_levels: f.mip_levels,
            psnr: f.psnr,
        })
    }
}

/// Channels that are one value everywhere: stored here, not as images.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ConstantsFile")]
pub struct Constants {
    /// `k_d` (linear), if constant.
    pub kd: Option<[f32; 3]>,
    /// `k_s` (linear), if constant.
    pub ks: Option<[f32; 3]>,
    /// `n`, if constant.
    pub n: Option<f32>,
}

/// Constants as a manifest spells them, before their ranges are checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConstantsFile {
    kd: Option<[f32; 3]>,
    ks: Option<[f32; 3]>,
    n: Option<f32>,
}

impl TryFrom<ConstantsFile> for Constants {
    type Error = String;

    fn try_from(f: ConstantsFile) -> Result<Self, String> {
        use crate::model::check::{all_in_range, in_range};
        Ok(Self {
            kd: f
                .kd
                .map(|v| all_in_range("constants.kd", v, 0.0, 1.0))
                .transpose()?,
            ks: f
                .ks
                .map(|v| all_in_range("constants.ks", v, 0.0, 1.0))
                .transpose()?,
            n: f.n
                .map(|v| in_range("constants.n", v, 0.0, crate::model::texel::N_MAX))
                .transpose()?,
        })
    }
}

/// How to recompute `k_a` as kapaint does.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ApproximationFile")]
pub struct Approximation {
    /// `fast`, `paper` or `paper-corrected`.
    pub name: String,
    /// The factor of `k_d` in `k_a` (2/pi, or the paper's 0.637).
    pub diffuse_factor: f64,
    /// For the paper's forms: `chi(n) = a (n + b)^c`.
    pub paper_constants: Option<[f64; 3]>,
}

/// An approximation as a manifest spells it, before its name is checked.
#[derive(Deserialize)]
struct ApproximationFile {
    name: String,
    diffuse_factor: f64,
    paper_constants: Option<[f64; 3]>,
}

impl TryFrom<ApproximationFile> for Approximation {
    type Error = String;

    fn try_from(f: ApproximationFile) -> Result<Self, String> {
        Approximation::of_name(&f.name)?;
        Ok(Self {
            name: f.name,
            diffuse_factor: f.diffuse_factor,
            paper_constants: f.paper_constants,
        })
    }
}

impl Approximation {
    /// The approximation this entry names.
    ///
    /// # Errors
    /// A name kapaint does not know.
    pub fn of_name(name: &str) -> Result<AmbientApprox, String> {
        AmbientApprox::ALL
            .into_iter()
            .find(|a| a.name() == name)
            .ok_or_else(|| {
                format!(
                    "approximation {name:?} is not one kapaint knows (known: {})",
                    AmbientApprox::ALL.map(AmbientApprox::name).join(", ")
                )
            })
    }
}

/// Bytes of the set against the alternatives.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MemoryReport {
    /// The exported files.
    pub exported: u64,
    /// The same maps stored naively: `k_a`, `k_d`, `k_s` RGB and `n`, uncompressed, at the
    /// set's depth.
    pub naive: u64,
    /// The project's uncompressed maps (14 bytes per texel).
    pub project: u64,
}

/// `material.json`.
///
/// Read only through its checks (`ManifestFile`): a known format and version, a size in
/// range, files of that size, and every channel either a constant or in a file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ManifestFile")]
pub struct Manifest {
    /// Always [`MANIFEST_FORMAT`].
    pub format: String,
    /// [`MANIFEST_VERSION`].
    pub version: u32,
    /// Map size.
    pub width: u32,
    /// Map size.
    pub height: u32,
    /// Shading model.
    pub model: ShadingModel,
    /// How `k_a` is computed.
    pub approximation: Approximation,
    /// Constant channels.
    pub constants: Constants,
    /// How stored `n` codes decode (absent when `n` is constant or stored as float).
    pub n_encoding: Option<NEncoding>,
    /// The images.
    pub files: Vec<FileEntry>,
    /// Relative `k_a` error of the set (decoded as a consumer would) against the project.
    pub ka_error: KaError,
    /// Texels outside the mesh's UV islands were filled from the nearest island.
    #[serde(default)]
    pub dilated: bool,
    /// Sizes.
    pub bytes: MemoryReport,
    /// The preset used.
    pub preset: String,
}

/// A manifest as a file spells it, before the checks that span its fields.
#[derive(Deserialize)]
struct ManifestFile {
    format: String,
    version: u32,
    width: u32,
    height: u32,
    model: ShadingModel,
    approximation: Approximation,
    constants: Constants,
    n_encoding: Option<NEncoding>,
    files: Vec<FileEntry>,
    ka_error: KaError,
    #[serde(default)]
    dilated: bool,
    bytes: MemoryReport,
    preset: String,
}

impl TryFrom<ManifestFile> for Manifest {
    type Error = String;

    fn try_from(f: ManifestFile) -> Result<Self, String> {
        if f.format != MANIFEST_FORMAT || f.version != MANIFEST_VERSION {
            return Err(format!(
                "format {:?} version {} is not one this kapaint reads ({MANIFEST_FORMAT:?} version {MANIFEST_VERSION})",
                f.format, f.version
            ));
        }
        let (w, h) = (f.width, f.height);
        let max = crate::model::maps::MAX_SIDE;
        if w == 0 || h == 0 || w > max || h > max {
            return Err(format!("size {w}x{h} is outside 1..={max}"));
        }
        crate::model::check::bounded_text(
            "preset",
            &f.preset,
            crate::model::check::MAX_NAME_BYTES,
        )?;
        let mut names: Vec<&str> = Vec::new();
        let mut comps: Vec<Comp> = Vec::new();
        for file in &f.files {
            if (file.width, file.height) != (w, h) {
                return Err(format!(
                    "{} is listed as {}x{}, the set is {w}x{h}",
                    file.path, file.width, file.height
                ));
            }
            if names.iter().any(|n| n.eq_ignore_ascii_case(&file.path)) {
                return Err(format!("{} is listed twice", file.path));
            }
            names.push(&file.path);
            for c in file.layout.iter().filter_map(|c| Comp::parse(c)) {
                if c == Comp::N
                    && file.compression != "exr"
                    && f.n_encoding
                        .is_none_or(|e| u32::from(e.bits) > file.bit_depth)
                {
                    return Err(format!(
                        "{} holds n in {}-bit codes, but n_encoding does not say how to decode them",
                        file.path, file.bit_depth
                    ));
                }
                comps.push(c);
            }
        }
        let has = |c: Comp| comps.contains(&c);
        let kd = (0..3).all(|c| has(Comp::Kd(c)));
        let ks = has(Comp::Ks(3)) || (0..3).all(|c| has(Comp::Ks(c)));
        for (name, constant, stored) in [
            ("k_d", f.constants.kd.is_some(), kd),
            ("k_s", f.constants.ks.is_some(), ks),
            ("n", f.constants.n.is_some(), has(Comp::N)),
        ] {
            if !constant && !stored {
                return Err(format!(
                    "{name} is neither a constant nor stored in any file"
                ));
            }
        }
        Ok(Self {
            format: f.format,
            version: f.version,
            width: w,
            height: h,
            model: f.model,
            approximation: f.approximation,
            constants: f.constants,
            n_encoding: f.n_encoding,
            files: f.files,
            ka_error: f.ka_error,
            dilated: f.dilated,
            bytes: f.bytes,
            preset: f.preset,
        })
    }
}

/// Why an export or import failed.
#[derive(Debug, thiserror::Error)]
pub enum SetError {
    /// A file could not be written or read.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// The set is malformed.
    #[error("{path}: {reason}")]
    Invalid {
        /// The manifest or image.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The target cannot take a set (a file, or a folder that is not empty).
    #[error("{path}: {reason}")]
    Target {
        /// The target.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// Cancelled through its [`Progress`]; nothing was left at the target.
    #[error("export cancelled")]
    Cancelled,
}

fn io(path: &Path, e: impl std::fmt::Display) -> SetError {
    SetError::Io {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

/// Whether `k_s` is grey everywhere.
fn ks_monochrome(maps: &MaterialMaps) -> bool {
    (0..maps.tile_count())
        .into_par_iter()
        .all(|id| match &maps.tile(id).ks {
            Plane::Uniform(v) => v[0] == v[1] && v[1] == v[2],
            Plane::Data(d) => d.iter().all(|v| v[0] == v[1] && v[1] == v[2]),
        })
}

/// Texels of the map in row-major order, read in parallel by rows.
fn rows(maps: &MaterialMaps) -> Vec<Texel> {
    let w = maps.width() as usize;
    let mut out = vec![Texel::encode(MaterialValue::default()); w * maps.height() as usize];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, t) in row.iter_mut().enumerate() {
            *t = maps.texel(x as u32, y as u32);
        }
    });
    out
}

/// A component source: which channel component of a texel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Comp {
    Kd(usize),
    Ks(usize),
    N,
    Ka(usize),
}

impl Comp {
    fn name(self, mono_ks: bool) -> String {
        const RGB: [&str; 3] = ["r", "g", "b"];
        match self {
            Self::Kd(c) => format!("kd.{}", RGB[c]),
            Self::Ks(_) if mono_ks => "ks".into(),
            Self::Ks(c) => format!("ks.{}", RGB[c]),
            Self::N => "n".into(),
            Self::Ka(c) => format!("ka.{}", RGB[c]),
        }
    }

    fn parse(name: &str) -> Option<Self> {
        let rgb = |s: &str| ["r", "g", "b"].iter().position(|c| *c == s);
        match name.split_once('.') {
            Some(("kd", c)) => rgb(c).map(Self::Kd),
            Some(("ks", c)) => rgb(c).map(Self::Ks),
            Some(("ka", c)) => rgb(c).map(Self::Ka),
            None if name == "ks" => Some(Self::Ks(3)),
            None if name == "n" => Some(Self::N),
            _ => None,
        }
    }
}

/// Whether a component is a colour (sRGB-encoded in 8-bit files).
fn is_colour(comp: Comp) -> bool {
    !matches!(comp, Comp::N)
}

fn approximation(approx: AmbientApprox, model: ShadingModel) -> Approximation {
    Approximation {
        name: approx.name().to_string(),
        diffuse_factor: reflectance::diffuse_factor(approx),
        paper_constants: (approx != AmbientApprox::Fast).then(|| {
            let (a, b, c) = reflectance::paper_constants(model, approx);
            [a, b, c]
        }),
    }
}

/// One encoded image.
struct EncodedImage {
    /// The file.
    bytes: Vec<u8>,
    /// For 8-bit formats: the components a consumer decodes (level 0), per texel.
    stored: Option<Vec<u8>>,
    /// The colour components are sRGB-encoded.
    srgb: bool,
    /// KTX2: mip levels, PSNR, compression name.
    ktx: Option<KtxInfo>,
}

/// What a KTX2 file reports beyond its bytes.
struct KtxInfo {
    levels: u32,
    psnr: Option<Vec<Option<f64>>>,
    compression: &'static str,
}

/// Whether an image's colour components are sRGB-encoded: in 8-bit PNGs always, in KTX2
/// where the format has an sRGB variant (three or four components).
fn srgb_image(format: Format, comps: &[Comp]) -> bool {
    let colour = comps.iter().any(|c| is_colour(*c));
    colour && (format == Format::Png8 || (format.is_ktx2() && comps.len() >= 3))
}

/// Per stored 16-bit code, what a file holds: colour components (sRGB-encoded where `srgb`),
/// and n through its encoding (as a fraction of the code range). Tables keep the per-texel
/// work to lookups.
fn file_tables(srgb: bool, n_enc: Option<NEncoding>) -> (Vec<f32>, Vec<f32>) {
    let colour = (0..=u16::MAX)
        .map(|q| {
            let v = decode_unorm(q);
            if srgb { linear_to_srgb(v) } else { v }
        })
        .collect();
    let n = (0..=u16::MAX)
        .map(|bits| {
            let n = decode_n(bits);
            match n_enc {
                Some(e) => f32::from(e.encode(n)) / ((1_u32 << e.bits) - 1) as f32,
                None => n,
            }
        })
        .collect();
    (colour, n)
}

/// A PNG of `data` (16-bit words native-endian) with `color`.
fn png_bytes(data: &[u8], (width, height): (u32, u32), color: C) -> Result<Vec<u8>, String> {
    let mut out = std::io::Cursor::new(Vec::new());
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new_with_quality(
            &mut out,
            image::codecs::png::CompressionType::Fast,
            image::codecs::png::FilterType::Adaptive,
        ),
        data,
        width,
        height,
        color,
    )
    .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// Encodes one image of `comps` components from the texels.
fn encode_image(
    texels: &[Texel],
    ka: &[Vec3],
    (width, height): (u32, u32),
    comps: &[Comp],
    preset: &ExportPreset,
    n_enc: Option<NEncoding>,
    progress: &Progress,
) -> Result<EncodedImage, String> {
    let format = preset.format;
    let channels = comps.len();
    let srgb = srgb_image(format, comps);
    let (colour_lut, n_lut) = file_tables(srgb, n_enc);
    let value = |i: usize, k: usize| -> f32 {
        let t = &texels[i];
        match comps[k] {
            Comp::Kd(c) => colour_lut[t.kd[c] as usize],
            Comp::Ks(c) => colour_lut[t.ks[c.min(2)] as usize],
            Comp::N => n_lut[t.n as usize],
            Comp::Ka(c) => {
                let v = ka.get(i).map_or(0.0, |k| k[c]);
                if srgb { linear_to_srgb(v) } else { v }
            }
        }
    };
    let count = texels.len();
    let png = |data: &[u8], colors: [C; 4]| {
        png_bytes(data, (width, height), colors[channels.clamp(1, 4) - 1])
    };
    let plain = |bytes| {
        progress.advance(u64::from(height));
        EncodedImage {
            bytes,
            stored: None,
            srgb,
            ktx: None,
        }
    };
    match format {
        Format::Png8 => {
            let data: Vec<u8> = (0..count * channels)
                .into_par_iter()
                .map(|j| (value(j / channels, j % channels).clamp(0.0, 1.0) * 255.0).round() as u8)
                .collect();
            let bytes = png(&data, [C::L8, C::La8, C::Rgb8, C::Rgba8])?;
            Ok(EncodedImage {
                stored: Some(data),
                ..plain(bytes)
            })
        }
        Format::Png16 => {
            // Native-endian 16-bit words, as the encoder expects.
            let data: Vec<u8> = (0..count * channels)
                .into_par_iter()
                .flat_map_iter(|j| {
                    let v = value(j / channels, j % channels);
                    ((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_ne_bytes()
                })
                .collect();
            Ok(plain(png(&data, [C::L16, C::La16, C::Rgb16, C::Rgba16])?))
        }
        Format::Exr => {
            // RGB floats; a one-component image repeats its value in all three.
            let data: Vec<f32> = (0..count * 3)
                .into_par_iter()
                .map(|j| value(j / 3, (j % 3).min(channels - 1)))
                .collect();
            let mut out = std::io::Cursor::new(Vec::new());
            image::Rgb32FImage::from_raw(width, height, data)
                .ok_or("image size")?
                .write_to(&mut out, image::ImageFormat::OpenExr)
                .map_err(|e| e.to_string())?;
            Ok(plain(out.into_inner()))
        }
        Format::Ktx2 | Format::Ktx2Bc => {
            let values: Vec<f32> = (0..count * channels)
                .into_par_iter()
                .map(|j| value(j / channels, j % channels))
                .collect();
            let source = super::ktx::Source {
                width,
                height,
                channels,
                values: &values,
                srgb,
            };
            let compressed = (format == Format::Ktx2Bc).then_some(preset.bc7_quality);
            let written = super::ktx::encode(&source, compressed, progress)?;
            Ok(EncodedImage {
                bytes: written.bytes,
                stored: Some(written.level0),
                srgb,
                ktx: Some(KtxInfo {
                    levels: written.levels,
                    psnr: written.psnr,
                    compression: written.compression,
                }),
            })
        }
    }
}

/// Which images a set holds, with which components: what is constant is left out, `k_s` is
/// one channel when grey, and the packed layout puts `n` in `k_d`'s alpha.
fn plan_images(
    preset: &ExportPreset,
    constants: &Constants,
    mono_ks: bool,
) -> Vec<(&'static str, Vec<Comp>)> {
    let kd: Vec<Comp> = (0..3).map(Comp::Kd).collect();
    let ks: Vec<Comp> = if mono_ks {
        vec![Comp::Ks(0)]
    } else {
        (0..3).map(Comp::Ks).collect()
    };
    let (with_kd, with_n) = (constants.kd.is_none(), constants.n.is_none());
    let mut images: Vec<(&'static str, Vec<Comp>)> = Vec::new();
    let with_ks = constants.ks.is_none();
    if preset.layout == Layout::Packed && with_kd && with_n {
        images.push(("kd_n", [kd, vec![Comp::N]].concat()));
    } else if preset.layout == Layout::Packed && with_n && with_ks && mono_ks {
        // k_d constant: grey k_s and n share a two-component image.
        images.push(("ks_n", vec![Comp::Ks(0), Comp::N]));
        if preset.include_ka {
            images.push(("ka", (0..3).map(Comp::Ka).collect()));
        }
        return images;
    } else {
        if with_kd {
            images.push(("kd", kd));
        }
        if with_n {
            images.push(("n", vec![Comp::N]));
        }
    }
    if constants.ks.is_none() {
        images.push(("ks", ks));
    }
    if preset.include_ka {
        images.push(("ka", (0..3).map(Comp::Ka).collect()));
    }
    images
}

/// An encoded image with its file name and components.
type Encoded = (String, Vec<Comp>, EncodedImage);

/// The bytes a consumer decodes from an 8-bit image, `comps.len()` per texel.
struct StoredImage {
    comps: Vec<Comp>,
    data: Vec<u8>,
    srgb: bool,
}

/// One file a set will hold, as planned before anything is encoded.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedFile {
    /// File name.
    pub path: String,
    /// Components in channel order (`kd.r`, `n`, `ks`, ...).
    pub layout: Vec<String>,
    /// Bytes of the image uncompressed, at the preset's depth (the file is smaller when the
    /// format compresses).
    pub raw_bytes: u64,
}

/// What exporting a document with a preset will write, and the `k_a` error that `n`'s
/// quantisation alone will cost: the export dialog's preview, computed without encoding.
#[derive(Clone, Debug, PartialEq)]
pub struct SetPlan {
    /// The images, in the order they are written.
    pub files: Vec<PlannedFile>,
    /// Channels that become constants in the manifest instead of images.
    pub constants: Constants,
    /// `n`'s curve, range and bits, when `n` is stored in an integer image.
    pub n_encoding: Option<NEncoding>,
    /// The relative `k_a` error of that quantisation (block compression adds to it).
    pub ka_error: KaError,
    /// Bytes: the images uncompressed, the naive maps, the project's maps.
    pub bytes: MemoryReport,
}

/// The plan of exporting `doc` with `preset` (see [`SetPlan`]).
pub fn plan(doc: &Document, preset: &ExportPreset) -> SetPlan {
    let (plan, _, _) = plan_set(doc, preset);
    plan
}

/// [`plan`], with the two facts the writer needs besides: whether `k_s` is grey, and the
/// planned images' components.
fn plan_set(
    doc: &Document,
    preset: &ExportPreset,
) -> (SetPlan, bool, Vec<(&'static str, Vec<Comp>)>) {
    let maps = doc.maps();
    let (model, approx) = (doc.settings().model, doc.settings().approx);
    let (kd, ks, n) = maps.uniform_channels();
    let constants = Constants {
        kd: kd.map(|v| v.map(decode_unorm)),
        ks: ks.map(|v| v.map(decode_unorm)),
        n: n.map(decode_n),
    };
    let mono_ks = ks_monochrome(maps);
    let (n_encoding, ka_error) = match (constants.n, preset.format) {
        (Some(_), _) | (None, Format::Exr) => (None, KaError::default()),
        (None, _) => rank_encodings(maps, model, approx, preset.n_bits)
            .first()
            .map_or((None, KaError::default()), |(e, err)| (Some(*e), *err)),
    };
    let images = plan_images(preset, &constants, mono_ks);
    let depth: u64 = match preset.format {
        Format::Png8 | Format::Ktx2 | Format::Ktx2Bc => 1,
        Format::Png16 => 2,
        Format::Exr => 4,
    };
    let texels = u64::from(maps.width()) * u64::from(maps.height());
    let ext = preset.format.extension();
    let files: Vec<PlannedFile> = images
        .iter()
        .map(|(stem, comps)| PlannedFile {
            path: format!("{stem}.{ext}"),
            layout: comps.iter().map(|c| c.name(mono_ks)).collect(),
            raw_bytes: texels * depth * comps.len() as u64,
        })
        .collect();
    let bytes = MemoryReport {
        exported: files.iter().map(|f| f.raw_bytes).sum(),
        naive: texels * 10 * depth,
        project: texels * 14,
    };
    (
        SetPlan {
            files,
            constants,
            n_encoding,
            ka_error,
            bytes,
        },
        mono_ks,
        images,
    )
}

/// Exports `doc` with `preset` into the folder `out` (which must not exist or be empty).
///
/// # Errors
/// An unwritable or non-empty target, or a failed encode or write: nothing is left at `out`.
pub fn export(doc: &Document, preset: &ExportPreset, out: &Path) -> Result<Manifest, SetError> {
    export_with(doc, preset, out, &Progress::default())
}

/// [`export`], reporting to `progress` (stages `analyse`, `encode`, `measure`) and stopping
/// with [`SetError::Cancelled`] when it is cancelled.
///
/// # Errors
/// As [`export`], or cancelled.
#[expect(
    clippy::too_many_lines,
    reason = "one pass: analyse, encode in parallel, measure, commit"
)]
pub fn export_with(
    doc: &Document,
    preset: &ExportPreset,
    out: &Path,
    progress: &Progress,
) -> Result<Manifest, SetError> {
    let cancelled = |_| SetError::Cancelled;
    progress.start("analyse", 1);
    if out.exists()
        && (!out.is_dir()
            || std::fs::read_dir(out)
                .map_err(|e| io(out, e))?
                .next()
                .is_some())
    {
        return Err(SetError::Target {
            path: out.to_path_buf(),
            reason: "exists and is not an empty folder".into(),
        });
    }
    let maps = doc.maps();
    let (model, approx) = (doc.settings().model, doc.settings().approx);
    let (w, h) = (maps.width(), maps.height());
    let (planned, mono_ks, images) = plan_set(doc, preset);
    let (constants, n_enc) = (planned.constants, planned.n_encoding);
    let mut texels = rows(maps);
    // Outside the mesh's UV islands, texels copy the nearest island's, so mips and filtering
    // do not pull the background into the edges.
    let dilated = doc.surface().is_some_and(|surface| {
        let mut filled: Vec<bool> = surface
            .bake
            .coverage
            .iter()
            .map(|c| *c == Coverage::Surface)
            .collect();
        let any = filled.iter().any(|f| *f);
        if any {
            crate::mesh::bake::dilate_grid(&mut filled, w, h, u32::MAX, |k, src| {
                texels[k] = texels[src];
            });
        }
        any
    });
    let ka: Vec<Vec3> = if preset.include_ka {
        texels
            .par_iter()
            .map(|t| {
                let v = t.decode();
                reflectance::ka(model, approx, v.kd, v.ks, v.n)
            })
            .collect()
    } else {
        Vec::new()
    };

    let ext = preset.format.extension();
    progress.check().map_err(cancelled)?;
    progress.start("encode", images.len() as u64 * u64::from(h));

    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| io(parent, e))?;
    let name = out
        .file_name()
        .map_or_else(|| "set".into(), |n| n.to_string_lossy().into_owned());
    remove_stale_sets(parent, &name);
    let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir(&tmp).map_err(|e| io(&tmp, e))?;
    // Removed on every way out but the last rename.
    let guard = crate::atomic::TempPath::new(tmp.clone());
    let result = (|| {
        let encoded: Vec<Result<Encoded, SetError>> = images
            .par_iter()
            .map(|(stem, comps)| {
                let file = format!("{stem}.{ext}");
                if progress.is_cancelled() {
                    return Err(SetError::Cancelled);
                }
                let image = encode_image(&texels, &ka, (w, h), comps, preset, n_enc, progress)
                    .map_err(|e| {
                        if progress.is_cancelled() {
                            SetError::Cancelled
                        } else {
                            io(&tmp.join(&file), e)
                        }
                    })?;
                if progress.is_cancelled() {
                    return Err(SetError::Cancelled);
                }
                Ok((file, comps.clone(), image))
            })
            .collect();
        progress.start("measure", 1);
        let mut files = Vec::new();
        let mut stored = Vec::new();
        for item in encoded {
            let (file, comps, image) = item?;
            let path = tmp.join(&file);
            crate::atomic::write_atomic(&path, &image.bytes).map_err(|e| io(&path, e))?;
            let (mip_levels, psnr, kind) = match image.ktx {
                Some(k) => (Some(k.levels), k.psnr, k.compression),
                None => (None, None, "none"),
            };
            files.push(FileEntry {
                path: file,
                layout: comps.iter().map(|c| c.name(mono_ks)).collect(),
                colour_space: if image.srgb { "srgb" } else { "linear" }.into(),
                bit_depth: match preset.format {
                    Format::Png8 | Format::Ktx2 | Format::Ktx2Bc => 8,
                    Format::Png16 => 16,
                    Format::Exr => 32,
                },
                compression: match preset.format {
                    Format::Ktx2Bc => format!("ktx2-{kind}"),
                    _ => ext.into(),
                },
                width: w,
                height: h,
                bytes: image.bytes.len() as u64,
                mip_levels,
                psnr,
            });
            if let Some(data) = image.stored {
                stored.push(StoredImage {
                    comps,
                    data,
                    srgb: image.srgb,
                });
            }
        }
        let depth = match preset.format {
            Format::Png8 | Format::Ktx2 | Format::Ktx2Bc => 1,
            Format::Png16 => 2,
            Format::Exr => 4,
        };
        let texel_count = u64::from(w) * u64::from(h);
        let mut manifest = Manifest {
            format: MANIFEST_FORMAT.into(),
            version: MANIFEST_VERSION,
            width: w,
            height: h,
            model,
            approximation: approximation(approx, model),
            constants,
            n_encoding: n_enc,
            files,
            ka_error: KaError::default(),
            dilated,
            bytes: MemoryReport {
                exported: 0,
                naive: texel_count * 10 * depth,
                project: texel_count * 14,
            },
            preset: preset.name.clone(),
        };
        // The k_a error, measured on the set as a consumer decodes it.
        manifest.ka_error =
            ka_error_of_set(&texels, &manifest, &stored, preset.format, model, approx);
        // The decode + k_a snippets for engines (WGSL and GLSL), beside the images.
        let mut exported = manifest.files.iter().map(|f| f.bytes).sum::<u64>();
        for (name, snippet) in [
            ("material.wgsl", super::snippet::wgsl(&manifest)),
            ("material.glsl", super::snippet::glsl(&manifest)),
        ] {
            let snippet_path = tmp.join(name);
            crate::atomic::write_atomic(&snippet_path, snippet.as_bytes())
                .map_err(|e| io(&snippet_path, e))?;
            exported += snippet.len() as u64;
        }
        // The manifest counts itself, and its length depends on the count's digits: repeat
        // until they agree (the count only grows, so this ends, in two or three rounds).
        let json = loop {
            let json = serde_json::to_vec_pretty(&manifest).map_err(|e| io(&tmp, e))?;
            let total = exported + json.len() as u64;
            if manifest.bytes.exported == total {
                break json;
            }
            manifest.bytes.exported = total;
        };
        let path = tmp.join("material.json");
        crate::atomic::write_atomic(&path, &json).map_err(|e| io(&path, e))?;
        Ok(manifest)
    })();
    let manifest = result?;
    if out.exists() {
        std::fs::remove_dir(out).map_err(|e| io(out, e))?;
    }
    std::fs::rename(&tmp, out).map_err(|e| io(out, e))?;
    guard.keep();
    Ok(manifest)
}

/// Removes the temporary folders of earlier exports to `name` in `dir` whose process is gone.
fn remove_stale_sets(dir: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.tmp-");
    for entry in entries.filter_map(Result::ok) {
        let Some(pid) = entry
            .file_name()
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && crate::atomic::process_gone(pid) == Some(true) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// Where a consumer's value of one component comes from.
#[derive(Clone, Copy)]
enum Read<'a> {
    /// Through a table per stored 16-bit code (constants, 16-bit and float files).
    Table(&'a [f32]),
    /// A table per byte of an 8-bit file as written (after block compression).
    Bytes {
        data: &'a [u8],
        stride: usize,
        offset: usize,
        table: &'a [f32],
    },
}

impl Read<'_> {
    fn get(self, i: usize, code: u16) -> f32 {
        match self {
            Self::Table(t) => t[code as usize],
            Self::Bytes {
                data,
                stride,
                offset,
                table,
            } => table[data[i * stride + offset] as usize],
        }
    }
}

/// The first of `want` that an 8-bit image holds, read through `table` (sRGB image) or
/// `linear`.
fn in_file<'r>(
    stored: &'r [StoredImage],
    want: &[Comp],
    table: &'r [f32],
    linear: &'r [f32],
) -> Option<Read<'r>> {
    want.iter().find_map(|w| {
        stored.iter().find_map(|image| {
            let offset = image.comps.iter().position(|c| c == w)?;
            Some(Read::Bytes {
                data: &image.data,
                stride: image.comps.len(),
                offset,
                table: if image.srgb { table } else { linear },
            })
        })
    })
}

/// Relative `k_a` error of the set described by `manifest` against the texels it was made
/// from, per texel and colour channel: every value goes through what a consumer reads (the
/// bytes an 8-bit file holds after compression, or 16-bit and float codes by table) and back.
fn ka_error_of_set(
    texels: &[Texel],
    manifest: &Manifest,
    stored: &[StoredImage],
    format: Format,
    model: ShadingModel,
    approx: AmbientApprox,
) -> KaError {
    let chi = crate::model::maps::chi_lut(model, approx);
    let diffuse = reflectance::diffuse_factor(approx) as f32;
    let exact: Vec<f32> = (0..=u16::MAX).map(decode_unorm).collect();
    let sixteen: Vec<f32> = exact
        .iter()
        .map(|v| (v * 65535.0).round() / 65535.0)
        .collect();
    // n: stored half-float bits -> chi of what the set decodes.
    let chi_of_set: Vec<f32> = (0..=u16::MAX)
        .map(|bits| match manifest.n_encoding {
            Some(e) => reflectance::chi_f32(model, approx, e.decode(e.encode(decode_n(bits)))),
            None => chi[bits as usize],
        })
        .collect();
    let srgb8: Vec<f32> = (0..=255_u8)
        .map(|b| srgb_to_linear(f32::from(b) / 255.0))
        .collect();
    let linear8: Vec<f32> = (0..=255_u8).map(|b| f32::from(b) / 255.0).collect();
    let chi8: Vec<f32> = (0..=255_u16)
        .map(|q| {
            manifest.n_encoding.map_or(0.0, |e| {
                reflectance::chi_f32(model, approx, e.decode(q.min((1 << e.bits) - 1)))
            })
        })
        .collect();
    // The source of each component: an 8-bit file's bytes, else a table.
    let colour_table: &[f32] = if format == Format::Png16 {
        &sixteen
    } else {
        &exact
    };
    let kd: [Read<'_>; 3] = std::array::from_fn(|c| {
        if manifest.constants.kd.is_some() {
            Read::Table(&exact)
        } else {
            in_file(stored, &[Comp::Kd(c)], &srgb8, &linear8).unwrap_or(Read::Table(colour_table))
        }
    });
    let ks: [Read<'_>; 3] = std::array::from_fn(|c| {
        if manifest.constants.ks.is_some() {
            Read::Table(&exact)
        } else {
            in_file(stored, &[Comp::Ks(c), Comp::Ks(0)], &srgb8, &linear8)
                .unwrap_or(Read::Table(colour_table))
        }
    });
    let n = if manifest.constants.n.is_some() {
        Read::Table(chi)
    } else {
        in_file(stored, &[Comp::N], &chi8, &chi8).unwrap_or(Read::Table(&chi_of_set))
    };
    let w = manifest.width as usize;
    let (max, sum, count) = texels
        .par_chunks(w)
        .enumerate()
        .map(|(y, row)| {
            let (mut max, mut sum) = (0.0_f64, 0.0_f64);
            for (x, t) in row.iter().enumerate() {
                let i = y * w + x;
                let chi_t = chi[t.n as usize];
                let chi_b = n.get(i, t.n);
                for c in 0..3 {
                    let ka = diffuse * exact[t.kd[c] as usize] + exact[t.ks[c] as usize] * chi_t;
                    let kb = diffuse * kd[c].get(i, t.kd[c]) + ks[c].get(i, t.ks[c]) * chi_b;
                    let err = if ka > 0.0 {
                        f64::from((kb - ka).abs() / ka)
                    } else {
                        0.0
                    };
                    max = max.max(err);
                    sum += err;
                }
            }
            (max, sum, row.len() as u64 * 3)
        })
        .reduce(
            || (0.0, 0.0, 0),
            |x, y| (x.0.max(y.0), x.1 + y.1, x.2 + y.2),
        );
    KaError {
        max,
        mean: if count > 0 { sum / count as f64 } else { 0.0 },
    }
}

/// An image of a set as RGBA floats: whether it is KTX2, its size, the texels.
type Pixels = (bool, (u32, u32), Vec<f32>);

/// Reads one image of a set.
fn read_pixels(path: &Path) -> Result<Pixels, SetError> {
    let invalid = |reason: String| SetError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let ktx = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ktx2"));
    if ktx {
        let bytes = crate::file_check::read_limited(path, crate::model::import::MAX_DECODED_BYTES)
            .map_err(|e| {
                if e.is_io() {
                    io(path, e)
                } else {
                    invalid(format!("the file {e}"))
                }
            })?;
        let decoded = super::ktx::decode(&bytes).map_err(invalid)?;
        let pixels = decoded.rgba.iter().map(|b| f32::from(*b) / 255.0).collect();
        Ok((true, (decoded.width, decoded.height), pixels))
    } else {
        let image = crate::model::import::read_image(path).map_err(|e| invalid(e.to_string()))?;
        Ok((
            false,
            (image.width(), image.height()),
            image.to_rgba32f().into_raw(),
        ))
    }
}

/// Reads a set's maps back as a consumer would (no settings).
fn read_maps(manifest: &Manifest, dir: &Path) -> Result<MaterialMaps, SetError> {
    let invalid = |path: &Path, reason: String| SetError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let (w, h) = (manifest.width, manifest.height);
    let mut values = vec![
        MaterialValue::new(
            Vec3::from(manifest.constants.kd.unwrap_or([0.0; 3])),
            Vec3::from(manifest.constants.ks.unwrap_or([0.0; 3])),
            manifest.constants.n.unwrap_or(0.0),
        );
        (w as usize) * (h as usize)
    ];
    for file in &manifest.files {
        let path = dir.join(&file.path);
        if file.path.contains(['/', '\\']) || file.path.starts_with('.') {
            return Err(invalid(&path, "file names must stay inside the set".into()));
        }
        let (ktx, size, pixels) = read_pixels(&path)?;
        if size != (w, h) {
            return Err(invalid(
                &path,
                format!("is {}x{}, the manifest says {w}x{h}", size.0, size.1),
            ));
        }
        let comps: Vec<Comp> = file
            .layout
            .iter()
            .map(|c| {
                Comp::parse(c).ok_or_else(|| invalid(&path, format!("unknown component {c:?}")))
            })
            .collect::<Result<_, _>>()?;
        let srgb = file.colour_space == "srgb";
        let exr = file.compression == "exr";
        let n_enc = manifest.n_encoding;
        let n_codes: Vec<f32> = n_enc.map_or_else(Vec::new, |e| {
            (0..=((1_u32 << e.bits) - 1) as u16)
                .map(|q| e.decode(q))
                .collect()
        });
        let srgb8: Vec<f32> = (0..=255_u8)
            .map(|v| srgb_to_linear(f32::from(v) / 255.0))
            .collect();
        values
            .par_iter_mut()
            .zip(pixels.par_chunks(4))
            .for_each(|(v, px)| {
                for (k, comp) in comps.iter().enumerate() {
                    // EXR one-component images repeat the value, grey + alpha PNGs read as
                    // (L, L, L, A); others hold components in order.
                    let raw = match (comps.len(), k) {
                        (1, _) if exr => px[0],
                        (2, 1) if !ktx && !exr => px[3],
                        _ => px[k.min(3)],
                    };
                    let colour = |x: f32| {
                        if srgb {
                            srgb8[(x.clamp(0.0, 1.0) * 255.0).round() as usize]
                        } else {
                            x
                        }
                    };
                    match *comp {
                        Comp::Kd(c) => v.kd[c] = colour(raw),
                        Comp::Ks(3) => v.ks = Vec3::splat(colour(raw)),
                        Comp::Ks(c) => v.ks[c] = colour(raw),
                        Comp::N => {
                            v.n = match n_enc {
                                Some(e) => {
                                    let q = (raw.clamp(0.0, 1.0) * ((1_u32 << e.bits) - 1) as f32)
                                        .round();
                                    n_codes[q as usize]
                                }
                                None => raw,
                            };
                        }
                        Comp::Ka(_) => {}
                    }
                }
            });
    }
    let mut maps = MaterialMaps::new(w, h, MaterialValue::default())
        .map_err(|e| invalid(dir, e.to_string()))?;
    for (i, v) in values.iter().enumerate() {
        let (x, y) = ((i % w as usize) as u32, (i / w as usize) as u32);
        let (id, k) = maps.locate(x, y);
        maps.tile_mut(id).set_texel(k, Texel::encode(v.sanitized()));
    }
    for id in 0..maps.tile_count() {
        maps.tile_mut(id).compact();
    }
    Ok(maps)
}

/// Reads a set (`material.json` and its images) back into a document.
///
/// # Errors
/// A missing, malformed or inconsistent manifest or image.
pub fn import(manifest_path: &Path) -> Result<Document, SetError> {
    let text = read_manifest_bytes(manifest_path)?;
    let manifest: Manifest = serde_json::from_slice(&text).map_err(|e| SetError::Invalid {
        path: manifest_path.to_path_buf(),
        reason: format!("not a valid kapaint material manifest: {e}"),
    })?;
    let dir = manifest_path.parent().unwrap_or(Path::new("."));
    let maps = read_maps(&manifest, dir)?;
    let approx = Approximation::of_name(&manifest.approximation.name).map_err(|reason| {
        SetError::Invalid {
            path: manifest_path.to_path_buf(),
            reason,
        }
    })?;
    let settings = DocumentSettings {
        model: manifest.model,
        approx,
        ..DocumentSettings::default()
    };
    Ok(Document::from_parts(maps, settings))
}

/// Largest manifest read (bytes).
const MAX_MANIFEST_BYTES: u64 = 4 << 20;

/// The manifest's bytes: a regular file of at most [`MAX_MANIFEST_BYTES`].
fn read_manifest_bytes(path: &Path) -> Result<Vec<u8>, SetError> {
    crate::file_check::read_limited(path, MAX_MANIFEST_BYTES).map_err(|e| {
        if e.is_io() {
            io(path, e)
        } else {
            SetError::Invalid {
                path: path.to_path_buf(),
                reason: e.to_string(),
            }
        }
    })
}
