//! Strokes on the mesh: each dab a ball in object space (with its mirrored copies), and a
//! clone's or a smudge's source found in object space.

use glam::{Vec2, Vec3};

use super::{DabTarget, StencilOn, next_unit};
use crate::ModelError;
use crate::brush::{DabPoint, StrokePoint, SurfacePoint, SurfacePos};
use crate::document::copy_dab::CloneSource;
use crate::document::surface_copy::SourceGrid;
use crate::document::{Document, StrokeTool};
use crate::surface::{BallFootprint, Surface};

impl Document {
    /// [`Self::stroke_to`] on the mesh.
    pub(in crate::document) fn surface_stroke_to(
        &mut self,
        surface: &Surface,
        point: SurfacePoint,
    ) -> Result<(), ModelError> {
        let Some(stroke) = &mut self.stroke else {
            return Ok(());
        };
        if stroke.tool == StrokeTool::Clone && stroke.clone.is_none() {
            // Aligned in object space: the offset from the first mesh clone stroke's first
            // point, kept until a new source is set.
            let Some(source) = self.aids.surface_clone_source else {
                return Err(ModelError::Command(
                    "clone on the mesh needs a source on the mesh: set one first (SetSurfaceCloneSource, or Ctrl+click on the mesh in the editor)".into(),
                ));
            };
            let offset = *self
                .aids
                .surface_clone_offset
                .get_or_insert(source - point.pos.point);
            stroke.clone = Some(CloneSource {
                tiles: self.maps.tiles().to_vec(),
                offset: Vec2::ZERO,
                object: Some(offset),
            });
        }
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
        let (stencil, to_clip) =
            surface_stencil(stroke, self.aids.stencil.as_ref(), surface, &self.maps);
        // A smudge's first dab only picks up; each later one drags by the step (object
        // space) since the same mirrored copy's last dab.
        let steps = if stroke.tool == StrokeTool::Smudge {
            let first = stroke.last_surface_dabs.len() != dabs.len();
            let steps: Vec<Vec3> = dabs
                .iter()
                .zip(
                    stroke
                        .last_surface_dabs
                        .iter()
                        .chain(std::iter::repeat(&Vec3::ZERO)),
                )
                .map(|(&(c, _), &last)| if first { Vec3::ZERO } else { c - last })
                .collect();
            stroke.last_surface_dabs = dabs.iter().map(|&(c, _)| c).collect();
            if first {
                return;
            }
            Some(steps)
        } else {
            None
        };
        for (k, (center, normal)) in dabs.into_iter().enumerate() {
            let parts = stroke.parts();
            // Where a mesh clone or smudge reads, found in object space near this dab: the
            // clone's offset, or back along the smudge's step.
            let shift = match &steps {
                Some(steps) => Some(-steps[k]),
                None => parts.clone.and_then(|c| c.object),
            };
            let grid = match shift {
                Some(offset) => match SourceGrid::new(surface, (center, normal), radius, offset) {
                    Some(grid) => Some(grid),
                    // No surface near this dab's source: it copies nothing.
                    None => continue,
                },
                None => None,
            };
            let brush = parts.brush;
            let fp = BallFootprint {
                surface,
                center,
                radius,
                normal: if front { normal } else { Vec3::ZERO },
                brush,
            };
            let mut to = DabTarget {
                maps: &mut self.maps,
                state: &mut self.state,
                compositor: &mut self.compositor,
            };
            let stencil = stencil.as_deref().map(|s| match to_clip {
                Some(m) => StencilOn::Screen(s, surface, m),
                None => StencilOn::Texels(s),
            });
            Self::dab_with(
                &mut to,
                parts,
                alpha,
                &fp,
                (Vec2::ZERO, stencil, grid.as_ref()),
            );
        }
    }
}

/// The stencil a stroke on the mesh paints through, on the canvas (where each texel lies) or
/// on the screen (where its surface point projects: with the view's matrix to clip space),
/// its weights made ready in the stroke.
fn surface_stencil(
    stroke: &mut super::ActiveStroke,
    stencil: Option<&std::sync::Arc<crate::paint::Stencil>>,
    surface: &Surface,
    maps: &crate::maps::MaterialMaps,
) -> (
    Option<std::sync::Arc<crate::paint::Stencil>>,
    Option<glam::Mat4>,
) {
    let stencil = stencil
        .filter(|_| stroke.tool.paints_through_stencil())
        .cloned();
    let to_clip = stencil
        .as_ref()
        .and_then(|s| s.view.as_ref())
        .map(crate::paint::ScreenView::to_clip);
    if let Some(s) = &stencil {
        let on_screen = to_clip.is_some().then_some(surface);
        stroke
            .stencil_weights
            .prepare(s, on_screen, maps.tile_count());
    }
    (stencil, to_clip)
}
