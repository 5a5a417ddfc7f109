//! Exporting compact texture sets: presets ([`preset`]), the choice of `n`'s
//! encoding by the `k_a` error it causes ([`encoding`]), and sets of images with a
//! `material.json` manifest written atomically and read back ([`set`]).

pub mod blocks;
pub mod encoding;
pub mod ktx;
pub mod preset;
pub mod set;
pub mod snippet;

use std::path::Path;

/// What an export wrote: a kapaint set, or a glTF PBR set.
#[derive(Clone, Debug)]
pub enum Exported {
    /// A kapaint set (`material.json` in [`set::MANIFEST_FORMAT`]).
    Set(set::Manifest),
    /// A glTF PBR set (the `gltf-pbr` preset).
    Pbr(crate::pbr::export::PbrManifest),
}

/// Exports `doc` with `preset` into the folder `out`: a kapaint set ([`set::export_with`],
/// [`set::export_replacing`] where `replace`), or for a [`preset::Format::GltfPbr`] preset a
/// glTF PBR set, with the `glb` mesh and the material as a `.glb` where given.
///
/// # Errors
/// As the exports; `glb` with a preset that is not glTF PBR.
pub fn run(
    doc: &crate::model::Document,
    preset: &preset::ExportPreset,
    out: &Path,
    progress: &crate::task::Progress,
    replace: bool,
    glb: Option<&crate::mesh::Mesh>,
) -> Result<Exported, set::SetError> {
    if preset.format == preset::Format::GltfPbr {
        return crate::pbr::export::export(doc, preset, out, progress, replace, glb)
            .map(Exported::Pbr);
    }
    if glb.is_some() {
        return Err(set::SetError::Invalid {
            path: out.to_path_buf(),
            reason: format!(
                "a .glb is written with the gltf-pbr preset, not {}",
                preset.name
            ),
        });
    }
    if replace {
        set::export_replacing(doc, preset, out, progress)
    } else {
        set::export_with(doc, preset, out, progress)
    }
    .map(Exported::Set)
}
