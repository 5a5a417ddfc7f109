//! Strokes: smoothing and resampling input into dabs, jitter, mirroring, and each dab's tool.

use glam::{Vec2, Vec3};

use super::copy_dab::{self, CloneSource};
use super::surface_copy::{self, SourceGrid};

mod stencil_weights;
mod surface;

use self::stencil_weights::{StencilOn, StencilRead, StencilWeights};
use super::{Document, StrokeTool};
use crate::ModelError;
use crate::brush::BlendMode;
use crate::brush::{BrushSettings, Resampler, Smoother, StrokePoint, SurfacePos};
use crate::layers::edit::{self, LayerEdit, Planes, PrePlanes};
use crate::layers::{Compositor, LayerStroke, State};
use crate::maps::MaterialMaps;
use crate::paint::{Coverage, DiscFootprint, Footprint};
use crate::texel::Channels;
use crate::tile::TileSpans;

/// A stroke in progress.
pub(super) struct ActiveStroke {
    tool: StrokeTool,
    target: LayerEdit,
    /// The state before the stroke: each dab blends from its planes, and undo restores it.
    before: State,
    label: &'static str,
    /// Whether a dab wrote anything.
    touched: bool,
    brush: BrushSettings,
    channels: Channels,
    resampler: Resampler,
    smoother: Smoother,
    surface_resampler: Resampler<SurfacePos>,
    surface_smoother: Smoother<SurfacePos>,
    coverage: Coverage,
    rng: u64,
    /// A clone stroke's source (set at its first point).
    clone: Option<CloneSource>,
    /// A smudge stroke's last dab centres, one per mirrored copy.
    last_dabs: Vec<Vec2>,
    /// The same on the mesh (object space).
    last_surface_dabs: Vec<Vec3>,
    /// The stencil's weights where the stroke's dabs read them, each tile once.
    stencil_weights: StencilWeights,
}

/// The parts of a stroke a dab reads, borrowed apart so a footprint can hold the brush.
struct StrokeParts<'a> {
    tool: StrokeTool,
    target: &'a LayerEdit,
    before: &'a State,
    brush: &'a BrushSettings,
    channels: Channels,
    coverage: &'a mut Coverage,
    touched: &'a mut bool,
    clone: Option<&'a CloneSource>,
    stencil_weights: &'a StencilWeights,
}

impl ActiveStroke {
    fn parts(&mut self) -> StrokeParts<'_> {
        StrokeParts {
            tool: self.tool,
            target: &self.target,
            before: &self.before,
            brush: &self.brush,
            channels: self.channels,
            coverage: &mut self.coverage,
            touched: &mut self.touched,
            clone: self.clone.as_ref(),
            stencil_weights: &self.stencil_weights,
        }
    }
}

/// What a dab writes into: the document's state and its composite, borrowed apart from the
/// stroke.
struct DabTarget<'a> {
    maps: &'a mut MaterialMaps,
    state: &'a mut State,
    compositor: &'a mut Compositor,
}

