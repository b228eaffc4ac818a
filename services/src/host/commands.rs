//! Draining the `cmd` channel: each command decoded, admitted or refused by the arbiter,
//! carried out by the handler, and its outcome (and those of the motions it preempted)
//! published.

use iceoryx2::port::ReceiveError;
use limber_interfaces::prelude::*;

use super::arbiter::{CmdRef, Told};
use super::told::Outcomes;
use super::{CmdSample, DeviceHandler, DeviceHost, HostStats, Origin, ProcessError};
use crate::context::monotonic_ns;
use crate::naming::DeviceName;
use crate::qos;

impl<I: Interface> DeviceHost<I> {
    /// Takes the pending commands fairly, in rounds: each round at most
    /// [`CMD_BORROWED`](qos::CMD_BORROWED) commands of each client (each client's in its
    /// sending order), until none is left or [`CMD_BUFFER`](qos::CMD_BUFFER) were taken in
    /// this call (the rest waits for the next call); a client that never stops sending
    /// neither holds the loop nor delays another client's command by more than a round.
    /// Handles each: a command that does not decode is refused with the matching status
    /// without reaching the handler. Returns how many commands were handled.
    pub fn process_commands<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<usize, ProcessError> {
        self.take_commands_fairly(|host, sample, received_ns| {
            host.process_command(handler, sample, received_ns)
        })
    }

    /// The rounds of [`DeviceHost::process_commands`] (and of the relay's): `each` handles
    /// one command, given when `receive` returned it, and says whether it counts; returns
    /// how many counted.
    ///
    /// Why rounds: the transport hands out the samples of its first connection that has
    /// data, so draining sample by sample served a flooding client before every client
    /// that connected after it, for as long as the flood lasted. A connection whose
    /// borrowed samples reach the service's limit is passed over until they are released:
    /// a round holds its samples until it has taken one of every client.
    pub(crate) fn take_commands_fairly(
        &mut self,
        mut each: impl FnMut(&mut Self, CmdSample<I>, u64) -> Result<bool, ProcessError>,
    ) -> Result<usize, ProcessError> {
        // The round's storage, allocated once for every client's CMD_BORROWED.
        let mut round = core::mem::take(&mut self.cmd_round);
        let (mut n, mut taken) = (0, 0);
        let result = loop {
            if taken >= qos::CMD_BUFFER {
                break Ok(n);
            }
            while round.len() < round.capacity() && taken + round.len() < qos::CMD_BUFFER {
                match self.commands.receive() {
                    Ok(Some(s)) => round.push((s, monotonic_ns())),
                    Ok(None) | Err(ReceiveError::ExceedsMaxBorrows) => break,
                    Err(e) => {
                        round.clear();
                        self.cmd_round = round;
                        return Err(ProcessError::Receive(e));
                    }
                }
            }
            if round.is_empty() {
                break Ok(n);
            }
            taken += round.len();
            let mut failed = None;
            for (sample, received_ns) in round.drain(..) {
                match each(self, sample, received_ns) {
                    Ok(true) => n += 1,
                    Ok(false) => {}
                    Err(e) => {
                        failed = Some(e);
                        break;
                    }
                }
            }
            if let Some(e) = failed {
                break Err(e);
            }
        };
        round.clear();
        self.cmd_round = round;
        result
    }

