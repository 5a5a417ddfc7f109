//! Atomic file writes, used by every save: a crash, a kill or a full disk never leaves a
//! half-written file where the user's file was.
//!
//! A save writes a temporary file beside the target (`.NAME.PID.RANDOM.tmp`), flushes it to
//! disk and renames it over the target. On top of that:
//! - the temporary file is made new (`O_CREAT | O_EXCL`, so never through a link planted at
//!   its name) under a name nobody can guess, by the `tempfile` crate; it is readable by its
//!   owner alone until it takes the target's mode;
//! - a write-protected target is refused, and any other target keeps its permissions (a new
//!   file gets the usual `0666` less the umask);
//! - a symbolic link is written through: its target is replaced, the link stays a link;
//! - temporary files that killed processes left beside the target are removed.

use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_with(path, |file| file.write_all(bytes))
}

/// Writes a file atomically: `write` fills a temporary file in the same directory, which is
/// flushed to disk, renamed over `path`, and the directory flushed. On any failure the
/// temporary file is removed and `path` is untouched.
///
/// # Errors
/// A write-protected target (`PermissionDenied`), or any failure to write, flush or rename.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let path = &through_links(path);
    let existing = std::fs::metadata(path).ok();
    if let Some(meta) = &existing {
        if meta.is_dir() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "is a folder",
            ));
        }
        if meta.permissions().readonly() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::PermissionDenied,
                "the file is write-protected; make it writable or save elsewhere",
            ));
        }
    }
    let dir = parent_dir(path);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    remove_stale(dir, &name);
    let (file, tmp) = temporary_file(dir, &name, existing.is_none())?.into_parts();
    let mut file = BufWriter::with_capacity(1 << 20, file);
    write(&mut file)?;
    let file = file
        .into_inner()
        .map_err(std::io::IntoInnerError::into_error)?;
    if let Some(meta) = &existing {
        // On the open file: a link swapped in at the temporary's name changes nothing.
        file.set_permissions(meta.permissions())?;
    }
    file.sync_all()?;
    drop(file);
    tmp.persist(path).map_err(|e| e.error)?;
    if let Ok(d) = File::open(dir) {
        // Best effort: some file systems cannot sync a directory.
        let _ = d.sync_all();
    }
    Ok(())
}

