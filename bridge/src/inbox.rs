//! What Zenoh's callbacks (on Zenoh's threads) hand to a bridge's loop: a channel, and a
//! wake-up the loop's WaitSet waits on beside the devices' iceoryx2 listeners, so that the
//! loop sleeps until something arrives instead of polling.
//!
//! The wake-up is one end of a socket pair: a sender writes a byte when no wake-up is
//! pending already and the loop is asleep (or about to be), the loop reads the socket empty
//! before it empties the channel. A loop awake (working, or looking without sleeping after
//! activity) finds the item by the `pending` flag alone: no system call on either side.

use std::io::{self, Read, Write};
use std::os::unix::net::UnixStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};

use limber_services::event_loop::FdSource;

struct Wake {
    writer: UnixStream,
    /// Something was sent since the loop's last drain (and, while the loop sleeps, a byte
    /// is or is about to be in the socket: no other is needed).
    pending: AtomicBool,
    /// The loop is asleep in its WaitSet, or about to be: a sender must write a byte.
    sleeping: AtomicBool,
}

/// The sending side, cloned into each callback.
pub(crate) struct Sender<T> {
    tx: mpsc::Sender<T>,
    wake: Arc<Wake>,
}

impl<T> Clone for Sender<T> {
    fn clone(&self) -> Self {
        Sender {
            tx: self.tx.clone(),
            wake: Arc::clone(&self.wake),
        }
    }
}

impl<T> Sender<T> {
    /// Hands `item` to the loop and wakes it; `Err(item)` once the loop has ended.
    pub(crate) fn send(&self, item: T) -> Result<(), T> {
        self.tx.send(item).map_err(|e| e.0)?;
        // In this order against the loop's (`Inbox::about_to_sleep`): `pending` set, then
        // `sleeping` read. Either this read sees the loop asleep and writes, or the loop's
        // look at `pending` after it said it sleeps sees this item, and it does not sleep.
        if !self.wake.pending.swap(true, Ordering::SeqCst)
            && self.wake.sleeping.load(Ordering::SeqCst)
        {
            match (&self.wake.writer).write(&[1]) {
                Ok(_) => {}
                // The socket is full of wake-ups the loop has not read yet.
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
                Err(e) => tracing::warn!(error = %e, "cannot wake the bridge's loop"),
            }
        }
        Ok(())
    }
}

/// The receiving side, owned by the loop.
pub(crate) struct Inbox<T> {
    rx: mpsc::Receiver<T>,
    reader: UnixStream,
    source: FdSource,
    wake: Arc<Wake>,
}

