//! Projections: where on an image each texel of the surface falls (planar, cylindrical,
//! spherical, tri-planar, or straight into UV space), and, for the planar one, which texels
//! the image reaches first along its direction (a depth map of the mesh as seen from it).
//!
//! Image coordinates are `(0, 0)` at the image's top-left corner and `(1, 1)` at its
//! bottom-right, as [`crate::paint_image::Pixels::sample`] reads them.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

use kapaint_mesh::Mesh;

/// How an image is laid on the surface.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Projection {
    /// From the side `normal` points to, the image's centre at `origin`, its right along
    /// `normalize(cross(up, normal))` and its top along `up` (made perpendicular to `normal`),
    /// `width` x `height` object units; only surfaces facing `normal` receive it, the nearest
    /// first (no painting through the mesh).
    Planar {
        /// The image's centre.
        origin: Vec3,
        /// The side the image is projected from: surfaces facing it receive the image.
        normal: Vec3,
        /// The image's top.
        up: Vec3,
        /// Width in object units.
        width: f32,
        /// Height in object units.
        height: f32,
    },
    /// Around `axis`: the image's u the angle around it (0.5 at `front`), its v along it
    /// (top towards `axis`), `height` object units tall, centred at `origin`.
    Cylindrical {
        /// A point on the axis, at the image's middle height.
        origin: Vec3,
        /// The axis.
        axis: Vec3,
        /// Where the image's middle faces.
        front: Vec3,
        /// Height in object units.
        height: f32,
    },
    /// Around `origin`: u the longitude (0.5 at `front`), v the latitude (the top at `up`).
    Spherical {
        /// The centre.
        origin: Vec3,
        /// The north pole's direction.
        up: Vec3,
        /// Where the image's middle faces.
        front: Vec3,
    },
    /// Three planar projections along the axes, tiled `scale` times per object unit, blended
    /// by the normal (`blend` in `(0, 1]`: 1 mixes by the normal's components, towards 0 only
    /// the dominant axis shows).
    Triplanar {
        /// Repeats per object unit.
        scale: f32,
        /// The blend's width.
        blend: f32,
    },
    /// Straight into UV space, tiled: the image turned by `rotation` degrees about the map's
    /// centre, `scale` repeats per map, shifted by `offset` (in images).
    Uv {
        /// Shift, in images.
        offset: Vec2,
        /// Repeats per map.
        scale: Vec2,
        /// Turn, in degrees.
        rotation: f32,
    },
}

/// A planar projection's frame: right, top and the direction it faces.
#[derive(Clone, Copy, Debug)]
pub struct PlaneFrame {
    origin: Vec3,
    right: Vec3,
    top: Vec3,
    normal: Vec3,
    size: Vec2,
}

impl PlaneFrame {
    /// The frame of `Planar { origin, normal, up, width, height }`.
    ///
    /// # Errors
    /// A zero or non-finite vector or size, or `up` parallel to `normal`.
    pub fn new(origin: Vec3, normal: Vec3, up: Vec3, size: Vec2) -> Result<Self, String> {
        if !(origin.is_finite() && normal.is_finite() && up.is_finite()) {
            return Err("a projection's origin, normal and up must be finite".into());
        }
        if !(size.is_finite() && size.min_element() > 0.0) {
            return Err(format!(
                "a projection's width and height must be positive, not {} x {}",
                size.x, size.y
            ));
        }
        let normal = normal
            .try_normalize()
            .ok_or("a projection's normal must not be zero")?;
        let top = (up - normal * up.dot(normal))
            .try_normalize()
            .filter(|_| up.length() > 0.0 && up.normalize().dot(normal).abs() < 0.9999)
            .ok_or("a projection's up must not be zero or parallel to its normal")?;
        let right = top.cross(normal);
        Ok(Self {
            origin,
            right,
            top,
            normal,
            size,
        })
    }