/// A new temporary file in `dir` for a save to `name`: `.NAME.PID.RANDOM.tmp`, made with
/// `O_EXCL` (a link or file already there is never opened), removed when dropped. A file that
/// is `new` gets `0666` less the umask, as any new file would; a replacement starts owner-only
/// and takes the target's mode once written.
fn temporary_file(dir: &Path, name: &str, new: bool) -> std::io::Result<tempfile::NamedTempFile> {
    let prefix = format!(".{name}.{}.", std::process::id());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp").rand_bytes(10);
    #[cfg(unix)]
    if new {
        use std::os::unix::fs::PermissionsExt as _;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    #[cfg(not(unix))]
    let _ = new;
    builder.tempfile_in(dir)
}

/// A new temporary folder in `dir` for work that becomes `name` (`.NAME.tmp-PID-RANDOM`),
/// made with `mkdir`, which never follows a link; removed on every way out unless kept.
///
/// # Errors
/// A folder that cannot be made.
pub fn temporary_dir(dir: &Path, name: &str, tag: &str) -> std::io::Result<TempPath> {
    let made = tempfile::Builder::new()
        .prefix(&format!(".{name}.{tag}-{}-", std::process::id()))
        .rand_bytes(10)
        .tempdir_in(dir)?;
    Ok(TempPath::new(made.keep()))
}

/// The folder a path is in (`.` for a bare name).
fn parent_dir(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// The file a save to `path` replaces: `path` itself, or, when it is a symbolic link, what
/// it points to (followed through chains of links, dangling or not).
pub fn through_links(path: &Path) -> PathBuf {
    let mut current = path.to_path_buf();
    for _ in 0..40 {
        let is_link = std::fs::symlink_metadata(&current).is_ok_and(|m| m.file_type().is_symlink());
        if !is_link {
            break;
        }
        let Ok(target) = std::fs::read_link(&current) else {
            break;
        };
        current = if target.is_relative() {
            parent_dir(&current).join(target)
        } else {
            target
        };
    }
    current
}

/// Removes the temporary files of earlier saves to `name` in `dir` whose process is gone
/// (a save killed half-way leaves one, as large as the project).
fn remove_stale(dir: &Path, name: &str) {
    remove_stale_with(dir, &format!(".{name}."), ".tmp", |path| {
        let _ = std::fs::remove_file(path);
    });
}

/// Calls `remove` on every entry of `dir` named `PREFIX PID [.RANDOM] SUFFIX` (`-` also
/// parts the PID from the rest) whose process `PID` has ended.
pub fn remove_stale_with(dir: &Path, prefix: &str, suffix: &str, remove: impl Fn(&Path)) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(Result::ok) {
        let file_name = entry.file_name();
        let Some(pid) = file_name
            .to_str()
            .and_then(|n| n.strip_prefix(prefix))
            .and_then(|rest| rest.strip_suffix(suffix))
            .and_then(|rest| rest.split(['.', '-']).next())
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && process_gone(pid) == Some(true) {
            remove(&entry.path());
        }
    }
}

/// Whether process `pid` has ended: `None` where the system cannot tell (no `/proc`).
pub fn process_gone(pid: u32) -> Option<bool> {
    if !Path::new("/proc/self").exists() {
        return None;
    }
    Some(!Path::new(&format!("/proc/{pid}")).exists())
}

/// A temporary file or folder that is removed when dropped, unless kept: every failure
/// path, early returns included, cleans up what it made.
#[derive(Debug)]
pub struct TempPath {
    path: PathBuf,
    armed: bool,
}

impl TempPath {
    /// Takes charge of `path` (a file or a folder, existing or about to be made).
    pub fn new(path: PathBuf) -> Self {
        Self { path, armed: true }
    }

    /// The path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Leaves the path where it is (it was renamed into place).
    pub fn keep(mut self) {
        self.armed = false;
    }
}

impl Drop for TempPath {
    fn drop(&mut self) {
        if self.armed {
            if self.path.is_dir() {
                let _ = std::fs::remove_dir_all(&self.path);
            } else {
                let _ = std::fs::remove_file(&self.path);
            }
        }
    }
}

/// A writer that keeps its first error and from then on accepts everything without writing:
/// a writer on top of it (a zip archive finishing itself when dropped) then ends quietly
/// instead of printing its own failure, and the caller reports the first error, once.
#[derive(Debug)]
pub struct FirstError<W> {
    inner: W,
    error: Option<std::io::Error>,
    /// The position and length as the writer above sees them.
    pos: u64,
    len: u64,
}

impl<W: Write + Seek> FirstError<W> {
    /// Wraps `inner`, which is at its start and empty.
    pub fn new(inner: W) -> Self {
        Self {
            inner,
            error: None,
            pos: 0,
            len: 0,
        }
    }

    /// The first error, if any write, flush or seek failed.
    pub fn take_error(&mut self) -> Option<std::io::Error> {
        self.error.take()
    }
}

impl<W: Write + Seek> Write for FirstError<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = if self.error.is_some() {
            buf.len()
        } else {
            match self.inner.write(buf) {
                Ok(n) => n,
                Err(e) => {
                    self.error = Some(e);
                    buf.len()
                }
            }
        };
        self.pos += n as u64;
        self.len = self.len.max(self.pos);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if self.error.is_none()
            && let Err(e) = self.inner.flush()
        {
            self.error = Some(e);
        }
        Ok(())
    }
}

