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

/// When process `pid` started (field 22 of `/proc/PID/stat`), if it runs. A process that has
/// ended but not yet been waited for (a zombie, state `Z`, or `X` while it goes) runs no more:
/// a killed editor whose parent has not reaped it holds nothing.
fn start_time(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    start_time_of(&stat)
}

/// [`start_time`] from the text of a `/proc/PID/stat`.
fn start_time_of(stat: &str) -> Option<u64> {
    // The command name, in parentheses, may hold spaces: count fields after its end.
    let mut rest = stat[stat.rfind(')')? + 1..].split_whitespace();
    if matches!(rest.next()?, "Z" | "X" | "x") {
        return None;
    }
    rest.nth(18)?.parse().ok()
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

    /// A killed process that its parent has not yet waited for (a killed editor under a
    /// launcher that does not reap it) runs no more: its locks and copies are free.
    #[test]
    fn a_killed_process_not_yet_reaped_has_ended() {
        if !Path::new("/proc/self").exists() {
            eprintln!("SKIPPED: this system has no /proc");
            return;
        }
        let Ok(mut child) = std::process::Command::new("sleep").arg("60").spawn() else {
            eprintln!("SKIPPED: no sleep to run");
            return;
        };
        let owner = Owner {
            pid: child.id(),
            start: start_time(child.id()).unwrap_or(0),
            ..Owner::this_process().clone()
        };
        assert_eq!(owner.running(), Some(true));
        child.kill().unwrap();
        // Not waited for: a zombie until the wait below.
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
        while owner.running() != Some(false) && std::time::Instant::now() < deadline {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        assert_eq!(owner.running(), Some(false), "a zombie runs no more");
        child.wait().unwrap();
    }

    #[test]
    fn a_zombie_has_ended() {
        let stat = |state: &str| {
            format!(
                "4242 (kapaint (edit)) {state} 1 4242 4242 0 -1 4194560 100 0 0 0 5 2 0 0 20 0 \
                 9 0 123456 1000 100"
            )
        };
        assert_eq!(start_time_of(&stat("S")), Some(123_456));
        assert_eq!(start_time_of(&stat("R")), Some(123_456));
        for ended in ["Z", "X"] {
            assert_eq!(start_time_of(&stat(ended)), None, "{ended}");
        }
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
