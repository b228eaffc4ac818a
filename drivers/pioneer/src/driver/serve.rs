//! Device routing: the handler of every device ([`DeviceSetHandler`]) hands each command
//! and request to the robot model and writes what the model queued to the link before the
//! outcome is given, so a write that fails is the command's outcome (LINK_DOWN).

use std::time::Instant;

use limber_interfaces::prelude::*;
use limber_p2os::Connection;
use limber_services::{DeviceSetHandler, Motion, Origin, Progress, monotonic_ns};

use crate::config::GripperGeometry;
use crate::robot::RobotModel;
use crate::stats::LoopStats;

/// Writes the model's outbox to the link, oldest first, timing each write for the
/// statistics. A write that fails drops the rest (the model forgets what they would have
/// started) and is `Err(LinkDown)`; the loop notices the dead link (read error or silence)
/// and reconnects.
pub(super) fn flush(
    robot: &mut RobotModel,
    conn: Option<&mut Connection>,
    stats: &mut LoopStats,
) -> Result<(), Status> {
    if robot.outbox().is_empty() {
        return Ok(());
    }
    let Some(conn) = conn else {
        // The model queues nothing while the link is down; never written later.
        let dropped = robot.link_down();
        tracing::warn!("{dropped} commands queued without a link were dropped");
        return Err(Status::LinkDown);
    };
    while let Some(q) = robot.outbox_mut().pop() {
        let from = q.from;
        let before = if from.received_ns != 0 {
            monotonic_ns()
        } else {
            0
        };
        let sent = conn.send(&q.cmd);
        // Read right after the write: the stages end when the bytes are on the wire.
        let now = monotonic_ns();
        if let Err(e) = sent {
            tracing::warn!("cannot send {:?} to the robot: {e}", q.cmd);
            robot.write_failed(&q);
            return Err(Status::LinkDown);
        }
        if from.sent_ns != 0 {
            stats.cmd_to_wire.push(now.saturating_sub(from.sent_ns));
        }
        if from.received_ns != 0 {
            stats
                .arrival_to_wire
                .push(now.saturating_sub(from.received_ns));
            stats.link_write.push(now.saturating_sub(before));
            stats
                .arrival_to_send
                .push(before.saturating_sub(from.received_ns));
        }
    }
    Ok(())
}

/// True for the statuses of a command carried out (a failed write turns them into
/// LINK_DOWN; a refusal keeps its own cause).
fn carried_out(s: Status) -> bool {
    matches!(s, Status::Ok | Status::Clamped | Status::Adjusted)
}

/// The handler of every device: borrows the robot model, the link and the loop's
/// statistics for the duration of a `process` call. `actarray/0` is the arm,
/// `actarray/1` the lift, `gripper/0` the body gripper and `gripper/1` the arm gripper.
pub(super) struct Serve<'a> {
    pub(super) robot: &'a mut RobotModel,
    pub(super) conn: Option<&'a mut Connection>,
    pub(super) stats: &'a mut LoopStats,
}

impl Serve<'_> {
    /// Writes what the model queued; a command carried out whose bytes could not be
    /// written is LINK_DOWN.
    fn done(&mut self, st: Status) -> Status {
        match flush(self.robot, self.conn.as_deref_mut(), self.stats) {
            Err(e) if carried_out(st) => e,
            _ => st,
        }
    }

    /// [`Serve::done`] for a request.
    fn answered<T>(&mut self, r: Result<T, Status>) -> Result<T, Status> {
        let w = flush(self.robot, self.conn.as_deref_mut(), self.stats);
        match (r, w) {
            (Ok(_), Err(e)) => Err(e),
            (r, _) => r,
        }
    }
}

