//! `kapaint import-pbr`: a PBR texture set (glTF material, metallic-roughness or
//! specular-glossiness images, or constants) converted into a project, with the conversion
//! error of every texel measured.

use std::path::{Path, PathBuf};

use super::args::{ModelArg, NMappingArg, parse_size};
use super::{CliError, mesh_error, model_error};
use crate::model::document::MeshRef;
use crate::model::normal::NormalMap;
use crate::model::project;
use crate::pbr::import::{ImportReport, PbrSet, Source};
use crate::reflectance::ShadingModel;

/// Convert a PBR texture set into a project.
#[derive(Debug, clap::Args)]
pub struct ImportPbrArgs {
    /// Project file to write.
    #[arg(long)]
    out: PathBuf,
    /// Map size, N or WxH (default: the largest input image's size).
    #[arg(long)]
    size: Option<String>,
    /// The target model the set is converted for.
    #[arg(long, value_enum, default_value = "phong")]
    model: ModelArg,
    /// How roughness and F0 become n and k_s for Phong and Blinn-Phong (kept with the
    /// project; its gltf-pbr export inverts the same).
    #[arg(long, value_enum, default_value = "height-fitted")]
    n_mapping: NMappingArg,
    /// A glTF file (.glb or .gltf): its mesh and its material's textures and factors.
    #[arg(long, conflicts_with_all = ["base_color", "metallic", "roughness", "metallic_roughness", "specular", "glossiness"])]
    gltf: Option<PathBuf>,
    /// A texture set by its file names: any one image of it (NAME_BaseColor, NAME_Metallic,
    /// NAME_Roughness or NAME_ORM / NAME_MetallicRoughness, NAME_Normal, ...), the others
    /// found beside it.
    #[arg(long, conflicts_with_all = ["gltf", "base_color", "metallic", "roughness", "metallic_roughness", "specular", "glossiness", "normal"])]
    set: Option<PathBuf>,
    /// With --gltf: the material, by name or index (default: the first primitive's).
    #[arg(long, requires = "gltf")]
    material: Option<String>,
    /// Base colour (sRGB image), or R,G,B or S in linear [0, 1]. With --specular, the diffuse
    /// colour.
    #[arg(long)]
    base_color: Option<String>,
    /// Metallic: a grey image (linear), or a number in [0, 1].
    #[arg(long, conflicts_with = "metallic_roughness")]
    metallic: Option<String>,
    /// Roughness: a grey image (linear), or a number in [0, 1].
    #[arg(long, conflicts_with = "metallic_roughness")]
    roughness: Option<String>,
    /// glTF's packed image: roughness in G, metallic in B.
    #[arg(long)]
    metallic_roughness: Option<PathBuf>,
    /// Specular colour F0 (sRGB image, or R,G,B or S linear): the specular-glossiness
    /// workflow.
    #[arg(long, conflicts_with_all = ["metallic", "roughness", "metallic_roughness"], requires = "glossiness")]
    specular: Option<String>,
    /// Glossiness (1 - roughness): a grey image (linear), or a number in [0, 1].
    #[arg(long, requires = "specular")]
    glossiness: Option<String>,
    /// A tangent-space normal map (RGB image, glTF's convention: +Y up), kept with the
    /// project and passed through by every export.
    #[arg(long, conflicts_with = "gltf")]
    normal: Option<PathBuf>,
    /// A mesh to paint on (.obj, .gltf, .glb, or sphere, plane, cube, torus).
    #[arg(long, conflicts_with = "gltf")]
    mesh: Option<String>,
    /// Give the --mesh a new UV atlas for the map size and keep the unwrapped mesh inside the
    /// project (the material's images are taken as they are, not moved to the new charts).
    #[arg(long, requires = "mesh")]
    unwrap: bool,
    /// Overwrite an existing file.
    #[arg(long)]
    force: bool,
}

/// A flag's value: a number (or R,G,B) where it parses as one, else an image file.
fn source(
    flag: &str,
    text: &str,
    colour: bool,
    channel: Option<usize>,
) -> Result<Source, CliError> {
    let numeric = text.split(',').all(|p| p.trim().parse::<f64>().is_ok());
    if numeric {
        let v = super::args::parse_rgb(flag, text, true)?;
        return Ok(Source::constant(v.as_vec3()));
    }
    let path = Path::new(text);
    if !path.exists() {
        return Err(CliError::usage(format!(
            "{flag}: {text}: no such file (give an image, or a number in [0, 1])"
        )));
    }
    Ok(Source::file(
        path,
        if colour { None } else { channel.or(Some(0)) },
        colour,
    ))
}

