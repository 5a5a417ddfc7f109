//! Writing a project: channels to rasters and PNGs, the manifest, and the zip around them.

use std::io::{Seek, Write};

use image::{ImageBuffer, Luma, Rgb};
use rayon::prelude::*;

use super::{
    ChannelEntry, FORMAT, Manifest, N_ENCODING, RGB_ENCODING, Raster, VERSION, parse_manifest,
    valid_n_bits,
};
use crate::document::{Document, DocumentSettings};
use crate::maps::MaterialMaps;
use crate::tile::{Plane, TILE_SIZE, Tile};

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

/// The three channels of `maps` as rasters (a constant where uniform), named `{prefix}kd`,
/// `{prefix}ks` and `{prefix}n`.
fn channel_rasters(maps: &MaterialMaps, prefix: &str) -> [(String, Raster); 3] {
    [
        (
            format!("{prefix}kd"),
            channel_uniform(maps, |t| &t.kd).map_or_else(
                || Raster::Rgb(rasterize::<3, _>(maps, |t| &t.kd, |v| v)),
                |v| Raster::Uniform(v.to_vec()),
            ),
        ),
        (
            format!("{prefix}ks"),
            channel_uniform(maps, |t| &t.ks).map_or_else(
                || Raster::Rgb(rasterize::<3, _>(maps, |t| &t.ks, |v| v)),
                |v| Raster::Uniform(v.to_vec()),
            ),
        ),
        (
            format!("{prefix}n"),
            channel_uniform(maps, |t| &t.n).map_or_else(
                || Raster::Gray(rasterize::<1, _>(maps, |t| &t.n, |v| [v])),
                |v| Raster::Uniform(vec![v]),
            ),
        ),
    ]
}

/// How the manifest names a raster.
fn entry((name, raster): &(String, Raster)) -> ChannelEntry {
    match raster {
        Raster::Uniform(v) => ChannelEntry::Uniform { value: v.clone() },
        Raster::Rgb(_) => ChannelEntry::Image {
            file: format!("{name}.png"),
            encoding: RGB_ENCODING.into(),
        },
        Raster::Gray(_) => ChannelEntry::Image {
            file: format!("{name}.png"),
            encoding: N_ENCODING.into(),
        },
    }
}

/// Why a project was not written.
pub(super) enum WriteFailure {
    /// The document holds what a project cannot (the loader would refuse it): which field.
    Unloadable(String),
    /// Encoding or writing failed.
    Other(String),
}

impl From<String> for WriteFailure {
    fn from(e: String) -> Self {
        Self::Other(e)
    }
}

impl WriteFailure {
    /// As one line.
    pub(super) fn into_text(self) -> String {
        match self {
            Self::Unloadable(e) => format!("the project would not load back ({e})"),
            Self::Other(e) => e,
        }
    }
}

/// Serialises a document into project bytes (what [`save`](super::save) writes).
pub fn to_bytes(doc: &Document) -> Result<Vec<u8>, String> {
    let mut cursor = std::io::Cursor::new(Vec::new());
    write_to(doc, &mut cursor)?;
    Ok(cursor.into_inner())
}

/// Serialises a document as a project into `out` (its mesh path as the document holds it).
pub fn write_to(doc: &Document, out: impl Write + Seek) -> Result<(), String> {
    write_project(doc, doc.settings().clone(), out).map_err(WriteFailure::into_text)
}

