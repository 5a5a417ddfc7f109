//! The document: maps, history and settings, changed only through [`Command`]s.
//!
//! The UI and scripts never touch the maps directly: they build commands and call
//! [`Document::apply`]. Every command leaves the maps valid (every texel decodes to finite,
//! in-range values) and every stroke, fill, gradient or import is one undo step.

mod aids;
mod command;
mod copy_dab;
mod fill;
mod id;
mod import;
mod layer_command;
mod layers;

mod decal;
mod make;
mod masks;
mod memory_need;
mod moves;
mod paths;
mod project_image;
pub use decal::{Decal, DecalFrame};
mod script;
mod structure;
mod surface;
pub use super::mesh_ref::MeshRef;
pub use id::DocumentId;
pub use paths::MAX_LAYERS;
mod stroke;
mod surface_copy;

pub use command::{
    AttachedBake, AttachedMesh, AttachedNormal, Command, FillRegion, HistoryCommand, ImportCommand,
    ImportedChannel, ImportedMaterial, LayerCommand, LayerKind, LayerMove, LayerPlace, LayerRef,
    MaskCommand, PaintCommand, SettingsCommand, StrokeCommand, StrokeTool,
};

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::ModelError;
use super::brush::BrushSettings;
use super::layers::{Compositor, LayerId, LayerStack, Selected, Selection, StackHistory, State};
use super::maps::MaterialMaps;
use super::surface::Surface;
use super::texel::{Channels, MaterialValue};
use kapaint_reflectance::{AmbientApprox, ShadingModel};
use stroke::ActiveStroke;

/// Everything about a document that is not the maps; saved with the project.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
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
    /// The PBR import the maps were made by, with its measured conversion error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub import: Option<super::provenance::ImportReport>,
    /// The PBR mapping imports and the glTF export use, where one was chosen (see
    /// [`Self::n_mapping`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub n_mapping: Option<super::provenance::NMapping>,
}

impl DocumentSettings {
    /// The PBR mapping the document's maps are in: the one chosen, else the one its import
    /// recorded (a project imported before the height fit records the height-fixed one), else
    /// the default.
    pub fn n_mapping(&self) -> super::provenance::NMapping {
        self.n_mapping
            .or_else(|| {
                self.import
                    .as_ref()
                    .and_then(|r| super::provenance::NMapping::from_name(&r.n_mapping))
            })
            .unwrap_or_default()
    }
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
            import: None,
            n_mapping: None,
        }
    }
}

/// The layer a stack opens with selected: the topmost paint layer (inside groups too), else the
/// topmost layer; empty for an empty stack.
fn topmost_paintable(stack: &LayerStack) -> Vec<usize> {
    let walk = stack.walk();
    walk.iter()
        .rev()
        .find(|(_, l)| matches!(l.content, super::layers::LayerContent::Paint(_)))
        .map(|(p, _)| p.clone())
        .or_else(|| stack.layers.len().checked_sub(1).map(|i| vec![i]))
        .unwrap_or_default()
}

/// A material being painted: a layer stack over a base material, and its composite.
pub struct Document {
    /// The composite of the stack: what the renderer, `k_a` and export read.
    maps: MaterialMaps,
    /// The stack, the selected layer and the mesh surface.
    state: State,
    compositor: Compositor,
    history: StackHistory,
    settings: DocumentSettings,
    stroke: Option<ActiveStroke>,
    /// Bumped by every command that changes the settings (which are saved too).
    settings_version: u64,
    /// The last revision number given to a state ([`State::revision`]).
    revisions: u64,
    /// The layer whose opacity the last command set: the next opacity change of that layer
    /// joins its undo step (a slider's drag is one step).
    opacity_run: Option<LayerId>,
    /// The layer whose mask generator the last command previewed (a drag in progress): the
    /// next change of it joins that step.
    generator_run: Option<LayerId>,
    /// The layer the Decal tool's last preview placed a decal in (a placement under way):
    /// the next placement there replaces it, in its step.
    decal_run: Option<LayerId>,
    /// Which document this is: kept in its project file and its recovery journal, so a
    /// journal is only ever recovered into the project it was written for.
    id: DocumentId,
    /// Which document value this is in this process (see [`Document::instance`]).
    instance: u64,
    /// The stencil and the clone source.
    aids: aids::Aids,
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
    /// [`Command::Pick`] (the composite's value) and [`Command::PickLayer`] (the selected
    /// layer's) into the primary material.
    fn pick(&mut self, x: u32, y: u32, layer: bool) -> Result<(), ModelError> {
        self.check_texel(x, y, "pick")?;
        let picked = if layer {
            self.layer_value(x, y, self.settings.primary)
        } else {
            self.maps.value(x, y)
        };
        if self.settings.primary != picked {
            self.settings.primary = picked;
            self.settings_version += 1;
        }
        Ok(())
    }

