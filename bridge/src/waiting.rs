//! How a bridge's loop sleeps: one iceoryx2 WaitSet over the [`Inbox`](crate::inbox) (what
//! Zenoh delivered) and the iceoryx2 listeners of the devices it relays (what the local
//! side has for it), with a timeout for the loop's own deadlines. Nothing is polled on a
//! fixed period: the loop wakes on evidence or at its next deadline.
//!
//! After activity the loop lingers: for [`linger`] (50 µs unless `LIMBER_BRIDGE_LINGER_US`
//! says otherwise) it looks at the inbox and the listeners
//! without sleeping (yielding the CPU between looks), as a driver does after a command
//! (`limber_services::event_loop::linger`): the answer to what it just relayed (a driver's
//! outcome, a client's next command) usually comes within that time, and is then taken
//! without the wake-up of a sleeping thread (10-25 us each on a 2-core VM; a command through
//! the bridge pair crosses several).
//!
//! A loop that is owed an answer lingers until it comes ([`Owed`]): the mirror, once it has
//! put a local client's command or request on Zenoh, and the exposing bridge, once it has
//! relayed a remote client's to the driver, look for its outcome or reply without sleeping
//! for up to [`await_linger`] (1 ms unless `LIMBER_BRIDGE_AWAIT_US` says
//! otherwise), unless the last answer took longer: on the loopback or a fast network the
//! answer comes back through the exposing bridge and the driver after a few hundred
//! microseconds, and is then taken without a sleeping thread's wake-up. It costs the CPU of
//! that wait, only while an answer is owed.

use std::rc::Rc;
use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use limber_services::DeviceName;
use limber_services::event_loop::LoopError;

use crate::inbox::Inbox;

/// How long a loop keeps looking without sleeping after something woke it when nothing
/// else is configured: the drivers' linger ([`limber_services::qos::DRIVER_LINGER`]).
pub(crate) const LINGER: Duration = limber_services::qos::DRIVER_LINGER;

/// The environment variable that sets the bridge loops' linger in µs (`0`: sleep at once).
pub(crate) const LINGER_ENV: &str = "LIMBER_BRIDGE_LINGER_US";

/// The linger of the bridge's loops: `LIMBER_BRIDGE_LINGER_US` if set (µs, at most 1 s),
/// else [`LINGER`].
pub(crate) fn linger() -> Duration {
    static LINGER_SET: std::sync::OnceLock<Duration> = std::sync::OnceLock::new();
    *LINGER_SET.get_or_init(|| limber_services::qos::micros_from_env(LINGER_ENV).unwrap_or(LINGER))
}

/// The environment variable that sets, in µs, how long a mirror looks without sleeping for
/// the answer to what it put on Zenoh (`0`: it sleeps after its linger).
pub(crate) const AWAIT_ENV: &str = "LIMBER_BRIDGE_AWAIT_US";

/// How long a loop owed an answer looks for it without sleeping when nothing else is
/// configured.
pub(crate) const AWAIT: Duration = Duration::from_millis(1);

/// `LIMBER_BRIDGE_AWAIT_US` if set (µs, at most 1 s), else [`AWAIT`].
pub(crate) fn await_linger() -> Duration {
    static AWAIT_SET: std::sync::OnceLock<Duration> = std::sync::OnceLock::new();
    *AWAIT_SET.get_or_init(|| limber_services::qos::micros_from_env(AWAIT_ENV).unwrap_or(AWAIT))
}

/// Whether a loop is owed an answer, and until when it looks for it without sleeping.
#[derive(Debug, Default)]
pub(crate) struct Owed {
    /// When the oldest thing still unanswered was sent.
    asked_at: Option<Instant>,
    /// How long the last answer took.
    last_answer: Option<Duration>,
    /// Looked for without sleeping until then.
    until: Option<Instant>,
}

impl Owed {
    /// Something that is answered was sent at `now`: its answer is looked for without
    /// sleeping for up to `cap`, unless the last answer took longer than that (a network
    /// slower than the loopback, where looking would only burn the CPU).
    pub(crate) fn asked(&mut self, now: Instant, cap: Duration) {
        self.asked_at.get_or_insert(now);
        if !cap.is_zero() && self.last_answer.is_none_or(|d| d <= cap) {
            self.until = Some(now + cap);
        }
    }

    /// An answer came at `now`: how long it took is kept, and nothing is owed.
    pub(crate) fn answered(&mut self, now: Instant) {
        if let Some(t) = self.asked_at.take() {
            self.last_answer = Some(now.saturating_duration_since(t));
        }
        self.until = None;
    }

