//! The real binary in a real X window (Xvfb), on a fresh `HOME` with no desktop portal, driven
//! with xdotool as a user would: paint a stroke on the UV canvas, save with Ctrl+S, quit with
//! Ctrl+Q, and check the saved project holds the stroke; and the same after `kill -9` and a
//! recovery. Skipped where Xvfb or xdotool are missing, unless `CI` or `KAPAINT_REQUIRE_GPU`
//! is set (CI installs them).

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn have(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Shell functions the scripts share: `start` (launch and wait for the first frame, focus the
/// window), `stroke` (drag across the UV canvas), `save_and_quit` (Ctrl+S, wait for the file,
/// Ctrl+Q, wait for the exit).
const FUNCTIONS: &str = r#"
set -u
bin=$1; project=$2; log=$3
start() {
  : > "$log"
  KAPAINT_LOG_STARTUP=1 "$bin" edit "$project" 2>>"$log" & pid=$!
  for _ in $(seq 1 600); do grep -q "first frame" "$log" && break; sleep 0.1; done
  grep -q "first frame" "$log" || { echo "no first frame"; cat "$log"; kill $pid; exit 3; }
  sleep 1
  # The title names the project: "stroke.kapaint - kapaint".
  win=$(xdotool search --sync --name ' - kapaint$' | head -1)
  xdotool windowfocus --sync "$win" 2>/dev/null || true
}
stroke() {
  # The UV canvas sits right of centre in the 1400x900 window, above the Layers tab.
  xdotool mousemove 890 270 sleep 0.3 mousedown 1 sleep 0.3
  for x in 900 920 940 960 980 1000 1020; do xdotool mousemove $x 300 sleep 0.1; done
  xdotool sleep 0.3 mouseup 1 sleep 0.5
}
save_and_quit() {
  xdotool key --clearmodifiers ctrl+s
  for _ in $(seq 1 300); do [ -f "$project" ] && break; sleep 0.1; done
  [ -f "$project" ] || { echo "nothing saved"; cat "$log"; kill $pid; exit 4; }
  sleep 1
  xdotool key --clearmodifiers ctrl+q
  for _ in $(seq 1 200); do kill -0 $pid 2>/dev/null || break; sleep 0.1; done
  if kill -0 $pid 2>/dev/null; then echo "still running after Ctrl+Q"; kill $pid; exit 5; fi
  wait $pid; code=$?
  cat "$log"
  exit $code
}
"#;

/// Runs `script` (after [`FUNCTIONS`]) under Xvfb with a fresh `HOME` and `env`; returns the
/// project it saved, or `None` where the tools are missing and the test may skip.
fn run_in_window(tag: &str, script: &str, env: &[(&str, &str)]) -> Option<PathBuf> {
    let required =
        std::env::var_os("CI").is_some() || std::env::var_os("KAPAINT_REQUIRE_GPU").is_some();
    if !(have("xvfb-run") && have("xdotool")) {
        assert!(!required, "xvfb-run and xdotool are required here");
        eprintln!("skipped: xvfb-run or xdotool missing");
        return None;
    }
    let dir = std::env::temp_dir().join(format!("kapaint-window-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // A fresh machine: a new HOME with no kapaint folders in it.
    let home = dir.join("home");
    let runtime = dir.join("xdg");
    for d in [&home, &runtime] {
        std::fs::create_dir_all(d).expect("dir");
    }
    let project = dir.join("stroke.kapaint");
    let out = Command::new("xvfb-run")
        .args([
            "-a",
            "-s",
            "-screen 0 1400x900x24",
            "bash",
            "-c",
            &format!("{FUNCTIONS}\n{script}"),
            "_",
        ])
        .arg(Path::new(env!("CARGO_BIN_EXE_kapaint")))
        .arg(&project)
        .arg(dir.join("editor.log"))
        .env("HOME", &home)
        .env_remove("XDG_STATE_HOME")
        .env_remove("XDG_CONFIG_HOME")
        .env("XDG_RUNTIME_DIR", &runtime)
        .env_remove("DBUS_SESSION_BUS_ADDRESS")
        .envs(env.iter().copied())
        .output()
        .expect("xvfb-run");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{text}");
    assert!(text.contains("first frame after"), "{text}");
    Some(project)
}

/// Asserts the saved project holds a stroke, then removes the test's folder.
fn assert_painted(project: &Path, what: &str) {
    let doc = kapaint::model::project::load(project).expect("saved project loads");
    assert!(doc.maps().uniform_texel().is_none(), "{what}");
    if let Some(dir) = project.parent() {
        let _ = std::fs::remove_dir_all(dir);
    }
}

#[test]
fn the_real_window_paints_saves_and_quits() {
    // The title marks the unsaved stroke, and the mark goes with the save.
    let script = r#"
start
stroke
title=$(xdotool getwindowname "$win")
[ "$title" = "stroke.kapaint* - kapaint" ] || { echo "title after the stroke: $title"; exit 7; }
xdotool key --clearmodifiers ctrl+s
for _ in $(seq 1 300); do [ -f "$project" ] && break; sleep 0.1; done
sleep 1
title=$(xdotool getwindowname "$win")
[ "$title" = "stroke.kapaint - kapaint" ] || { echo "title after saving: $title"; exit 8; }
save_and_quit
"#;
    if let Some(project) = run_in_window("save", script, &[]) {
        assert_painted(&project, "the saved project does not hold the stroke");
    }
}

#[test]
fn work_survives_kill_9_through_the_autosave() {
    // The stroke ends before the 4-second autosave falls due and no input follows it: the
    // idle window must wake up by itself to save it.
    let script = r#"
start
stroke
sleep 7
kill -9 $pid; wait $pid 2>/dev/null
[ -f "$project" ] && { echo "the project was saved before the kill"; exit 6; }
start
# The recovery offer is up: Enter recovers, then save and quit.
xdotool key --clearmodifiers Return
sleep 2
save_and_quit
"#;
    if let Some(project) = run_in_window("crash", script, &[("KAPAINT_AUTOSAVE_SECONDS", "4")]) {
        assert_painted(
            &project,
            "the stroke painted before kill -9 was not recovered",
        );
    }
}

#[test]
fn work_painted_after_the_first_save_survives_kill_9() {
    // Untitled work saved once with Ctrl+S, painted again, autosaved, killed: `kapaint edit`
    // on the saved project offers the second stroke back (the copy followed the save).
    let script = r#"
cd "$(dirname "$project")"
project="$PWD/material.kapaint"
: > "$log"
KAPAINT_LOG_STARTUP=1 "$bin" 2>>"$log" & pid=$!
for _ in $(seq 1 600); do grep -q "first frame" "$log" && break; sleep 0.1; done
sleep 1
win=$(xdotool search --sync --name '^untitled - kapaint$' | head -1)
xdotool windowfocus --sync "$win" 2>/dev/null || true
stroke
xdotool key --clearmodifiers ctrl+s
sleep 2
xdotool key --clearmodifiers Return
for _ in $(seq 1 300); do [ -f "$project" ] && break; sleep 0.1; done
[ -f "$project" ] || { echo "nothing saved"; cat "$log"; kill $pid; exit 10; }
sleep 1
cp "$project" first.kapaint
xdotool windowfocus --sync "$win" 2>/dev/null || true
xdotool mousemove 890 380 sleep 0.3 mousedown 1 sleep 0.3
for x in 900 920 940 960 980 1000 1020; do xdotool mousemove $x 400 sleep 0.1; done
xdotool sleep 0.3 mouseup 1 sleep 0.5
sleep 7
kill -9 $pid; wait $pid 2>/dev/null
cmp -s "$project" first.kapaint || { echo "the project changed before the kill"; exit 6; }
start
# The recovery offer is up: Enter recovers, then save and quit.
xdotool key --clearmodifiers Return
sleep 2
save_and_quit
"#;
    if let Some(project) = run_in_window("first-save", script, &[("KAPAINT_AUTOSAVE_SECONDS", "4")])
    {
        let saved = project.with_file_name("material.kapaint");
        let first = kapaint::model::project::load(&project.with_file_name("first.kapaint"))
            .expect("first save loads");
        let last = kapaint::model::project::load(&saved).expect("the recovered project loads");
        let differ = (0..last.maps().height())
            .flat_map(|y| (0..last.maps().width()).map(move |x| (x, y)))
            .filter(|&(x, y)| first.maps().texel(x, y) != last.maps().texel(x, y))
            .count();
        assert!(
            differ > 100,
            "the second stroke was not recovered ({differ} texels differ)"
        );
        assert_painted(&saved, "the recovered project holds the strokes");
    }
}

#[test]
fn untitled_work_is_saved_through_kapaints_own_file_dialog_without_a_portal() {
    // No desktop portal runs here: Ctrl+S on an untitled project must still ask where (in
    // kapaint's own dialog, which starts in the working folder with the name filled in) and
    // save there when Enter is pressed.
    let script = r#"
cd "$(dirname "$project")"
project="$PWD/material.kapaint"
: > "$log"
KAPAINT_LOG_STARTUP=1 "$bin" 2>>"$log" & pid=$!
for _ in $(seq 1 600); do grep -q "first frame" "$log" && break; sleep 0.1; done
sleep 1
win=$(xdotool search --sync --name '^untitled - kapaint$' | head -1)
[ -n "$win" ] || { echo "no untitled window"; kill $pid; exit 9; }
xdotool windowfocus --sync "$win" 2>/dev/null || true
stroke
xdotool key --clearmodifiers ctrl+s
sleep 2
xdotool key --clearmodifiers Return
for _ in $(seq 1 300); do [ -f "$project" ] && break; sleep 0.1; done
[ -f "$project" ] || { echo "Enter in the file dialog saved nothing"; cat "$log"; kill $pid; exit 10; }
sleep 1
title=$(xdotool getwindowname "$win")
[ "$title" = "material.kapaint - kapaint" ] || { echo "title after saving: $title"; exit 11; }
save_and_quit
"#;
    if let Some(project) = run_in_window("untitled", script, &[]) {
        let saved = project.with_file_name("material.kapaint");
        assert_painted(&saved, "the untitled stroke was not saved");
    }
}

#[test]
fn the_real_window_paints_on_a_second_layer() {
    // Ctrl+Shift+N adds "Layer 2" and selects it; the stroke lands there, not on "Layer 1".
    let script = r"
start
xdotool key --clearmodifiers ctrl+shift+n
sleep 0.5
stroke
save_and_quit
";
    if let Some(project) = run_in_window("layer", script, &[]) {
        let doc = kapaint::model::project::load(&project).expect("saved project loads");
        let layers = &doc.stack().layers;
        let names: Vec<&str> = layers.iter().map(|l| l.props.name.as_str()).collect();
        assert_eq!(names, ["Layer 1", "Layer 2"]);
        assert_eq!(layers[0].heap_bytes(), 0, "Layer 1 stays empty");
        assert!(layers[1].heap_bytes() > 0, "the stroke is on Layer 2");
        assert_painted(&project, "the composite shows the stroke");
    }
}