impl Document {
    /// Starts a stroke on the selected layer's content or mask.
    ///
    /// # Errors
    /// When the selection cannot be painted (locked, a fill layer's content, no layer).
    pub(super) fn begin_stroke(&mut self, tool: StrokeTool) -> Result<(), ModelError> {
        self.end_stroke();
        self.check_paintable()?;
        let brush = self.settings.brush.clone().sanitized();
        let (stroke, label) = match tool {
            StrokeTool::Brush => (LayerStroke::Brush(brush.blend), "Brush stroke"),
            StrokeTool::Eraser => (LayerStroke::Erase, "Eraser stroke"),
            StrokeTool::Blur => (LayerStroke::Brush(brush.blend), "Blur stroke"),
            StrokeTool::Clone => {
                if self.aids.clone_source.is_none() && self.aids.surface_clone_source.is_none() {
                    return Err(ModelError::Command(
                        "clone needs a source: set one first (SetCloneSource, or Ctrl+click in the editor)".into(),
                    ));
                }
                (LayerStroke::Brush(BlendMode::Normal), "Clone stroke")
            }
            StrokeTool::Smudge => (LayerStroke::Brush(BlendMode::Normal), "Smudge stroke"),
        };
        let target = self.layer_edit(self.settings.primary, self.settings.primary, stroke);
        // On a mesh, sizes in texels become object units at the mesh's texel density.
        let units = self
            .state
            .surface
            .as_ref()
            .map_or(1.0, |s| s.units_per_texel);
        // A smudge drags by whole dab steps: at most a tenth of the radius apart, so the
        // steps do not show as bands across the smear.
        let spacing = match tool {
            StrokeTool::Smudge => brush.spacing_px().min((0.1 * brush.radius_px).max(0.5)),
            StrokeTool::Brush | StrokeTool::Eraser | StrokeTool::Blur | StrokeTool::Clone => {
                brush.spacing_px()
            }
        };
        self.stroke = Some(ActiveStroke {
            tool,
            target,
            before: self.state.clone(),
            label,
            touched: false,
            channels: self.settings.channels,
            resampler: Resampler::new(spacing),
            smoother: Smoother::new(brush.smoothing_px),
            surface_resampler: Resampler::new(spacing * units),
            surface_smoother: Smoother::new(brush.smoothing_px * units),
            coverage: Coverage::default(),
            rng: 0x5EED_0F4A_9A1E_5700,
            brush,
            clone: None,
            last_dabs: Vec::new(),
            last_surface_dabs: Vec::new(),
            stencil_weights: StencilWeights::default(),
        });
        Ok(())
    }

