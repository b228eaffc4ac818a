//! How a bridge's loop sleeps: one iceoryx2 WaitSet over the [`Inbox`](crate::inbox) (what
//! Zenoh delivered) and the iceoryx2 listeners of the devices it relays (what the local
//! side has for it), with a timeout for the loop's own deadlines. Nothing is polled on a
//! fixed period: the loop wakes on evidence or at its next deadline.

use std::rc::Rc;
use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use limber_services::DeviceName;
use limber_services::event_loop::{FdSource, LoopError};

/// What woke the loop.
#[derive(Debug, Default)]
pub(crate) struct Woken {
    /// The inbox has something.
    pub mail: bool,
    /// These devices' listeners were notified (their events are consumed).
    pub devices: Vec<DeviceName>,
}

/// The listeners a WaitSet is built over, each with the device it belongs to.
pub(crate) type Attached = Vec<(DeviceName, Rc<Listener<ipc::Service>>)>;

/// A wait of at least `d` rounded up to whole milliseconds (the WaitSet's resolution), so
/// that a deadline a fraction of a millisecond away is slept to rather than spun to.
fn whole_ms(d: Duration) -> Duration {
    Duration::from_millis(d.as_nanos().div_ceil(1_000_000).min(u64::MAX as u128) as u64)
}

/// Builds a WaitSet over `inbox` and `listeners`, then runs `body` with a function that
/// waits up to the given time for either and says what woke it. Rebuild (call again) when
/// the set of devices changes.
pub(crate) fn with_waitset<R>(
    inbox: &FdSource,
    listeners: &Attached,
    body: impl FnOnce(&mut dyn FnMut(Duration) -> Result<Woken, LoopError>) -> R,
) -> Result<R, LoopError> {
    let ws = WaitSetBuilder::new()
        // The bridge's `stop` decides when it ends; a signal only interrupts the wait.
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| LoopError::WaitSet(e.into()))?;
    let inbox_guard = ws
        .attach_notification(inbox)
        .map_err(|e| LoopError::WaitSet(e.into()))?;
    let mut guards = Vec::with_capacity(listeners.len());
    for (_, l) in listeners {
        guards.push(
            ws.attach_notification(l.as_ref())
                .map_err(|e| LoopError::WaitSet(e.into()))?,
        );
    }
    let mut wait = |timeout: Duration| -> Result<Woken, LoopError> {
        let mut woken = Woken::default();
        ws.wait_and_process_once_with_timeout(
            |id| {
                if id.has_event_from(&inbox_guard) {
                    woken.mail = true;
                }
                for ((device, l), g) in listeners.iter().zip(&guards) {
                    if id.has_event_from(g) {
                        // Unconsumed, they would wake the loop again at once.
                        if let Err(e) = l.try_wait(|_| {}) {
                            tracing::warn!(device = %device, error = %e, "cannot consume notifications");
                        }
                        woken.devices.push(device.clone());
                    }
                }
                CallbackProgression::Continue
            },
            whole_ms(timeout),
        )
        .map_err(LoopError::Wait)?;
        Ok(woken)
    };
    Ok(body(&mut wait))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn waits_are_rounded_up_to_whole_milliseconds() {
        assert_eq!(whole_ms(Duration::ZERO), Duration::ZERO);
        assert_eq!(whole_ms(Duration::from_micros(1)), Duration::from_millis(1));
        assert_eq!(whole_ms(Duration::from_millis(3)), Duration::from_millis(3));
        assert_eq!(
            whole_ms(Duration::from_micros(3001)),
            Duration::from_millis(4)
        );
    }
}
