//! The simulated arm on the services layer: three [`DeviceHost`]s around one
//! [`ArmModel`], advanced and published on a timer tick.

use core::ops::ControlFlow;
use std::time::Instant;

use limber_interfaces::common::device_flag;
use limber_services::event_loop::{self, LoopError, LoopExit, Wake};
use limber_services::prelude::*;
use limber_services::{HostError, ProcessError, PublishError};

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
    /// The robot name does not make valid device names.
    #[error("invalid robot name {robot:?}: {reason}")]
    RobotName {
        /// The name.
        robot: String,
        /// Why.
        reason: String,
    },
    /// The domain or the driver context could not be set up.
    #[error("cannot join the domain: {0}")]
    Setup(String),
    /// A device could not be offered (another driver serves it?).
    #[error(transparent)]
    Host(#[from] HostError),
    /// A state could not be published.
    #[error(transparent)]
    Publish(#[from] PublishError),
    /// Commands or requests could not be received.
    #[error(transparent)]
    Process(#[from] ProcessError),
    /// The event loop failed.
    #[error(transparent)]
    Loop(#[from] LoopError),
}

struct ArmH<'a>(&'a mut ArmModel);
struct LimbH<'a>(&'a mut ArmModel);
struct GripH<'a>(&'a mut ArmModel);

impl DeviceHandler<ActArray> for ArmH<'_> {
    fn command(&mut self, cmd: &ActArrayCommand, _: &Origin, state: &mut ActArrayData) -> Status {
        let s = self.0.arm_command(cmd);
        self.0.arm_state(state);
        s
    }
    fn request(
        &mut self,
        req: &ActArrayRequest,
        _: &Origin,
        state: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        let r = self.0.arm_request(req);
        self.0.arm_state(state);
        r
    }
}

impl DeviceHandler<Limb> for LimbH<'_> {
    fn command(&mut self, cmd: &LimbCommand, _: &Origin, state: &mut LimbData) -> Status {
        let s = self.0.limb_command(cmd);
        self.0.limb_state(state);
        s
    }
    fn request(
        &mut self,
        req: &LimbRequest,
        _: &Origin,
        state: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        let r = self.0.limb_request(req);
        self.0.limb_state(state);
        r
    }
}

impl DeviceHandler<Gripper> for GripH<'_> {
    fn command(&mut self, cmd: &GripperCommand, _: &Origin, state: &mut GripperData) -> Status {
        let s = self.0.gripper_command(cmd);
        self.0.gripper_state(state);
        s
    }
    fn request(
        &mut self,
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
}

/// The simulated arm: serves `<robot>/actarray/0` (the chain's joints, then the gripper
/// opening as the last actuator), `<robot>/limb/0` and `<robot>/gripper/0`, every
/// state flagged [`device_flag::SIMULATED`].
pub struct SimArm {
    model: ArmModel,
    arm_host: DeviceHost<ActArray>,
    limb_host: DeviceHost<Limb>,
    gripper_host: DeviceHost<Gripper>,
    last: Instant,
    failures: SimArmFailures,
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
        let name = |i: InterfaceKind| {
            DeviceName::new(&robot, i, 0).map_err(|e| SimArmError::RobotName {
                robot: robot.clone(),
                reason: e.to_string(),
            })
        };
        let mut arm_host =
            DeviceHost::<ActArray>::new(ctx, &name(InterfaceKind::ActArray)?, DRIVER_NAME)?;
        let mut limb_host = DeviceHost::<Limb>::new(ctx, &name(InterfaceKind::Limb)?, DRIVER_NAME)?;
        let mut gripper_host =
            DeviceHost::<Gripper>::new(ctx, &name(InterfaceKind::Gripper)?, DRIVER_NAME)?;
        let flags = device_flag::SIMULATED | device_flag::LINK_UP | device_flag::CALIBRATED;
        arm_host.set_flags(flags);
        limb_host.set_flags(flags);
        gripper_host.set_flags(flags);
        let mut s = SimArm {
            model,
            arm_host,
            limb_host,
            gripper_host,
            last: Instant::now(),
            failures: SimArmFailures::default(),
        };
        s.publish_all()?;
        Ok(s)
    }

    /// The simulation (read-only: joint values, gripper, object).
    pub fn model(&self) -> &ArmModel {
        &self.model
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
    }

    /// Fills and publishes the state of all three devices.
    pub fn publish_all(&mut self) -> Result<(), PublishError> {
        self.model.arm_state(self.arm_host.state_mut());
        self.model.limb_state(self.limb_host.state_mut());
        self.model.gripper_state(self.gripper_host.state_mut());
        let now = monotonic_ns();
        self.arm_host.publish_acquired(now)?;
        self.limb_host.publish_acquired(now)?;
        self.gripper_host.publish_acquired(now)
    }

    /// Handles every pending command and request of the three devices (the simulation
    /// is advanced to now first); never blocks. Returns how many there were.
    pub fn process(&mut self) -> Result<usize, ProcessError> {
        self.advance();
        let a = self.arm_host.process(&mut ArmH(&mut self.model))?;
        let l = self.limb_host.process(&mut LimbH(&mut self.model))?;
        let g = self.gripper_host.process(&mut GripH(&mut self.model))?;
        Ok(a.commands + a.requests + l.commands + l.requests + g.commands + g.requests)
    }

    /// Serves until SIGINT/SIGTERM ([`LoopExit::Signal`]) or until `stop` returns true
    /// (checked at every wake-up, [`LoopExit::Stopped`]): advances the simulation and
    /// publishes every device each tick, handles clients as they wake it. Transient
    /// publish or receive failures are skipped (the next tick retries), counted in
    /// [`failures`](Self::failures) and logged. The wake
    /// listeners move into the loop: a second `run` reacts to clients only on ticks.
    pub fn run(&mut self, mut stop: impl FnMut() -> bool) -> Result<LoopExit, SimArmError> {
        let listeners: Vec<_> = [
            self.arm_host.take_wake_listener(),
            self.limb_host.take_wake_listener(),
            self.gripper_host.take_wake_listener(),
        ]
        .into_iter()
        .flatten()
        .collect();
        let tick = self.model.options().tick;
        let mut housekeeping = 0u32;
        let (mut process_failing, mut publish_failing) = (false, false);
        self.last = Instant::now();
        let exit = event_loop::run(&listeners, tick, None, |wake| {
            match self.process() {
                Ok(_) => process_failing = false,
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
                housekeeping += 1;
                if u128::from(housekeeping) * tick.as_millis().max(1) >= 1000 {
                    housekeeping = 0;
                    self.arm_host.cleanup_dead();
                    self.limb_host.cleanup_dead();
                    self.gripper_host.cleanup_dead();
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
            "simarm: {what} failed; skipped, retried at the next tick"
        );
    }
    *failing = true;
}
