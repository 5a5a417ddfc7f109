//! The layering, as far as Cargo cannot see it.
//!
//! Cargo already enforces that no crate imports one above it: `kapaint-core` has no kapaint
//! crate to import, `kapaint-export` only the core, `kapaint-gpu` the core and the export,
//! `kapaint-editor` those three, and a crate cannot name a module of a crate it does not
//! depend on. What Cargo does not stop is a dependency added to a crate's manifest that pulls a
//! GUI or GPU crate into a room that must build and test without a window or a device. This
//! test asks `cargo tree` (features resolved for that crate alone) what each crate links.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::collections::BTreeSet;
use std::process::Command;

/// The window, GUI and device crates.
const GUI: [&str; 6] = ["egui", "eframe", "egui_dock", "rfd", "zbus", "winit"];

/// Every package in `krate`'s normal (not dev, not build) dependency tree.
fn normal_tree(krate: &str) -> BTreeSet<String> {
    let out = Command::new(env!("CARGO"))
        .args([
            "tree", "--locked", "-p", krate, "-e", "normal", "--prefix", "none",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree -p {krate}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .expect("utf-8")
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_owned)
        .collect()
}

fn assert_free_of(krate: &str, forbidden: &[&str]) {
    let tree = normal_tree(krate);
    assert!(tree.len() > 1, "{krate} has a tree: {tree:?}");
    let found: Vec<&&str> = forbidden.iter().filter(|f| tree.contains(**f)).collect();
    assert!(found.is_empty(), "{krate} links {found:?}");
}

/// The kapaint crates `krate` depends on.
fn kapaint_deps(krate: &str) -> BTreeSet<String> {
    normal_tree(krate)
        .into_iter()
        .filter(|p| p.starts_with("kapaint") && p != krate)
        .collect()
}

#[test]
fn the_core_links_no_gui_or_gpu_crate() {
    let mut forbidden = GUI.to_vec();
    forbidden.push("wgpu");
    assert_free_of("kapaint-core", &forbidden);
    assert!(kapaint_deps("kapaint-core").is_empty());
}

#[test]
fn the_export_links_no_gui_or_gpu_crate_and_only_the_core() {
    let mut forbidden = GUI.to_vec();
    forbidden.push("wgpu");
    assert_free_of("kapaint-export", &forbidden);
    assert_eq!(
        kapaint_deps("kapaint-export"),
        BTreeSet::from(["kapaint-core".to_owned()])
    );
}

#[test]
fn the_gpu_crate_links_no_gui_crate_and_nothing_above_it() {
    assert_free_of("kapaint-gpu", &GUI);
    assert_eq!(
        kapaint_deps("kapaint-gpu"),
        BTreeSet::from(["kapaint-core".to_owned(), "kapaint-export".to_owned()])
    );
}

#[test]
fn the_editor_sits_below_the_command_line() {
    assert_eq!(
        kapaint_deps("kapaint-editor"),
        BTreeSet::from([
            "kapaint-core".to_owned(),
            "kapaint-export".to_owned(),
            "kapaint-gpu".to_owned()
        ])
    );
}
