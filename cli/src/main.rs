//! `limber`: the command-line tool of the limber middleware (see the `limber_cli` library).

fn main() -> std::process::ExitCode {
    limber_cli::run()
}
