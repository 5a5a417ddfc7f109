//! Bad input, faults and hostile files as a user or an attacker would bring them: every one
//! gets one line of error and a documented exit code, never a panic, a hang or a changed
//! input file.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::fmt::Write as _;
use std::io::{Read as _, Write as _};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

#[path = "common/encode.rs"]
mod encode;
#[path = "common/faults.rs"]
mod faults;
use faults::tmpfs;

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-hostile-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// The binary under test (`KAPAINT_TEST_BIN` runs these tests against another build, to see
/// them fail before a fix).
fn bin() -> PathBuf {
    std::env::var_os("KAPAINT_TEST_BIN").map_or_else(
        || PathBuf::from(env!("CARGO_BIN_EXE_kapaint")),
        PathBuf::from,
    )
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

/// A failure as docs/cli.md promises: exit `code`, exactly one line on stderr that mentions
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

/// A failed command left the file as it was.
fn assert_unchanged(path: &Path, before: &[u8]) {
    assert_eq!(
        std::fs::read(path).expect("the file is still there"),
        before,
        "{} changed",
        path.display()
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

/// One triangle with UVs, as an OBJ file.
const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";

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
    // The smallest size the machine cannot hold with a fifth to spare (16384 is the largest
    // the bench takes): memory other processes free between this look and kapaint's must not
    // let a bench just past the edge start (it did once, and ran a 25 GB bench).
    let Some(size) = (16..=16384_usize)
        .step_by(16)
        .find(|&s| kapaint::report::bench::bytes_needed(s) as f64 > 1.2 * available as f64)
    else {
        eprintln!("SKIPPED: this machine holds a 16384^2 bench, or nearly");
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

#[test]
fn the_documented_script_and_its_command_names_run() {
    let dir = temp("documented-script");
    let docs = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/cli.md"))
        .expect("docs/cli.md");
    let script = docs
        .split("```ron\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("docs/cli.md has a RON script");
    std::fs::write(dir.join("readme.ron"), script).expect("script");
    assert_ok(&kapaint_in(
        &dir,
        &["new", "--size", "1024", "--out", "p.kapaint"],
    ));
    assert_ok(&kapaint_in(
        &dir,
        &["paint", "p.kapaint", "--script", "readme.ron"],
    ));
    for (command, model, method) in [
        ("SetModel(BlinnPhong)", "blinn", "fast"),
        ("SetModel(Phong)", "phong", "fast"),
        ("SetModel(blinn)", "blinn", "fast"),
        ("SetApprox(PaperCorrected)", "blinn", "paper-corrected"),
        ("SetApprox(PaperPrinted)", "blinn", "paper"),
        ("SetApprox(Fast)", "blinn", "fast"),
    ] {
        std::fs::write(dir.join("m.ron"), format!("(commands: [ {command} ])")).expect("script");
        assert_ok(&kapaint_in(
            &dir,
            &["paint", "p.kapaint", "--script", "m.ron"],
        ));
        let info = kapaint_in(&dir, &["info", "p.kapaint"]);
        let text = String::from_utf8_lossy(&info.stdout);
        assert!(
            text.contains(&format!("model: {model}\n"))
                && text.contains(&format!("method: {method}\n")),
            "{command}: {text}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs kapaint and fails the test when it has not ended after `seconds` (a hang).
fn kapaint_within(dir: &Path, args: &[&str], seconds: u64) -> Output {
    let out = dir.join(".out");
    let err = dir.join(".err");
    let mut child = Command::new(bin())
        .args(args)
        .current_dir(dir)
        .env("XDG_STATE_HOME", dir.join("state"))
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out).expect("stdout file"))
        .stderr(std::fs::File::create(&err).expect("stderr file"))
        .spawn()
        .expect("kapaint starts");
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if start.elapsed().as_secs() >= seconds {
            let _ = child.kill();
            let _ = child.wait();
            panic!("kapaint {args:?} hung: still running after {seconds} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    Output {
        status,
        stdout: std::fs::read(&out).expect("stdout"),
        stderr: std::fs::read(&err).expect("stderr"),
    }
}

/// A `.gltf` whose one buffer is `uri`, holding one triangle, instantiated by `nodes`.
fn gltf_text(uri: &str, nodes: &str, scene_nodes: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{scene_nodes}}}],"nodes":{nodes},
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"buffers":[{{"uri":"{uri}","byteLength":36}}]}}"#
    )
}

/// One triangle's positions as a base64 data URI.
fn triangle_uri() -> String {
    let floats: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    format!(
        "data:application/octet-stream;base64,{}",
        encode::base64(&bytes)
    )
}

#[test]
fn a_gltf_reusing_nodes_is_counted_before_it_is_expanded() {
    let dir = temp("gltf-graph");
    // 40 nodes, each listing the next twice; the last holds the mesh: 2^40 instances.
    let nodes: Vec<String> = (0..40)
        .map(|i| {
            if i == 39 {
                r#"{"mesh":0}"#.to_string()
            } else {
                format!(r#"{{"children":[{},{}]}}"#, i + 1, i + 1)
            }
        })
        .collect();
    let text = gltf_text(&triangle_uri(), &format!("[{}]", nodes.join(",")), "[0]");
    std::fs::write(dir.join("bomb.gltf"), text).expect("gltf");
    let o = kapaint_within(&dir, &["mesh-info", "bomb.gltf"], 30);
    assert_fails(&o, 2, "instantiates");
    // The same file with a sane graph loads.
    let sane = gltf_text(&triangle_uri(), r#"[{"mesh":0}]"#, "[0]");
    std::fs::write(dir.join("one.gltf"), sane).expect("gltf");
    assert_ok(&kapaint_within(&dir, &["mesh-info", "one.gltf"], 30));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn gltf_buffers_stay_in_their_folder_and_within_their_length() {
    let dir = temp("gltf-uri");
    let nodes = r#"[{"mesh":0}]"#;
    let mut bytes = Vec::new();
    for f in [0.0_f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&f.to_le_bytes());
    }
    std::fs::write(dir.join("tri.bin"), &bytes).expect("bin");
    std::fs::write(dir.join("ok.gltf"), gltf_text("tri.bin", nodes, "[0]")).expect("gltf");
    assert_ok(&kapaint_within(&dir, &["mesh-info", "ok.gltf"], 30));
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("/dev/zero", dir.join("zero.bin")).expect("link");
        let fifo = dir.join("pipe.bin");
        assert!(
            Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .expect("mkfifo")
                .success()
        );
    }
    for (uri, mentions) in [
        ("/dev/zero", "leaves the glTF's folder"),
        ("../../../../etc/passwd", "leaves the glTF's folder"),
        ("file:///etc/passwd", "no URI schemes"),
        ("%2E%2E/%2E%2E/etc/passwd", "leaves the glTF's folder"),
        ("%FF%FE.bin", "not a valid URI"),
        ("missing.bin", "missing.bin"),
        ("zero.bin", "links outside the glTF's folder"),
        ("pipe.bin", "not a regular file"),
    ] {
        std::fs::write(dir.join("bad.gltf"), gltf_text(uri, nodes, "[0]")).expect("gltf");
        let o = kapaint_within(&dir, &["mesh-info", "bad.gltf"], 30);
        assert_fails(&o, 2, mentions);
    }
    // A buffer file shorter than its byteLength.
    std::fs::write(dir.join("short.bin"), &bytes[..20]).expect("bin");
    std::fs::write(dir.join("bad.gltf"), gltf_text("short.bin", nodes, "[0]")).expect("gltf");
    assert_fails(
        &kapaint_within(&dir, &["mesh-info", "bad.gltf"], 30),
        2,
        "truncated",
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn meshes_never_read_materials_devices_or_fifos() {
    let dir = temp("obj-mtl");
    let obj = TRIANGLE_OBJ;
    let fifo = dir.join("pipe");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo")
            .success()
    );
    for lib in ["/dev/zero", "pipe"] {
        std::fs::write(dir.join("m.obj"), format!("mtllib {lib}\n{obj}")).expect("obj");
        let o = kapaint_within(&dir, &["mesh-info", "m.obj"], 30);
        assert_ok(&o);
        assert!(String::from_utf8_lossy(&o.stdout).contains("triangles: 1"));
    }
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.obj")).expect("link");
    std::os::unix::fs::symlink("pipe", dir.join("pipe.glb")).expect("link");
    for mesh in ["zero.obj", "pipe.glb"] {
        let o = kapaint_within(&dir, &["mesh-info", mesh], 30);
        assert_fails(&o, 2, "not a regular file");
    }
    // A project whose mesh turns into a FIFO: export notes it (no padding), render refuses.
    std::fs::write(dir.join("m.obj"), obj).expect("obj");
    assert_ok(&kapaint_within(
        &dir,
        &[
            "new",
            "--size",
            "64",
            "--mesh",
            "m.obj",
            "--out",
            "p.kapaint",
        ],
        30,
    ));
    std::fs::remove_file(dir.join("m.obj")).expect("rm");
    assert!(
        Command::new("mkfifo")
            .arg(dir.join("m.obj"))
            .status()
            .expect("mkfifo")
            .success()
    );
    let o = kapaint_within(&dir, &["export", "p.kapaint", "--out", "set"], 30);
    assert_ok(&o);
    assert!(String::from_utf8_lossy(&o.stdout).contains("no padding"));
    let o = kapaint_within(
        &dir,
        &[
            "render",
            "--project",
            "p.kapaint",
            "--model",
            "phong",
            "--view",
            "shaded",
            "--out",
            "r.png",
        ],
        30,
    );
    assert_fails(&o, 2, "not a regular file");
    // A project that is itself a FIFO.
    assert!(
        Command::new("mkfifo")
            .arg(dir.join("q.kapaint"))
            .status()
            .expect("mkfifo")
            .success()
    );
    assert_fails(
        &kapaint_within(&dir, &["info", "q.kapaint"], 30),
        2,
        "not a regular file",
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn strokes_a_billion_texels_long_end_with_an_error_not_a_hang() {
    let dir = temp("long-stroke");
    new_project(&dir, "p.kapaint");
    let before = std::fs::read(dir.join("p.kapaint")).expect("project");
    for script in [
        "(commands: [ Stroke(tool: Brush, points: [(pos: (0, 0), pressure: 1), (pos: (1e9, 0), pressure: 1)]) ])",
        "(commands: [ SetBrush((radius_px: 0.5, spacing_percent: 1)), Stroke(tool: Brush, points: [(pos: (0, 0), pressure: 1), (pos: (6e6, 6e6), pressure: 1)]) ])",
    ] {
        std::fs::write(dir.join("s.ron"), script).expect("script");
        let o = kapaint_within(&dir, &["paint", "p.kapaint", "--script", "s.ron"], 60);
        assert_fails(&o, 2, "limit of");
        assert_unchanged(&dir.join("p.kapaint"), &before);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn stacked_uvs_bake_in_the_time_of_their_texels() {
    let dir = temp("stacked-uvs");
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n");
    for _ in 0..10_000 {
        obj.push_str("f 1/1 2/2 3/3\n");
    }
    std::fs::write(dir.join("stack.obj"), obj).expect("obj");
    assert_ok(&kapaint_within(
        &dir,
        &[
            "new",
            "--size",
            "1024",
            "--mesh",
            "stack.obj",
            "--out",
            "p.kapaint",
        ],
        30,
    ));
    // Export bakes the mesh for padding: 25 s before overlapping UVs were settled once.
    let o = kapaint_within(&dir, &["export", "p.kapaint", "--out", "set"], 20);
    assert_ok(&o);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `min mean max` of one channel component in `kapaint info`.
fn info_stat(dir: &Path, project: &str, label: &str) -> [f64; 3] {
    let o = kapaint_in(dir, &["info", project]);
    assert_ok(&o);
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let line = text
        .lines()
        .find(|l| l.split_whitespace().next() == Some(label))
        .unwrap_or_else(|| panic!("no {label} line in {text}"));
    let v: Vec<f64> = line
        .split_whitespace()
        .skip(1)
        .map(|t| t.parse().expect("number"))
        .collect();
    [v[0], v[1], v[2]]
}

#[test]
fn an_exr_of_n_keeps_its_values_when_resized() {
    let dir = temp("exr-n");
    new_project(&dir, "p.kapaint");
    for (side, n) in [(10_u32, 300.0_f32), (64, 300.0), (200, 5000.0)] {
        image::Rgb32FImage::from_pixel(side, side, image::Rgb([n, n, n]))
            .save(dir.join("n.exr"))
            .expect("exr");
        assert_ok(&kapaint_in(
            &dir,
            &["import", "p.kapaint", "--channel", "n", "--image", "n.exr"],
        ));
        for v in info_stat(&dir, "p.kapaint", "n") {
            assert!(
                (v / f64::from(n) - 1.0).abs() < 2e-3,
                "{side}^2 of n = {n}: {v}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn truncated_jpegs_are_refused() {
    let dir = temp("jpeg");
    new_project(&dir, "p.kapaint");
    let spot = image::open(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png"),
    )
    .expect("spot")
    .to_rgb8();
    spot.save(dir.join("whole.jpg")).expect("jpeg");
    let whole = std::fs::read(dir.join("whole.jpg")).expect("jpeg");
    assert_ok(&kapaint_in(
        &dir,
        &[
            "import",
            "p.kapaint",
            "--channel",
            "kd",
            "--image",
            "whole.jpg",
        ],
    ));
    let before = std::fs::read(dir.join("p.kapaint")).expect("project");
    for percent in [10, 50, 90, 99] {
        std::fs::write(dir.join("cut.jpg"), &whole[..whole.len() * percent / 100]).expect("cut");
        let o = kapaint_in(
            &dir,
            &[
                "import",
                "p.kapaint",
                "--channel",
                "kd",
                "--image",
                "cut.jpg",
            ],
        );
        assert_fails(&o, 2, "truncated");
        assert_unchanged(&dir.join("p.kapaint"), &before);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_projects_mesh_is_found_from_any_folder() {
    let dir = temp("mesh-path");
    std::fs::create_dir_all(dir.join("sub")).expect("sub");
    let obj = TRIANGLE_OBJ;
    std::fs::write(dir.join("m.obj"), obj).expect("obj");
    assert_ok(&kapaint_in(
        &dir,
        &[
            "new",
            "--size",
            "64",
            "--mesh",
            "m.obj",
            "--out",
            "sub/p.kapaint",
        ],
    ));
    std::fs::write(
        dir.join("sub/s.ron"),
        "(commands: [ Fill(Island(x: 5, y: 60)) ])",
    )
    .expect("script");
    let sub = dir.join("sub");
    assert_ok(&kapaint_in(
        &sub,
        &["paint", "p.kapaint", "--script", "s.ron"],
    ));
    // The project and its mesh move together.
    std::fs::rename(&dir, dir.with_extension("moved")).expect("move");
    let moved = dir.with_extension("moved");
    assert_ok(&kapaint_in(
        &moved,
        &["paint", "sub/p.kapaint", "--script", "sub/s.ron"],
    ));
    let _ = std::fs::remove_dir_all(&moved);
}

#[test]
fn a_batch_export_checks_every_target_before_writing_any() {
    let dir = temp("batch");
    std::fs::create_dir_all(dir.join("a")).expect("a");
    std::fs::create_dir_all(dir.join("b")).expect("b");
    new_project(&dir, "a/p.kapaint");
    new_project(&dir, "b/p.kapaint");
    let o = kapaint_in(
        &dir,
        &["export", "a/p.kapaint", "b/p.kapaint", "--out", "D"],
    );
    assert_fails(&o, 2, "would both export to");
    assert!(!dir.join("D").exists(), "nothing written");
    new_project(&dir, "c.kapaint");
    std::fs::create_dir_all(dir.join("D/c")).expect("busy");
    std::fs::write(dir.join("D/c/mine.txt"), "mine").expect("busy");
    let o = kapaint_in(&dir, &["export", "a/p.kapaint", "c.kapaint", "--out", "D"]);
    assert_fails(&o, 2, "not an empty folder");
    assert!(!dir.join("D/p").exists(), "nothing written");
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn saves_keep_modes_respect_write_protection_and_follow_links() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = temp("modes");
    let project = new_project(&dir, "p.kapaint");
    std::fs::write(dir.join("s.ron"), "(commands: [ Fill(All) ])").expect("script");
    std::fs::set_permissions(&project, std::fs::Permissions::from_mode(0o444)).expect("chmod");
    let before = std::fs::read(&project).expect("project");
    let o = kapaint_in(&dir, &["paint", "p.kapaint", "--script", "s.ron"]);
    assert_fails(&o, 1, "write-protected");
    assert_eq!(std::fs::read(&project).expect("project"), before);
    let mode = std::fs::metadata(&project)
        .expect("meta")
        .permissions()
        .mode()
        & 0o777;
    assert_eq!(mode, 0o444);
    std::fs::set_permissions(&project, std::fs::Permissions::from_mode(0o640)).expect("chmod");
    assert_ok(&kapaint_in(
        &dir,
        &["paint", "p.kapaint", "--script", "s.ron"],
    ));
    let mode = std::fs::metadata(&project)
        .expect("meta")
        .permissions()
        .mode()
        & 0o777;
    assert_eq!(mode, 0o640, "the mode is kept");
    // Painting through a link changes the linked project; the link stays a link.
    std::fs::create_dir_all(dir.join("links")).expect("links");
    std::os::unix::fs::symlink(&project, dir.join("links/l.kapaint")).expect("link");
    let before = std::fs::read(&project).expect("project");
    std::fs::write(
        dir.join("t.ron"),
        "(commands: [ SetPrimary((kd: (0, 1, 0), ks: (0, 0, 0), n: 2)), Fill(All) ])",
    )
    .expect("script");
    assert_ok(&kapaint_in(
        &dir,
        &["paint", "links/l.kapaint", "--script", "t.ron"],
    ));
    assert!(
        std::fs::symlink_metadata(dir.join("links/l.kapaint"))
            .expect("link")
            .file_type()
            .is_symlink()
    );
    assert_ne!(std::fs::read(&project).expect("project"), before);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_killed_saves_temporary_file_is_removed_by_the_next_save() {
    if !Path::new("/proc/self").exists() {
        eprintln!("SKIPPED: no /proc to tell which processes run");
        return;
    }
    let dir = temp("stale");
    new_project(&dir, "p.kapaint");
    // As a save killed half-way leaves it: PID 4194305 is above every kernel's limit.
    let stale = dir.join(".p.kapaint.4194305.tmp");
    std::fs::write(&stale, vec![7_u8; 1 << 20]).expect("stale");
    std::fs::write(dir.join("s.ron"), "(commands: [ Fill(All) ])").expect("script");
    assert_ok(&kapaint_in(
        &dir,
        &["paint", "p.kapaint", "--script", "s.ron"],
    ));
    assert!(!stale.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A project of noise in k_d and n at 512^2 (about 2 MB, none of it compressible).
fn big_project(dir: &Path) -> PathBuf {
    let mut state = 0x2545_F491_u32;
    let noise = image::RgbImage::from_fn(512, 512, |_, _| {
        let mut px = [0_u8; 3];
        for c in &mut px {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            *c = (state >> 24) as u8;
        }
        image::Rgb(px)
    });
    noise.save(dir.join("noise.png")).expect("noise");
    assert_ok(&kapaint_in(
        dir,
        &["new", "--size", "512", "--out", "big.kapaint", "--force"],
    ));
    for channel in ["kd", "n"] {
        assert_ok(&kapaint_in(
            dir,
            &[
                "import",
                "big.kapaint",
                "--channel",
                channel,
                "--image",
                "noise.png",
            ],
        ));
    }
    let project = dir.join("big.kapaint");
    assert!(std::fs::metadata(&project).expect("meta").len() > 1 << 20);
    project
}

#[test]
fn a_full_disk_is_one_line_exit_1_and_leaves_nothing() {
    let dir = temp("full");
    let Some(mount) = tmpfs(&dir.join("full"), "size=512k") else {
        return;
    };
    big_project(&dir);
    std::fs::write(dir.join("s.ron"), "(commands: [ ])").expect("script");
    for args in [
        vec![
            "paint",
            "big.kapaint",
            "--script",
            "s.ron",
            "--out",
            "full/p.kapaint",
        ],
        vec!["import-set", "set/material.json", "--out", "full/q.kapaint"],
        vec![
            "export",
            "big.kapaint",
            "--out",
            "full/set",
            "--no-padding",
            "--preset",
            "16-bit",
        ],
        vec!["new", "--size", "2048", "--out", "full/n.kapaint"],
    ] {
        if args[0] == "import-set" {
            assert_ok(&kapaint_in(
                &dir,
                &[
                    "export",
                    "big.kapaint",
                    "--out",
                    "set",
                    "--no-padding",
                    "--preset",
                    "16-bit",
                ],
            ));
        }
        let o = kapaint_in(&dir, &args);
        if args[0] == "new" {
            // A uniform project is tiny: it fits.
            assert_ok(&o);
            continue;
        }
        assert_fails(&o, 1, "no space left");
        assert!(!stderr(&o).contains("ZipWriter"), "{}", stderr(&o));
        let left: Vec<_> = std::fs::read_dir(dir.join("full"))
            .expect("mount")
            .filter_map(Result::ok)
            .map(|e| e.file_name())
            .filter(|n| n != "n.kapaint")
            .collect();
        assert!(left.is_empty(), "{args:?} left {left:?}");
    }
    let _ = std::fs::remove_dir_all(dir.join("set"));
    drop(mount);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_read_only_folder_and_a_file_in_the_way_are_clear_errors() {
    let dir = temp("read-only");
    new_project(&dir, "p.kapaint");
    std::fs::write(dir.join("s.ron"), "(commands: [ Fill(All) ])").expect("script");
    std::fs::write(dir.join("a-file"), "x").expect("file");
    let paint_to = |out: &str| {
        kapaint_in(
            &dir,
            &["paint", "p.kapaint", "--script", "s.ron", "--out", out],
        )
    };
    assert_fails(&paint_to("a-file/p.kapaint"), 2, "a-file/p.kapaint");
    let o = kapaint_in(&dir, &["export", "p.kapaint", "--out", "a-file"]);
    assert_fails(&o, 2, "not an empty folder");
    assert_eq!(std::fs::read(dir.join("a-file")).expect("file"), b"x");
    if let Some(_mount) = tmpfs(&dir.join("ro"), "size=1m,ro") {
        assert_fails(&paint_to("ro/p.kapaint"), 1, "read-only");
        let o = kapaint_in(&dir, &["export", "p.kapaint", "--out", "ro/set"]);
        assert_fails(&o, 1, "read-only");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bits packed as deflate packs them: fields from their low bit, Huffman codes from their
/// high bit.
struct Bits {
    bytes: Vec<u8>,
    used: u32,
}

impl Bits {
    fn field(&mut self, value: u32, len: u32) {
        for k in 0..len {
            if self.used == 0 {
                self.bytes.push(0);
            }
            if (value >> k) & 1 == 1 {
                *self.bytes.last_mut().expect("a byte") |= 1 << self.used;
            }
            self.used = (self.used + 1) % 8;
        }
    }

    fn code(&mut self, code: u32, len: u32) {
        for k in (0..len).rev() {
            self.field((code >> k) & 1, 1);
        }
    }
}

/// A PNG of `width x height` black pixels (every sample zero), deflated by hand with the
/// fixed Huffman codes: one zero, then copies of the 258 bytes before, so 2 GB of pixels
/// fit in a 14 MB file, as a decompression bomb would.
fn black_png(width: u32, height: u32, colour_type: u8, bytes_per_pixel: u64) -> Vec<u8> {
    let raw = u64::from(height) * (1 + u64::from(width) * bytes_per_pixel);
    let mut bits = Bits {
        bytes: vec![0x78, 0x01],
        used: 0,
    };
    bits.field(1, 1); // the last block
    bits.field(1, 2); // fixed codes
    bits.code(0x30, 8); // literal 0
    let runs = (raw - 1) / 258;
    for _ in 0..runs {
        bits.code(0xC5, 8); // length 258
        bits.code(0, 5); // distance 1
    }
    for _ in 0..(raw - 1 - runs * 258) {
        bits.code(0x30, 8);
    }
    bits.code(0, 7); // end of block
    let adler = (((raw % 65521) as u32) << 16) | 1;
    let mut idat = bits.bytes;
    idat.extend_from_slice(&adler.to_be_bytes());
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut out = (data.len() as u32).to_be_bytes().to_vec();
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
        out.extend_from_slice(&crc32fast::hash(&[kind, data].concat()).to_be_bytes());
        out
    };
    let mut header = width.to_be_bytes().to_vec();
    header.extend_from_slice(&height.to_be_bytes());
    let depth = if bytes_per_pixel == 8 { 16 } else { 8 };
    header.extend_from_slice(&[depth, colour_type, 0, 0, 0]);
    [
        b"\x89PNG\r\n\x1a\n".to_vec(),
        chunk(b"IHDR", &header),
        chunk(b"IDAT", &idat),
        chunk(b"IEND", &[]),
    ]
    .concat()
}

#[test]
fn importing_a_huge_image_costs_its_decoded_size_not_four_times_it() {
    if !Command::new("prlimit")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
    {
        assert!(
            std::env::var_os("KAPAINT_REQUIRE_FAULTS").is_none(),
            "prlimit is needed here"
        );
        eprintln!("SKIPPED: no prlimit");
        return;
    }
    let dir = temp("huge-image");
    new_project(&dir, "p.kapaint");
    // 16384 x 16383 RGBA16 decodes to 2.0 GiB (was 5.3 GB peak), 16384^2 RGB8 to 0.75 GiB
    // (was 4.0 GB): each must import with its decoded size plus 0.9 GB of address space for
    // everything else.
    for (name, width, height, colour_type, bytes_per_pixel) in [
        ("rgba16.png", 16384, 16383, 6, 8),
        ("rgb8.png", 16384, 16384, 2, 3),
    ] {
        std::fs::write(
            dir.join(name),
            black_png(width, height, colour_type, bytes_per_pixel),
        )
        .expect("png");
        let limit = u64::from(width) * u64::from(height) * bytes_per_pixel + (900 << 20);
        let o = Command::new("prlimit")
            .arg(format!("--data={limit}"))
            .arg("--")
            .arg(bin())
            .args(["import", "p.kapaint", "--channel", "kd", "--image", name])
            .current_dir(&dir)
            .output()
            .expect("prlimit runs");
        assert_ok(&o);
        assert_eq!(
            info_stat(&dir, "p.kapaint", "kd.r"),
            [0.0, 0.0, 0.0],
            "{name}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn autosave_on_a_full_disk_is_an_error_that_leaves_nothing_half_written() {
    use kapaint::model::recovery::{self, Autosaver};
    use kapaint::model::{Document, DocumentSettings};
    use std::time::{Duration, Instant};
    let dir = temp("autosave-full");
    let Some(mount) = tmpfs(&dir.join("full"), "size=256k") else {
        return;
    };
    let project = dir.join("full/p.kapaint");
    // Noise in every channel: a project far larger than the disk.
    let mut doc = Document::new(256, 256, DocumentSettings::default()).expect("doc");
    let noise = dir.join("noise.png");
    let mut state = 0x9E37_79B9_u32;
    image::RgbImage::from_fn(256, 256, |_, _| {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        image::Rgb(state.to_le_bytes()[..3].try_into().expect("three bytes"))
    })
    .save(&noise)
    .expect("noise");
    let mut saver = Autosaver::new(Duration::ZERO, Some(&project), &doc);
    let path = saver.session();
    doc.import_file(kapaint::model::Channel::Kd, &noise)
        .expect("import");
    saver.poll(&doc, Instant::now());
    let err = saver
        .wait()
        .expect("an autosave ran")
        .expect_err("the disk is full");
    assert!(
        err.to_string().to_lowercase().contains("no space left"),
        "{err}"
    );
    assert!(!err.to_string().contains('\n'));
    // Nothing half-written: no journal, and nothing a recovery could mistake for one.
    let left: Vec<_> = std::fs::read_dir(&path)
        .map(|d| d.filter_map(Result::ok).map(|e| e.file_name()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "{left:?}");
    assert!(recovery::load(&path).is_err());
    assert_eq!(recovery::offer(Some(&project)), None);
    drop(mount);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A project whose kept mesh (`mesh.obj`) inflates to far more than the triangles its
/// manifest declares can need is refused by that size, before the entry is read whole or
/// parsed (a 3.9 MB project inflating to 1.4 GB ran out of memory with exit 134).
#[test]
fn a_kept_mesh_that_inflates_past_its_declared_size_is_refused() {
    let dir = temp("inflated-mesh");
    let mesh = dir.join("tri.obj");
    std::fs::write(&mesh, TRIANGLE_OBJ).expect("obj");
    let project = dir.join("p.kapaint");
    assert_ok(&kapaint_in(
        &dir,
        &[
            "new",
            "--size",
            "64",
            "--mesh",
            "tri.obj",
            "--unwrap",
            "--out",
            "p.kapaint",
        ],
    ));
    // The same entries, `mesh.obj` padded with 40 MB of comment lines (a few hundred KB
    // compressed) after its real triangles.
    let bytes = std::fs::read(&project).expect("read project");
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).expect("zip");
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).expect("entry");
        let name = entry.name().expect("entry name").to_string();
        let mut data = Vec::new();
        entry.read_to_end(&mut data).expect("entry bytes");
        if name == "mesh.obj" {
            let line = format!("# {}\n", "x".repeat(1021));
            for _ in 0..40 << 10 {
                data.extend_from_slice(line.as_bytes());
            }
        }
        let deflated = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        out.start_file(name, deflated).expect("start");
        out.write_all(&data).expect("write");
    }
    std::fs::write(&project, out.finish().expect("finish").into_inner()).expect("write");
    assert!(std::fs::metadata(&project).expect("size").len() < 4 << 20);
    let before = std::fs::read(&project).expect("project");
    let o = kapaint_in(&dir, &["info", "p.kapaint"]);
    assert_fails(&o, 2, "mesh.obj");
    assert!(stderr(&o).contains("declares"), "{}", stderr(&o));
    assert_unchanged(&project, &before);
}

/// An octahedron with its own UV triangles, every coordinate times `scale`, as an OBJ.
fn octahedron_obj(scale: f64) -> String {
    let v = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let faces = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let mut out = String::new();
    for p in v {
        let _ = writeln!(
            out,
            "v {:e} {:e} {:e}",
            p[0] * scale,
            p[1] * scale,
            p[2] * scale
        );
    }
    // Each face its own triangle in a 4 x 2 grid of cells.
    for k in 0..8 {
        let (u0, v0) = (f64::from(k % 4) * 0.25, f64::from(k / 4) * 0.5);
        for (du, dv) in [(0.02, 0.02), (0.23, 0.02), (0.02, 0.48)] {
            let _ = writeln!(out, "vt {} {}", u0 + du, v0 + dv);
        }
    }
    for (k, f) in faces.iter().enumerate() {
        let _ = writeln!(
            out,
            "f {}/{} {}/{} {}/{}",
            f[0] + 1,
            3 * k + 1,
            f[1] + 1,
            3 * k + 2,
            f[2] + 1,
            3 * k + 3
        );
    }
    out
}

/// The mean `kapaint bake` prints for `map` of `project`, written to a PNG (the project is
/// left as it is).
fn baked_mean(dir: &Path, project: &str, map: &str) -> f64 {
    let out = format!("{map}.png");
    let o = kapaint_in(
        dir,
        &[
            "bake", project, "--map", map, "--rays", "16", "--out", &out, "--force",
        ],
    );
    assert_ok(&o);
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    text.split(", mean ")
        .nth(1)
        .and_then(|rest| rest.split(',').next())
        .and_then(|m| m.trim().parse().ok())
        .unwrap_or_else(|| panic!("no mean in {text}"))
}

/// A mesh of coordinates like 1e30 (or 1e-20) bakes, renders traced and is measured as at
/// scale 1: the BVH build panicked (exit 70), curvature read 0, and a traced view drew
/// nothing.
#[test]
fn meshes_at_any_scale_bake_and_trace_as_at_scale_one() {
    let dir = temp("any-scale");
    let mut seen: Vec<(f64, [f64; 3], usize)> = Vec::new();
    for scale in [1.0, 1e30, 1e-20] {
        std::fs::write(dir.join("oct.obj"), octahedron_obj(scale)).expect("obj");
        assert_ok(&kapaint_in(
            &dir,
            &[
                "new",
                "--size",
                "64",
                "--mesh",
                "oct.obj",
                "--out",
                "p.kapaint",
                "--force",
            ],
        ));
        let means = ["ao", "thickness", "curvature"].map(|m| baked_mean(&dir, "p.kapaint", m));
        let o = kapaint_in(
            &dir,
            &[
                "render",
                "--project",
                "p.kapaint",
                "--model",
                "phong",
                "--view",
                "ka-traced",
                "--samples",
                "2",
                "--size",
                "48",
                "--out",
                "r.png",
            ],
        );
        assert_ok(&o);
        let image = image::open(dir.join("r.png")).expect("render").to_rgba16();
        let covered = image.pixels().filter(|p| p.0[3] > 0).count();
        seen.push((scale, means, covered));
    }
    let (_, at_one, covered_at_one) = seen[0];
    assert!(covered_at_one > 100, "the octahedron is drawn: {seen:?}");
    for (scale, means, covered) in &seen[1..] {
        for (a, b) in means.iter().zip(at_one) {
            assert!(
                (a - b).abs() < 0.01,
                "scale {scale}: {means:?} vs {at_one:?}"
            );
        }
        assert!(
            covered.abs_diff(covered_at_one) <= covered_at_one / 50,
            "scale {scale}: {covered} pixels drawn, {covered_at_one} at scale 1"
        );
    }
}
