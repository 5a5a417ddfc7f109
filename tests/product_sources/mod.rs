//! The product's sources and ARCHITECTURE.md's file lists, for the tests that hold a unit to
//! its files (`model_unit.rs`, `codec_unit.rs`, `editor_unit.rs`).

use std::path::{Path, PathBuf};

/// The workspace root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file under `dir` whose name ends with `ext`, recursively.
pub fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            files(&path, ext, out);
        } else if path.to_string_lossy().ends_with(ext) {
            out.push(path);
        }
    }
}

/// The product's Rust sources (the root package and every crate), each with its path from the
/// root and its text up to its first `#[cfg(test)]`: test files and test modules are left out.
pub fn product_sources() -> Vec<(String, String)> {
    let root = root();
    let mut paths = Vec::new();
    files(&root.join("src"), ".rs", &mut paths);
    files(&root.join("crates"), ".rs", &mut paths);
    let mut out: Vec<(String, String)> = paths
        .into_iter()
        .filter_map(|p| {
            let relative = p
                .strip_prefix(&root)
                .ok()?
                .to_string_lossy()
                .replace('\\', "/");
            let is_test = relative.contains("/tests/")
                || relative.ends_with("/tests.rs")
                || relative.contains("/benches/");
            if is_test {
                return None;
            }
            let text = std::fs::read_to_string(&p).ok()?;
            let code = text.split("#[cfg(test)]").next().unwrap_or("").to_owned();
            Some((relative, code))
        })
        .collect();
    out.sort();
    out
}

/// The files ARCHITECTURE.md lists between its `<!-- MARKER -->` and `<!-- /MARKER -->`
/// lines, one `` - `path`: why `` item each.
pub fn listed_files(marker: &str) -> Vec<String> {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let start = text
        .find(&format!("<!-- {marker} -->"))
        .unwrap_or_else(|| panic!("ARCHITECTURE.md marks its {marker} list"));
    let end = text
        .find(&format!("<!-- /{marker} -->"))
        .unwrap_or_else(|| panic!("the {marker} list's end marker"));
    text[start..end]
        .lines()
        .filter_map(|line| {
            let line = line.trim().strip_prefix("- `")?;
            Some(line[..line.find('`')?].to_owned())
        })
        .collect()
}
