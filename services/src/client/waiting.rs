//! Reading the state and waiting: for a state, for the outcome of a command, with the
//! driver's liveness checked while waiting.

use core::time::Duration;
use std::time::Instant;

use iceoryx2::port::listener::ListenerWaitError;
use limber_interfaces::prelude::*;

use super::{Client, LIVENESS_PERIOD, OUTCOME_SLOTS, Outcome, Ticket, WaitError};
use crate::context::monotonic_ns;
use crate::error::Iox2Error;

/// Whether the driver of a device is running.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriverStatus {
    /// Its process is alive.
    Alive,
    /// Its process died without cleaning up (found dead by this client and cleaned up;
    /// so it stays until a driver is alive again).
    Dead,
    /// No driver is attached.
    Absent,
}

/// How fresh the latest state is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Freshness {
    /// Younger than the limit.
    Fresh,
    /// Older than the limit, but the driver is alive.
    Stale,
    /// The driver is gone.
    Gone,
    /// No state received yet.
    NoData,
}

/// A state older than this makes [`Client::freshness`] look at the driver's process,
/// whatever its `max_age`: a few periods of a driver's loop (the Pioneer driver and simarm
/// publish every 10 ms).
pub const FRESHNESS_CHECK_AGE: Duration = Duration::from_millis(50);

/// In spin mode, the waiting loops read the clock on every this many polls.
const SPIN_CLOCK_EVERY: u32 = 32;

/// How a client waits for states and replies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WaitMode {
    /// Block on the driver's notification (default; costs a wake-up, frees the CPU).
    Event,
    /// Busy-poll shared memory (lowest latency; takes a whole core).
    Spin,
}

impl<I: Interface> Client<I> {
    // ----- state ------------------------------------------------------------------------

    /// Takes every state sample that arrived; returns true if there was a new one.
    pub fn refresh(&mut self) -> Result<bool, WaitError> {
        // Outcomes first: a driver sends the state that shows a command before the
        // command's outcome, so the states taken after an outcome include that one.
        self.take_outcomes()?;
        self.take_states()
    }

    /// Takes every state sample that arrived; returns true if there was a new one. A
    /// state that shows one of this client's commands (`last_cmd`) gives that command's
    /// outcome: a limber driver sends it before the outcome message, which follows with
    /// the details (the holder of a lease, when refused as [`Status::Leased`]: waited for).
    fn take_states(&mut self) -> Result<bool, WaitError> {
        let mut got = false;
        loop {
            match self.states.receive() {
                Ok(Some(s)) => {
                    let data: &I::Data = &s;
                    let h = data.header();
                    let (last, stamp_ns) = (h.last_cmd, h.stamp_ns);
                    self.latest = Some(s);
                    got = true;
                    if last.client_id == self.client_id && last.cmd_seq != 0 {
                        self.outcome_shown(last, stamp_ns);
                    }
                }
                Ok(None) => break,
                Err(e) => return Err(WaitError::Transport(e.into())),
            }
        }
        Ok(got)
    }

    /// Records the outcome of this client's command `last` as a state showed it, unless
    /// it is known already or needs the outcome message's details.
    fn outcome_shown(&mut self, last: CmdOutcome, stamp_ns: u64) {
        let slot = (last.cmd_seq as usize) % OUTCOME_SLOTS;
        if self.outcomes[slot].seq == last.cmd_seq {
            return;
        }
        match Status::try_from(last.status) {
            Ok(Status::Leased) | Err(_) => {}
            Ok(status) => {
                self.outcomes[slot] = Outcome::shown(last.cmd_seq, status, stamp_ns);
                self.max_seen_seq = self.max_seen_seq.max(last.cmd_seq);
            }
        }
    }

    /// Takes the outcomes of this client's commands that arrived on its stream.
    fn take_outcomes(&mut self) -> Result<(), WaitError> {
        loop {
            let Some(stream) = &self.told.stream else {
                return Ok(());
            };
            let m: OutcomeMsg = match stream.receive() {
                Ok(Some(r)) => *r.payload(),
                Ok(None) => return Ok(()),
                Err(e) => return Err(WaitError::Transport(e.into())),
            };
            // Only its own come on its stream; a driver of another kind may say otherwise.
            if m.client_id != self.client_id {
                continue;
            }
            if m.result != 0 {
                self.result_arrived(&m);
                if !m.is_outcome() {
                    continue;
                }
            }
            let o = Outcome::from_msg(&m);
            let slot = (m.cmd_seq as usize) % OUTCOME_SLOTS;
            if m.status == Status::Preempted.code() {
                self.preemptions[slot] = o;
            } else {
                self.outcomes[slot] = o;
                self.max_seen_seq = self.max_seen_seq.max(m.cmd_seq);
            }
        }
    }

