//! The material model: per-texel maps, painting, undo, presets and project files.
//!
//! Nothing here knows about egui or wgpu: the editor reads the model and issues
//! [`document::Command`]s; the GPU mirrors the maps' dirty tiles.

pub mod brush;
pub mod check;
pub mod document;
mod error;
pub mod generator;
pub mod import;
pub mod layers;
pub mod maps;
pub mod mesh_ref;
pub mod mips;
pub mod normal;
pub mod paint;
pub mod paint_image;
pub mod preset;
pub mod project;
pub mod provenance;
pub mod recovery;
pub mod resize;
pub mod stats;
pub mod surface;
pub mod texel;
pub mod tile;

pub use document::{
    Command, Decal, DecalFrame, Document, DocumentSettings, FillRegion, HistoryCommand,
    ImportCommand, LayerCommand, LayerKind, LayerMove, LayerPlace, LayerRef, MaskCommand,
    PaintCommand, SettingsCommand, StrokeCommand, StrokeTool,
};
pub use error::ModelError;
pub use maps::MaterialMaps;
pub use mesh_ref::MeshRef;
pub use texel::{Channel, Channels, MaterialValue};
