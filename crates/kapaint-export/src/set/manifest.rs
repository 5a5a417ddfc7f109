//! `material.json`: the manifest of a set, its file entries, constants and approximation,
//! each read only through its checks, and the components images hold.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::perceptual::SrgbError;
use crate::codec::AstcBlock;
use crate::encoding::{KaError, NEncoding};
use kapaint_reflectance::{self as reflectance, AmbientApprox, ShadingModel};

pub use crate::file_kind::{ColourSpace, Compression, Supercompression};

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
    /// How the colour components are encoded.
    pub colour_space: ColourSpace,
    /// Bits per component (8, 16, or 32 for float EXR).
    pub bit_depth: u32,
    /// The file's container and compression.
    pub compression: Compression,
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
    /// For ASTC files: the block footprint (`"4x4"`; the file's `vkFormat` says it too).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub astc_block: Option<AstcBlock>,
    /// For KTX2 files whose levels are supercompressed: how, and the file's size without.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub supercompression: Option<Supercompression>,
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
    #[serde(default)]
    astc_block: Option<AstcBlock>,
    #[serde(default)]
    supercompression: Option<Supercompression>,
}

impl TryFrom<FileEntryFile> for FileEntry {
    type Error = String;

    fn try_from(f: FileEntryFile) -> Result<Self, String> {
        let name = &f.path;
        kapaint_model::check::bounded_text("a file name", name, 255)?;
        if name.is_empty() || name.contains(['/', '\\', ':']) || name.starts_with('.') {
            return Err(format!(
                "file name {name:?} must be a plain name inside the set's folder"
            ));
        }
        let compression = Compression::parse(&f.compression).ok_or_else(|| {
            format!(
                "{name}: unknown compression {:?} (known: {})",
                f.compression,
                Compression::ALL.map(Compression::name).join(", ")
            )
        })?;
        let (ext, depths) = (compression.extension(), compression.bit_depths());
        if !Path::new(name)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
        {
            return Err(format!("{name}: a {compression} file must end in .{ext}"));
        }
        if !depths.contains(&f.bit_depth) {
            return Err(format!(
                "{name}: bit_depth {} is not one a {compression} file has ({depths:?})",
                f.bit_depth
            ));
        }
        if let Some(sc) = &f.supercompression
            && (!sc.is_known() || compression.extension() != "ktx2")
        {
            return Err(format!(
                "{name}: supercompression must be zstd at a level in 1..=22 on a KTX2 file, got {} {}",
                sc.scheme, sc.level
            ));
        }
        if f.astc_block.is_some() && compression != Compression::Ktx2Astc {
            return Err(format!(
                "{name}: astc_block names an ASTC file's footprint, not a {compression} file's"
            ));
        }
        let colour_space = ColourSpace::parse(&f.colour_space).ok_or_else(|| {
            format!(
                "{name}: colour_space must be srgb or linear, got {:?}",
                f.colour_space
            )
        })?;
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
            colour_space,
            bit_depth: f.bit_depth,
            compression,
            width: f.width,
            height: f.height,
            bytes: f.bytes,
            mip_levels: f.mip_levels,
            psnr: f.psnr,
            astc_block: f.astc_block,
            supercompression: f.supercompression,
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
        use kapaint_model::check::{all_in_range, in_range};
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
                .map(|v| in_range("constants.n", v, 0.0, kapaint_model::texel::N_MAX))
                .transpose()?,
        })
    }
}