    /// Whether the latest state shows this client's command `seq` (or a later one of its).
    fn latest_shows(&self, seq: u64) -> bool {
        self.latest.as_deref().is_some_and(|d| {
            let l = d.header().last_cmd;
            l.client_id == self.client_id && l.cmd_seq >= seq
        })
    }

    /// Whether the motion that the command of `ticket` started was cut short by another
    /// client's command (the outcome says which client, and its name if it held the
    /// device). Looks at what arrived; remembers the last 16 commands.
    pub fn preempted(&mut self, ticket: Ticket) -> Result<Option<Outcome>, WaitError> {
        self.refresh()?;
        let p = self.preemptions[(ticket.seq as usize) % OUTCOME_SLOTS];
        Ok((p.seq == ticket.seq).then_some(p))
    }

    /// The latest state (read in place from shared memory), after taking what arrived.
    pub fn state(&mut self) -> Option<&I::Data> {
        self.refresh_or_log();
        self.latest.as_deref()
    }

    /// The latest state, waiting up to `timeout` for a first one if none arrived yet.
    pub fn current(&mut self, timeout: Duration) -> Result<&I::Data, WaitError> {
        self.refresh()?;
        if self.latest.is_none() {
            self.wait_state(timeout)?;
        }
        self.latest.as_deref().ok_or(WaitError::Timeout(timeout))
    }

    /// The latest state already taken, without looking for a newer one.
    pub fn last_state(&self) -> Option<&I::Data> {
        self.latest.as_deref()
    }

    /// Age of the latest state: now minus its acquisition time.
    pub fn state_age(&self) -> Option<Duration> {
        self.latest
            .as_deref()
            .map(|d| Duration::from_nanos(monotonic_ns().saturating_sub(d.header().stamp_ns)))
    }

    /// Fresh (younger than `max_age`), stale (older, driver alive), gone, or no data.
    ///
    /// A state older than [`FRESHNESS_CHECK_AGE`] (or `max_age`, if shorter) has the
    /// driver's process looked at, whatever `max_age`: a driver that died is gone within
    /// about that bound plus [`LIVENESS_PERIOD`], not only after `max_age`. The look costs
    /// tens of microseconds and is taken at most once per [`LIVENESS_PERIOD`]; a driver
    /// that publishes more often than the bound costs none.
    pub fn freshness(&mut self, max_age: Duration) -> Freshness {
        self.refresh_or_log();
        let Some(age) = self.state_age() else {
            return Freshness::NoData;
        };
        // A driver this client found dead is gone, however young its last state: the states
        // it published before it died say nothing of now (looked at again at most every
        // LIVENESS_PERIOD, so a driver that is back is seen).
        if self.driver_died.get()
            && self.driver_status_at_most_every(LIVENESS_PERIOD) != DriverStatus::Alive
        {
            return Freshness::Gone;
        }
        if age <= max_age.min(FRESHNESS_CHECK_AGE) {
            return Freshness::Fresh;
        }
        match (
            self.driver_status_at_most_every(LIVENESS_PERIOD),
            age <= max_age,
        ) {
            (DriverStatus::Alive, true) => Freshness::Fresh,
            (DriverStatus::Alive, false) => Freshness::Stale,
            _ => Freshness::Gone,
        }
    }

    /// [`Client::driver_status`], looked at again only when the last look is older than
    /// `period`.
    fn driver_status_at_most_every(&mut self, period: Duration) -> DriverStatus {
        let now = Instant::now();
        if let Some((at, status)) = self.liveness_seen
            && now.saturating_duration_since(at) < period
        {
            return status;
        }
        let status = self.driver_status();
        self.liveness_seen = Some((now, status));
        status
    }

