//! `ProjectImage`: an image painted through a projection into the selected layer, one undo
//! step: its colour (decoded from sRGB) into `k_d`, its luminance into `k_s`, its gray into
//! `n` through the import's mapping, each where the command enables it; its alpha times the
//! opacity is the coverage (0 outside the image).

use glam::{Vec2, Vec3};

use super::Document;
use super::decal::Decal;
use crate::ModelError;
use crate::brush::BlendMode;
use crate::layers::LayerStroke;
use crate::layers::edit::{self, TileTargets};
use crate::paint::projection::{DepthMap, Frame3, PlaneFrame, Projection};
use crate::paint_image::{PaintImage, Pixels, Sample};
use crate::surface::Surface;
use crate::texel::{Channels, n_to_blend};
use crate::tile::TileSpans;
use kapaint_mesh::bake::Coverage;

/// A projection made ready for a map: its frame, and for a planar one the mesh's depth map.
enum Mapper {
    Planar(PlaneFrame, DepthMap),
    Cylindrical(Vec3, Frame3, f32),
    Spherical(Vec3, Frame3),
    Triplanar(f32, f32),
    Uv(Vec2, Vec2, f32),
}

/// What the image gives a texel: its seven target components (a mask's gray first when
/// `mask`), and its coverage before the opacity.
fn target(s: &Sample, mask: bool) -> ([f32; 7], f32) {
    let l = s.luminance();
    let c = if mask {
        [s.gray, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    } else {
        [s.rgb.x, s.rgb.y, s.rgb.z, l, l, l, n_to_blend(s.n)]
    };
    (c, s.alpha)
}

impl Mapper {
    fn new(
        projection: &Projection,
        surface: Option<&Surface>,
        image: &Pixels,
        slab: Option<f32>,
    ) -> Result<Self, ModelError> {
        let bad = ModelError::Command;
        Ok(match *projection {
            Projection::Planar {
                origin,
                normal,
                up,
                width,
                height,
            } => {
                let frame =
                    PlaneFrame::new(origin, normal, up, Vec2::new(width, height)).map_err(bad)?;
                let surface = surface.ok_or_else(|| {
                    ModelError::Command("a planar projection needs a mesh".into())
                })?;
                // A cell per image pixel, within reason.
                let side = image.width().max(image.height()).clamp(64, 2048) as usize;
                Self::Planar(frame, DepthMap::new(&frame, &surface.mesh, side, slab))
            }
            Projection::Cylindrical {
                origin,
                axis,
                front,
                height,
            } => Self::Cylindrical(origin, Frame3::new(axis, front).map_err(bad)?, height),
            Projection::Spherical { origin, up, front } => {
                Self::Spherical(origin, Frame3::new(up, front).map_err(bad)?)
            }
            Projection::Triplanar { scale, blend } => Self::Triplanar(scale, blend),
            Projection::Uv {
                offset,
                scale,
                rotation,
            } => Self::Uv(offset, scale, rotation.to_radians()),
        })
    }

    /// The image at a texel: `uv` its place on the map (in maps), `p` and `n` its baked
    /// position and normal.
    fn sample(&self, image: &Pixels, uv: Vec2, p: Vec3, n: Vec3, mask: bool) -> ([f32; 7], f32) {
        const NONE: ([f32; 7], f32) = ([0.0; 7], 0.0);
        match self {
            Self::Planar(frame, depth) => {
                if !frame.faces(n) {
                    return NONE;
                }
                let (at, d) = frame.image_uv(p);
                if !depth.visible(frame, at, d, n) {
                    return NONE;
                }
                target(&image.sample(at, false), mask)
            }
            Self::Cylindrical(origin, frame, height) => {
                let d = p - *origin;
                let along = d.dot(frame.pole);
                let radial = d - frame.pole * along;
                if n.dot(radial) <= 0.0 {
                    return NONE;
                }
                let at = Vec2::new(frame.around(radial), 0.5 - along / height);
                target(&image.sample(at, false), mask)
            }
            Self::Spherical(origin, frame) => {
                let Some(d) = (p - *origin).try_normalize() else {
                    return NONE;
                };
                if n.dot(d) <= 0.0 {
                    return NONE;
                }
                let latitude = d.dot(frame.pole).clamp(-1.0, 1.0).asin();
                let at = Vec2::new(frame.around(d), 0.5 - latitude / std::f32::consts::PI);
                target(&image.sample(at, false), mask)
            }
            Self::Triplanar(scale, blend) => {
                let a = n.abs();
                let top = a.max_element();
                let w = (a - Vec3::splat((1.0 - blend) * top)).max(Vec3::ZERO);
                let sum = w.element_sum();
                if sum <= 0.0 {
                    return NONE;
                }
                // Each axis's plane, the image's top towards +Y (the Y plane's towards -Z).
                let planes = [(p.z, p.y), (p.x, -p.z), (p.x, p.y)];
                let mut out = [0.0_f32; 7];
                let mut alpha = 0.0;
                for (k, (h, v)) in planes.into_iter().enumerate() {
                    if w[k] <= 0.0 {
                        continue;
                    }
                    let at = Vec2::new(h * scale, -v * scale);
                    let (c, a) = target(&image.sample(at, true), mask);
                    let wk = w[k] / sum;
                    for (o, c) in out.iter_mut().zip(c) {
                        *o += c * a * wk;
                    }
                    alpha += a * wk;
                }
                if alpha <= 0.0 {
                    return NONE;
                }
                (out.map(|c| c / alpha), alpha)
            }
            Self::Uv(offset, scale, rotation) => {
                let (sin, cos) = (-rotation).sin_cos();
                let d = uv - 0.5;
                let turned = Vec2::new(d.x * cos - d.y * sin, d.x * sin + d.y * cos) + 0.5;
                target(&image.sample(turned * *scale + *offset, true), mask)
            }
        }
    }
}

/// What `ProjectImage` names.
pub(super) struct ProjectSpec<'a> {
    pub(super) image: &'a PaintImage,
    pub(super) projection: &'a Projection,
    pub(super) channels: Channels,
    pub(super) opacity: f32,
}

