//! The maps baked from a project's mesh, as the project keeps them: a 16-bit PNG each
//! (`bake_MAP.png`, grey, or RGB for position and normal) and an entry in the manifest with
//! the mesh's hash and the rays it was made with.

use std::io::{Read, Seek};
use std::sync::Arc;

use image::{ImageBuffer, Luma, Rgb};
use kapaint_mesh::bakes::{BakeMap, BakeOptions, Baked, FromHigh, RAYS, SAMPLES};

use super::Manifest;

/// The archive entry of a map's bake.
pub(super) fn file_of(map: BakeMap) -> String {
    format!("bake_{}.png", map.name())
}

/// The bake as a 16-bit PNG (grey, or RGB for position and normal): as the project keeps it,
/// and as `kapaint bake --out` writes it.
pub fn to_png(bake: &Baked) -> Result<Vec<u8>, String> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut bytes = Vec::new();
    let encoder = PngEncoder::new_with_quality(&mut bytes, CompressionType::Fast, FilterType::Up);
    let (w, h) = (bake.width, bake.height);
    let result = if bake.map.channels() == 3 {
        ImageBuffer::<Rgb<u16>, &[u16]>::from_raw(w, h, &bake.data)
            .ok_or("bake size mismatch")?
            .write_with_encoder(encoder)
    } else {
        ImageBuffer::<Luma<u16>, &[u16]>::from_raw(w, h, &bake.data)
            .ok_or("bake size mismatch")?
            .write_with_encoder(encoder)
    };
    result.map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// The manifest's entries of `bakes` (none when there are none).
pub(super) fn entries(bakes: &[Arc<Baked>]) -> Option<Vec<super::BakeEntry>> {
    (!bakes.is_empty()).then(|| {
        bakes
            .iter()
            .map(|b| super::BakeEntry {
                map: b.map.name().into(),
                file: file_of(b.map),
                mesh_hash: format!("{:016x}", b.mesh_hash),
                rays: b.options.rays,
                max_distance: b.options.max_distance,
                high: b.from_high.as_ref().map(|h| super::HighEntry {
                    mesh: h.mesh.clone(),
                    mesh_hash: format!("{:016x}", h.mesh_hash),
                    front: h.front,
                    rear: h.rear,
                    samples: h.samples,
                    cage: h.cage.clone(),
                }),
            })
            .collect()
    })
}

/// The bakes the manifest lists, each checked: a known map listed once, its file, a hash,
/// rays and a distance in range, a PNG of the map's size and channels.
pub(super) fn read<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    manifest: &Manifest,
) -> Result<Vec<Arc<Baked>>, String> {
    let Some(entries) = &manifest.bakes else {
        return Ok(Vec::new());
    };
    let mut bakes: Vec<Arc<Baked>> = Vec::new();
    for e in entries {
        let map = BakeMap::ALL
            .iter()
            .find(|(n, _)| *n == e.map)
            .map(|(_, m)| *m)
            .ok_or_else(|| format!("no map is called {:?}", e.map))?;
        if bakes.iter().any(|b| b.map == map) {
            return Err(format!("the {} bake is listed twice", e.map));
        }
        if e.file != file_of(map) {
            return Err(format!(
                "the {} bake is {:?}, expected {:?}",
                e.map,
                e.file,
                file_of(map)
            ));
        }
        let mesh_hash = hash_of(&e.file, &e.mesh_hash)?;
        if !RAYS.contains(&e.rays) {
            return Err(format!("{}: {} rays is out of range", e.file, e.rays));
        }
        if let Some(d) = e.max_distance
            && !(d.is_finite() && d > 0.0)
        {
            return Err(format!(
                "{}: the maximum distance {d} is not a positive number",
                e.file
            ));
        }
        let data = read_png(zip, &e.file, map, manifest.width, manifest.height)?;
        bakes.push(Arc::new(Baked {
            map,
            options: BakeOptions {
                rays: e.rays,
                max_distance: e.max_distance,
            },
            mesh_hash,
            width: manifest.width,
            height: manifest.height,
            data,
            from_high: e.high.as_ref().map(|h| from_high(&e.file, h)).transpose()?,
        }));
    }
    Ok(bakes)
}

/// A 16-hex-digit hash of entry `file`.
fn hash_of(file: &str, hex: &str) -> Result<u64, String> {
    u64::from_str_radix(hex, 16)
        .ok()
        .filter(|_| hex.len() == 16)
        .ok_or_else(|| format!("{file}: the mesh hash {hex:?} is not 16 hex digits"))
}

/// Where entry `file`'s bake came from, checked: a hash, positive finite distances, 1, 4 or
/// 16 samples.
fn from_high(file: &str, h: &super::HighEntry) -> Result<FromHigh, String> {
    for (what, d) in [("front", h.front), ("rear", h.rear)] {
        if !(d.is_finite() && d > 0.0) {
            return Err(format!(
                "{file}: the {what} distance {d} is not a positive number"
            ));
        }
    }
    if !SAMPLES.contains(&h.samples) {
        return Err(format!(
            "{file}: {} samples per texel (1, 4 or 16)",
            h.samples
        ));
    }
    Ok(FromHigh {
        mesh: h.mesh.clone(),
        mesh_hash: hash_of(file, &h.mesh_hash)?,
        front: h.front,
        rear: h.rear,
        samples: h.samples,
        cage: h.cage.clone(),
    })
}

/// A bake's samples from its PNG, which must be the map's size, 16 bits, the map's channels.
fn read_png<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    file: &str,
    map: BakeMap,
    width: u32,
    height: u32,
) -> Result<Vec<u16>, String> {
    let channels = map.channels() as u64;
    let limit = u64::from(width) * u64::from(height) * channels * 2 + (1 << 20);
    let entry = zip.by_name(file).map_err(|e| format!("{file}: {e}"))?;
    if entry.size() > limit {
        return Err(format!(
            "{file} is larger than a {width}x{height} bake can be"
        ));
    }
    let mut bytes = Vec::new();
    entry
        .take(limit)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{file}: {e}"))?;
    let mut decoder = image::ImageReader::new(std::io::Cursor::new(bytes));
    decoder.set_format(image::ImageFormat::Png);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(width);
    limits.max_image_height = Some(height);
    decoder.limits(limits);
    let image = decoder.decode().map_err(|e| format!("{file}: {e}"))?;
    if (image.width(), image.height()) != (width, height) {
        return Err(format!(
            "{file} is {}x{}, the maps are {width}x{height}",
            image.width(),
            image.height()
        ));
    }
    match (map.channels(), image) {
        (1, image::DynamicImage::ImageLuma16(g)) => Ok(g.into_raw()),
        (3, image::DynamicImage::ImageRgb16(rgb)) => Ok(rgb.into_raw()),
        (c, other) => Err(format!(
            "{file} is {:?}, expected 16-bit {}",
            other.color(),
            if c == 3 { "RGB" } else { "grey" }
        )),
    }
}
