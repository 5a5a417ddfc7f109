//! Strokes: smoothing and resampling input into dabs, jitter, mirroring, and each dab's tool.

use glam::{Vec2, Vec3};

use super::{Document, StrokeTool};
use crate::model::ModelError;
use crate::model::brush::{
    BrushSettings, DabPoint, Resampler, Smoother, StrokePoint, SurfacePoint, SurfacePos,
};
use crate::model::history::History;
use crate::model::maps::MaterialMaps;
use crate::model::paint::{self, Coverage, DiscFootprint, Footprint, PaintTarget};
use crate::model::surface::{BallFootprint, Surface};
use crate::model::texel::Channels;

/// A stroke in progress.
pub(super) struct ActiveStroke {
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

impl Document {
    pub(super) fn begin_stroke(&mut self, tool: StrokeTool) {
        self.end_stroke();
        let brush = self.settings.brush.clone().sanitized();
        let (value, label) = match tool {
            StrokeTool::Brush => (self.settings.primary, "Brush stroke"),
            StrokeTool::Eraser => (self.settings.base, "Eraser stroke"),
            StrokeTool::Blur => (self.settings.primary, "Blur stroke"),
        };
        let mut target = self.target_for(value);
        if tool == StrokeTool::Eraser {
            target.mode = crate::model::brush::BlendMode::Normal;
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

    /// Moves the stroke; the dabs of a stroke past [`crate::model::brush::MAX_STROKE_DABS`] are
    /// not painted, and the error says so (what was painted stays, as one undo step).
    pub(super) fn stroke_to(&mut self, point: StrokePoint) -> Result<(), ModelError> {
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
    pub(super) fn surface_stroke_to(
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

    pub(super) fn end_stroke(&mut self) {
        if self.stroke.take().is_some() {
            self.history.end();
        }
    }

    pub(super) fn abort_stroke(&mut self) {
        if self.stroke.take().is_some() {
            self.history.abort(&mut self.maps);
        }
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
