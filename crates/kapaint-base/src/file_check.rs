//! The checks every input file passes before it is read: it is a regular file (not a FIFO
//! that blocks forever, not a device such as `/dev/zero` that never ends, not a folder), and
//! it is no larger than what its reader accepts. Symbolic links are followed, so a link to a
//! regular file is fine and a link to a device is not.

use std::path::Path;

/// Why a file may not be read.
#[derive(Debug, thiserror::Error)]
pub enum FileCheck {
    /// It could not be looked at (missing, no permission, ...).
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// It is not a regular file.
    #[error("is {0}, not a regular file")]
    NotRegular(&'static str),
    /// It is larger than its reader accepts.
    #[error("is {bytes} bytes, more than the {max_bytes} bytes supported")]
    TooLarge {
        /// The file's size.
        bytes: u64,
        /// The limit.
        max_bytes: u64,
    },
}

impl FileCheck {
    /// Whether the failure is the system's (an I/O error other than a missing file) rather
    /// than the input's.
    pub fn is_io(&self) -> bool {
        matches!(self, Self::Io(e) if e.kind() != std::io::ErrorKind::NotFound)
    }
}

/// The size of `path` when it is a regular file of at most `max_bytes`.
///
/// # Errors
/// A file that cannot be looked at, is not a regular file, or is too large.
pub fn regular_file(path: &Path, max_bytes: u64) -> Result<u64, FileCheck> {
    let meta = std::fs::metadata(path)?;
    let kind = meta.file_type();
    if !kind.is_file() {
        return Err(FileCheck::NotRegular(kind_name(kind)));
    }
    if meta.len() > max_bytes {
        return Err(FileCheck::TooLarge {
            bytes: meta.len(),
            max_bytes,
        });
    }
    Ok(meta.len())
}

/// Reads a whole file after [`regular_file`], never more than `max_bytes` even when it grows
/// while it is read.
///
/// # Errors
/// As [`regular_file`], or a read error.
pub fn read_limited(path: &Path, max_bytes: u64) -> Result<Vec<u8>, FileCheck> {
    use std::io::Read as _;
    let len = regular_file(path, max_bytes)?;
    let mut bytes = Vec::with_capacity(len as usize);
    std::fs::File::open(path)?
        .take(max_bytes + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(FileCheck::TooLarge {
            bytes: bytes.len() as u64,
            max_bytes,
        });
    }
    Ok(bytes)
}

fn kind_name(kind: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_of_bounded_size_pass() {
        let dir = std::env::temp_dir().join(format!("kapaint-file-check-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("a.txt");
        std::fs::write(&file, b"12345").unwrap();
        assert_eq!(regular_file(&file, 5).unwrap(), 5);
        assert!(matches!(
            regular_file(&file, 4),
            Err(FileCheck::TooLarge { bytes: 5, .. })
        ));
        assert!(matches!(
            regular_file(&dir, 1 << 20),
            Err(FileCheck::NotRegular(_))
        ));
        #[cfg(unix)]
        {
            let err = regular_file(Path::new("/dev/zero"), 1 << 20).unwrap_err();
            assert!(err.to_string().contains("device"), "{err}");
            let link = dir.join("zero-link");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
            assert!(matches!(
                regular_file(&link, 1 << 20),
                Err(FileCheck::NotRegular(_))
            ));
        }
        let missing = regular_file(&dir.join("missing"), 1).unwrap_err();
        assert!(!missing.is_io(), "a missing file is the input's fault");
        assert_eq!(read_limited(&file, 5).unwrap(), b"12345");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
