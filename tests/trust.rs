//! Ordinary flows that must never lose work, from the command line: `export --replace` removes
//! only what an export wrote, two `paint` runs on one project keep both edits, and a document
//! stays saveable whatever its commands did.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn kapaint(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .output()
        .expect("kapaint runs")
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-trust-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn new_project(path: &Path) {
    let o = kapaint(&["new", "--size", "64", "--out", s(path)]);
    assert!(o.status.success(), "{o:?}");
}

/// Asserts exit 2 with one line on stderr mentioning `mentions`.
fn assert_refused(o: &Output, mentions: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains(mentions),
        "{err:?} should mention {mentions:?}"
    );
}

/// Every file under `dir`, relative, sorted.
fn files_under(dir: &Path) -> Vec<String> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(p.strip_prefix(base).expect("under").display().to_string());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

#[test]
fn export_replace_never_removes_what_no_export_wrote() {
    let dir = scratch("replace");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).expect("folder");
    // The project inside the folder it exports to, beside a material.json.
    let project = out.join("P.kapaint");
    new_project(&project);
    let elsewhere = dir.join("set");
    let o = kapaint(&["export", s(&project), "--out", s(&elsewhere)]);
    assert!(o.status.success(), "{o:?}");
    std::fs::copy(elsewhere.join("material.json"), out.join("material.json")).expect("copy");
    let o = kapaint(&["export", s(&project), "--out", s(&out), "--replace"]);
    assert_refused(&o, "holds the project");
    assert!(project.exists(), "the project was removed");
    // A folder of the artist's own files with a material.json among them.
    let theirs = dir.join("theirs");
    std::fs::create_dir_all(theirs.join("textures")).expect("folder");
    std::fs::copy(
        elsewhere.join("material.json"),
        theirs.join("material.json"),
    )
    .expect("copy");
    std::fs::write(theirs.join("notes.txt"), "mine").expect("write");
    std::fs::write(theirs.join("textures/wood.psd"), "mine").expect("write");
    let before = files_under(&theirs);
    let o = kapaint(&["export", s(&project), "--out", s(&theirs), "--replace"]);
    assert_refused(&o, "notes.txt");
    assert_eq!(files_under(&theirs), before, "files were touched");
    // A set of another kind is not replaced either.
    let pbr = dir.join("pbr");
    let o = kapaint(&[
        "export",
        s(&project),
        "--out",
        s(&pbr),
        "--preset",
        "gltf-pbr",
    ]);
    assert!(o.status.success(), "{o:?}");
    let o = kapaint(&["export", s(&project), "--out", s(&pbr), "--replace"]);
    assert_refused(&o, "not a kapaint-material set");
    // A set holding only what its export wrote is replaced.
    let o = kapaint(&["export", s(&project), "--out", s(&elsewhere), "--replace"]);
    assert!(o.status.success(), "{o:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn export_replace_through_a_linked_set_folder_keeps_the_link() {
    let dir = scratch("replace-link");
    let project = dir.join("P.kapaint");
    new_project(&project);
    let real = dir.join("real");
    let o = kapaint(&["export", s(&project), "--out", s(&real)]);
    assert!(o.status.success(), "{o:?}");
    let link = dir.join("link");
    std::os::unix::fs::symlink(&real, &link).expect("link");
    let o = kapaint(&["export", s(&project), "--out", s(&link), "--replace"]);
    assert!(o.status.success(), "{o:?}");
    let meta = std::fs::symlink_metadata(&link).expect("link");
    assert!(meta.file_type().is_symlink(), "the link became a folder");
    assert!(
        real.join("material.json").is_file(),
        "the set is where the link points"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The layer names of a project.
fn layer_names(path: &Path) -> Vec<String> {
    let doc = kapaint::model::project::load(path).expect("project loads");
    doc.stack()
        .walk()
        .into_iter()
        .map(|(_, l)| l.props.name.clone())
        .collect()
}

#[test]
fn two_paint_runs_on_one_project_keep_both_edits() {
    let dir = scratch("two-paints");
    let project = dir.join("P.kapaint");
    // Long enough scripts that the two runs overlap.
    let mut strokes = String::new();
    for k in 0..60 {
        let y = 20 + (k * 13) % 980;
        let _ = writeln!(
            strokes,
            "Stroke(tool: Brush, points: [(pos: (10.0, {y}.0), pressure: 1.0), (pos: (1000.0, {y}.0), pressure: 1.0)]),"
        );
    }
    let script = |name: &str| {
        let path = dir.join(format!("{name}.ron"));
        let text = format!(
            "(commands: [AddLayer(kind: Paint, name: \"{name}\"), SetBrush((radius_px: 30.0)), {strokes}])"
        );
        std::fs::write(&path, text).expect("script");
        path
    };
    let (a, b) = (script("A"), script("B"));
    for round in 0..10 {
        let _ = std::fs::remove_file(&project);
        let o = kapaint(&["new", "--size", "1024", "--out", s(&project)]);
        assert!(o.status.success(), "{o:?}");
        let run = |script: &Path| {
            Command::new(env!("CARGO_BIN_EXE_kapaint"))
                .args(["paint", s(&project), "--script", s(script)])
                .spawn()
                .expect("paint starts")
        };
        let (ra, rb) = (run(&a), run(&b));
        let (oa, ob) = (
            ra.wait_with_output().expect("A ends"),
            rb.wait_with_output().expect("B ends"),
        );
        for o in [&oa, &ob] {
            assert!(
                matches!(o.status.code(), Some(0 | 1)),
                "round {round}: {o:?}"
            );
        }
        // Every edit is in the project or in a conflict copy beside it.
        let mut names = layer_names(&project);
        for e in std::fs::read_dir(&dir).expect("folder").flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with("P.kapaint.conflict-") {
                names.extend(layer_names(&e.path()));
                std::fs::remove_file(e.path()).expect("remove");
            }
        }
        assert!(
            names.contains(&"A".into()) && names.contains(&"B".into()),
            "round {round}: an edit was lost: {names:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn duplicating_a_layer_never_makes_the_project_unsaveable() {
    let dir = scratch("names");
    let project = dir.join("P.kapaint");
    new_project(&project);
    let long = "n".repeat(1020);
    let script = dir.join("dup.ron");
    let dups = "DuplicateLayer, ".repeat(204);
    std::fs::write(
        &script,
        format!("(commands: [RenameLayer(\"{long}\"), DuplicateLayer, SelectLayer(0), RenameLayer(\"Layer 1\"), {dups}])"),
    )
    .expect("script");
    let o = kapaint(&["paint", s(&project), "--script", s(&script)]);
    assert!(o.status.success(), "{o:?}");
    let names = layer_names(&project);
    assert_eq!(names.len(), 206);
    for name in &names {
        assert!(name.len() <= 1024, "{} bytes", name.len());
    }
    let long_copy = names.last().expect("layers");
    assert!(long_copy.ends_with(" copy") && long_copy.starts_with("nnn"));
    assert!(names[names.len() - 2].ends_with(" copy"));
    let _ = std::fs::remove_dir_all(&dir);
}
