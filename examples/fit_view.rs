//! Regenerates `crates/kapaint-reflectance/src/view_table.rs`, the per-view table of
//! `ln chi_view`, from the exact integrator, and prints its worst relative error on points
//! between the nodes (to stderr).
//!
//! Usage: `cargo run --release --example fit_view [NODES] > crates/kapaint-reflectance/src/view_table.rs`

use kapaint::reflectance::view::view_table_source;

fn main() {
    let nodes: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(128);
    let start = std::time::Instant::now();
    print!("{}", view_table_source(nodes));
    eprintln!("{nodes}^2 nodes in {:.1} s", start.elapsed().as_secs_f64());
}
