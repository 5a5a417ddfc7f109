//! A PBR texture set into a document: every texel converted for the target model, with the
//! conversion error measured at every texel ([`super::convert`]).
//!
//! Images are read with the import limits ([`kapaint_model::import`]) and resampled to the
//! map size by its triangle filter, a band of tile rows at a time: the set is never held as
//! floats, only as the decoded images and one band. A texture under a glTF texture transform
//! is sampled bilinearly at the transformed coordinates instead, with the sampler's wrap.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::DynamicImage;
use rayon::prelude::*;

use super::NMapping;
use super::convert::{Conversion, ErrorStats};
use kapaint_model::ModelError;
use kapaint_model::document::{Document, DocumentSettings};
use kapaint_model::import::{Resampler, fill_outside, is_float, read_image};
use kapaint_model::maps::MaterialMaps;
use kapaint_model::normal::NormalMap;
pub use kapaint_model::provenance::{ErrorSummary, ImportReport};
use kapaint_model::texel::{MaterialValue, encode_n, encode_rgb, srgb_to_linear};
use kapaint_model::tile::{Plane, TILE_SIZE, Tile};
use kapaint_reflectance::ShadingModel;

/// Map side used when every input is a constant.
pub const CONSTANT_SIZE: u32 = 256;

/// How texture coordinates wrap outside `[0, 1]` (glTF sampler modes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// `REPEAT`.
    Repeat,
    /// `CLAMP_TO_EDGE`.
    Clamp,
    /// `MIRRORED_REPEAT`.
    Mirror,
}

impl Wrap {
    fn apply(self, t: f32) -> f32 {
        match self {
            Self::Repeat => t - t.floor(),
            Self::Clamp => t.clamp(0.0, 1.0),
            Self::Mirror => {
                let m = t.rem_euclid(2.0);
                if m > 1.0 { 2.0 - m } else { m }
            }
        }
    }
}

/// A glTF texture transform (`KHR_texture_transform`) with its sampler's wrap modes:
/// `uv' = T(offset) R(rotation) S(scale) uv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// Translation.
    pub offset: Vec2,
    /// Rotation in radians (counter-clockwise in UV space, as glTF defines it).
    pub rotation: f32,
    /// Scale.
    pub scale: Vec2,
    /// Wrap in u and v.
    pub wrap: [Wrap; 2],
}

impl UvTransform {
    /// `uv` transformed.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let s = uv * self.scale;
        let (sin, cos) = self.rotation.sin_cos();
        // glTF's rotation matrix: [cos, sin; -sin, cos] applied to (u, v).
        Vec2::new(cos * s.x + sin * s.y, -sin * s.x + cos * s.y) + self.offset
    }
}

/// Where one quantity's values come from.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// An image file.
    File(PathBuf),
    /// An image already decoded (one embedded in a glTF binary), with its name for messages.
    Decoded(Arc<DynamicImage>, String),
    /// The same value everywhere (linear; a scalar is repeated).
    Constant(Vec3),
}

/// One quantity: its input, which channel of it, a factor, and a texture transform.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// The values.
    pub input: Input,
    /// Which channels: `None` for RGB, `Some(c)` for channel `c` only (0 R, 1 G, 2 B).
    pub channel: Option<usize>,
    /// The values are sRGB-encoded colour (base colour, specular); others are linear data.
    pub srgb: bool,
    /// Multiplies the values (glTF's factors).
    pub factor: Vec3,
    /// A texture transform, if the material gives one.
    pub transform: Option<UvTransform>,
}

impl Source {
    /// A source that is the image at `path`, all of its channels or one.
    pub fn file(path: impl Into<PathBuf>, channel: Option<usize>, srgb: bool) -> Self {
        Self {
            input: Input::File(path.into()),
            channel,
            srgb,
            factor: Vec3::ONE,
            transform: None,
        }
    }

    /// A constant.
    pub fn constant(value: Vec3) -> Self {
        Self {
            input: Input::Constant(value),
            channel: None,
            srgb: false,
            factor: Vec3::ONE,
            transform: None,
        }
    }
}

/// A texture set in one of the two PBR workflows.
#[derive(Clone, Debug, PartialEq)]
pub enum PbrSet {
    /// glTF's metallic-roughness: base colour, metallic, roughness.
    MetallicRoughness {
        /// Base colour.
        base: Source,
        /// Metallic.
        metallic: Source,
        /// Perceptual roughness.
        roughness: Source,
    },
    /// Specular-glossiness: `k_d = diffuse (1 - max(specular))`, `k_s = specular`,
    /// `roughness = 1 - glossiness` (as `KHR_materials_pbrSpecularGlossiness` shades it).
    SpecularGlossiness {
        /// Diffuse colour.
        diffuse: Source,
        /// Specular colour (`F0`).
        specular: Source,
        /// Glossiness.
        glossiness: Source,
    },
}

