//! The `.kapaint` project file.
//!
//! A zip archive holding `manifest.json` (format name, version, size, document settings, and
//! how each channel is stored) and one 16-bit lossless PNG per channel that is not uniform:
//! `kd.png` and `ks.png` as linear unorm16 RGB, `n.png` as 16-bit gray holding half-float
//! bits. A channel that is the same everywhere is a constant in the manifest instead.
//!
//! Saving writes a temporary file beside the target, flushes it to disk and renames it over
//! the target, so a crash or a full disk never leaves a half-written project. Loading checks
//! everything (zip and PNG checksums, sizes, colour types, every stored value) and reports
//! the first problem as one error; it never panics on any input.

use std::fs::File;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use image::{ImageBuffer, Luma, Rgb};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::ModelError;
use super::document::{Document, DocumentSettings, MeshRef};
use super::maps::{MAX_SIDE, MaterialMaps};
use super::texel::{MaterialValue, N_MAX};
use super::tile::{Plane, TILE_SIZE, Tile};

/// The format name in the manifest.
pub const FORMAT: &str = "kapaint-project";

/// The manifest version this build writes and reads.
pub const VERSION: u32 = 1;

/// Largest manifest accepted (bytes).
const MAX_MANIFEST_BYTES: u64 = 4 << 20;

/// How one channel is stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum ChannelEntry {
    /// The same stored value at every texel (unorm16 RGB, or half-float bits for `n`).
    Uniform {
        /// The stored value: three components for `kd`/`ks`, one for `n`.
        value: Vec<u16>,
    },
    /// A PNG in the archive.
    Image {
        /// Entry name in the archive.
        file: String,
        /// How the PNG's samples are to be read.
        encoding: String,
    },
}

/// `manifest.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// Manifest version.
    pub version: u32,
    /// Map width in texels.
    pub width: u32,
    /// Map height in texels.
    pub height: u32,
    /// Model, approximation, materials, brush, mesh reference.
    pub settings: DocumentSettings,
    /// `k_d` storage.
    pub kd: ChannelEntry,
    /// `k_s` storage.
    pub ks: ChannelEntry,
    /// `n` storage.
    pub n: ChannelEntry,
}

const RGB_ENCODING: &str = "png-rgb16-unorm-linear";
const N_ENCODING: &str = "png-gray16-half-float-bits";

/// One channel of the whole map, row-major.
enum Raster {
    Uniform(Vec<u16>),
    Rgb(Vec<u16>),
    Gray(Vec<u16>),
}

fn channel_uniform<T: Copy + PartialEq>(
    maps: &MaterialMaps,
    plane: impl Fn(&Tile) -> &Plane<T>,
) -> Option<T> {
    let first = plane(maps.tile(0)).uniform()?;
    (0..maps.tile_count())
        .all(|id| plane(maps.tile(id)).uniform() == Some(first))
        .then_some(first)
}

/// Copies a channel of every tile into a row-major raster of `C` samples per texel.
fn rasterize<const C: usize, T: Copy + PartialEq + Send + Sync>(
    maps: &MaterialMaps,
    plane: impl Fn(&Tile) -> &Plane<T> + Sync,
    samples: impl Fn(T) -> [u16; C] + Sync,
) -> Vec<u16> {
    let (w, h) = (maps.width() as usize, maps.height() as usize);
    let mut out = vec![0u16; w * h * C];
    out.par_chunks_mut(w * C * TILE_SIZE)
        .enumerate()
        .for_each(|(ty, band)| {
            let rows = band.len() / (w * C);
            for tx in 0..maps.tiles_x() as usize {
                let tile = maps.tile(ty * maps.tiles_x() as usize + tx);
                let p = plane(tile);
                let x0 = tx * TILE_SIZE;
                let cols = TILE_SIZE.min(w - x0);
                for r in 0..rows {
                    for c in 0..cols {
                        let s = samples(p.get(r * TILE_SIZE + c));
                        let at = (r * w + x0 + c) * C;
                        band[at..at + C].copy_from_slice(&s);
                    }
                }
            }
        });
    out
}

