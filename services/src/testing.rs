//! A small test driver: an arm whose joints reach their targets at once, a limb that
//! accepts poses within a sphere, and a gripper. It implements the same [`DeviceHandler`]
//! traits as real drivers, so tests and examples exercise the real services layer.

use core::ops::ControlFlow;
use core::time::Duration;

use limber_interfaces::prelude::*;
use thiserror::Error;

use crate::context::{Context, monotonic_ns};
use crate::device_set::{DeviceError, DeviceSet, DeviceSetHandler};
use crate::event_loop::{self, LoopError, LoopExit, Wake};
use crate::host::{
    DeviceHandler, DeviceHost, HostError, Motion, Origin, ProcessError, PublishError,
};

/// Joint limits of the test arm, rad.
pub const JOINT_LIMIT: f64 = core::f64::consts::PI;
/// Reach of the test limb, m: farther targets are out of reach.
pub const REACH: f64 = 1.0;

/// The test arm (`actarray`): `n` rotary joints in ±π, moving instantly.
#[derive(Debug, Clone)]
pub struct TestArm {
    /// Number of joints.
    pub joints: usize,
    /// Every command received, in order: (client, seq, kind). Capacity fixed at creation
    /// (further commands are not logged).
    pub log: Vec<(u64, u64, u32)>,
    /// Sleep this long in each request (to test clients that die mid-request).
    pub reply_delay: Duration,
    /// Joints moving at a speed (bit j = joint j): a SPEED command starts a motion that
    /// runs until a SPEED 0, another command of that joint, or a stop.
    pub moving: u32,
}

impl TestArm {
    /// An arm of `joints` joints (at most 32).
    pub fn new(joints: usize) -> Self {
        TestArm {
            joints: joints.min(MAX_ACTUATORS),
            log: Vec::with_capacity(100_000),
            reply_delay: Duration::ZERO,
            moving: 0,
        }
    }

    fn check(&self, joint: usize, v: f64) -> Result<(), Status> {
        if joint >= self.joints {
            Err(Status::UnknownJoint)
        } else if !(-JOINT_LIMIT..=JOINT_LIMIT).contains(&v) {
            Err(Status::BeyondLimits)
        } else {
            Ok(())
        }
    }

    /// Stops joint `j` if it moves at a speed.
    fn halt(&mut self, j: usize, state: &mut ActArrayData) {
        if self.moving & (1 << j) != 0 {
            self.moving &= !(1 << j);
            state.actuators[j].speed = 0.0;
            state.actuators[j].state = ActuatorFlags::IDLE.bits();
        }
    }

    /// The initial state: every joint idle at 0, power off.
    pub fn initial_state(&self, state: &mut ActArrayData) {
        state.actuators_count = self.joints as u32;
        for a in &mut state.actuators[..self.joints] {
            a.state = ActuatorFlags::IDLE.bits();
            a.acceleration = -1.0;
            a.current = -1.0;
        }
    }
}

