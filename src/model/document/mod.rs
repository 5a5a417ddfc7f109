//! The document: maps, history and settings, changed only through [`Command`]s.
//!
//! The UI and scripts never touch the maps directly: they build commands and call
//! [`Document::apply`]. Every command leaves the maps valid (every texel decodes to finite,
//! in-range values) and every stroke, fill, gradient or import is one undo step.

mod command;
mod fill;
mod stroke;

pub use command::{Command, FillRegion, ImportedChannel, StrokeTool};

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::ModelError;
use super::brush::BrushSettings;
use super::history::History;
use super::maps::MaterialMaps;
use super::paint::PaintTarget;
use super::surface::Surface;
use super::texel::{Channels, MaterialValue};
use crate::reflectance::{AmbientApprox, ShadingModel};
use stroke::ActiveStroke;

/// The mesh a document is painted on.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(try_from = "MeshRefFile")]
pub enum MeshRef {
    /// The built-in UV sphere.
    #[default]
    Sphere,
    /// A mesh file, by path.
    File(String),
    /// Another built-in mesh (plane, cube, torus), by name.
    Builtin(String),
}

/// A mesh reference as a file spells it, before it is checked.
#[derive(Deserialize)]
enum MeshRefFile {
    Sphere,
    File(String),
    Builtin(String),
}

impl TryFrom<MeshRefFile> for MeshRef {
    type Error = String;

    fn try_from(f: MeshRefFile) -> Result<Self, String> {
        use super::check::{MAX_PATH_BYTES, bounded_text};
        match f {
            MeshRefFile::Sphere => Ok(Self::Sphere),
            MeshRefFile::File(path) => {
                if path.is_empty() {
                    return Err("the mesh path is empty".into());
                }
                bounded_text("the mesh path", &path, MAX_PATH_BYTES)?;
                Ok(Self::File(path))
            }
            MeshRefFile::Builtin(name) if crate::mesh::BUILTIN_NAMES.contains(&name.as_str()) => {
                Ok(Self::Builtin(name))
            }
            MeshRefFile::Builtin(name) => Err(format!(
                "no built-in mesh is named {name:?} (known: {})",
                crate::mesh::BUILTIN_NAMES.join(", ")
            )),
        }
    }
}

impl MeshRef {
    /// What `kapaint` commands take for it: a built-in name or a path.
    pub fn spec(&self) -> &str {
        match self {
            Self::Sphere => "sphere",
            Self::File(p) | Self::Builtin(p) => p,
        }
    }

    /// From a built-in name or a path.
    pub fn from_spec(spec: &str) -> Self {
        match spec {
            "sphere" => Self::Sphere,
            s if crate::mesh::BUILTIN_NAMES.contains(&s) => Self::Builtin(s.to_string()),
            s => Self::File(s.to_string()),
        }
    }
}

/// Everything about a document that is not the maps; saved with the project.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DocumentSettings {
    /// Shading model of the preview and of derived `k_a`.
    pub model: ShadingModel,
    /// Approximation of `chi`.
    pub approx: AmbientApprox,
    /// The base material: what the maps start as and what the eraser restores.
    pub base: MaterialValue,
    /// The brush's primary material.
    pub primary: MaterialValue,
    /// The secondary material (gradient end, swapped with X).
    pub secondary: MaterialValue,
    /// Channels tools write.
    pub channels: Channels,
    /// Brush settings.
    pub brush: BrushSettings,
    /// Mesh the material is painted on.
    pub mesh: MeshRef,
    /// The material preset the document was made from, if any.
    #[serde(deserialize_with = "super::check::optional_name")]
    pub preset: Option<String>,
}

impl Default for DocumentSettings {
    fn default() -> Self {
        let base = MaterialValue::default();
        Self {
            model: ShadingModel::Phong,
            approx: AmbientApprox::Fast,
            base,
            primary: MaterialValue::new(
                glam::Vec3::new(0.8, 0.1, 0.1),
                glam::Vec3::splat(0.5),
                64.0,
            ),
            secondary: base,
            channels: Channels::ALL,
            brush: BrushSettings::default(),
            mesh: MeshRef::Sphere,
            preset: None,
        }
    }
}

