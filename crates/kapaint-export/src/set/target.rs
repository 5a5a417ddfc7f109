//! Where a set goes: what is at the target (free, a set of the same kind holding only what
//! its export wrote, or something never replaced), and the swap that puts a finished set in
//! place through a temporary folder.

use std::path::Path;

use super::{MANIFEST_FORMAT, SetError, io};
use crate::preset::ExportPreset;

/// What is at an export's target folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// Nothing, or an empty folder: the set goes there.
    Free,
    /// A set an export of the same kind wrote, holding nothing but what its `material.json`
    /// lists: it can be replaced.
    Set,
    /// Something else (a file, a folder of other things, or a set beside files no export
    /// wrote): never replaced. Why, in words.
    Taken(String),
}

/// The kind of set an export writes, by its manifest's `format`: `--replace` replaces only a
/// set of the same kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetKind {
    /// Material sets (`kapaint-material`): images, `material.json` and the shader snippets.
    Material,
    /// glTF PBR sets (`kapaint-gltf-pbr`): images, `material.json` and maybe a `.glb`.
    Pbr,
}

impl SetKind {
    /// The kind of set `preset` writes.
    pub fn of(preset: &ExportPreset) -> Self {
        if preset.format.is_pbr() {
            Self::Pbr
        } else {
            Self::Material
        }
    }

    /// Its manifest's `format`.
    fn format(self) -> &'static str {
        match self {
            Self::Material => MANIFEST_FORMAT,
            Self::Pbr => PBR_MANIFEST_FORMAT,
        }
    }

    /// Files a set of this kind holds that its manifest does not list.
    fn unlisted(self) -> &'static [&'static str] {
        match self {
            Self::Material => &["material.json", "material.wgsl", "material.glsl"],
            Self::Pbr => &["material.json"],
        }
    }
}

/// Largest `material.json` read to learn what a set holds (bytes).
const MAX_LISTING_BYTES: u64 = 16 << 20;

/// The files `dir/material.json` says its export wrote, if it is a manifest of `kind`.
fn listed_files(dir: &Path, kind: SetKind) -> Option<Vec<String>> {
    #[derive(serde::Deserialize)]
    struct Listed {
        path: String,
    }
    #[derive(serde::Deserialize)]
    struct Listing {
        format: String,
        files: Vec<Listed>,
        #[serde(default)]
        normal: Option<Listed>,
    }
    let bytes =
        kapaint_base::file_check::read_limited(&dir.join("material.json"), MAX_LISTING_BYTES)
            .ok()?;
    let listing: Listing = serde_json::from_slice(&bytes).ok()?;
    (listing.format == kind.format()).then(|| {
        listing
            .files
            .into_iter()
            .chain(listing.normal)
            .map(|f| f.path)
            .collect()
    })
}

/// What is at `out` (a link to a folder is looked through: a set there is written through the
/// link, which stays), for an export of `kind`.
///
/// # Errors
/// A folder that cannot be read.
pub fn target(out: &Path, kind: SetKind) -> Result<Target, SetError> {
    let linked = kapaint_base::atomic::through_links(out);
    if linked.as_path() != out && std::fs::symlink_metadata(&linked).is_err() {
        return Ok(Target::Taken(format!(
            "is a link to {}, which does not exist",
            linked.display()
        )));
    }
    let out = &linked;
    if let Some(file) = out
        .ancestors()
        .skip(1)
        .find(|a| std::fs::metadata(a).is_ok_and(|m| !m.is_dir()))
    {
        return Ok(Target::Taken(format!(
            "lies inside {}, which is a file, not a folder",
            file.display()
        )));
    }
    if !out.exists() {
        return Ok(Target::Free);
    }
    if !out.is_dir() {
        return Ok(Target::Taken(
            "exists and is not an empty folder (it is a file)".into(),
        ));
    }
    let mut names = Vec::new();
    for entry in std::fs::read_dir(out).map_err(|e| io(out, e))? {
        let entry = entry.map_err(|e| io(out, e))?;
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        let mut name = entry.file_name().to_string_lossy().into_owned();
        if !is_file {
            name.push('/');
        }
        names.push(name);
    }
    if names.is_empty() {
        return Ok(Target::Free);
    }
    let Some(listed) = listed_files(out, kind) else {
        return Ok(Target::Taken(if out.join("material.json").exists() {
            format!(
                "exists and is not an empty folder (its material.json is not a {} set's)",
                kind.format()
            )
        } else {
            "exists and is not an empty folder".into()
        }));
    };
    let mut strays: Vec<String> = names
        .into_iter()
        .filter(|n| !kind.unlisted().contains(&n.as_str()) && !listed.contains(n))
        .collect();
    if strays.is_empty() {
        return Ok(Target::Set);
    }
    strays.sort();
    let more = strays.len().saturating_sub(5);
    strays.truncate(5);
    Ok(Target::Taken(format!(
        "exists and is not an empty folder: besides an exported set it holds {}{} (a replace removes only what an export wrote)",
        strays.join(", "),
        if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        }
    )))
}

