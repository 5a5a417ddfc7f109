//! Every kind of preset goes through one loader and lives in one user preset folder: export
//! presets in its `export` folder beside `brushes` and `masks`, `$KAPAINT_EXPORT_PRESET_DIR`
//! still taking precedence where it is set.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};
use std::process::Output;

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-presets-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn export(dir: &Path, preset: &str, env: &[(&str, &Path)]) -> Output {
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"));
    command
        .args(["export", "p.kapaint", "--preset", preset, "--out", "sets"])
        .current_dir(dir)
        .env_remove("KAPAINT_EXPORT_PRESET_DIR")
        .env_remove("KAPAINT_PRESET_DIR");
    for (key, value) in env {
        command.env(key, value);
    }
    command.output().expect("runs")
}

const MINE: &str = "(name: \"mine\", description: \"a user's set\", format: Png16, \
                    layout: Packed, n_bits: 16, include_ka: false)";

#[test]
fn an_export_preset_in_the_user_preset_folder_is_found_as_every_other_kind() {
    let dir = temp("export");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(["new", "--size", "32x32", "--out", "p.kapaint"])
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{o:?}");
    let user = dir.join("user-presets");
    // Not there yet: an unknown preset, exit 2.
    let o = export(&dir, "mine", &[("KAPAINT_PRESET_DIR", &user)]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    std::fs::create_dir_all(user.join("export")).expect("folder");
    std::fs::write(user.join("export/mine.ron"), MINE).expect("preset");
    let o = export(&dir, "mine", &[("KAPAINT_PRESET_DIR", &user)]);
    assert!(o.status.success(), "{o:?}");
    // The explicit folder wins: a malformed preset of that name there is the error.
    let explicit = dir.join("explicit");
    std::fs::create_dir_all(&explicit).expect("folder");
    std::fs::write(explicit.join("mine.ron"), "(").expect("preset");
    let o = export(
        &dir,
        "mine",
        &[
            ("KAPAINT_PRESET_DIR", &user),
            ("KAPAINT_EXPORT_PRESET_DIR", &explicit),
        ],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("mine.ron"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}