impl PbrSet {
    fn sources(&self) -> [&Source; 3] {
        match self {
            Self::MetallicRoughness {
                base,
                metallic,
                roughness,
            } => [base, metallic, roughness],
            Self::SpecularGlossiness {
                diffuse,
                specular,
                glossiness,
            } => [diffuse, specular, glossiness],
        }
    }

    /// A texel's `k_d`, `F0` and roughness from the three quantities' values.
    fn texel(&self, [a, b, c]: [Vec3; 3]) -> (Vec3, Vec3, f32) {
        let unit = |v: Vec3| v.map(kapaint_model::texel::unit);
        match self {
            Self::MetallicRoughness { .. } => {
                let (base, m) = (unit(a), kapaint_model::texel::unit(b.x));
                (
                    base * (1.0 - m),
                    Vec3::splat(super::DIELECTRIC_F0).lerp(base, m),
                    c.x,
                )
            }
            Self::SpecularGlossiness { .. } => {
                let (diffuse, specular) = (unit(a), unit(b));
                (
                    diffuse * (1.0 - specular.max_element()),
                    specular,
                    1.0 - kapaint_model::texel::unit(c.x),
                )
            }
        }
    }
}

/// A set imported: the document, and the report (also in its settings).
pub struct Imported {
    /// The converted maps, with the target model.
    pub doc: Document,
    /// The report.
    pub report: ImportReport,
}

/// A decoded input.
enum Loaded {
    Image {
        image: Arc<DynamicImage>,
        name: String,
    },
    Constant(Vec3),
}

fn load(input: &Input) -> Result<Loaded, ModelError> {
    Ok(match input {
        Input::File(path) => Loaded::Image {
            image: Arc::new(read_image(path)?),
            name: file_name(path),
        },
        Input::Decoded(image, name) => Loaded::Image {
            image: Arc::clone(image),
            name: name.clone(),
        },
        Input::Constant(v) => Loaded::Constant(*v),
    })
}

/// The size an import of `set` takes when none is asked for: the largest input image's (by
/// area), `None` when every input is a constant. Image files are read for their header only.
///
/// # Errors
/// An image file whose header does not read.
pub fn native_size(set: &PbrSet) -> Result<Option<(u32, u32)>, ModelError> {
    let mut sizes = Vec::new();
    for s in set.sources() {
        match &s.input {
            Input::File(path) => {
                let size = image::image_dimensions(path).map_err(|e| ModelError::Image {
                    path: path.clone(),
                    reason: e.to_string(),
                })?;
                sizes.push(size);
            }
            Input::Decoded(image, _) => sizes.push((image.width(), image.height())),
            Input::Constant(_) => {}
        }
    }
    Ok(sizes
        .into_iter()
        .max_by_key(|(w, h)| u64::from(*w) * u64::from(*h)))
}

/// Imports `set` at `size` (or the largest input image's size) for `model` under `mapping`
/// (which the document keeps: its glTF export inverts the same one).
///
/// # Errors
/// An input that does not read (missing, corrupt, too large), or maps too large to make.
pub fn import(
    set: &PbrSet,
    size: Option<(u32, u32)>,
    model: ShadingModel,
    mapping: NMapping,
) -> Result<Imported, ModelError> {
    let sources = set.sources();
    let loaded = sources
        .par_iter()
        .map(|s| load(&s.input))
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?;
    let image_size = loaded
        .iter()
        .filter_map(|l| match l {
            Loaded::Image { image, .. } => Some((image.width(), image.height())),
            Loaded::Constant(_) => None,
        })
        .max_by_key(|(w, h)| u64::from(*w) * u64::from(*h));
    let (width, height) = size
        .or(image_size)
        .unwrap_or((CONSTANT_SIZE, CONSTANT_SIZE));
    let mut maps = MaterialMaps::new(width, height, MaterialValue::default())?;
    let mut notes = Vec::new();
    for (l, s) in loaded.iter().zip(&sources) {
        if let Loaded::Image { image, name } = l
            && s.transform.is_none()
            && (image.width(), image.height()) != (width, height)
        {
            notes.push(format!(
                "resampled {name} from {}x{} to {width}x{height}",
                image.width(),
                image.height()
            ));
        }
    }
    notes.dedup();
    let samplers: Vec<Sampler<'_>> = loaded
        .iter()
        .zip(&sources)
        .map(|(l, s)| Sampler::new(l, s, width, height))
        .collect();
    let conversion = Conversion::for_model(model, mapping);
    let tiles_x = maps.tiles_x() as usize;
    let tiles_y = maps.tiles_y() as usize;
    let bands: Vec<(Vec<Tile>, ErrorStats)> = (0..tiles_y)
        .into_par_iter()
        .map(|ty| {
            convert_band(
                set,
                &samplers,
                conversion,
                ty,
                width as usize,
                height as usize,
            )
        })
        .collect();
    let mut stats = ErrorStats::new();
    for (ty, (tiles, band_stats)) in bands.into_iter().enumerate() {
        stats = stats.merge(&band_stats);
        for (tx, tile) in tiles.into_iter().enumerate() {
            maps.replace_tile(ty * tiles_x + tx, Arc::new(tile));
        }
    }
    let mut names: Vec<String> = loaded
        .iter()
        .map(|l| match l {
            Loaded::Image { name, .. } => name.clone(),
            Loaded::Constant(v) => format!("constant {}", fmt_vec(*v)),
        })
        .collect();
    // A packed image feeds two quantities: named once.
    let mut seen = std::collections::HashSet::new();
    names.retain(|n| n.starts_with("constant") || seen.insert(n.clone()));
    let report = ImportReport {
        source: names.join(", "),
        model: model.name().to_string(),
        n_mapping: mapping.report_name(model).into(),
        error: stats.summary(),
        notes,
        double_sided: false,
    };
    let settings = DocumentSettings {
        model,
        import: Some(report.clone()),
        n_mapping: Some(mapping),
        ..DocumentSettings::default()
    };
    Ok(Imported {
        doc: Document::from_parts(maps, settings),
        report,
    })
}

