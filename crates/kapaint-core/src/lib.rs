//! kapaint's core above the model: everything that needs neither a window nor a device.
//!
//! [`render`] holds the camera and shading maths the GPU mirrors; [`tools`] turns pointer
//! input into commands; [`report`] measures the core; [`crash`]
//! is the crash handler. The crates below are re-exported under their room names, so the
//! rooms above name one crate: [`reflectance`] (`kapaint-reflectance`, the paper's `chi` exactly
//! and fast, `k_a` per model), [`model`] (`kapaint-model`, tiles, layers, documents, commands,
//! undo, projects, recovery), [`mesh`] (`kapaint-mesh`) and [`atomic`], [`file_check`],
//! [`memory`], [`task`] (`kapaint-base`). Cargo keeps egui, eframe, wgpu, rfd and zbus out of
//! this crate and every crate below it.

pub use kapaint_base::{atomic, file_check, memory, task};
pub use kapaint_mesh as mesh;
pub use kapaint_model as model;
pub use kapaint_reflectance as reflectance;

pub mod crash;
pub mod render;
pub mod report;
pub mod tools;