    /// The layer stack: read it freely; it changes only through [`Document::apply`].
    pub fn stack(&self) -> &LayerStack {
        &self.state.stack
    }

    /// The selected layer's path and whether tools paint its mask.
    pub fn selection(&self) -> Selection {
        self.state.selection()
    }

    /// The selected layer's id (none: the stack has no layers), without finding its path.
    pub fn selected_id(&self) -> Option<LayerId> {
        self.state.selection.id
    }

    /// The selected layer.
    pub fn selected_layer(&self) -> Option<&crate::layers::Layer> {
        self.state.stack.layer(&self.state.selected_path())
    }

    /// Whether tools paint the selected layer's mask.
    pub fn painting_mask(&self) -> bool {
        self.state.selection.mask
    }

    /// The maps: read them freely; they change only through [`Document::apply`].
    pub fn maps(&self) -> &MaterialMaps {
        &self.maps
    }

    /// Undo and redo.
    pub fn history(&self) -> &StackHistory {
        &self.history
    }

    /// The settings saved with the project (changed through the `Set*` commands).
    pub fn settings(&self) -> &DocumentSettings {
        &self.settings
    }

    /// The composite maps and the settings, for a caller that builds another document or
    /// renders them (the layers, history and attached mesh are dropped).
    pub fn into_parts(self) -> (MaterialMaps, DocumentSettings) {
        (self.maps, self.settings)
    }

    /// Records `before` as one undo step, the state now as a new revision.
    fn record(&mut self, label: &str, before: State) {
        let stack = &self.state.stack;
        let same_size = (stack.width, stack.height) == (self.maps.width(), self.maps.height());
        // A resize composites anew after it is recorded.
        if masks::lay_generators(&mut self.state) && same_size {
            self.compositor.update(&self.state.stack, &mut self.maps);
        }
        self.revisions += 1;
        self.state.revision = self.revisions;
        self.history.push(label, before, &self.state);
        self.sync_settings();
    }

    /// The settings that mirror the state (saved in the project's settings) follow it.
    fn sync_settings(&mut self) {
        self.settings.mesh.clone_from(&self.state.mesh);
        self.settings.import.clone_from(&self.state.import);
    }

