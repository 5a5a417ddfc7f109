//! A decal as a value: what `PlaceDecal` names, and what the editor's Decal tool holds while
//! it places one (`PreviewDecal`). Laid by `project_image`.

use glam::Vec3;

use crate::paint_image::PaintImage;
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
