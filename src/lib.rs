//! kapaint: paint per-texel Phong reflectance and preview it with a derived ambient term.
//!
//! The library holds all logic; the `kapaint` binary is a thin shell around [`cli::main`].
//! [`reflectance`] is the numerical core (no GUI or GPU code), [`report`] measures it.

pub mod atomic;
pub mod cli;
pub mod crash;
pub mod export;
pub mod file_check;
pub mod gpu;
pub mod memory;
pub mod mesh;
pub mod model;
pub mod pbr;
pub mod reflectance;
pub mod render;
pub mod report;
pub mod task;
pub mod tools;
pub mod ui;
