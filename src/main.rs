//! The `kapaint` binary: everything lives in the library.

fn main() {
    std::process::exit(kapaint::cli::main());
}
