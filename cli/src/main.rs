//! `limber`: the command-line tool of the limber middleware.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod layout;

/// limber: Player's generic limb interfaces (actarray, limb, gripper) over zero-copy
/// shared memory, with a real-time driver for the Pioneer arm.
#[derive(Debug, Parser)]
#[command(name = "limber", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print the wire contract: every message struct with its type name, size and fields.
    ///
    /// Without a flag, a readable catalogue. `--json` prints the layout manifest that the
    /// C header and the Python classes are generated from.
    Layout(layout::LayoutArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Layout(args) => layout::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("limber: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// An error of a verb, with the exit code it maps to.
#[derive(Debug)]
pub struct CliError {
    message: String,
    code: u8,
}

impl CliError {
    /// An error with exit code `code`.
    pub fn new(code: u8, message: impl Into<String>) -> Self {
        CliError {
            message: message.into(),
            code,
        }
    }

    fn exit_code(&self) -> u8 {
        self.code
    }
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
