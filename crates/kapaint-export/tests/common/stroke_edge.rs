//! The stroke-edge project the KTX2 tests export, and where they write it.

use std::path::{Path, PathBuf};

use kapaint_core::report::typical::stroke_edge_document;
use kapaint_export::codec::Effort;
use kapaint_export::preset::{self, BlockBudget, ExportPreset, Format};
use kapaint_export::set::{self, Manifest};
use kapaint_model::Document;

/// A fresh folder for test `tag`'s files.
pub fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-ktx2-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The spot texture from ../shared/testdata, where it is.
pub fn spot() -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/testdata/spot/spot_texture.png");
    path.exists().then_some(path)
}

/// The stroke-edge project at `side`: the spot texture in k_d, soft strokes of n = 3000 and 2.
pub fn project(side: u32) -> Document {
    stroke_edge_document(side, spot().as_deref()).expect("project")
}

/// Exports `doc` with `preset` into a fresh folder for `tag`.
pub fn export(doc: &Document, preset: &ExportPreset, tag: &str) -> (PathBuf, Manifest) {
    let out = temp(tag);
    let manifest = set::export(doc, preset, &out).expect("export");
    (out, manifest)
}

/// A budget of the older measures alone (relative `k_a` errors and PSNR), the perceptual
/// one left loose: the search paths these tests follow were made for those.
pub fn relative_budget(max: f64, mean: f64, psnr: f64) -> BlockBudget {
    BlockBudget {
        ka_error_srgb_p999: 255.0,
        ka_error_srgb_mean: 255.0,
        max_ka_error: Some(max),
        mean_ka_error: Some(mean),
        min_psnr: Some(psnr),
    }
}

/// The `ktx2` preset with `budget` and at most `ceiling` of effort.
pub fn with_budget(budget: BlockBudget, ceiling: Effort) -> ExportPreset {
    let mut p = preset::find("ktx2").expect("preset");
    p.budget = budget;
    p.format = Format::Ktx2Bc {
        max_effort: ceiling,
        bc6h: true,
    };
    p
}
