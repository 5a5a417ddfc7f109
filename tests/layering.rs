//! The layering, checked: the model, the reflectance core, meshes, the render math and the
//! tools know nothing of egui, eframe or wgpu, directly or through the crate's own `ui` and
//! `gpu` modules. They are where almost all logic and tests live, and must stay testable
//! without a window or a device.

use std::path::Path;

/// The rooms that must stay free of the GUI and GPU crates.
const PURE: [&str; 6] = ["model", "reflectance", "mesh", "render", "tools", "pbr"];

/// What a file of those rooms may not name.
const FORBIDDEN: [&str; 6] = [
    "egui",
    "eframe",
    "wgpu",
    "crate::ui",
    "crate::gpu",
    "super::ui",
];

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(Result::ok) {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Whether `line` names `word` as code (not inside a comment).
fn names(line: &str, word: &str) -> bool {
    let code = line.split("//").next().unwrap_or("");
    code.match_indices(word).any(|(at, _)| {
        let before = code[..at].chars().next_back();
        let after = code[at + word.len()..].chars().next();
        !before.is_some_and(|c| c.is_alphanumeric() || c == '_')
            && !after.is_some_and(|c| c.is_alphanumeric() || c == '_')
    })
}

#[test]
fn the_pure_rooms_import_neither_egui_nor_wgpu() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    for room in PURE {
        rust_files(&src.join(room), &mut files);
        let single = src.join(format!("{room}.rs"));
        if single.exists() {
            files.push(single);
        }
    }
    assert!(files.len() > 30, "the rooms were not found: {files:?}");
    let mut found = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap_or_default();
        for (k, line) in text.lines().enumerate() {
            for word in FORBIDDEN {
                if names(line, word) {
                    found.push(format!("{}:{}: {word}", file.display(), k + 1));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "GUI or GPU code in a pure room:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_check_sees_what_it_looks_for() {
    assert!(names("use egui::Ui;", "egui"));
    assert!(names("    let t: wgpu::Texture;", "wgpu"));
    assert!(!names("// egui is not used here", "egui"));
    assert!(!names("let legui = 1;", "egui"));
    assert!(names("use crate::gpu::Gpu;", "crate::gpu"));
}