    /// Handles one command sample, taken from the channel at `received_ns`; `false` if it
    /// was dropped uncounted (a forged client id).
    fn process_command<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
        sample: CmdSample<I>,
        received_ns: u64,
    ) -> Result<bool, ProcessError> {
        let raw: &I::CmdMsg = &sample;
        let meta = *raw.meta();
        // Who sent it, as the transport says: the node of its publisher.
        let sender = self
            .cmd_senders
            .publisher(sample.header().publisher_id().value(), &self.cmd_svc);
        let node = sender.node;
        if !super::senders::client_of_process(meta.client_id, sender.pid) {
            // Another process's client id: its outcome would go to that client (who
            // never sent it, and would take it for one of its own). Dropped, counted.
            drop(sample);
            self.forged_command(meta.client_id, sender.pid);
            return Ok(false);
        }
        let origin = Origin {
            client_id: meta.client_id,
            seq: meta.seq,
            sent_ns: meta.stamp_ns,
            received_ns,
        };
        let cmd = CmdRef {
            client_id: meta.client_id,
            seq: meta.seq,
            kind: meta.kind,
        };
        self.stats.overflows += self.arbiter.arrived(cmd);
        let status = match I::Command::read(raw) {
            Ok(decoded) => {
                drop(sample);
                if self.arbiter.refusing(cmd.client_id, node).is_some() {
                    self.stats.leased_refusals += 1;
                    Status::Leased
                } else {
                    self.apply(handler, &decoded, &origin, cmd)
                }
            }
            Err(e) => e.status(),
        };
        self.outcome = CmdOutcome {
            client_id: meta.client_id,
            cmd_seq: meta.seq,
            kind: meta.kind,
            status: status.code(),
        };
        // The state that shows the command goes out before its outcome: a client that
        // has seen the outcome and then takes the state sees the command's effect.
        // (Clients are notified after both.)
        let state_sent = self.publish_each_outcome.then(|| self.send_state());
        let told = self.arbiter.outcome(cmd, node, status);
        // A command carried out whose result is decided now: one sample, result and
        // outcome (`publish_decided`); else the outcome, and the result when it comes.
        let decided = told.status == Status::Ok
            && told.other_client == 0
            && told.other_name.is_none()
            && self.publish_decided(cmd);
        if !decided {
            publish_outcome(&mut self.out, &mut self.stats, &self.device, told);
        }
        self.stats.commands += 1;
        if !status.is_carried_out() {
            self.stats.refused += 1;
        }
        if let Some(sent) = state_sent {
            sent?;
            self.state_sent();
        }
        // The motions it preempted or stopped have their results now, after its outcome
        // (and so has the command itself if it was not sent with its outcome).
        self.publish_results();
        // The next command's outcome sample, loaned now rather than on its path.
        self.out.loan_ahead(&self.device);
        Ok(true)
    }

    /// A command whose client id is another process's: counted as refused, and logged
    /// (at warning level the first time, then once per 1,000).
    fn forged_command(&mut self, client_id: u64, pid: u32) {
        self.stats.commands += 1;
        self.stats.refused += 1;
        self.forged += 1;
        if self.forged % 1000 == 1 {
            tracing::warn!(device = %self.device, client_id, sender_pid = pid, forged = self.forged,
                "a command with another process's client id: dropped (no outcome to that client)");
        }
    }

    /// Carries out one decoded command of a client allowed to command the device, and
    /// tells the client whose running motion it cuts short that it was preempted.
    fn apply<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
        decoded: &I::Command,
        origin: &Origin,
        cmd: CmdRef,
    ) -> Status {
        let motion = handler.motion(decoded, &self.state);
        self.record_before(handler, motion);
        let status = handler.command(decoded, origin, &mut self.state);
        if !status.is_carried_out() {
            return status;
        }
        if decoded.is_piece() {
            // A piece of a larger command: its outcome only (no result of its own).
            return status;
        }
        self.motion_started(cmd, motion);
        let (out, stats, device) = (&mut self.out, &mut self.stats, &self.device);
        self.arbiter.carried_out(cmd, motion, |told| {
            stats.preempted += 1;
            publish_outcome(out, stats, device, told);
        });
        status
    }
}

/// Sends one outcome to the client it names and to the watchers ([`Outcomes::publish`]);
/// a failure is counted and logged (that client then waits up to its timeout), never fatal
/// to the loop.
fn publish_outcome(out: &mut Outcomes, stats: &mut HostStats, device: &DeviceName, told: Told) {
    let mut msg = OutcomeMsg {
        client_id: told.cmd.client_id,
        cmd_seq: told.cmd.seq,
        other_client: told.other_client,
        kind: told.cmd.kind,
        status: told.status.code(),
        ..OutcomeMsg::default()
    };
    if let Some(n) = told.other_name {
        msg.other_name = n;
    }
    out.publish(stats, device, msg);
}
