//! A session's outgoing DATA: held until REQ DATA in PULL mode, sent at once in PUSH mode,
//! with Player's replace rules and queue limit.

use std::collections::VecDeque;

use crate::header::DevAddr;
use crate::player::ReplaceRule;

/// Player's default queue length (`PLAYER_MSGQUEUE_DEFAULT_MAXLEN`).
pub const QUEUE_MAX: usize = 1024;

/// A waiting message: its address, type and subtype (for the replace rules) and its
/// bytes (header and body).
#[derive(Debug, Clone)]
struct Waiting {
    addr: DevAddr,
    mtype: u8,
    subtype: u8,
    bytes: Vec<u8>,
}

/// The queue.
#[derive(Debug, Default)]
pub struct OutQueue {
    waiting: VecDeque<Waiting>,
    rules: Vec<ReplaceRule>,
    overflow: u32,
}

impl OutQueue {
    /// Adds a rule; a later rule for the same pattern wins over an earlier one.
    pub fn add_rule(&mut self, rule: ReplaceRule) {
        self.rules.insert(0, rule);
    }

    /// Whether a new message replaces a waiting one of the same kind: the first matching
    /// rule says; without one, never (Player's default for DATA).
    fn replaces(&self, addr: DevAddr, mtype: u8, subtype: u8) -> bool {
        self.rules
            .iter()
            .find(|r| r.matches(addr, mtype, subtype))
            .is_some_and(|r| r.replace)
    }

    /// Queues a message (replacing a waiting one when a rule says so); past
    /// [`QUEUE_MAX`] it is dropped and counted.
    pub fn push(&mut self, addr: DevAddr, mtype: u8, subtype: u8, bytes: Vec<u8>) {
        if self.replaces(addr, mtype, subtype)
            && let Some(w) = self
                .waiting
                .iter_mut()
                .find(|w| w.addr == addr && w.mtype == mtype && w.subtype == subtype)
        {
            w.bytes = bytes;
            return;
        }
        if self.waiting.len() >= QUEUE_MAX {
            self.overflow = self.overflow.saturating_add(1);
            return;
        }
        self.waiting.push_back(Waiting {
            addr,
            mtype,
            subtype,
            bytes,
        });
    }

    /// Whether nothing waits.
    pub fn is_empty(&self) -> bool {
        self.waiting.is_empty()
    }

    /// Takes every waiting message, in order, and the count of those dropped since the
    /// last take.
    pub fn take(&mut self) -> (Vec<Vec<u8>>, u32) {
        let msgs = self.waiting.drain(..).map(|w| w.bytes).collect();
        (msgs, core::mem::take(&mut self.overflow))
    }

    /// Forgets the waiting messages of a device (closed).
    pub fn forget(&mut self, addr: DevAddr) {
        self.waiting.retain(|w| w.addr != addr);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn addr(index: u16) -> DevAddr {
        DevAddr {
            interf: 53,
            index,
            ..DevAddr::default()
        }
    }

    #[test]
    fn data_accumulates_by_default_and_is_replaced_under_a_rule() {
        let mut q = OutQueue::default();
        q.push(addr(0), 1, 1, vec![1]);
        q.push(addr(0), 1, 1, vec![2]);
        assert_eq!(q.take().0, vec![vec![1], vec![2]]);
        q.add_rule(ReplaceRule {
            interf: -1,
            index: -1,
            mtype: 1,
            subtype: -1,
            replace: true,
        });
        q.push(addr(0), 1, 1, vec![1]);
        q.push(addr(1), 1, 1, vec![3]);
        q.push(addr(0), 1, 1, vec![2]);
        assert_eq!(q.take().0, vec![vec![2], vec![3]]);
    }

    #[test]
    fn past_the_limit_messages_are_dropped_and_counted() {
        let mut q = OutQueue::default();
        for i in 0..QUEUE_MAX + 5 {
            q.push(addr(0), 1, 1, vec![i as u8]);
        }
        let (msgs, dropped) = q.take();
        assert_eq!(msgs.len(), QUEUE_MAX);
        assert_eq!(dropped, 5);
        assert!(q.is_empty());
    }
}
