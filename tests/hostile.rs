//! Bad input, faults and hostile files as a user or an attacker would bring them: every one
//! gets one line of error and a documented exit code, never a panic, a hang or a changed
//! input file.
#![allow(clippy::expect_used)] // Test helpers: a failed expectation is a failed test.

use std::io::{Read as _, Write as _};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-hostile-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// The binary under test (`KAPAINT_TEST_BIN` runs these tests against another build, to see
/// them fail before a fix).
fn bin() -> PathBuf {
    std::env::var_os("KAPAINT_TEST_BIN")
        .map_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_kapaint")), PathBuf::from)
}

fn kapaint_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(bin())
        .args(args)
        .current_dir(dir)
        .env("XDG_STATE_HOME", dir.join("state"))
        .stdin(Stdio::null())
        .output()
        .expect("kapaint runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A failure as the README promises: exit `code`, exactly one line on stderr that mentions
/// `mentions`, nothing on stdout.
fn assert_fails(o: &Output, code: i32, mentions: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "stderr: {err}");
    assert!(
        o.stdout.is_empty(),
        "partial output: {}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert_eq!(err.lines().count(), 1, "not one line: {err:?}");
    assert!(err.ends_with('\n') && !err.ends_with("\n\n"), "{err:?}");
    assert!(
        err.to_lowercase().contains(&mentions.to_lowercase()),
        "stderr {err:?} should mention {mentions:?}"
    );
}

fn assert_ok(o: &Output) {
    assert!(o.status.success(), "failed: {}", stderr(o));
}

/// A fresh 64^2 project in `dir`.
fn new_project(dir: &Path, name: &str) -> PathBuf {
    assert_ok(&kapaint_in(
        dir,
        &["new", "--size", "64", "--out", name, "--force"],
    ));
    dir.join(name)
}

/// Rewrites `manifest.json` inside a project (a zip) through `edit`.
fn edit_project_manifest(path: &Path, mut edit: impl FnMut(&mut serde_json::Value)) {
    let bytes = std::fs::read(path).expect("read project");
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).expect("zip");
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).expect("entry");
        let name = entry.name().expect("entry name").to_string();
        let mut data = Vec::new();
        entry.read_to_end(&mut data).expect("entry bytes");
        if name == "manifest.json" {
            let mut json: serde_json::Value = serde_json::from_slice(&data).expect("json");
            edit(&mut json);
            data = serde_json::to_vec(&json).expect("json out");
        }
        out.start_file(name, zip::write::SimpleFileOptions::default())
            .expect("start");
        out.write_all(&data).expect("write");
    }
    let bytes = out.finish().expect("finish").into_inner();
    std::fs::write(path, bytes).expect("write project");
}

