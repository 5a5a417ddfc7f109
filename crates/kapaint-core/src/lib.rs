//! kapaint's core: everything that needs neither a window nor a device.
//!
//! [`reflectance`] is the numerical core (the paper's `chi` exactly and fast, `k_a` per
//! model); [`model`] is the material being painted (tiles, layers, documents, commands,
//! undo, projects, recovery); [`mesh`] loads and bakes meshes; [`render`] holds the camera
//! and shading maths the GPU mirrors; [`tools`] turns pointer input into commands; [`pbr`]
//! converts PBR materials; [`report`] measures the core. Below them: atomic files
//! ([`atomic`]), file checks ([`file_check`]), memory ([`memory`]), tasks ([`task`]) and the
//! crash handler ([`crash`]). Cargo keeps egui, eframe, wgpu, rfd and zbus out of this crate.

pub mod atomic;
pub mod crash;
pub mod file_check;
pub mod memory;
pub mod mesh;
pub mod model;
pub mod pbr;
pub mod reflectance;
pub mod render;
pub mod report;
pub mod task;
pub mod tools;
