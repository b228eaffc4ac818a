//! `limber list`: every device of the domain.

use clap::Args;
use limber_services::list_devices;

use crate::out::outln;
use crate::{CliError, domain, exit};

/// Arguments of `limber list`.
#[derive(Debug, Args)]
pub struct ListArgs {
    /// One JSON object per device and line, for scripts.
    #[arg(long)]
    json: bool,
}

/// Runs `limber list`.
pub fn run(args: ListArgs) -> Result<(), CliError> {
    let domain = domain()?;
    let devices = list_devices(&domain).map_err(|e| CliError::new(exit::FAILURE, e.to_string()))?;
    if args.json {
        for d in &devices {
            outln!(
                "{}",
                serde_json::json!({
                    "device": d.name.to_string(),
                    "robot": d.name.robot(),
                    "interface": d.name.interface().name(),
                    "index": d.name.index(),
                    "driver": d.driver,
                    "alive": d.alive,
                    "layout": d.layout,
                    "processes": d.nodes,
                })
            )?;
        }
        return Ok(());
    }
    let robots = limber_services::diagnostics::list_drivers(&domain)
        .map_err(|e| CliError::new(exit::FAILURE, e.to_string()))?;
    if devices.is_empty() && robots.is_empty() {
        outln!(
            "no devices in domain {} (start a driver, e.g. `limber pioneer --emulated`, or check --domain / LIMBER_DOMAIN){}",
            domain.name(),
            limber_services::domain_dir::elsewhere_note(domain.name())
        )?;
        return Ok(());
    }
    if devices.is_empty() {
        // Drivers that serve only their statistics: a robot without arm or gripper.
        return print_lacks(&robots, true);
    }
    outln!(
        "{:<28} {:<12} {:<6} {:>9}",
        "DEVICE",
        "DRIVER",
        "STATE",
        "PROCESSES"
    )?;
    for d in &devices {
        outln!(
            "{:<28} {:<12} {:<6} {:>9}",
            d.name.to_string(),
            d.driver,
            if d.alive { "alive" } else { "dead" },
            d.nodes
        )?;
    }
    print_lacks(&robots, false)
}

/// One line per robot (of `robots`, whose drivers publish statistics) whose running driver
/// found hardware missing: "robot pioneer has no arm (driver pioneer)"; with `every`, also
/// one for each robot that lacks nothing ("robot r: driver d serves no devices").
fn print_lacks(robots: &[String], every: bool) -> Result<(), CliError> {
    if robots.is_empty() {
        return Ok(());
    }
    let ctx = crate::client_context()?;
    for robot in robots {
        let Some(l) = crate::lacks::of_robot(&ctx, robot) else {
            if every {
                outln!("robot {robot}: its driver serves no devices (no statistics arrived)")?;
            }
            continue;
        };
        let missing = limber_interfaces::diagnostics::hardware::lacking(l.bits);
        if !missing.is_empty() {
            outln!(
                "robot {robot} has no {} (driver {})",
                missing.join(", no "),
                l.driver
            )?;
        } else if every {
            outln!("robot {robot}: driver {} serves no devices", l.driver)?;
        }
    }
    Ok(())
}