fn encode_png(raster: &Raster, width: u32, height: u32) -> Result<Vec<u8>, String> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut bytes = Vec::new();
    let encoder = PngEncoder::new_with_quality(&mut bytes, CompressionType::Fast, FilterType::Up);
    let result = match raster {
        Raster::Rgb(data) => {
            ImageBuffer::<Rgb<u16>, &[u16]>::from_raw(width, height, data.as_slice())
                .ok_or("raster size mismatch")?
                .write_with_encoder(encoder)
        }
        Raster::Gray(data) => {
            ImageBuffer::<Luma<u16>, &[u16]>::from_raw(width, height, data.as_slice())
                .ok_or("raster size mismatch")?
                .write_with_encoder(encoder)
        }
        Raster::Uniform(_) => return Ok(Vec::new()),
    };
    result.map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// Serialises a document into project bytes (what [`save`] writes).
pub fn to_bytes(doc: &Document) -> Result<Vec<u8>, String> {
    let mut cursor = std::io::Cursor::new(Vec::new());
    write_to(doc, &mut cursor)?;
    Ok(cursor.into_inner())
}

/// Serialises a document as a project into `out` (its mesh path as the document holds it).
pub fn write_to(doc: &Document, out: impl Write + Seek) -> Result<(), String> {
    write_project(doc, doc.settings().clone(), out)
}

/// The settings as a project at `project` stores them: a mesh file's path relative to the
/// project's folder (so a project and its mesh can move together, and commands run from any
/// folder find it), or absolute where no relative path exists.
fn settings_for_file(settings: &DocumentSettings, project: &Path) -> DocumentSettings {
    let mut stored = settings.clone();
    if let MeshRef::File(mesh) = &settings.mesh
        && let (Ok(mesh_abs), Ok(dir_abs)) = (
            std::path::absolute(mesh),
            std::path::absolute(project_dir(project)),
        )
    {
        let relative = relative_path(&dir_abs, &mesh_abs).unwrap_or(mesh_abs);
        stored.mesh = MeshRef::File(relative.to_string_lossy().into_owned());
    }
    stored
}

/// The settings as loaded from a project at `project`: a relative mesh path is taken from the
/// project's folder (projects written before paths were stored that way held paths relative
/// to the folder they were made in: those are tried there too), and held absolute.
pub(super) fn settings_from_file(
    mut settings: DocumentSettings,
    project: &Path,
) -> DocumentSettings {
    if let MeshRef::File(mesh) = &settings.mesh {
        let mesh = Path::new(mesh);
        if mesh.is_relative() {
            let beside = project_dir(project).join(mesh);
            let found = if beside.exists() || !mesh.exists() {
                beside
            } else {
                mesh.to_path_buf()
            };
            let found = std::path::absolute(&found).unwrap_or(found);
            settings.mesh = MeshRef::File(found.to_string_lossy().into_owned());
        }
    }
    settings
}

/// The folder a project is in (`.` for a bare file name).
fn project_dir(project: &Path) -> &Path {
    project
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `target` relative to the folder `base` (both absolute), by their components: `None` when
/// they share no root (another drive).
fn relative_path(base: &Path, target: &Path) -> Option<PathBuf> {
    use std::path::Component;
    fn normal(p: &Path) -> Vec<Component<'_>> {
        let mut out: Vec<Component<'_>> = Vec::new();
        for c in p.components() {
            match c {
                Component::CurDir => {}
                Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                    out.pop();
                }
                other => out.push(other),
            }
        }
        out
    }
    let (base, target) = (normal(base), normal(target));
    if base.first() != target.first() {
        return None;
    }
    let common = base.iter().zip(&target).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..base.len() {
        out.push("..");
    }
    for c in &target[common..] {
        out.push(c.as_os_str());
    }
    Some(out)
}

