//! `limber actarray|limb|gripper|ranger <device> <command>`: every command and request of each
//! interface from the shell, and `limber echo <device>`: the live state.

use std::time::Duration;

use clap::{Args, Subcommand, ValueEnum};
use limber_interfaces::Describe;
use limber_services::prelude::*;
use limber_services::{CommandError, ConnectError, LeaseError, RequestError, WaitError};

use crate::out::outln;
use crate::{CliError, exit};

/// How long commands wait for their outcome and requests for their reply.
#[derive(Debug, Args)]
pub struct Common {
    /// Seconds to wait for the driver's answer (the outcome of a command, the reply to a
    /// request, the connection).
    #[arg(long, global = true, default_value_t = 2.0, value_name = "S",
          value_parser = crate::parse_seconds)]
    timeout: f64,
    /// Send commands without waiting for their outcome ("sent"); the CLI still ends only
    /// once the driver has taken them.
    #[arg(long, global = true)]
    no_wait: bool,
    /// After the outcome, wait up to S seconds (default 60) until the command's motion
    /// has ended, and say how (reached within the tolerance, stalled, stopped, preempted,
    /// aborted, timed out) with the largest final error; exit 1 when it did not reach its
    /// goal.
    #[arg(long, global = true, value_name = "S", num_args = 0..=1,
          default_missing_value = "60", value_parser = crate::parse_seconds,
          conflicts_with = "no_wait")]
    wait: Option<f64>,
    /// Take the device for this command (a control lease, released when it ends): refused
    /// with the holder's name if another client holds it. Without it, the last writer wins.
    #[arg(long, global = true)]
    own: bool,
    /// Connect as a priority client (as LIMBER_PRIORITY=1 does): it may take the slots a
    /// device keeps beyond its --max-clients for the robot's control program. Cooperative
    /// among the domain owner's processes, not a protection.
    #[arg(long, global = true)]
    priority: bool,
}

impl Common {
    pub(crate) fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.timeout.clamp(0.0, 3600.0))
    }
}

/// On or off.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum OnOff {
    /// On.
    On,
    /// Off.
    Off,
}

impl OnOff {
    fn on(self) -> bool {
        matches!(self, OnOff::On)
    }
}

/// Arguments of `limber actarray`.
#[derive(Debug, Args)]
pub struct ActArrayArgs {
    /// The device, e.g. pioneer/actarray/0.
    device: String,
    #[command(subcommand)]
    cmd: ActArrayVerb,
    #[command(flatten)]
    common: Common,
}

/// An actarray command or request.
#[derive(Debug, Subcommand)]
pub enum ActArrayVerb {
    /// Move one joint to a position (rad or m).
    Pos {
        /// Joint index (0-based).
        joint: usize,
        /// Target position.
        #[arg(allow_negative_numbers = true)]
        position: f64,
    },
    /// Move joints 0..n to these positions.
    Multipos {
        /// One position per joint, joint 0 first.
        #[arg(required = true, allow_negative_numbers = true)]
        positions: Vec<f64>,
    },
    /// Move one joint at a speed (rad/s or m/s).
    Speed {
        /// Joint index.
        joint: usize,
        /// Speed.
        #[arg(allow_negative_numbers = true)]
        speed: f64,
    },
    /// Move joints 0..n at these speeds.
    Multispeed {
        /// One speed per joint.
        #[arg(required = true, allow_negative_numbers = true)]
        speeds: Vec<f64>,
    },
    /// Home one joint, or every joint ("all", the default).
    Home {
        /// Joint index or "all".
        #[arg(default_value = "all")]
        joint: String,
    },
    /// Drive a joint (or "all") with a current, A.
    Current {
        /// Joint index or "all".
        joint: String,
        /// Current in A.
        #[arg(allow_negative_numbers = true)]
        current: f64,
    },
    /// Drive joints 0..n with these currents, A.
    Multicurrent {
        /// One current per joint.
        #[arg(required = true, allow_negative_numbers = true)]
        currents: Vec<f64>,
    },
    /// Power on or off (request).
    Power {
        /// on or off.
        value: OnOff,
    },
    /// Brakes on or off (request).
    Brakes {
        /// on or off.
        value: OnOff,
    },
    /// Print the geometry: every actuator's type, limits, home and speed (request).
    Geom,
    /// Set the speed of one joint for later moves (request).
    Speedcfg {
        /// Joint index.
        joint: usize,
        /// Speed, rad/s or m/s.
        speed: f64,
    },
    /// Set the acceleration of one joint for later moves (request).
    Accel {
        /// Joint index.
        joint: usize,
        /// Acceleration.
        accel: f64,
    },
    /// Follow a joint trajectory read from a CSV file (`-`: standard input): a header
    /// `t,j0,j1,...` (time from start in s, then each joint's position), optional
    /// `v0,...` velocity and `a0,...` acceleration columns, one line per point. With
    /// `--wait`, the result and each joint's final error.
    Traj(crate::traj::TrajArgs),
    /// The speed scaling of trajectories: 0 pauses the running one, 1 is nominal.
    Scale {
        /// The factor, 0 to 1.
        factor: f64,
    },
}