    /// Image coordinates of `p`, and its depth towards the image (larger: nearer).
    pub fn image_uv(&self, p: Vec3) -> (Vec2, f32) {
        let d = p - self.origin;
        let uv = Vec2::new(
            d.dot(self.right) / self.size.x + 0.5,
            0.5 - d.dot(self.top) / self.size.y,
        );
        (uv, d.dot(self.normal))
    }

    /// Whether a surface of normal `n` faces the image.
    pub fn faces(&self, n: Vec3) -> bool {
        n.dot(self.normal) > 0.0
    }
}

/// The mesh seen from a planar projection: per cell of the image, the depth of the nearest
/// surface, so a texel further along is known to be behind it.
pub struct DepthMap {
    side: usize,
    depth: Vec<f32>,
    /// Object units per cell.
    cell: f32,
    /// A decal's reach along its normal: only surfaces within it, either side, count.
    slab: Option<f32>,
}

impl DepthMap {
    /// Rasterises `mesh` into a `side x side` depth map of the image's rectangle; with a
    /// `slab`, only the triangles that reach within it of the image's plane.
    pub fn new(frame: &PlaneFrame, mesh: &Mesh, side: usize, slab: Option<f32>) -> Self {
        let mut depth = vec![f32::NEG_INFINITY; side * side];
        let s = side as f32;
        let to_grid = |p: Vec3| {
            let (uv, d) = frame.image_uv(p);
            (uv * s, d)
        };
        for tri in &mesh.triangles {
            let v = tri.map(|i| to_grid(mesh.positions[i as usize]));
            if let Some(slab) = slab
                && (v.iter().all(|p| p.1 > slab) || v.iter().all(|p| p.1 < -slab))
            {
                continue;
            }
            let (a, b, c) = (v[0].0, v[1].0, v[2].0);
            let lo = a.min(b).min(c).floor().max(Vec2::ZERO);
            let hi = a.max(b).max(c).ceil().min(Vec2::splat(s));
            if lo.x >= hi.x || lo.y >= hi.y {
                continue;
            }
            let area = (b - a).perp_dot(c - a);
            if area.abs() < 1e-12 {
                continue;
            }
            // A corner's weight is linear in the cell's centre p: (e.x, e.y) . p + e.z, so a
            // row is one multiply-add a weight a cell.
            let inv = 1.0 / area;
            let edge = |b: Vec2, c: Vec2| Vec3::new(b.y - c.y, c.x - b.x, b.perp_dot(c)) * inv;
            let (e0, e1) = (edge(b, c), edge(c, a));
            let (x0, x1) = (lo.x as usize, hi.x as usize);
            for y in lo.y as usize..hi.y as usize {
                let py = y as f32 + 0.5;
                let (r0, r1) = (e0.y * py + e0.z, e1.y * py + e1.z);
                let row = &mut depth[y * side + x0..y * side + x1];
                for (k, cell) in row.iter_mut().enumerate() {
                    let px = (x0 + k) as f32 + 0.5;
                    let (w0, w1) = (e0.x * px + r0, e1.x * px + r1);
                    let w2 = 1.0 - w0 - w1;
                    if w0 >= -1e-4 && w1 >= -1e-4 && w2 >= -1e-4 {
                        let d = v[0].1 * w0 + v[1].1 * w1 + v[2].1 * w2;
                        *cell = cell.max(d);
                    }
                }
            }
        }
        let cell = frame.size.max_element() / s;
        Self {
            side,
            depth,
            cell,
            slab,
        }
    }

    /// Whether a point at image coordinates `uv` and depth `d` on a surface of normal `n` is
    /// the nearest surface there (within the slope's bias).
    pub fn visible(&self, frame: &PlaneFrame, uv: Vec2, d: f32, n: Vec3) -> bool {
        if self.slab.is_some_and(|slab| d.abs() > slab) {
            return false;
        }
        let s = self.side as f32;
        let g = (uv * s).floor();
        if g.x < 0.0 || g.y < 0.0 || g.x >= s || g.y >= s {
            return false;
        }
        // A surface at a slope changes depth across a cell; two cells' worth is allowed.
        let cos = n.dot(frame.normal).abs().max(0.05);
        let bias = 2.0 * self.cell * (1.0 - cos * cos).sqrt() / cos + 1e-4 * self.cell;
        let nearest = self.depth[g.y as usize * self.side + g.x as usize];
        d >= nearest - bias
    }
}

