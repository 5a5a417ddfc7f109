//! A projection made ready for a map ([`Mapper`]): what an image gives each texel of the
//! surface through it, a tile at a time. `ProjectImage` and `PlaceDecal` paint what it lays
//! into a layer; a projection fill keeps what it lays as the layer's tiles. Both lay a texel
//! through [`Mapper::lay_tile`], so a projection fill shows what painting the same projection
//! into an empty layer would.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use kapaint_mesh::bake::Coverage;

use super::projection::{DepthMap, Frame3, PlaneFrame, Projection};
use crate::paint_image::{Pixels, Sample};
use crate::surface::Surface;
use crate::tile::{TILE_SIZE, TileSpans, tile_texels};

/// How texels find their place on the image.
enum Kind {
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
        [s.rgb.x, s.rgb.y, s.rgb.z, l, l, l, s.n_blend]
    };
    (c, s.alpha)
}

impl Kind {
    fn new(
        projection: &Projection,
        surface: Option<&Surface>,
        image: &Pixels,
        slab: Option<f32>,
    ) -> Result<Self, String> {
        Ok(match *projection {
            Projection::Planar {
                origin,
                normal,
                up,
                width,
                height,
            } => {
                let frame = PlaneFrame::new(origin, normal, up, Vec2::new(width, height))?;
                let surface = surface.ok_or("a planar projection needs a mesh")?;
                // A cell per image pixel, within reason.
                let side = image.width().max(image.height()).clamp(64, 2048) as usize;
                Self::Planar(frame, DepthMap::new(&frame, &surface.mesh, side, slab))
            }
            Projection::Cylindrical {
                origin,
                axis,
                front,
                height,
            } => Self::Cylindrical(origin, Frame3::new(axis, front)?, height),
            Projection::Spherical { origin, up, front } => {
                Self::Spherical(origin, Frame3::new(up, front)?)
            }
            Projection::Triplanar { scale, blend } => Self::Triplanar(scale, blend),
            Projection::Uv {
                offset,
                scale,
                rotation,
            } => Self::Uv(offset, scale, rotation.to_radians()),
        })
    }

    /// The image at a texel: `uv` its place on the map (in maps), `p` and `normal` its baked
    /// position and normal (the normal asked for only where the image reaches the texel).
    fn sample(
        &self,
        image: &Pixels,
        (uv, p): (Vec2, Vec3),
        normal: impl FnOnce() -> Vec3,
        mask: bool,
    ) -> ([f32; 7], f32) {
        const NONE: ([f32; 7], f32) = ([0.0; 7], 0.0);
        match self {
            Self::Planar(frame, depth) => {
                // Off the image first: a decal's ball reaches a third more surface than its
                // square.
                let (at, d) = frame.image_uv(p);
                if !(at.cmpge(Vec2::ZERO).all() && at.cmple(Vec2::ONE).all()) {
                    return NONE;
                }
                let n = normal();
                if !frame.faces(n) || !depth.visible(frame, at, d, n) {
                    return NONE;
                }
                target(&image.sample(at, false), mask)
            }
            Self::Cylindrical(origin, frame, height) => {
                let d = p - *origin;
                let along = d.dot(frame.pole);
                let radial = d - frame.pole * along;
                if normal().dot(radial) <= 0.0 {
                    return NONE;
                }
                let at = Vec2::new(frame.around(radial), 0.5 - along / height);
                target(&image.sample(at, false), mask)
            }
            Self::Spherical(origin, frame) => {
                let Some(d) = (p - *origin).try_normalize() else {
                    return NONE;
                };
                if normal().dot(d) <= 0.0 {
                    return NONE;
                }
                let latitude = d.dot(frame.pole).clamp(-1.0, 1.0).asin();
                let at = Vec2::new(frame.around(d), 0.5 - latitude / std::f32::consts::PI);
                target(&image.sample(at, false), mask)
            }
            Self::Triplanar(scale, blend) => {
                let a = normal().abs();
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

/// A projection made ready for a map of `width x height` texels: its frame (and for a planar
/// one the mesh's depth map, made once), the image, and what bounds it.
pub struct Mapper {
    kind: Kind,
    pixels: Arc<Pixels>,
    surface: Option<Arc<Surface>>,
    width: u32,
    height: u32,
    /// A decal's reach: the point it is laid at and the squared distance it reaches.
    ball: Option<(Vec3, f32)>,
}

impl Mapper {
    /// `projection` of `pixels` on a `width x height` map, through `surface` (its baked
    /// positions and normals; needed by every projection but the UV one); `reach` bounds a
    /// planar projection to the surface within that distance of its origin (a decal).
    ///
    /// # Errors
    /// A projection that needs a mesh without one, or a frame its vectors do not make.
    pub fn new(
        projection: &Projection,
        surface: Option<Arc<Surface>>,
        pixels: Arc<Pixels>,
        (width, height): (u32, u32),
        reach: Option<f32>,
    ) -> Result<Self, String> {
        let surface = surface.filter(|_| projection.needs_surface());
        let kind = Kind::new(projection, surface.as_deref(), &pixels, reach)?;
        let ball = match (reach, projection) {
            (Some(r), Projection::Planar { origin, .. }) => Some((*origin, r * r)),
            _ => None,
        };
        Ok(Self {
            kind,
            pixels,
            surface,
            width,
            height,
            ball,
        })
    }

    /// The tiles it may reach: a decal's near its point, else every tile of the map.
    pub fn tiles(&self) -> Vec<usize> {
        if let (Some((origin, r2)), Some(s)) = (self.ball, &self.surface) {
            return s.tiles_near(origin, r2.sqrt());
        }
        let count =
            (self.width as usize).div_ceil(TILE_SIZE) * (self.height as usize).div_ceil(TILE_SIZE);
        (0..count).collect()
    }

    /// Lays tile `id`: each texel the image reaches gets its coverage (the image's alpha
    /// times `opacity`; 0 leaves a texel untouched) in `cover` and its target in `targets`
    /// (the seven components a layer blends: `k_d` RGB, `k_s` RGB, `n` in log space; with
    /// `mask`, the image's gray first, for a mask); the texels reached.
    pub fn lay_tile(
        &self,
        id: usize,
        (opacity, mask): (f32, bool),
        cover: &mut [f32],
        targets: &mut crate::layers::edit::TileTargets,
    ) -> TileSpans {
        let (w, h) = (self.width, self.height);
        let mut spans = TileSpans::EMPTY;
        for (i, x, y) in tile_texels(w, h, id) {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let (p, t) = match &self.surface {
                Some(s) => {
                    let t = y as usize * w as usize + x as usize;
                    if s.bake.coverage(t) == Coverage::Empty {
                        continue;
                    }
                    let p = s.bake.position(t);
                    // A decal reaches only the surface near its point.
                    if self.ball.is_some_and(|(c, r2)| p.distance_squared(c) > r2) {
                        continue;
                    }
                    (p, t)
                }
                None => (Vec3::ZERO, 0),
            };
            let normal = || self.surface.as_ref().map_or(Vec3::Z, |s| s.bake.normal(t));
            let (c, a) = self.kind.sample(&self.pixels, (uv, p), normal, mask);
            let a = (a * opacity).min(1.0);
            if a > 0.0 {
                cover[i] = a;
                targets.set(i, c);
                spans.include(i);
            }
        }
        spans
    }
}