/// The undo step's label of a decal's placement.
const DECAL_STEP: &str = "Place decal";

impl Document {
    /// A decal placed as one undo step; right after a preview in the same layer (`run`), in
    /// place of that preview and in its step.
    pub(super) fn decal_step(
        &mut self,
        decal: &Decal,
        run: Option<crate::layers::LayerId>,
    ) -> Result<(), ModelError> {
        let id = self.state.selection.id;
        let joined = id.is_some() && run == id && !self.stroking();
        let Some(before) = joined.then(|| self.history.take_last(DECAL_STEP)).flatten() else {
            return self.place_decal(decal);
        };
        // The preview's placement goes; the new one is laid on what lay before it.
        let preview = std::mem::replace(&mut self.state, before);
        self.place_decal(decal).inspect_err(|_| {
            // Refused (it reaches nothing there): the preview and its step stay as they were.
            let before = std::mem::replace(&mut self.state, preview);
            self.history.push(DECAL_STEP, before, &self.state);
        })
    }

    /// `DropDecal`: the placement under way in the same layer (`run`) taken back out.
    pub(super) fn drop_decal(&mut self, run: Option<crate::layers::LayerId>) {
        let id = self.state.selection.id;
        if id.is_none() || run != id || self.stroking() {
            return;
        }
        if let Some(before) = self.history.take_last(DECAL_STEP) {
            self.state = before;
            self.compositor.update(&self.state.stack, &mut self.maps);
        }
    }

    /// `PlaceDecal`: a planar projection along the surface's normal at the surface point
    /// nearest `at`, `size` object units wide (its height by the image's aspect), turned by
    /// `rotation` degrees about the normal (counter-clockwise seen from outside), reaching
    /// only the surface within its half-diagonal of that point.
    fn place_decal(&mut self, spec: &Decal) -> Result<(), ModelError> {
        let surface = self.require_surface("placing a decal")?;
        let frame = spec.frame(&surface)?;
        let radius = 0.5 * (frame.width * frame.width + frame.height * frame.height).sqrt();
        let projection = Projection::Planar {
            origin: frame.origin,
            normal: frame.normal,
            up: frame.up,
            width: frame.width,
            height: frame.height,
        };
        let project = ProjectSpec {
            image: &spec.image,
            projection: &projection,
            channels: spec.channels,
            opacity: spec.opacity,
        };
        self.project(&project, Some(radius), DECAL_STEP)
    }