    /// Until when to look without sleeping (the second argument of the loop's wait).
    pub(crate) fn until(&self) -> Option<Instant> {
        self.until
    }
}

/// What woke the loop.
#[derive(Debug, Default)]
pub(crate) struct Woken {
    /// The inbox has something.
    pub mail: bool,
    /// These devices' listeners were notified (their events are consumed).
    pub devices: Vec<DeviceName>,
    /// It was found by looking without sleeping (the linger), not by the WaitSet (what the
    /// tests look at; the loops need not know).
    #[cfg_attr(not(test), allow(dead_code))]
    pub looked: bool,
}

impl Woken {
    /// Something woke the loop (not its timeout).
    fn any(&self) -> bool {
        self.mail || !self.devices.is_empty()
    }
}

/// The listeners a WaitSet is built over, each with the device it belongs to.
pub(crate) type Attached = Vec<(DeviceName, Rc<Listener<ipc::Service>>)>;

/// A wait of at least `d` rounded up to whole milliseconds (the WaitSet's resolution), so
/// that a deadline a fraction of a millisecond away is slept to rather than spun to.
fn whole_ms(d: Duration) -> Duration {
    Duration::from_millis(d.as_nanos().div_ceil(1_000_000).min(u64::MAX as u128) as u64)
}

/// The function a loop waits with: up to `timeout`; `owed`: an answer is owed until then
/// (keep looking without sleeping until it, see the module's text).
pub(crate) type Wait<'a> = dyn FnMut(Duration, Option<Instant>) -> Result<Woken, LoopError> + 'a;

/// Builds a WaitSet over `inbox` and `listeners`, then runs `body` with a function that
/// waits up to the given time for either and says what woke it (lingering first after
/// activity and while an answer is owed: see the module's text). Rebuild (call again) when
/// the set of devices changes.
pub(crate) fn with_waitset<T, R>(
    inbox: &Inbox<T>,
    listeners: &Attached,
    body: impl FnOnce(&mut Wait<'_>) -> R,
) -> Result<R, LoopError> {
    let ws = WaitSetBuilder::new()
        // The bridge's `stop` decides when it ends; a signal only interrupts the wait.
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| LoopError::WaitSet(e.into()))?;
    let inbox_guard = ws
        .attach_notification(inbox.source())
        .map_err(|e| LoopError::WaitSet(e.into()))?;
    let mut guards = Vec::with_capacity(listeners.len());
    for (_, l) in listeners {
        guards.push(
            ws.attach_notification(l.as_ref())
                .map_err(|e| LoopError::WaitSet(e.into()))?,
        );
    }
    let linger = linger();
    let mut linger_until: Option<Instant> = None;
    let mut wait = |timeout: Duration, owed: Option<Instant>| -> Result<Woken, LoopError> {
        let now = Instant::now();
        let until = match (linger_until.take(), owed.filter(|o| *o > now)) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        let lingered = until.and_then(|u| linger_look(inbox, listeners, u.min(now + timeout)));
        let woken = match lingered {
            Some(w) => w,
            // Something came since the last look: no sleep.
            None if !inbox.about_to_sleep() => Woken {
                mail: true,
                ..Woken::default()
            },
            None => {
                let mut woken = Woken::default();
                let waited = ws.wait_and_process_once_with_timeout(
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
                );
                inbox.awake();
                waited.map_err(LoopError::Wait)?;
                woken
            }
        };
        if woken.any() && !linger.is_zero() {
            linger_until = Some(Instant::now() + linger);
        }
        Ok(woken)
    };
    Ok(body(&mut wait))
}

/// Looks without sleeping (yielding the CPU between looks) until something came or `until`:
/// what came, or `None`.
fn linger_look<T>(inbox: &Inbox<T>, listeners: &Attached, until: Instant) -> Option<Woken> {
    loop {
        let woken = look(inbox, listeners);
        if woken.any() {
            return Some(woken);
        }
        if Instant::now() >= until {
            return None;
        }
        std::thread::yield_now();
    }
}

