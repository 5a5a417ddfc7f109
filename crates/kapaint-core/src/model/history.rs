//! Undo and redo by tile copy-on-write.
//!
//! A transaction remembers, for every tile it touches, the tile as it was before (an `Arc`,
//! no copy). Ending it stores those tiles as one step. Undo swaps them back into the maps and
//! keeps the swapped-out tiles for redo, so both directions are bit-exact and cost only the
//! tiles the step touched. A memory cap drops the oldest steps.
//!
//! The document keeps layer-stack snapshots instead ([`super::layers::StackHistory`]); this
//! transaction recorder serves the flat-maps paint engine ([`super::paint`]).

use std::collections::{HashMap, VecDeque};
use std::sync::Arc;

use super::maps::{MaterialMaps, TileId};
use super::tile::Tile;

/// Default cap on the memory history may hold: 1 GiB.
pub const DEFAULT_UNDO_CAP_BYTES: usize = 1 << 30;

/// One undoable step: the tiles it replaced.
#[derive(Clone, Debug)]
pub struct Step {
    /// What the step did, for the history panel.
    pub label: String,
    tiles: Vec<(TileId, Arc<Tile>)>,
    bytes: usize,
}

impl Step {
    /// Heap bytes of the tiles the step keeps.
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// Number of tiles the step touched.
    pub fn tile_count(&self) -> usize {
        self.tiles.len()
    }

    fn new(label: String, mut tiles: Vec<(TileId, Arc<Tile>)>) -> Self {
        tiles.sort_by_key(|(id, _)| *id);
        let bytes = tiles.iter().map(|(_, t)| t.heap_bytes()).sum();
        Self {
            label,
            tiles,
            bytes,
        }
    }

    /// Swaps the step's tiles with the maps' and returns the step that reverses it.
    fn apply(self, maps: &mut MaterialMaps) -> Self {
        let tiles = self
            .tiles
            .into_iter()
            .map(|(id, tile)| (id, maps.replace_tile(id, tile)))
            .collect();
        Self::new(self.label, tiles)
    }
}

/// A transaction in progress.
#[derive(Debug)]
struct Transaction {
    label: String,
    saved: HashMap<TileId, Arc<Tile>>,
}

/// The undo and redo stacks.
#[derive(Debug)]
pub struct History {
    undo: VecDeque<Step>,
    redo: Vec<Step>,
    open: Option<Transaction>,
    cap_bytes: usize,
}

impl Default for History {
    fn default() -> Self {
        Self::new(DEFAULT_UNDO_CAP_BYTES)
    }
}

impl History {
    /// Empty history with a memory cap in bytes.
    pub fn new(cap_bytes: usize) -> Self {
        Self {
            undo: VecDeque::new(),
            redo: Vec::new(),
            open: None,
            cap_bytes,
        }
    }

    /// Starts a transaction; an open one is ended first.
    pub fn begin(&mut self, label: impl Into<String>) {
        if self.open.is_some() {
            self.end();
        }
        self.open = Some(Transaction {
            label: label.into(),
            saved: HashMap::new(),
        });
    }

    /// Whether a transaction is open.
    pub fn in_transaction(&self) -> bool {
        self.open.is_some()
    }

    /// The tile as it was when the open transaction began, if the transaction touched it.
    pub fn saved_tile(&self, id: TileId) -> Option<&Arc<Tile>> {
        self.open.as_ref()?.saved.get(&id)
    }