impl DeviceHandler<ActArray> for TestArm {
    fn command(
        &mut self,
        cmd: &ActArrayCommand,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Status {
        if self.log.len() < self.log.capacity() {
            self.log.push((from.client_id, from.seq, cmd_kind(cmd)));
        }
        let r = match *cmd {
            ActArrayCommand::Position { joint, position } => {
                self.check(joint as usize, position).map(|()| {
                    self.halt(joint as usize, state);
                    state.actuators[joint as usize].position = position;
                })
            }
            ActArrayCommand::Speed { joint, speed } => self.check(joint as usize, 0.0).map(|()| {
                let j = joint as usize;
                self.halt(j, state);
                if speed != 0.0 {
                    self.moving |= 1 << j;
                    state.actuators[j].speed = speed;
                    state.actuators[j].state = ActuatorFlags::MOVING.bits();
                }
            }),
            ActArrayCommand::MultiPosition(v) => {
                if v.len() > self.joints {
                    Err(Status::UnknownJoint)
                } else {
                    v.as_slice()
                        .iter()
                        .enumerate()
                        .try_for_each(|(j, p)| self.check(j, *p))
                        .map(|()| {
                            for (j, p) in v.as_slice().iter().enumerate() {
                                self.halt(j, state);
                                state.actuators[j].position = *p;
                            }
                        })
                }
            }
            ActArrayCommand::Home(JointSel::All) => {
                self.stop(state);
                for a in &mut state.actuators[..self.joints] {
                    a.position = 0.0;
                }
                Ok(())
            }
            ActArrayCommand::Home(JointSel::One(j)) => self.check(j as usize, 0.0).map(|()| {
                self.halt(j as usize, state);
                state.actuators[j as usize].position = 0.0;
            }),
            _ => Err(Status::Unsupported),
        };
        state.header.stamp_ns = monotonic_ns();
        r.err().unwrap_or(Status::Ok)
    }

    fn motion(&mut self, cmd: &ActArrayCommand, _state: &ActArrayData) -> Motion {
        let mask = match *cmd {
            ActArrayCommand::Position { joint, .. }
            | ActArrayCommand::Speed { joint, .. }
            | ActArrayCommand::Home(JointSel::One(joint)) => 1u64.checked_shl(joint as u32),
            ActArrayCommand::MultiPosition(v) | ActArrayCommand::MultiSpeed(v) => {
                Some(1u64.checked_shl(v.len() as u32).map_or(u64::MAX, |b| b - 1))
            }
            ActArrayCommand::Home(JointSel::All) => Some(u64::MAX),
            _ => None,
        };
        Motion::of(mask.unwrap_or(0), self.moving as u64)
    }

    fn stop(&mut self, state: &mut ActArrayData) -> Status {
        for j in 0..self.joints {
            self.halt(j, state);
        }
        state.header.stamp_ns = monotonic_ns();
        Status::Ok
    }

    fn request(
        &mut self,
        req: &ActArrayRequest,
        _from: &Origin,
        state: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        if !self.reply_delay.is_zero() {
            std::thread::sleep(self.reply_delay);
        }
        match *req {
            ActArrayRequest::Power(on) => {
                state.motor_state = on as u32;
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::GetGeom => {
                let mut g = ActArrayGeom {
                    actuators_count: self.joints as u32,
                    ..Default::default()
                };
                for a in &mut g.actuators[..self.joints] {
                    a.kind = ActuatorKind::Rotary as u32;
                    a.min = -JOINT_LIMIT;
                    a.max = JOINT_LIMIT;
                    a.config_speed = 1.0;
                    a.axis = Vec3::new(0.0, 0.0, 1.0);
                }
                Ok(ActArrayReply::Geom(g))
            }
            ActArrayRequest::Speed { joint, .. } | ActArrayRequest::Accel { joint, .. } => {
                if (joint as usize) < self.joints {
                    Ok(ActArrayReply::Done)
                } else {
                    Err(Status::UnknownJoint)
                }
            }
            ActArrayRequest::Brakes(_) => Err(Status::Unsupported),
        }
    }
}

fn cmd_kind(cmd: &ActArrayCommand) -> u32 {
    use limber_interfaces::Message;
    cmd.kind()
}

/// The test limb: accepts any pose within [`REACH`] of the origin.
#[derive(Debug, Clone, Copy, Default)]
pub struct TestLimb;

impl DeviceHandler<Limb> for TestLimb {
    fn stop(&mut self, _state: &mut LimbData) -> Status {
        // Reaches its targets at once: nothing runs on to stop.
        Status::Ok
    }

    fn command(&mut self, cmd: &LimbCommand, _from: &Origin, state: &mut LimbData) -> Status {
        let target = match *cmd {
            LimbCommand::Home => Vec3::new(0.5, 0.0, 0.0),
            LimbCommand::Stop => return Status::Ok,
            LimbCommand::SetPose { position, .. } | LimbCommand::SetPosition { position } => {
                position
            }
            LimbCommand::VecMove { direction, length } => {
                let n = direction.norm();
                let p = state.position;
                Vec3::new(
                    p.x + direction.x / n * length,
                    p.y + direction.y / n * length,
                    p.z + direction.z / n * length,
                )
            }
            // No path checks here: the test limb has no kinematics.
            LimbCommand::Line(_) | LimbCommand::Ptp(_) => return Status::Unsupported,
        };
        if target.norm() > REACH {
            state.state = LimbState::OutOfReach as u32;
            return Status::OutOfReach;
        }
        state.position = target;
        state.state = LimbState::Idle as u32;
        Status::Ok
    }

    fn request(
        &mut self,
        req: &LimbRequest,
        _from: &Origin,
        _state: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        match req {
            LimbRequest::Geom => Ok(LimbReply::Geom(LimbGeom::default())),
            LimbRequest::Power(_) | LimbRequest::Speed(_) => Ok(LimbReply::Done),
            LimbRequest::Brakes(_) => Err(Status::Unsupported),
            // Any pose within reach is held exactly.
            LimbRequest::Reach {
                position,
                approach,
                orientation,
            } => {
                if position.norm() > REACH {
                    return Err(Status::OutOfReach);
                }
                Ok(LimbReply::Reach(LimbReach {
                    position: *position,
                    approach: *approach,
                    orientation: *orientation,
                    ..LimbReach::default()
                }))
            }
        }
    }
}

/// The test gripper: opens and closes at once; cannot store nor go to a gap.
#[derive(Debug, Clone, Copy, Default)]
pub struct TestGripper;

impl DeviceHandler<Gripper> for TestGripper {
    fn command(&mut self, cmd: &GripperCommand, _from: &Origin, state: &mut GripperData) -> Status {
        match cmd {
            GripperCommand::Open => state.state = GripperState::Open as u32,
            GripperCommand::Close => state.state = GripperState::Closed as u32,
            GripperCommand::Stop => {}
            GripperCommand::Store | GripperCommand::Retrieve | GripperCommand::Goal { .. } => {
                return Status::Unsupported;
            }
        }
        Status::Ok
    }

    fn stop(&mut self, _state: &mut GripperData) -> Status {
        // Opens and closes at once: nothing runs on to stop.
        Status::Ok
    }

    fn request(
        &mut self,
        _req: &GripperRequest,
        _from: &Origin,
        _state: &mut GripperData,
    ) -> Result<GripperReply, Status> {
        Ok(GripperReply::Geom(GripperGeom {
            num_beams: 2,
            ..Default::default()
        }))
    }
}

/// The test arm, limb and gripper as one [`DeviceSetHandler`] (each at index 0).
struct Handlers<'a> {
    arm: &'a mut TestArm,
    limb: &'a mut TestLimb,
    gripper: &'a mut TestGripper,
}

impl DeviceSetHandler for Handlers<'_> {
    fn actarray_motion(&mut self, _: u16, cmd: &ActArrayCommand, state: &ActArrayData) -> Motion {
        self.arm.motion(cmd, state)
    }
    fn actarray_stop(&mut self, _: u16, state: &mut ActArrayData) -> Status {
        self.arm.stop(state)
    }
    fn limb_stop(&mut self, _: u16, state: &mut LimbData) -> Status {
        self.limb.stop(state)
    }
    fn gripper_stop(&mut self, _: u16, state: &mut GripperData) -> Status {
        self.gripper.stop(state)
    }
    fn actarray_command(
        &mut self,
        _: u16,
        cmd: &ActArrayCommand,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Status {
        self.arm.command(cmd, from, state)
    }
    fn actarray_request(
        &mut self,
        _: u16,
        req: &ActArrayRequest,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        self.arm.request(req, from, state)
    }
    fn limb_command(
        &mut self,
        _: u16,
        cmd: &LimbCommand,
        from: &Origin,
        state: &mut LimbData,
    ) -> Status {
        self.limb.command(cmd, from, state)
    }
    fn limb_request(
        &mut self,
        _: u16,
        req: &LimbRequest,
        from: &Origin,
        state: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        self.limb.request(req, from, state)
    }
    fn gripper_command(
        &mut self,
        _: u16,
        cmd: &GripperCommand,
        from: &Origin,
        state: &mut GripperData,
    ) -> Status {
        self.gripper.command(cmd, from, state)
    }
    fn gripper_request(
        &mut self,
        _: u16,
        req: &GripperRequest,
        from: &Origin,
        state: &mut GripperData,
    ) -> Result<GripperReply, Status> {
        self.gripper.request(req, from, state)
    }
}

/// The three devices of the test driver, `<robot>/actarray/0`, `<robot>/limb/0`,
/// `<robot>/gripper/0`.
pub struct TestDriver {
    /// The hosts of the three devices.
    pub hosts: DeviceSet,
    /// The arm.
    pub arm: TestArm,
    /// The limb.
    pub limb: TestLimb,
    /// The gripper.
    pub gripper: TestGripper,
}

impl core::fmt::Debug for TestDriver {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("TestDriver")
            .field("arm", &self.arm.joints)
            .finish()
    }
}