    /// Moves the stroke; the dabs of a stroke past [`crate::brush::MAX_STROKE_DABS`] are
    /// not painted, and the error says so (what was painted stays, as one undo step).
    pub(super) fn stroke_to(&mut self, point: StrokePoint) -> Result<(), ModelError> {
        let Some(stroke) = &mut self.stroke else {
            return Ok(());
        };
        if stroke.tool == StrokeTool::Clone && stroke.clone.is_none() {
            // Aligned: the offset from the first clone stroke's first point, kept until a new
            // source is set.
            let source = self.aids.clone_source.unwrap_or(point.pos);
            let offset = *self
                .aids
                .clone_offset
                .get_or_insert_with(|| (source - point.pos).round());
            stroke.clone = Some(CloneSource {
                tiles: self.maps.tiles().to_vec(),
                offset,
                object: None,
            });
        }
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

    /// Applies the stroke's tool through footprint `fp` (which may borrow `stroke.brush`) to
    /// the selected planes, and recomposites the tiles it touched; a smudge drags by `step`,
    /// and a stencil caps what the brush, the eraser and clone cover.
    fn dab_with(
        to: &mut DabTarget<'_>,
        stroke: StrokeParts<'_>,
        alpha: f32,
        fp: &impl Footprint,
        (step, stencil, grid): (Vec2, Option<StencilOn<'_>>, Option<&SourceGrid<'_>>),
    ) {
        let StrokeParts {
            tool,
            target,
            before,
            brush,
            channels,
            coverage,
            touched,
            clone,
            stencil_weights,
        } = stroke;
        let mut ids = fp.tiles(to.maps);
        ids.sort_unstable();
        ids.dedup();
        if ids.is_empty() || alpha <= 0.0 || brush.opacity <= 0.0 {
            return;
        }
        // Tiles composited up to date before the dab need recompositing only where it writes.
        let current = to.compositor.current(&to.state.stack, &ids);
        let selection = to.state.selection();
        let Some(layer) = to.state.stack.layer_mut(&selection.path) else {
            return;
        };
        let Some(planes) = layer.planes_mut(selection.mask) else {
            return;
        };
        let maps: &MaterialMaps = to.maps;
        let pre = || {
            before
                .stack
                .layer(&selection.path)
                .and_then(|l| l.planes(selection.mask))
        };
        *touched = true;
        // What the brush, the eraser and clone raise the stroke's coverage by.
        let raise = DabRaise {
            fp,
            maps,
            alpha,
            opacity: brush.opacity,
            stencil: stencil.map(|on| StencilRead::new(on, stencil_weights)),
        };
        let written = match tool {
            StrokeTool::Brush | StrokeTool::Eraser => {
                let Some(pre) = pre() else {
                    return;
                };
                cover_dab((planes, pre), target, coverage, (maps, &ids), &raise)
            }
            StrokeTool::Clone => {
                let (Some(pre), Some(source)) = (pre(), clone) else {
                    return;
                };
                let at = (maps, ids.as_slice());
                match grid {
                    Some(grid) => surface_copy::surface_clone_dab(
                        (planes, pre),
                        target,
                        coverage,
                        at,
                        (source, grid),
                        &raise,
                    ),
                    None => {
                        copy_dab::clone_dab((planes, pre), target, coverage, at, source, &raise)
                    }
                }
            }
            StrokeTool::Smudge => {
                let strength = alpha * brush.opacity;
                match grid {
                    Some(grid) => surface_copy::surface_smudge_dab(
                        planes,
                        target,
                        (maps, &ids),
                        (fp, strength),
                        grid,
                    ),
                    None => copy_dab::smudge_dab(planes, target, (maps, &ids), fp, strength, step),
                }
            }
            StrokeTool::Blur => {
                let ch = [channels.kd, channels.ks, channels.n];
                let strength = alpha * brush.opacity;
                blur_dab(
                    planes,
                    (maps, &ids),
                    fp,
                    strength,
                    (ch, brush.blur_radius_px),
                )
            }
        };
        Self::recomposite(to, &ids, written, &current);
    }

    /// Recomposites what a dab wrote in the tiles `ids` (all of a tile that was not up to
    /// date before it).
    fn recomposite(
        to: &mut DabTarget<'_>,
        ids: &[usize],
        written: Vec<TileSpans>,
        current: &[bool],
    ) {
        let regions: Vec<_> = ids
            .iter()
            .zip(written)
            .zip(current)
            .filter_map(|((&id, spans), &current)| {
                if !current {
                    Some((id, TileSpans::FULL))
                } else if spans.is_empty() {
                    None
                } else {
                    Some((id, spans))
                }
            })
            .collect();
        to.compositor
            .update_regions(&to.state.stack, to.maps, &regions);
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
        // A smudge's first dab only picks up; each later one drags by the step since the
        // same mirrored copy's last dab.
        let mut steps = vec![Vec2::ZERO; centers.len()];
        if stroke.tool == StrokeTool::Smudge {
            let first = stroke.last_dabs.len() != centers.len();
            for (k, &c) in centers.iter().enumerate() {
                steps[k] = if first {
                    Vec2::ZERO
                } else {
                    c - stroke.last_dabs[k]
                };
            }
            stroke.last_dabs.clone_from(&centers);
            if first {
                return;
            }
        }
        // A stencil on the screen is for strokes on the mesh.
        let stencil = stroke
            .tool
            .paints_through_stencil()
            .then(|| self.aids.stencil.clone())
            .flatten()
            .filter(|s| s.view.is_none());
        if let Some(s) = &stencil {
            stroke
                .stencil_weights
                .prepare(s, None, self.maps.tile_count());
        }
        for (c, step) in centers.into_iter().zip(steps) {
            let parts = stroke.parts();
            let brush = parts.brush;
            let fp = DiscFootprint {
                center: c,
                radius,
                brush,
            };
            let mut to = DabTarget {
                maps: &mut self.maps,
                state: &mut self.state,
                compositor: &mut self.compositor,
            };
            let stencil = stencil.as_deref().map(StencilOn::Texels);
            Self::dab_with(&mut to, parts, alpha, &fp, (step, stencil, None));
        }
    }

    /// Ends the stroke: one undo step if it changed anything.
    pub(super) fn end_stroke(&mut self) {
        if let Some(stroke) = self.stroke.take()
            && stroke.touched
        {
            self.record(stroke.label, stroke.before);
        }
    }

    /// Abandons the stroke, restoring the state before it.
    pub(super) fn abort_stroke(&mut self) {
        if let Some(stroke) = self.stroke.take() {
            self.state = stroke.before;
            self.compositor.update(&self.state.stack, &mut self.maps);
        }
    }
}

/// A brush or eraser dab raising the stroke's coverage by `raise`: the coverage rises where
/// the dab reaches, then every texel whose coverage rose takes its pre-stroke value at that
/// coverage. Returns, per tile of `ids`, the texels written.
///
/// A texel whose coverage did not rise (the stroke already covers it as much as this dab
/// would) already holds its pre-stroke value at that coverage, and is left alone: where dabs
/// overlap, only what they add is written and recomposited.
fn cover_dab(
    (planes, pre): (Planes<'_>, PrePlanes<'_>),
    target: &LayerEdit,
    coverage: &mut Coverage,
    (maps, ids): (&MaterialMaps, &[usize]),
    raise: &impl edit::Raise,
) -> Vec<TileSpans> {
    let covers = coverage.tiles_mut(maps.tile_count(), ids);
    edit::edit_cover((planes, pre), target, ids, covers, raise)
}

/// A dab's raise of the stroke's coverage: towards `opacity` (times the stencil's weight,
/// where there is one) by the footprint's weight times `alpha`.
struct DabRaise<'a, F> {
    fp: &'a F,
    maps: &'a MaterialMaps,
    alpha: f32,
    opacity: f32,
    stencil: Option<StencilRead<'a>>,
}

