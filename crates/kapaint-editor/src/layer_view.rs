//! The maps the viewport and canvas show: the composite, or for the "selected layer only" and
//! "mask" views, maps composited from a stack of that layer (or mask) alone, kept up to date
//! tile by tile as it is painted.

use kapaint_model::layers::{Compositor, ops};
use kapaint_model::{Document, MaterialMaps};

/// What the viewport and canvas show of the layers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LayerView {
    /// The composite of the stack (what export ships).
    #[default]
    Composite,
    /// The selected layer alone over the base material.
    Selected,
    /// The selected layer's mask, in grey.
    Mask,
}

impl LayerView {
    /// Every view, in the order the view panel lists them.
    pub const ALL: [Self; 3] = [Self::Composite, Self::Selected, Self::Mask];

    /// Its label.
    pub fn label(self) -> &'static str {
        match self {
            Self::Composite => "All layers",
            Self::Selected => "Selected layer only",
            Self::Mask => "Mask",
        }
    }
}

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
