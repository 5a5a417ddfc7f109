//! Faults the tests make for real: a full disk and a read-only disk, as small tmpfs mounts.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// A tmpfs mounted for a test, unmounted when dropped.
pub struct Mount(PathBuf);

impl Drop for Mount {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// Mounts a tmpfs with `options` at `at` (needs root); `None`, reported, where mounting is
/// not allowed, unless `KAPAINT_REQUIRE_FAULTS` says these tests must run (CI).
pub fn tmpfs(at: &Path, options: &str) -> Option<Mount> {
    std::fs::create_dir_all(at).expect("mount point");
    let mounted = Command::new("mount")
        .args(["-t", "tmpfs", "-o", options, "tmpfs"])
        .arg(at)
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if mounted {
        return Some(Mount(at.to_path_buf()));
    }
    assert!(
        std::env::var_os("KAPAINT_REQUIRE_FAULTS").is_none(),
        "fault tests must run here, but a tmpfs cannot be mounted"
    );
    eprintln!("SKIPPED: cannot mount a tmpfs (not root?)");
    None
}
