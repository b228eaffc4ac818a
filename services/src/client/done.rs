//! Waiting for a motion's end: [`Client::wait_done`] returns the result the driver
//! publishes on the `outcome` channel when the motion a command started has ended.

use core::time::Duration;
use std::time::Instant;

use limber_interfaces::prelude::*;
use thiserror::Error;

use super::{Client, DriverStatus, LIVENESS_PERIOD, OUTCOME_SLOTS, Ticket, WaitError};

/// How the motion of one of this client's commands ended ([`Client::wait_done`]): the
/// result sample as the driver published it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Done {
    msg: OutcomeMsg,
}

impl Done {
    /// The command's sequence number (its [`Ticket::seq`]).
    pub fn seq(&self) -> u64 {
        self.msg.cmd_seq
    }

    /// How the motion ended.
    pub fn result(&self) -> MotionResult {
        // Only samples whose result decodes are kept.
        self.msg
            .motion_result()
            .ok()
            .flatten()
            .unwrap_or(MotionResult::Aborted)
    }

    /// Why: `Ok` when reached; the cause of an abort (`LinkDown`, `PoweredOff`, `Braked`);
    /// `Preempted`; `Leased` for the deadman's stop.
    pub fn cause(&self) -> Status {
        self.msg.status().unwrap_or(Status::InvalidArgument)
    }

    /// True when every part reached its goal within the device's tolerance.
    pub fn reached(&self) -> bool {
        self.result() == MotionResult::Reached
    }

    /// The client whose command preempted or stopped it (0: none or the driver).
    pub fn other_client(&self) -> u64 {
        self.msg.other_client
    }

    /// The largest |final error| of its parts against the goal (rad or m); NaN if not
    /// known.
    pub fn max_error(&self) -> f64 {
        self.msg.max_error
    }

    /// The device's tolerance for "reached" (the loosest of the parts').
    pub fn tolerance(&self) -> f64 {
        self.msg.tolerance
    }

    /// Each part's final position (part i: joint i); NaN where not known. Parts the
    /// command did not drive are NaN too.
    pub fn positions(&self) -> &[f64] {
        &self.msg.position[..self.parts()]
    }

    /// Each part's final error against the goal (position − goal); NaN where not known.
    pub fn errors(&self) -> &[f64] {
        &self.msg.error[..self.parts()]
    }

    /// The result in one sentence.
    pub fn sentence(&self) -> String {
        self.msg.result_sentence()
    }

    /// The sample as published (for the C API).
    pub fn message(&self) -> &OutcomeMsg {
        &self.msg
    }

    fn parts(&self) -> usize {
        (self.msg.parts as usize).min(self.msg.position.len())
    }
}

impl core::fmt::Display for Done {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(&self.sentence())
    }
}

/// [`Client::wait_done`] failed: no result.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DoneError {
    /// The command was refused: it started no motion.
    #[error("the command was refused: {0}")]
    Refused(Status),
    /// No result within the timeout, the driver is gone, the result was overwritten by
    /// those of 16 later commands before it was read, or receiving failed.
    #[error(transparent)]
    Wait(#[from] WaitError),
}

impl<I: Interface> Client<I> {
    /// Records a motion's result from the `outcome` channel.
    pub(super) fn result_arrived(&mut self, m: &OutcomeMsg) {
        match m.motion_result() {
            Ok(Some(_)) => {
                self.results[(m.cmd_seq as usize) % OUTCOME_SLOTS] = Some(Done { msg: *m });
            }
            Ok(None) => {}
            Err(e) => tracing::warn!(device = %self.device, error = %e, "unknown motion result"),
        }
    }

    /// The result of the command of `ticket` if it arrived (looks at what arrived).
    pub fn done(&mut self, ticket: Ticket) -> Result<Option<Done>, WaitError> {
        self.refresh()?;
        Ok(self.result_of(ticket.seq))
    }

    fn result_of(&self, seq: u64) -> Option<Done> {
        self.results[(seq as usize) % OUTCOME_SLOTS].filter(|d| d.seq() == seq)
    }

    /// Waits until the motion the command of `ticket` started has ended, and returns how:
    /// reached (within the device's tolerance), stalled, stopped, preempted, aborted or
    /// timed out, with each part's final position and error against the goal. A command
    /// that starts nothing that runs on (a speed of 0, a request-like command) is reached
    /// when carried out. A refused command is [`DoneError::Refused`].
    ///
    /// The states taken when it returns include the one that shows the motion's end.
    pub fn wait_done(&mut self, ticket: Ticket, timeout: Duration) -> Result<Done, DoneError> {
        let start = Instant::now();
        let deadline = start + timeout;
        let mut next_check = start + LIVENESS_PERIOD;
        let slot = (ticket.seq as usize) % OUTCOME_SLOTS;
        loop {
            self.refresh()?;
            if let Some(d) = self.result_of(ticket.seq) {
                return Ok(d);
            }
            let o = self.outcomes[slot];
            if o.seq == ticket.seq && !o.status.is_carried_out() {
                return Err(DoneError::Refused(o.status));
            }
            // Sixteen later commands since: this one's slots are taken by theirs.
            if self.max_seen_seq >= ticket.seq + OUTCOME_SLOTS as u64 {
                return Err(WaitError::Missed {
                    newer_seq: self.max_seen_seq,
                }
                .into());
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(WaitError::Timeout(timeout).into());
            }
            if now >= next_check {
                next_check = now + LIVENESS_PERIOD;
                if self.driver_status() != DriverStatus::Alive {
                    return Err(WaitError::DriverGone.into());
                }
                self.keep_told_stream();
            }
            self.pause(deadline.min(next_check))
                .map_err(WaitError::Transport)?;
        }
    }
}