/// Arguments of `limber limb`.
#[derive(Debug, Args)]
pub struct LimbArgs {
    /// The device, e.g. pioneer/limb/0.
    device: String,
    #[command(subcommand)]
    cmd: LimbVerb,
    #[command(flatten)]
    common: Common,
}

/// A limb command or request.
#[derive(Debug, Subcommand)]
pub enum LimbVerb {
    /// Go to the home pose.
    Home,
    /// Stop every joint now.
    Stop,
    /// Move the end effector to a pose: position x y z (m, robot frame), with the approach
    /// and orientation vectors.
    Setpose {
        /// x, y, z in m.
        #[arg(num_args = 3, required = true, allow_negative_numbers = true, value_names = ["X", "Y", "Z"])]
        position: Vec<f64>,
        /// Approach vector (forward along the gripper).
        #[arg(long, num_args = 3, allow_negative_numbers = true, default_values_t = [1.0, 0.0, 0.0], value_names = ["AX", "AY", "AZ"])]
        approach: Vec<f64>,
        /// Orientation vector ("up" from the gripper).
        #[arg(long, num_args = 3, allow_negative_numbers = true, default_values_t = [0.0, 0.0, 1.0], value_names = ["OX", "OY", "OZ"])]
        orient: Vec<f64>,
    },
    /// Where would this setpose end, and how much would it adjust the orientation?
    /// Nothing moves (request). Exit 0 when the limb can get there, 5 (refused, with the
    /// cause) when it cannot.
    Reach {
        /// x, y, z in m.
        #[arg(num_args = 3, required = true, allow_negative_numbers = true, value_names = ["X", "Y", "Z"])]
        position: Vec<f64>,
        /// Approach vector (forward along the gripper).
        #[arg(long, num_args = 3, allow_negative_numbers = true, default_values_t = [1.0, 0.0, 0.0], value_names = ["AX", "AY", "AZ"])]
        approach: Vec<f64>,
        /// Orientation vector ("up" from the gripper).
        #[arg(long, num_args = 3, allow_negative_numbers = true, default_values_t = [0.0, 0.0, 1.0], value_names = ["OX", "OY", "OZ"])]
        orient: Vec<f64>,
    },
    /// Move the end effector to a position; the driver chooses the orientation.
    Setposition {
        /// x, y, z in m.
        #[arg(num_args = 3, required = true, allow_negative_numbers = true, value_names = ["X", "Y", "Z"])]
        position: Vec<f64>,
    },
    /// Move the end effector in a straight line: direction dx dy dz, length in m.
    Vecmove {
        /// Direction and length.
        #[arg(num_args = 4, required = true, allow_negative_numbers = true, value_names = ["DX", "DY", "DZ", "LEN"])]
        args: Vec<f64>,
    },
    /// Move the tool in a straight line to x y z (m), checked whole before anything
    /// moves: a line out of reach or into the world is refused (exit 5) with where.
    Line(crate::path::PathArgs),
    /// Move the joints, interpolated, to where the tool is at x y z (m), checked as line.
    Ptp(crate::path::PathArgs),
    /// Power on or off (request).
    Power {
        /// on or off.
        value: OnOff,
    },
    /// Brakes on or off (request).
    Brakes {
        /// on or off.
        value: OnOff,
    },
    /// Print the geometry (base position) (request).
    Geom,
    /// Set the end-effector speed, m/s (request).
    Speed {
        /// Speed in m/s.
        speed: f64,
    },
}

/// Arguments of `limber gripper`.
#[derive(Debug, Args)]
pub struct GripperArgs {
    /// The device, e.g. pioneer/gripper/0.
    device: String,
    #[command(subcommand)]
    cmd: GripperVerb,
    #[command(flatten)]
    common: Common,
}

