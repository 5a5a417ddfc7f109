//! A set's normal map: the project's tangent-space normal map beside the maps (it lights only:
//! `k_a` never reads it), named in `material.json` and read back with the set.
//!
//! PNG and EXR sets carry it as the project stores it ([`NORMAL_FILE`], 8-bit RGB). KTX2 sets
//! carry x and y alone ([`NORMAL_KTX2_FILE`]: BC5 in `ktx2`, two-component ASTC in
//! `ktx2-astc`, RG8 in `ktx2-raw`), with a full mip chain of box-filtered normals made unit
//! again; the consumer rebuilds `z = sqrt(1 - x^2 - y^2)`. The manifest names that layout and
//! the angular error of level 0 as a consumer decodes it, against the project's map.

use std::path::Path;

use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{SetError, io};
use crate::blocks::Coder;
use crate::codec::{AstcBlock, Codec, Effort};
use crate::file_kind::Compression;
use crate::ktx::Space;
use crate::preset::{ExportPreset, Format};
use kapaint_model::normal::NormalMap;
use kapaint_model::project::NORMAL_ENCODING;

/// The normal map's file in a set of PNG or EXR images.
pub const NORMAL_FILE: &str = "normal.png";
/// The normal map's file in a KTX2 set.
pub const NORMAL_KTX2_FILE: &str = "normal.ktx2";
/// The encoding of [`NORMAL_KTX2_FILE`]: a tangent-space normal's x and y (+Y up, glTF's
/// convention) as unsigned normalised components `c`, `x = 2 c - 1`; z is rebuilt
/// ([`NORMAL_Z`]).
pub const NORMAL_XY_ENCODING: &str = "ktx2-tangent-normal-xy";
/// How a consumer rebuilds z from x and y in a KTX2 set.
pub const NORMAL_Z: &str = "sqrt(max(0, 1 - x^2 - y^2))";

/// How a set stores its normal map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalStorage {
    /// [`NORMAL_FILE`], as the project stores it.
    Png,
    /// [`NORMAL_KTX2_FILE`], x and y: 8-bit RG uncompressed, or in the blocks a block format
    /// gives two components (BC5, or ASTC as luminance and alpha) at an effort.
    Ktx2(Option<(Format, Effort)>),
}

impl NormalStorage {
    /// How a set of `preset` stores it.
    pub fn of(preset: &ExportPreset) -> Self {
        match preset.format {
            Format::Png8 | Format::Png16 | Format::Exr | Format::GltfPbr | Format::PbrTextures => {
                Self::Png
            }
            Format::Ktx2 => Self::Ktx2(None),
            blocks @ (Format::Ktx2Bc { .. }
            | Format::Ktx2Astc { .. }
            | Format::Ktx2Uastc { .. }) => Self::Ktx2(Some((blocks, NORMAL_EFFORT))),
            // ETC1S's endpoints, shared by whole blocks and codebook entries, blur
            // directions: its normal map is UASTC, as Basis Universal's guidance has it.
            Format::Ktx2Etc1s { max_effort } => {
                Self::Ktx2(Some((Format::Ktx2Uastc { max_effort }, NORMAL_EFFORT)))
            }
        }
    }

    /// The codec of its blocks, where it has blocks.
    fn codec(self) -> Option<Box<dyn Codec>> {
        match self {
            Self::Ktx2(Some((format, _))) => format.codec(&[Space::Linear; 2]),
            Self::Png | Self::Ktx2(None) => None,
        }
    }

    /// Its file's name.
    pub fn file(self) -> &'static str {
        match self {
            Self::Png => NORMAL_FILE,
            Self::Ktx2(_) => NORMAL_KTX2_FILE,
        }
    }

    /// In words, for the export dialog: "x and y as BC5, z rebuilt".
    pub fn describe(self) -> String {
        match self {
            Self::Png => "8-bit RGB tangent space, as the project stores it".into(),
            Self::Ktx2(_) => format!(
                "x and y as {}, z rebuilt by the consumer",
                self.codec()
                    .map_or_else(|| "8-bit RG".to_string(), |c| c.describe())
            ),
        }
    }
}

