//! What a driver implements: [`DeviceHandler`], with the [`Origin`] of each message and the
//! [`Motion`] a command drives, and the [`Progress`] of a motion.

use limber_interfaces::prelude::*;

/// Who sent a command or request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Origin {
    /// The client's id.
    pub client_id: u64,
    /// The client's sequence number of this message.
    pub seq: u64,
    /// When the client sent it (`CLOCK_MONOTONIC` ns).
    pub sent_ns: u64,
    /// When the driver took it from the channel (`CLOCK_MONOTONIC` ns; 0 for the driver's
    /// own commands): what the driver does from here on is its own cost.
    pub received_ns: u64,
}

/// What a driver implements for each interface it serves: `DeviceHandler<ActArray>`,
/// `DeviceHandler<Limb>`, `DeviceHandler<Gripper>`. The Pioneer driver, the simulated arm
/// and test doubles plug into a [`DeviceHost`](super::DeviceHost) the same way.
pub trait DeviceHandler<I: Interface> {
    /// Carries out (or refuses) a validated command; `state` is the device state the host
    /// publishes next. The returned status reaches the sender in the next state sample's
    /// `last_cmd`. Must not block.
    fn command(&mut self, cmd: &I::Command, from: &Origin, state: &mut I::Data) -> Status;

    /// Answers a validated request: `Ok` is an ACK with that payload, `Err` a NACK with
    /// the reason. Must not block.
    fn request(
        &mut self,
        req: &I::Request,
        from: &Origin,
        state: &mut I::Data,
    ) -> Result<I::Reply, Status>;

    /// Asked before `cmd` is carried out: which parts of the device it drives, and which
    /// of those are still moving from an earlier command (a new motion of the same joints
    /// or a stop cuts that one short). The host remembers which client's command drives
    /// each part and tells a client whose motion another client's command cut short that
    /// it was [`Status::Preempted`]. Default: [`Motion::NONE`] (nothing runs on by itself).
    fn motion(&mut self, cmd: &I::Command, state: &I::Data) -> Motion {
        let _ = (cmd, state);
        Motion::NONE
    }

    /// How part `part` (a bit of [`Motion::drives`]) of a motion the host follows is
    /// doing: still moving, or ended and how, with its position and its error against the
    /// goal the driver holds for it. The host asks for each running part after each
    /// command and whenever the driver calls
    /// [`DeviceHost::check_motions`](super::DeviceHost::check_motions), and publishes a
    /// command's result when its last part ended. Must not block. Default:
    /// [`Progress::UNKNOWN`] (the motion ends only when another command takes its parts).
    fn progress(&mut self, part: u32, state: &I::Data) -> Progress {
        let _ = (part, state);
        Progress::UNKNOWN
    }

    /// Stops every motion of the device now (the deadman: the holder of the device's
    /// lease died or missed its heartbeat). Must not block. Default: unsupported (logged
    /// by the host); every driver of moving hardware implements it.
    fn stop(&mut self, state: &mut I::Data) -> Status {
        let _ = state;
        Status::Unsupported
    }
}

/// The parts of a device a command drives, and those of them still moving
/// ([`DeviceHandler::motion`]). Bit i is a part that moves on its own: joint i of an arm;
/// a limb's joints; bit 0 for a gripper.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Motion {
    /// The parts the command drives (a new target, a speed, a stop).
    pub drives: u64,
    /// Those of them still moving now: the command cuts their motion short.
    pub cuts: u64,
    /// The command is a stop: the motions it cuts end [`MotionResult::Stopped`] rather
    /// than [`MotionResult::Preempted`].
    pub stop: bool,
}

impl Motion {
    /// Drives nothing that runs on by itself.
    pub const NONE: Motion = Motion {
        drives: 0,
        cuts: 0,
        stop: false,
    };

    /// `drives`, of which the parts in `running` are still moving.
    pub const fn of(drives: u64, running: u64) -> Motion {
        Motion {
            drives,
            cuts: drives & running,
            stop: false,
        }
    }

    /// The same parts, driven by a stop.
    pub const fn stopping(self) -> Motion {
        Motion { stop: true, ..self }
    }
}

/// How one part of a motion is doing ([`DeviceHandler::progress`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// `None` while it moves; how it ended and why (`Ok`, or the cause: `LINK_DOWN`,
    /// `POWERED_OFF`, `BRAKED`, ...).
    pub end: Option<(MotionResult, Status)>,
    /// Its position now (rad or m); NaN if not known.
    pub position: f64,
    /// Its position minus its goal; NaN if not known (a SPEED has no goal).
    pub error: f64,
    /// The device's tolerance for "reached" for this part; 0 if exact.
    pub tolerance: f64,
}

impl Progress {
    /// Nothing known: still moving, position and error unknown.
    pub const UNKNOWN: Progress = Progress {
        end: None,
        position: f64::NAN,
        error: f64::NAN,
        tolerance: 0.0,
    };

    /// Still moving, at `position`, `error` from its goal.
    pub const fn moving(position: f64, error: f64, tolerance: f64) -> Progress {
        Progress {
            end: None,
            position,
            error,
            tolerance,
        }
    }

    /// Ended with `result` (because of `cause`), at `position`, `error` from its goal.
    pub const fn ended(
        result: MotionResult,
        cause: Status,
        position: f64,
        error: f64,
        tolerance: f64,
    ) -> Progress {
        Progress {
            end: Some((result, cause)),
            position,
            error,
            tolerance,
        }
    }
}

/// The indices of the bits set in `mask`, lowest first.
pub(crate) fn set_bits(mut mask: u64) -> impl Iterator<Item = usize> {
    core::iter::from_fn(move || {
        if mask == 0 {
            return None;
        }
        let bit = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        Some(bit)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_bits_walks_every_set_bit_lowest_first() {
        assert_eq!(set_bits(0).count(), 0);
        assert_eq!(set_bits(0b1011).collect::<Vec<_>>(), [0, 1, 3]);
        assert_eq!(set_bits(1 << 63 | 1).collect::<Vec<_>>(), [0, 63]);
        assert_eq!(set_bits(u64::MAX).count(), 64);
    }
}