/// A material being painted.
pub struct Document {
    maps: MaterialMaps,
    history: History,
    settings: DocumentSettings,
    surface: Option<Arc<Surface>>,
    stroke: Option<ActiveStroke>,
    /// Bumped by every command that changes the settings (which are saved too).
    settings_version: u64,
}

impl std::fmt::Debug for Document {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Document")
            .field("width", &self.maps.width())
            .field("height", &self.maps.height())
            .field("settings", &self.settings)
            .finish_non_exhaustive()
    }
}

impl Document {
    /// A document of `width x height` texels, every texel the settings' base material.
    pub fn new(width: u32, height: u32, settings: DocumentSettings) -> Result<Self, ModelError> {
        let maps = MaterialMaps::new(width, height, settings.base)?;
        Ok(Self::from_parts(maps, settings))
    }

    /// A document around existing maps (loading), with empty history.
    pub fn from_parts(maps: MaterialMaps, settings: DocumentSettings) -> Self {
        Self {
            maps,
            history: History::default(),
            settings,
            surface: None,
            stroke: None,
            settings_version: 0,
        }
    }

    /// The maps: read them freely; they change only through [`Document::apply`].
    pub fn maps(&self) -> &MaterialMaps {
        &self.maps
    }

    /// Undo and redo.
    pub fn history(&self) -> &History {
        &self.history
    }

    /// The settings saved with the project (changed through the `Set*` commands).
    pub fn settings(&self) -> &DocumentSettings {
        &self.settings
    }

    /// The maps and settings, for a caller that builds another document from them (the
    /// history and the attached mesh are dropped).
    pub fn into_parts(self) -> (MaterialMaps, DocumentSettings) {
        (self.maps, self.settings)
    }

    /// Attaches the mesh surface that object-space strokes and island/part fills paint on
    /// (baked at the map size), or detaches it.
    ///
    /// # Errors
    /// When the bake's size differs from the maps'.
    pub fn set_surface(&mut self, surface: Option<Arc<Surface>>) -> Result<(), ModelError> {
        if let Some(s) = &surface
            && (s.width(), s.height()) != (self.maps.width(), self.maps.height())
        {
            return Err(ModelError::Internal(format!(
                "the mesh is baked at {}x{} but the maps are {}x{}",
                s.width(),
                s.height(),
                self.maps.width(),
                self.maps.height()
            )));
        }
        self.end_stroke();
        self.surface = surface;
        Ok(())
    }

    /// Makes `mesh` the project's mesh (saved with it) and attaches its baked surface.
    ///
    /// # Errors
    /// As [`set_surface`](Self::set_surface); nothing changes then.
    pub fn set_mesh(&mut self, mesh: MeshRef, surface: Arc<Surface>) -> Result<(), ModelError> {
        self.set_surface(Some(surface))?;
        if self.settings.mesh != mesh {
            self.settings.mesh = mesh;
            self.settings_version += 1;
        }
        Ok(())
    }

    /// A number that changes whenever anything a project file stores changes (the maps, or
    /// a setting through a command): what "unsaved changes" and autosave compare.
    pub fn version(&self) -> u64 {
        // Both parts only grow, so their sum changes whenever either does.
        self.maps.version().wrapping_add(self.settings_version)
    }

    /// The attached mesh surface.
    pub fn surface(&self) -> Option<&Arc<Surface>> {
        self.surface.as_ref()
    }

    fn require_surface(&self, what: &str) -> Result<Arc<Surface>, ModelError> {
        self.surface.clone().ok_or_else(|| {
            ModelError::Command(format!(
                "{what} needs a mesh to paint on, and this document has none attached"
            ))
        })
    }

    /// Whether a stroke is in progress.
    pub fn stroking(&self) -> bool {
        self.stroke.is_some()
    }