/// Serialises a document with `settings` into `out`.
fn write_project(
    doc: &Document,
    settings: DocumentSettings,
    out: impl Write + Seek,
) -> Result<(), String> {
    let maps = doc.maps();
    let (w, h) = (maps.width(), maps.height());
    let rasters: Vec<(&str, Raster)> = vec![
        (
            "kd",
            channel_uniform(maps, |t| &t.kd).map_or_else(
                || Raster::Rgb(rasterize::<3, _>(maps, |t| &t.kd, |v| v)),
                |v| Raster::Uniform(v.to_vec()),
            ),
        ),
        (
            "ks",
            channel_uniform(maps, |t| &t.ks).map_or_else(
                || Raster::Rgb(rasterize::<3, _>(maps, |t| &t.ks, |v| v)),
                |v| Raster::Uniform(v.to_vec()),
            ),
        ),
        (
            "n",
            channel_uniform(maps, |t| &t.n).map_or_else(
                || Raster::Gray(rasterize::<1, _>(maps, |t| &t.n, |v| [v])),
                |v| Raster::Uniform(vec![v]),
            ),
        ),
    ];
    let pngs: Vec<Result<Vec<u8>, String>> = rasters
        .par_iter()
        .map(|(_, r)| encode_png(r, w, h))
        .collect();
    let entry = |(name, raster): &(&str, Raster)| match raster {
        Raster::Uniform(v) => ChannelEntry::Uniform { value: v.clone() },
        Raster::Rgb(_) => ChannelEntry::Image {
            file: format!("{name}.png"),
            encoding: RGB_ENCODING.into(),
        },
        Raster::Gray(_) => ChannelEntry::Image {
            file: format!("{name}.png"),
            encoding: N_ENCODING.into(),
        },
    };
    let manifest = Manifest {
        format: FORMAT.into(),
        version: VERSION,
        width: w,
        height: h,
        settings,
        kd: entry(&rasters[0]),
        ks: entry(&rasters[1]),
        n: entry(&rasters[2]),
    };
    let json = serde_json::to_vec_pretty(&manifest).map_err(|e| e.to_string())?;
    // Never write what the loader would refuse: the manifest goes through the loader's own
    // checks, and every stored exponent through its test, before a byte is written.
    parse_manifest(&json).map_err(|e| format!("the project would not load back ({e})"))?;
    if let Some(bits) = invalid_n_in(maps) {
        return Err(format!(
            "the project would not load back (n holds half-float bits {bits:#06x})"
        ));
    }
    let mut zip = zip::ZipWriter::new(out);
    let deflated = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    let stored = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .large_file(true);
    zip.start_file("manifest.json", deflated)
        .map_err(|e| e.to_string())?;
    zip.write_all(&json).map_err(|e| e.to_string())?;
    for ((name, raster), png) in rasters.iter().zip(pngs) {
        let png = png?;
        if !matches!(raster, Raster::Uniform(_)) {
            zip.start_file(format!("{name}.png"), stored)
                .map_err(|e| e.to_string())?;
            zip.write_all(&png).map_err(|e| e.to_string())?;
        }
    }
    zip.finish().map_err(|e| e.to_string())?;
    Ok(())
}

/// Saves a document to `path` atomically.
pub fn save(doc: &Document, path: &Path) -> Result<(), ModelError> {
    // A serialisation failure (e.g. the disk filling up inside the zip writer) is reported as
    // an I/O error on the file, like any other write failure.
    crate::atomic::write_atomic_with(path, |file| {
        // The first write error (a full disk) is the one reported; the zip writer then
        // finishes quietly instead of printing its own failure.
        let mut out = crate::atomic::FirstError::new(file);
        let written = write_project(doc, settings_for_file(doc.settings(), path), &mut out);
        if let Some(e) = out.take_error() {
            return Err(e);
        }
        written.map_err(std::io::Error::other)
    })
    .map_err(|e| ModelError::io(path, e))
}

