//! `ProjectImage`: an image painted through a projection into the selected layer, one undo
//! step: its colour (decoded from sRGB) into `k_d`, its luminance into `k_s`, its gray into
//! `n` through the import's mapping, each where the command enables it; its alpha times the
//! opacity is the coverage (0 outside the image).

use super::Document;
use super::decal::Decal;
use crate::ModelError;
use crate::brush::BlendMode;
use crate::layers::LayerStroke;
use crate::layers::edit::{self, TileTargets};
use crate::paint::mapper::Mapper;
use crate::paint::projection::Projection;
use crate::paint_image::PaintImage;
use crate::texel::Channels;

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
        let size = (self.maps.width(), self.maps.height());
        let mapper = Mapper::new(spec.projection, surface, pixels, size, reach)
            .map_err(ModelError::Command)?;
        let mut edit = self.layer_edit(
            self.settings.primary,
            self.settings.primary,
            LayerStroke::Brush(BlendMode::Normal),
        );
        edit.channels = [spec.channels.kd, spec.channels.ks, spec.channels.n];
        let mask = self.painting_mask();
        let opacity = spec.opacity;
        // Whether any texel took the image, to refuse a projection that hits nothing.
        let reached = std::sync::atomic::AtomicBool::new(false);
        let prepare = |id: usize, cover: &mut [f32], targets: &mut TileTargets| {
            let spans = mapper.lay_tile(id, (opacity, mask), cover, targets);
            if !spans.is_empty() {
                reached.store(true, std::sync::atomic::Ordering::Relaxed);
            }
            spans
        };
        let ids = mapper.tiles();
        self.try_edit_planes(
            label,
            |planes, pre, _| {
                let _ = edit::edit_each((planes, pre), &edit, &ids, &prepare);
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