    /// A number that identifies what a project file stores (the state's revision, the saved
    /// settings and a stroke in progress): it changes with every change, and undo back to a
    /// state brings that state's number back. What "unsaved changes" and autosave compare.
    pub fn version(&self) -> u64 {
        /// splitmix64's finaliser: every input bit moves every output bit.
        fn mix(h: u64, v: u64) -> u64 {
            let mut z = (h ^ v).wrapping_add(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        // A stroke changes the maps dab by dab before it is recorded as a step.
        let stroke = if self.stroking() {
            self.maps.version() | 1 << 63
        } else {
            0
        };
        mix(
            mix(mix(0, self.state.revision), self.settings_version),
            stroke,
        )
    }

    /// Which document value this is in this process: every document made, opened or
    /// recovered has its own number, never reused. With [`Document::version`] it keys what a
    /// view makes from a document (thumbnails, a rename under way): a document opened in
    /// place of another may have the other's version, never its instance.
    pub fn instance(&self) -> u64 {
        self.instance
    }

    /// The attached mesh surface.
    pub fn surface(&self) -> Option<&Arc<Surface>> {
        self.state.surface.as_ref()
    }

    fn require_surface(&self, what: &str) -> Result<Arc<Surface>, ModelError> {
        self.state.surface.clone().ok_or_else(|| {
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
    pub fn apply(&mut self, command: impl Into<Command>) -> Result<(), ModelError> {
        let command = command.into();
        self.check_memory(&command)?;
        let opacity_run = self.opacity_run.take();
        let generator_run = self.generator_run.take();
        let decal_run = self.decal_run.take();
        match command {
            Command::Settings(c) => self.settings_command(c),
            Command::Stroke(c) => self.stroke_command(c),
            Command::Paint(c) => self.paint_command(c, decal_run),
            Command::Import(c) => self.import_command(c),
            Command::History(c) => {
                self.history_command(c);
                Ok(())
            }
            Command::Layer(c) => self.layer_command(c, opacity_run),
            Command::Mask(c) => self.mask_command(c, generator_run),
        }
    }

    /// The settings room: no undo step, a settings version counted where a value changed.
    fn settings_command(&mut self, command: SettingsCommand) -> Result<(), ModelError> {
        /// Sets a setting, counting a change.
        fn set<T: PartialEq>(field: &mut T, value: T, version: &mut u64) {
            if *field != value {
                *field = value;
                *version += 1;
            }
        }
        let v = &mut self.settings_version;
        let s = &mut self.settings;
        match command {
            SettingsCommand::SetBrush(b) => set(&mut s.brush, b.sanitized(), v),
            SettingsCommand::SetPrimary(p) => set(&mut s.primary, p.sanitized(), v),
            SettingsCommand::SetSecondary(p) => set(&mut s.secondary, p.sanitized(), v),
            SettingsCommand::SwapMaterials => {
                let primary = s.primary;
                let secondary = std::mem::replace(&mut s.secondary, primary);
                set(&mut s.primary, secondary, v);
            }
            SettingsCommand::SetChannels(c) => set(&mut s.channels, c, v),
            SettingsCommand::SetModel(m) => set(&mut s.model, m, v),
            SettingsCommand::SetApprox(a) => set(&mut s.approx, a, v),
            SettingsCommand::SetStencil {
                image,
                center,
                size,
                rotation,
                opacity,
                tiled,
                view,
            } => {
                return self.set_stencil(&aids::StencilSpec {
                    image,
                    center,
                    size,
                    rotation,
                    opacity,
                    tiled,
                    view,
                });
            }
            SettingsCommand::ClearStencil => {
                self.aids.stencil = None;
                self.aids.stencil_image = None;
            }
            SettingsCommand::SetCloneSource(at) => return self.set_clone_source(at),
            SettingsCommand::SetSurfaceCloneSource(at) => {
                return self.set_surface_clone_source(at);
            }
        }
        Ok(())
    }

    /// The stroke room.
    fn stroke_command(&mut self, command: StrokeCommand) -> Result<(), ModelError> {
        match command {
            StrokeCommand::BeginStroke(tool) => self.begin_stroke(tool)?,
            StrokeCommand::StrokeTo(p) => self.stroke_to(p)?,
            StrokeCommand::EndStroke => self.end_stroke(),
            StrokeCommand::AbortStroke => self.abort_stroke(),
            StrokeCommand::Stroke { tool, points } => {
                self.begin_stroke(tool)?;
                let result = points.into_iter().try_for_each(|p| self.stroke_to(p));
                self.end_stroke();
                result?;
            }
            StrokeCommand::SurfaceStrokeTo(p) => {
                let surface = self.require_surface("a stroke on the mesh")?;
                self.surface_stroke_to(&surface, p)?;
            }
            StrokeCommand::SurfaceStroke { tool, points } => {
                let surface = self.require_surface("a stroke on the mesh")?;
                self.begin_stroke(tool)?;
                let result = points
                    .into_iter()
                    .try_for_each(|p| self.surface_stroke_to(&surface, p));
                self.end_stroke();
                result?;
            }
        }
        Ok(())
    }

    /// The one-click tools.
    fn paint_command(
        &mut self,
        command: PaintCommand,
        decal_run: Option<LayerId>,
    ) -> Result<(), ModelError> {
        match command {
            PaintCommand::Fill(region) => self.fill(region),
            PaintCommand::Gradient { shape, start, end } => self.gradient(shape, start, end),
            PaintCommand::ProjectImage {
                image,
                projection,
                channels,
                opacity,
            } => self.project_image(&project_image::ProjectSpec {
                image: &image,
                projection: &projection,
                channels,
                opacity,
            }),
            PaintCommand::PlaceDecal {
                image,
                at,
                size,
                rotation,
                channels,
                opacity,
            } => {
                let decal = Decal {
                    image,
                    at,
                    size,
                    rotation,
                    channels,
                    opacity,
                };
                self.decal_step(&decal, decal_run)
            }
            PaintCommand::PreviewDecal(decal) => {
                let placed = self.decal_step(&decal, decal_run);
                // A move refused keeps the placement under way (its preview stays).
                let id = self.state.selection.id;
                self.decal_run = if placed.is_ok() {
                    id
                } else {
                    decal_run.filter(|&run| Some(run) == id)
                };
                placed
            }
            PaintCommand::DropDecal => {
                self.drop_decal(decal_run);
                Ok(())
            }
            PaintCommand::Pick { x, y } => self.pick(x, y, false),
            PaintCommand::PickLayer { x, y } => self.pick(x, y, true),
        }
    }

    /// What workers made from files.
    fn import_command(&mut self, command: ImportCommand) -> Result<(), ModelError> {
        match command {
            ImportCommand::ImportChannel(imported) => self.import_channel(&imported.0),
            ImportCommand::ImportMaterial(imported) => self.import_material(&imported),
            ImportCommand::SetNormal(normal) => {
                self.set_normal(normal.0);
                Ok(())
            }
            ImportCommand::SetMesh(mesh) => self.set_mesh(&mesh),
            ImportCommand::SetBake(bake) => self.set_bakes(vec![bake.0]),
            ImportCommand::SetBakes(bakes) => {
                self.set_bakes(bakes.into_iter().map(|b| b.0).collect())
            }
            ImportCommand::Resize(resized) => self.install_resized(&resized),
        }
    }

    /// Undo, redo and jumps through the history; a stroke in progress ends first.
    fn history_command(&mut self, command: HistoryCommand) {
        self.end_stroke();
        let moved = match command {
            HistoryCommand::Undo => self.history.undo(&mut self.state),
            HistoryCommand::Redo => self.history.redo(&mut self.state),
            HistoryCommand::HistoryJump(applied) => {
                let now = self.history.undo_steps().count();
                let mut moved = false;
                for _ in applied..now {
                    moved |= self.history.undo(&mut self.state);
                }
                for _ in now..applied {
                    if !self.history.redo(&mut self.state) {
                        break;
                    }
                    moved = true;
                }
                moved
            }
        };
        if moved {
            self.after_history();
        }
    }

    /// Refuses a command that may fill a whole layer (or a mask, or a merged layer) when the
    /// memory available could not hold one more layer and its composite: a clear error instead
    /// of an out-of-memory abort part-way through a script.
    fn check_memory(&self, command: &Command) -> Result<(), ModelError> {
        let writes_a_layer = command.may_write_a_whole_layer();
        if !writes_a_layer {
            return Ok(());
        }
        let tiles = self.maps.tile_count() as u64;
        let texels = tiles * crate::tile::TILE_TEXELS as u64;
        // A paint layer's values and coverage (20 bytes a texel), and the composite's (14).
        let bytes = texels * (20 + 14);
        kapaint_base::memory::check_fits("painting a whole layer", bytes).map_err(|e| {
            ModelError::Command(format!(
                "{e}: the document has {} layers; merge or delete some, or use a smaller map",
                paths::count_layers(&self.state.stack.layers)
            ))
        })
    }

    /// An error when `(x, y)` is outside the map.
    fn check_texel(&self, x: u32, y: u32, what: &str) -> Result<(), ModelError> {
        if x >= self.maps.width() || y >= self.maps.height() {
            return Err(ModelError::Command(format!(
                "{what} at ({x}, {y}) is outside the {}x{} map",
                self.maps.width(),
                self.maps.height()
            )));
        }
        Ok(())
    }

    /// After undo or redo swapped the state: the composite follows it, and the maps take
    /// the new size where a step resized them.
    fn after_history(&mut self) {
        let stack = &self.state.stack;
        if (stack.width, stack.height) != (self.maps.width(), self.maps.height()) {
            let version = self.maps.version();
            if let Ok(mut maps) = MaterialMaps::new(stack.width, stack.height, stack.base) {
                maps.stamp_after(version);
                self.maps = maps;
                self.compositor = Compositor::new();
            }
        }
        self.compositor.update(&self.state.stack, &mut self.maps);
        self.sync_settings();
    }

    /// Puts a resized stack and its surface in place, keeping the old ones as one undo step.
    fn install_resized(&mut self, resized: &crate::resize::ResizedMaps) -> Result<(), ModelError> {
        let (stack, surface) = &*resized.0;
        let size = (stack.width, stack.height);
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
        let label = format!(
            "Resize {}x{} to {}x{}",
            self.maps.width(),
            self.maps.height(),
            size.0,
            size.1
        );
        let before = self.state.clone();
        self.state.stack = stack.clone();
        self.state.surface.clone_from(surface);
        self.record(&label, before);
        self.after_history();
        Ok(())
    }
}
