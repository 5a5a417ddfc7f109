//! Imports into the selected paint layer: one channel from an image, or every channel from a
//! converted material, each one undo step.

use super::Document;
use super::paths::command_error;
use crate::ModelError;
use crate::import::ChannelPlanes;
use crate::layers::Stamped;
use crate::layers::edit::{Planes, PrePlanes};
use crate::texel::Channel;
use crate::tile::Plane;

impl Document {
    /// Writes `image` into `channel` of the selected paint layer, resampled to the map size,
    /// as one undo step.
    ///
    /// # Errors
    /// The command's: the selected layer is locked, a fill layer or a group, or its mask is
    /// selected; the document is unchanged then.
    pub fn import_image(
        &mut self,
        channel: Channel,
        image: &image::DynamicImage,
    ) -> Result<(), ModelError> {
        let (w, h) = (self.maps().width(), self.maps().height());
        let planes = crate::import::resample(image, channel, w, h);
        self.apply(super::ImportCommand::ImportChannel(super::ImportedChannel(
            std::sync::Arc::new(planes),
        )))
    }

    /// Reads `path` and imports it into `channel` of the selected paint layer.
    ///
    /// # Errors
    /// The image's, or the command's ([`Document::import_image`]).
    pub fn import_file(
        &mut self,
        channel: Channel,
        path: &std::path::Path,
    ) -> Result<(), ModelError> {
        let image = crate::import::read_image(path)?;
        self.import_image(channel, &image)
    }

    /// [`ImportCommand::ImportMaterial`]: every channel of the selected paint layer from `maps`.
    pub(super) fn import_material(
        &mut self,
        imported: &super::ImportedMaterial,
    ) -> Result<(), ModelError> {
        let maps = &*imported.maps;
        self.end_stroke();
        if (maps.width(), maps.height()) != (self.maps.width(), self.maps.height()) {
            return Err(ModelError::Internal(format!(
                "the material was made at {}x{}, but the maps are {}x{}",
                maps.width(),
                maps.height(),
                self.maps.width(),
                self.maps.height()
            )));
        }
        if self.state.selection.mask {
            return Err(command_error(
                "a material imports into a paint layer, not a mask: select the layer's content",
            ));
        }
        let write = |planes: Planes<'_>, _: PrePlanes<'_>, _: usize| {
            let Planes::Paint(tiles) = planes else { return };
            for (id, slot) in tiles.iter_mut().enumerate() {
                let tile =
                    Stamped::write(slot.get_or_insert_with(crate::layers::edit::empty_paint_tile));
                let source = maps.tile(id);
                tile.value.kd = source.kd.clone();
                tile.value.ks = source.ks.clone();
                tile.value.n = source.n.clone();
                tile.alpha = std::array::from_fn(|_| Plane::Uniform(u16::MAX));
            }
        };
        // The normal map and the report join the maps' undo step.
        self.edit_planes_and("Import material", write, |state| {
            state.normal.clone_from(&imported.normal);
            state.import.clone_from(&imported.report);
        })
    }

    /// Replaces one channel of the selected paint layer with imported planes, opaque there.
    pub(super) fn import_channel(&mut self, imported: &ChannelPlanes) -> Result<(), ModelError> {
        self.end_stroke();
        let count = match imported {
            ChannelPlanes::Rgb(_, p) => p.len(),
            ChannelPlanes::N(p) => p.len(),
        };
        if count != self.maps.tile_count() {
            return Err(ModelError::Internal(format!(
                "the image was resampled for {count} tiles, but the maps have {}",
                self.maps.tile_count()
            )));
        }
        if self.state.selection.mask {
            return Err(command_error(
                "an image imports into a paint layer's channel, not a mask: select the layer's content",
            ));
        }
        let label = format!("Import {}", imported.channel().name());
        self.edit_planes(&label, |planes, _, _| {
            let Planes::Paint(tiles) = planes else { return };
            for (id, slot) in tiles.iter_mut().enumerate() {
                let tile =
                    Stamped::write(slot.get_or_insert_with(crate::layers::edit::empty_paint_tile));
                match imported {
                    ChannelPlanes::Rgb(Channel::Ks, p) => {
                        tile.value.ks = p[id].clone();
                        tile.alpha[1] = Plane::Uniform(u16::MAX);
                    }
                    ChannelPlanes::Rgb(_, p) => {
                        tile.value.kd = p[id].clone();
                        tile.alpha[0] = Plane::Uniform(u16::MAX);
                    }
                    ChannelPlanes::N(p) => {
                        tile.value.n = p[id].clone();
                        tile.alpha[2] = Plane::Uniform(u16::MAX);
                    }
                }
            }
        })
    }
}
