//! The real binary in a real X window (Xvfb): wait for the first frame, paint a stroke on the
//! UV canvas with xdotool, save with Ctrl+S into a temporary project, quit with Ctrl+Q, and
//! check that the saved project holds the stroke. Skipped where Xvfb or xdotool are missing,
//! unless `CI` or `KAPAINT_REQUIRE_GPU` is set (CI installs them).

#![allow(clippy::expect_used)]

use std::path::Path;
use std::process::Command;

fn have(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

const SCRIPT: &str = r#"
set -u
bin=$1; project=$2; log=$3
KAPAINT_LOG_STARTUP=1 "$bin" edit "$project" 2>"$log" & pid=$!
for _ in $(seq 1 600); do grep -q "first frame" "$log" && break; sleep 0.1; done
grep -q "first frame" "$log" || { echo "no first frame"; cat "$log"; kill $pid; exit 3; }
sleep 1
win=$(xdotool search --sync --name '^kapaint$' | head -1)
xdotool windowfocus --sync "$win" 2>/dev/null || true
# The UV canvas sits right of centre in the 1400x900 window.
xdotool mousemove 890 430 sleep 0.3 mousedown 1 sleep 0.3
for x in 900 920 940 960 980 1000 1020; do xdotool mousemove $x 460 sleep 0.1; done
xdotool sleep 0.3 mouseup 1 sleep 0.5
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
"#;

#[test]
fn the_real_window_paints_saves_and_quits() {
    let required =
        std::env::var_os("CI").is_some() || std::env::var_os("KAPAINT_REQUIRE_GPU").is_some();
    if !(have("xvfb-run") && have("xdotool")) {
        assert!(!required, "xvfb-run and xdotool are required here");
        eprintln!("skipped: xvfb-run or xdotool missing");
        return;
    }
    let dir = std::env::temp_dir().join(format!("kapaint-window-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let project = dir.join("stroke.kapaint");
    let log = dir.join("editor.log");
    let bin = Path::new(env!("CARGO_BIN_EXE_kapaint"));
    let runtime = dir.join("xdg");
    std::fs::create_dir_all(&runtime).expect("runtime dir");
    let out = Command::new("xvfb-run")
        .args([
            "-a",
            "-s",
            "-screen 0 1400x900x24",
            "bash",
            "-c",
            SCRIPT,
            "_",
        ])
        .arg(bin)
        .arg(&project)
        .arg(&log)
        .env("XDG_RUNTIME_DIR", &runtime)
        .output()
        .expect("xvfb-run");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{text}");
    assert!(text.contains("first frame after"), "{text}");
    let doc = kapaint::model::project::load(&project).expect("saved project loads");
    assert!(
        doc.maps.uniform_texel().is_none(),
        "the saved project does not hold the stroke"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

const CRASH_SCRIPT: &str = r#"
set -u
bin=$1; project=$2; log=$3
export KAPAINT_AUTOSAVE_SECONDS=2
start() {
  : > "$log"
  KAPAINT_LOG_STARTUP=1 "$bin" edit "$project" 2>>"$log" & pid=$!
  for _ in $(seq 1 600); do grep -q "first frame" "$log" && break; sleep 0.1; done
  grep -q "first frame" "$log" || { echo "no first frame"; cat "$log"; kill $pid; exit 3; }
  sleep 1
  win=$(xdotool search --sync --name '^kapaint$' | head -1)
  xdotool windowfocus --sync "$win" 2>/dev/null || true
}
start
xdotool mousemove 890 430 sleep 0.3 mousedown 1 sleep 0.3
for x in 900 920 940 960 980 1000 1020; do xdotool mousemove $x 460 sleep 0.1; done
xdotool sleep 0.3 mouseup 1
# Two autosave intervals, then the process dies without a chance to save anything.
sleep 5
kill -9 $pid; wait $pid 2>/dev/null
[ -f "$project" ] && { echo "the project was saved before the kill"; exit 6; }
start
# The recovery offer is up: Enter recovers, Ctrl+S saves, Ctrl+Q quits.
xdotool key --clearmodifiers Return
sleep 2
xdotool key --clearmodifiers ctrl+s
for _ in $(seq 1 300); do [ -f "$project" ] && break; sleep 0.1; done
[ -f "$project" ] || { echo "nothing saved after recovery"; cat "$log"; kill $pid; exit 4; }
sleep 1
xdotool key --clearmodifiers ctrl+q
for _ in $(seq 1 200); do kill -0 $pid 2>/dev/null || break; sleep 0.1; done
if kill -0 $pid 2>/dev/null; then echo "still running after Ctrl+Q"; kill $pid; exit 5; fi
wait $pid; code=$?
cat "$log"
exit $code
"#;

#[test]
fn work_survives_kill_9_through_the_autosave() {
    let required =
        std::env::var_os("CI").is_some() || std::env::var_os("KAPAINT_REQUIRE_GPU").is_some();
    if !(have("xvfb-run") && have("xdotool")) {
        assert!(!required, "xvfb-run and xdotool are required here");
        eprintln!("skipped: xvfb-run or xdotool missing");
        return;
    }
    let dir = std::env::temp_dir().join(format!("kapaint-crash-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // A fresh machine: a new HOME with no kapaint folders in it.
    let home = dir.join("home");
    std::fs::create_dir_all(&home).expect("home");
    let project = dir.join("crash.kapaint");
    let log = dir.join("editor.log");
    let runtime = dir.join("xdg");
    std::fs::create_dir_all(&runtime).expect("runtime dir");
    let out = Command::new("xvfb-run")
        .args([
            "-a",
            "-s",
            "-screen 0 1400x900x24",
            "bash",
            "-c",
            CRASH_SCRIPT,
            "_",
        ])
        .arg(Path::new(env!("CARGO_BIN_EXE_kapaint")))
        .arg(&project)
        .arg(&log)
        .env("HOME", &home)
        .env_remove("XDG_STATE_HOME")
        .env_remove("XDG_CONFIG_HOME")
        .env("XDG_RUNTIME_DIR", &runtime)
        .output()
        .expect("xvfb-run");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{text}");
    let doc = kapaint::model::project::load(&project).expect("saved project loads");
    assert!(
        doc.maps.uniform_texel().is_none(),
        "the stroke painted before kill -9 was not recovered"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
