//! A journal's framing: its header, and records written and read as streams with a checksum.
//!
//! A record is `KPRC`, its payload's length (u64, little-endian), the payload, and the
//! payload's CRC-32. The length is written last, once payload and checksum are in the file: a
//! record cut short by a kill has length 0 and is never read as whole. Reading streams the
//! payload (never more than the file holds) and accepts it only when its checksum matches.

use std::fs::File;
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};

/// The journal's first bytes.
pub(super) const JOURNAL_MAGIC: &[u8; 8] = b"KPJRNL02";

/// A record's first bytes.
const RECORD_MAGIC: &[u8; 4] = b"KPRC";

/// Bytes before a record's payload: its magic and length.
pub(super) const RECORD_HEAD: u64 = 12;

/// The smallest payload a record has (its map size and the length of its description).
const MIN_PAYLOAD: u64 = 12;

/// Appends one record at `at` in `file`: `write` streams the payload. The record is on disk
/// when this returns; on failure the file is cut back to `at`.
///
/// # Errors
/// What `write` or the file returns.
pub(super) fn append(
    file: &mut File,
    at: u64,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<u64> {
    let written = append_unchecked(file, at, write);
    if written.is_err() {
        let _ = file.set_len(at);
    }
    written
}

fn append_unchecked(
    file: &mut File,
    at: u64,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<u64> {
    file.seek(SeekFrom::Start(at))?;
    let mut out = BufWriter::with_capacity(1 << 20, &mut *file);
    out.write_all(RECORD_MAGIC)?;
    // The length stays 0 until the rest is written.
    out.write_all(&0_u64.to_le_bytes())?;
    let mut hashing = HashingWriter {
        inner: &mut out,
        hasher: crc32fast::Hasher::new(),
        bytes: 0,
    };
    write(&mut hashing)?;
    let (len, sum) = (hashing.bytes, hashing.hasher.finalize());
    out.write_all(&sum.to_le_bytes())?;
    out.flush()?;
    drop(out);
    file.sync_data()?;
    file.seek(SeekFrom::Start(at + 4))?;
    file.write_all(&len.to_le_bytes())?;
    file.sync_data()?;
    Ok(at + RECORD_HEAD + len + 4)
}

/// A writer that counts and checksums what passes through it.
struct HashingWriter<'a, W: Write> {
    inner: &'a mut W,
    hasher: crc32fast::Hasher,
    bytes: u64,
}

impl<W: Write> Write for HashingWriter<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hasher.update(&buf[..n]);
        self.bytes += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// A record's payload being read: never past its declared length, checksummed as it goes.
pub(super) struct Payload<'a, R: Read> {
    inner: &'a mut R,
    hasher: crc32fast::Hasher,
    left: u64,
}

impl<R: Read> Payload<'_, R> {
    /// Bytes of the payload not read yet: what any count in it must fit in.
    pub(super) fn left(&self) -> u64 {
        self.left
    }
}

impl<R: Read> Read for Payload<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let max = buf
            .len()
            .min(usize::try_from(self.left).unwrap_or(usize::MAX));
        let n = self.inner.read(&mut buf[..max])?;
        self.hasher.update(&buf[..n]);
        self.left -= n as u64;
        Ok(n)
    }
}

/// What reading the next record found.
pub(super) enum Next<T> {
    /// A whole record whose checksum matched, decoded.
    Record(T),
    /// The end of the journal, or a record cut short or damaged: nothing after it is read.
    End,
}