/// The effort for normal maps' blocks: the cheapest, as the set's first trial. BC5 has one;
/// astcenc's medium search halves the angular error of bumpy maps but takes three to seven
/// times as long as its fastest, more than the rest of the set (docs/export.md).
const NORMAL_EFFORT: Effort = Effort::UltraFast;

/// The angle between a normal as a consumer decodes it and the project's, in degrees.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngularError {
    /// The mean over texels.
    pub mean: f64,
    /// The 99th percentile (to a hundredth of a degree).
    pub p99: f64,
    /// The largest.
    pub max: f64,
}

impl AngularError {
    /// In the words the notices use: "angular error mean 0.41°, p99 1.52°, max 6.10°".
    pub fn describe(&self) -> String {
        format!(
            "angular error mean {:.2}°, p99 {:.2}°, max {:.2}°",
            self.mean, self.p99, self.max
        )
    }
}

/// A set's normal map: its file, how it is stored, its size and, in KTX2 sets, the layout a
/// consumer reads and what that costs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalFile {
    /// [`NORMAL_FILE`] or [`NORMAL_KTX2_FILE`].
    pub path: String,
    /// The project's normal encoding (`png-rgb8-tangent-normal`), or [`NORMAL_XY_ENCODING`].
    pub encoding: String,
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// Size in bytes.
    pub bytes: u64,
    /// KTX2: the file's compression (`ktx2` for RG8, `ktx2-bc5`, `ktx2-astc`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compression: Option<Compression>,
    /// ASTC: the block footprint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub astc_block: Option<AstcBlock>,
    /// KTX2: mip levels (a full chain).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mip_levels: Option<u32>,
    /// KTX2: where a consumer samples x and y: `rg` (BC5, RG8: x in R, y in G) or `ra`
    /// (ASTC's luminance and alpha: x in R, G and B, y in A).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xy: Option<String>,
    /// KTX2: how z is rebuilt ([`NORMAL_Z`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<String>,
    /// KTX2: level 0 as a consumer decodes it (z rebuilt) against the project's map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_error: Option<AngularError>,
    /// KTX2 whose levels are supercompressed: how, and the file's size without.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub supercompression: Option<crate::file_kind::Supercompression>,
}

/// Where x and y are in a KTX2 normal map of `compression`.
fn xy_of(compression: Compression) -> &'static str {
    if compression.second_in_alpha() {
        "ra"
    } else {
        "rg"
    }
}

