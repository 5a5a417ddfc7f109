//! What a panic looks like to the user: one line on stderr, the full report (message,
//! place, thread, backtrace) in a log file under kapaint's state folder, and exit code
//! [`EXIT_INTERNAL`]. A panic in any thread (a worker, every rayon thread at once) prints one
//! line, never a flood of backtraces.

use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Mutex;

/// Exit code of an internal error (a bug): `EX_SOFTWARE` of the BSD `sysexits` codes.
pub const EXIT_INTERNAL: i32 = 70;

/// What a panic does after it is reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnPanic {
    /// End the process with [`EXIT_INTERNAL`] (the command line: nothing can go on).
    Exit,
    /// End the process only when the main thread panics; a worker's panic unwinds to whoever
    /// joins it (the editor shows it as a failed job and the user's work stays open).
    ExitOnMainThread,
}

/// Serialises reports: the first panic of many at once is reported, the others wait for the
/// exit (or, in the editor, for their turn).
static REPORTING: Mutex<()> = Mutex::new(());

/// Installs the panic hook, and keeps a write past the file-size limit an error.
pub fn install(on_panic: OnPanic) {
    keep_file_size_errors();
    std::panic::set_hook(Box::new(move |info| {
        let guard = REPORTING.lock();
        let thread = std::thread::current();
        let thread_name = thread.name().unwrap_or("unnamed").to_string();
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(no message)".into());
        let place = info
            .location()
            .map_or_else(|| "unknown place".into(), ToString::to_string);
        let backtrace = std::backtrace::Backtrace::force_capture();
        let report = format!(
            "kapaint {} panicked\nthread: {thread_name}\nat: {place}\nmessage: {message}\n\nbacktrace:\n{backtrace}\n",
            env!("CARGO_PKG_VERSION")
        );
        let one_line: String = message.split_whitespace().collect::<Vec<_>>().join(" ");
        let log = write_report(&report);
        let mut stderr = std::io::stderr().lock();
        let _ = match &log {
            Some(path) => writeln!(
                stderr,
                "kapaint: internal error: {one_line} (at {place}; report in {})",
                path.display()
            ),
            None => writeln!(stderr, "kapaint: internal error: {one_line} (at {place})"),
        };
        let _ = stderr.flush();
        let exit = match on_panic {
            OnPanic::Exit => true,
            OnPanic::ExitOnMainThread => thread_name == "main",
        };
        if exit {
            std::process::exit(EXIT_INTERNAL);
        }
        drop(guard);
    }));
}

/// Under `ulimit -f`, a write past the limit raises SIGXFSZ, whose default action ends the
/// process with no word (exit 153). With a handler in place the write fails with `EFBIG`
/// instead, and the save that made it reports it in one line like any other write error.
fn keep_file_size_errors() {
    #[cfg(unix)]
    {
        let seen = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        // Best effort: without it, the default action stays.
        let _ = signal_hook::flag::register(signal_hook::consts::SIGXFSZ, seen);
    }
}

/// Writes the report into `crash-<seconds>-<pid>.log` in the state folder; `None` when it
/// cannot be written (the one line still says what happened).
fn write_report(report: &str) -> Option<PathBuf> {
    let dir = kapaint_model::project::state_dir();
    std::fs::create_dir_all(&dir).ok()?;
    let seconds = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let path = dir.join(format!("crash-{seconds}-{}.log", std::process::id()));
    // Made new: a link planted at the name is never followed.
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&path)
        .ok()?;
    std::io::Write::write_all(&mut file, report.as_bytes()).ok()?;
    Some(path)
}