/// One look without sleeping: mail waiting in the inbox, and the listeners notified (their
/// notifications consumed).
fn look<T>(inbox: &Inbox<T>, listeners: &Attached) -> Woken {
    let mut woken = Woken {
        mail: inbox.has_mail(),
        devices: Vec::new(),
        looked: true,
    };
    for (device, l) in listeners {
        let mut notified = false;
        if let Err(e) = l.try_wait(|_| notified = true) {
            tracing::warn!(device = %device, error = %e, "cannot consume notifications");
        }
        if notified {
            woken.devices.push(device.clone());
        }
    }
    woken
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inbox::Inbox;

    /// A notification that comes while the loop lingers wakes it, and is consumed: the
    /// next wait does not return at once for it again.
    #[test]
    fn a_notification_during_the_linger_is_taken_and_consumed() {
        use limber_services::{Context, Domain, Role};
        let domain = Domain::unique_for_test();
        let ctx = Context::new(&domain, Role::Client, "linger").unwrap();
        let events = ctx
            .node()
            .service_builder(&"linger/test/notify".try_into().unwrap())
            .event()
            .open_or_create()
            .unwrap();
        let listener = Rc::new(events.listener_builder().create().unwrap());
        let notifier = events.notifier_builder().create().unwrap();
        let device: DeviceName = "linger/actarray/0".parse().unwrap();
        let attached: Attached = vec![(device.clone(), listener)];
        let (inbox, tx) = Inbox::<u32>::new().unwrap();
        with_waitset(&inbox, &attached, |wait| {
            // Activity: mail wakes the loop, which then lingers.
            assert!(tx.send(1).is_ok());
            assert!(wait(Duration::from_secs(10), None).unwrap().mail);
            assert_eq!(inbox.drain(), vec![1]);
            notifier.notify().unwrap();
            let woken = wait(Duration::from_secs(10), None).unwrap();
            assert_eq!(woken.devices, vec![device.clone()]);
            // Consumed: nothing more within a short wait (the lingering look and the
            // WaitSet both find nothing).
            let again = wait(Duration::from_millis(20), None).unwrap();
            assert!(!again.mail && again.devices.is_empty(), "{again:?}");
        })
        .unwrap();
    }

    /// A loop owed an answer takes it by looking, long after its linger after activity
    /// would have ended; one owed nothing, idle, takes it from the WaitSet.
    #[test]
    fn an_owed_answer_is_looked_for_without_sleeping() {
        let (inbox, tx) = Inbox::<u32>::new().unwrap();
        with_waitset(&inbox, &Vec::new(), |wait| {
            // Idle, nothing owed: the WaitSet.
            assert!(tx.send(1).is_ok());
            let w = wait(Duration::from_secs(10), None).unwrap();
            assert!(w.mail && !w.looked, "{w:?}");
            assert_eq!(inbox.drain(), vec![1]);
            // Nothing came within the linger that followed.
            let quiet = wait(Duration::from_millis(20), None).unwrap();
            assert!(!quiet.mail, "{quiet:?}");
            // Owed an answer for an hour: the answer is taken by looking.
            assert!(tx.send(2).is_ok());
            let owed = Instant::now() + Duration::from_secs(3600);
            let w = wait(Duration::from_secs(10), Some(owed)).unwrap();
            assert!(w.mail && w.looked, "{w:?}");
            assert_eq!(inbox.drain(), vec![2]);
        })
        .unwrap();
    }

    /// An answer is looked for up to the cap after the first unanswered send; after an
    /// answer that took longer than the cap, the next one is not (until a quick one came).
    #[test]
    fn an_answer_is_owed_up_to_the_cap_unless_the_last_came_later() {
        let cap = Duration::from_millis(1);
        let t0 = Instant::now();
        let mut owed = Owed::default();
        assert_eq!(owed.until(), None);
        owed.asked(t0, cap);
        assert_eq!(owed.until(), Some(t0 + cap));
        // A second send before the answer keeps the first one's time for the measure.
        owed.asked(t0 + Duration::from_micros(100), cap);
        owed.answered(t0 + Duration::from_micros(300));
        assert_eq!(owed.until(), None);
        assert_eq!(owed.last_answer, Some(Duration::from_micros(300)));
        // A slow answer (2 ms): the next send is not looked for...
        let t1 = t0 + Duration::from_millis(10);
        owed.asked(t1, cap);
        owed.answered(t1 + Duration::from_millis(2));
        let t2 = t1 + Duration::from_millis(10);
        owed.asked(t2, cap);
        assert_eq!(owed.until(), None);
        // ...and its answer, quick again, brings the looking back.
        owed.answered(t2 + Duration::from_micros(200));
        let t3 = t2 + Duration::from_millis(10);
        owed.asked(t3, cap);
        assert_eq!(owed.until(), Some(t3 + cap));
        // A cap of zero never looks.
        let mut off = Owed::default();
        off.asked(t0, Duration::ZERO);
        assert_eq!(off.until(), None);
    }

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