impl<W: Write + Seek> Seek for FirstError<W> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let target = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
            SeekFrom::End(d) => self.len.checked_add_signed(d),
        };
        let Some(target) = target else {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "seek before the start",
            ));
        };
        if self.error.is_none()
            && let Err(e) = self.inner.seek(SeekFrom::Start(target))
        {
            self.error = Some(e);
        }
        self.pos = target;
        Ok(target)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("kapaint-atomic-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let dir = temp("fail");
        let path = dir.join("f.txt");
        write_atomic(&path, b"first").unwrap();
        let failed = write_atomic_with(&path, |f| {
            f.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"first");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "temporary file left behind"
        );
        write_atomic(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn modes_are_kept_write_protection_is_respected_and_links_are_written_through() {
        use std::os::unix::fs::PermissionsExt as _;
        let dir = temp("modes");
        let path = dir.join("p.kapaint");
        write_atomic(&path, b"one").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&path, b"two").unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640, "the mode is kept");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o444)).unwrap();
        let err = write_atomic(&path, b"three").unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::PermissionDenied);
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
        // A link in another folder: its target changes, the link stays.
        let other = temp("modes-link");
        let link = other.join("link.kapaint");
        std::os::unix::fs::symlink(&path, &link).unwrap();
        write_atomic(&link, b"four").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"four");
        let _ = std::fs::remove_dir_all(&dir);
        let _ = std::fs::remove_dir_all(&other);
    }

    /// The process's umask, from `/proc/self/status`.
    #[cfg(unix)]
    fn umask() -> Option<u32> {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("Umask:"))?;
        u32::from_str_radix(line.trim_start_matches("Umask:").trim(), 8).ok()
    }

    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_the_temporary_name_is_never_followed() {
        use std::os::unix::fs::PermissionsExt as _;
        let dir = temp("planted");
        let victim = dir.join("victim.txt");
        std::fs::write(&victim, b"a stranger's file").unwrap();
        std::fs::set_permissions(&victim, std::fs::Permissions::from_mode(0o600)).unwrap();
        let path = dir.join("p.kapaint");
        // Where earlier builds put the temporary: `.NAME.PID.tmp`.
        let planted = dir.join(format!(".p.kapaint.{}.tmp", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        write_atomic(&path, b"the project").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"a stranger's file");
        let victim_mode = std::fs::metadata(&victim).unwrap().permissions().mode() & 0o777;
        assert_eq!(victim_mode, 0o600, "the stranger's file keeps its mode");
        let meta = std::fs::symlink_metadata(&path).unwrap();
        assert!(
            meta.file_type().is_file(),
            "the project is a file, not a link"
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"the project");
        if let Some(mask) = umask() {
            assert_eq!(
                meta.permissions().mode() & 0o777,
                0o666 & !mask,
                "a new file gets the usual mode"
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn temporaries_of_dead_processes_are_removed() {
        if process_gone(1) != Some(false) {
            eprintln!("SKIPPED: this system does not say which processes run");
            return;
        }
        let dir = temp("stale");
        let path = dir.join("p.kapaint");
        // A PID above the kernel's limit never runs; PID 1 always does.
        let dead = dir.join(".p.kapaint.4194305.x7Gq2Lm0aZ.tmp");
        let alive = dir.join(".p.kapaint.1.Hq8sKx02Lp.tmp");
        let other = dir.join(".q.kapaint.4194305.x7Gq2Lm0aZ.tmp");
        for f in [&dead, &alive, &other] {
            std::fs::write(f, b"half a save").unwrap();
        }
        write_atomic(&path, b"saved").unwrap();
        assert!(!dead.exists(), "a dead process's temporary is removed");
        assert!(alive.exists(), "a running process's save is left alone");
        assert!(other.exists(), "another file's temporaries are left alone");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_first_error_is_kept_and_later_writes_are_quiet() {
        struct Fails(usize);
        impl Write for Fails {
            fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
                if self.0 < buf.len() {
                    return Err(std::io::Error::other("no space left"));
                }
                self.0 -= buf.len();
                Ok(buf.len())
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        impl Seek for Fails {
            fn seek(&mut self, _: SeekFrom) -> std::io::Result<u64> {
                Ok(0)
            }
        }
        let mut w = FirstError::new(Fails(4));
        w.write_all(b"abcd").unwrap();
        w.write_all(b"efgh").unwrap();
        assert_eq!(w.stream_position().unwrap(), 8);
        assert_eq!(w.seek(SeekFrom::End(-2)).unwrap(), 6);
        let err = w.take_error().unwrap();
        assert_eq!(err.to_string(), "no space left");
    }
}
