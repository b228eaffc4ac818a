//! `limber echo <device>`: the live state, like `ros2 topic echo` or playerprint.

use std::time::Duration;

use clap::Args;
use limber_interfaces::common::device_flag;
use limber_interfaces::describe::header_json;
use limber_interfaces::diagnostics::DriverStats;
use limber_services::prelude::*;
use limber_services::{DeviceName, WaitError};
use serde_json::{Value, json};

use crate::device::{connect_err, wait_err};
use crate::out::outln;
use crate::{CliError, exit};

/// Arguments of `limber echo`.
#[derive(Debug, Args)]
pub struct EchoArgs {
    /// The device, e.g. pioneer/actarray/0 (see `limber list`), or `<robot>/driver` for the
    /// driver's loop and link statistics.
    device: String,
    /// Print one JSON object per line (for scripts: jq, Python).
    #[arg(long)]
    json: bool,
    /// Stop after this many samples.
    #[arg(long, value_name = "N")]
    count: Option<u64>,
    /// Seconds without a new sample before giving up.
    #[arg(long, default_value_t = 5.0, value_name = "S", value_parser = crate::parse_seconds)]
    timeout: f64,
}

fn echo(a: &EchoArgs) -> Result<(), CliError> {
    let ctx = crate::client_context()?;
    let mut c = connect_device(&ctx, &a.device, Duration::from_millis(500)).map_err(connect_err)?;
    let timeout = Duration::from_secs_f64(a.timeout.clamp(0.01, 3600.0));
    let mut n = 0;
    // The latest sample (history 1) first, then every new one.
    loop {
        if a.count.is_some_and(|c| n >= c) {
            return Ok(());
        }
        let got = if n == 0 {
            c.refresh().map_err(wait_err)?;
            match c.header() {
                Some(_) => Ok(()),
                None => c.wait_state_bytes(timeout).map(|_| ()),
            }
        } else {
            c.wait_state_bytes(timeout).map(|_| ())
        };
        match got {
            Ok(()) => {}
            Err(WaitError::Timeout(_)) => {
                return Err(CliError::new(
                    exit::TIMEOUT,
                    format!("no new state from {} within {:?}", a.device, timeout),
                ));
            }
            Err(e) => return Err(wait_err(e)),
        }
        let Some(s) = c.describe() else {
            continue;
        };
        if a.json {
            let mut v = s.json();
            v["device"] = json!(a.device);
            outln!("{v}")?;
        } else {
            outln!("{}", s.human())?;
        }
        n += 1;
    }
}

fn stats_json(s: &DriverStats) -> Value {
    use limber_interfaces::diagnostics::{get_text, hardware};
    json!({
        "header": header_json(&s.header),
        "driver": get_text(&s.driver).unwrap_or("?"),
        "robot": {
            "name": get_text(&s.robot_name).unwrap_or("?"),
            "class": get_text(&s.robot_class).unwrap_or("?"),
            "subclass": get_text(&s.robot_subclass).unwrap_or("?"),
            "arm": s.hardware & hardware::ARM != 0,
            "gripper": s.hardware & hardware::GRIPPER != 0,
            "lift": s.hardware & hardware::LIFT != 0,
            "lacks": hardware::lacking(s.hardware),
        },
        "loop": {
            "mode": if s.loop_mode == 2 { "spin" } else { "event" },
            "cycles": s.cycles,
            "overruns": s.overruns,
            "period_ns": {"p50": s.period_p50_ns, "p99": s.period_p99_ns, "max": s.period_max_ns},
            "jitter_p99_ns": s.jitter_p99_ns,
            "cmd_to_wire_ns": {"p50": s.cmd_to_wire_p50_ns, "p99": s.cmd_to_wire_p99_ns, "max": s.cmd_to_wire_max_ns},
        },
        "link": {
            "up": s.header.flags & device_flag::LINK_UP != 0,
            "sips_per_s": s.sips_per_s,
            "bytes_in": s.bytes_in,
            "bytes_out": s.bytes_out,
            "packets_in": s.packets_in,
            "bad_checksums": s.bad_checksums,
            "resync_bytes": s.resync_bytes,
            "reconnects": s.reconnects,
            "faults": s.link_faults,
        },
        "clients": {"commands": s.commands, "refused": s.refused, "requests": s.requests, "overflows": s.cmd_overflows},
    })
}

fn stats_human(s: &DriverStats) -> String {
    use limber_interfaces::diagnostics::get_text;
    format!(
        "#{:<5} {} on {} ({} {}): link {}, {:.1} SIPs/s, period p50 {:.2} ms p99 {:.2} ms, overruns {}, cmd→wire p50 {:.1} µs p99 {:.1} µs, {} cmds ({} refused), {} reqs, {} bad checksums, {} reconnects",
        s.header.seq,
        get_text(&s.driver).unwrap_or("?"),
        get_text(&s.robot_name).unwrap_or("?"),
        get_text(&s.robot_class).unwrap_or("?"),
        get_text(&s.robot_subclass).unwrap_or("?"),
        if s.header.flags & device_flag::LINK_UP != 0 {
            "up"
        } else {
            "DOWN"
        },
        s.sips_per_s,
        s.period_p50_ns as f64 / 1e6,
        s.period_p99_ns as f64 / 1e6,
        s.overruns,
        s.cmd_to_wire_p50_ns as f64 / 1e3,
        s.cmd_to_wire_p99_ns as f64 / 1e3,
        s.commands,
        s.refused,
        s.requests,
        s.bad_checksums,
        s.reconnects
    )
}

fn echo_driver(robot: &str, a: &EchoArgs) -> Result<(), CliError> {
    use limber_services::diagnostics::{DiagnosticsError, StatsReader};
    let ctx = crate::client_context()?;
    let mut r = StatsReader::open(&ctx, robot).map_err(|e| match e {
        DiagnosticsError::NoDriver(_) => CliError::new(exit::NO_DRIVER, e.to_string()),
        DiagnosticsError::Name(_) => CliError::new(exit::USAGE, e.to_string()),
        _ => CliError::new(exit::FAILURE, e.to_string()),
    })?;
    let timeout = Duration::from_secs_f64(a.timeout.clamp(0.01, 3600.0));
    let mut n = 0;
    while a.count.is_none_or(|c| n < c) {
        let s = *r
            .wait(timeout)
            .map_err(|e| CliError::new(exit::TIMEOUT, e.to_string()))?;
        if a.json {
            let mut v = stats_json(&s);
            v["device"] = json!(format!("{robot}/driver/0"));
            outln!("{v}")?;
        } else {
            outln!("{}", stats_human(&s))?;
        }
        n += 1;
    }
    Ok(())
}

/// Runs `limber echo`.
pub fn run(a: EchoArgs) -> Result<(), CliError> {
    let parts: Vec<&str> = a.device.split('/').collect();
    if let [robot, "driver"] | [robot, "driver", "0"] = parts.as_slice() {
        return echo_driver(robot, &a);
    }
    let _: DeviceName = a
        .device
        .parse()
        .map_err(|e: limber_services::NameError| CliError::new(exit::USAGE, e.to_string()))?;
    echo(&a)
}
