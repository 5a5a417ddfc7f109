//! The `kapaint` binary: everything lives in the library. No arguments opens the editor;
//! `kapaint edit [FILE]` opens it on a project; anything else is the command line.

fn main() {
    let mut args = std::env::args_os().skip(1);
    let code = match (args.next(), args.next(), args.next()) {
        (None, _, _) => kapaint::ui::run(None),
        (Some(cmd), file, None) if cmd == "edit" => kapaint::ui::run(file.map(Into::into)),
        _ => kapaint::cli::main(),
    };
    std::process::exit(code);
}
