//! File > Import PBR material when the material is not the project's size: the editor asks
//! whether to adopt the material's size (the maps resized to it, one undo step, then the
//! material at its own resolution) or to resample the material to the maps, instead of
//! resampling without a word. Adopting is the default while the project holds no paint. The
//! question's data ([`SizePrompt`]) lives with the jobs that make it.

use std::path::PathBuf;
use std::sync::Arc;

use super::{notice, warning};
use crate::desk::{Ask, Desk, JobStart, Prompt, centred};
pub use crate::results::SizePrompt;
use crate::results::{LoadedMaterial, PBR_ERROR_WARNING, PbrMaterial};
use kapaint_base::task::Progress;
use kapaint_model::Document;
use kapaint_model::ModelError;
use kapaint_model::resize::{ResizedMaps, resized_stack};
use kapaint_model::surface::Surface;
use kapaint_pbr::NMapping;
use kapaint_reflectance::ShadingModel;

/// The answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SizeAnswer {
    /// Resize the maps to the material's size, then import it there.
    Adopt,
    /// Import the material resampled to the maps' size.
    Resample,
    /// Import nothing.
    Cancel,
}

/// Reads the material of the glTF at `path`, or the texture set `path` is one image of.
fn load(path: &std::path::Path) -> Result<LoadedMaterial, ModelError> {
    let gltf = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"));
    if gltf {
        let m =
            kapaint_pbr::gltf::material_set(path, None, Some(kapaint_export::ktx::decode_image))?;
        let file = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        return Ok(LoadedMaterial {
            name: format!("{file}'s material"),
            set: m.set,
            normal: m.normal,
            notes: m.notes,
            double_sided: m.double_sided,
        });
    }
    let named = kapaint_pbr::names::set_of(path)?;
    let mut notes = named.notes.clone();
    let normal = named.load_normal(&mut notes)?;
    Ok(LoadedMaterial {
        name: format!("The texture set {}", named.name),
        set: named.set,
        normal,
        notes,
        double_sided: false,
    })
}

/// Converts `loaded` at `size` for `model` under `mapping`.
fn convert(
    loaded: &LoadedMaterial,
    size: (u32, u32),
    model: ShadingModel,
    mapping: NMapping,
    progress: &Progress,
) -> Result<PbrMaterial, ModelError> {
    progress.start("convert", 1);
    let imported = kapaint_pbr::import::import(&loaded.set, Some(size), model, mapping)?;
    let mut report = imported.report;
    report.notes.extend(loaded.notes.iter().cloned());
    report.double_sided = loaded.double_sided;
    let (maps, _) = imported.doc.into_parts();
    Ok(PbrMaterial {
        maps,
        normal: loaded.normal.clone(),
        report,
    })
}

/// A material import's outcome: converted, or a question about its size first.
pub(super) enum Material {
    /// Converted at the map size for the document's model.
    Converted(PathBuf, Box<PbrMaterial>),
    /// Of another size than the maps: the editor asks whether to adopt it.
    AskSize(Box<SizePrompt>),
}

/// A material converted, or the size question.
fn material_done(material: Material, desk: &mut Desk) {
    match material {
        Material::Converted(path, m) => take_material(&path, *m, desk),
        Material::AskSize(prompt) => desk.ask(Ask::Prompt(Prompt::Size(prompt))),
    }
}

/// The maps resized to a material's size, and the material converted at it.
fn adopted((resized, path, m): (ResizedMaps, PathBuf, Box<PbrMaterial>), desk: &mut Desk) {
    let (w, h) = (resized.0.0.width, resized.0.0.height);
    let said = notice(format!("Resized the maps to the material's {w}x{h}"), false);
    desk.command_saying(kapaint_model::ImportCommand::Resize(resized), vec![said]);
    take_material(&path, *m, desk);
}

/// Takes a converted PBR material: its maps into the selected layer (one undo step), its
/// normal map and its report into the document.
fn take_material(path: &std::path::Path, m: PbrMaterial, desk: &mut Desk) {
    let PbrMaterial {
        maps,
        normal,
        report,
    } = m;
    let e = report.error;
    let text = format!(
        "{} imported for {}: conversion error max {:.1}%, mean {:.1}%, p99 {:.1}%",
        path.display(),
        report.model,
        e.max * 100.0,
        e.mean * 100.0,
        e.p99 * 100.0
    );
    let mut said = vec![if e.max > PBR_ERROR_WARNING {
        warning(format!(
            "{text}: over the {:.0}% a faithful conversion keeps",
            PBR_ERROR_WARNING * 100.0
        ))
    } else {
        notice(text, false)
    }];
    said.extend(report.notes.iter().map(|n| notice(n.clone(), false)));
    let imported = kapaint_model::document::ImportedMaterial {
        maps: Arc::new(maps),
        normal: normal.map(Arc::new),
        report: Some(report),
    };
    desk.command_saying(kapaint_model::ImportCommand::ImportMaterial(imported), said);
}