/// Loads `mesh` (a built-in name or a mesh file), bakes it at the document's size and
/// attaches it: what strokes on the mesh and island fills paint on.
///
/// # Errors
/// A mesh that does not load (an I/O error as [`ModelError::Io`]), has no UVs, or does not
/// bake; the document is unchanged.
pub fn attach_mesh(doc: &mut Document, mesh: &Path) -> Result<(), ModelError> {
    use crate::mesh::MeshError;
    let loaded = crate::mesh::open(mesh).map_err(|e| match e {
        MeshError::Io { path, source } => ModelError::Io { path, source },
        invalid @ MeshError::Invalid { .. } => ModelError::Command(invalid.to_string()),
    })?;
    let surface = super::surface::Surface::new(loaded, doc.maps().width(), doc.maps().height())
        .map_err(|e| ModelError::Command(format!("{}: {e}", mesh.display())))?;
    doc.set_surface(Some(std::sync::Arc::new(surface)))
}

/// Opens a project with its mesh attached (`mesh` instead of the project's own, when given):
/// the document, and why the mesh could not be attached when it could not (the document
/// then has no surface, and the caller decides: the editor shows the sphere, `export` skips
/// padding, `paint` refuses strokes on the mesh).
///
/// # Errors
/// A project that does not load.
pub fn open_with_mesh(
    path: &Path,
    mesh: Option<&Path>,
) -> Result<(Document, Option<ModelError>), ModelError> {
    let mut doc = load(path)?;
    let own = PathBuf::from(doc.settings().mesh.spec());
    let failed = attach_mesh(&mut doc, mesh.unwrap_or(&own)).err();
    Ok((doc, failed))
}

/// Largest project file read (bytes): an 8192^2 project of noise is about 1 GB.
pub const MAX_PROJECT_BYTES: u64 = 4 << 30;

/// Loads and validates a project file (a regular file: a FIFO or a device is refused before
/// it is opened).
pub fn load(path: &Path) -> Result<Document, ModelError> {
    crate::file_check::regular_file(path, MAX_PROJECT_BYTES).map_err(|e| match e {
        crate::file_check::FileCheck::Io(source) => ModelError::io(path, source),
        other => ModelError::Project {
            path: path.to_path_buf(),
            reason: format!("the file {other}"),
        },
    })?;
    let file = File::open(path).map_err(|e| ModelError::io(path, e))?;
    let doc = from_reader(file).map_err(|reason| ModelError::Project {
        path: path.to_path_buf(),
        reason,
    })?;
    let (maps, settings) = doc.into_parts();
    Ok(Document::from_parts(
        maps,
        settings_from_file(settings, path),
    ))
}

/// Loads and validates a project from any seekable reader; the error is a reason text.
pub fn from_reader(reader: impl Read + Seek) -> Result<Document, String> {
    let mut zip = zip::ZipArchive::new(reader).map_err(|e| format!("not a zip archive ({e})"))?;
    let manifest = {
        let entry = zip
            .by_name("manifest.json")
            .map_err(|e| format!("manifest.json: {e}"))?;
        if entry.size() > MAX_MANIFEST_BYTES {
            return Err(format!(
                "manifest.json is {} bytes, more than the limit",
                entry.size()
            ));
        }
        let mut text = Vec::new();
        entry
            .take(MAX_MANIFEST_BYTES)
            .read_to_end(&mut text)
            .map_err(|e| format!("manifest.json: {e}"))?;
        parse_manifest(&text)?
    };
    let (w, h) = (manifest.width, manifest.height);
    let kd = read_channel(&mut zip, &manifest.kd, "kd", w, h, 3)?;
    let ks = read_channel(&mut zip, &manifest.ks, "ks", w, h, 3)?;
    let n = read_channel(&mut zip, &manifest.n, "n", w, h, 1)?;
    let n_samples = match &n {
        Raster::Uniform(v) | Raster::Gray(v) | Raster::Rgb(v) => v,
    };
    if let Some(bad) = n_samples.par_iter().find_any(|&&bits| !valid_n_bits(bits)) {
        return Err(format!(
            "n holds an invalid exponent (half-float bits {bad:#06x})"
        ));
    }
    let settings = manifest.settings;
    let mut maps = MaterialMaps::new(w, h, MaterialValue::default()).map_err(|e| e.to_string())?;
    fill_maps(&mut maps, &kd, &ks, &n);
    Ok(Document::from_parts(maps, settings))
}

