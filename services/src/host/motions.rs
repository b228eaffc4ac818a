//! Motions with a result: the host remembers each command carried out that started a
//! motion (the parts it drives), asks the driver how each part is doing
//! ([`DeviceHandler::progress`]), and publishes one result per command on the `outcome`
//! channel when its last part ends (reached, stalled, stopped, preempted, aborted, timed
//! out), with each part's final position and error against the goal.
//!
//! Fixed size, no allocation: at most [`MAX_TRACKED`] motions at once (one per part of a
//! device of up to 32 parts); a command that would be one more ends the oldest's parts as
//! preempted (never reached: the device could not follow it).

use limber_interfaces::prelude::*;

use super::arbiter::CmdRef;
use super::handler::{Motion, Progress, set_bits};
use super::{DeviceHandler, DeviceHost};

/// Motions followed at once per device.
pub const MAX_TRACKED: usize = MAX_ACTUATORS;

/// Parts whose position and error a result carries (a motion's parts beyond are followed
/// but not reported).
const REPORTED: usize = MAX_ACTUATORS;

/// One command's motion while it runs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tracked {
    pub(crate) cmd: CmdRef,
    /// Every part it drove.
    parts: u64,
    /// The parts still running.
    left: u64,
    result: MotionResult,
    /// Why (`Ok` for reached; the cause of an abort; `Preempted` for a preemption).
    cause: Status,
    /// The client whose command preempted or stopped it (0: none).
    other: u64,
    tolerance: f64,
    position: [f64; REPORTED],
    error: [f64; REPORTED],
}

impl Tracked {
    fn new(cmd: CmdRef, parts: u64) -> Self {
        Tracked {
            cmd,
            parts,
            left: parts,
            result: MotionResult::Reached,
            cause: Status::Ok,
            other: 0,
            tolerance: 0.0,
            position: [f64::NAN; REPORTED],
            error: [f64::NAN; REPORTED],
        }
    }

    /// Records where `part` is (its last known position and error).
    fn record(&mut self, part: usize, p: &Progress) {
        if part < REPORTED {
            if !p.position.is_nan() {
                self.position[part] = p.position;
            }
            if !p.error.is_nan() {
                self.error[part] = p.error;
            }
        }
        if p.tolerance > self.tolerance {
            self.tolerance = p.tolerance;
        }
    }

    /// `part` ended with `result` (because of `cause`, by client `other`).
    fn end(&mut self, part: usize, result: MotionResult, cause: Status, other: u64) {
        if self.left & (1 << part) == 0 {
            return;
        }
        self.left &= !(1 << part);
        let combined = self.result.combine(result);
        if combined != self.result {
            self.result = combined;
            self.cause = cause;
            self.other = other;
        } else if result == self.result && self.cause == Status::Ok {
            // The same result with a cause where there was none (a gripper that reached
            // its goal with an object between the fingers: `OBJECT_PRESENT`).
            self.cause = cause;
            self.other = other;
        }
    }

    /// The result sample of a motion that ended.
    pub(crate) fn message(&self) -> OutcomeMsg {
        let n = (64 - self.parts.leading_zeros()).min(REPORTED as u32);
        let mut max_error = f64::NAN;
        for j in 0..n as usize {
            if self.parts & (1 << j) != 0 && !self.error[j].is_nan() {
                let e = self.error[j].abs();
                max_error = if max_error.is_nan() {
                    e
                } else {
                    max_error.max(e)
                };
            }
        }
        if self.parts == 0 {
            max_error = 0.0;
        }
        OutcomeMsg {
            client_id: self.cmd.client_id,
            cmd_seq: self.cmd.seq,
            other_client: self.other,
            kind: self.cmd.kind,
            status: self.cause.code(),
            result: self.result.code(),
            parts: n,
            max_error,
            tolerance: self.tolerance,
            position: self.position,
            error: self.error,
            ..OutcomeMsg::default()
        }
    }
}

/// The motions of one device.
#[derive(Debug)]
pub(crate) struct Motions {
    slots: [Option<Tracked>; MAX_TRACKED],
    /// Order of arrival, to pick the oldest when full.
    age: [u64; MAX_TRACKED],
    next_age: u64,
}

impl Motions {
    pub(crate) fn new() -> Self {
        Motions {
            slots: [None; MAX_TRACKED],
            age: [0; MAX_TRACKED],
            next_age: 0,
        }
    }

