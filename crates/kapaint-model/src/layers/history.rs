//! Undo and redo of a layer stack by snapshots that share tiles.
//!
//! A step keeps the stack (and the selection and mesh surface) as it was before the step. Its
//! tiles are `Arc`s shared with the states around it, so a step costs only the tiles it alone
//! holds: those the next state no longer has. Undo swaps the snapshot with the document's
//! state and keeps the swapped-out state for redo, so both directions are bit-exact. A memory
//! cap drops the oldest steps.

use std::collections::{HashSet, VecDeque};
use std::sync::Arc;

use super::{Layer, LayerContent, LayerId, LayerStack};
use crate::mesh_ref::MeshRef;
use crate::normal::NormalMap;
use crate::provenance::ImportReport;
use crate::surface::Surface;

/// Default cap on the memory history may hold: 1 GiB.
pub const DEFAULT_UNDO_CAP_BYTES: usize = 1 << 30;

/// Which layer tools act on, as a path (what the Layers panel, projects and scripts show),
/// and whether on its mask. The document keeps a [`Selected`] layer by id; this is where that
/// layer is now.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Selection {
    /// Indices from the top-level list down into groups; empty when the stack has no layers.
    pub path: Vec<usize>,
    /// Tools paint the layer's mask rather than its content.
    pub mask: bool,
}

/// The selected layer, by id: the same layer whatever moves around it, and after undo.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Selected {
    /// The layer (none when the stack has no layers).
    pub id: Option<LayerId>,
    /// Tools paint the layer's mask rather than its content.
    pub mask: bool,
}

/// What a step restores: everything a project stores except the settings a tool reads
/// (brush, materials, channels, model), which are not undone.
#[derive(Clone, Debug)]
pub struct State {
    /// The layer stack.
    pub stack: LayerStack,
    /// The selected layer.
    pub selection: Selected,
    /// The mesh surface baked at the stack's size.
    pub surface: Option<Arc<Surface>>,
    /// The mesh the project is painted on.
    pub mesh: MeshRef,
    /// The mesh itself when the project keeps it ([`MeshRef::Embedded`]).
    pub embedded_mesh: Option<Arc<kapaint_mesh::Mesh>>,
    /// Maps baked from the mesh, at most one of each: caches, never painted or exported as
    /// material, dropped when the mesh changes.
    pub bakes: Vec<Arc<kapaint_mesh::bakes::Baked>>,
    /// The tangent-space normal map an imported material brought.
    pub normal: Option<Arc<NormalMap>>,
    /// The PBR import the maps were made by.
    pub import: Option<ImportReport>,
    /// Which revision of the content this is: a new number for every step, so that undo back to
    /// a state brings its number back (what "unsaved changes" compares).
    pub revision: u64,
}

impl State {
    /// Where the selected layer is in the stack (empty: none is selected).
    pub fn selected_path(&self) -> Vec<usize> {
        self.selection
            .id
            .and_then(|id| self.stack.path_of(id))
            .unwrap_or_default()
    }

    /// Selects the layer at `path` (none where no layer is there).
    pub fn select_path(&mut self, path: &[usize]) {
        self.selection.id = self.stack.layer(path).map(|l| l.props.id);
    }

    /// The selection as a path.
    pub fn selection(&self) -> Selection {
        Selection {
            path: self.selected_path(),
            mask: self.selection.mask,
        }
    }
}

/// One undoable step.
#[derive(Clone, Debug)]
pub struct Step {
    /// What the step did, for the history panel.
    pub label: String,
    state: State,
    bytes: usize,
}

impl Step {
    /// Heap bytes of the tiles only this step holds.
    pub fn bytes(&self) -> usize {
        self.bytes
    }
}

/// Calls `f(pointer, heap bytes)` for every tile of `layers` (paint and mask tiles).
fn each_tile(layers: &[Layer], f: &mut impl FnMut(usize, usize)) {
    for layer in layers {
        match &layer.content {
            LayerContent::Paint(tiles) => {
                for t in tiles.iter().flatten() {
                    f(Arc::as_ptr(t) as usize, t.get().heap_bytes());
                }
            }
            LayerContent::Projected(p) => f(Arc::as_ptr(p) as usize, p.heap_bytes()),
            LayerContent::Fill(_) => {}
            LayerContent::Group(children) => each_tile(children, f),
        }
        for t in layer.mask.iter().flat_map(|m| &m.tiles) {
            f(Arc::as_ptr(t) as usize, t.get().heap_bytes());
        }
    }
}

