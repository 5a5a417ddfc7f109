//! The document: maps, history and settings, changed only through [`Command`]s.
//!
//! The UI and scripts never touch the maps directly: they build commands and call
//! [`Document::apply`]. Every command leaves the maps valid (every texel decodes to finite,
//! in-range values) and every stroke, fill, gradient or import is one undo step.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

use super::ModelError;
use super::brush::{
    BrushSettings, DabPoint, Resampler, Smoother, StrokePoint, SurfacePoint, SurfacePos,
};
use super::history::History;
use super::maps::MaterialMaps;
use super::paint::{self, Coverage, DiscFootprint, Footprint, GradientShape, PaintTarget};
use super::surface::{BallFootprint, Surface};
use super::texel::{Channel, Channels, MaterialValue};
use crate::reflectance::{AmbientApprox, ShadingModel};

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

/// Tools that work as strokes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StrokeTool {
    /// Paints the primary material.
    Brush,
    /// Paints the base material back.
    Eraser,
    /// Smooths the enabled channels.
    Blur,
}

/// Which texels a fill writes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum FillRegion {
    /// The whole map.
    All,
    /// The connected region around a texel whose channel is within `tolerance` (blend space).
    Similar {
        /// Seed texel column.
        x: u32,
        /// Seed texel row.
        y: u32,
        /// Channel compared.
        channel: Channel,
        /// Largest difference still filled, in `[0, 1]`.
        #[serde(deserialize_with = "super::check::tolerance")]
        tolerance: f32,
    },
    /// The UV island under a texel (needs the document's mesh surface).
    Island {
        /// Texel column.
        x: u32,
        /// Texel row.
        y: u32,
    },
    /// The mesh part (connected piece of surface, across UV seams) under a texel.
    Part {
        /// Texel column.
        x: u32,
        /// Texel row.
        y: u32,
    },
}

/// Everything that changes a document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Command {
    /// Replaces the brush settings (sanitised).
    SetBrush(BrushSettings),
    /// Sets the primary material.
    SetPrimary(MaterialValue),
    /// Sets the secondary material.
    SetSecondary(MaterialValue),
    /// Swaps primary and secondary.
    SwapMaterials,
    /// Sets the channels tools write.
    SetChannels(Channels),
    /// Sets the shading model.
    SetModel(ShadingModel),
    /// Sets the approximation of `chi`.
    SetApprox(AmbientApprox),
    /// Starts a stroke (one undo step).
    BeginStroke(StrokeTool),
    /// Moves the stroke to a new input point.
    StrokeTo(StrokePoint),
    /// Ends the stroke.
    EndStroke,
    /// Abandons the stroke, restoring the maps.
    AbortStroke,
    /// A whole stroke at once (scripts): begin, every point, end.
    Stroke {
        /// The tool.
        tool: StrokeTool,
        /// Input points in texel units.
        points: Vec<StrokePoint>,
    },
    /// Moves the stroke to a new point on the mesh (object-space brush; needs a surface).
    SurfaceStrokeTo(SurfacePoint),
    /// A whole stroke on the mesh at once (scripts).
    SurfaceStroke {
        /// The tool.
        tool: StrokeTool,
        /// Input points in object space.
        points: Vec<SurfacePoint>,
    },
    /// Fills with the primary material.
    Fill(FillRegion),
    /// A gradient from the primary (at `start`) to the secondary material (at `end`).
    Gradient {
        /// Linear or radial.
        shape: GradientShape,
        /// Start point in texel units.
        #[serde(deserialize_with = "super::check::finite_vec2")]
        start: Vec2,
        /// End point in texel units.
        #[serde(deserialize_with = "super::check::finite_vec2")]
        end: Vec2,
    },
    /// Reads every channel at a texel into the primary material.
    Pick {
        /// Texel column.
        x: u32,
        /// Texel row.
        y: u32,
    },
    /// Replaces a channel with an image already resampled to the map size (one undo step;
    /// see [`super::import`]). Not for scripts: its planes come from a decoder.
    #[serde(skip)]
    ImportChannel(ImportedChannel),
    /// Undoes the last step.
    Undo,
    /// Redoes the last undone step.
    Redo,
}

