//! File > Import PBR material when the material is not the project's size: the editor asks
//! whether to adopt the material's size (the maps resized to it, one undo step, then the
//! material at its own resolution) or to resample the material to the maps, instead of
//! resampling without a word. Adopting is the default while the project holds no paint. The
//! question's data ([`SizePrompt`]) lives with the jobs that make it.

use std::path::PathBuf;
use std::sync::Arc;

use super::EditorState;
use super::dialogs::centred;
pub use super::jobs::SizePrompt;
use super::jobs::{LoadedMaterial, PbrMaterial};
use kapaint_base::task::Progress;
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
        let m = kapaint_pbr::gltf::material_set(path, None)?;
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

impl EditorState {
    /// A material converted, or the size question.
    fn material_done(&mut self, material: Material) {
        match material {
            Material::Converted(path, m) => self.take_material(&path, *m),
            Material::AskSize(prompt) => self.prompts.size = Some(*prompt),
        }
    }

    /// The maps resized to a material's size, and the material converted at it.
    fn adopted(&mut self, (resized, path, m): (ResizedMaps, PathBuf, Box<PbrMaterial>)) {
        let (w, h) = (resized.0.0.width, resized.0.0.height);
        self.apply(kapaint_model::ImportCommand::Resize(resized));
        self.notices.push(super::notice(
            format!("Resized the maps to the material's {w}x{h}"),
            false,
        ));
        self.take_material(&path, *m);
    }

    /// Converts the material of the glTF at `path`, or the texture set `path` is one image of
    /// ([`kapaint_pbr::names`]), for the document's model, on a worker; it replaces the
    /// selected layer's channels (one undo step) when it arrives. A material of another size
    /// than the maps is not resampled silently: the editor asks first ([`SizePrompt`]).
    pub fn import_pbr(&mut self, path: PathBuf) {
        let project = (self.doc.maps().width(), self.doc.maps().height());
        let (model, mapping) = (self.doc.settings().model, self.doc.settings().n_mapping());
        let adopt_by_default = !self.doc.stack().holds_paint();
        self.start_job(
            "Material",
            move |progress| {
                progress.start("decode", 1);
                let fail = |e: ModelError| Err(format!("{}: {e}", path.display()));
                let loaded = match load(&path) {
                    Ok(l) => l,
                    Err(e) => return fail(e),
                };
                match kapaint_pbr::import::native_size(&loaded.set) {
                    Ok(Some(size)) if size != project => {
                        Ok(Material::AskSize(Box::new(SizePrompt {
                            path,
                            loaded: Arc::new(loaded),
                            size,
                            project,
                            adopt_by_default,
                        })))
                    }
                    Ok(_) => match convert(&loaded, project, model, mapping, progress) {
                        Ok(m) => Ok(Material::Converted(path, Box::new(m))),
                        Err(e) => fail(e),
                    },
                    Err(e) => fail(e),
                }
            },
            Self::material_done,
        );
    }

    /// The size question, while it is open.
    pub fn size_prompt(&self) -> Option<&SizePrompt> {
        self.prompts.size.as_ref()
    }

    /// Answers the size question: adopt the material's size (the maps resized on a worker with
    /// the mesh baked again, then the material converted there: two undo steps), resample the
    /// material to the maps, or import nothing.
    pub fn answer_size_prompt(&mut self, answer: SizeAnswer) {
        let Some(prompt) = self.prompts.size.take() else {
            return;
        };
        let (model, mapping) = (self.doc.settings().model, self.doc.settings().n_mapping());
        let SizePrompt {
            path,
            loaded,
            size,
            project,
            ..
        } = prompt;
        match answer {
            SizeAnswer::Cancel => {}
            SizeAnswer::Resample => self.start_job(
                "Material",
                move |progress| match convert(&loaded, project, model, mapping, progress) {
                    Ok(m) => Ok(Material::Converted(path, Box::new(m))),
                    Err(e) => Err(format!("{}: {e}", path.display())),
                },
                Self::material_done,
            ),
            SizeAnswer::Adopt => {
                let stack = self.doc.stack().clone();
                let mesh = self.doc.surface().map(|s| s.mesh.clone());
                let (w, h) = size;
                self.start_job_modal(
                    "Material",
                    format!("Resizing the maps to {w}x{h} and converting the material…"),
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
                    Self::adopted,
                );
            }
        }
    }

    /// The size question: the two sizes, Adopt / Resample / Cancel, the default first and
    /// taken by Enter.
    pub(super) fn size_prompt_window(&mut self, ctx: &egui::Context) {
        let Some(prompt) = &self.prompts.size else {
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
        if let Some(a) = answer {
            self.answer_size_prompt(a);
        }
    }
}