impl DeviceSetHandler for Serve<'_> {
    fn actarray_motion(&mut self, index: u16, cmd: &ActArrayCommand, _s: &ActArrayData) -> Motion {
        if index == 0 {
            self.robot.arm_motion(cmd)
        } else {
            self.robot.lift_motion()
        }
    }
    fn actarray_stop(&mut self, index: u16, _s: &mut ActArrayData) -> Status {
        let st = if index == 0 {
            self.robot.arm_stop()
        } else {
            self.robot.lift_stop()
        };
        self.done(st)
    }
    fn actarray_progress(&mut self, index: u16, part: u32, _s: &ActArrayData) -> Progress {
        if index == 0 {
            self.robot.arm_progress(part)
        } else {
            self.robot.lift_progress()
        }
    }
    fn limb_motion(&mut self, _index: u16, cmd: &LimbCommand, _s: &LimbData) -> Motion {
        self.robot.limb_motion(cmd)
    }
    fn limb_progress(&mut self, _index: u16, part: u32, _s: &LimbData) -> Progress {
        self.robot.limb_progress(part)
    }
    fn gripper_progress(&mut self, index: u16, _part: u32, _s: &GripperData) -> Progress {
        if index == 0 {
            self.robot.gripper_progress()
        } else {
            self.robot.armgrip_progress()
        }
    }
    fn limb_stop(&mut self, _index: u16, _s: &mut LimbData) -> Status {
        let st = self.robot.arm_stop();
        self.done(st)
    }
    fn gripper_motion(&mut self, index: u16, cmd: &GripperCommand, _s: &GripperData) -> Motion {
        let m = if index == 0 {
            self.robot.gripper_motion()
        } else {
            self.robot.armgrip_motion()
        };
        if *cmd == GripperCommand::Stop {
            m.stopping()
        } else {
            m
        }
    }
    fn gripper_stop(&mut self, index: u16, _s: &mut GripperData) -> Status {
        let st = if index == 0 {
            self.robot.gripper_stop()
        } else {
            self.robot.armgrip_stop()
        };
        self.done(st)
    }
    fn actarray_command(
        &mut self,
        index: u16,
        cmd: &ActArrayCommand,
        from: &Origin,
        s: &mut ActArrayData,
    ) -> Status {
        if index == 0 {
            let st = self.robot.arm_command(cmd, from);
            let st = self.done(st);
            // The state sent with the outcome shows the command: a joint given a new
            // target is MOVING from now on, not from the next ARMpac.
            self.robot.arm_state(s, Instant::now());
            st
        } else {
            let st = self.robot.lift_command(cmd, from);
            let st = self.done(st);
            self.robot.lift_state(s);
            st
        }
    }
    fn actarray_request(
        &mut self,
        index: u16,
        req: &ActArrayRequest,
        from: &Origin,
        s: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        let r = if index == 0 {
            self.robot.arm_request(req, from)
        } else {
            self.robot.lift_request(req)
        };
        let r = self.answered(r);
        // The state sent before the reply shows what the request did (a POWER: the motor
        // state asked for).
        if index == 0 {
            self.robot.arm_state(s, Instant::now());
        } else {
            self.robot.lift_state(s);
        }
        r
    }
    fn limb_command(
        &mut self,
        _index: u16,
        cmd: &LimbCommand,
        from: &Origin,
        s: &mut LimbData,
    ) -> Status {
        let st = self.robot.limb_command(cmd, from);
        let st = self.done(st);
        self.robot.limb_state(s, Instant::now());
        st
    }
    fn limb_request(
        &mut self,
        _index: u16,
        req: &LimbRequest,
        from: &Origin,
        s: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        let r = self.robot.limb_request(req, from);
        let r = self.answered(r);
        self.robot.limb_state(s, Instant::now());
        r
    }
    fn gripper_command(
        &mut self,
        index: u16,
        cmd: &GripperCommand,
        from: &Origin,
        s: &mut GripperData,
    ) -> Status {
        let st = if index == 0 {
            self.robot.gripper_command(cmd, from)
        } else {
            self.robot.armgrip_command(cmd, from)
        };
        let st = self.done(st);
        if index == 1 {
            self.robot.armgrip_state(s, Instant::now());
        }
        st
    }
    fn gripper_request(
        &mut self,
        index: u16,
        _req: &GripperRequest,
        _from: &Origin,
        _s: &mut GripperData,
    ) -> Result<GripperReply, Status> {
        let cfg = self.robot.config();
        let geom = if index == 0 {
            gripper_geom(&cfg.gripper, 2)
        } else {
            gripper_geom(&cfg.arm_gripper, 0)
        };
        Ok(GripperReply::Geom(geom))
    }
}

/// A gripper's geometry from the configuration, with `beams` break beams.
fn gripper_geom(g: &GripperGeometry, beams: u32) -> GripperGeom {
    GripperGeom {
        pose: Pose3 {
            position: Vec3::new(g.pose[0], g.pose[1], g.pose[2]),
            orientation: Orientation3 {
                roll: g.pose[3],
                pitch: g.pose[4],
                yaw: g.pose[5],
            },
        },
        outer_size: Bbox3 {
            width: g.outer[0],
            length: g.outer[1],
            height: g.outer[2],
        },
        inner_size: Bbox3 {
            width: g.inner[0],
            length: g.inner[1],
            height: g.inner[2],
        },
        num_beams: beams,
        capacity: 0,
    }
}
