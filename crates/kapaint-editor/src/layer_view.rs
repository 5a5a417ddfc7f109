//! The maps the viewport and canvas show: the composite, or for the "selected layer only" and
//! "mask" views, maps composited from a stack of that layer (or mask) alone, kept up to date
//! tile by tile as it is painted.

use crate::panels::layers::LayerView;
use kapaint_core::model::layers::{Compositor, ops};
use kapaint_core::model::{Document, MaterialMaps};

/// The maps of the view being shown, when it is not the composite.
#[derive(Default)]
pub struct ViewMaps {
    /// The view and layer path they are of.
    key: Option<(LayerView, Vec<usize>)>,
    compositor: Compositor,
    maps: Option<MaterialMaps>,
}

impl ViewMaps {
    /// The maps `view` shows of `doc`, and their identity ([`MaterialMaps::id`]: mirrors
    /// upload other maps whole). A view of a layer without a mask shows the composite.
    pub fn get<'a>(&'a mut self, doc: &'a Document, view: LayerView) -> (&'a MaterialMaps, u64) {
        let path = &doc.selection().path;
        let stack = match view {
            LayerView::Composite => None,
            LayerView::Selected => ops::layer_alone(doc.stack(), path),
            LayerView::Mask => ops::mask_alone(doc.stack(), path),
        };
        let Some(stack) = stack else {
            self.key = None;
            self.maps = None;
            return (doc.maps(), doc.maps().id());
        };
        let key = Some((view, path.clone()));
        let fits = self
            .maps
            .as_ref()
            .is_some_and(|m| (m.width(), m.height()) == (stack.width, stack.height));
        if self.key != key || !fits {
            self.key = key;
            self.compositor = Compositor::new();
            self.maps = MaterialMaps::new(stack.width, stack.height, stack.base).ok();
        }
        match &mut self.maps {
            Some(maps) => {
                self.compositor.update(&stack, maps);
                (maps, maps.id())
            }
            None => (doc.maps(), doc.maps().id()),
        }
    }
}
