//! Regenerates `crates/kapaint-reflectance/src/view_table.bin`, the per-view table of
//! `ln chi_view` (four tables of NODES^2 little-endian `f32`), from the exact integrator, and
//! prints each table's worst relative error between the nodes (to stderr). The shipped table
//! has 128 nodes a side (`VIEW_NODES`).
//!
//! Usage: `cargo run --release --example fit_view [NODES] > crates/kapaint-reflectance/src/view_table.bin`

use std::io::Write;

use kapaint::reflectance::view::{VIEW_NODES, view_table_bytes};

fn main() {
    let nodes: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(VIEW_NODES);
    let start = std::time::Instant::now();
    let bytes = view_table_bytes(nodes);
    if let Err(e) = std::io::stdout().write_all(&bytes) {
        eprintln!("fit_view: {e}");
        std::process::exit(1);
    }
    eprintln!("{nodes}^2 nodes in {:.1} s", start.elapsed().as_secs_f64());
}
