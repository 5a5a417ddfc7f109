//! A texture set found by its file names, the way painting tools export them:
//! `wood_BaseColor.png`, `wood_Metallic.png`, `wood_Roughness.png`, `wood_Normal.png` (or
//! `_albedo`, `_metalness`, `_rough`, `_nrm`, a packed `_MetallicRoughness` or `_ORM`, ...).
//! Any one file of the set names it: the others are found beside it by the shared prefix.

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::import::{PbrSet, Source};
use crate::model::ModelError;

/// What a file of a set holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    Base,
    Metallic,
    Roughness,
    /// glTF's packing: roughness in G, metallic in B (also ORM: occlusion in R).
    Packed,
    /// OpenGL convention (+Y up).
    Normal,
    /// DirectX convention (+Y down): green is flipped on import.
    NormalDx,
}

/// Suffixes, normalised (lower case, no separators), longest first within a slot's meaning.
const SUFFIXES: &[(&str, Slot)] = &[
    ("occlusionroughnessmetallic", Slot::Packed),
    ("metallicroughness", Slot::Packed),
    ("orm", Slot::Packed),
    ("basecolour", Slot::Base),
    ("basecolor", Slot::Base),
    ("albedo", Slot::Base),
    ("diffuse", Slot::Base),
    ("colour", Slot::Base),
    ("color", Slot::Base),
    ("col", Slot::Base),
    ("metalness", Slot::Metallic),
    ("metallic", Slot::Metallic),
    ("metal", Slot::Metallic),
    ("roughness", Slot::Roughness),
    ("rough", Slot::Roughness),
    ("normaldx", Slot::NormalDx),
    ("nordx", Slot::NormalDx),
    ("normalgl", Slot::Normal),
    ("norgl", Slot::Normal),
    ("normal", Slot::Normal),
    ("nrm", Slot::Normal),
];

const IMAGE_EXTENSIONS: &[&str] = &["png", "jpg", "jpeg", "tga", "exr"];

/// A file stem as `(prefix, slot)`: the prefix lower-cased with separators dropped, where the
/// stem ends in a known suffix.
fn split(stem: &str) -> Option<(String, Slot)> {
    let flat: String = stem
        .chars()
        .filter(|c| !matches!(c, '_' | '-' | '.' | ' '))
        .flat_map(char::to_lowercase)
        .collect();
    SUFFIXES.iter().find_map(|(suffix, slot)| {
        flat.strip_suffix(suffix)
            .map(|prefix| (prefix.to_string(), *slot))
    })
}

/// A set found by name.
pub struct NamedSet {
    /// The set (metallic 0 and roughness 0.5 where no file gives them).
    pub set: PbrSet,
    /// The normal map's file, if the set has one, and whether its green is DirectX's.
    pub normal: Option<(PathBuf, bool)>,
    /// The set's name (the shared prefix).
    pub name: String,
    /// What was assumed, one line each.
    pub notes: Vec<String>,
}