/// How to recompute `k_a` as kapaint does.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ApproximationFile")]
pub struct Approximation {
    /// `fast`, `paper` or `paper-corrected`.
    pub name: AmbientApprox,
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
        Ok(Self {
            name: Approximation::of_name(&f.name)?,
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
        AmbientApprox::from_name(name).ok_or_else(|| {
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
    /// The same in levels of 8-bit sRGB of the ambient-lit colour (`k_a` under unit ambient,
    /// sRGB-encoded; [`super::perceptual`]). Absent in sets written before it was measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ka_error_srgb: Option<SrgbError>,
    /// Texels outside the mesh's UV islands were filled from the nearest island.
    #[serde(default)]
    pub dilated: bool,
    /// Sizes.
    pub bytes: MemoryReport,
    /// The preset used.
    pub preset: String,
    /// How many layers (groups and their children included) the project had, flattened into
    /// the set (0 in sets from before layers).
    #[serde(default)]
    pub layers: u32,
    /// KTX2 sets: the `k_a` error of every mip level, finest first (level 0 is `ka_error`;
    /// each further level against the mean of the exact level 0's `k_a` over its footprint).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub level_ka_error: Vec<KaError>,
    /// KTX2 sets: the sRGB-level error of every mip level, finest first (level 0 is
    /// `ka_error_srgb`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub level_ka_error_srgb: Vec<SrgbError>,
    /// Block-compressed sets: how the layout and BC7 effort were chosen.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blocks: Option<Box<super::choice::BlockChoice>>,
    /// The project's tangent-space normal map, beside the maps as it stores it (it lights
    /// only: `k_a` never reads it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<Box<super::normal::NormalFile>>,
}

impl Manifest {
    /// Every file the set's folder holds: the images, the normal map, `material.json`,
    /// `material.wgsl` and `material.glsl`.
    pub fn file_count(&self) -> usize {
        self.files.len() + usize::from(self.normal.is_some()) + 3
    }

    /// What supercompression saved, in words ("zstd 9: 33555400 -> 2945614 bytes, 91.2 %
    /// smaller"), over every supercompressed file (the normal map's included); `None` where
    /// none is.
    pub fn supercompression_summary(&self) -> Option<String> {
        let entries = self
            .files
            .iter()
            .map(|f| (f.bytes, f.supercompression.as_ref()))
            .chain(
                self.normal
                    .iter()
                    .map(|n| (n.bytes, n.supercompression.as_ref())),
            );
        let (mut after, mut before, mut level) = (0_u64, 0_u64, None);
        for (bytes, sc) in entries {
            if let Some(sc) = sc {
                after += bytes;
                before += sc.uncompressed_bytes;
                level = Some(sc.level);
            }
        }
        let level = level?;
        Some(format!(
            "zstd {level}: {before} -> {after} bytes, {:.1} % smaller",
            (1.0 - after as f64 / before.max(1) as f64) * 100.0
        ))
    }
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
    ka_error_srgb: Option<SrgbError>,
    #[serde(default)]
    dilated: bool,
    bytes: MemoryReport,
    preset: String,
    #[serde(default)]
    layers: u32,
    #[serde(default)]
    level_ka_error: Vec<KaError>,
    #[serde(default)]
    level_ka_error_srgb: Vec<SrgbError>,
    #[serde(default)]
    blocks: Option<Box<super::choice::BlockChoice>>,
    #[serde(default)]
    normal: Option<Box<super::normal::NormalFile>>,
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
        let max = kapaint_model::maps::MAX_SIDE;
        if w == 0 || h == 0 || w > max || h > max {
            return Err(format!("size {w}x{h} is outside 1..={max}"));
        }
        kapaint_model::check::bounded_text(
            "preset",
            &f.preset,
            kapaint_model::check::MAX_NAME_BYTES,
        )?;
        let comps = stored_components(&f, (w, h))?;
        if let Some(n) = &f.normal {
            n.check()?;
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
            ka_error_srgb: f.ka_error_srgb,
            dilated: f.dilated,
            bytes: f.bytes,
            preset: f.preset,
            layers: f.layers,
            level_ka_error: f.level_ka_error,
            level_ka_error_srgb: f.level_ka_error_srgb,
            blocks: f.blocks,
            normal: f.normal,
        })
    }
}

/// Every component the manifest's files hold, each file checked against the set: its size,
/// its name once, and `n` in integer codes only with an encoding that decodes them.
fn stored_components(f: &ManifestFile, (w, h): (u32, u32)) -> Result<Vec<Comp>, String> {
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
                && file.compression != Compression::Exr
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
    Ok(comps)
}

/// A component source: which channel component of a texel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Comp {
    Kd(usize),
    Ks(usize),
    N,
    Ka(usize),
}

impl Comp {
    pub(super) fn name(self, mono_ks: bool) -> String {
        const RGB: [&str; 3] = ["r", "g", "b"];
        match self {
            Self::Kd(c) => format!("kd.{}", RGB[c]),
            Self::Ks(_) if mono_ks => "ks".into(),
            Self::Ks(c) => format!("ks.{}", RGB[c]),
            Self::N => "n".into(),
            Self::Ka(c) => format!("ka.{}", RGB[c]),
        }
    }

    pub(super) fn parse(name: &str) -> Option<Self> {
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
pub(super) fn is_colour(comp: Comp) -> bool {
    !matches!(comp, Comp::N)
}

pub(super) fn approximation(approx: AmbientApprox, model: ShadingModel) -> Approximation {
    // What the set's k_a really uses: Cook-Torrance has its fit whatever the method.
    let approx = approx.for_model(model);
    Approximation {
        name: approx,
        diffuse_factor: reflectance::diffuse_factor(approx),
        paper_constants: reflectance::paper_constants(model, approx).map(|(a, b, c)| [a, b, c]),
    }
}
