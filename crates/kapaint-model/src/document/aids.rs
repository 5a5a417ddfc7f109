//! What the painting tools hold between strokes and no project stores: the stencil and the
//! clone source (with the offset an aligned clone keeps).

use std::sync::Arc;

use glam::Vec2;

use super::Document;
use crate::ModelError;
use crate::paint::Stencil;
use crate::paint_image::PaintImage;

/// The painting aids of a document.
#[derive(Clone, Debug, Default)]
pub(super) struct Aids {
    pub(super) stencil: Option<Arc<Stencil>>,
    /// The stencil's image as `SetStencil` named it (the editor moves the stencil by naming
    /// it again).
    pub(super) stencil_image: Option<PaintImage>,
    pub(super) clone_source: Option<Vec2>,
    /// Source minus the first point of the first clone stroke since the source was set.
    pub(super) clone_offset: Option<Vec2>,
    /// The clone source on the mesh (object space).
    pub(super) surface_clone_source: Option<glam::Vec3>,
    /// Its offset, as `clone_offset` (object units).
    pub(super) surface_clone_offset: Option<glam::Vec3>,
}

/// The stencil as `SetStencil` names it.
pub(super) struct StencilSpec {
    pub(super) image: PaintImage,
    pub(super) center: Vec2,
    pub(super) size: f32,
    pub(super) rotation: f32,
    pub(super) opacity: f32,
    pub(super) tiled: bool,
    pub(super) view: Option<crate::paint::ScreenView>,
}

impl Document {
    /// The stencil the brush, the eraser and clone paint through.
    pub fn stencil(&self) -> Option<&Arc<Stencil>> {
        self.aids.stencil.as_ref()
    }

    /// The stencil's image, as the command that set it named it.
    pub fn stencil_image(&self) -> Option<&PaintImage> {
        self.aids.stencil_image.as_ref()
    }

    /// The clone source (texels), and the offset from a stroke's point to its source once
    /// a clone stroke fixed it.
    pub fn clone_source(&self) -> Option<(Vec2, Option<Vec2>)> {
        self.aids.clone_source.map(|s| (s, self.aids.clone_offset))
    }

    /// `SetStencil`.
    pub(super) fn set_stencil(&mut self, spec: &StencilSpec) -> Result<(), ModelError> {
        let image = Arc::clone(spec.image.pixels()?);
        // The same image moved: its weights are kept (a drag sets the stencil every frame).
        let mut stencil = match &self.aids.stencil {
            Some(s) if Arc::ptr_eq(&s.image, &image) => {
                s.placed(spec.center, spec.size, spec.rotation)
            }
            _ => Stencil::new(image, spec.center, spec.size, spec.rotation),
        };
        stencil.opacity = spec.opacity;
        stencil.tiled = spec.tiled;
        stencil.view = spec.view;
        stencil.check().map_err(ModelError::Command)?;
        self.aids.stencil = Some(Arc::new(stencil));
        self.aids.stencil_image = Some(spec.image.clone());
        Ok(())
    }

    /// The clone source on the mesh (object space), and the offset from a mesh stroke's
    /// point to its source once a clone stroke fixed it.
    pub fn surface_clone_source(&self) -> Option<(glam::Vec3, Option<glam::Vec3>)> {
        self.aids
            .surface_clone_source
            .map(|s| (s, self.aids.surface_clone_offset))
    }

    /// `SetSurfaceCloneSource`: the point must be finite and on (near) the mesh.
    pub(super) fn set_surface_clone_source(&mut self, at: glam::Vec3) -> Result<(), ModelError> {
        let surface = self.require_surface("a clone source on the mesh")?;
        let near = 4.0 * surface.units_per_texel;
        if !at.is_finite() || surface.nearest(at, near).is_none() {
            return Err(ModelError::Command(format!(
                "the clone source ({}, {}, {}) is not on the mesh",
                at.x, at.y, at.z
            )));
        }
        self.aids.surface_clone_source = Some(at);
        self.aids.surface_clone_offset = None;
        Ok(())
    }

    /// `SetCloneSource`.
    pub(super) fn set_clone_source(&mut self, at: Vec2) -> Result<(), ModelError> {
        let (w, h) = (self.maps.width() as f32, self.maps.height() as f32);
        if !(at.is_finite() && (0.0..w).contains(&at.x) && (0.0..h).contains(&at.y)) {
            return Err(ModelError::Command(format!(
                "the clone source ({}, {}) is outside the {}x{} map",
                at.x,
                at.y,
                self.maps.width(),
                self.maps.height()
            )));
        }
        self.aids.clone_source = Some(at);
        self.aids.clone_offset = None;
        Ok(())
    }
}