    /// The parts of some motion still running.
    pub(crate) fn running(&self) -> u64 {
        self.slots.iter().flatten().fold(0, |m, t| m | t.left)
    }

    /// Records, for each running part of `parts`, where the driver says it is.
    fn record_parts(&mut self, parts: u64, mut at: impl FnMut(usize) -> Progress) {
        for t in self.slots.iter_mut().flatten() {
            for part in set_bits(t.left & parts) {
                let p = at(part);
                t.record(part, &p);
            }
        }
    }

    /// Ends every running part of `parts` with `result` (by `cause`, client `other`).
    pub(crate) fn end_parts(
        &mut self,
        parts: u64,
        result: MotionResult,
        cause: Status,
        other: u64,
    ) {
        for t in self.slots.iter_mut().flatten() {
            for part in set_bits(t.left & parts) {
                t.end(part, result, cause, other);
            }
        }
    }

    /// A command carried out, driving `motion`: the motions of its parts end (preempted,
    /// or stopped by a stop), and it is followed from now on (a stop, or a command that
    /// drives nothing, ends at once, reached).
    fn start(&mut self, cmd: CmdRef, motion: Motion) -> Option<Tracked> {
        let (result, cause) = if motion.stop {
            (MotionResult::Stopped, Status::Ok)
        } else {
            (MotionResult::Preempted, Status::Preempted)
        };
        self.end_parts(motion.drives, result, cause, cmd.client_id);
        let (slot, given_up) = match self.slots.iter().position(Option::is_none) {
            Some(i) => (i, None),
            None => {
                // Full: the oldest is given up (its parts preempted by this one), and
                // returned for its result to be published.
                let oldest = (0..MAX_TRACKED).min_by_key(|&i| self.age[i]).unwrap_or(0);
                let mut old = self.slots[oldest].take();
                if let Some(t) = old.as_mut() {
                    for part in set_bits(t.left) {
                        t.end(
                            part,
                            MotionResult::Preempted,
                            Status::Preempted,
                            cmd.client_id,
                        );
                    }
                }
                (oldest, old)
            }
        };
        // A stop is not followed: it ends at once (what it stopped says so).
        let parts = if motion.stop { 0 } else { motion.drives };
        self.slots[slot] = Some(Tracked::new(cmd, parts));
        self.next_age += 1;
        self.age[slot] = self.next_age;
        given_up
    }

    /// Takes the motion of `cmd` if it has ended already (a command that drives nothing
    /// that runs on, or a stop, ends when it is carried out).
    pub(crate) fn take_ended_of(&mut self, cmd: CmdRef) -> Option<Tracked> {
        let i = self
            .slots
            .iter()
            .position(|t| t.is_some_and(|t| t.cmd == cmd && t.left == 0))?;
        self.slots[i].take()
    }

    /// Takes the motions that ended (every part), oldest first, one at a time.
    pub(crate) fn take_ended(&mut self) -> Option<Tracked> {
        let i = (0..MAX_TRACKED)
            .filter(|&i| self.slots[i].is_some_and(|t| t.left == 0))
            .min_by_key(|&i| self.age[i])?;
        self.slots[i].take()
    }
}

impl<I: Interface> DeviceHost<I> {
    /// Before a command is carried out: where each running part it drives is now (the
    /// final position and error of the motion it may cut short).
    pub(super) fn record_before<H: DeviceHandler<I>>(&mut self, handler: &mut H, motion: Motion) {
        let state = &self.state;
        self.motions
            .record_parts(motion.drives, |part| handler.progress(part as u32, state));
    }

    /// A command carried out: follows its motion (see [`Motions::start`]).
    pub(super) fn motion_started(&mut self, cmd: CmdRef, motion: Motion) {
        if let Some(t) = self.motions.start(cmd, motion) {
            tracing::debug!(device = %self.device, client = t.cmd.client_id, seq = t.cmd.seq,
                "motion table full: the oldest motion was given up");
            self.publish_one(&t);
        }
    }

    /// Asks the driver how each running part is doing ([`DeviceHandler::progress`]), and
    /// publishes the result of each motion whose last part ended. A driver calls it after
    /// publishing the state (so a client that has the result and takes the state sees the
    /// motion's end); [`DeviceSet::check_motions`](crate::DeviceSet::check_motions) does it
    /// for every device of a set.
    pub fn check_motions<H: DeviceHandler<I>>(&mut self, handler: &mut H) {
        let running = self.motions.running();
        if running != 0 {
            let state = &self.state;
            for t in self.motions.slots.iter_mut().flatten() {
                for part in set_bits(t.left) {
                    let p = handler.progress(part as u32, state);
                    t.record(part, &p);
                    if let Some((result, cause)) = p.end {
                        t.end(part, result, cause, 0);
                    }
                }
            }
        }
        self.publish_results();
    }