/// A gripper command or request.
#[derive(Debug, Subcommand)]
pub enum GripperVerb {
    /// Open.
    Open,
    /// Close.
    Close,
    /// Stop.
    Stop,
    /// Store the held object.
    Store,
    /// Retrieve a stored object.
    Retrieve,
    /// Move the fingers to a gap, m. With --wait the result: reached, or stalled on an
    /// object (exit 1), "an object is between the fingers" when the beams see one. A
    /// gripper that cannot set the gap, the effort or the speed refuses (exit 5).
    Goal {
        /// The gap between the fingers, m (0: closed).
        gap: f64,
        /// The largest grip effort, N (0: the gripper's own).
        #[arg(long, default_value_t = 0.0)]
        effort: f64,
        /// The fingers' speed, m/s (0: the configured speed).
        #[arg(long, default_value_t = 0.0)]
        speed: f64,
    },
    /// Print the geometry (request).
    Geom,
}

pub(crate) fn connect_err(e: ConnectError) -> CliError {
    // A device missing because the robot lacks its hardware is said so, not blamed on a
    // driver that is not running.
    if let ConnectError::NoDriver { device, domain, .. } = &e
        && let Some(msg) = crate::lacks::explain(device, domain)
    {
        return CliError::new(exit::NO_DRIVER, msg);
    }
    let code = match e {
        ConnectError::NoDriver { .. } => exit::NO_DRIVER,
        // The device refused one more client: it says how many it admits and what to do.
        ConnectError::Full { .. } => exit::REFUSED,
        ConnectError::Name(_) => exit::USAGE,
        // A verb of another interface than the device's: a usage error.
        ConnectError::Incompatible {
            reason: limber_services::Incompatibility::Interface { .. },
            ..
        } => exit::USAGE,
        _ => exit::FAILURE,
    };
    CliError::new(code, e.to_string())
}

pub(crate) fn command_err(e: CommandError) -> CliError {
    let code = match e {
        CommandError::Invalid(_) => exit::USAGE,
        CommandError::NoDriver => exit::NO_DRIVER,
        CommandError::Transport(_) => exit::FAILURE,
    };
    CliError::new(code, e.to_string())
}

fn request_err(e: RequestError) -> CliError {
    let code = match e {
        RequestError::Nack(_) => exit::REFUSED,
        RequestError::Timeout(_) => exit::TIMEOUT,
        RequestError::NoDriver => exit::NO_DRIVER,
        RequestError::DriverGone => exit::DRIVER_GONE,
        RequestError::Invalid(_) => exit::USAGE,
        _ => exit::FAILURE,
    };
    CliError::new(code, e.to_string())
}

pub(crate) fn wait_err(e: WaitError) -> CliError {
    let code = match e {
        WaitError::Timeout(_) => exit::TIMEOUT,
        WaitError::DriverGone => exit::DRIVER_GONE,
        _ => exit::FAILURE,
    };
    CliError::new(code, e.to_string())
}

fn connect<I: Interface>(device: &str, common: &Common) -> Result<Client<I>, CliError> {
    let ctx = crate::client_context()?;
    if common.priority {
        ctx.set_priority(true);
    }
    let timeout = common.timeout();
    // A driver that is starting gets the whole --timeout to appear.
    let mut c = Client::<I>::connect_timeout(&ctx, device, timeout).map_err(connect_err)?;
    c.set_request_timeout(timeout);
    if common.own {
        // Held while this command runs (released when the client is dropped); the
        // heartbeat outlasts the longest wait of the command.
        let name = format!("limber-cli pid {}", std::process::id());
        c.acquire(&name, timeout.max(Duration::from_secs(1)) * 2)
            .map_err(lease_err)?;
    }
    Ok(c)
}

/// The refusal of a device held by another client, naming the holder.
fn held_by(name: &str) -> CliError {
    let who = if name.is_empty() { "unnamed" } else { name };
    CliError::new(
        exit::REFUSED,
        format!("refused: {} ({who})", Status::Leased),
    )
}

fn lease_err(e: LeaseError) -> CliError {
    let code = match &e {
        LeaseError::Held { name, .. } => return held_by(name),
        LeaseError::Refused(_) => exit::REFUSED,
        LeaseError::Timeout(_) => exit::TIMEOUT,
        LeaseError::NoDriver => exit::NO_DRIVER,
        LeaseError::DriverGone => exit::DRIVER_GONE,
        _ => exit::FAILURE,
    };
    CliError::new(code, e.to_string())
}

