//! Sending commands: not acknowledged, their outcome arrives in a later state sample.

use iceoryx2::prelude::*;
use limber_interfaces::prelude::*;

use super::{Client, CommandError};
use crate::context::monotonic_ns;
use crate::qos;

/// The shortest time between two new notifiers of a client whose wake-ups reach no
/// driver (see `Client::wake_driver_with`).
const WAKE_RETRY: std::time::Duration = std::time::Duration::from_millis(100);

/// A command that was sent, to wait for its outcome.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ticket {
    /// The command's sequence number.
    pub seq: u64,
    /// How many driver processes received it (normally 1).
    pub receivers: usize,
}

impl<I: Interface> Client<I> {
    // ----- commands ---------------------------------------------------------------------

    /// Sends a typed command. Returns at once (commands are not acknowledged; see
    /// [`Client::wait_outcome`]).
    pub fn send(&mut self, cmd: &I::Command) -> Result<Ticket, CommandError> {
        let loan = match self.cmd_loan.take() {
            Some(l) => l,
            None => self
                .commands
                .loan_uninit()
                .map_err(|e| CommandError::Transport(e.into()))?,
        };
        let mut sample = loan.write_payload(I::CmdMsg::default());
        let raw: &mut I::CmdMsg = sample.payload_mut();
        cmd.write(raw);
        self.cmd_seq += 1;
        let m = raw.meta_mut();
        m.client_id = self.client_id;
        m.seq = self.cmd_seq;
        m.stamp_ns = monotonic_ns();
        let receivers = sample
            .send()
            .map_err(|e| CommandError::Transport(e.into()))?;
        if self.wake_driver {
            self.wake_driver_with(qos::EVENT_COMMAND);
        }
        // A spinning client has a core of its own: it loans the next command's sample
        // while the driver handles this one. (A client in event mode may share the
        // driver's core, which would wait for that loan: it loans when it sends.)
        if self.wait_mode == super::WaitMode::Spin {
            self.cmd_loan = crate::host::loan_ahead(&self.commands, &self.device, "command");
        }
        self.sent();
        if receivers == 0 {
            return Err(CommandError::NoDriver);
        }
        Ok(Ticket {
            seq: self.cmd_seq,
            receivers,
        })
    }

    /// Wakes the driver's loop. A failure delays the command or request until the
    /// driver's next tick rather than losing it: logged, not fatal.
    ///
    /// A wake-up that reaches no listener while the driver has one means this notifier's
    /// connection to it failed (iceoryx2 then retries only when a port joins or leaves the
    /// service): a new notifier is made, which connects afresh, at most every
    /// [`WAKE_RETRY`], and the wake-up sent again.
    pub(crate) fn wake_driver_with(&self, event: usize) {
        let sent = self
            .wake
            .borrow()
            .notify_with_custom_event_id(EventId::new(event));
        match sent {
            Ok(0) => {}
            Ok(_) => return,
            Err(e) => {
                tracing::debug!(device = %self.device, error = %e, "cannot wake the driver");
                return;
            }
        }
        let now = std::time::Instant::now();
        if self.wake_retry_at.get().is_some_and(|t| now < t) {
            return;
        }
        self.wake_retry_at.set(Some(now + WAKE_RETRY));
        if self.wake_svc.dynamic_config().number_of_listeners() == 0 {
            return;
        }
        match self.wake_svc.notifier_builder().create() {
            Ok(n) => {
                tracing::debug!(device = %self.device, "a wake-up reached no driver: reconnected");
                if let Err(e) = n.notify_with_custom_event_id(EventId::new(event)) {
                    tracing::debug!(device = %self.device, error = %e, "cannot wake the driver");
                }
                *self.wake.borrow_mut() = n;
            }
            Err(e) => {
                tracing::debug!(device = %self.device, error = %e, "cannot make a new notifier");
            }
        }
    }
}
