//! kapaint: paint per-texel Phong reflectance and preview it with a derived ambient term.
//!
//! The library is the command line ([`cli`]) over the workspace's crates, re-exported here by
//! their room names so that one path names each thing: [`reflectance`], [`model`], [`mesh`]
//! and the base ([`atomic`], [`task`], ...) from their own crates, [`render`] and [`tools`]
//! (`kapaint-core`), [`pbr`], [`export`] (`kapaint-export`), [`gpu`] (`kapaint-gpu`) and [`ui`]
//! (`kapaint-editor`). The `kapaint` binary is a thin shell around [`cli::main`].

pub use kapaint_base::{atomic, file_check, memory, task};
pub use kapaint_core::{crash, render};
pub use kapaint_editor as ui;
pub use kapaint_export as export;
pub use kapaint_gpu as gpu;
pub use kapaint_mesh as mesh;
pub use kapaint_model as model;
pub use kapaint_pbr as pbr;
pub use kapaint_reflectance as reflectance;
pub use kapaint_tools as tools;

pub mod cli;
pub mod report;