impl<F: Footprint + Sync> edit::Raise for DabRaise<'_, F> {
    #[inline(always)]
    #[expect(
        clippy::inline_always,
        reason = "compiled into a `simd::vectorized` kernel: only code inlined there is vectorised for the wider instructions"
    )]
    fn raise(&self, id: usize, cov: &mut [f32]) -> TileSpans {
        let (alpha, opacity) = (self.alpha, self.opacity);
        let mut rose = TileSpans::EMPTY;
        // A row's run at a time: the raise in a loop that vectorises, then where it rose.
        let mut up = [false; crate::tile::TILE_SIZE];
        let mut caps = [opacity; crate::tile::TILE_SIZE];
        let rect = self.maps.tile_rect(id);
        // The run's body inlined too (a closure left out of line is compiled for the baseline).
        self.fp.visit_runs(
            id,
            rect,
            #[inline(always)]
            |start, weights| {
                let row = &mut cov[start..start + weights.len()];
                let up = &mut up[..weights.len()];
                let caps = &mut caps[..weights.len()];
                if let Some(stencil) = &self.stencil {
                    stencil.weights(self.maps, id, start, caps);
                    for cap in caps.iter_mut() {
                        *cap *= opacity;
                    }
                }
                for (((c, &w), up), &cap) in row
                    .iter_mut()
                    .zip(weights)
                    .zip(up.iter_mut())
                    .zip(caps.iter())
                {
                    let next = *c + (cap - *c) * (w * alpha).min(1.0);
                    *up = next > *c;
                    *c = if *up { next } else { *c };
                }
                let first = up.iter().position(|&u| u);
                if let (Some(first), Some(last)) = (first, up.iter().rposition(|&u| u)) {
                    rose.include_run(start + first, start + last + 1);
                }
            },
        );
        rose
    }
}

/// A blur dab through `fp` at `strength` over `channels` with a kernel of `radius` texels.
/// Returns, per tile of `ids`, the texels written.
fn blur_dab(
    planes: Planes<'_>,
    (maps, ids): (&MaterialMaps, &[usize]),
    fp: &impl Footprint,
    strength: f32,
    (channels, radius): ([bool; 3], u32),
) -> Vec<TileSpans> {
    let weights: Vec<_> = ids
        .iter()
        .map(|&id| {
            let mut texels = Vec::new();
            fp.visit_tile(id, maps.tile_rect(id), |i, w| {
                texels.push((i, (w * strength).min(1.0)));
            });
            (id, texels)
        })
        .collect();
    let written = weights
        .iter()
        .map(|(_, texels)| {
            let mut spans = TileSpans::EMPTY;
            for &(i, _) in texels {
                spans.include(i);
            }
            spans
        })
        .collect();
    let size = (maps.width(), maps.height());
    match planes {
        Planes::Paint(tiles) => {
            let pre = tiles.to_vec();
            let pre = PrePlanes::Paint(&pre);
            edit::blur(Planes::Paint(tiles), pre, size, channels, radius, weights);
        }
        Planes::Mask(tiles) => {
            let pre = tiles.to_vec();
            let pre = PrePlanes::Mask(&pre);
            edit::blur(Planes::Mask(tiles), pre, size, channels, radius, weights);
        }
    }
    written
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