impl NormalFile {
    /// Writes `normal` into the set folder `dir` as `storage` says (a KTX2 file's levels
    /// supercompressed at `zstd`, where given); its entry.
    ///
    /// # Errors
    /// A failed encode or write.
    pub(super) fn write(
        normal: &NormalMap,
        dir: &Path,
        storage: NormalStorage,
        zstd: Option<u8>,
    ) -> Result<Self, SetError> {
        let path = dir.join(storage.file());
        let blocks = match storage {
            NormalStorage::Png => {
                let png = normal.to_png().map_err(|e| io(&path, e))?;
                kapaint_base::atomic::write_atomic(&path, &png).map_err(|e| io(&path, e))?;
                return Ok(Self {
                    path: NORMAL_FILE.into(),
                    encoding: NORMAL_ENCODING.into(),
                    width: normal.width(),
                    height: normal.height(),
                    bytes: png.len() as u64,
                    compression: None,
                    astc_block: None,
                    mip_levels: None,
                    xy: None,
                    z: None,
                    angular_error: None,
                    supercompression: None,
                });
            }
            NormalStorage::Ktx2(blocks) => blocks,
        };
        let unit = unit_normals(normal);
        let size = (normal.width(), normal.height());
        let levels = xy_levels(&unit, size);
        let codec = storage.codec();
        let written = crate::ktx::encode_levels(
            &levels,
            2,
            codec
                .as_deref()
                .zip(blocks)
                .map(|(codec, (_, effort))| (Coder::best_cpu(), codec, effort)),
        )
        .map_err(|e| io(&path, e))?;
        let decoded = written.decoded.first().map_or(&[][..], |d| &d[..]);
        let angular_error = angular_error(&unit, decoded);
        let (bytes, supercompression) = match zstd {
            Some(level) => {
                let (bytes, said) = super::supercompressed(&written.bytes, level, &path)?;
                (bytes, Some(said))
            }
            None => (written.bytes, None),
        };
        kapaint_base::atomic::write_atomic(&path, &bytes).map_err(|e| io(&path, e))?;
        Ok(Self {
            path: NORMAL_KTX2_FILE.into(),
            encoding: NORMAL_XY_ENCODING.into(),
            width: size.0,
            height: size.1,
            bytes: bytes.len() as u64,
            supercompression,
            compression: Some(written.compression),
            astc_block: blocks.and_then(|(format, _)| format.astc_block()),
            mip_levels: Some(written.levels),
            xy: Some(xy_of(written.compression).into()),
            z: Some(NORMAL_Z.into()),
            angular_error: Some(angular_error),
        })
    }

    /// One line for people where the set stores it otherwise than the project does: the
    /// file, its layout, and the angular error it costs ("normal.ktx2: x and y as BC5, z
    /// rebuilt as sqrt(...); angular error mean 0.41°, ..."). `None` for a PNG as stored.
    pub fn summary(&self) -> Option<String> {
        let error = self.angular_error?;
        let blocks = match (self.compression?, self.astc_block) {
            (Compression::Ktx2Astc, Some(b)) => format!("ASTC {b} (luminance and alpha)"),
            (Compression::Ktx2Uastc, _) => "UASTC (luminance and alpha)".into(),
            (Compression::Ktx2Bc5, _) => "BC5".into(),
            _ => "8-bit RG".into(),
        };
        Some(format!(
            "{}: x and y as {blocks}, z rebuilt as {NORMAL_Z}; {}, not judged by the k_a budget",
            self.path,
            error.describe()
        ))
    }

    /// What a manifest may say of it: one of the two files with its encoding and fields, a
    /// size a map may have.
    ///
    /// # Errors
    /// Anything else, in a sentence.
    pub(super) fn check(&self) -> Result<(), String> {
        let max = kapaint_model::maps::MAX_SIDE;
        let sized = (1..=max).contains(&self.width) && (1..=max).contains(&self.height);
        let png = self.path == NORMAL_FILE
            && self.encoding == NORMAL_ENCODING
            && self.compression.is_none()
            && self.astc_block.is_none()
            && self.xy.is_none()
            && self.z.is_none()
            && self.supercompression.is_none();
        let ktx2 = self.path == NORMAL_KTX2_FILE
            && self
                .supercompression
                .as_ref()
                .is_none_or(crate::file_kind::Supercompression::is_known)
            && self.encoding == NORMAL_XY_ENCODING
            && self.compression.is_some_and(|c| {
                matches!(
                    c,
                    Compression::Ktx2
                        | Compression::Ktx2Bc5
                        | Compression::Ktx2Astc
                        | Compression::Ktx2Uastc
                ) && self.xy.as_deref() == Some(xy_of(c))
                    && self.astc_block.is_some() == (c == Compression::Ktx2Astc)
            })
            && self.z.as_deref() == Some(NORMAL_Z);
        if !sized || !(png || ktx2) {
            return Err(format!(
                "the normal map must be {NORMAL_FILE} ({NORMAL_ENCODING}) or {NORMAL_KTX2_FILE} \
                 ({NORMAL_XY_ENCODING}: ktx2, ktx2-bc5, ktx2-astc or ktx2-uastc, xy rg, or ra for ASTC and UASTC, z \
                 {NORMAL_Z}), 1..={max} a side"
            ));
        }
        Ok(())
    }