#[test]
fn a_nan_stamp_in_a_script_is_refused_and_the_project_stays_loadable() {
    let dir = temp("nan-stamp");
    let project = new_project(&dir, "d.kapaint");
    let before = std::fs::read(&project).expect("project");
    let stamps = [
        ("(width: 1, height: 1, alpha: [NaN])", "alpha"),
        ("(width: 1, height: 1, alpha: [inf])", "alpha"),
        ("(width: 1, height: 1, alpha: [1e300])", "alpha"),
        ("(width: 1, height: 1, alpha: [-0.5])", "alpha"),
        ("(width: 0, height: 1, alpha: [])", "width"),
        ("(width: 2, height: 2, alpha: [0.5])", "alpha values"),
        ("(width: 4294967295, height: 1, alpha: [0.5])", "width"),
        ("(width: 65536, height: 65536, alpha: [0.5])", "width"),
    ];
    for (stamp, mentions) in stamps {
        let script = dir.join("d.ron");
        std::fs::write(
            &script,
            format!(
                "(commands: [ SetBrush((stamp: Some({stamp}))), Stroke(tool: Brush, points: [(pos: (10, 10), pressure: 1), (pos: (40, 40), pressure: 1)]) ])"
            ),
        )
        .expect("script");
        let o = kapaint_in(&dir, &["paint", "d.kapaint", "--script", "d.ron"]);
        assert_fails(&o, 2, mentions);
        assert_eq!(
            std::fs::read(&project).expect("project"),
            before,
            "a failed paint changed the project ({stamp})"
        );
        assert_ok(&kapaint_in(&dir, &["info", "d.kapaint"]));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_manifest_with_a_bad_brush_is_refused_by_every_command() {
    let dir = temp("manifest-stamp");
    let cases: [(&str, serde_json::Value); 5] = [
        (
            "stamp",
            serde_json::json!({"width": 1, "height": 1, "alpha": [1e300]}),
        ),
        (
            "stamp",
            serde_json::json!({"width": 0, "height": 1, "alpha": []}),
        ),
        (
            "stamp",
            serde_json::json!({"width": 3, "height": 3, "alpha": [0.5]}),
        ),
        (
            "stamp",
            serde_json::json!({"width": 4_294_967_295_u64, "height": 1, "alpha": [0.5]}),
        ),
        ("radius_px", serde_json::json!(null)),
    ];
    for (field, value) in cases {
        let project = new_project(&dir, "p.kapaint");
        edit_project_manifest(&project, |json| {
            json["settings"]["brush"][field] = value.clone();
        });
        for args in [
            vec!["info", "p.kapaint"],
            vec!["export", "p.kapaint", "--out", "set", "--no-padding"],
        ] {
            let o = kapaint_in(&dir, &args);
            assert_fails(&o, 2, "not a valid kapaint project");
            assert!(!dir.join("set").exists());
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A painted project exported with the compact preset: `(dir, material.json)`.
fn exported_set(tag: &str) -> (PathBuf, PathBuf) {
    let dir = temp(tag);
    new_project(&dir, "p.kapaint");
    std::fs::write(
        dir.join("s.ron"),
        "(commands: [ SetPrimary((kd: (0.9, 0.2, 0.1), ks: (0.5, 0.5, 0.5), n: 900)), Stroke(tool: Brush, points: [(pos: (5, 5), pressure: 1), (pos: (60, 50), pressure: 1)]) ])",
    )
    .expect("script");
    assert_ok(&kapaint_in(
        &dir,
        &["paint", "p.kapaint", "--script", "s.ron"],
    ));
    assert_ok(&kapaint_in(
        &dir,
        &["export", "p.kapaint", "--out", "set", "--no-padding"],
    ));
    let manifest = dir.join("set/material.json");
    (dir, manifest)
}

fn edit_json(path: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(path).expect("read")).expect("json");
    edit(&mut json);
    std::fs::write(path, serde_json::to_vec_pretty(&json).expect("json")).expect("write");
}

/// A change to a manifest.
type JsonEdit = Box<dyn Fn(&mut serde_json::Value)>;

#[test]
fn import_set_refuses_every_bad_manifest_field_in_one_line() {
    let (dir, manifest) = exported_set("import-set");
    let original = std::fs::read(&manifest).expect("manifest");
    let mut cases: Vec<(&str, JsonEdit, &str)> = Vec::new();
    for bits in [0, 1, 7, 9, 15, 17, 31, 32, 40, 255] {
        cases.push((
            "bits",
            Box::new(move |m| m["n_encoding"]["bits"] = bits.into()),
            "bits",
        ));
    }
    cases.push((
        "lo",
        Box::new(|m| m["n_encoding"]["lo"] = (-1.0).into()),
        "lo",
    ));
    cases.push((
        "hi",
        Box::new(|m| m["n_encoding"]["hi"] = 1e30.into()),
        "hi",
    ));
    cases.push((
        "curve",
        Box::new(|m| m["n_encoding"]["curve"] = "cubic".into()),
        "cubic",
    ));
    cases.push((
        "approximation",
        Box::new(|m| m["approximation"]["name"] = "magic".into()),
        "magic",
    ));
    cases.push((
        "colour space",
        Box::new(|m| m["files"][0]["colour_space"] = "cmyk".into()),
        "colour_space",
    ));
    cases.push((
        "empty layout",
        Box::new(|m| m["files"][0]["layout"] = serde_json::json!([])),
        "layout",
    ));
    cases.push((
        "no files",
        Box::new(|m| m["files"] = serde_json::json!([])),
        "neither a constant nor stored",
    ));
    cases.push((
        "escape",
        Box::new(|m| m["files"][0]["path"] = "../../etc/passwd".into()),
        "plain name",
    ));
    cases.push((
        "absolute",
        Box::new(|m| m["files"][0]["path"] = "/etc/passwd".into()),
        "plain name",
    ));
    cases.push(("size", Box::new(|m| m["width"] = 100_000.into()), "size"));
    cases.push((
        "file size",
        Box::new(|m| m["files"][0]["width"] = 7.into()),
        "listed as",
    ));
    cases.push((
        "depth",
        Box::new(|m| m["files"][0]["bit_depth"] = 12.into()),
        "bit_depth",
    ));
    cases.push((
        "constant",
        Box::new(|m| m["constants"]["ks"] = serde_json::json!([2.0, 0.0, 0.0])),
        "constants.ks",
    ));
    cases.push(("version", Box::new(|m| m["version"] = 0.into()), "version"));
    for (what, edit, mentions) in &cases {
        std::fs::write(&manifest, &original).expect("restore");
        edit_json(&manifest, edit);
        let o = kapaint_in(
            &dir,
            &["import-set", "set/material.json", "--out", "back.kapaint"],
        );
        assert_fails(&o, 2, mentions);
        assert!(
            !dir.join("back.kapaint").exists(),
            "{what}: wrote a project"
        );
    }
    std::fs::write(&manifest, &original).expect("restore");
    assert_ok(&kapaint_in(
        &dir,
        &["import-set", "set/material.json", "--out", "back.kapaint"],
    ));
    eprintln!("import-set: {} bad manifests refused", cases.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn accuracy_points_are_bounded() {
    let dir = temp("accuracy");
    for points in ["18446744073709551615", "4294967296", "257", "1"] {
        let o = kapaint_in(&dir, &["accuracy", "--points", points]);
        assert_fails(&o, 2, "--points must be 2 to 256");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_panic_is_one_line_a_report_file_and_exit_70() {
    let dir = temp("panic");
    for args in [vec!["debug-panic"], vec!["debug-panic", "--workers"]] {
        let _ = std::fs::remove_dir_all(dir.join("state"));
        let o = kapaint_in(&dir, &args);
        assert_fails(&o, 70, "internal error: deliberate panic");
        let reports: Vec<PathBuf> = std::fs::read_dir(dir.join("state/kapaint"))
            .expect("state folder")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.to_string_lossy().contains("crash-"))
            .collect();
        assert_eq!(reports.len(), 1, "{reports:?}");
        let report = std::fs::read_to_string(&reports[0]).expect("report");
        assert!(report.contains("deliberate panic") && report.contains("backtrace"));
        assert!(stderr(&o).contains(&reports[0].display().to_string()));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn stdin_values_are_checked_as_arguments_are() {
    let mut child = Command::new(bin())
        .args(["chi", "--model", "phong", "--method", "exact", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("kapaint starts");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(b"2e6\n")
        .expect("write");
    let o = child.wait_with_output().expect("kapaint ends");
    assert_fails(&o, 2, "limit");
}

#[test]
fn bench_refuses_sizes_the_machine_cannot_hold() {
    let Some(available) = kapaint::memory::available_bytes() else {
        eprintln!("SKIPPED: this system does not say how much memory is available");
        return;
    };
    // The smallest size the machine cannot hold (16384 is the largest the bench takes).
    let Some(size) = (16..=16384_usize)
        .step_by(16)
        .find(|&s| kapaint::report::bench::bytes_needed(s) > available)
    else {
        eprintln!("SKIPPED: this machine holds even a 16384^2 bench");
        return;
    };
    let dir = temp("bench");
    let o = kapaint_in(&dir, &["bench", "--size", &size.to_string()]);
    assert_fails(&o, 2, "memory");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn argument_errors_are_one_line_naming_what_is_missing() {
    let dir = temp("clap");
    let o = kapaint_in(&dir, &["new", "--size", "64"]);
    assert_fails(&o, 2, "--out");
    let o = kapaint_in(&dir, &["frobnicate"]);
    assert_fails(&o, 2, "frobnicate");
    let _ = std::fs::remove_dir_all(&dir);
}