/// Serialises a document with `settings` into `out`.
pub(super) fn write_project(
    doc: &Document,
    settings: DocumentSettings,
    out: impl Write + Seek,
) -> Result<(), WriteFailure> {
    let maps = doc.maps();
    let (w, h) = (maps.width(), maps.height());
    let mut rasters: Vec<(String, Raster)> = channel_rasters(maps, "").into();
    // Each raster's size: the map's, or a layer's atlas.
    let mut sizes = vec![(w, h); 3];
    let layer_maps = super::layers::layer_maps(doc.stack())?;
    let mut stored = Vec::new();
    for l in &layer_maps {
        let mut planes = None;
        if let (Some(v), Some(a)) = (&l.values, &l.alpha) {
            let at = rasters.len();
            rasters.extend(channel_rasters(v, &format!("{}_", l.stem)));
            let [alpha, _, _] = channel_rasters(a, &format!("{}_alpha_", l.stem));
            rasters.push(alpha);
            sizes.extend([(v.width(), v.height()); 4]);
            planes = Some(super::layers::PlanesEntry {
                kd: entry(&rasters[at]),
                ks: entry(&rasters[at + 1]),
                n: entry(&rasters[at + 2]),
                alpha: entry(&rasters[at + 3]),
                tiles: Some(l.tiles.clone()),
            });
        }
        let mask = l.mask.as_ref().map(|m| {
            let [gray, _, _] = channel_rasters(m, &format!("{}_mask_", l.stem));
            let e = entry(&gray);
            rasters.push(gray);
            sizes.push((m.width(), m.height()));
            super::layers::MaskEntry {
                enabled: true,
                inverted: false,
                gray: e,
                tiles: Some(l.mask_tiles.clone()),
                fill: Some(l.mask_fill),
                generator: None,
            }
        });
        stored.push((planes, mask));
    }
    let pngs: Vec<Result<Vec<u8>, String>> = rasters
        .par_iter()
        .zip(&sizes)
        .map(|((_, r), &(w, h))| encode_png(r, w, h))
        .collect();
    let layers = super::layers::entries(&doc.stack().layers, &mut 0, &|k| stored[k].clone());
    let files = projection_files(&layer_maps)?;
    let kept_mesh = kept_mesh(doc, &settings)?;
    let manifest = Manifest {
        format: FORMAT.into(),
        version: version_of(&layers, kept_mesh.is_some(), doc.bakes()),
        width: w,
        height: h,
        settings,
        kd: entry(&rasters[0]),
        ks: entry(&rasters[1]),
        n: entry(&rasters[2]),
        base: Some(doc.stack().base),
        layers: Some(layers),
        normal: doc.normal().map(|m| super::NormalEntry {
            file: super::NORMAL_FILE.into(),
            encoding: super::NORMAL_ENCODING.into(),
            width: m.width(),
            height: m.height(),
        }),
        id: Some(doc.id().to_hex()),
        selection: Some(super::SelectionEntry::of(&doc.selection())),
        mesh: kept_mesh.as_ref().map(|(_, triangles)| super::MeshEntry {
            file: super::MESH_FILE.into(),
            triangles: *triangles,
        }),
        bakes: super::bakes::entries(doc.bakes()),
    };
    let json = serde_json::to_vec_pretty(&manifest).map_err(|e| e.to_string())?;
    // Never write what the loader would refuse: the manifest goes through the loader's own
    // checks, and every stored exponent through its test, before a byte is written.
    parse_manifest(&json).map_err(WriteFailure::Unloadable)?;
    let mut all_maps = vec![maps];
    all_maps.extend(layer_maps.iter().filter_map(|l| l.values.as_ref()));
    if let Some(bits) = all_maps.into_iter().find_map(invalid_n_in) {
        return Err(WriteFailure::Unloadable(format!(
            "n holds half-float bits {bits:#06x}"
        )));
    }
    let pngs = pngs.into_iter().collect::<Result<Vec<_>, String>>()?;
    let stored = Stored {
        rasters: &rasters,
        pngs: &pngs,
        files: &files,
    };
    write_archive(out, &json, &stored, doc, kept_mesh.as_ref())
}