/// Reads the record at the reader's position (which is `at` bytes into a file of `size`
/// bytes): `decode` streams its payload, and its result counts only when the whole payload
/// was read and the checksum matches. A declared length past the end of the file is refused
/// before anything is read.
pub(super) fn read_next<R: Read, T>(
    reader: &mut R,
    at: u64,
    size: u64,
    decode: impl FnOnce(&mut Payload<'_, R>) -> Result<T, String>,
) -> Next<(T, u64)> {
    let mut head = [0_u8; RECORD_HEAD as usize];
    if reader.read_exact(&mut head).is_err() || &head[..4] != RECORD_MAGIC {
        return Next::End;
    }
    let mut len_bytes = [0_u8; 8];
    len_bytes.copy_from_slice(&head[4..]);
    let len = u64::from_le_bytes(len_bytes);
    let room = size.saturating_sub(at + RECORD_HEAD + 4);
    if len < MIN_PAYLOAD || len > room {
        return Next::End;
    }
    let mut payload = Payload {
        inner: reader,
        hasher: crc32fast::Hasher::new(),
        left: len,
    };
    let Ok(decoded) = decode(&mut payload) else {
        return Next::End;
    };
    if payload.left != 0 {
        return Next::End;
    }
    let sum = payload.hasher.finalize();
    let mut stored = [0_u8; 4];
    if reader.read_exact(&mut stored).is_err() || u32::from_le_bytes(stored) != sum {
        return Next::End;
    }
    Next::Record((decoded, at + RECORD_HEAD + len + 4))
}

/// The declared length of the first record after the header, when the journal at `file`
/// holds one that was written whole (its length is set only then): a cheap check that a
/// journal has something to recover, without reading it.
pub(super) fn first_record_len(file: &mut File) -> Option<u64> {
    let size = file.metadata().ok()?.len();
    file.seek(SeekFrom::Start(0)).ok()?;
    let mut head = [0_u8; JOURNAL_MAGIC.len() + RECORD_HEAD as usize];
    file.read_exact(&mut head).ok()?;
    if &head[..8] != JOURNAL_MAGIC || &head[8..12] != RECORD_MAGIC {
        return None;
    }
    let mut len_bytes = [0_u8; 8];
    len_bytes.copy_from_slice(&head[12..20]);
    let len = u64::from_le_bytes(len_bytes);
    let end = JOURNAL_MAGIC.len() as u64 + RECORD_HEAD + len + 4;
    (len >= MIN_PAYLOAD && end <= size).then_some(len)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(tag: &str) -> std::path::PathBuf {
        let p = std::env::temp_dir().join(format!("kapaint-record-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_file(&p);
        p
    }

    fn read_all(path: &std::path::Path) -> Vec<Vec<u8>> {
        let mut f = File::open(path).unwrap();
        let size = f.metadata().unwrap().len();
        let mut out = Vec::new();
        let mut at = 0;
        while let Next::Record((bytes, next)) = read_next(&mut f, at, size, |p| {
            let mut v = Vec::new();
            p.read_to_end(&mut v).map_err(|e| e.to_string())?;
            Ok(v)
        }) {
            out.push(bytes);
            at = next;
        }
        out
    }

    #[test]
    fn records_round_trip_and_a_cut_or_damaged_one_ends_the_journal() {
        let path = temp("frame");
        let mut f = File::create(&path).unwrap();
        let a = vec![7_u8; 40];
        let b: Vec<u8> = (0..5000).map(|i| (i % 251) as u8).collect();
        let end_a = append(&mut f, 0, |w| w.write_all(&a)).unwrap();
        let end_b = append(&mut f, end_a, |w| w.write_all(&b)).unwrap();
        assert_eq!(read_all(&path), vec![a.clone(), b.clone()]);
        // A record whose length was never written (a kill before its end).
        f.seek(SeekFrom::Start(end_a + 4)).unwrap();
        f.write_all(&0_u64.to_le_bytes()).unwrap();
        assert_eq!(read_all(&path), vec![a.clone()]);
        // A flipped byte in the payload.
        let end_b2 = append(&mut f, end_a, |w| w.write_all(&b)).unwrap();
        assert_eq!(end_b2, end_b);
        f.seek(SeekFrom::Start(end_a + 100)).unwrap();
        f.write_all(&[0xff]).unwrap();
        assert_eq!(read_all(&path), vec![a]);
        let _ = std::fs::remove_file(&path);
    }

    #[test]
    fn a_declared_length_past_the_file_is_refused_before_reading() {
        let path = temp("sparse");
        let mut f = File::create(&path).unwrap();
        let end = append(&mut f, 0, |w| w.write_all(&[1_u8; 64])).unwrap();
        // A 2 GiB length on a 96-byte file: nothing is allocated or read for it.
        f.seek(SeekFrom::Start(4)).unwrap();
        f.write_all(&(2_u64 << 30).to_le_bytes()).unwrap();
        let mut reader = File::open(&path).unwrap();
        let mut called = false;
        let next = read_next(&mut reader, 0, end, |_| {
            called = true;
            Ok(())
        });
        assert!(matches!(next, Next::End));
        assert!(!called, "the payload was read");
        let _ = std::fs::remove_file(&path);
    }
}
