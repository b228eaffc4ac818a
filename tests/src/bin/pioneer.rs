//! `limber pioneer` as a test binary (the CLI crate's binary is not visible to this
//! package's tests): the very same code as the `limber` binary, with `pioneer` inserted.

fn main() -> std::process::ExitCode {
    let mut args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    args.insert(1, "pioneer".into());
    limber_cli::run_from(args)
}
