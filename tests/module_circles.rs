//! No circle of modules inside a crate: what Cargo cannot see of the layering.
//!
//! Cargo stops a crate from importing one above it; inside a crate, nothing stops `a` using
//! `b` while `b` uses `a`. This test reads every crate's sources, takes each `crate::`,
//! `super::` and `self::` path to the module it names (the deepest module that exists), and
//! asks that the modules and the paths between them form no circle. A module's children and
//! ancestors do not count (a parent declares its children; a child may use what its parent
//! re-exports), nor does test code (`#[cfg(test)]` to the end of a file).
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod source_tree;

use source_tree::modules;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The code of a file without comments, string literals and its test module.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).expect("source");
    let text = text.split("#[cfg(test)]").next().unwrap_or_default();
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let line = line.split("//").next().unwrap_or_default();
        // Drop string literals (a path inside a message is not a use).
        let mut quoted = false;
        for c in line.chars() {
            if c == '"' {
                quoted = !quoted;
            } else if !quoted {
                out.push(c);
            }
        }
        out.push('\n');
    }
    out
}

/// What each module re-exports: a name its `pub use` (or `pub(crate) use`) brings in, and the
/// module that name comes from (the deepest module of the path), for paths that start at
/// `crate::`, `self::`, `super::` or a child module.
type Reexports = BTreeMap<String, BTreeMap<String, String>>;

/// The deepest module of `all` along `segments` from `base`, and the segment after it.
fn deepest(
    base: &[String],
    segments: &[String],
    all: &BTreeMap<String, PathBuf>,
) -> (Vec<String>, Option<String>) {
    let mut target = base.to_vec();
    for seg in segments {
        let candidate = [target.as_slice(), std::slice::from_ref(seg)].concat();
        if !all.contains_key(&candidate.join("::")) {
            return (target, Some(seg.clone()));
        }
        target = candidate;
    }
    (target, None)
}

/// [`Reexports`] of one module.
fn reexports_of(
    module: &str,
    path: &Path,
    all: &BTreeMap<String, PathBuf>,
) -> BTreeMap<String, String> {
    let here: Vec<String> = module
        .split("::")
        .filter(|s| !s.is_empty())
        .map(str::to_owned)
        .collect();
    let mut out = BTreeMap::new();
    for statement in code(path).split(';') {
        let Some(at) = statement
            .find("pub use ")
            .map(|i| i + "pub use ".len())
            .or_else(|| {
                statement
                    .find("pub(crate) use ")
                    .map(|i| i + "pub(crate) use ".len())
            })
        else {
            continue;
        };
        let body: String = statement[at..]
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        let (prefix, items) = match body.split_once('{') {
            Some((p, list)) => (
                p.trim_end_matches("::").to_string(),
                list.trim_end_matches('}')
                    .split(',')
                    .map(|i| i.trim().to_string())
                    .filter(|i| !i.is_empty())
                    .collect::<Vec<_>>(),
            ),
            None => match body.rsplit_once("::") {
                Some((p, item)) => (p.to_string(), vec![item.to_string()]),
                None => continue,
            },
        };
        let mut segments: Vec<String> = prefix.split("::").map(|s| s.trim().to_owned()).collect();
        let base: Vec<String> = match segments.first().map(String::as_str) {
            Some("crate") => Vec::new(),
            Some("self") => here.clone(),
            Some("super") => here[..here.len().saturating_sub(1)].to_vec(),
            Some(child)
                if all
                    .contains_key(&[here.as_slice(), &[child.to_owned()]].concat().join("::")) =>
            {
                segments.insert(0, "self".into());
                here.clone()
            }
            _ => continue,
        };
        for item in items {
            let (path, alias) = match item.split_once(" as ") {
                Some((p, a)) => (p.trim().to_string(), a.trim().to_string()),
                None => (
                    item.clone(),
                    item.rsplit("::").next().unwrap_or_default().to_string(),
                ),
            };
            let full: Vec<String> = segments[1..]
                .iter()
                .cloned()
                .chain(path.split("::").map(|s| s.trim().to_owned()))
                .collect();
            let (target, _) = deepest(&base, &full, all);
            let target = target.join("::");
            if target != module {
                out.insert(alias, target);
            }
        }
    }
    out
}

