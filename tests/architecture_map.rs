//! ARCHITECTURE.md cannot drift from the workspace (issue 55): every crate has its row in the
//! crate table, every public module of a crate (and every crate it re-exports by a name) is
//! named in that row, and every module the row names exists in that crate. Every crate the
//! document names exists.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod source_tree;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The workspace root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every crate of the workspace by its package name, with its source folder: the root package
/// `kapaint` and each `crates/kapaint-*`.
fn crates() -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    out.insert("kapaint".to_string(), root().join("src"));
    for entry in std::fs::read_dir(root().join("crates")).expect("crates folder") {
        let path = entry.expect("entry").path();
        if path.join("Cargo.toml").is_file() {
            let name = path
                .file_name()
                .expect("a name")
                .to_string_lossy()
                .into_owned();
            out.insert(name, path.join("src"));
        }
    }
    out
}

/// What a crate's root shows, from `lib.rs`: the names it must document (`pub mod NAME` and
/// `pub use CRATE as NAME`), and the other lower-case names its `pub use`s bring up (modules
/// of the crates below, functions), which it may name.
fn public_modules(src: &Path) -> (BTreeSet<String>, BTreeSet<String>) {
    let lib = std::fs::read_to_string(src.join("lib.rs")).expect("lib.rs");
    let (mut required, mut allowed) = (BTreeSet::new(), BTreeSet::new());
    for line in lib.lines() {
        if let Some(name) = line.strip_prefix("pub mod ") {
            required.insert(name.trim_end_matches(';').trim().to_string());
        }
    }
    // `pub use` statements, which may run over lines.
    for statement in lib.split(';') {
        let Some(at) = statement.find("pub use ") else {
            continue;
        };
        let body = &statement[at + "pub use ".len()..];
        if let Some((_, alias)) = body.split_once(" as ") {
            required.insert(alias.trim().to_string());
            continue;
        }
        let names = match body.split_once('{') {
            Some((_, list)) => list.trim_end().trim_end_matches('}').to_string(),
            None => body.rsplit("::").next().unwrap_or_default().to_string(),
        };
        for name in names.split(',').map(str::trim) {
            if name.starts_with(|c: char| c.is_ascii_lowercase()) {
                allowed.insert(name.to_string());
            }
        }
    }
    (required, allowed)
}

/// Every module of a crate by its path from the root (`set`, `set::plan`), public or not.
fn module_paths(src: &Path) -> BTreeSet<String> {
    source_tree::modules(src)
        .into_keys()
        .filter(|m| !m.is_empty())
        .collect()
}

/// The text between backticks in `text`.
fn quoted(text: &str) -> Vec<&str> {
    text.split('`').skip(1).step_by(2).collect()
}

/// The crate table's rows: the crate a row is of, and its "rooms" cell.
fn rows(doc: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for line in doc.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // "| `kapaint-x` | rooms | links |" splits into ["", crate, rooms, links, ""].
        if cells.len() == 5
            && let [name] = quoted(cells[1])[..]
            && name.starts_with("kapaint")
            && cells[1] == format!("`{name}`")
        {
            out.insert(name.to_string(), cells[2].to_string());
        }
    }
    out
}

#[test]
fn architecture_names_every_crate_and_public_module_and_nothing_else() {
    let doc = std::fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let crates = crates();
    let rows = rows(&doc);
    let mut wrong = Vec::new();
    for (name, src) in &crates {
        let Some(rooms) = rows.get(name) else {
            wrong.push(format!("{name} has no row in the crate table"));
            continue;
        };
        let named: BTreeSet<&str> = quoted(rooms).into_iter().collect();
        let (public, reexported) = public_modules(src);
        for module in &public {
            if !named.contains(module.as_str()) {
                wrong.push(format!("{name}'s row does not name its module `{module}`"));
            }
        }
        // Every module-like name in the row (lower case, maybe a path) is one of the crate's.
        let paths = module_paths(src);
        for n in &named {
            let module_like = n
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' || c == ':');
            if module_like
                && !public.contains(*n)
                && !reexported.contains(*n)
                && !paths.contains(*n)
            {
                wrong.push(format!(
                    "{name}'s row names `{n}`, which is no module of it"
                ));
            }
        }
    }
    for row in rows.keys() {
        if !crates.contains_key(row) {
            wrong.push(format!(
                "the crate table has a row for {row}, no crate of the workspace"
            ));
        }
    }
    // Any crate named anywhere exists.
    for n in quoted(&doc) {
        if n.starts_with("kapaint-")
            && n.chars().all(|c| c.is_ascii_lowercase() || c == '-')
            && !crates.contains_key(n)
        {
            wrong.push(format!(
                "ARCHITECTURE.md names the crate {n}, which does not exist"
            ));
        }
    }
    assert!(wrong.is_empty(), "ARCHITECTURE.md:\n{}", wrong.join("\n"));
}