    /// [`Client::refresh`] for the callers that answer with the latest state taken: a
    /// failure to receive leaves that state as it was (its age shows it) and is logged.
    fn refresh_or_log(&mut self) {
        if let Err(e) = self.refresh() {
            tracing::warn!(device = %self.device, error = %e, "cannot receive the state");
        }
    }

    /// Waits for a state sample newer than the latest one taken.
    pub fn wait_state(&mut self, timeout: Duration) -> Result<&I::Data, WaitError> {
        let start = Instant::now();
        let deadline = start + timeout;
        let mut next_check = start + LIVENESS_PERIOD;
        let mut polls = 0u32;
        loop {
            // Read before looking: a state published after the look changes it.
            let seen = self.state_wake_seen();
            if self.refresh()? {
                break;
            }
            if self.spun_without_clock(&mut polls) {
                continue;
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(WaitError::Timeout(timeout));
            }
            if now >= next_check {
                next_check = now + LIVENESS_PERIOD;
                if self.driver_status() != DriverStatus::Alive {
                    return Err(WaitError::DriverGone);
                }
            }
            self.pause_on(deadline.min(next_check), seen)
                .map_err(WaitError::Transport)?;
        }
        Ok(self.latest.as_deref().expect("refresh returned a sample"))
    }

    /// In event mode, the device's wake word as it is now (opened on the first call; when
    /// it cannot be, tried again a liveness period later), or None: wait on the event.
    fn state_wake_seen(&mut self) -> Option<u32> {
        if self.wait_mode != WaitMode::Event {
            return None;
        }
        if self.state_wake.is_none() {
            let now = Instant::now();
            if self
                .state_wake_tried
                .is_some_and(|t| now < t + LIVENESS_PERIOD)
            {
                return None;
            }
            self.state_wake_tried = Some(now);
            match crate::wake::WakeWord::open(self.ctx.domain(), &self.device) {
                Ok(w) => self.state_wake = Some(w),
                Err(e) => {
                    tracing::debug!(device = %self.device, error = %e, "no wake word: waiting for a state on the notify event");
                    return None;
                }
            }
        }
        self.state_wake.as_ref().map(crate::wake::WakeWord::seen)
    }

    /// Waits for the outcome of the command of `ticket`, as published by the driver.
    /// When it returns, the latest state ([`Client::last_state`], [`Client::state`])
    /// shows the command: a limber driver sends that state before the outcome message,
    /// and the outcome is taken from whichever comes first.
    pub fn wait_outcome(&mut self, ticket: Ticket, timeout: Duration) -> Result<Status, WaitError> {
        self.wait_outcome_detail(ticket, timeout).map(|o| o.status)
    }

    /// Waits for the outcome of the command of `ticket`, with the other client involved
    /// (the holder of the device when it is refused as [`Status::Leased`]).
    pub fn wait_outcome_detail(
        &mut self,
        ticket: Ticket,
        timeout: Duration,
    ) -> Result<Outcome, WaitError> {
        let start = Instant::now();
        let deadline = start + timeout;
        let mut next_check = start + LIVENESS_PERIOD;
        let mut polls = 0u32;
        loop {
            // The state that shows the command comes first, then the outcome message.
            self.take_states()?;
            let slot = (ticket.seq as usize) % OUTCOME_SLOTS;
            if self.outcomes[slot].seq == ticket.seq {
                return Ok(self.outcomes[slot]);
            }
            self.take_outcomes()?;
            let o = self.outcomes[slot];
            if o.seq == ticket.seq {
                // Known from the message alone (a state overwritten before it was taken,
                // or sent after it by a driver that is not limber's): the states again.
                if !self.latest_shows(ticket.seq) {
                    self.take_states()?;
                }
                return Ok(o);
            }
            // Commands of one client are applied in order: an outcome of a later one
            // means this one was applied too, its sample overwritten before it was read.
            if self.max_seen_seq > ticket.seq {
                return Err(WaitError::Missed {
                    newer_seq: self.max_seen_seq,
                });
            }
            if self.spun_without_clock(&mut polls) {
                continue;
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(WaitError::Timeout(timeout));
            }
            if now >= next_check {
                next_check = now + LIVENESS_PERIOD;
                if self.driver_status() != DriverStatus::Alive {
                    return Err(WaitError::DriverGone);
                }
                self.keep_told_stream();
            }
            self.pause(deadline.min(next_check))
                .map_err(WaitError::Transport)?;
        }
    }