impl ImportPbrArgs {
    /// The set, its normal map and the notes on them, and whether it is seen from both
    /// sides.
    fn set(&self) -> Result<(PbrSet, Option<NormalMap>, Vec<String>, bool), CliError> {
        if let Some(gltf) = &self.gltf {
            let m = crate::pbr::gltf::material_set(
                gltf,
                self.material.as_deref(),
                Some(crate::export::ktx::decode_image),
            )
            .map_err(model_error)?;
            return Ok((m.set, m.normal, m.notes, m.double_sided));
        }
        if let Some(file) = &self.set {
            if !file.exists() {
                return Err(CliError::usage(format!(
                    "--set: {}: no such file",
                    file.display()
                )));
            }
            let named = crate::pbr::names::set_of(file).map_err(model_error)?;
            let mut notes = named.notes.clone();
            let normal = named.load_normal(&mut notes).map_err(model_error)?;
            return Ok((named.set, normal, notes, false));
        }
        let mut notes = Vec::new();
        if let Some(p) = self.normal.as_deref().filter(|p| !p.exists()) {
            return Err(CliError::usage(format!(
                "--normal: {}: no such file",
                p.display()
            )));
        }
        let normal = self
            .normal
            .as_deref()
            .map(|p| crate::pbr::import::normal_map_file(p, &mut notes))
            .transpose()
            .map_err(model_error)?;
        let need = |flag: &str, v: &Option<String>| -> Result<String, CliError> {
            v.clone().ok_or_else(|| {
                CliError::usage(format!(
                    "{flag} is missing (give --gltf, --set, or --base-color with --metallic and --roughness, --metallic-roughness, or --specular and --glossiness)"
                ))
            })
        };
        let base = source(
            "--base-color",
            &need("--base-color", &self.base_color)?,
            true,
            None,
        )?;
        if let Some(specular) = &self.specular {
            let glossiness = need("--glossiness", &self.glossiness)?;
            return Ok((
                PbrSet::SpecularGlossiness {
                    diffuse: base,
                    specular: source("--specular", specular, true, None)?,
                    glossiness: source("--glossiness", &glossiness, false, None)?,
                },
                normal,
                notes,
                false,
            ));
        }
        let (metallic, roughness) = match &self.metallic_roughness {
            Some(packed) => {
                let text = packed.to_string_lossy();
                (
                    source("--metallic-roughness", &text, false, Some(2))?,
                    source("--metallic-roughness", &text, false, Some(1))?,
                )
            }
            None => (
                source(
                    "--metallic",
                    &need("--metallic", &self.metallic)?,
                    false,
                    None,
                )?,
                source(
                    "--roughness",
                    &need("--roughness", &self.roughness)?,
                    false,
                    None,
                )?,
            ),
        };
        Ok((
            PbrSet::MetallicRoughness {
                base,
                metallic,
                roughness,
            },
            normal,
            notes,
            false,
        ))
    }

    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// Missing or bad inputs, an existing file without `--force`, a failed write.
    pub fn run(self) -> Result<String, CliError> {
        if self.out.exists() && !self.force {
            return Err(CliError::usage(format!(
                "{} exists; pass --force to overwrite it",
                self.out.display()
            )));
        }
        let size = self.size.as_deref().map(parse_size).transpose()?;
        let model = ShadingModel::from(self.model);
        // A mesh file must exist and load now, not at the first stroke on it.
        if let Some(m) = &self.mesh {
            crate::mesh::open(Path::new(m)).map_err(mesh_error)?;
        }
        if let Some(g) = &self.gltf {
            crate::mesh::open(g).map_err(mesh_error)?;
        }
        let (set, normal, notes, double_sided) = self.set()?;
        let mesh = match (&self.gltf, &self.mesh) {
            (Some(gltf), _) => Some(gltf.to_string_lossy().into_owned()),
            (None, Some(m)) => Some(m.clone()),
            (None, None) => None,
        };
        let mut imported = crate::pbr::import::import(&set, size, model, self.n_mapping.into())
            .map_err(model_error)?;
        imported.report.notes.extend(notes);
        imported.report.double_sided = double_sided;
        let mut settings = imported.doc.settings().clone();
        settings.import = Some(imported.report.clone());
        if let Some(mesh) = &mesh {
            settings.mesh = MeshRef::from_spec(mesh);
        }
        let doc = imported
            .doc
            .with_normal(normal.map(std::sync::Arc::new))
            .with_settings(settings);
        let (doc, unwrapped) = match (&self.mesh, self.unwrap) {
            (Some(m), true) => {
                let (doc, line) = super::unwrap::keep_unwrapped(doc, m)?;
                (doc, format!("{line}\n"))
            }
            _ => (doc, String::new()),
        };
        project::save(&doc, &self.out).map_err(model_error)?;
        Ok(format!(
            "{unwrapped}{}",
            report_text(&self.out, &doc, &imported.report)
        ))
    }
}

/// What the command prints: where it wrote, then `key: value` lines a script can read.
fn report_text(out: &Path, doc: &crate::model::Document, report: &ImportReport) -> String {
    use std::fmt::Write as _;
    let mut text = format!(
        "imported {} into {} ({}x{}, {})\n",
        report.source,
        out.display(),
        doc.maps().width(),
        doc.maps().height(),
        report.model
    );
    let e = report.error;
    let _ = writeln!(
        text,
        "conversion error (relative, box average): max {:.2} %, mean {:.2} %, p99 {:.2} %",
        100.0 * e.max,
        100.0 * e.mean,
        100.0 * e.p99
    );
    let _ = writeln!(text, "n mapping: {}", report.n_mapping);
    if let Some(normal) = doc.normal() {
        let _ = writeln!(
            text,
            "normal map: {}x{}, kept with the project (the gltf-pbr export passes it through; k_a never uses it)",
            normal.width(),
            normal.height()
        );
    }
    for note in &report.notes {
        let _ = writeln!(text, "note: {note}");
    }
    text
}