/// The archive: the manifest, every channel that is not one value, the normal map and the
/// kept mesh.
fn write_archive(
    out: impl Write + Seek,
    json: &[u8],
    stored: &Stored<'_>,
    doc: &Document,
    kept_mesh: Option<&(String, u64)>,
) -> Result<(), WriteFailure> {
    let mut zip = zip::ZipWriter::new(out);
    let deflated = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    let stored_file = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .large_file(true);
    zip.start_file("manifest.json", deflated)
        .map_err(|e| e.to_string())?;
    zip.write_all(json).map_err(|e| e.to_string())?;
    for ((name, raster), png) in stored.rasters.iter().zip(stored.pngs) {
        if !matches!(raster, Raster::Uniform(_)) {
            zip.start_file(format!("{name}.png"), stored_file)
                .map_err(|e| e.to_string())?;
            zip.write_all(png).map_err(|e| e.to_string())?;
        }
    }
    for (name, bytes) in stored.files {
        zip.start_file(name, stored_file)
            .map_err(|e| e.to_string())?;
        zip.write_all(bytes).map_err(|e| e.to_string())?;
    }
    if let Some(normal) = doc.normal() {
        let png = normal.to_png()?;
        zip.start_file(super::NORMAL_FILE, stored_file)
            .map_err(|e| e.to_string())?;
        zip.write_all(&png).map_err(|e| e.to_string())?;
    }
    if let Some((obj, _)) = kept_mesh {
        zip.start_file(super::MESH_FILE, deflated)
            .map_err(|e| e.to_string())?;
        zip.write_all(obj.as_bytes()).map_err(|e| e.to_string())?;
    }
    for bake in doc.bakes() {
        let png = super::bakes::to_png(bake)?;
        zip.start_file(super::bakes::file_of(bake.map), stored_file)
            .map_err(|e| e.to_string())?;
        zip.write_all(&png).map_err(|e| e.to_string())?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    Ok(())
}

/// The mesh the project keeps, as OBJ text, and its triangles; none unless the settings name
/// an embedded mesh, which the document must then hold.
fn kept_mesh(
    doc: &Document,
    settings: &DocumentSettings,
) -> Result<Option<(String, u64)>, WriteFailure> {
    if !settings.mesh.is_embedded() {
        return Ok(None);
    }
    let mesh = doc.embedded_mesh().ok_or_else(|| {
        WriteFailure::Unloadable(format!(
            "the project's mesh {} is to be kept inside it, but the document holds no mesh",
            settings.mesh.spec()
        ))
    })?;
    Ok(Some((
        kapaint_mesh::write_obj(mesh),
        mesh.triangles.len() as u64,
    )))
}

/// The first stored exponent the loader would refuse, if any (none ever should be: every
/// writer encodes through [`crate::texel::encode_n`]).
fn invalid_n_in(maps: &MaterialMaps) -> Option<u16> {
    (0..maps.tile_count())
        .into_par_iter()
        .find_map_any(|id| match &maps.tile(id).n {
            Plane::Uniform(bits) => (!valid_n_bits(*bits)).then_some(*bits),
            Plane::Data(d) => d.iter().copied().find(|&bits| !valid_n_bits(bits)),
        })
}

/// What the archive holds besides the manifest, the normal map, the mesh and the bakes: the
/// channel rasters (as PNGs where not uniform) and other files, named.
struct Stored<'a> {
    rasters: &'a [(String, Raster)],
    pngs: &'a [Vec<u8>],
    files: &'a [(String, Vec<u8>)],
}

/// The oldest version that holds what `layers` hold, a kept mesh where `mesh`, and `bakes`.
fn version_of(
    layers: &[super::layers::LayerEntry],
    mesh: bool,
    bakes: &[std::sync::Arc<kapaint_mesh::bakes::Baked>],
) -> u32 {
    if bakes.iter().any(|b| b.from_high.is_some()) {
        VERSION
    } else if super::layers::any_projection(layers) {
        super::PROJECTION_VERSION
    } else if super::layers::any_generator(layers) {
        super::GENERATOR_VERSION
    } else if mesh || !bakes.is_empty() {
        super::MESH_VERSION
    } else {
        super::LAYERS_VERSION
    }
}

/// The projection fills' images, each under the names its entry gives it.
fn projection_files(
    layer_maps: &[super::layers::LayerMaps],
) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut files = Vec::new();
    for l in layer_maps {
        if let Some(pixels) = &l.projection {
            let names = super::layers::projection_files(&l.stem);
            files.extend(names.into_iter().zip(super::images::encode(pixels)?));
        }
    }
    Ok(files)
}
