//! The model's outbox: the P2OS commands a device's command, request or packet produced,
//! in order, waiting for the driver to write them to the link. A fixed-capacity ring:
//! nothing is allocated per cycle.

use limber_p2os::Command;
use limber_services::Origin;

/// Commands one handler call may queue before the driver drains them (the most a single
/// call produces is a limb SPEED request: one ARM_SPEED per joint).
pub const OUTBOX_CAPACITY: usize = 32;

/// A command waiting for the link, with the origin of the client command that produced it
/// (all zero for the driver's own commands) for the command-to-wire statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Queued {
    /// The P2OS command.
    pub cmd: Command,
    /// Who asked for it.
    pub from: Origin,
}

/// The outbox is full: the command was not queued (nothing was lost from the queue).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the outbox is full ({OUTBOX_CAPACITY} commands not yet written)")]
pub struct OutboxFull;

/// A fixed-capacity FIFO of [`Queued`] commands.
#[derive(Debug, Clone)]
pub struct Outbox {
    slots: [Option<Queued>; OUTBOX_CAPACITY],
    head: usize,
    len: usize,
}

impl Default for Outbox {
    fn default() -> Self {
        Outbox {
            slots: [None; OUTBOX_CAPACITY],
            head: 0,
            len: 0,
        }
    }
}

impl Outbox {
    /// Appends a command.
    pub fn push(&mut self, q: Queued) -> Result<(), OutboxFull> {
        if self.len == OUTBOX_CAPACITY {
            return Err(OutboxFull);
        }
        self.slots[(self.head + self.len) % OUTBOX_CAPACITY] = Some(q);
        self.len += 1;
        Ok(())
    }

    /// Takes the oldest command.
    pub fn pop(&mut self) -> Option<Queued> {
        if self.len == 0 {
            return None;
        }
        let q = self.slots[self.head].take();
        self.head = (self.head + 1) % OUTBOX_CAPACITY;
        self.len -= 1;
        q
    }

    /// Commands waiting.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when nothing waits.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Forgets every waiting command (the link went down: nothing queued before a link
    /// loss is sent after it); returns how many there were.
    pub fn clear(&mut self) -> usize {
        let n = self.len;
        while self.pop().is_some() {}
        n
    }

    /// The waiting commands, oldest first (not removed).
    pub fn iter(&self) -> impl Iterator<Item = &Queued> + '_ {
        (0..self.len).filter_map(|i| self.slots[(self.head + i) % OUTBOX_CAPACITY].as_ref())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(n: u16) -> Queued {
        Queued {
            cmd: Command::ArmAutoPark(n),
            from: Origin {
                client_id: 0,
                seq: 0,
                sent_ns: 0,
                received_ns: 0,
            },
        }
    }

    #[test]
    fn first_in_first_out_across_the_wrap_and_full_refuses() {
        let mut o = Outbox::default();
        for round in 0..3u16 {
            for i in 0..OUTBOX_CAPACITY as u16 {
                o.push(q(round * 100 + i)).unwrap();
            }
            assert_eq!(o.push(q(999)), Err(OutboxFull));
            for i in 0..OUTBOX_CAPACITY as u16 / 2 {
                assert_eq!(o.pop(), Some(q(round * 100 + i)));
            }
            assert_eq!(o.clear(), OUTBOX_CAPACITY / 2);
            assert!(o.is_empty() && o.pop().is_none());
        }
    }
}
