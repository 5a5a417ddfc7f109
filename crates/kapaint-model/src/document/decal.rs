//! A decal as a value: what `PlaceDecal` names, and what the editor's Decal tool holds while
//! it places one (`PreviewDecal`). Laid by `project_image`.

use glam::Vec3;

use crate::ModelError;
use crate::paint_image::PaintImage;
use crate::surface::Surface;
use crate::texel::Channels;

/// A decal: what `PlaceDecal` names, and what the editor's Decal tool holds while it
/// places one.
#[derive(Clone, Debug, PartialEq)]
pub struct Decal {
    /// The image.
    pub image: PaintImage,
    /// A point near the surface, in object space.
    pub at: Vec3,
    /// Width in object units.
    pub size: f32,
    /// Turn about the surface's normal, degrees (counter-clockwise seen from outside).
    pub rotation: f32,
    /// The channels it paints.
    pub channels: Channels,
    /// Its strength.
    pub opacity: f32,
}

/// Where a decal lies: the planar projection `PlaceDecal` lays it through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecalFrame {
    /// The image's centre, on the surface.
    pub origin: Vec3,
    /// The surface's normal there (the projection's direction).
    pub normal: Vec3,
    /// The image's right and its top, unit and across the normal.
    pub right: Vec3,
    /// Its top.
    pub up: Vec3,
    /// Its width and height (object units).
    pub width: f32,
    /// Its height.
    pub height: f32,
}

impl DecalFrame {
    /// The image's corners: top-left, top-right, bottom-right, bottom-left.
    pub fn corners(&self) -> [Vec3; 4] {
        let (r, u) = (self.right * 0.5 * self.width, self.up * 0.5 * self.height);
        let o = self.origin;
        [o - r + u, o + r + u, o + r - u, o - r - u]
    }

    /// The handle that scales it: its top-right corner.
    pub fn scale_handle(&self) -> Vec3 {
        self.corners()[1]
    }

    /// The handle that turns it: above the middle of its top edge.
    pub fn turn_handle(&self) -> Vec3 {
        self.origin + self.up * (0.5 * self.height + 0.2 * self.width)
    }

    /// `p` in the frame's plane, from its origin: (along `right`, along `up`).
    pub fn local(&self, p: Vec3) -> glam::Vec2 {
        let d = p - self.origin;
        glam::Vec2::new(d.dot(self.right), d.dot(self.up))
    }
}

impl Decal {
    /// Where the decal lies on `surface`: at the baked surface texel nearest its point, along
    /// the normal there, `size` wide (its height by the image's aspect), turned by `rotation`.
    ///
    /// # Errors
    /// A non-finite point or rotation, a size that is not positive, an image not loaded, no
    /// surface near the point.
    pub fn frame(&self, surface: &Surface) -> Result<DecalFrame, ModelError> {
        let aspect = self.image.pixels()?.aspect();
        if !(self.at.is_finite() && self.rotation.is_finite()) {
            return Err(ModelError::Command(
                "a decal's point and rotation must be finite".into(),
            ));
        }
        if !(self.size.is_finite() && self.size > 0.0) {
            return Err(ModelError::Command(format!(
                "a decal's size must be positive, not {}",
                self.size
            )));
        }
        let Some(near) = surface.nearest_texel_from(self.at, self.size) else {
            return Err(ModelError::Command(
                "the decal finds no surface near its point".into(),
            ));
        };
        let (origin, normal) = (surface.bake.position(near), surface.bake.normal(near));
        let reference = if normal.dot(Vec3::Y).abs() > 0.99 {
            Vec3::NEG_Z
        } else {
            Vec3::Y
        };
        let turned = glam::Quat::from_axis_angle(normal, self.rotation.to_radians()) * reference;
        // Made across the normal, as the planar projection makes it.
        let up = (turned - normal * turned.dot(normal)).normalize_or_zero();
        Ok(DecalFrame {
            origin,
            normal,
            right: up.cross(normal).normalize_or_zero(),
            up,
            width: self.size,
            height: self.size * aspect,
        })
    }
}
