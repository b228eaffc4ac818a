//! `limber echo <device>`: the live state, like `ros2 topic echo` or playerprint.

use std::fmt::Write as _;
use std::time::Duration;

use clap::Args;
use limber_interfaces::common::{StateHeader, device_flag};
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

/// A state that `echo` can print.
pub trait Show {
    /// One human-readable line.
    fn human(&self) -> String;
    /// One JSON object.
    fn json(&self) -> Value;
}

fn header_json(h: &StateHeader) -> Value {
    json!({
        "seq": h.seq,
        "stamp_ns": h.stamp_ns,
        "link_up": h.flags & device_flag::LINK_UP != 0,
        "calibrated": h.flags & device_flag::CALIBRATED != 0,
        "flags": h.flags,
        "cmd_overflows": h.cmd_overflows,
        "last_cmd": {
            "client_id": h.last_cmd.client_id,
            "seq": h.last_cmd.cmd_seq,
            "kind": h.last_cmd.kind,
            "status": Status::try_from(h.last_cmd.status).map(|s| s.describe()).unwrap_or("?"),
        },
    })
}

fn header_human(h: &StateHeader) -> String {
    let mut s = format!("#{:<6}", h.seq);
    if h.flags & device_flag::LINK_UP == 0 && h.flags != 0 {
        s.push_str(" LINK DOWN");
    }
    if h.last_cmd.client_id != 0 && h.last_cmd.status != 0 {
        match Status::try_from(h.last_cmd.status) {
            // "ok, clamped to the limit", "ok, orientation adjusted": carried out.
            Ok(st) if st.is_carried_out() => {
                s.push_str(&format!(" [last command: {st}]"));
            }
            Ok(st) => {
                s.push_str(&format!(" [last command refused: {st}]"));
            }
            Err(_) => s.push_str(" [last command refused: ?]"),
        }
    }
    s
}

fn flags_name(bits: u32) -> &'static str {
    match ActuatorFlags::from_bits(bits) {
        Some(f) if f.contains(ActuatorFlags::STALLED) => "stalled",
        Some(f) if f.contains(ActuatorFlags::MOVING) => "moving",
        Some(f) if f.contains(ActuatorFlags::BRAKED) => "braked",
        Some(f) if f.contains(ActuatorFlags::IDLE) => "idle",
        Some(_) => "-",
        None => "?",
    }
}

impl Show for ActArrayData {
    fn human(&self) -> String {
        let mut s = header_human(&self.header);
        let _ = write!(
            s,
            " power {}",
            if self.motor_state != 0 { "on " } else { "off" }
        );
        for (i, a) in self.actuators().iter().enumerate() {
            let _ = write!(s, " | j{i} {:+.4} {}", a.position, flags_name(a.state));
        }
        s
    }
    fn json(&self) -> Value {
        json!({
            "header": header_json(&self.header),
            "motor_state": self.motor_state,
            "actuators": self.actuators().iter().map(|a| json!({
                "position": a.position,
                "speed": a.speed,
                "acceleration": a.acceleration,
                "current": a.current,
                "state": flags_name(a.state),
            })).collect::<Vec<_>>(),
        })
    }
}

fn limb_state_name(v: u32) -> &'static str {
    match LimbState::try_from(v) {
        Ok(LimbState::Idle) => "idle",
        Ok(LimbState::Braked) => "braked",
        Ok(LimbState::Moving) => "moving",
        Ok(LimbState::OutOfReach) => "out-of-reach",
        Ok(LimbState::Collision) => "collision",
        Err(_) => "?",
    }
}

impl Show for LimbData {
    fn human(&self) -> String {
        let (p, a, o) = (self.position, self.approach, self.orientation);
        let adjusted = if self.orientation_adjustment > 0.0 {
            format!(
                " (orientation adjusted by {:.6} rad)",
                self.orientation_adjustment
            )
        } else {
            String::new()
        };
        format!(
            "{} {:<12} pos ({:+.4}, {:+.4}, {:+.4}) approach ({:+.3}, {:+.3}, {:+.3}) orient ({:+.3}, {:+.3}, {:+.3}){adjusted}",
            header_human(&self.header),
            limb_state_name(self.state),
            p.x,
            p.y,
            p.z,
            a.x,
            a.y,
            a.z,
            o.x,
            o.y,
            o.z
        )
    }
    fn json(&self) -> Value {
        json!({
            "header": header_json(&self.header),
            "state": limb_state_name(self.state),
            "position": self.position.to_array(),
            "approach": self.approach.to_array(),
            "orientation": self.orientation.to_array(),
            "orientation_adjustment": self.orientation_adjustment,
        })
    }
}

fn gripper_state_name(v: u32) -> &'static str {
    match GripperState::try_from(v) {
        Ok(GripperState::Open) => "open",
        Ok(GripperState::Closed) => "closed",
        Ok(GripperState::Moving) => "moving",
        Ok(GripperState::Error) => "error",
        Err(_) => "?",
    }
}

impl Show for GripperData {
    fn human(&self) -> String {
        format!(
            "{} {:<7} beams {:#06b} stored {}",
            header_human(&self.header),
            gripper_state_name(self.state),
            self.beams,
            self.stored
        )
    }
    fn json(&self) -> Value {
        json!({
            "header": header_json(&self.header),
            "state": gripper_state_name(self.state),
            "beams": self.beams,
            "stored": self.stored,
        })
    }
}

fn echo<I: Interface>(a: &EchoArgs) -> Result<(), CliError>
where
    I::Data: Show,
{
    let ctx = crate::client_context()?;
    let mut c = Client::<I>::connect_timeout(&ctx, &a.device, Duration::from_millis(500))
        .map_err(connect_err)?;
    let timeout = Duration::from_secs_f64(a.timeout.clamp(0.01, 3600.0));
    let mut n = 0;
    // The latest sample (history 1) first, then every new one.
    loop {
        if a.count.is_some_and(|c| n >= c) {
            return Ok(());
        }
        let got = if n == 0 {
            c.refresh().map_err(wait_err)?;
            match c.last_state() {
                Some(_) => Ok(()),
                None => c.wait_state(timeout).map(|_| ()),
            }
        } else {
            c.wait_state(timeout).map(|_| ())
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
        let Some(s) = c.last_state() else {
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
    let dev: DeviceName = a
        .device
        .parse()
        .map_err(|e: limber_services::NameError| CliError::new(exit::USAGE, e.to_string()))?;
    match dev.interface() {
        InterfaceKind::ActArray => echo::<ActArray>(&a),
        InterfaceKind::Limb => echo::<Limb>(&a),
        InterfaceKind::Gripper => echo::<Gripper>(&a),
    }
}
