//! The `kapaint` binary: everything lives in the library. No arguments opens the editor;
//! `kapaint edit [FILE]` opens it on a project; anything else is the command line
//! (`kapaint --help` lists both).

fn main() {
    let code = if std::env::args_os().len() <= 1 {
        kapaint::crash::install(kapaint::crash::OnPanic::ExitOnMainThread);
        kapaint::ui::run(None)
    } else {
        kapaint::cli::main()
    };
    std::process::exit(code);
}