/// Sends a command and reports its outcome.
pub(crate) fn finish<I: Interface>(
    c: &mut Client<I>,
    sent: Result<Ticket, CommandError>,
    common: &Common,
) -> Result<(), CliError> {
    finish_ticket(c, sent.map_err(command_err)?, common, false)
}

/// Reports the outcome of a command sent (with `--wait`, its result; `per_joint`: and
/// each joint's final error).
fn finish_ticket<I: Interface>(
    c: &mut Client<I>,
    ticket: Ticket,
    common: &Common,
    per_joint: bool,
) -> Result<(), CliError> {
    if common.no_wait {
        outln!("sent")?;
        return Ok(());
    }
    match c.wait_outcome_detail(ticket, common.timeout()) {
        // "ok", or "ok, clamped to the limit": carried out either way.
        Ok(o) if o.status.is_carried_out() => {
            outln!("{}", o.status)?;
            match common.wait {
                Some(s) => wait_done(c, ticket, s, per_joint),
                None => Ok(()),
            }
        }
        // Another client holds the device: "refused: held by another client (its name)".
        Ok(o) if o.status == Status::Leased => Err(held_by(o.other_name())),
        // The cause in words: "refused: powered off", "refused: out of reach", ...
        Ok(o) => Err(CliError::new(
            exit::REFUSED,
            format!("refused: {}", o.status),
        )),
        Err(WaitError::Missed { .. }) => {
            outln!("ok (applied; outcome overwritten by a later command)")?;
            Ok(())
        }
        Err(e) => Err(wait_err(e)),
    }
}

/// `--wait`: how the motion of `ticket`'s command ended, in the core's sentence ("done:
/// reached the goal within the tolerance; largest final error ..."); exit 1 when it did
/// not reach its goal.
fn wait_done<I: Interface>(
    c: &mut Client<I>,
    ticket: Ticket,
    seconds: f64,
    per_joint: bool,
) -> Result<(), CliError> {
    match c.wait_done(ticket, Duration::from_secs_f64(seconds)) {
        Ok(d) if d.reached() => {
            outln!("done: {d}")?;
            if per_joint {
                crate::traj::print_errors(&d)?;
            }
            Ok(())
        }
        Ok(d) => {
            if per_joint {
                outln!("done: {d}")?;
                crate::traj::print_errors(&d)?;
            }
            Err(CliError::new(exit::FAILURE, format!("done: {d}")))
        }
        Err(DoneError::Refused(s)) => Err(CliError::new(exit::REFUSED, format!("refused: {s}"))),
        Err(DoneError::Wait(e)) => Err(wait_err(e)),
    }
}

fn joint_sel(s: &str) -> Result<Option<usize>, CliError> {
    if s == "all" || s == "-1" {
        return Ok(None);
    }
    s.parse().map(Some).map_err(|_| {
        CliError::new(
            exit::USAGE,
            format!("joint must be an index or \"all\", not {s:?}"),
        )
    })
}

/// Sends a request that changes the device and reports the answer.
fn done<I: Interface>(
    c: &mut Client<I>,
    request: impl FnOnce(&mut Client<I>) -> Result<(), RequestError>,
) -> Result<(), CliError> {
    match request(c) {
        Ok(()) => {
            outln!("ok")?;
            Ok(())
        }
        Err(RequestError::Nack(Status::Leased)) => {
            let name = match c.holder() {
                Ok(Some(h)) => h.name,
                Ok(None) => String::new(),
                Err(e) => {
                    tracing::debug!(error = %e, "cannot ask who holds the device");
                    String::new()
                }
            };
            Err(held_by(&name))
        }
        Err(e) => Err(request_err(e)),
    }
}

/// `speedcfg`: drivers set a speed beyond the joint's limit (the geometry's
/// `config_speed`) to the limit, and a request's reply has no room to say so: said here,
/// from the geometry.
fn speedcfg(c: &mut Client<ActArray>, joint: usize, speed: f64) -> Result<(), CliError> {
    match c.set_speed_config(joint, speed) {
        Ok(()) => {
            let limit = match c.geometry() {
                Ok(g) => g
                    .actuators()
                    .get(joint)
                    .map(|a| a.config_speed)
                    .filter(|&l| l > 0.0 && speed > l),
                Err(e) => {
                    tracing::debug!(error = %e, "cannot read the geometry after speedcfg");
                    None
                }
            };
            match limit {
                Some(l) => outln!("ok: clamped to {l} rad/s, the joint's limit")?,
                None => outln!("ok")?,
            }
            Ok(())
        }
        Err(e) => done(c, |_| Err(e)),
    }
}

