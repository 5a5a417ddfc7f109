//! Reading a set (`material.json` and its images) back into a document.

use std::path::Path;

use glam::Vec3;
use rayon::prelude::*;

use super::manifest::{ColourSpace, Comp, Compression, Manifest};
use super::{SetError, io};
use kapaint_model::texel::{MaterialValue, Texel, srgb_to_linear};
use kapaint_model::{Document, DocumentSettings, MaterialMaps};

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
        let bytes =
            kapaint_base::file_check::read_limited(path, kapaint_model::import::MAX_DECODED_BYTES)
                .map_err(|e| {
                    if e.is_io() {
                        io(path, e)
                    } else {
                        invalid(format!("the file {e}"))
                    }
                })?;
        let decoded = crate::ktx::decode(&bytes).map_err(invalid)?;
        Ok((true, (decoded.width, decoded.height), decoded.rgba))
    } else {
        let image = kapaint_model::import::read_image(path).map_err(|e| invalid(e.to_string()))?;
        Ok((
            false,
            (image.width(), image.height()),
            image.to_rgba32f().into_raw(),
        ))
    }
}

/// Reads a set's maps back as a consumer would (no settings).
fn read_maps(manifest: &Manifest, dir: &Path) -> Result<MaterialMaps, SetError> {
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
        read_file(&mut values, manifest, dir, file)?;
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

fn invalid(path: &Path, reason: String) -> SetError {
    SetError::Invalid {
        path: path.to_path_buf(),
        reason,
    }
}

/// Reads one image of the set into the components of `values` it holds.
fn read_file(
    values: &mut [MaterialValue],
    manifest: &Manifest,
    dir: &Path,
    file: &super::FileEntry,
) -> Result<(), SetError> {
    let (w, h) = (manifest.width, manifest.height);
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
        .map(|c| Comp::parse(c).ok_or_else(|| invalid(&path, format!("unknown component {c:?}"))))
        .collect::<Result<_, _>>()?;
    let srgb = file.colour_space == ColourSpace::Srgb;
    let exr = file.compression == Compression::Exr;
    // Two-component ASTC and UASTC images are luminance + alpha, as grey + alpha PNGs.
    let second_in_alpha = !exr && (!ktx || file.compression.second_in_alpha());
    let n_enc = manifest.n_encoding;
    let n_codes: Vec<f32> = n_enc.map_or_else(Vec::new, |e| {
        (0..=((1_u32 << e.bits) - 1) as u16)
            .map(|q| e.decode(q))
            .collect()
    });
    let srgb8: Vec<f32> = (0..=255_u8)
        .map(|v| srgb_to_linear(f32::from(v) / 255.0))
        .collect();
    let colour = |x: f32| {
        if srgb {
            srgb8[(x.clamp(0.0, 1.0) * 255.0).round() as usize]
        } else {
            x
        }
    };
    values
        .par_iter_mut()
        .zip(pixels.par_chunks(4))
        .for_each(|(v, px)| {
            for (k, comp) in comps.iter().enumerate() {
                // EXR one-component images repeat the value, grey + alpha PNGs and ASTC
                // read as (L, L, L, A); others hold components in order.
                let raw = match (comps.len(), k) {
                    (1, _) if exr => px[0],
                    (2, 1) if second_in_alpha => px[3],
                    _ => px[k.min(3)],
                };
                match *comp {
                    Comp::Kd(c) => v.kd[c] = colour(raw),
                    Comp::Ks(3) => v.ks = Vec3::splat(colour(raw)),
                    Comp::Ks(c) => v.ks[c] = colour(raw),
                    Comp::N => {
                        v.n = match n_enc {
                            Some(e) => {
                                let q =
                                    (raw.clamp(0.0, 1.0) * ((1_u32 << e.bits) - 1) as f32).round();
                                n_codes[q as usize]
                            }
                            None => raw,
                        };
                    }
                    Comp::Ka(_) => {}
                }
            }
        });
    Ok(())
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
    let approx = manifest.approximation.name;
    let settings = DocumentSettings {
        model: manifest.model,
        approx,
        ..DocumentSettings::default()
    };
    let normal = match &manifest.normal {
        None => None,
        Some(n) => Some(std::sync::Arc::new(n.read(dir)?)),
    };
    Ok(Document::from_parts(maps, settings).with_normal(normal))
}

/// Largest manifest read (bytes).
const MAX_MANIFEST_BYTES: u64 = 4 << 20;

/// The manifest's bytes: a regular file of at most [`MAX_MANIFEST_BYTES`].
fn read_manifest_bytes(path: &Path) -> Result<Vec<u8>, SetError> {
    kapaint_base::file_check::read_limited(path, MAX_MANIFEST_BYTES).map_err(|e| {
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