fn fmt_vec(v: Vec3) -> String {
    if v.x == v.y && v.y == v.z {
        format!("{}", v.x)
    } else {
        format!("{},{},{}", v.x, v.y, v.z)
    }
}

/// One input prepared for sampling at the map size.
enum Sampler<'a> {
    Constant(Vec3),
    Filtered {
        image: &'a DynamicImage,
        resampler: Resampler,
        source: &'a Source,
        linear: bool,
    },
    Transformed {
        image: image::Rgb32FImage,
        source: &'a Source,
        transform: UvTransform,
        linear: bool,
    },
}

impl<'a> Sampler<'a> {
    fn new(loaded: &'a Loaded, source: &'a Source, width: u32, height: u32) -> Self {
        match loaded {
            Loaded::Constant(v) => Self::Constant(*v * source.factor),
            Loaded::Image { image, .. } => {
                let linear = is_float(image) || !source.srgb;
                match source.transform {
                    Some(transform) => Self::Transformed {
                        image: image.to_rgb32f(),
                        source,
                        transform,
                        linear,
                    },
                    None => Self::Filtered {
                        image,
                        resampler: Resampler::new((image.width(), image.height()), width, height),
                        source,
                        linear,
                    },
                }
            }
        }
    }

    /// Tile row `ty`'s values, row-major, decoded (sRGB to linear where the source is colour),
    /// the channel picked and the factor applied.
    fn band(&self, ty: usize, width: usize, height: usize) -> Vec<Vec3> {
        let rows = TILE_SIZE.min(height - ty * TILE_SIZE);
        let finish = |raw: [f32; 3], source: &Source, linear: bool| {
            let v = Vec3::from(raw);
            let v = match source.channel {
                Some(c) => Vec3::splat(v[c.min(2)]),
                None => v,
            };
            let v = if linear { v } else { v.map(srgb_to_linear) };
            v * source.factor
        };
        match self {
            Self::Constant(v) => vec![*v; rows * width],
            Self::Filtered {
                image,
                resampler,
                source,
                linear,
            } => resampler
                .band(image, ty)
                .into_iter()
                .map(|p| finish(p, source, *linear))
                .collect(),
            Self::Transformed {
                image,
                source,
                transform,
                linear,
            } => {
                let mut out = Vec::with_capacity(rows * width);
                for r in 0..rows {
                    let y = ty * TILE_SIZE + r;
                    for x in 0..width {
                        let uv = Vec2::new(
                            (x as f32 + 0.5) / width as f32,
                            (y as f32 + 0.5) / height as f32,
                        );
                        let p = bilinear(image, transform.apply(uv), transform.wrap);
                        out.push(finish(p, source, *linear));
                    }
                }
                out
            }
        }
    }
}