    /// Every running motion ends with `result` because of `cause` (e.g. the deadman's
    /// stop), and its result is published.
    pub fn end_motions(&mut self, result: MotionResult, cause: Status) {
        self.motions.end_parts(u64::MAX, result, cause, 0);
        self.publish_results();
    }

    /// The parts of some motion still running (bit i: part i).
    pub fn running_parts(&self) -> u64 {
        self.motions.running()
    }

    /// Publishes the result of every motion that ended.
    pub(super) fn publish_results(&mut self) {
        let mut any = false;
        while let Some(t) = self.motions.take_ended() {
            self.publish_one(&t);
            any = true;
        }
        if any {
            self.notify_clients(crate::qos::EVENT_STATE);
        }
    }

    /// Publishes the result of one motion.
    fn publish_one(&mut self, t: &Tracked) {
        self.out.publish(&mut self.stats, &self.device, t.message());
        self.stats.results += 1;
    }

    /// The command `cmd` carried out with `STATUS_OK` just now: if its result is decided
    /// already (it drives nothing that runs on, or it is a stop), publishes one sample, its
    /// result and its outcome at once ([`OutcomeMsg::also_outcome`]), and returns true;
    /// else false (its outcome is to be published on its own). One sample where there were
    /// two: a send and a wake-up less on the command's path.
    pub(super) fn publish_decided(&mut self, cmd: CmdRef) -> bool {
        let Some(t) = self.motions.take_ended_of(cmd) else {
            return false;
        };
        let mut msg = t.message();
        msg.also_outcome = 1;
        self.out.publish(&mut self.stats, &self.device, msg);
        self.stats.results += 1;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(client: u64, seq: u64) -> CmdRef {
        CmdRef {
            client_id: client,
            seq,
            kind: 1,
        }
    }

    #[test]
    fn a_motion_ends_reached_when_every_part_does() {
        let mut m = Motions::new();
        m.start(cmd(1, 1), Motion::of(0b11, 0));
        m.end_parts(0b01, MotionResult::Reached, Status::Ok, 0);
        assert!(m.take_ended().is_none());
        m.end_parts(0b10, MotionResult::Reached, Status::Ok, 0);
        let t = m.take_ended().unwrap();
        assert_eq!(t.result, MotionResult::Reached);
        assert_eq!(t.message().parts, 2);
    }

    #[test]
    fn a_new_motion_of_a_part_preempts_the_old_one_a_stop_stops_it() {
        let mut m = Motions::new();
        m.start(cmd(1, 1), Motion::of(0b1, 0));
        m.start(cmd(1, 2), Motion::of(0b1, 0b1));
        let t = m.take_ended().unwrap();
        assert_eq!((t.cmd, t.result), (cmd(1, 1), MotionResult::Preempted));
        m.start(cmd(2, 1), Motion::of(0b1, 0b1).stopping());
        let t = m.take_ended().unwrap();
        assert_eq!(
            (t.cmd, t.result, t.other),
            (cmd(1, 2), MotionResult::Stopped, 2)
        );
        // The stop itself ends at once.
        assert_eq!(m.running(), 0);
        assert_eq!(m.take_ended().unwrap().cmd, cmd(2, 1));
    }

    #[test]
    fn the_worst_part_decides_and_a_command_driving_nothing_is_reached_at_once() {
        let mut m = Motions::new();
        m.start(cmd(1, 1), Motion::of(0b11, 0));
        m.end_parts(0b01, MotionResult::Reached, Status::Ok, 0);
        m.end_parts(0b10, MotionResult::Aborted, Status::LinkDown, 0);
        let t = m.take_ended().unwrap();
        assert_eq!(
            (t.result, t.cause),
            (MotionResult::Aborted, Status::LinkDown)
        );
        m.start(cmd(1, 2), Motion::NONE);
        assert!(m.take_ended_of(cmd(1, 3)).is_none());
        let t = m.take_ended_of(cmd(1, 2)).unwrap();
        assert!(m.take_ended().is_none());
        assert_eq!(
            (t.result, t.message().max_error),
            (MotionResult::Reached, 0.0)
        );
    }
}