/// The inbox could not be made (no file descriptors left?).
#[derive(Debug, thiserror::Error)]
#[error("cannot create the bridge's wake-up socket: {0}")]
pub struct InboxError(#[source] pub io::Error);

impl<T> Inbox<T> {
    /// A new inbox and its first sender.
    pub(crate) fn new() -> Result<(Inbox<T>, Sender<T>), InboxError> {
        let (reader, writer) = UnixStream::pair().map_err(InboxError)?;
        reader.set_nonblocking(true).map_err(InboxError)?;
        writer.set_nonblocking(true).map_err(InboxError)?;
        let source = FdSource::new(&reader).ok_or_else(|| {
            InboxError(io::Error::new(
                io::ErrorKind::InvalidInput,
                "the socket's file descriptor cannot be waited on",
            ))
        })?;
        let (tx, rx) = mpsc::channel();
        let wake = Arc::new(Wake {
            writer,
            pending: AtomicBool::new(false),
            sleeping: AtomicBool::new(false),
        });
        let sender = Sender {
            tx,
            wake: Arc::clone(&wake),
        };
        Ok((
            Inbox {
                rx,
                reader,
                source,
                wake,
            },
            sender,
        ))
    }

    /// What a WaitSet attaches: readable while something waits in the inbox.
    pub(crate) fn source(&self) -> &FdSource {
        &self.source
    }

    /// Whether something was sent since the last [`Inbox::drain`] (a look without a
    /// system call, for a loop that lingers).
    pub(crate) fn has_mail(&self) -> bool {
        self.wake.pending.load(Ordering::SeqCst)
    }

    /// The loop is about to sleep in its WaitSet: senders write their wake-up from now on.
    /// False (and the loop must not sleep) when something was sent since the last drain.
    pub(crate) fn about_to_sleep(&self) -> bool {
        self.wake.sleeping.store(true, Ordering::SeqCst);
        if self.wake.pending.load(Ordering::SeqCst) {
            self.wake.sleeping.store(false, Ordering::SeqCst);
            return false;
        }
        true
    }

    /// The loop is awake again: senders leave their wake-up out.
    pub(crate) fn awake(&self) {
        self.wake.sleeping.store(false, Ordering::SeqCst);
    }

    /// Takes everything that arrived, oldest first, and consumes the wake-ups.
    pub(crate) fn drain(&self) -> Vec<T> {
        // In this order: the socket is read empty, then `pending` cleared, then the channel
        // read. A sender that sets `pending` after it was cleared writes a wake-up that
        // nobody has read yet; one that found it set sent its item before the clearing, so
        // the channel read below finds the item. (Clearing first would let this read
        // swallow the wake-up of a sender that comes in between, leaving `pending` set
        // with the socket empty: every later item would wait for nothing.)
        let mut buf = [0u8; 64];
        loop {
            match (&self.reader).read(&mut buf) {
                Ok(0) => break,
                Ok(_) => {}
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => {
                    tracing::warn!(error = %e, "cannot read the bridge's wake-ups");
                    break;
                }
            }
        }
        self.wake.pending.store(false, Ordering::SeqCst);
        self.rx.try_iter().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_arrive_in_order_and_the_wakeup_is_consumed() {
        let (inbox, tx) = Inbox::<u32>::new().expect("an inbox");
        let tx2 = tx.clone();
        assert!(inbox.about_to_sleep(), "nothing sent yet");
        for i in 0..3 {
            assert!(tx.send(i).is_ok());
        }
        assert!(tx2.send(3).is_ok());
        // One wake-up for the four.
        let mut one = [0u8; 8];
        assert_eq!((&inbox.reader).read(&mut one).ok(), Some(1));
        inbox.awake();
        assert_eq!(inbox.drain(), vec![0, 1, 2, 3]);
        // Nothing left: the socket is empty again.
        let mut b = [0u8; 1];
        assert_eq!(
            (&inbox.reader).read(&mut b).map_err(|e| e.kind()),
            Err(io::ErrorKind::WouldBlock)
        );
        assert!(inbox.drain().is_empty());
        // A later send to a sleeping loop wakes it again.
        assert!(inbox.about_to_sleep());
        assert!(tx.send(7).is_ok());
        assert_eq!((&inbox.reader).read(&mut b).ok(), Some(1));
        inbox.awake();
        assert_eq!(inbox.drain(), vec![7]);
        // A send to a loop awake writes nothing: the flag says it.
        assert!(tx.send(8).is_ok());
        assert!(inbox.has_mail());
        assert_eq!(
            (&inbox.reader).read(&mut b).map_err(|e| e.kind()),
            Err(io::ErrorKind::WouldBlock)
        );
        // ...and a loop about to sleep then does not.
        assert!(!inbox.about_to_sleep());
        assert_eq!(inbox.drain(), vec![8]);
    }

    /// `n` items from a sender on another thread, as Zenoh's callbacks are, pausing
    /// `pause(i)` after item `i`, against a loop that sleeps in a WaitSet between drains:
    /// every item arrives in order, and no wait ends without a wake-up while items are on
    /// their way (a lost wake-up would leave the loop asleep for the wait's 10 s). Returns
    /// how many waits ended asleep (by the WaitSet, not by looking).
    fn every_item_arrives(
        n: u32,
        pause: impl Fn(u32) -> Option<std::time::Duration> + Send + 'static,
    ) -> usize {
        let (inbox, tx) = Inbox::<u32>::new().expect("an inbox");
        let sender = std::thread::spawn(move || {
            for i in 0..n {
                assert!(tx.send(i).is_ok());
                if let Some(d) = pause(i) {
                    std::thread::sleep(d);
                }
            }
        });
        let mut got = Vec::with_capacity(n as usize);
        let mut slept = 0;
        crate::waiting::with_waitset(&inbox, &Vec::new(), |wait| {
            while got.len() < n as usize {
                let woken = wait(std::time::Duration::from_secs(10), None).expect("a wait");
                assert!(
                    woken.mail,
                    "no wake-up within 10 s with {} of {n} items received",
                    got.len()
                );
                if !woken.looked {
                    slept += 1;
                }
                got.extend(inbox.drain());
            }
        })
        .expect("a WaitSet");
        sender.join().expect("the sender");
        assert!(got.iter().copied().eq(0..n), "items lost or out of order");
        slept
    }

    #[test]
    fn a_loop_that_sleeps_between_drains_gets_every_item_of_another_thread() {
        every_item_arrives(200_000, |_| None);
    }

    /// With pauses longer than the loop's linger between bursts, the loop goes to sleep
    /// between them and the sender races its falling asleep.
    #[test]
    fn a_loop_falling_asleep_between_bursts_misses_no_wakeup() {
        // Past the 50 µs linger, by a varying amount, every third item.
        let slept = every_item_arrives(3_000, |i| {
            (i % 3 == 0).then(|| std::time::Duration::from_micros(60 + u64::from(i % 7) * 30))
        });
        assert!(slept > 0, "the loop never slept: the test raced nothing");
    }

    #[test]
    fn a_send_after_the_loop_ended_gives_the_item_back() {
        let (inbox, tx) = Inbox::<u32>::new().expect("an inbox");
        drop(inbox);
        assert_eq!(tx.send(5), Err(5));
    }
}