/// `image` sampled bilinearly at `uv` (texel centres at half-integers), wrapped.
fn bilinear(image: &image::Rgb32FImage, uv: Vec2, wrap: [Wrap; 2]) -> [f32; 3] {
    let (w, h) = (image.width().max(1), image.height().max(1));
    let u = wrap[0].apply(uv.x) * w as f32 - 0.5;
    let v = wrap[1].apply(uv.y) * h as f32 - 0.5;
    let (x0, y0) = (u.floor(), v.floor());
    let (fx, fy) = (u - x0, v - y0);
    let index = |i: f32, n: u32, mode: Wrap| -> u32 {
        let i = i as i64;
        let n = i64::from(n);
        let j = match mode {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n { 2 * n - 1 - m } else { m }
            }
        };
        j as u32
    };
    let mut out = [0.0; 3];
    for (dy, wy) in [(0.0, 1.0 - fy), (1.0, fy)] {
        for (dx, wx) in [(0.0, 1.0 - fx), (1.0, fx)] {
            let px = image.get_pixel(index(x0 + dx, w, wrap[0]), index(y0 + dy, h, wrap[1]));
            for c in 0..3 {
                out[c] += px[c] * wx * wy;
            }
        }
    }
    out
}

/// Tile row `ty` converted: its tiles and its error statistics.
fn convert_band(
    set: &PbrSet,
    samplers: &[Sampler<'_>],
    conversion: &Conversion,
    ty: usize,
    width: usize,
    height: usize,
) -> (Vec<Tile>, ErrorStats) {
    let values: Vec<Vec<Vec3>> = samplers.iter().map(|s| s.band(ty, width, height)).collect();
    let rows = TILE_SIZE.min(height - ty * TILE_SIZE);
    let mut stats = ErrorStats::new();
    let mut tiles = Vec::new();
    for tx in 0..width.div_ceil(TILE_SIZE) {
        let x0 = tx * TILE_SIZE;
        let cols = TILE_SIZE.min(width - x0);
        let (mut kd, mut ks, mut n) = (
            Plane::Uniform([0; 3]),
            Plane::Uniform([0; 3]),
            Plane::Uniform(0),
        );
        {
            let (kd, ks, n) = (kd.data_mut(), ks.data_mut(), n.data_mut());
            for r in 0..rows {
                for c in 0..cols {
                    let at = r * width + x0 + c;
                    let (d, f0, rough) = set.texel([values[0][at], values[1][at], values[2][at]]);
                    let v = conversion.convert(d, f0, rough);
                    let i = r * TILE_SIZE + c;
                    kd[i] = encode_rgb(v.kd);
                    ks[i] = encode_rgb(v.ks);
                    n[i] = encode_n(v.n);
                    stats.add(conversion.error_of(d, f0, rough));
                }
            }
            fill_outside(kd, (cols, rows));
            fill_outside(ks, (cols, rows));
            fill_outside(n, (cols, rows));
        }
        let mut tile = Tile { kd, ks, n };
        tile.compact();
        tiles.push(tile);
    }
    (tiles, stats)
}

/// A decoded image as a tangent-space normal map (`name` for the notes): 8-bit RGB as
/// stored, with glTF's `scale` baked in where it is not 1 (each normal's x and y times it,
/// then renormalised). A deeper image is reduced to 8 bits, and a note says so.
///
/// # Errors
/// An image larger than the maps may be.
pub fn normal_map(
    image: &DynamicImage,
    scale: f32,
    name: &str,
    notes: &mut Vec<String>,
) -> Result<NormalMap, ModelError> {
    if !matches!(
        image,
        DynamicImage::ImageRgb8(_) | DynamicImage::ImageRgba8(_)
    ) {
        notes.push(format!(
            "normal map {name}: {:?} reduced to 8-bit RGB",
            image.color()
        ));
    }
    let mut rgb = image.to_rgb8();
    if scale.is_finite() && (scale - 1.0).abs() > f32::EPSILON {
        notes.push(format!(
            "normal map {name}: its scale {scale} is baked into the texels"
        ));
        rgb.par_chunks_mut(3).for_each(|c| {
            let v = Vec3::new(
                f32::from(c[0]) / 127.5 - 1.0,
                f32::from(c[1]) / 127.5 - 1.0,
                f32::from(c[2]) / 127.5 - 1.0,
            );
            let v = Vec3::new(v.x * scale, v.y * scale, v.z)
                .try_normalize()
                .unwrap_or(Vec3::Z);
            for (k, x) in v.to_array().into_iter().enumerate() {
                c[k] = ((x + 1.0) * 127.5).round().clamp(0.0, 255.0) as u8;
            }
        });
    }
    NormalMap::new(rgb).map_err(|reason| ModelError::Image {
        path: PathBuf::from(name),
        reason,
    })
}

/// The normal map in the image file at `path` ([`normal_map`] with scale 1), read with the
/// import limits.
///
/// # Errors
/// A file that does not read, or too large.
pub fn normal_map_file(path: &Path, notes: &mut Vec<String>) -> Result<NormalMap, ModelError> {
    let image = read_image(path)?;
    normal_map(&image, 1.0, &file_name(path), notes)
}

/// The file name of a path, for messages.
pub fn file_name(path: &std::path::Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}