/// Whether half-float bits hold a storable exponent: finite, not negative, at most `N_MAX`.
pub(super) fn valid_n_bits(bits: u16) -> bool {
    let v = half::f16::from_bits(bits).to_f32();
    v.is_finite() && (0.0..=N_MAX).contains(&v) && bits & 0x8000 == 0
}

/// Parses `manifest.json` and checks what it says about the project as a whole (format,
/// version, size); every field was checked as it was read.
fn parse_manifest(json: &[u8]) -> Result<Manifest, String> {
    let manifest: Manifest =
        serde_json::from_slice(json).map_err(|e| format!("manifest.json: {e}"))?;
    if manifest.format != FORMAT {
        return Err(format!(
            "manifest format is {:?}, expected {FORMAT:?}",
            manifest.format
        ));
    }
    if manifest.version != VERSION {
        return Err(format!(
            "project version {} is not supported (this build reads version {VERSION})",
            manifest.version
        ));
    }
    let (w, h) = (manifest.width, manifest.height);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(format!("map size {w}x{h} is out of range"));
    }
    Ok(manifest)
}

/// The first stored exponent the loader would refuse, if any (none ever should be: every
/// writer encodes through [`super::texel::encode_n`]).
fn invalid_n_in(maps: &MaterialMaps) -> Option<u16> {
    (0..maps.tile_count())
        .into_par_iter()
        .find_map_any(|id| match &maps.tile(id).n {
            Plane::Uniform(bits) => (!valid_n_bits(*bits)).then_some(*bits),
            Plane::Data(d) => d.iter().copied().find(|&bits| !valid_n_bits(bits)),
        })
}

fn read_channel<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    entry: &ChannelEntry,
    name: &str,
    w: u32,
    h: u32,
    components: usize,
) -> Result<Raster, String> {
    match entry {
        ChannelEntry::Uniform { value } => {
            if value.len() != components {
                return Err(format!(
                    "{name}: uniform value has {} components, expected {components}",
                    value.len()
                ));
            }
            Ok(Raster::Uniform(value.clone()))
        }
        ChannelEntry::Image { file, encoding } => {
            let expected = if components == 3 {
                RGB_ENCODING
            } else {
                N_ENCODING
            };
            if encoding != expected {
                return Err(format!(
                    "{file}: encoding {encoding:?} is not supported for {name}"
                ));
            }
            let mut entry = zip.by_name(file).map_err(|e| format!("{file}: {e}"))?;
            // A 16-bit PNG of this size can never need more than this.
            let limit = u64::from(w) * u64::from(h) * components as u64 * 2 * 2 + (1 << 20);
            if entry.size() > limit {
                return Err(format!(
                    "{file} claims {} bytes, more than a {w}x{h} map can need",
                    entry.size()
                ));
            }
            let mut bytes = Vec::with_capacity(entry.size() as usize);
            (&mut entry)
                .take(limit)
                .read_to_end(&mut bytes)
                .map_err(|e| format!("{file}: {e}"))?;
            let mut reader = image::ImageReader::with_format(
                std::io::Cursor::new(bytes),
                image::ImageFormat::Png,
            );
            let mut limits = image::Limits::default();
            limits.max_image_width = Some(w);
            limits.max_image_height = Some(h);
            limits.max_alloc = Some(limit);
            reader.limits(limits);
            let image = reader.decode().map_err(|e| format!("{file}: {e}"))?;
            if (image.width(), image.height()) != (w, h) {
                return Err(format!(
                    "{file} is {}x{}, the manifest says {w}x{h}",
                    image.width(),
                    image.height()
                ));
            }
            match (components, image) {
                (3, image::DynamicImage::ImageRgb16(img)) => Ok(Raster::Rgb(img.into_raw())),
                (1, image::DynamicImage::ImageLuma16(img)) => Ok(Raster::Gray(img.into_raw())),
                (_, other) => Err(format!(
                    "{file} has colour type {:?}, expected 16-bit {}",
                    other.color(),
                    if components == 3 { "RGB" } else { "gray" }
                )),
            }
        }
    }
}