/// The modules `module`'s code names, by `crate::`, `super::` and `self::` paths (brace
/// groups included); a name a module re-exports counts as the module it comes from.
fn edges(
    module: &str,
    path: &Path,
    all: &BTreeMap<String, PathBuf>,
    reexports: &Reexports,
) -> BTreeSet<String> {
    let here: Vec<String> = module
        .split("::")
        .filter(|s| !s.is_empty())
        .map(str::to_owned)
        .collect();
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let code = code(path);
    let mut out = BTreeSet::new();
    for (at, _) in code.match_indices("::") {
        // The path's first segment, where it is one.
        let start = code[..at].rfind(|c: char| !ident(c)).map_or(0, |i| i + 1);
        if code[..start].ends_with("::") {
            continue;
        }
        let base: Vec<String> = match &code[start..at] {
            "crate" => Vec::new(),
            "self" => here.clone(),
            // A file `a/b.rs` (or `a/b/mod.rs`) is module `a::b`; its `super` is `a`.
            "super" => here[..here.len().saturating_sub(1)].to_vec(),
            _ => continue,
        };
        // What follows: `a::b::c`, or `{a, b::c}`.
        let rest = &code[at + 2..];
        let heads: Vec<&str> = match rest.strip_prefix('{') {
            Some(group) => group
                .split('}')
                .next()
                .unwrap_or_default()
                .split(',')
                .map(str::trim)
                .collect(),
            None => vec![rest],
        };
        for head in heads {
            let segments: Vec<String> = head
                .split("::")
                .map(|seg| seg.trim().chars().take_while(|c| ident(*c)).collect())
                .collect();
            let (target, item) = deepest(&base, &segments, all);
            let mut name = target.join("::");
            // An item the module re-exports is a use of the module it comes from (followed
            // through a few re-exports).
            for _ in 0..4 {
                match item
                    .as_ref()
                    .and_then(|i| reexports.get(&name).and_then(|r| r.get(i)))
                {
                    Some(from) if *from != name => name.clone_from(from),
                    _ => break,
                }
            }
            let related = name.is_empty()
                || name == module
                || module.starts_with(&format!("{name}::"))
                || name.starts_with(&format!("{module}::"));
            if !related {
                out.insert(name);
            }
        }
    }
    out
}

/// The circles (strongly connected groups of more than one module) of a graph.
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    // Two modules are in one circle when each reaches the other.
    let reach = |from: &str| {
        let mut seen = BTreeSet::new();
        let mut todo = vec![from.to_owned()];
        while let Some(m) = todo.pop() {
            for next in graph.get(&m).into_iter().flatten() {
                if seen.insert(next.clone()) {
                    todo.push(next.clone());
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&String, BTreeSet<String>> =
        graph.keys().map(|m| (m, reach(m))).collect();
    let mut done = BTreeSet::new();
    let mut out = Vec::new();
    for (m, r) in &reaches {
        if done.contains(*m) || !r.contains(*m) {
            continue;
        }
        let circle: Vec<String> = r
            .iter()
            .filter(|o| reaches.get(o).is_some_and(|back| back.contains(*m)))
            .cloned()
            .collect();
        done.extend(circle.iter().cloned());
        out.push(circle);
    }
    out
}

#[test]
fn no_crate_has_a_circle_of_modules() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut sources = vec![root.join("src")];
    for entry in std::fs::read_dir(root.join("crates")).expect("crates") {
        sources.push(entry.expect("crate").path().join("src"));
    }
    let mut found = Vec::new();
    for src in &sources {
        let all = modules(src);
        assert!(!all.is_empty(), "{} has modules", src.display());
        let reexports: Reexports = all
            .iter()
            .map(|(m, path)| (m.clone(), reexports_of(m, path, &all)))
            .collect();
        let graph: BTreeMap<String, BTreeSet<String>> = all
            .iter()
            .map(|(m, path)| (m.clone(), edges(m, path, &all, &reexports)))
            .collect();
        for circle in circles(&graph) {
            found.push(format!("{}: {}", src.display(), circle.join(" <-> ")));
        }
    }
    assert!(found.is_empty(), "module circles:\n{}", found.join("\n"));
}

/// The test sees a circle where there is one.
#[test]
fn a_circle_is_seen() {
    let graph: BTreeMap<String, BTreeSet<String>> = [
        ("a", &["b"][..]),
        ("b", &["c"][..]),
        ("c", &["a"][..]),
        ("d", &["a"][..]),
    ]
    .into_iter()
    .map(|(m, to)| (m.to_owned(), to.iter().map(|s| (*s).to_owned()).collect()))
    .collect();
    assert_eq!(circles(&graph), vec![vec!["a", "b", "c"]]);
}
