//! The simulated arm on the services layer: a [`DeviceSet`] of three devices around one
//! [`ArmModel`], advanced and published on a timer tick, and the driver's statistics
//! ([`DriverStats`]) on `<robot>/driver/0` as every driver publishes them
//! ([`limber_services::diagnostics`]).

use core::ops::ControlFlow;
use std::time::Instant;

use limber_interfaces::common::device_flag;
use limber_interfaces::diagnostics::{self, DriverStats, loop_mode};
use limber_services::diagnostics::{DiagnosticsError, StatsPublisher, put_clients, put_loop};
use limber_services::event_loop::{self, LoopError, LoopExit, Wake};
use limber_services::loop_stats::TickStats;
use limber_services::prelude::*;
use limber_services::{DeviceError, HostError, ProcessError, PublishError, ShareLeaseError, qos};

use limber_kinematics::chain::Chain;

use super::model::{ArmModel, OptionsError, SimArmOptions};

/// Name under which simarm's devices are offered (shown by `limber list`).
pub const DRIVER_NAME: &str = "simarm";

/// The simulated arm could not start or stopped with an error.
#[derive(Debug, thiserror::Error)]
pub enum SimArmError {
    /// The chain file could not be loaded.
    #[error(transparent)]
    Chain(#[from] limber_kinematics::chain::ChainLoadError),
    /// The options (tick, time scale, object) are invalid.
    #[error("invalid simarm options: {0}")]
    Options(#[from] OptionsError),
    /// A device could not be offered (another driver serves it?).
    #[error(transparent)]
    Host(#[from] HostError),
    /// A state could not be published.
    #[error(transparent)]
    Publish(#[from] DeviceError<PublishError>),
    /// The arm's devices could not be made to share one lease.
    #[error(transparent)]
    ShareLease(#[from] ShareLeaseError),
    /// Commands or requests could not be received.
    #[error(transparent)]
    Process(#[from] DeviceError<ProcessError>),
    /// The driver statistics could not be offered or first published.
    #[error("cannot publish the simarm driver statistics: {0}")]
    Stats(#[source] DiagnosticsError),
    /// The event loop failed.
    #[error(transparent)]
    Loop(#[from] LoopError),
}

/// The handler of the three devices (each index 0): borrows the model for one `process`
/// call; every answer also refreshes the device's state in place.
struct Serve<'a>(&'a mut ArmModel);

impl DeviceSetHandler for Serve<'_> {
    fn actarray_motion(&mut self, _: u16, cmd: &ActArrayCommand, _: &ActArrayData) -> Motion {
        self.0.arm_motion(cmd)
    }
    fn actarray_stop(&mut self, _: u16, state: &mut ActArrayData) -> Status {
        let s = self.0.stop_arm();
        self.0.arm_state(state);
        s
    }
    fn actarray_progress(&mut self, _: u16, part: u32, _: &ActArrayData) -> Progress {
        self.0.arm_progress(part)
    }
    fn limb_motion(&mut self, _: u16, cmd: &LimbCommand, _: &LimbData) -> Motion {
        self.0.limb_motion(cmd)
    }
    fn limb_progress(&mut self, _: u16, part: u32, _: &LimbData) -> Progress {
        self.0.limb_progress(part)
    }
    fn limb_stop(&mut self, _: u16, state: &mut LimbData) -> Status {
        let s = self.0.stop_limb();
        self.0.limb_state(state);
        s
    }
    fn gripper_motion(&mut self, _: u16, cmd: &GripperCommand, _: &GripperData) -> Motion {
        self.0.gripper_motion(cmd)
    }
    fn gripper_progress(&mut self, _: u16, _: u32, _: &GripperData) -> Progress {
        self.0.gripper_progress()
    }
    fn gripper_stop(&mut self, _: u16, state: &mut GripperData) -> Status {
        let s = self.0.stop_gripper();
        self.0.gripper_state(state);
        s
    }
    fn actarray_command(
        &mut self,
        _: u16,
        cmd: &ActArrayCommand,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Status {
        let s = match self
            .0
            .trajectory_command(cmd, from.client_id, monotonic_ns())
        {
            Some(s) => s,
            None => self.0.arm_command(cmd),
        };
        self.0.arm_state(state);
        s
    }
    fn actarray_request(
        &mut self,
        _: u16,
        req: &ActArrayRequest,
        _: &Origin,
        state: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        let r = self.0.arm_request(req);
        self.0.arm_state(state);
        r
    }
    fn limb_command(
        &mut self,
        _: u16,
        cmd: &LimbCommand,
        _: &Origin,
        state: &mut LimbData,
    ) -> Status {
        let s = self.0.limb_command(cmd);
        self.0.limb_state(state);
        s
    }
    fn limb_request(
        &mut self,
        _: u16,
        req: &LimbRequest,
        _: &Origin,
        state: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        let r = self.0.limb_request(req);
        self.0.limb_state(state);
        r
    }
    fn gripper_command(
        &mut self,
        _: u16,
        cmd: &GripperCommand,
        _: &Origin,
        state: &mut GripperData,
    ) -> Status {
        let s = self.0.gripper_command(cmd);
        self.0.gripper_state(state);
        s
    }
    fn gripper_request(
        &mut self,
        _: u16,
        req: &GripperRequest,
        _: &Origin,
        state: &mut GripperData,
    ) -> Result<GripperReply, Status> {
        let r = self.0.gripper_request(req);
        self.0.gripper_state(state);
        r
    }
}

/// What [`SimArm::run`] survived: failures it skipped, each retried at the next wake-up
/// or tick. Each is logged too (a warning when a run of failures starts, debug while it
/// repeats).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct SimArmFailures {
    /// Wake-ups whose commands or requests could not all be received
    /// ([`SimArm::process`] failed).
    pub process: u64,
    /// Ticks whose states could not all be published ([`SimArm::publish_all`] failed).
    pub publish: u64,
    /// Driver statistics that could not be published (retried a second later).
    pub stats: u64,
}

/// The flags of every state simarm publishes: a simulation whose "link" is always up and
/// whose joints are calibrated.
const FLAGS: u32 = device_flag::SIMULATED | device_flag::LINK_UP | device_flag::CALIBRATED;

/// The simulated arm: serves `<robot>/actarray/0` (the chain's joints, then the gripper
/// opening as the last actuator), `<robot>/limb/0` and `<robot>/gripper/0`, every
/// state flagged [`device_flag::SIMULATED`], and publishes its [`DriverStats`] on
/// `<robot>/driver/0` (`limber echo <robot>/driver`): at start, then about once a second
/// while it [runs](Self::run).
pub struct SimArm {
    model: ArmModel,
    hosts: DeviceSet,
    last: Instant,
    failures: SimArmFailures,
    ticks: TickStats,
    stats_pub: StatsPublisher,
    stats: DriverStats,
}

impl core::fmt::Debug for SimArm {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SimArm")
            .field("chain", &self.model.chain().name())
            .field("robot", &self.model.options().robot)
            .finish()
    }
}

impl SimArm {
    /// Offers the three devices of `options.robot` for `chain` in the context's domain
    /// (the arm at home, the gripper open, powered) and publishes their first states.
    pub fn new(ctx: &Context, chain: Chain, options: SimArmOptions) -> Result<Self, SimArmError> {
        let robot = options.robot.clone();
        let model = ArmModel::new(chain, options)?;
        let devices = [
            (InterfaceKind::ActArray, 0),
            (InterfaceKind::Limb, 0),
            (InterfaceKind::Gripper, 0),
        ];
        let mut hosts = DeviceSet::new(ctx, &robot, DRIVER_NAME, &devices)?;
        // The joints, the end effector and the gripper are one arm: one lease holds them.
        hosts.share_lease(&devices)?;
        hosts.set_flags(FLAGS);
        // After the devices: a robot name another driver serves is refused before this.
        let stats_pub = StatsPublisher::new(ctx, &robot).map_err(SimArmError::Stats)?;
        let mut stats = DriverStats::default();
        diagnostics::put_text(&mut stats.driver, DRIVER_NAME);
        diagnostics::put_text(&mut stats.robot_name, &robot);
        // A simulation has no link: its header says LINK_UP (as its devices' states do) and
        // SIMULATED; the robot's class, subclass and hardware bits, the link's and the
        // command-to-wire fields stay empty and zero.
        stats.header.flags = device_flag::SIMULATED | device_flag::LINK_UP;
        let mut s = SimArm {
            model,
            hosts,
            last: Instant::now(),
            failures: SimArmFailures::default(),
            ticks: TickStats::default(),
            stats_pub,
            stats,
        };
        s.publish_all()?;
        s.publish_stats().map_err(SimArmError::Stats)?;
        Ok(s)
    }

    /// The simulation (read-only: joint values, gripper, object).
    pub fn model(&self) -> &ArmModel {
        &self.model
    }

    /// The timer cycles of [`run`](Self::run): periods between ticks, their jitter, overruns
    /// (the latest 512, as every driver keeps them).
    pub fn tick_stats(&self) -> &TickStats {
        &self.ticks
    }

    /// The driver statistics as last published (the sequence number of the header counts
    /// the publications).
    pub fn driver_stats(&self) -> &DriverStats {
        &self.stats
    }

    /// Fills the driver statistics from the loop's timer cycles and the devices' counters
    /// and publishes them.
    fn publish_stats(&mut self) -> Result<(), DiagnosticsError> {
        put_loop(&mut self.stats, loop_mode::EVENT, &self.ticks);
        put_clients(&mut self.stats, &self.hosts.stats());
        self.stats_pub.publish(&mut self.stats)
    }

    /// The failures [`run`](Self::run) survived so far.
    pub fn failures(&self) -> SimArmFailures {
        self.failures
    }

    /// Advances the simulation to now (real time since the last call, times the time
    /// scale).
    pub fn advance(&mut self) {
        let now = Instant::now();
        let dt = now.duration_since(self.last).as_secs_f64();
        self.last = now;
        self.model.advance(dt);
        self.model.step_trajectory(monotonic_ns());
    }

    /// Fills and publishes the state of all three devices.
    pub fn publish_all(&mut self) -> Result<(), DeviceError<PublishError>> {
        if let Some(h) = self.hosts.actarray_mut(0) {
            self.model.arm_state(h.state_mut());
        }
        if let Some(h) = self.hosts.limb_mut(0) {
            self.model.limb_state(h.state_mut());
        }
        if let Some(h) = self.hosts.gripper_mut(0) {
            self.model.gripper_state(h.state_mut());
        }
        self.hosts.publish_all(monotonic_ns())?;
        // After the states that show them: the results of the motions that ended.
        self.hosts.check_motions(&mut Serve(&mut self.model));
        Ok(())
    }

    /// Handles every pending command and request of the three devices (the simulation
    /// is advanced to now first); never blocks. Returns how many there were.
    pub fn process(&mut self) -> Result<usize, DeviceError<ProcessError>> {
        self.advance();
        let a = self.hosts.process(&mut Serve(&mut self.model))?;
        Ok(a.total())
    }

    /// Serves until SIGINT/SIGTERM ([`LoopExit::Signal`]) or until `stop` returns true
    /// (checked at every wake-up, [`LoopExit::Stopped`]): advances the simulation and
    /// publishes every device each tick, handles clients as they wake it, and publishes the
    /// driver statistics about once a second. Transient
    /// publish or receive failures are skipped (the next tick retries), counted in
    /// [`failures`](Self::failures) and logged. The wake
    /// listeners move into the loop: a second `run` reacts to clients only on ticks.
    pub fn run(&mut self, mut stop: impl FnMut() -> bool) -> Result<LoopExit, SimArmError> {
        let listeners = self.hosts.take_wake_listeners();
        let tick = self.model.options().tick;
        let nominal = u64::try_from(tick.as_nanos()).unwrap_or(u64::MAX);
        let mut housekeeping = 0u32;
        let (mut process_failing, mut publish_failing, mut stats_failing) = (false, false, false);
        self.last = Instant::now();
        let exit = event_loop::run(&listeners, tick, None, |wake| {
            if let Wake::Tick(expirations) = wake {
                self.ticks.tick(Instant::now(), nominal, expirations);
            }
            match self.process() {
                Ok(n) => {
                    process_failing = false;
                    if n > 0 && matches!(wake, Wake::Clients) {
                        // A client in a tight loop sends its next command within the
                        // linger: picked up without a wake-up. A failure ends the linger;
                        // the next wake-up meets it again and counts it.
                        event_loop::linger(qos::DRIVER_LINGER, || {
                            match self.hosts.process_linger(&mut Serve(&mut self.model)) {
                                Ok(a) => a.total() > 0,
                                Err(e) => {
                                    tracing::debug!(error = %e, "processing while lingering");
                                    false
                                }
                            }
                        });
                    }
                }
                Err(e) => {
                    self.failures.process += 1;
                    let n = self.failures.process;
                    survived(
                        &mut process_failing,
                        "receiving commands and requests",
                        &e,
                        n,
                    );
                }
            }
            if let Wake::Tick(_) = wake {
                match self.publish_all() {
                    Ok(()) => publish_failing = false,
                    Err(e) => {
                        self.failures.publish += 1;
                        let n = self.failures.publish;
                        survived(&mut publish_failing, "publishing the states", &e, n);
                    }
                }
                if self.stats_pub.due(Instant::now()) {
                    match self.publish_stats() {
                        Ok(()) => stats_failing = false,
                        Err(e) => {
                            self.failures.stats += 1;
                            let n = self.failures.stats;
                            survived(
                                &mut stats_failing,
                                "publishing the driver statistics",
                                &e,
                                n,
                            );
                        }
                    }
                }
                housekeeping += 1;
                if u128::from(housekeeping) * tick.as_millis().max(1) >= 1000 {
                    housekeeping = 0;
                    self.hosts.cleanup_dead();
                }
            }
            if stop() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })?;
        Ok(exit)
    }
}

/// Logs a failure the run loop survives: a warning when a run of failures starts, debug
/// while it repeats (the loop retries at every tick, so a lasting fault would flood the
/// log). `count` is the total so far.
fn survived(failing: &mut bool, what: &str, error: &dyn std::error::Error, count: u64) {
    if *failing {
        tracing::debug!(error = %error, count, "simarm: {what} failed again");
    } else {
        tracing::warn!(
            error = %error,
            count,
            "simarm: {what} failed; skipped, retried at the next tick (the statistics a \
             second later)"
        );
    }
    *failing = true;
}
