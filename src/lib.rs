//! kapaint: paint per-texel Phong reflectance and preview it with a derived ambient term.
//!
//! The library is the command line ([`cli`]) over the workspace's crates, re-exported here by
//! their room names so that one path names each thing: [`kapaint_core`] (the reflectance
//! maths, the model, meshes, render maths, tools, PBR conversion; no GUI or GPU crate),
//! [`export`] (`kapaint-export`), [`gpu`] (`kapaint-gpu`) and [`ui`] (`kapaint-editor`). The
//! `kapaint` binary is a thin shell around [`cli::main`].

pub use kapaint_core::{
    atomic, crash, file_check, memory, mesh, model, reflectance, render, task, tools,
};
pub use kapaint_editor as ui;
pub use kapaint_export as export;
pub use kapaint_gpu as gpu;
pub use kapaint_pbr as pbr;

pub mod cli;
pub mod report;
