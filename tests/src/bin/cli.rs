//! The `limber` command line as a test binary (the CLI crate's binary is not visible to
//! this package's tests): the very same code as the `limber` binary.

fn main() -> std::process::ExitCode {
    limber_cli::run_from(std::env::args_os())
}
