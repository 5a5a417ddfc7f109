//! `kapaint info`: a project's resolution, per-channel min/mean/max and memory.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::CliError;
use crate::model::{self, Document};

/// Print a project's resolution, per-channel min/mean/max and memory.
#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// Project file.
    file: PathBuf,
}

impl InfoArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A project that does not load.
    pub fn run(self) -> Result<String, CliError> {
        let doc = super::open_project(&self.file)?;
        let bytes = std::fs::metadata(&self.file).map_or(0, |m| m.len());
        Ok(info_text(&self.file, &doc, bytes))
    }
}

/// `kapaint info` output: `key: value` lines, then one line per channel component.
pub fn info_text(path: &Path, doc: &Document, file_bytes: u64) -> String {
    let maps = doc.maps();
    let s = doc.settings();
    let mut out = String::new();
    let _ = writeln!(out, "file: {}", path.display());
    let _ = writeln!(out, "size: {}x{}", maps.width(), maps.height());
    let _ = writeln!(
        out,
        "tiles: {} ({}x{} of 64x64)",
        maps.tile_count(),
        maps.tiles_x(),
        maps.tiles_y()
    );
    let _ = writeln!(out, "model: {}", s.model.name());
    let _ = writeln!(out, "method: {}", s.approx.name());
    let _ = writeln!(out, "mesh: {}", s.mesh.spec());
    let _ = writeln!(out, "preset: {}", s.preset.as_deref().unwrap_or("-"));
    let expanded = maps.tile_count() * model::tile::TILE_TEXELS * 14;
    let _ = writeln!(
        out,
        "memory: {} bytes in maps ({} bytes if every tile were expanded)",
        maps.heap_bytes(),
        expanded
    );
    let _ = writeln!(out, "file bytes: {file_bytes}");
    let _ = writeln!(out, "channel min mean max");
    for stat in model::stats::channel_stats(maps) {
        let _ = writeln!(
            out,
            "{} {:.6} {:.6} {:.6}",
            stat.label, stat.min, stat.mean, stat.max
        );
    }
    out
}
