//! A texture set found by its file names, the way painting tools export them:
//! `wood_BaseColor.png`, `wood_Metallic.png`, `wood_Roughness.png`, `wood_Normal.png` (or
//! `_albedo`, `_metalness`, `_rough`, `_nrm`, a packed `_MetallicRoughness` or `_ORM`, ...).
//! Any one file of the set names it: the others are found beside it by the same prefix and
//! separator, exactly as written (`wood_BaseColor.png` never takes `wood-col.png` or
//! `Wood_Roughness.png`). Two files for one map are an error that names them.

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::import::{PbrSet, Source};
use kapaint_model::ModelError;

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

/// Characters that part a set's name from a map's.
const SEPARATORS: [char; 4] = ['_', '-', '.', ' '];

/// A suffix as it is compared: lower case, separators dropped.
fn flat(text: &str) -> String {
    text.chars()
        .filter(|c| !SEPARATORS.contains(c))
        .flat_map(char::to_lowercase)
        .collect()
}

/// Where a set's file name parts: its prefix as written, the separator after it (none when
/// the map's name follows directly), and the map.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Parts {
    prefix: String,
    separator: Option<char>,
    slot: Slot,
}

/// A file stem as the set's prefix, separator and map: the first separator whose rest is a
/// known map name (`wood_base_color`: `wood`, `_`, base colour), else a known map name ending
/// the stem directly (`woodAlbedo`).
fn split(stem: &str) -> Option<Parts> {
    let known = |rest: &str| {
        let rest = flat(rest);
        SUFFIXES
            .iter()
            .find(|(suffix, _)| *suffix == rest)
            .map(|(_, slot)| *slot)
    };
    for (i, c) in stem.char_indices().filter(|(_, c)| SEPARATORS.contains(c)) {
        if let Some(slot) = known(&stem[i + c.len_utf8()..])
            && i > 0
        {
            return Some(Parts {
                prefix: stem[..i].to_string(),
                separator: Some(c),
                slot,
            });
        }
    }
    let lower = stem.to_lowercase();
    SUFFIXES.iter().find_map(|(suffix, slot)| {
        let cut = stem.len().checked_sub(suffix.len())?;
        (cut > 0 && stem.is_char_boundary(cut) && lower.ends_with(suffix)).then(|| Parts {
            prefix: stem[..cut].to_string(),
            separator: None,
            slot: *slot,
        })
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
    let named = split(&stem).ok_or_else(|| {
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
    let mut found: Vec<(Slot, Vec<PathBuf>)> = Vec::new();
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
        if let (true, Some(parts)) = (is_image, split(&stem))
            && parts.prefix == named.prefix
            && parts.separator == named.separator
        {
            match found.iter_mut().find(|(s, _)| *s == parts.slot) {
                Some((_, files)) => files.push(file),
                None => found.push((parts.slot, vec![file])),
            }
        }
    }
    if let Some((_, files)) = found.iter().find(|(_, files)| files.len() > 1) {
        let names: Vec<String> = files.iter().map(|f| super::import::file_name(f)).collect();
        return Err(fail(format!(
            "more than one file beside it is the same map: {}; keep one, or rename the others",
            names.join(", ")
        )));
    }
    let of = |slot: Slot| {
        found
            .iter()
            .find(|(s, _)| *s == slot)
            .map(|(_, f)| f[0].clone())
    };
    let prefix = named.prefix;
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
    ) -> Result<Option<kapaint_model::normal::NormalMap>, ModelError> {
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
        kapaint_model::normal::NormalMap::new(image)
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

    fn parts(prefix: &str, separator: Option<char>, slot: Slot) -> Parts {
        Parts {
            prefix: prefix.into(),
            separator,
            slot,
        }
    }

    #[test]
    fn suffixes_name_the_maps_and_the_prefix_is_kept_as_written() {
        let cases = [
            ("Wood_BaseColor", "Wood", Some('_'), Slot::Base),
            ("wood-base-color", "wood", Some('-'), Slot::Base),
            ("my_wood_albedo", "my_wood", Some('_'), Slot::Base),
            ("Wood_Metalness", "Wood", Some('_'), Slot::Metallic),
            ("wood_rough", "wood", Some('_'), Slot::Roughness),
            ("wood_ORM", "wood", Some('_'), Slot::Packed),
            ("wood_metallicRoughness", "wood", Some('_'), Slot::Packed),
            ("wood_Normal_DX", "wood", Some('_'), Slot::NormalDx),
            ("wood_nrm", "wood", Some('_'), Slot::Normal),
            ("woodAlbedo", "wood", None, Slot::Base),
        ];
        for (stem, prefix, separator, slot) in cases {
            assert_eq!(split(stem), Some(parts(prefix, separator, slot)), "{stem}");
        }
        assert_eq!(split("wood"), None);
        assert_eq!(split("gun_metal"), None, "gunmetal is a colour, not a map");
    }

    #[test]
    fn a_set_is_its_exact_prefix_and_separator_and_two_files_for_one_map_are_refused() {
        let dir = std::env::temp_dir().join(format!("kapaint-names-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let png = |name: &str| {
            image::RgbImage::new(4, 4).save(dir.join(name)).unwrap();
        };
        for name in [
            "wood_BaseColor.png",
            "wood_Roughness.png",
            "wood-col.png",
            "wood-Metallic.png",
            "Wood_Normal.png",
            "gun_BaseColor.png",
            "gun_metal.png",
        ] {
            png(name);
        }
        let set = set_of(&dir.join("wood_BaseColor.png")).unwrap();
        assert_eq!(set.normal, None, "Wood_ is another prefix");
        assert!(
            set.notes.iter().any(|n| n.contains("no metallic map")),
            "wood-Metallic has another separator: {:?}",
            set.notes
        );
        let gun = set_of(&dir.join("gun_BaseColor.png")).unwrap();
        assert!(gun.notes.iter().any(|n| n.contains("no metallic map")));
        png("wood_Albedo.png");
        let err = set_of(&dir.join("wood_Roughness.png"))
            .err()
            .unwrap()
            .to_string();
        assert!(
            err.contains("wood_Albedo.png") && err.contains("wood_BaseColor.png"),
            "{err}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