    /// `ProjectImage`.
    pub(super) fn project_image(&mut self, spec: &ProjectSpec<'_>) -> Result<(), ModelError> {
        self.project(spec, None, "Project image")
    }

    /// A projection into the selected layer as one undo step `label`; a decal reaches only
    /// the surface within `reach` of its origin.
    fn project(
        &mut self,
        spec: &ProjectSpec<'_>,
        reach: Option<f32>,
        label: &str,
    ) -> Result<(), ModelError> {
        self.end_stroke();
        let pixels = std::sync::Arc::clone(spec.image.pixels()?);
        spec.projection.check().map_err(ModelError::Command)?;
        if !(0.0..=1.0).contains(&spec.opacity) {
            return Err(ModelError::Command(format!(
                "a projection's opacity must be in [0, 1], not {}",
                spec.opacity
            )));
        }
        let surface = if spec.projection.needs_surface() {
            Some(self.require_surface("projecting an image onto the mesh")?)
        } else {
            None
        };
        self.check_paintable()?;
        let mapper = Mapper::new(spec.projection, surface.as_deref(), &pixels, reach)?;
        let mut edit = self.layer_edit(
            self.settings.primary,
            self.settings.primary,
            LayerStroke::Brush(BlendMode::Normal),
        );
        edit.channels = [spec.channels.kd, spec.channels.ks, spec.channels.n];
        let mask = self.painting_mask();
        let (w, h) = (self.maps.width(), self.maps.height());
        let opacity = spec.opacity;
        let surface = surface.as_deref();
        let ball = match (reach, spec.projection) {
            (Some(r), Projection::Planar { origin, .. }) => Some((*origin, r * r)),
            _ => None,
        };
        // Whether any texel took the image, to refuse a projection that hits nothing.
        let reached = std::sync::atomic::AtomicBool::new(false);
        let prepare = |id: usize, cover: &mut [f32], targets: &mut TileTargets| {
            let mut spans = TileSpans::EMPTY;
            for (i, x, y) in edit::tile_texels(w, h, id) {
                let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                let (p, n) = match surface {
                    Some(s) => {
                        let t = y as usize * w as usize + x as usize;
                        if s.bake.coverage(t) == Coverage::Empty {
                            continue;
                        }
                        let p = s.bake.position(t);
                        // A decal reaches only the surface near its point.
                        if ball.is_some_and(|(c, r2)| p.distance_squared(c) > r2) {
                            continue;
                        }
                        (p, s.bake.normal(t))
                    }
                    None => (Vec3::ZERO, Vec3::Z),
                };
                let (c, a) = mapper.sample(&pixels, uv, p, n, mask);
                let a = (a * opacity).min(1.0);
                if a > 0.0 {
                    cover[i] = a;
                    targets[i] = c;
                    spans.include(i);
                }
            }
            if !spans.is_empty() {
                reached.store(true, std::sync::atomic::Ordering::Relaxed);
            }
            spans
        };
        let ids: Vec<usize> = match (ball, surface) {
            (Some((origin, r2)), Some(s)) => s.tiles_near(origin, r2.sqrt()),
            _ => (0..self.maps.tile_count()).collect(),
        };
        self.try_edit_planes(
            label,
            |planes, pre, _| {
                edit::edit_each((planes, pre), &edit, &ids, &prepare);
                if reached.load(std::sync::atomic::Ordering::Relaxed) {
                    Ok(())
                } else {
                    Err(ModelError::Command(
                        "the projection reaches no texel of the map (nothing faces it, or it lies off the mesh)".into(),
                    ))
                }
            },
            |_| {},
        )
    }
}
