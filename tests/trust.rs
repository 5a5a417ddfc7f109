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
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
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

#[cfg(unix)]
#[test]
fn a_script_that_outgrows_memory_is_refused_with_the_bytes_needed() {
    let dir = scratch("memory");
    let project = dir.join("P.kapaint");
    let o = kapaint(&["new", "--size", "4096", "--out", s(&project)]);
    assert!(o.status.success(), "{o:?}");
    let layer = r#"AddLayer(kind: Paint, name: "G"), Gradient(shape: Linear, start: (0.0, 0.0), end: (4096.0, 4096.0)),"#;
    let script = dir.join("layers.ron");
    std::fs::write(&script, format!("(commands: [{}])", layer.repeat(40))).expect("script");
    let before = std::fs::read(&project).expect("project");
    // A machine with 3 GB for this process: 40 full layers of 4096^2 need far more.
    let o = Command::new("bash")
        .args([
            "-c",
            "ulimit -v 3000000; exec \"$0\" paint \"$1\" --script \"$2\"",
            env!("CARGO_BIN_EXE_kapaint"),
            s(&project),
            s(&script),
        ])
        .output()
        .expect("bash");
    assert_refused(&o, "needs about");
    assert_eq!(
        std::fs::read(&project).expect("project"),
        before,
        "the project changed"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Rewrites `manifest.json` inside a project through `edit`.
fn edit_manifest(path: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    use std::io::{Read as _, Write as _};
    let bytes = std::fs::read(path).expect("read project");
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).expect("zip");
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let mut edit = Some(edit);
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).expect("entry");
        let name = entry.name().expect("entry name").to_string();
        let mut data = Vec::new();
        entry.read_to_end(&mut data).expect("entry bytes");
        if name == "manifest.json"
            && let Some(edit) = edit.take()
        {
            let mut json: serde_json::Value = serde_json::from_slice(&data).expect("json");
            edit(&mut json);
            data = serde_json::to_vec(&json).expect("json out");
        }
        out.start_file(name.as_str(), zip::write::SimpleFileOptions::default())
            .expect("start");
        out.write_all(&data).expect("write");
    }
    let bytes = out.finish().expect("finish").into_inner();
    std::fs::write(path, bytes).expect("write project");
}

