//! `limber clean`: removes every file of a domain (or of every domain of the user) that no
//! live process uses: what processes killed with SIGKILL left behind.

use clap::Args;
use limber_services::Domain;
use limber_services::domain::{RemoveError, dir};

use crate::out::outln;
use crate::{CliError, domain, exit};

/// Arguments of `limber clean`.
#[derive(Debug, Args)]
pub struct CleanArgs {
    /// Every domain of this user (of its runtime directory), not only the one of --domain /
    /// LIMBER_DOMAIN.
    #[arg(long)]
    all: bool,
    /// With --all: only the domains whose name starts with PREFIX (repeatable; e.g.
    /// `limber_t` for the tests' domains).
    #[arg(long, requires = "all", value_name = "PREFIX")]
    prefix: Vec<String>,
}

/// Runs `limber clean`.
pub fn run(args: CleanArgs) -> Result<(), CliError> {
    let domains = if args.all {
        let names = dir::domain_names().map_err(|e| CliError::new(exit::FAILURE, e.to_string()))?;
        names
            .into_iter()
            .filter(|n| args.prefix.is_empty() || args.prefix.iter().any(|p| n.starts_with(p)))
            .map(|n| Domain::new(&n).map_err(|e| CliError::new(exit::FAILURE, e.to_string())))
            .collect::<Result<Vec<_>, _>>()?
    } else {
        vec![domain()?]
    };
    if args.all && domains.is_empty() {
        outln!("no domain has files")?;
        return Ok(());
    }
    let mut in_use = Vec::new();
    for d in &domains {
        match d.remove_files() {
            Ok(r) if r.is_nothing() => outln!("domain {}: no files", d.name())?,
            Ok(r) if r.dead_processes == 0 => {
                outln!("domain {}: removed {}", d.name(), files(r.files))?;
            }
            Ok(r) => outln!(
                "domain {}: removed the files of {} dead process{}, then {}",
                d.name(),
                r.dead_processes,
                if r.dead_processes == 1 { "" } else { "es" },
                files(r.files)
            )?,
            Err(e @ RemoveError::Alive { .. }) => {
                tracing::debug!(domain = d.name(), error = %e, "domain kept");
                in_use.push(e.to_string());
            }
            Err(e) => {
                return Err(CliError::new(
                    exit::FAILURE,
                    format!("cannot clean domain {}: {e}", d.name()),
                ));
            }
        }
    }
    if in_use.is_empty() {
        return Ok(());
    }
    Err(CliError::new(
        exit::REFUSED,
        format!(
            "refused: {}; its files are theirs (limber list shows its devices)",
            in_use.join("; ")
        ),
    ))
}

/// `1 file`, `N files`.
fn files(n: usize) -> String {
    if n == 1 {
        "1 file".to_string()
    } else {
        format!("{n} files")
    }
}
