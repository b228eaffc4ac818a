//! What a running driver says its robot lacks (the `NO_*` bits of its statistics): used by
//! `limber list` and by the "no driver offers ..." message, so that a device missing
//! because the robot has no such hardware is not blamed on a driver that is not running.

use std::time::Duration;

use limber_interfaces::diagnostics::{get_text, hardware};
use limber_services::diagnostics::StatsReader;
use limber_services::{Context, DeviceName, Domain, Role};

/// How long to wait for a driver's latest statistics (kept as history: normally at once).
const STATS_WAIT: Duration = Duration::from_millis(1500);

/// A running driver's account of its robot.
pub(crate) struct Lacks {
    /// The driver's name.
    pub driver: String,
    /// The `NO_*` bits.
    pub bits: u32,
}

/// What `robot`'s driver says the robot lacks; `None` when no driver publishes
/// statistics for it (or none arrive within [`STATS_WAIT`]).
pub(crate) fn of_robot(ctx: &Context, robot: &str) -> Option<Lacks> {
    let mut r = StatsReader::open(ctx, robot).ok()?;
    let s = match r.wait(STATS_WAIT) {
        Ok(s) => *s,
        Err(e) => {
            tracing::debug!("no statistics from the driver of {robot}: {e}");
            return None;
        }
    };
    Some(Lacks {
        driver: get_text(&s.driver).unwrap_or("?").to_string(),
        bits: s.hardware,
    })
}

/// The message for "no driver offers `device`" when the robot's driver runs and says the
/// robot lacks the hardware behind it: "robot pioneer has no arm ...". `None` otherwise.
pub(crate) fn explain(device: &str, domain: &str) -> Option<String> {
    let name: DeviceName = device.parse().ok()?;
    let (bit, what) = hardware::of_device(name.interface(), name.index())?;
    let domain = Domain::new(domain).ok()?;
    let ctx = Context::new(&domain, Role::Client, "limber").ok()?;
    let lacks = of_robot(&ctx, name.robot())?;
    (lacks.bits & bit != 0).then(|| {
        format!(
            "robot {robot} has no {what}: its driver ({driver}) runs in domain {domain} and \
             found none, so {device} is not offered (`limber list` shows what each robot lacks)",
            robot = name.robot(),
            driver = lacks.driver,
            domain = domain.name(),
        )
    })
}
