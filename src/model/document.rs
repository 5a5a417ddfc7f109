//! The document: maps, history and settings, changed only through [`Command`]s.
//!
//! The UI and scripts never touch the maps directly: they build commands and call
//! [`Document::apply`]. Every command leaves the maps valid (every texel decodes to finite,
//! in-range values) and every stroke, fill, gradient or import is one undo step.

use glam::Vec2;
use serde::{Deserialize, Serialize};

use super::ModelError;
use super::brush::{BrushSettings, Resampler, Smoother, StrokePoint};
use super::history::History;
use super::maps::MaterialMaps;
use super::paint::{self, Coverage, DiscFootprint, GradientShape, PaintTarget};
use super::texel::{Channel, Channels, MaterialValue};
use crate::reflectance::{AmbientApprox, ShadingModel};

/// The mesh a document is painted on.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum MeshRef {
    /// The built-in UV sphere.
    #[default]
    Sphere,
    /// A mesh file, by path.
    File(String),
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
        tolerance: f32,
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
    /// Fills with the primary material.
    Fill(FillRegion),
    /// A gradient from the primary (at `start`) to the secondary material (at `end`).
    Gradient {
        /// Linear or radial.
        shape: GradientShape,
        /// Start point in texel units.
        start: Vec2,
        /// End point in texel units.
        end: Vec2,
    },
    /// Reads every channel at a texel into the primary material.
    Pick {
        /// Texel column.
        x: u32,
        /// Texel row.
        y: u32,
    },
    /// Undoes the last step.
    Undo,
    /// Redoes the last undone step.
    Redo,
}

/// A stroke in progress.
struct ActiveStroke {
    tool: StrokeTool,
    target: PaintTarget,
    brush: BrushSettings,
    channels: Channels,
    resampler: Resampler,
    smoother: Smoother,
    coverage: Coverage,
    rng: u64,
    dabs: Vec<super::brush::DabPoint>,
}

/// A material being painted.
pub struct Document {
    /// The maps (read freely; change them only through commands).
    pub maps: MaterialMaps,
    /// Undo and redo.
    pub history: History,
    /// Settings saved with the project.
    pub settings: DocumentSettings,
    stroke: Option<ActiveStroke>,
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
            stroke: None,
        })
    }

    /// A document around existing maps (loading), with empty history.
    pub fn from_parts(maps: MaterialMaps, settings: DocumentSettings) -> Self {
        Self {
            maps,
            history: History::default(),
            settings,
            stroke: None,
        }
    }

    /// Whether a stroke is in progress.
    pub fn stroking(&self) -> bool {
        self.stroke.is_some()
    }

    /// Applies a command.
    pub fn apply(&mut self, command: Command) -> Result<(), ModelError> {
        match command {
            Command::SetBrush(b) => self.settings.brush = b.sanitized(),
            Command::SetPrimary(v) => self.settings.primary = v.sanitized(),
            Command::SetSecondary(v) => self.settings.secondary = v.sanitized(),
            Command::SwapMaterials => {
                std::mem::swap(&mut self.settings.primary, &mut self.settings.secondary);
            }
            Command::SetChannels(c) => self.settings.channels = c,
            Command::SetModel(m) => self.settings.model = m,
            Command::SetApprox(a) => self.settings.approx = a,
            Command::BeginStroke(tool) => self.begin_stroke(tool),
            Command::StrokeTo(p) => self.stroke_to(p),
            Command::EndStroke => self.end_stroke(),
            Command::AbortStroke => self.abort_stroke(),
            Command::Stroke { tool, points } => {
                self.begin_stroke(tool);
                for p in points {
                    self.stroke_to(p);
                }
                self.end_stroke();
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
                self.settings.primary = self.maps.value(x, y);
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
        self.stroke = Some(ActiveStroke {
            tool,
            target,
            channels: self.settings.channels,
            resampler: Resampler::new(brush.spacing_px()),
            smoother: Smoother::new(brush.smoothing_px),
            coverage: Coverage::default(),
            rng: 0x5EED_0F4A_9A1E_5700,
            brush,
            dabs: Vec::new(),
        });
    }

    fn stroke_to(&mut self, point: StrokePoint) {
        let Some(stroke) = &mut self.stroke else {
            return;
        };
        let Some(pos) = stroke.smoother.follow(point.pos) else {
            return;
        };
        stroke.dabs.clear();
        stroke.resampler.push(
            StrokePoint {
                pos,
                pressure: point.pressure,
            },
            &mut stroke.dabs,
        );
        let dabs = std::mem::take(&mut stroke.dabs);
        for dab in &dabs {
            self.apply_dab(dab.pos, dab.pressure);
        }
        if let Some(stroke) = &mut self.stroke {
            stroke.dabs = dabs;
        }
    }

    /// One dab and its mirrored copies.
    fn apply_dab(&mut self, pos: Vec2, pressure: f32) {
        let (w, h) = (self.maps.width() as f32, self.maps.height() as f32);
        let Some(stroke) = &mut self.stroke else {
            return;
        };
        let b = &stroke.brush;
        let radius = if b.pressure_size {
            b.radius_px * pressure.max(0.05)
        } else {
            b.radius_px
        };
        let alpha = if b.pressure_opacity {
            b.flow * pressure
        } else {
            b.flow
        };
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
            let fp = DiscFootprint {
                center: c,
                radius,
                brush: &stroke.brush,
            };
            match stroke.tool {
                StrokeTool::Brush | StrokeTool::Eraser => paint::paint_dab(
                    &mut self.maps,
                    &mut self.history,
                    &mut stroke.coverage,
                    &stroke.target,
                    stroke.brush.opacity,
                    alpha,
                    &fp,
                ),
                StrokeTool::Blur => paint::blur_dab(
                    &mut self.maps,
                    &mut self.history,
                    stroke.channels,
                    stroke.brush.blur_radius_px,
                    alpha * stroke.brush.opacity,
                    &fp,
                ),
            }
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