/// Heap bytes of the tiles of `a` that `b` does not share.
pub fn unshared_bytes(a: &LayerStack, b: &LayerStack) -> usize {
    let mut in_b = HashSet::new();
    each_tile(&b.layers, &mut |p, _| {
        in_b.insert(p);
    });
    let mut seen = HashSet::new();
    let mut bytes = 0;
    each_tile(&a.layers, &mut |p, n| {
        if !in_b.contains(&p) && seen.insert(p) {
            bytes += n;
        }
    });
    bytes
}

/// The undo and redo stacks.
#[derive(Debug)]
pub struct StackHistory {
    undo: VecDeque<Step>,
    redo: Vec<Step>,
    cap_bytes: usize,
}

impl Default for StackHistory {
    fn default() -> Self {
        Self::new(DEFAULT_UNDO_CAP_BYTES)
    }
}

impl StackHistory {
    /// Empty history with a memory cap in bytes.
    pub fn new(cap_bytes: usize) -> Self {
        Self {
            undo: VecDeque::new(),
            redo: Vec::new(),
            cap_bytes,
        }
    }

    /// Records a step: `before` is the state the step changed, `now` the state after it.
    pub fn push(&mut self, label: impl Into<String>, before: State, now: &State) {
        self.redo.clear();
        let bytes = unshared_bytes(&before.stack, &now.stack);
        self.undo.push_back(Step {
            label: label.into(),
            state: before,
            bytes,
        });
        self.enforce_cap();
    }

    /// Takes the last step's state before it off the history, if that step is labelled
    /// `label` and nothing is undone: what a change joining that step records again.
    pub fn take_last(&mut self, label: &str) -> Option<State> {
        if !self.redo.is_empty() || self.undo.back().is_none_or(|s| s.label != label) {
            return None;
        }
        self.undo.pop_back().map(|s| s.state)
    }

    /// Undoes the last step into `now`; false if there is none.
    pub fn undo(&mut self, now: &mut State) -> bool {
        let Some(step) = self.undo.pop_back() else {
            return false;
        };
        let reverse = Self::swap(step, now);
        self.redo.push(reverse);
        true
    }

    /// Redoes the last undone step into `now`; false if there is none.
    pub fn redo(&mut self, now: &mut State) -> bool {
        let Some(step) = self.redo.pop() else {
            return false;
        };
        let reverse = Self::swap(step, now);
        self.undo.push_back(reverse);
        self.enforce_cap();
        true
    }

    fn swap(step: Step, now: &mut State) -> Step {
        let old = std::mem::replace(now, step.state);
        Step {
            bytes: unshared_bytes(&old.stack, &now.stack),
            label: step.label,
            state: old,
        }
    }

    /// Heap bytes held only by undo and redo steps.
    pub fn bytes(&self) -> usize {
        self.undo.iter().chain(&self.redo).map(Step::bytes).sum()
    }

    /// The undo steps, oldest first.
    pub fn undo_steps(&self) -> impl Iterator<Item = &Step> {
        self.undo.iter()
    }

    /// The redo steps, next first.
    pub fn redo_steps(&self) -> impl Iterator<Item = &Step> {
        self.redo.iter().rev()
    }

    /// The memory cap in bytes.
    pub fn cap_bytes(&self) -> usize {
        self.cap_bytes
    }

    /// Changes the cap, dropping old steps if needed.
    pub fn set_cap_bytes(&mut self, cap: usize) {
        self.cap_bytes = cap;
        self.enforce_cap();
    }

    /// Forgets all steps (a new or loaded document).
    pub fn clear(&mut self) {
        self.undo.clear();
        self.redo.clear();
    }

    fn enforce_cap(&mut self) {
        while self.bytes() > self.cap_bytes {
            if self.undo.pop_front().is_none() {
                if self.redo.is_empty() {
                    break;
                }
                self.redo.remove(0);
            }
        }
    }
}