/// Creating the test driver failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TestDriverError {
    /// A device could not be offered.
    #[error(transparent)]
    Host(#[from] HostError),
    /// A first state could not be published.
    #[error(transparent)]
    Publish(#[from] DeviceError<PublishError>),
}

impl TestDriver {
    /// Offers the three devices of `robot` with an arm of `joints` joints, and publishes
    /// their initial states.
    pub fn new(ctx: &Context, robot: &str, joints: usize) -> Result<Self, TestDriverError> {
        let mut hosts = DeviceSet::new(
            ctx,
            robot,
            "testdriver",
            &[
                (InterfaceKind::ActArray, 0),
                (InterfaceKind::Limb, 0),
                (InterfaceKind::Gripper, 0),
            ],
        )?;
        let arm = TestArm::new(joints);
        if let Some(h) = hosts.actarray_mut(0) {
            arm.initial_state(h.state_mut());
        }
        if let Some(h) = hosts.limb_mut(0) {
            h.state_mut().state = LimbState::Idle as u32;
        }
        if let Some(h) = hosts.gripper_mut(0) {
            h.state_mut().state = GripperState::Open as u32;
        }
        let mut d = TestDriver {
            hosts,
            arm,
            limb: TestLimb,
            gripper: TestGripper,
        };
        d.publish_all()?;
        Ok(d)
    }

    /// The arm's host.
    pub fn arm_host(&self) -> &DeviceHost<ActArray> {
        self.hosts
            .actarray(0)
            .expect("the test driver serves actarray/0")
    }

    /// Publishes the state of all three devices.
    pub fn publish_all(&mut self) -> Result<(), DeviceError<PublishError>> {
        self.hosts.publish_all(monotonic_ns())
    }

    /// Handles everything pending on the three devices; never blocks.
    pub fn process(&mut self) -> Result<usize, DeviceError<ProcessError>> {
        let mut h = Handlers {
            arm: &mut self.arm,
            limb: &mut self.limb,
            gripper: &mut self.gripper,
        };
        self.hosts.process(&mut h).map(|a| a.total())
    }

    /// Serves until SIGINT/SIGTERM (or `stop` returns true, checked at every wake-up),
    /// publishing every device's state each `period` and handling clients as they wake it.
    /// A failure to publish or process is logged (by the [`DeviceSet`]) and retried at the
    /// next wake-up.
    pub fn run(
        &mut self,
        period: Duration,
        mut stop: impl FnMut() -> bool,
    ) -> Result<LoopExit, LoopError> {
        let listeners = self.hosts.take_wake_listeners();
        event_loop::run(&listeners, period, None, |wake| {
            if let Wake::Tick(_) = wake
                && let Err(e) = self.publish_all()
            {
                tracing::debug!(error = %e, "test driver: publication skipped");
            }
            if let Err(e) = self.process() {
                tracing::debug!(error = %e, "test driver: processing skipped");
            }
            if stop() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
    }
}

/// A test of this test binary run as a process of its own (a test that does nothing unless
/// its variable is set), waited for until it said it is ready.
#[derive(Debug)]
pub struct TestProcess {
    /// The process (its stdin piped: closing it, or a line, tells it to go on).
    pub child: std::process::Child,
    /// Its stdout, after the ready line.
    pub out: std::io::BufReader<std::process::ChildStdout>,
}

impl TestProcess {
    /// Runs the test `name` of this binary with `var` = `value` in its environment, and
    /// reads its stdout until a line starting with `ready`. Panics if it cannot start or
    /// ends before that line.
    pub fn start(name: &str, var: &str, value: &str, ready: &str) -> TestProcess {
        use std::io::BufRead;
        let mut child = std::process::Command::new(std::env::current_exe().expect("this test"))
            .args(["--exact", name, "--nocapture"])
            .env(var, value)
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .expect("the test process starts");
        let mut out = std::io::BufReader::new(child.stdout.take().expect("its stdout"));
        let mut line = String::new();
        loop {
            line.clear();
            match out.read_line(&mut line) {
                Ok(n) if n > 0 && line.starts_with(ready) => return TestProcess { child, out },
                Ok(n) if n > 0 => {}
                ended => {
                    if let Err(e) = child.kill().and_then(|()| child.wait().map(drop)) {
                        tracing::warn!(error = %e, "cannot end test process {name}");
                    }
                    panic!("test process {name} ended before saying {ready:?}: {ended:?}");
                }
            }
        }
    }
}
