//! Which process a recovery copy or a project lock belongs to, and whether it still runs.
//!
//! A process is named by its host, its PID and when it started (the kernel's start time in
//! `/proc`, so a PID used again by a later process is not taken for the old one).

use std::path::Path;
use std::sync::OnceLock;

/// A process, as it names its recovery copies and locks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Owner {
    /// The machine (its host name).
    pub host: String,
    /// The process ID.
    pub pid: u32,
    /// When the process started (clock ticks since boot, from `/proc`), or 0 where unknown.
    pub start: u64,
}

impl Owner {
    /// This process.
    pub fn this_process() -> &'static Self {
        static THIS: OnceLock<Owner> = OnceLock::new();
        THIS.get_or_init(|| {
            let pid = std::process::id();
            Self {
                host: host_name(),
                pid,
                start: start_time(pid).unwrap_or(0),
            }
        })
    }

    /// Whether the process still runs: `Some(false)` only when it certainly has ended (this
    /// machine, and no process of that PID started then); `None` where it cannot be told (another
    /// machine, or no `/proc`).
    pub fn running(&self) -> Option<bool> {
        let this = Self::this_process();
        if self.host != this.host {
            return None;
        }
        if self.pid == this.pid && self.start == this.start {
            return Some(true);
        }
        if !Path::new("/proc/self").exists() {
            return None;
        }
        Some(start_time(self.pid).is_some_and(|s| self.start == 0 || s == self.start))
    }

    /// As a file name: `HOST-PID-START` (the host's characters outside `[A-Za-z0-9._]` as `_`).
    pub fn file_name(&self) -> String {
        format!("{}-{}-{}", self.host, self.pid, self.start)
    }

    /// From [`Owner::file_name`].
    pub fn from_file_name(name: &str) -> Option<Self> {
        let mut parts = name.rsplitn(3, '-');
        let start = parts.next()?.parse().ok()?;
        let pid = parts.next()?.parse().ok()?;
        let host = parts.next()?.to_string();
        (!host.is_empty()).then_some(Self { host, pid, start })
    }
}

/// This machine's name, as file names may hold it.
fn host_name() -> String {
    let raw = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .or_else(|| std::env::var("COMPUTERNAME").ok())
        .unwrap_or_else(|| "localhost".into());
    let name: String = raw
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .take(64)
        .collect();
    if name.is_empty() {
        "localhost".into()
    } else {
        name
    }
}

/// When process `pid` started (field 22 of `/proc/PID/stat`), if it runs.
fn start_time(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name, in parentheses, may hold spaces: count fields after its end.
    let rest = &stat[stat.rfind(')')? + 1..];
    rest.split_whitespace().nth(19)?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_runs_and_a_name_round_trips() {
        let this = Owner::this_process();
        assert_eq!(this.running(), Some(true));
        let back = Owner::from_file_name(&this.file_name()).unwrap();
        assert_eq!(&back, this);
        let host = Owner::from_file_name("my-host-12-34").unwrap();
        assert_eq!(
            (host.host.as_str(), host.pid, host.start),
            ("my-host", 12, 34)
        );
        assert!(Owner::from_file_name("nonsense").is_none());
    }

    #[test]
    fn an_ended_process_is_told_from_a_running_one() {
        if !Path::new("/proc/self").exists() {
            eprintln!("SKIPPED: this system has no /proc");
            return;
        }
        let this = Owner::this_process();
        // A PID above the kernel's limit never runs.
        let gone = Owner {
            pid: 4_194_305,
            ..this.clone()
        };
        assert_eq!(gone.running(), Some(false));
        // This PID, but a process that started at another time: the PID was used again.
        let reused = Owner {
            start: this.start + 1,
            ..this.clone()
        };
        assert_eq!(reused.running(), Some(false));
        let elsewhere = Owner {
            host: "another-machine".into(),
            ..gone
        };
        assert_eq!(elsewhere.running(), None);
    }
}