/// The set that `path` (any one of its images) belongs to.
///
/// # Errors
/// A name with no known suffix, a folder that does not read, or no base colour beside it.
pub fn set_of(path: &Path) -> Result<NamedSet, ModelError> {
    let fail = |reason: String| ModelError::Image {
        path: path.to_path_buf(),
        reason,
    };
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (prefix, _) = split(&stem).ok_or_else(|| {
        fail(
            "the name does not say which map it is: a set's files end in _BaseColor (or \
             _Albedo), _Metallic, _Roughness, _MetallicRoughness / _ORM and _Normal"
                .into(),
        )
    })?;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut found: Vec<(Slot, PathBuf)> = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| ModelError::io(dir, e))?;
    let mut files: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    files.sort();
    for file in files {
        let is_image = file
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| IMAGE_EXTENSIONS.iter().any(|x| e.eq_ignore_ascii_case(x)));
        let Some(stem) = file.file_stem().map(|s| s.to_string_lossy().into_owned()) else {
            continue;
        };
        if let (true, Some((p, slot))) = (is_image, split(&stem))
            && p == prefix
            && !found.iter().any(|(s, _)| *s == slot)
        {
            found.push((slot, file));
        }
    }
    let of = |slot: Slot| {
        found
            .iter()
            .find(|(s, _)| *s == slot)
            .map(|(_, f)| f.clone())
    };
    let base = of(Slot::Base).ok_or_else(|| {
        fail(format!(
            "no base colour beside it (looked in {} for {prefix}_BaseColor, _Albedo, _Diffuse, _Color)",
            dir.display()
        ))
    })?;
    let mut notes = Vec::new();
    let (metallic, roughness) = match (of(Slot::Metallic), of(Slot::Roughness), of(Slot::Packed)) {
        (m, r, Some(packed)) if m.is_none() || r.is_none() => (
            Source::file(&packed, Some(2), false),
            Source::file(&packed, Some(1), false),
        ),
        (m, r, _) => (
            m.map_or_else(
                || {
                    notes.push("no metallic map beside it: metallic 0 (a dielectric)".into());
                    Source::constant(Vec3::ZERO)
                },
                |m| Source::file(m, Some(0), false),
            ),
            r.map_or_else(
                || {
                    notes.push("no roughness map beside it: roughness 0.5".into());
                    Source::constant(Vec3::splat(0.5))
                },
                |r| Source::file(r, Some(0), false),
            ),
        ),
    };
    let normal = of(Slot::Normal)
        .map(|n| (n, false))
        .or_else(|| of(Slot::NormalDx).map(|n| (n, true)));
    Ok(NamedSet {
        set: PbrSet::MetallicRoughness {
            base: Source::file(&base, None, true),
            metallic,
            roughness,
        },
        normal,
        name: prefix,
        notes,
    })
}

impl NamedSet {
    /// Reads the set's normal map, if it has one (DirectX's green flipped to glTF's, with a
    /// note).
    ///
    /// # Errors
    /// A normal map that does not read.
    pub fn load_normal(
        &self,
        notes: &mut Vec<String>,
    ) -> Result<Option<crate::model::normal::NormalMap>, ModelError> {
        let Some((path, dx)) = &self.normal else {
            return Ok(None);
        };
        let map = super::import::normal_map_file(path, notes)?;
        if !dx {
            return Ok(Some(map));
        }
        notes.push(format!(
            "normal map {}: DirectX convention (green down), flipped to glTF's",
            super::import::file_name(path)
        ));
        let mut image = map.image().clone();
        for p in image.pixels_mut() {
            p[1] = 255 - p[1];
        }
        crate::model::normal::NormalMap::new(image)
            .map(Some)
            .map_err(|reason| ModelError::Image {
                path: path.clone(),
                reason,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suffixes_name_the_maps_whatever_the_separators_and_case() {
        assert_eq!(split("Wood_BaseColor"), Some(("wood".into(), Slot::Base)));
        assert_eq!(split("wood-base-color"), Some(("wood".into(), Slot::Base)));
        assert_eq!(split("wood_albedo"), Some(("wood".into(), Slot::Base)));
        assert_eq!(
            split("Wood_Metalness"),
            Some(("wood".into(), Slot::Metallic))
        );
        assert_eq!(split("wood_rough"), Some(("wood".into(), Slot::Roughness)));
        assert_eq!(split("wood_ORM"), Some(("wood".into(), Slot::Packed)));
        assert_eq!(
            split("wood_metallicRoughness"),
            Some(("wood".into(), Slot::Packed))
        );
        assert_eq!(
            split("wood_Normal_DX"),
            Some(("wood".into(), Slot::NormalDx))
        );
        assert_eq!(split("wood_nrm"), Some(("wood".into(), Slot::Normal)));
        assert_eq!(split("wood"), None);
    }
}
