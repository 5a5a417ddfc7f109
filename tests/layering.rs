//! The layering, as far as Cargo cannot see it.
//!
//! Cargo already enforces that no crate imports one above it (a dependency back down would be
//! a cycle, which Cargo refuses) and that a crate cannot name a module of a crate it does not
//! depend on. What Cargo does not stop is a new edge that still makes no cycle (the maths
//! taking the mesh crate, say) or a dependency that pulls a GUI or GPU crate into a room that
//! must build and test without a window or a device. This test pins the graph and asks
//! `cargo tree` (features resolved for that crate alone) what each crate links.
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

/// Each crate with the kapaint crates under it (its whole tree, not only what it names).
const LAYERS: [(&str, &[&str]); 11] = [
    ("kapaint-base", &[]),
    ("kapaint-reflectance", &[]),
    ("kapaint-mesh", &["kapaint-base"]),
    (
        "kapaint-model",
        &["kapaint-base", "kapaint-mesh", "kapaint-reflectance"],
    ),
    ("kapaint-pbr", &BELOW_CORE),
    ("kapaint-core", &BELOW_CORE),
    ("kapaint-tools", &BELOW_CORE),
    (
        "kapaint-export",
        &[
            BELOW_CORE[0],
            BELOW_CORE[1],
            BELOW_CORE[2],
            BELOW_CORE[3],
            "kapaint-basis",
            "kapaint-pbr",
        ],
    ),
    (
        "kapaint-gpu",
        &[
            BELOW_CORE[0],
            BELOW_CORE[1],
            BELOW_CORE[2],
            BELOW_CORE[3],
            "kapaint-basis",
            "kapaint-core",
            "kapaint-export",
            "kapaint-pbr",
        ],
    ),
    (
        "kapaint-editor",
        &[
            BELOW_CORE[0],
            BELOW_CORE[1],
            BELOW_CORE[2],
            BELOW_CORE[3],
            "kapaint-basis",
            "kapaint-core",
            "kapaint-export",
            "kapaint-gpu",
            "kapaint-pbr",
            "kapaint-tools",
        ],
    ),
    (
        "kapaint",
        &[
            BELOW_CORE[0],
            BELOW_CORE[1],
            BELOW_CORE[2],
            BELOW_CORE[3],
            "kapaint-basis",
            "kapaint-core",
            "kapaint-editor",
            "kapaint-export",
            "kapaint-gpu",
            "kapaint-pbr",
            "kapaint-tools",
        ],
    ),
];

const BELOW_CORE: [&str; 4] = [
    "kapaint-base",
    "kapaint-mesh",
    "kapaint-model",
    "kapaint-reflectance",
];

#[test]
fn every_crate_stands_only_on_the_crates_below_it() {
    for (krate, below) in LAYERS {
        let want: BTreeSet<String> = below.iter().map(|s| (*s).to_owned()).collect();
        assert_eq!(
            kapaint_deps(krate),
            want,
            "the kapaint crates under {krate}"
        );
    }
}

#[test]
fn the_core_and_everything_under_it_link_no_gui_or_gpu_crate() {
    let mut forbidden = GUI.to_vec();
    forbidden.push("wgpu");
    for krate in [
        "kapaint-base",
        "kapaint-reflectance",
        "kapaint-mesh",
        "kapaint-model",
        "kapaint-pbr",
        "kapaint-core",
        "kapaint-tools",
        "kapaint-export",
    ] {
        assert_free_of(krate, &forbidden);
    }
}

/// The export needs the model and the PBR conversion, never the tools nor the reports'
/// charts (issue 55: every crate above the core linked `plotters`).
#[test]
fn the_export_links_neither_the_core_nor_its_charts() {
    assert_free_of("kapaint-export", &["kapaint-core", "plotters"]);
    assert_free_of("kapaint-pbr", &["kapaint-core", "plotters"]);
}

/// The tools are the editor's: the GPU crate (and so the export's GPU encoder) never links
/// them (issue 55: they sat in the core, under the GPU crate).
#[test]
fn the_tools_are_the_editors_alone() {
    assert_free_of("kapaint-gpu", &["kapaint-tools"]);
    assert_free_of("kapaint-core", &["kapaint-tools"]);
    assert_free_of("kapaint-export", &["kapaint-tools"]);
}