/// Whether the folder `out` holds the file `project` (at any depth): an export there would
/// mix the set with the project, and a replace could remove it.
pub fn holds(out: &Path, project: &Path) -> bool {
    let (Ok(out), Ok(project)) = (std::fs::canonicalize(out), std::fs::canonicalize(project))
    else {
        return false;
    };
    project.starts_with(out)
}

/// Whether `out` can take a set (free, or a set when `replace`): what is there.
///
/// # Errors
/// A target that is taken, or a set when not replacing.
pub(crate) fn claim(out: &Path, replace: bool, kind: SetKind) -> Result<Target, SetError> {
    let found = target(out, kind)?;
    let reason = match &found {
        Target::Free => return Ok(found),
        Target::Set if replace => return Ok(found),
        Target::Set => "holds an exported set already: replace it, or choose another folder".into(),
        Target::Taken(why) => format!("cannot take the set: {why}"),
    };
    Err(SetError::Target {
        path: out.to_path_buf(),
        reason,
    })
}

/// Writes a set with `write` into a temporary folder beside `out` and moves it into place
/// (`found` is what [`claim`] found there: a set is swapped out, so `out` always holds a whole
/// set). Nothing is left behind when `write` fails.
///
/// # Errors
/// What `write` returns; a folder that cannot be made or renamed.
pub(crate) fn commit<T>(
    out: &Path,
    found: &Target,
    write: impl FnOnce(&Path) -> Result<T, SetError>,
) -> Result<T, SetError> {
    // Through a link to the folder: the set is swapped in where the link points, and the
    // link stays a link.
    let out = &kapaint_base::atomic::through_links(out);
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| io(parent, e))?;
    let name = out
        .file_name()
        .map_or_else(|| "set".into(), |n| n.to_string_lossy().into_owned());
    remove_stale_sets(parent, &name);
    // Removed on every way out but the last rename; made new, so never a planted link.
    let guard =
        kapaint_base::atomic::temporary_dir(parent, &name, "tmp").map_err(|e| io(parent, e))?;
    let tmp = guard.path().to_path_buf();
    let manifest = write(&tmp)?;
    if *found == Target::Set {
        // Swap: the old set moves aside, the new one takes its name, the old one goes. Should
        // the second rename fail, the old set is put back.
        let old =
            kapaint_base::atomic::temporary_dir(parent, &name, "old").map_err(|e| io(parent, e))?;
        // Onto the empty folder just made: the name was never free for anyone else to take.
        std::fs::rename(out, old.path()).map_err(|e| io(out, e))?;
        if let Err(e) = std::fs::rename(&tmp, out) {
            let _ = std::fs::rename(old.path(), out);
            return Err(io(out, e));
        }
        guard.keep();
        // The old set goes with its guard.
        drop(old);
        return Ok(manifest);
    }
    if out.exists() {
        std::fs::remove_dir(out).map_err(|e| io(out, e))?;
    }
    std::fs::rename(&tmp, out).map_err(|e| io(out, e))?;
    guard.keep();
    Ok(manifest)
}

/// Removes the temporary folders of earlier exports to `name` in `dir` whose process is gone.
fn remove_stale_sets(dir: &Path, name: &str) {
    for tag in ["tmp", "old"] {
        kapaint_base::atomic::remove_stale_with(dir, &format!(".{name}.{tag}-"), "", |path| {
            let _ = std::fs::remove_dir_all(path);
        });
    }
}

/// `format` of a glTF PBR set's `material.json`.
pub const PBR_MANIFEST_FORMAT: &str = "kapaint-gltf-pbr";