/// A channel's planes made by [`super::import::resample`], shared so that the command clones
/// cheaply.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedChannel(pub Arc<super::import::ChannelPlanes>);

impl Command {
    /// Whether the command paints on the mesh (and so needs [`Document::set_surface`]).
    pub fn needs_surface(&self) -> bool {
        matches!(
            self,
            Self::SurfaceStrokeTo(_)
                | Self::SurfaceStroke { .. }
                | Self::Fill(FillRegion::Island { .. } | FillRegion::Part { .. })
        )
    }
}

/// A stroke in progress.
struct ActiveStroke {
    tool: StrokeTool,
    target: PaintTarget,
    brush: BrushSettings,
    channels: Channels,
    resampler: Resampler,
    smoother: Smoother,
    surface_resampler: Resampler<SurfacePos>,
    surface_smoother: Smoother<SurfacePos>,
    coverage: Coverage,
    rng: u64,
}

/// The parts of a stroke a dab reads, borrowed apart so a footprint can hold the brush.
struct StrokeParts<'a> {
    tool: StrokeTool,
    target: &'a PaintTarget,
    brush: &'a BrushSettings,
    channels: Channels,
    coverage: &'a mut Coverage,
}

impl ActiveStroke {
    fn parts(&mut self) -> StrokeParts<'_> {
        StrokeParts {
            tool: self.tool,
            target: &self.target,
            brush: &self.brush,
            channels: self.channels,
            coverage: &mut self.coverage,
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
        Ok(Self {
            maps,
            history: History::default(),
            settings,
            surface: None,
            stroke: None,
            settings_version: 0,
        })
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
            return Err(ModelError::Command(format!(
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
                self.history.undo(&mut self.maps);
            }
            Command::Redo => {
                self.end_stroke();
                self.history.redo(&mut self.maps);
            }
        }
        Ok(())
    }

    fn target_for(&self, value: MaterialValue) -> PaintTarget {
        let s = &self.settings;
        PaintTarget::new(value, s.channels, s.brush.blend, s.brush.energy_guard)
    }

    fn begin_stroke(&mut self, tool: StrokeTool) {
        self.end_stroke();
        let brush = self.settings.brush.clone().sanitized();
        let (value, label) = match tool {
            StrokeTool::Brush => (self.settings.primary, "Brush stroke"),
            StrokeTool::Eraser => (self.settings.base, "Eraser stroke"),
            StrokeTool::Blur => (self.settings.primary, "Blur stroke"),
        };
        let mut target = self.target_for(value);
        if tool == StrokeTool::Eraser {
            target.mode = super::brush::BlendMode::Normal;
        }
        self.history.begin(label);
        // On a mesh, sizes in texels become object units at the mesh's texel density.
        let units = self.surface.as_ref().map_or(1.0, |s| s.units_per_texel);
        self.stroke = Some(ActiveStroke {
            tool,
            target,
            channels: self.settings.channels,
            resampler: Resampler::new(brush.spacing_px()),
            smoother: Smoother::new(brush.smoothing_px),
            surface_resampler: Resampler::new(brush.spacing_px() * units),
            surface_smoother: Smoother::new(brush.smoothing_px * units),
            coverage: Coverage::default(),
            rng: 0x5EED_0F4A_9A1E_5700,
            brush,
        });
    }

    /// Moves the stroke; the dabs of a stroke past [`super::brush::MAX_STROKE_DABS`] are not
    /// painted, and the error says so (what was painted stays, as one undo step).
    fn stroke_to(&mut self, point: StrokePoint) -> Result<(), ModelError> {
        let Some(stroke) = &mut self.stroke else {
            return Ok(());
        };
        let Some(pos) = stroke.smoother.follow(point.pos) else {
            return Ok(());
        };
        let mut dabs = Vec::new();
        let placed = stroke.resampler.push(
            StrokePoint {
                pos,
                pressure: point.pressure,
            },
            &mut dabs,
        );
        for dab in &dabs {
            self.apply_dab(dab.pos, dab.pressure);
        }
        placed.map_err(|e| ModelError::Command(e.to_string()))
    }

    /// [`Self::stroke_to`] on the mesh.
    fn surface_stroke_to(
        &mut self,
        surface: &Surface,
        point: SurfacePoint,
    ) -> Result<(), ModelError> {
        let Some(stroke) = &mut self.stroke else {
            return Ok(());
        };
        let Some(pos) = stroke.surface_smoother.follow(point.pos) else {
            return Ok(());
        };
        let mut dabs = Vec::new();
        let placed = stroke.surface_resampler.push(
            StrokePoint {
                pos,
                pressure: point.pressure,
            },
            &mut dabs,
        );
        for dab in dabs {
            self.apply_surface_dab(surface, dab);
        }
        placed.map_err(|e| ModelError::Command(e.to_string()))
    }

    /// Radius and alpha of a dab at `pressure`, in texels.
    fn dab_size(brush: &BrushSettings, pressure: f32) -> (f32, f32) {
        let radius = if brush.pressure_size {
            brush.radius_px * pressure.max(0.05)
        } else {
            brush.radius_px
        };
        let alpha = if brush.pressure_opacity {
            brush.flow * pressure
        } else {
            brush.flow
        };
        (radius, alpha)
    }

    /// One object-space dab and its mirrored copies.
    fn apply_surface_dab(&mut self, surface: &Surface, dab: DabPoint<SurfacePos>) {
        let Some(stroke) = &mut self.stroke else {
            return;
        };
        let b = &stroke.brush;
        let (radius_px, alpha) = Self::dab_size(b, dab.pressure);
        let radius = radius_px * surface.units_per_texel;
        let mut center = dab.pos.point;
        let normal = if dab.pos.normal.length_squared() > 0.0 {
            dab.pos.normal.normalize_or_zero()
        } else {
            surface.normal_near(center, radius).unwrap_or(Vec3::ZERO)
        };
        if b.jitter > 0.0 {
            let (dx, dy) = (next_unit(&mut stroke.rng), next_unit(&mut stroke.rng));
            let (t, u) = if normal == Vec3::ZERO {
                (Vec3::X, Vec3::Y)
            } else {
                normal.any_orthonormal_pair()
            };
            center += (t * dx + u * dy) * (b.jitter * radius);
        }
        let mut dabs = vec![(center, normal)];
        for (on, axis) in [(b.mirror_x, 0), (b.mirror_y, 1), (b.mirror_z, 2)] {
            if on {
                let flip = |mut v: Vec3| {
                    v[axis] = -v[axis];
                    v
                };
                let mirrored: Vec<_> = dabs.iter().map(|&(c, n)| (flip(c), flip(n))).collect();
                dabs.extend(mirrored);
            }
        }
        let front = b.front_faces_only;
        for (center, normal) in dabs {
            let parts = stroke.parts();
            let brush = parts.brush;
            let fp = BallFootprint {
                surface,
                center,
                radius,
                normal: if front { normal } else { Vec3::ZERO },
                brush,
            };
            Self::dab_with(&mut self.maps, &mut self.history, parts, alpha, &fp);
        }
    }

    /// Applies the stroke's tool through footprint `fp` (which may borrow `stroke.brush`).
    fn dab_with(
        maps: &mut MaterialMaps,
        history: &mut History,
        stroke: StrokeParts<'_>,
        alpha: f32,
        fp: &impl Footprint,
    ) {
        let StrokeParts {
            tool,
            target,
            brush,
            channels,
            coverage,
        } = stroke;
        match tool {
            StrokeTool::Brush | StrokeTool::Eraser => {
                paint::paint_dab(maps, history, coverage, target, brush.opacity, alpha, fp);
            }
            StrokeTool::Blur => paint::blur_dab(
                maps,
                history,
                channels,
                brush.blur_radius_px,
                alpha * brush.opacity,
                fp,
            ),
        }
    }

    /// One dab and its mirrored copies.
    fn apply_dab(&mut self, pos: Vec2, pressure: f32) {
        let (w, h) = (self.maps.width() as f32, self.maps.height() as f32);
        let Some(stroke) = &mut self.stroke else {
            return;
        };
        let b = &stroke.brush;
        let (radius, alpha) = Self::dab_size(b, pressure);
        let mut center = pos;
        if b.jitter > 0.0 {
            let (dx, dy) = (next_unit(&mut stroke.rng), next_unit(&mut stroke.rng));
            center += Vec2::new(dx, dy) * (b.jitter * b.radius_px);
        }
        let mut centers = vec![center];
        if b.mirror_u {
            centers.push(Vec2::new(w - center.x, center.y));
        }
        if b.mirror_v {
            centers.push(Vec2::new(center.x, h - center.y));
        }
        if b.mirror_u && b.mirror_v {
            centers.push(Vec2::new(w - center.x, h - center.y));
        }
        for c in centers {
            let parts = stroke.parts();
            let brush = parts.brush;
            let fp = DiscFootprint {
                center: c,
                radius,
                brush,
            };
            Self::dab_with(&mut self.maps, &mut self.history, parts, alpha, &fp);
        }
    }

    fn end_stroke(&mut self) {
        if self.stroke.take().is_some() {
            self.history.end();
        }
    }

    fn abort_stroke(&mut self) {
        if self.stroke.take().is_some() {
            self.history.abort(&mut self.maps);
        }
    }

    fn fill(&mut self, region: FillRegion) -> Result<(), ModelError> {
        self.end_stroke();
        let target = self.target_for(self.settings.primary);
        let opacity = self.settings.brush.opacity;
        match region {
            FillRegion::All => {
                self.history.begin("Fill");
                paint::fill_all(&mut self.maps, &mut self.history, &target, opacity);
            }
            FillRegion::Similar {
                x,
                y,
                channel,
                tolerance,
            } => {
                if x >= self.maps.width() || y >= self.maps.height() {
                    return Err(ModelError::Command(format!(
                        "fill seed ({x}, {y}) is outside the map"
                    )));
                }
                let mask =
                    paint::flood_region(&self.maps, x, y, channel, tolerance.clamp(0.0, 1.0));
                self.history.begin("Fill similar");
                paint::fill_mask(&mut self.maps, &mut self.history, &target, opacity, &mask);
            }
            FillRegion::Island { x, y } | FillRegion::Part { x, y } => {
                let surface = self.require_surface("filling a UV island or mesh part")?;
                let (mask, label) = if matches!(region, FillRegion::Island { .. }) {
                    (surface.island_mask(x, y), "Fill island")
                } else {
                    (surface.part_mask(x, y), "Fill part")
                };
                let mask = mask.ok_or_else(|| {
                    ModelError::Command(format!("no part of the mesh is at texel ({x}, {y})"))
                })?;
                self.history.begin(label);
                paint::fill_mask(&mut self.maps, &mut self.history, &target, opacity, &mask);
            }
        }
        self.history.end();
        Ok(())
    }

    fn gradient(&mut self, shape: GradientShape, start: Vec2, end: Vec2) {
        self.end_stroke();
        if !(start.is_finite() && end.is_finite()) {
            return;
        }
        let from = self.target_for(self.settings.primary);
        let to = self.target_for(self.settings.secondary);
        self.history.begin("Gradient");
        paint::gradient(
            &mut self.maps,
            &mut self.history,
            &from,
            &to,
            shape,
            start,
            end,
            self.settings.brush.opacity,
        );
        self.history.end();
    }
}

/// A deterministic number in `[-1, 1)` (SplitMix64), for jitter that replays identically.
fn next_unit(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 23) as f32 - 1.0
}