    /// The tile to write, saving its pre-transaction version on first touch. Outside a
    /// transaction the write is not undoable (used for loading).
    pub fn tile_for_write<'m>(&mut self, maps: &'m mut MaterialMaps, id: TileId) -> &'m mut Tile {
        if let Some(open) = &mut self.open {
            open.saved
                .entry(id)
                .or_insert_with(|| Arc::clone(maps.tile(id)));
        }
        maps.tile_mut(id)
    }

    /// Saves the pre-transaction version of each tile in `ids` that the open transaction has
    /// not touched yet (call before writing them through [`MaterialMaps::tiles_mut_many`]).
    pub fn save_before_write(&mut self, maps: &MaterialMaps, ids: &[TileId]) {
        if let Some(open) = &mut self.open {
            for &id in ids {
                open.saved
                    .entry(id)
                    .or_insert_with(|| Arc::clone(maps.tile(id)));
            }
        }
    }

    /// Puts a new tile in place of tile `id`, saving the old one on first touch like
    /// [`Self::tile_for_write`], but without copying it first (for whole-tile writes).
    pub fn replace_for_write(&mut self, maps: &mut MaterialMaps, id: TileId, tile: Tile) {
        if let Some(open) = &mut self.open {
            open.saved
                .entry(id)
                .or_insert_with(|| Arc::clone(maps.tile(id)));
        }
        maps.replace_tile(id, Arc::new(tile));
    }

    /// Ends the open transaction; a transaction that touched nothing leaves no step.
    pub fn end(&mut self) {
        let Some(open) = self.open.take() else { return };
        if open.saved.is_empty() {
            return;
        }
        self.redo.clear();
        self.undo
            .push_back(Step::new(open.label, open.saved.into_iter().collect()));
        self.enforce_cap();
    }

    /// Abandons the open transaction, restoring every tile it touched.
    pub fn abort(&mut self, maps: &mut MaterialMaps) {
        if let Some(open) = self.open.take() {
            for (id, tile) in open.saved {
                maps.replace_tile(id, tile);
            }
        }
    }

    /// Undoes the last step; false if there is none.
    pub fn undo(&mut self, maps: &mut MaterialMaps) -> bool {
        self.end();
        let Some(step) = self.undo.pop_back() else {
            return false;
        };
        self.redo.push(step.apply(maps));
        true
    }

    /// Redoes the last undone step; false if there is none.
    pub fn redo(&mut self, maps: &mut MaterialMaps) -> bool {
        self.end();
        let Some(step) = self.redo.pop() else {
            return false;
        };
        self.undo.push_back(step.apply(maps));
        self.enforce_cap();
        true
    }

    /// Heap bytes held by undo and redo steps (tiles shared with the maps count too: they
    /// stay alive for history's sake once the maps move on).
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
        self.open = None;
    }

    fn enforce_cap(&mut self) {
        while self.bytes() > self.cap_bytes {
            if self.undo.pop_front().is_none() {
                // Only redo steps are left; drop the furthest.
                if self.redo.is_empty() {
                    break;
                }
                self.redo.remove(0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::texel::MaterialValue;

    fn write(history: &mut History, maps: &mut MaterialMaps, id: TileId, value: u16) {
        history.tile_for_write(maps, id).n.data_mut()[0] = value;
    }

    #[test]
    fn undo_and_redo_restore_tiles_exactly() {
        let mut maps = MaterialMaps::new(256, 256, MaterialValue::default()).unwrap();
        let before = maps.clone();
        let mut history = History::default();
        history.begin("stroke");
        write(&mut history, &mut maps, 3, 11);
        write(&mut history, &mut maps, 3, 12);
        write(&mut history, &mut maps, 7, 13);
        history.end();
        let after = maps.clone();
        assert_eq!(history.undo_steps().next().map(Step::tile_count), Some(2));
        assert!(history.undo(&mut maps));
        for id in 0..maps.tile_count() {
            assert_eq!(**maps.tile(id), **before.tile(id));
        }
        assert!(history.redo(&mut maps));
        for id in 0..maps.tile_count() {
            assert_eq!(**maps.tile(id), **after.tile(id));
        }
        assert!(!history.redo(&mut maps));
    }

    #[test]
    fn abort_restores_and_leaves_no_step() {
        let mut maps = MaterialMaps::new(64, 64, MaterialValue::default()).unwrap();
        let before = maps.tile(0).clone();
        let mut history = History::default();
        history.begin("stroke");
        write(&mut history, &mut maps, 0, 99);
        history.abort(&mut maps);
        assert_eq!(**maps.tile(0), *before);
        assert!(!history.undo(&mut maps));
    }

    #[test]
    fn the_cap_drops_the_oldest_steps() {
        let mut maps = MaterialMaps::new(512, 512, MaterialValue::default()).unwrap();
        let mut history = History::new(0);
        history.set_cap_bytes(usize::MAX);
        for i in 0..10u16 {
            history.begin(format!("s{i}"));
            write(&mut history, &mut maps, usize::from(i), i);
            history.end();
        }
        // Every step saved a uniform tile (0 bytes) so far; now make steps cost memory.
        for i in 0..10u16 {
            history.begin(format!("t{i}"));
            write(&mut history, &mut maps, usize::from(i), 100 + i);
            history.end();
        }
        let per_step = history.undo_steps().last().map(Step::bytes).unwrap();
        assert!(per_step > 0);
        history.set_cap_bytes(3 * per_step);
        assert!(history.bytes() <= 3 * per_step);
        assert_eq!(
            history.undo_steps().last().map(|s| s.label.clone()),
            Some("t9".into())
        );
    }
}