fn fill_maps(maps: &mut MaterialMaps, kd: &Raster, ks: &Raster, n: &Raster) {
    let w = maps.width() as usize;
    let rgb_plane =
        |r: &Raster, x0: usize, y0: usize, cols: usize, rows: usize| -> Plane<[u16; 3]> {
            match r {
                Raster::Uniform(v) => Plane::Uniform([v[0], v[1], v[2]]),
                Raster::Rgb(d) | Raster::Gray(d) => {
                    let mut p = Plane::Uniform([0; 3]);
                    let data = p.data_mut();
                    for y in 0..rows {
                        for x in 0..cols {
                            let at = ((y0 + y) * w + x0 + x) * 3;
                            data[y * TILE_SIZE + x] = [d[at], d[at + 1], d[at + 2]];
                        }
                    }
                    p.compact();
                    p
                }
            }
        };
    let tiles: Vec<Tile> = (0..maps.tile_count())
        .into_par_iter()
        .map(|id| {
            let (x0, y0, x1, y1) = maps.tile_rect(id);
            let (x0, y0, cols, rows) = (
                x0 as usize,
                y0 as usize,
                (x1 - x0) as usize,
                (y1 - y0) as usize,
            );
            let n_plane = match n {
                Raster::Uniform(v) => Plane::Uniform(v[0]),
                Raster::Gray(d) | Raster::Rgb(d) => {
                    let mut p = Plane::Uniform(0);
                    let data = p.data_mut();
                    for y in 0..rows {
                        data[y * TILE_SIZE..y * TILE_SIZE + cols]
                            .copy_from_slice(&d[(y0 + y) * w + x0..(y0 + y) * w + x0 + cols]);
                    }
                    p.compact();
                    p
                }
            };
            Tile {
                kd: rgb_plane(kd, x0, y0, cols, rows),
                ks: rgb_plane(ks, x0, y0, cols, rows),
                n: n_plane,
            }
        })
        .collect();
    for (id, tile) in tiles.into_iter().enumerate() {
        *maps.tile_mut(id) = tile;
    }
}

/// kapaint's state folder: `$XDG_STATE_HOME/kapaint`, else `~/.local/state/kapaint` (else
/// the temporary folder). It may not exist yet: writers create it.
pub fn state_dir() -> PathBuf {
    std::env::var_os("XDG_STATE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/state")))
        .unwrap_or_else(std::env::temp_dir)
        .join("kapaint")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_paths_are_stored_relative_to_the_project() {
        let rel = |a: &str, b: &str| relative_path(Path::new(a), Path::new(b));
        assert_eq!(
            rel("/w/sub", "/w/barrel.glb"),
            Some(PathBuf::from("../barrel.glb"))
        );
        assert_eq!(rel("/w", "/w/m/x.obj"), Some(PathBuf::from("m/x.obj")));
        assert_eq!(
            rel("/w/a/b", "/w/a/../m.obj"),
            Some(PathBuf::from("../../m.obj"))
        );
        assert_eq!(rel("/w", "/w/./x.obj"), Some(PathBuf::from("x.obj")));
    }
}
