//! kapaint's core above the model: everything that needs neither a window nor a device.
//!
//! [`render`] holds the camera and shading maths the GPU mirrors; [`report`] measures the
//! core; [`crash`] is the crash handler. The tools are a crate of their own
//! (`kapaint-tools`), beside the editor that uses them. It re-exports nothing: a crate above that uses the model, the meshes,
//! the reflectance maths or the base depends on that crate itself. Cargo keeps egui, eframe,
//! wgpu, rfd and zbus out of this crate and every crate below it.

pub mod crash;
pub mod render;
pub mod report;