impl Projection {
    /// Checks the projection's numbers.
    ///
    /// # Errors
    /// A zero or non-finite vector or size, parallel axes, a blend outside `(0, 1]`.
    pub fn check(&self) -> Result<(), String> {
        let unit = |what: &str, v: Vec3| {
            if v.is_finite() && v.length() > 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "a projection's {what} must be a finite, non-zero vector"
                ))
            }
        };
        match *self {
            Self::Planar {
                origin,
                normal,
                up,
                width,
                height,
            } => PlaneFrame::new(origin, normal, up, Vec2::new(width, height)).map(|_| ()),
            Self::Cylindrical {
                origin,
                axis,
                front,
                height,
            } => {
                unit("axis", axis)?;
                unit("front", front)?;
                if !(origin.is_finite() && height.is_finite() && height > 0.0) {
                    return Err(
                        "a cylindrical projection's origin must be finite and its height positive"
                            .into(),
                    );
                }
                Frame3::new(axis, front).map(|_| ())
            }
            Self::Spherical { origin, up, front } => {
                unit("up", up)?;
                unit("front", front)?;
                if !origin.is_finite() {
                    return Err("a spherical projection's origin must be finite".into());
                }
                Frame3::new(up, front).map(|_| ())
            }
            Self::Triplanar { scale, blend } => {
                if !(scale.is_finite() && scale > 0.0) {
                    return Err(format!("a tri-planar scale must be positive, not {scale}"));
                }
                if !(blend > 0.0 && blend <= 1.0) {
                    return Err(format!("a tri-planar blend must be in (0, 1], not {blend}"));
                }
                Ok(())
            }
            Self::Uv {
                offset,
                scale,
                rotation,
            } => {
                if !(offset.is_finite() && rotation.is_finite()) {
                    return Err("a UV projection's offset and rotation must be finite".into());
                }
                if !(scale.is_finite() && scale.min_element() > 0.0) {
                    return Err("a UV projection's scale must be positive".into());
                }
                Ok(())
            }
        }
    }

    /// Whether it needs the mesh (every projection but the UV one).
    pub fn needs_surface(&self) -> bool {
        !matches!(self, Self::Uv { .. })
    }
}

/// An orthonormal frame from a pole and a front (made perpendicular to it).
#[derive(Clone, Copy, Debug)]
pub struct Frame3 {
    /// The pole (a cylinder's axis, a sphere's up).
    pub pole: Vec3,
    /// Where u = 0.5 faces.
    pub front: Vec3,
    /// A quarter turn from the front, towards u = 0.75.
    pub side: Vec3,
}

impl Frame3 {
    /// The frame of `pole` and `front`.
    ///
    /// # Errors
    /// Parallel or zero vectors.
    pub fn new(pole: Vec3, front: Vec3) -> Result<Self, String> {
        let pole = pole.try_normalize().ok_or("a projection's axis is zero")?;
        let front = (front - pole * front.dot(pole))
            .try_normalize()
            .filter(|_| front.normalize().dot(pole).abs() < 0.9999)
            .ok_or("a projection's front must not be parallel to its axis")?;
        Ok(Self {
            pole,
            front,
            side: front.cross(pole),
        })
    }

    /// The angle around the pole of direction `d` as u (0.5 at the front, growing towards
    /// the side).
    pub fn around(&self, d: Vec3) -> f32 {
        let angle = d.dot(self.side).atan2(d.dot(self.front));
        0.5 + angle / std::f32::consts::TAU
    }
}
