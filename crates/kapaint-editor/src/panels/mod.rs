//! The editor's panels: tools, brush and material on the left; shading, compare, view, light
//! and presets on the right; the menu bar, the status bar, dropped files and notices. Each
//! reads the state and issues [`Command`](kapaint_model::Command)s.

pub(super) mod bars;
pub mod colour;
pub(super) mod generator;
mod layer_settings;
pub mod layers;
pub(super) mod presets;
pub(super) mod tool_panel;
pub(super) mod view_panel;
