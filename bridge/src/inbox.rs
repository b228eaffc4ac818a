//! What Zenoh's callbacks (on Zenoh's threads) hand to a bridge's loop: a channel, and a
//! wake-up the loop's WaitSet waits on beside the devices' iceoryx2 listeners, so that the
//! loop sleeps until something arrives instead of polling.
//!
//! The wake-up is one end of a socket pair: a sender writes a byte when no wake-up is
//! pending already, the loop reads the socket empty before it empties the channel.

use std::io::{self, Read, Write};
use std::os::unix::net::UnixStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};

use limber_services::event_loop::FdSource;

struct Wake {
    writer: UnixStream,
    /// A byte is (or is about to be) in the socket: no other is needed.
    pending: AtomicBool,
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
        if !self.wake.pending.swap(true, Ordering::SeqCst) {
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
        for i in 0..3 {
            assert!(tx.send(i).is_ok());
        }
        assert!(tx2.send(3).is_ok());
        assert_eq!(inbox.drain(), vec![0, 1, 2, 3]);
        // Nothing left: the socket is empty again.
        let mut b = [0u8; 1];
        assert_eq!(
            (&inbox.reader).read(&mut b).map_err(|e| e.kind()),
            Err(io::ErrorKind::WouldBlock)
        );
        assert!(inbox.drain().is_empty());
        // A later send wakes again.
        assert!(tx.send(7).is_ok());
        assert_eq!((&inbox.reader).read(&mut b).ok(), Some(1));
        assert_eq!(inbox.drain(), vec![7]);
    }

    /// A sender on another thread, as Zenoh's callbacks are, against a loop that sleeps
    /// in a WaitSet between drains: every item arrives, and no wait ends without a wake-up
    /// while items are on their way (a lost wake-up would leave the loop asleep).
    #[test]
    fn a_loop_that_sleeps_between_drains_gets_every_item_of_another_thread() {
        const N: u32 = 200_000;
        let (inbox, tx) = Inbox::<u32>::new().expect("an inbox");
        let sender = std::thread::spawn(move || {
            for i in 0..N {
                assert!(tx.send(i).is_ok());
            }
        });
        let mut got = Vec::with_capacity(N as usize);
        crate::waiting::with_waitset(&inbox, &Vec::new(), |wait| {
            while got.len() < N as usize {
                let woken = wait(std::time::Duration::from_secs(10), None).expect("a wait");
                assert!(
                    woken.mail,
                    "no wake-up within 10 s with {} of {N} items received",
                    got.len()
                );
                got.extend(inbox.drain());
            }
        })
        .expect("a WaitSet");
        sender.join().expect("the sender");
        assert!(got.iter().copied().eq(0..N), "items lost or out of order");
    }

    #[test]
    fn a_send_after_the_loop_ended_gives_the_item_back() {
        let (inbox, tx) = Inbox::<u32>::new().expect("an inbox");
        drop(inbox);
        assert_eq!(tx.send(5), Err(5));
    }
}