    /// In spin mode, spins once and returns true on all but every [`SPIN_CLOCK_EVERY`]th
    /// poll: the waiting loops read the clock (for their timeout and the driver's
    /// liveness) only then, since a read costs about as much as a poll and would slow the
    /// loop that sees the answer. False in event mode, and on the polls that read it.
    fn spun_without_clock(&self, polls: &mut u32) -> bool {
        if self.wait_mode != WaitMode::Spin {
            return false;
        }
        *polls = polls.wrapping_add(1);
        if polls.is_multiple_of(SPIN_CLOCK_EVERY) {
            return false;
        }
        core::hint::spin_loop();
        true
    }

    /// Blocks (event mode) or spins once (spin mode) until `until` or a notification.
    pub(super) fn pause(&mut self, until: Instant) -> Result<(), Iox2Error> {
        self.pause_on(until, None)
    }

    /// [`Client::pause`]; with `state_seen` (the wake word as read before looking for a
    /// state), the block is a sleep on the wake word until it changes.
    fn pause_on(&mut self, until: Instant, state_seen: Option<u32>) -> Result<(), Iox2Error> {
        match self.wait_mode {
            WaitMode::Spin => {
                core::hint::spin_loop();
                Ok(())
            }
            WaitMode::Event => {
                // Right after a send: busy-poll for the answer of a driver that is awake.
                if let Some(spin_end) = self.spin_until {
                    if Instant::now() < spin_end.min(until) {
                        // Yield rather than spin: when the driver shares this core (2 cores
                        // and other load), it runs now instead of after the budget.
                        std::thread::yield_now();
                        return Ok(());
                    }
                    self.spin_until = None;
                }
                if let (Some(seen), Some(word)) = (state_seen, &self.state_wake) {
                    let left = until.saturating_duration_since(Instant::now());
                    if !left.is_zero() {
                        word.wait(seen, left);
                    }
                    return Ok(());
                }
                if self.notify.is_none() {
                    let l = self.notify_svc.listener_builder().create()?;
                    self.notify = Some(l);
                    // Something may have arrived before the listener existed.
                    return Ok(());
                }
                let left = until.saturating_duration_since(Instant::now());
                // iceoryx2 waits on a socket with SO_RCVTIMEO, in whole microseconds: less
                // than one is a timeout of zero, which blocks without end.
                if left < Duration::from_micros(1) {
                    return Ok(());
                }
                if let Some(l) = &self.notify {
                    match l.timed_wait(|_| {}, left) {
                        // A signal interrupted the wait (a stop and continue, Ctrl-Z and
                        // `fg`, interrupts it even without a handler): no failure. The
                        // caller's loop looks again and waits what is left of its timeout.
                        Err(ListenerWaitError::InterruptSignal) => {
                            tracing::debug!(device = %self.device, "a wait was interrupted by a signal: resumed");
                        }
                        Err(e) => return Err(e.into()),
                        Ok(_woken) => {}
                    }
                }
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use core::time::Duration;
    use std::time::Instant;

    use crate::testing::TestDriver;
    use crate::{ActArrayClient, Context, Domain, Role};

    #[test]
    fn a_pause_whose_end_has_come_returns_at_once() {
        let (tx, rx) = std::sync::mpsc::channel();
        // Its own thread: a pause that blocks for good fails the test instead of hanging it.
        let t = std::thread::spawn(move || {
            let domain = Domain::unique_for_test();
            let ctx = Context::new(&domain, Role::Driver, "pause").unwrap();
            let _driver = TestDriver::new(&ctx, "pause", 2).unwrap();
            let mut arm =
                ActArrayClient::connect_timeout(&ctx, "pause/actarray/0", Duration::from_secs(5))
                    .unwrap();
            arm.spin_until = None;
            for _ in 0..3 {
                // The first one makes the listener; the others wait on it.
                arm.pause(Instant::now()).unwrap();
            }
            tx.send(()).unwrap();
        });
        rx.recv_timeout(Duration::from_secs(30))
            .expect("a pause ending now returned");
        // The thread's domain removes its files as the thread ends: before this process does.
        t.join().unwrap();
    }
}