    /// Reads it from the set folder `dir`, checked against this entry: a KTX2 file's x and y
    /// with z rebuilt, as the project stores normals.
    ///
    /// # Errors
    /// A file that does not read or decode, or is not the size the entry says.
    pub(super) fn read(&self, dir: &Path) -> Result<NormalMap, SetError> {
        let path = dir.join(&self.path);
        let invalid = |reason: String| SetError::Invalid {
            path: path.clone(),
            reason,
        };
        let bytes =
            kapaint_base::file_check::read_limited(&path, kapaint_model::import::MAX_DECODED_BYTES)
                .map_err(|e| {
                    if e.is_io() {
                        io(&path, e)
                    } else {
                        invalid(format!("the file {e}"))
                    }
                })?;
        let map = if self.path == NORMAL_KTX2_FILE {
            let decoded = crate::ktx::decode(&bytes).map_err(&invalid)?;
            let second = if self.xy.as_deref() == Some("ra") {
                3
            } else {
                1
            };
            let image = image::RgbImage::from_fn(decoded.width, decoded.height, |x, y| {
                let at = (y as usize * decoded.width as usize + x as usize) * 4;
                let px = &decoded.rgba[at..at + 4];
                let n = rebuilt(px[0], px[second]);
                image::Rgb(n.to_array().map(|v| ((v + 1.0) * 127.5).round() as u8))
            });
            NormalMap::new(image).map_err(&invalid)?
        } else {
            NormalMap::from_png(&bytes).map_err(&invalid)?
        };
        if (map.width(), map.height()) != (self.width, self.height) {
            return Err(invalid(format!(
                "it is {}x{}, the manifest says {}x{}",
                map.width(),
                map.height(),
                self.width,
                self.height
            )));
        }
        Ok(map)
    }
}

/// The unit normal a consumer rebuilds from stored x and y (fractions `c` of the unorm range,
/// `x = 2 c - 1`): `z = sqrt(1 - x^2 - y^2)`, or x and y made unit where they reach past it.
fn rebuilt(cx: f32, cy: f32) -> Vec3 {
    let (x, y) = (2.0 * cx - 1.0, 2.0 * cy - 1.0);
    let zz = 1.0 - x * x - y * y;
    if zz >= 0.0 {
        Vec3::new(x, y, zz.sqrt())
    } else {
        Vec3::new(x, y, 0.0).normalize_or(Vec3::Z)
    }
}

/// The map's unit normals, row-major, as [`NormalMap::normal`] reads them.
fn unit_normals(normal: &NormalMap) -> Vec<Vec3> {
    let w = normal.width() as usize;
    (0..w * normal.height() as usize)
        .into_par_iter()
        .map(|i| normal.normal((i % w) as u32, (i / w) as u32))
        .collect()
}

/// x and y of a unit normal as stored bytes (`c = (v + 1) / 2`).
fn xy_bytes(n: Vec3) -> [u8; 2] {
    [n.x, n.y].map(|v| ((v.clamp(-1.0, 1.0) + 1.0) * 127.5).round() as u8)
}

/// Every level of a normal map of unit normals `unit` (`size`), x and y bytes per texel:
/// level 0 as is, each further level the 2x2 box mean of the one before made unit again.
fn xy_levels(unit: &[Vec3], size: (u32, u32)) -> Vec<((u32, u32), Vec<u8>)> {
    let bytes = |normals: &[Vec3]| -> Vec<u8> {
        normals.par_iter().flat_map_iter(|n| xy_bytes(*n)).collect()
    };
    let mut levels = vec![(size, bytes(unit))];
    let mut prev: Vec<Vec3> = unit.to_vec();
    let mut at = size;
    for _ in 1..crate::ktx::level_count(size.0, size.1) {
        let next: Vec<Vec3> = crate::ktx::box_down(at, |i| prev[i].to_array())
            .into_par_iter()
            .map(|v| Vec3::from_array(v).normalize_or(Vec3::Z))
            .collect();
        at = ((at.0 / 2).max(1), (at.1 / 2).max(1));
        levels.push((at, bytes(&next)));
        prev = next;
    }
    levels
}

