//! Exporting compact texture sets: presets ([`preset`]), block codecs ([`codec`]), the choice of `n`'s
//! encoding by the `k_a` error it causes ([`encoding`]), and sets of images with a
//! `material.json` manifest written atomically and read back ([`set`]).

pub mod blocks;
pub mod codec;
pub mod encoding;
pub mod file_kind;
pub mod glb;
pub mod gltf_basisu;
pub mod gltf_pbr;
pub mod ktx;
pub mod pbr_files;
pub mod preset;
pub mod set;
pub mod snippet;

use std::path::Path;

/// What an export wrote: a kapaint set, or a glTF PBR set.
#[derive(Clone, Debug)]
pub enum Exported {
    /// A kapaint set (`material.json` in [`set::MANIFEST_FORMAT`]).
    Set(set::Manifest),
    /// A PBR set (the `gltf-pbr` preset, an engine's, or a user's layout).
    Pbr(gltf_pbr::PbrManifest),
}

/// Exports `doc` with `preset` into the folder `out`: a kapaint set ([`set::export_with`],
/// [`set::export_replacing`] where `replace`), or for a PBR preset ([`preset::Format::is_pbr`])
/// a PBR set, for glTF's with the `glb` mesh and the material as a `.glb` where given. Blocks are
/// encoded by `brought` (a GPU's encoder) where given, else on the CPU.
///
/// # Errors
/// As the exports; `glb` with a preset that is not glTF PBR.
pub fn run(
    doc: &kapaint_model::Document,
    preset: &preset::ExportPreset,
    out: &Path,
    progress: &kapaint_base::task::Progress,
    replace: bool,
    glb: Option<gltf_pbr::Glb<'_>>,
    brought: Option<&dyn blocks::BlockEncoder>,
) -> Result<Exported, set::SetError> {
    if glb.is_some() && !preset.format.is_gltf_pbr() {
        return Err(set::SetError::Invalid {
            path: out.to_path_buf(),
            reason: format!(
                "a .glb is written with the gltf-pbr preset, not {}",
                preset.name
            ),
        });
    }
    if preset.format.is_pbr() {
        return gltf_pbr::export(doc, preset, out, progress, replace, glb).map(Exported::Pbr);
    }
    set::export_into(doc, preset, out, progress, replace, brought).map(Exported::Set)
}
