//! Making a document: new, from maps, from a stack (with or without a stored composite), a
//! snapshot, and the loader's `with_` setters.

use super::{
    Compositor, Document, DocumentId, DocumentSettings, LayerStack, MaterialMaps, ModelError,
    Selected, Selection, StackHistory, State, topmost_paintable,
};

impl Document {
    /// A document of `width x height` texels: the settings' base material and one empty
    /// paint layer, "Layer 1", selected.
    pub fn new(width: u32, height: u32, settings: DocumentSettings) -> Result<Self, ModelError> {
        let maps = MaterialMaps::new(width, height, settings.base)?;
        let stack = LayerStack::new(width, height, settings.base);
        Ok(Self::assemble(maps, stack, settings))
    }

    /// A document around existing maps (a version 1 project, an imported set): the maps become
    /// one opaque paint layer, "Layer 1", over the settings' base. Empty history.
    pub fn from_parts(maps: MaterialMaps, settings: DocumentSettings) -> Self {
        let stack = LayerStack::from_maps(&maps, settings.base, "Layer 1");
        Self::assemble(maps, stack, settings)
    }

    /// A document around a layer stack (a version 2 project), its topmost layer selected.
    ///
    /// # Errors
    /// A stack of a size the maps cannot have.
    pub fn from_stack(
        mut stack: LayerStack,
        settings: DocumentSettings,
    ) -> Result<Self, ModelError> {
        stack.make_ids_unique();
        let maps = MaterialMaps::new(stack.width, stack.height, stack.base)?;
        Ok(Self::assemble(maps, stack, settings))
    }

    /// A copy of the document without its history (autosave, background saves, export): the
    /// same content, mesh surface and version.
    #[must_use]
    pub fn snapshot(&self) -> Self {
        let mut doc = Self::assemble_with(
            self.maps.clone(),
            self.state.stack.clone(),
            self.settings.clone(),
            self.compositor.clone(),
        );
        doc.state = self.state.clone();
        doc.settings_version = self.settings_version;
        doc.revisions = self.revisions;
        doc.id = self.id;
        doc
    }

    /// This document with `selection` selected, where it names a layer of the stack (a
    /// project or recovery copy restoring what was selected); otherwise as it was.
    #[must_use]
    pub fn with_selection(mut self, selection: Selection) -> Self {
        let Selection { path, mask } = selection;
        if let Some(layer) = self.state.stack.layer(&path) {
            self.state.selection = Selected {
                id: Some(layer.props.id),
                mask: mask && layer.mask.is_some(),
            };
        }
        self
    }

    /// This document with `settings` (a loader adjusting paths, an importer recording its
    /// report and mesh), as it is made: no undo step.
    #[must_use]
    pub fn with_settings(mut self, settings: DocumentSettings) -> Self {
        self.state.mesh.clone_from(&settings.mesh);
        self.state.import.clone_from(&settings.import);
        self.settings = settings;
        self
    }

    /// This document with the identity `id` (a loader making it from a file that has one).
    #[must_use]
    pub fn with_id(mut self, id: DocumentId) -> Self {
        self.id = id;
        self
    }

    /// Which document this is.
    pub fn id(&self) -> DocumentId {
        self.id
    }

    fn assemble(mut maps: MaterialMaps, stack: LayerStack, settings: DocumentSettings) -> Self {
        let mut compositor = Compositor::new();
        compositor.update(&stack, &mut maps);
        Self::assemble_with(maps, stack, settings, compositor)
    }

    fn assemble_with(
        maps: MaterialMaps,
        stack: LayerStack,
        settings: DocumentSettings,
        compositor: Compositor,
    ) -> Self {
        let id = stack.layer(&topmost_paintable(&stack)).map(|l| l.props.id);
        Self {
            maps,
            state: State {
                stack,
                selection: Selected { id, mask: false },
                surface: None,
                mesh: settings.mesh.clone(),
                embedded_mesh: None,
                bakes: Vec::new(),
                normal: None,
                import: settings.import.clone(),
                revision: 0,
            },
            compositor,
            history: StackHistory::default(),
            settings,
            stroke: None,
            settings_version: 0,
            revisions: 0,
            opacity_run: None,
            generator_run: None,
            decal_run: None,
            aids: super::aids::Aids::default(),
            id: DocumentId::random(),
            instance: next_instance(),
        }
    }
}

/// A number no document value of this process had before.
fn next_instance() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}