/// Converts the material of the glTF at `path`, or the texture set `path` is one image of
/// ([`kapaint_pbr::names`]), for `doc`'s model, on a worker; it replaces the selected layer's
/// channels (one undo step) when it arrives. A material of another size than the maps is not
/// resampled silently: the editor asks first ([`SizePrompt`]).
pub(super) fn import_pbr(doc: &Document, path: PathBuf) -> JobStart {
    let project = (doc.maps().width(), doc.maps().height());
    let (model, mapping) = (doc.settings().model, doc.settings().n_mapping());
    let adopt_by_default = !doc.stack().holds_paint();
    JobStart::new(
        "Material",
        move |progress| {
            progress.start("decode", 1);
            let fail = |e: ModelError| Err(format!("{}: {e}", path.display()));
            let loaded = match load(&path) {
                Ok(l) => l,
                Err(e) => return fail(e),
            };
            match kapaint_pbr::import::native_size(&loaded.set) {
                Ok(Some(size)) if size != project => Ok(Material::AskSize(Box::new(SizePrompt {
                    path,
                    loaded: Arc::new(loaded),
                    size,
                    project,
                    adopt_by_default,
                }))),
                Ok(_) => match convert(&loaded, project, model, mapping, progress) {
                    Ok(m) => Ok(Material::Converted(path, Box::new(m))),
                    Err(e) => fail(e),
                },
                Err(e) => fail(e),
            }
        },
        material_done,
    )
}

/// The work an answer to the size question starts: adopt the material's size (the maps
/// resized on a worker with the mesh baked again, then the material converted there: two
/// undo steps), resample the material to the maps, or nothing.
pub(super) fn answer(doc: &Document, prompt: SizePrompt, answer: SizeAnswer) -> Option<JobStart> {
    let (model, mapping) = (doc.settings().model, doc.settings().n_mapping());
    let SizePrompt {
        path,
        loaded,
        size,
        project,
        ..
    } = prompt;
    match answer {
        SizeAnswer::Cancel => None,
        SizeAnswer::Resample => Some(JobStart::new(
            "Material",
            move |progress| match convert(&loaded, project, model, mapping, progress) {
                Ok(m) => Ok(Material::Converted(path, Box::new(m))),
                Err(e) => Err(format!("{}: {e}", path.display())),
            },
            material_done,
        )),
        SizeAnswer::Adopt => {
            let stack = doc.stack().clone();
            let mesh = doc.surface().map(|s| s.mesh.clone());
            let (w, h) = size;
            let job = JobStart::new(
                "Material",
                move |progress| {
                    let fail = |e: String| Err(format!("{}: {e}", path.display()));
                    progress.start("resample", 1);
                    let stack = match resized_stack(&stack, w, h) {
                        Ok(s) => s,
                        Err(e) => return fail(format!("resize: {e}")),
                    };
                    progress.start("bake", 1);
                    let surface = match mesh.map(|m| Surface::new(m, w, h)).transpose() {
                        Ok(s) => s.map(Arc::new),
                        Err(e) => return fail(format!("resize: the mesh: {e}")),
                    };
                    match convert(&loaded, size, model, mapping, progress) {
                        Ok(m) => Ok((
                            ResizedMaps(Arc::new((stack, surface))),
                            path.clone(),
                            Box::new(m),
                        )),
                        Err(e) => fail(e.to_string()),
                    }
                },
                adopted,
            );
            Some(job.modal(format!(
                "Resizing the maps to {w}x{h} and converting the material…"
            )))
        }
    }
}

/// The size question, while `asked`: the two sizes, Adopt / Resample / Cancel, the default
/// first and taken by Enter.
pub(super) fn size_prompt_window(
    asked: &mut Option<SizePrompt>,
    ctx: &egui::Context,
    desk: &mut Desk,
) {
    let Some(prompt) = asked.as_ref() else {
        return;
    };
    let ((w, h), (pw, ph)) = (prompt.size, prompt.project);
    let name = &prompt.loaded.name;
    let adopt_label = format!("Adopt {w}x{h}");
    let resample_label = format!("Resample to {pw}x{ph}");
    let adopt_first = prompt.adopt_by_default;
    let mut answer = None;
    centred(egui::Window::new("Material size"), ctx)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            ui.label(format!(
                "{name} is {w}x{h}; the project's maps are {pw}x{ph}. Adopt the material's \
                 size (the maps are resized to it, one undo step, and the material comes in \
                 at its own resolution), or resample the material to the maps?"
            ));
            if adopt_first {
                ui.label("The project holds no paint yet: adopting loses nothing.");
            }
            ui.horizontal(|ui| {
                let order = if adopt_first {
                    [
                        (SizeAnswer::Adopt, &adopt_label),
                        (SizeAnswer::Resample, &resample_label),
                    ]
                } else {
                    [
                        (SizeAnswer::Resample, &resample_label),
                        (SizeAnswer::Adopt, &adopt_label),
                    ]
                };
                for (k, (a, label)) in order.into_iter().enumerate() {
                    let button = egui::Button::new(label.as_str());
                    let button = if k == 0 {
                        button.fill(ui.visuals().selection.bg_fill)
                    } else {
                        button
                    };
                    if ui.add(button).clicked() {
                        answer = Some(a);
                    }
                }
                if ui.button("Cancel").clicked() {
                    answer = Some(SizeAnswer::Cancel);
                }
            });
        });
    if answer.is_none() {
        let (enter, escape) = ctx.input(|i| {
            (
                i.key_pressed(egui::Key::Enter),
                i.key_pressed(egui::Key::Escape),
            )
        });
        if enter {
            answer = Some(if adopt_first {
                SizeAnswer::Adopt
            } else {
                SizeAnswer::Resample
            });
        } else if escape {
            answer = Some(SizeAnswer::Cancel);
        }
    }
    if let Some(a) = answer
        && let Some(prompt) = asked.take()
        && let Some(job) = self::answer(desk.doc, prompt, a)
    {
        desk.job(job);
    }
}