/// Runs `limber actarray`.
pub fn actarray(a: ActArrayArgs) -> Result<(), CliError> {
    let mut c = connect::<ActArray>(&a.device, &a.common)?;
    let sent = match a.cmd {
        ActArrayVerb::Pos { joint, position } => c.move_to(joint, position),
        ActArrayVerb::Multipos { positions } => c.move_to_multi(&positions),
        ActArrayVerb::Speed { joint, speed } => c.move_at_speed(joint, speed),
        ActArrayVerb::Multispeed { speeds } => c.move_at_speed_multi(&speeds),
        ActArrayVerb::Home { joint } => c.home(joint_sel(&joint)?),
        ActArrayVerb::Current { joint, current } => c.set_current(joint_sel(&joint)?, current),
        ActArrayVerb::Multicurrent { currents } => c.set_current_multi(&currents),
        ActArrayVerb::Power { value } => return done(&mut c, |c| c.power(value.on())),
        ActArrayVerb::Brakes { value } => return done(&mut c, |c| c.brakes(value.on())),
        ActArrayVerb::Speedcfg { joint, speed } => return speedcfg(&mut c, joint, speed),
        ActArrayVerb::Accel { joint, accel } => {
            return done(&mut c, |c| c.set_accel_config(joint, accel));
        }
        ActArrayVerb::Traj(t) => {
            let ticket = crate::traj::send(&mut c, &t, a.common.timeout())?;
            return finish_ticket(&mut c, ticket, &a.common, true);
        }
        ActArrayVerb::Scale { factor } => c.set_trajectory_scale(factor),
        ActArrayVerb::Geom => {
            let g = c.geometry().map_err(request_err)?;
            outln!(
                "{:<5} {:<7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>7}",
                "joint",
                "type",
                "min",
                "centre",
                "max",
                "home",
                "speed",
                "brakes"
            )?;
            for (i, a) in g.actuators().iter().enumerate() {
                let kind = match a.actuator_kind() {
                    Ok(ActuatorKind::Rotary) => "rotary",
                    Ok(ActuatorKind::Linear) => "linear",
                    Err(_) => "?",
                };
                outln!(
                    "{i:<5} {kind:<7} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>7}",
                    a.min,
                    a.centre,
                    a.max,
                    a.home,
                    a.config_speed,
                    if a.has_brakes != 0 { "yes" } else { "no" }
                )?;
            }
            outln!(
                "base position ({:.4}, {:.4}, {:.4}) m",
                g.base_pos.x,
                g.base_pos.y,
                g.base_pos.z
            )?;
            return Ok(());
        }
    };
    finish(&mut c, sent, &a.common)
}

fn v3(v: &[f64]) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// Runs `limber limb`.
pub fn limb(a: LimbArgs) -> Result<(), CliError> {
    let mut c = connect::<Limb>(&a.device, &a.common)?;
    let sent = match a.cmd {
        LimbVerb::Home => c.home(),
        LimbVerb::Stop => c.stop(),
        LimbVerb::Setpose {
            position,
            approach,
            orient,
        } => c.set_pose(v3(&position), v3(&approach), v3(&orient)),
        LimbVerb::Setposition { position } => c.set_position(v3(&position)),
        LimbVerb::Vecmove { args } => c.vec_move(v3(&args), args[3]),
        LimbVerb::Line(p) => return crate::path::run(&mut c, p, true, &a.common),
        LimbVerb::Ptp(p) => return crate::path::run(&mut c, p, false, &a.common),
        LimbVerb::Power { value } => return done(&mut c, |c| c.power(value.on())),
        LimbVerb::Brakes { value } => return done(&mut c, |c| c.brakes(value.on())),
        LimbVerb::Speed { speed } => return done(&mut c, |c| c.set_speed(speed)),
        LimbVerb::Reach {
            position,
            approach,
            orient,
        } => {
            let r = c
                .reach(v3(&position), v3(&approach), v3(&orient))
                .map_err(request_err)?;
            let f = |v: Vec3| format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z);
            outln!(
                "would end at {} m, approach {}, orientation {}",
                f(r.position),
                f(r.approach),
                f(r.orientation)
            )?;
            if r.adjusted != 0 {
                outln!(
                    "orientation adjusted by {:.6} rad ({:.4} deg); position off by {:.6} m, approach by {:.6} rad",
                    r.orientation_adjustment,
                    r.orientation_adjustment.to_degrees(),
                    r.position_error,
                    r.approach_error
                )?;
            } else {
                outln!(
                    "as asked (position off by {:.6} m, approach by {:.6} rad)",
                    r.position_error,
                    r.approach_error
                )?;
            }
            return Ok(());
        }
        LimbVerb::Geom => {
            let g = c.geometry().map_err(request_err)?;
            outln!(
                "base position ({:.4}, {:.4}, {:.4}) m",
                g.base_pos.x,
                g.base_pos.y,
                g.base_pos.z
            )?;
            return Ok(());
        }
    };
    finish(&mut c, sent, &a.common)
}