#[test]
fn a_project_declaring_more_than_memory_or_one_image_many_times_is_refused_at_once() {
    let dir = scratch("declared");
    let project = dir.join("P.kapaint");
    new_project(&project);
    let script = dir.join("paint.ron");
    std::fs::write(
        &script,
        "(commands: [Stroke(tool: Brush, points: [(pos: (3.0, 3.0), pressure: 1.0), (pos: (60.0, 50.0), pressure: 1.0)])])",
    )
    .expect("script");
    let o = kapaint(&["paint", s(&project), "--script", s(&script)]);
    assert!(o.status.success(), "{o:?}");
    // 256 layers naming the one layer's images.
    let shared = dir.join("shared.kapaint");
    std::fs::copy(&project, &shared).expect("copy");
    edit_manifest(&shared, |m| {
        let layer = m["layers"][0].clone();
        assert!(layer["planes"].is_object(), "{layer}");
        m["layers"] = serde_json::Value::Array(vec![layer; 256]);
    });
    let start = std::time::Instant::now();
    let o = kapaint(&["info", s(&shared)]);
    assert_refused(&o, "more than once");
    assert!(start.elapsed().as_secs() < 10);
    // 256 whole-map layers of 8192^2: far more than any machine here holds.
    let huge = dir.join("huge.kapaint");
    std::fs::copy(&project, &huge).expect("copy");
    edit_manifest(&huge, |m| {
        m["width"] = 8192.into();
        m["height"] = 8192.into();
        let mut layer = m["layers"][0].clone();
        layer["planes"]
            .as_object_mut()
            .expect("planes")
            .remove("tiles");
        let layers: Vec<serde_json::Value> = (0..256)
            .map(|k| {
                let mut l = layer.clone();
                for c in ["kd", "ks", "n", "alpha"] {
                    l["planes"][c] = serde_json::json!({
                        "kind": "image", "file": format!("l{k}_{c}.png"),
                        "encoding": if c == "n" { "png-gray16-half-float-bits" } else { "png-rgb16-unorm-linear" }
                    });
                }
                l
            })
            .collect();
        m["layers"] = serde_json::Value::Array(layers);
    });
    let o = kapaint(&["info", s(&huge)]);
    assert_refused(&o, "needs about");
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn a_write_past_the_file_size_limit_is_one_line_not_a_silent_death() {
    let dir = scratch("fsize");
    let project = dir.join("P.kapaint");
    let o = kapaint(&["new", "--size", "512", "--out", s(&project)]);
    assert!(o.status.success(), "{o:?}");
    let script = dir.join("g.ron");
    std::fs::write(
        &script,
        "(commands: [Gradient(shape: Radial, start: (0.0, 0.0), end: (512.0, 300.0))])",
    )
    .expect("script");
    let before = std::fs::read(&project).expect("project");
    // 20 KiB: the painted project is larger.
    let o = Command::new("bash")
        .args([
            "-c",
            "ulimit -f 20; exec \"$0\" paint \"$1\" --script \"$2\"",
            env!("CARGO_BIN_EXE_kapaint"),
            s(&project),
            s(&script),
        ])
        .output()
        .expect("bash");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{o:?}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("File too large"), "{err}");
    assert_eq!(std::fs::read(&project).expect("project"), before);
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn faults_of_the_input_exit_2() {
    let dir = scratch("input-faults");
    let project = dir.join("P.kapaint");
    new_project(&project);
    // A --set image that is a link looping onto itself.
    let looped = dir.join("wood_BaseColor.png");
    std::os::unix::fs::symlink(&looped, &looped).expect("link");
    let o = kapaint(&[
        "import-pbr",
        "--set",
        s(&looped),
        "--out",
        s(&dir.join("Q.kapaint")),
    ]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    // --out inside a file.
    let file = dir.join("notes.txt");
    std::fs::write(&file, "mine").expect("write");
    let o = kapaint(&["export", s(&project), "--out", s(&file.join("set"))]);
    assert_refused(&o, "is a file");
    // --out a link to nothing.
    let dangling = dir.join("dangling");
    std::os::unix::fs::symlink(dir.join("gone/set"), &dangling).expect("link");
    let o = kapaint(&["export", s(&project), "--out", s(&dangling)]);
    assert_refused(&o, "does not exist");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Without `XDG_RUNTIME_DIR` at all (a service, a container, `env -i`), Mesa's
/// device-select layer printed `error: XDG_RUNTIME_DIR is invalid or not set in the
/// environment.` from every command that made a Vulkan instance: `render` and `export` print
/// nothing there now.
#[test]
fn commands_print_no_runtime_dir_error_without_one() {
    let dir = scratch("no-runtime-dir");
    let project = dir.join("p.kapaint");
    new_project(&project);
    let quiet = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args(args)
            .env_remove("XDG_RUNTIME_DIR")
            .env_remove("NODEVICE_SELECT")
            .output()
            .expect("kapaint runs")
    };
    let out = dir.join("r.png");
    let render = [
        "render",
        "--project",
        s(&project),
        "--model",
        "phong",
        "--view",
        "shaded",
        "--size",
        "32",
        "--out",
        s(&out),
    ];
    let set = dir.join("set");
    let export = ["export", s(&project), "--preset", "ktx2", "--out", s(&set)];
    for args in [&render[..], &export[..]] {
        let o = quiet(args);
        if !o.status.success() && std::env::var_os("KAPAINT_REQUIRE_GPU").is_none() {
            eprintln!("SKIPPED: no GPU adapter here");
            return;
        }
        assert!(o.status.success(), "{args:?}: {o:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!err.contains("XDG_RUNTIME_DIR"), "{args:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_headless_render_prints_nothing_of_the_window_system() {
    let dir = scratch("render-quiet");
    let out = dir.join("r.png");
    let o = Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args([
            "render",
            "--kd",
            "0.5,0.2,0.1",
            "--ks",
            "0.3",
            "--n",
            "40",
            "--model",
            "phong",
            "--view",
            "shaded",
            "--size",
            "64",
            "--out",
            s(&out),
        ])
        .env("XDG_RUNTIME_DIR", dir.join("not-there"))
        .output()
        .expect("kapaint runs");
    if !o.status.success() && std::env::var_os("KAPAINT_REQUIRE_GPU").is_none() {
        eprintln!("SKIPPED: no GPU adapter here");
        return;
    }
    assert!(o.status.success(), "{o:?}");
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_set_preset_carries_the_normal_map_and_help_lists_every_preset() {
    let dir = scratch("normal-sets");
    let bumps = dir.join("bumps.png");
    image::RgbImage::from_fn(32, 16, |x, y| {
        image::Rgb([128 + (x as u8 % 9), 120 + (y as u8 % 7), 250])
    })
    .save(&bumps)
    .expect("png");
    let project = dir.join("P.kapaint");
    let o = kapaint(&[
        "import-pbr",
        "--base-color",
        "0.6,0.4,0.3",
        "--metallic",
        "0",
        "--roughness",
        "0.5",
        "--normal",
        s(&bumps),
        "--size",
        "64",
        "--out",
        s(&project),
    ]);
    assert!(o.status.success(), "{o:?}");
    // Every built-in preset that writes a kapaint set.
    for p in kapaint::export::preset::builtin_sets() {
        let preset = p.name.as_str();
        let out = dir.join(preset);
        let o = kapaint(&["export", s(&project), "--preset", preset, "--out", s(&out)]);
        assert!(o.status.success(), "{preset}: {o:?}");
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("material.json")).expect("manifest"))
                .expect("json");
        // KTX2 sets hold its x and y in a KTX2 file (z rebuilt); the others, as stored.
        let ktx2 = p.format.is_ktx2();
        let file = if ktx2 { "normal.ktx2" } else { "normal.png" };
        assert_eq!(manifest["normal"]["path"], file, "{preset}: {manifest}");
        let size = if ktx2 {
            let bytes = std::fs::read(out.join(file)).expect("normal.ktx2");
            let header = ktx2::Reader::new(&bytes[..]).expect("KTX2").header();
            (header.pixel_width, header.pixel_height)
        } else {
            image::image_dimensions(out.join(file)).expect("normal.png")
        };
        assert_eq!(size, (32, 16), "{preset}");
        // Read back, the set keeps it.
        let back = dir.join(format!("{preset}.kapaint"));
        let o = kapaint(&[
            "import-set",
            s(&out.join("material.json")),
            "--out",
            s(&back),
        ]);
        assert!(o.status.success(), "{preset}: {o:?}");
        let doc = kapaint::model::project::load(&back).expect("loads");
        assert_eq!(
            doc.normal().map(|n| (n.width(), n.height())),
            Some((32, 16))
        );
    }
    let help = kapaint(&["export", "--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    for p in kapaint::export::preset::builtin() {
        assert!(
            text.contains(&p.name),
            "--help does not name {}: {text}",
            p.name
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kapaint info`'s `kd.r` mean.
fn kd_r_mean(project: &Path) -> f64 {
    let o = kapaint(&["info", s(project)]);
    assert!(o.status.success(), "{o:?}");
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    text.lines()
        .find_map(|l| l.strip_prefix("kd.r "))
        .and_then(|rest| rest.split_whitespace().nth(1))
        .and_then(|m| m.parse().ok())
        .unwrap_or_else(|| panic!("no kd.r line in {text}"))
}

fn paint(project: &Path, dir: &Path, commands: &str) -> Output {
    let script = dir.join("script.ron");
    std::fs::write(&script, format!("(commands: [{commands}])")).expect("script");
    kapaint(&["paint", s(project), "--script", s(&script)])
}

/// The teapot unwrapped into a 64^2 project that keeps it.
fn teapot_project(dir: &Path) -> PathBuf {
    let project = dir.join("v3.kapaint");
    let teapot = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/teapot.obj");
    let o = kapaint(&[
        "new",
        "--size",
        "64",
        "--mesh",
        s(&teapot),
        "--unwrap",
        "--out",
        s(&project),
    ]);
    assert!(o.status.success(), "{o:?}");
    project
}

const DIRT: &str = r#"AddLayer(kind: Fill, name: "Dirt"), SetMaskGenerator(Blend(op: Multiply, a: Remap(black: 0.3, white: 0.7, of: Noise(kind: Perlin, scale: 8.0, octaves: 4, seed: 1, space: Object)), b: Facing(axis: Y, black: 0.5, white: 0.9)))"#;

/// A generator mask laid by a script is laid on the project's own mesh, as the editor and
/// `bake` lay it: the same composite whichever command made it, and a script that changes
/// something else (an opacity) recomposites it there, not on nothing.
#[test]
fn generator_masks_are_laid_on_the_projects_mesh_by_every_command() {
    let dir = scratch("generators");
    let project = teapot_project(&dir);
    let base = kd_r_mean(&project);
    let o = paint(&project, &dir, DIRT);
    assert!(o.status.success(), "{o:?}");
    let scripted = kd_r_mean(&project);
    assert!(
        (scripted - base).abs() > 1e-3,
        "the fill shows: {scripted} vs {base}"
    );
    // `bake` lays the masks again with the mesh attached (and keeps the AO bake).
    let o = kapaint(&["bake", s(&project), "--map", "ao", "--rays", "4"]);
    assert!(o.status.success(), "{o:?}");
    let baked = kd_r_mean(&project);
    assert!(
        (scripted - baked).abs() < 1e-6,
        "the script's composite {scripted} differs from the one made on the mesh {baked}"
    );
    // Half the fill's opacity: half its effect, not the fill gone.
    let o = paint(&project, &dir, "SelectLayer(1), SetLayerOpacity(0.5)");
    assert!(o.status.success(), "{o:?}");
    let halved = kd_r_mean(&project);
    let expected = base + (baked - base) * 0.5;
    assert!(
        (halved - expected).abs() < 2e-3,
        "half the fill: {halved}, expected about {expected} (base {base}, full {baked})"
    );
}

/// The stored composite is a cache: a version 4 project whose `kd` was replaced opens with
/// what its layers make, not with the replacement.
#[test]
fn a_stored_composite_with_generator_masks_is_never_taken_as_it_is() {
    use std::io::{Read as _, Write as _};
    let dir = scratch("stale");
    let project = teapot_project(&dir);
    let o = paint(&project, &dir, DIRT);
    assert!(o.status.success(), "{o:?}");
    let right = kd_r_mean(&project);
    // Every entry copied, `kd` made uniform white.
    let bytes = std::fs::read(&project).expect("read");
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).expect("zip");
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).expect("entry");
        let name = entry.name().expect("entry name").to_string();
        let mut data = Vec::new();
        entry.read_to_end(&mut data).expect("entry");
        if name == "manifest.json" {
            let mut json: serde_json::Value = serde_json::from_slice(&data).expect("json");
            assert_eq!(json["version"], 4);
            json["kd"] = serde_json::json!({"kind": "uniform", "value": [65535, 65535, 65535]});
            data = serde_json::to_vec(&json).expect("json");
        }
        out.start_file(name.as_str(), zip::write::SimpleFileOptions::default())
            .expect("start");
        out.write_all(&data).expect("write");
    }
    let edited = dir.join("white.kapaint");
    std::fs::write(&edited, out.finish().expect("finish").into_inner()).expect("write");
    let opened = kd_r_mean(&edited);
    assert!(
        (opened - right).abs() < 1e-6,
        "opened as {opened}, the layers make {right}"
    );
}

/// A generator that reads a bake the project lacks is refused, naming the `kapaint bake`
/// that makes it (it read a flat 0.5 before); unknown fields inside a generator are refused.
#[test]
fn a_generator_never_reads_a_missing_bake_or_unknown_fields() {
    let dir = scratch("missing-bake");
    let project = teapot_project(&dir);
    let before = std::fs::read(&project).expect("read");
    let o = paint(
        &project,
        &dir,
        r#"AddLayer(kind: Fill, name: "Wear"), SetMaskGenerator(Ao(black: 0.2, white: 0.9))"#,
    );
    assert_refused(&o, "kapaint bake");
    let o = paint(
        &project,
        &dir,
        r#"AddLayer(kind: Fill, name: "Wear"), SetMaskGenerator(Noise(kind: Perlin, scale: 8.0, colour: 3))"#,
    );
    assert_refused(&o, "colour");
    assert_eq!(
        std::fs::read(&project).expect("read"),
        before,
        "the project changed"
    );
    // With the bake made first, the same script runs.
    let o = kapaint(&["bake", s(&project), "--map", "ao", "--rays", "4"]);
    assert!(o.status.success(), "{o:?}");
    let o = paint(
        &project,
        &dir,
        r#"AddLayer(kind: Fill, name: "Wear"), SetMaskGenerator(Ao(black: 0.2, white: 0.9))"#,
    );
    assert!(o.status.success(), "{o:?}");
}
