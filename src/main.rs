//! The `kapaint` binary: everything lives in the library. No arguments opens the editor;
//! `kapaint edit [FILE]` opens it on a project; anything else is the command line
//! (`kapaint --help` lists both).

fn main() {
    #[cfg(target_os = "linux")]
    quiet_device_select();
    let code = if std::env::args_os().len() <= 1 {
        kapaint::crash::install(kapaint::crash::OnPanic::ExitOnMainThread);
        kapaint::ui::run(None)
    } else {
        kapaint::cli::main()
    };
    std::process::exit(code);
}

/// Mesa's device-select layer, an implicit Vulkan layer that only orders the GPUs, connects
/// to Wayland whenever a Vulkan instance is made, and without a usable `XDG_RUNTIME_DIR`
/// libwayland prints `error: XDG_RUNTIME_DIR is invalid or not set in the environment.` on
/// stderr (once per instance: `render`, `export`, the editor), an error that is none.
/// kapaint picks its adapter itself, so where that folder is missing the layer is switched
/// off (`NODEVICE_SELECT=1`, which Mesa reads) for this process, by starting it again with
/// that one variable added: the environment is set before anything runs, with no threads to
/// race. Real errors still print: the layer reports nothing else, and the Vulkan loader,
/// drivers and wgpu are as before. A user's own `NODEVICE_SELECT` is left as it is.
#[cfg(target_os = "linux")]
fn quiet_device_select() {
    use std::os::unix::process::CommandExt;
    let runtime_dir_usable = std::env::var_os("XDG_RUNTIME_DIR")
        .filter(|d| !d.is_empty())
        .is_some_and(|d| std::path::Path::new(&d).is_dir());
    if runtime_dir_usable || std::env::var_os("NODEVICE_SELECT").is_some() {
        return;
    }
    let Ok(exe) = std::env::current_exe() else {
        return;
    };
    // Only returns if the program could not be started again: then it runs as it is.
    let _ = std::process::Command::new(exe)
        .args(std::env::args_os().skip(1))
        .env("NODEVICE_SELECT", "1")
        .exec();
}