/// Runs `limber gripper`.
pub fn gripper(a: GripperArgs) -> Result<(), CliError> {
    let mut c = connect::<Gripper>(&a.device, &a.common)?;
    let sent = match a.cmd {
        GripperVerb::Open => c.open(),
        GripperVerb::Close => c.close(),
        GripperVerb::Stop => c.stop(),
        GripperVerb::Store => c.store(),
        GripperVerb::Retrieve => c.retrieve(),
        GripperVerb::Goal { gap, effort, speed } => c.goal(gap, effort, speed),
        GripperVerb::Geom => {
            let g = c.geometry().map_err(request_err)?;
            let p = g.pose.position;
            outln!(
                "pose ({:.4}, {:.4}, {:.4}) m; outer {:.3} x {:.3} x {:.3} m; inner {:.3} x {:.3} x {:.3} m; {} beams; capacity {}",
                p.x,
                p.y,
                p.z,
                g.outer_size.width,
                g.outer_size.length,
                g.outer_size.height,
                g.inner_size.width,
                g.inner_size.length,
                g.inner_size.height,
                g.num_beams,
                g.capacity
            )?;
            return Ok(());
        }
    };
    finish(&mut c, sent, &a.common)
}

/// Arguments of `limber ranger`.
#[derive(Debug, Args)]
pub struct RangerArgs {
    /// The device, e.g. pioneer/ranger/0.
    device: String,
    #[command(subcommand)]
    cmd: RangerVerb,
    #[command(flatten)]
    common: Common,
}

/// What to read from a ranger (it has no command).
#[derive(Debug, Subcommand)]
pub enum RangerVerb {
    /// Print the latest scan: one line per range (index, bearing in degrees, range in m),
    /// then the closest one; `--json` prints the scan as `limber echo --json` does.
    Scan {
        /// One JSON object (the schema of `limber echo --json`).
        #[arg(long)]
        json: bool,
    },
    /// Print the geometry: the sensor's pose on the robot and its configuration (request).
    Geom,
}

/// Runs `limber ranger`.
pub fn ranger(a: RangerArgs) -> Result<(), CliError> {
    let mut c = connect::<Ranger>(&a.device, &a.common)?;
    match a.cmd {
        RangerVerb::Scan { json } => {
            let s = *c.current(a.common.timeout()).map_err(wait_err)?;
            if json {
                outln!("{}", s.json())?;
                return Ok(());
            }
            for (i, r) in s.ranges().iter().enumerate() {
                outln!("{i:3} {:+7.2} deg {r:.3} m", s.bearing(i).to_degrees())?;
            }
            outln!("{}", s.human())?;
        }
        RangerVerb::Geom => {
            let g = c.geometry().map_err(request_err)?;
            let (p, o) = (g.pose.position, g.pose.orientation);
            outln!(
                "pose ({:.4}, {:.4}, {:.4}) m yaw {:.2} deg; size {:.3} x {:.3} x {:.3} m; {} ranges over {:+.1}..{:+.1} deg every {:.2} deg; range {:.3} to {:.3} m (resolution {:.3} m); {:.1} Hz",
                p.x,
                p.y,
                p.z,
                o.yaw.to_degrees(),
                g.size.width,
                g.size.length,
                g.size.height,
                g.ranges_count,
                g.min_angle.to_degrees(),
                g.max_angle.to_degrees(),
                g.angular_res.to_degrees(),
                g.min_range,
                g.max_range,
                g.range_res,
                g.frequency
            )?;
        }
    }
    Ok(())
}