/// The reports' charts are the command line's: no crate of the workspace links `plotters`
/// but the root package.
#[test]
fn only_the_command_line_links_the_charts() {
    for krate in ["kapaint-core", "kapaint-gpu", "kapaint-editor"] {
        assert_free_of(krate, &["plotters"]);
    }
}

#[test]
fn the_gpu_crate_links_no_gui_crate() {
    assert_free_of("kapaint-gpu", &GUI);
}

/// The build needs a Rust toolchain and a C/C++ compiler, nothing else: no crate in any tree
/// (normal, build or dev) runs bindgen, which needs
/// libclang installed (ARM's ASTC encoder comes with hand-written bindings).
#[test]
fn nothing_in_the_build_needs_libclang() {
    let out = Command::new(env!("CARGO"))
        .args([
            "tree",
            "--locked",
            "--workspace",
            "-e",
            "all",
            "--prefix",
            "none",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree: BTreeSet<String> = String::from_utf8(out.stdout)
        .expect("utf-8")
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_owned)
        .collect();
    assert!(
        tree.contains("ctt-astcenc"),
        "the ASTC encoder is in the tree"
    );
    for needs_libclang in ["bindgen", "clang-sys"] {
        assert!(
            !tree.contains(needs_libclang),
            "{needs_libclang} is in the build"
        );
    }
}

/// Whether `line` re-exports a kapaint crate whole (`pub use kapaint_model as model;`) or its
/// modules (`pub use kapaint_base::{atomic, task};`, lower-case names): a facade. An item
/// (`pub use kapaint_core::render::Compare;`) is a type the crate's own API hands out.
fn re_exports_a_crate_or_its_modules(line: &str) -> bool {
    let Some(rest) = line.trim_start().strip_prefix("pub use kapaint_") else {
        return false;
    };
    let rest = rest.trim_end().trim_end_matches(';');
    let Some((_krate, path)) = rest.split_once("::") else {
        // The crate itself, renamed or not.
        return true;
    };
    let names = path.trim_start_matches('{').trim_end_matches('}');
    !names.contains("::")
        && names
            .split(',')
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .all(|n| n.chars().next().is_some_and(|c| c.is_ascii_lowercase()))
}

#[test]
fn the_facade_reader_tells_crates_and_modules_from_items() {
    assert!(re_exports_a_crate_or_its_modules(
        "pub use kapaint_model as model;"
    ));
    assert!(re_exports_a_crate_or_its_modules(
        "pub use kapaint_base::{atomic, task};"
    ));
    assert!(re_exports_a_crate_or_its_modules(
        "pub use kapaint_mesh::pick;"
    ));
    assert!(!re_exports_a_crate_or_its_modules(
        "pub use kapaint_core::render::Compare;"
    ));
    assert!(!re_exports_a_crate_or_its_modules(
        "pub use kapaint_model::provenance::{A, B};"
    ));
    assert!(!re_exports_a_crate_or_its_modules(
        "use kapaint_model as model;"
    ));
}

/// No facade: a crate under the command line re-exports no other kapaint crate, so what a
/// crate uses is what its Cargo.toml names (`cargo tree -p` tells the truth about it). The
/// root package, the command line and the binary, names the rooms for its users.
#[test]
fn no_crate_under_the_command_line_re_exports_another() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut found = Vec::new();
    for (krate, _) in LAYERS.iter().filter(|(k, _)| *k != "kapaint") {
        let dir = root.join("crates").join(krate).join("src");
        let mut stack = vec![dir];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).expect("a source folder").flatten() {
                let path = entry.path();
                if path.is_dir() {
                    stack.push(path);
                } else if path.extension().is_some_and(|e| e == "rs") {
                    let text = std::fs::read_to_string(&path).expect("a source file");
                    for (i, line) in text.lines().enumerate() {
                        if re_exports_a_crate_or_its_modules(line) {
                            found.push(format!("{}:{}: {line}", path.display(), i + 1));
                        }
                    }
                }
            }
        }
    }
    assert!(found.is_empty(), "facade re-exports: {found:#?}");
}