    /// Applies a command.
    ///
    /// # Errors
    /// When the command cannot apply (outside the map, a mesh command with no mesh): the
    /// document is unchanged.
    pub fn apply(&mut self, command: Command) -> Result<(), ModelError> {
        /// Sets a setting, counting a change.
        fn set<T: PartialEq>(field: &mut T, value: T, version: &mut u64) {
            if *field != value {
                *field = value;
                *version += 1;
            }
        }
        let v = &mut self.settings_version;
        match command {
            Command::SetBrush(b) => set(&mut self.settings.brush, b.sanitized(), v),
            Command::SetPrimary(p) => set(&mut self.settings.primary, p.sanitized(), v),
            Command::SetSecondary(p) => set(&mut self.settings.secondary, p.sanitized(), v),
            Command::SwapMaterials => {
                let primary = self.settings.primary;
                let secondary = std::mem::replace(&mut self.settings.secondary, primary);
                set(&mut self.settings.primary, secondary, v);
            }
            Command::SetChannels(c) => set(&mut self.settings.channels, c, v),
            Command::SetModel(m) => set(&mut self.settings.model, m, v),
            Command::SetApprox(a) => set(&mut self.settings.approx, a, v),
            Command::BeginStroke(tool) => self.begin_stroke(tool),
            Command::StrokeTo(p) => self.stroke_to(p)?,
            Command::EndStroke => self.end_stroke(),
            Command::AbortStroke => self.abort_stroke(),
            Command::Stroke { tool, points } => {
                self.begin_stroke(tool);
                let result = points.into_iter().try_for_each(|p| self.stroke_to(p));
                self.end_stroke();
                result?;
            }
            Command::SurfaceStrokeTo(p) => {
                let surface = self.require_surface("a stroke on the mesh")?;
                self.surface_stroke_to(&surface, p)?;
            }
            Command::SurfaceStroke { tool, points } => {
                let surface = self.require_surface("a stroke on the mesh")?;
                self.begin_stroke(tool);
                let result = points
                    .into_iter()
                    .try_for_each(|p| self.surface_stroke_to(&surface, p));
                self.end_stroke();
                result?;
            }
            Command::Fill(region) => self.fill(region)?,
            Command::Gradient { shape, start, end } => self.gradient(shape, start, end),
            Command::Pick { x, y } => {
                if x >= self.maps.width() || y >= self.maps.height() {
                    return Err(ModelError::Command(format!(
                        "pick at ({x}, {y}) is outside the {}x{} map",
                        self.maps.width(),
                        self.maps.height()
                    )));
                }
                let picked = self.maps.value(x, y);
                set(
                    &mut self.settings.primary,
                    picked,
                    &mut self.settings_version,
                );
            }
            Command::ImportChannel(imported) => {
                self.end_stroke();
                super::import::install(&mut self.maps, &mut self.history, &imported.0)?;
            }
            Command::Undo => {
                self.end_stroke();
                self.history.undo(&mut self.maps, &mut self.surface);
            }
            Command::Redo => {
                self.end_stroke();
                self.history.redo(&mut self.maps, &mut self.surface);
            }
            Command::Resize(resized) => self.install_resized(&resized)?,
            Command::HistoryJump(applied) => {
                self.end_stroke();
                let now = self.history.undo_steps().count();
                for _ in applied..now {
                    self.history.undo(&mut self.maps, &mut self.surface);
                }
                for _ in now..applied {
                    if !self.history.redo(&mut self.maps, &mut self.surface) {
                        break;
                    }
                }
            }
        }
        Ok(())
    }

    /// Puts resized maps and their surface in place, keeping the old ones as one undo step.
    fn install_resized(
        &mut self,
        resized: &crate::model::resize::ResizedMaps,
    ) -> Result<(), ModelError> {
        let (maps, surface) = &*resized.0;
        let size = (maps.width(), maps.height());
        if let Some(s) = surface
            && (s.width(), s.height()) != size
        {
            return Err(ModelError::Internal(format!(
                "the mesh is baked at {}x{} but the resized maps are {}x{}",
                s.width(),
                s.height(),
                size.0,
                size.1
            )));
        }
        self.end_stroke();
        let mut maps = maps.clone();
        maps.stamp_after(self.maps.version());
        let old = std::mem::replace(&mut self.maps, maps);
        let old_surface = std::mem::replace(&mut self.surface, surface.clone());
        let label = format!(
            "Resize {}x{} to {}x{}",
            old.width(),
            old.height(),
            size.0,
            size.1
        );
        self.history.push_whole(label, old, old_surface);
        Ok(())
    }

    fn target_for(&self, value: MaterialValue) -> PaintTarget {
        let s = &self.settings;
        PaintTarget::new(value, s.channels, s.brush.blend, s.brush.energy_guard)
    }
}
