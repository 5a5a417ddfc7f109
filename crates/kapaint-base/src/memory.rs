//! How much memory the machine can give: big allocations (a benchmark's maps, a decoded
//! image) are checked against it first, so they fail with a clear error instead of an
//! out-of-memory kill.

/// Bytes this process can still allocate: what the system says it can give without swapping
/// (`MemAvailable` of `/proc/meminfo`), less where a limit on the process is nearer (its
/// cgroup's `memory.max`, its address-space limit `ulimit -v`); `None` where none of that is
/// known (other systems).
pub fn available_bytes() -> Option<u64> {
    [
        kib_field("/proc/meminfo", "MemAvailable:"),
        cgroup_room(),
        address_space_room(),
    ]
    .into_iter()
    .flatten()
    .min()
}

/// What this process's cgroup (v2) still allows: `memory.max` less `memory.current`.
fn cgroup_room() -> Option<u64> {
    let cgroup = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = cgroup.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = std::path::Path::new("/sys/fs/cgroup").join(path.trim_start_matches('/'));
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).ok();
    let max: u64 = read("memory.max")?.trim().parse().ok()?;
    let current: u64 = read("memory.current")?.trim().parse().ok()?;
    Some(max.saturating_sub(current))
}

/// What the address-space limit (`ulimit -v`) still allows: the soft limit less the process's
/// virtual size.
fn address_space_room() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let soft: u64 = line
        .trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    Some(soft.saturating_sub(process_bytes("VmSize:")?))
}

/// A size field of this process's `/proc/self/status` in bytes (`"VmRSS:"`, resident now;
/// `"VmHWM:"`, its peak), or `None` where that is not known (other systems). For the memory
/// measurements of examples and benches.
pub fn process_bytes(field: &str) -> Option<u64> {
    kib_field("/proc/self/status", field)
}

/// Field `name` (given in kB) of a `/proc` file, in bytes.
fn kib_field(path: &str, name: &str) -> Option<u64> {
    let text = std::fs::read_to_string(path).ok()?;
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// `Ok` when `bytes` fit in the memory available now (always, where that is not known).
///
/// # Errors
/// A sentence saying what needs how much, and how much there is.
pub fn check_fits(what: &str, bytes: u64) -> Result<(), String> {
    fits_in(what, bytes, available_bytes())
}

/// [`check_fits`] against `available` bytes (`None`: not known, so it fits).
fn fits_in(what: &str, bytes: u64, available: Option<u64>) -> Result<(), String> {
    match available {
        Some(available) if bytes > available => Err(format!(
            "{what} needs about {} of memory, and {} is available",
            human(bytes),
            human(available)
        )),
        _ => Ok(()),
    }
}

/// Bytes as GB or MB with one decimal.
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.1} MB", b / 1e6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_does_not_fit_is_refused_with_both_sizes() {
        let e = fits_in("--size 9000", 3_000_000_000, Some(2_000_000_000)).unwrap_err();
        assert_eq!(
            e,
            "--size 9000 needs about 3.0 GB of memory, and 2.0 GB is available"
        );
        assert!(fits_in("x", 2_000_000_000, Some(2_000_000_000)).is_ok());
        assert!(fits_in("x", u64::MAX, None).is_ok());
    }

    #[test]
    fn this_process_is_resident() {
        if let Some(now) = process_bytes("VmRSS:") {
            assert!(now > 0);
            assert!(process_bytes("VmHWM:").is_some_and(|peak| peak >= now));
        }
        assert_eq!(process_bytes("NoSuchField:"), None);
    }

    #[test]
    fn an_absurd_request_does_not_fit() {
        if available_bytes().is_some() {
            let err = check_fits("the test", u64::MAX).unwrap_err();
            assert!(err.starts_with("the test needs about"), "{err}");
            assert!(check_fits("a byte", 1).is_ok());
        }
        assert_eq!(human(25_800_000_000), "25.8 GB");
    }
}
