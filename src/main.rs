//! The `kapaint` binary: everything lives in the library. No arguments opens the editor;
//! `kapaint edit [FILE]` opens it on a project; anything else is the command line.

fn main() {
    let mut args = std::env::args_os().skip(1);
    let code = match (args.next(), args.next(), args.next()) {
        (None, _, _) => editor(None),
        (Some(cmd), file, None) if cmd == "edit" => editor(file.map(Into::into)),
        _ => {
            kapaint::crash::install(kapaint::crash::OnPanic::Exit);
            kapaint::cli::main()
        }
    };
    std::process::exit(code);
}

/// The editor: a worker's panic is a failed job; only the window's own thread ends the app.
fn editor(path: Option<std::path::PathBuf>) -> i32 {
    kapaint::crash::install(kapaint::crash::OnPanic::ExitOnMainThread);
    kapaint::ui::run(path)
}