/// Histogram bins per degree for the percentile.
const BINS_PER_DEGREE: f64 = 100.0;

/// The angle between each decoded normal (x and y bytes per texel in `decoded`, z rebuilt)
/// and the unit normal it was made from.
fn angular_error(unit: &[Vec3], decoded: &[u8]) -> AngularError {
    let bins = (180.0 * BINS_PER_DEGREE) as usize + 1;
    let (hist, sum, max) = unit
        .par_iter()
        .zip(decoded.par_chunks_exact(2))
        .fold(
            || (vec![0_u32; bins], 0.0_f64, 0.0_f64),
            |(mut hist, sum, max), (want, xy)| {
                let got = rebuilt(f32::from(xy[0]) / 255.0, f32::from(xy[1]) / 255.0);
                let (a, b) = (want.as_dvec3(), got.as_dvec3());
                let degrees = a.cross(b).length().atan2(a.dot(b)).to_degrees();
                hist[((degrees * BINS_PER_DEGREE) as usize).min(bins - 1)] += 1;
                (hist, sum + degrees, max.max(degrees))
            },
        )
        .reduce(
            || (vec![0_u32; bins], 0.0, 0.0),
            |(mut h, s, m), (h2, s2, m2)| {
                for (a, b) in h.iter_mut().zip(&h2) {
                    *a += b;
                }
                (h, s + s2, m.max(m2))
            },
        );
    let count = unit.len().max(1) as u64;
    let target = (count as f64 * 0.99).ceil() as u64;
    let mut seen = 0_u64;
    let mut p99 = max;
    for (i, b) in hist.iter().enumerate() {
        seen += u64::from(*b);
        if seen >= target {
            p99 = ((i + 1) as f64 / BINS_PER_DEGREE).min(max);
            break;
        }
    }
    AngularError {
        mean: sum / count as f64,
        p99,
        max,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_is_rebuilt_and_a_mip_is_the_unit_mean() {
        // The flat normal's bytes and back.
        let flat = xy_bytes(Vec3::Z);
        let back = rebuilt(f32::from(flat[0]) / 255.0, f32::from(flat[1]) / 255.0);
        assert!(back.angle_between(Vec3::Z).to_degrees() < 0.5, "{back}");
        // Past the unit circle: x and y made unit, z 0.
        assert_eq!(rebuilt(1.0, 1.0), Vec3::new(1.0, 1.0, 0.0).normalize());
        // Two normals tilted opposite ways average to +Z, made unit.
        let a = Vec3::new(0.6, 0.0, 0.8);
        let b = Vec3::new(-0.6, 0.0, 0.8);
        let levels = xy_levels(&[a, b, a, b], (2, 2));
        assert_eq!(levels.len(), 2);
        assert_eq!(levels[1].0, (1, 1));
        let mid = &levels[1].1;
        let n = rebuilt(f32::from(mid[0]) / 255.0, f32::from(mid[1]) / 255.0);
        assert!(n.angle_between(Vec3::Z).to_degrees() < 0.5, "{n}");
        // The error of exact bytes is the rounding's alone; a wrong one is its angle.
        let unit = [a, Vec3::Z];
        let exact: Vec<u8> = unit.iter().flat_map(|n| xy_bytes(*n)).collect();
        assert!(angular_error(&unit, &exact).max < 0.5);
        let tilted = [exact[0], exact[1], 255, exact[3]];
        let e = angular_error(&unit, &tilted);
        assert!(e.max > 80.0 && e.mean > 40.0 && e.p99 <= e.max, "{e:?}");
    }
}
