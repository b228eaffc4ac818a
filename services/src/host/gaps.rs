//! The per-client gap table: which commands of a client went missing before the driver saw
//! them.

/// Clients per device whose sequence numbers are followed (the most recently active).
pub const CLIENT_SLOTS: usize = 64;

/// Per-client last sequence number, to detect lost commands: a bounded table of the
/// [`CLIENT_SLOTS`] most recently active clients, least recently active evicted first. Fixed
/// size, no allocation.
///
/// Only gaps that can be proven are counted: a gap between two commands of a client in the
/// table. A client not in the table (new, evicted after [`CLIENT_SLOTS`] others commanded,
/// or from before a driver restart) starts a new entry and counts nothing: its earlier
/// sequence numbers may have been delivered before the entry was evicted.
#[derive(Debug, Clone)]
pub(crate) struct ClientTable {
    /// (client id, last sequence number, last use); client id 0 marks a free slot.
    slots: [(u64, u64, u64); CLIENT_SLOTS],
    /// Use counter (the LRU clock).
    clock: u64,
}

impl ClientTable {
    /// An empty table.
    pub(crate) fn new() -> Self {
        ClientTable {
            slots: [(0, 0, 0); CLIENT_SLOTS],
            clock: 0,
        }
    }

    /// Records `seq` from `client`; returns how many of its commands provably went missing
    /// since its previous one.
    pub(crate) fn record(&mut self, client: u64, seq: u64) -> u64 {
        self.clock += 1;
        if let Some(slot) = self.slots.iter_mut().find(|s| s.0 == client && client != 0) {
            let lost = seq.saturating_sub(slot.1.saturating_add(1));
            slot.1 = slot.1.max(seq);
            slot.2 = self.clock;
            return lost;
        }
        // Unknown: take a free slot, else the least recently active client's.
        let victim = self
            .slots
            .iter_mut()
            .min_by_key(|s| if s.0 == 0 { 0 } else { s.2 })
            .expect("CLIENT_SLOTS > 0");
        *victim = (client, seq, self.clock);
        0
    }
}

#[cfg(test)]
mod tests {
    use super::{CLIENT_SLOTS, ClientTable};

    #[test]
    fn gaps_of_a_followed_client_are_counted_exactly() {
        let mut t = ClientTable::new();
        assert_eq!(t.record(7, 1), 0);
        assert_eq!(t.record(7, 2), 0);
        // 3 and 4 went missing.
        assert_eq!(t.record(7, 5), 2);
        // A late or repeated one is no loss and does not move the mark back.
        assert_eq!(t.record(7, 4), 0);
        assert_eq!(t.record(7, 6), 0);
    }

    /// Issue 12, item 11: after more than `CLIENT_SLOTS` other clients commanded, a
    /// long-lived client's next command counted `seq - 1` overflows.
    #[test]
    fn a_forgotten_client_is_not_counted_as_losing_its_history() {
        let mut t = ClientTable::new();
        let mut lost = 0;
        for seq in 1..=1000 {
            lost += t.record(1, seq);
        }
        for other in 0..70u64 {
            lost += t.record(1000 + other, 1);
        }
        // Client 1 was evicted (the least recently active): its next command proves no gap.
        lost += t.record(1, 1001);
        assert_eq!(lost, 0);
        // Followed again from there on.
        assert_eq!(t.record(1, 1003), 1);
    }

    #[test]
    fn an_active_client_is_never_evicted_by_many_one_shot_clients() {
        let mut t = ClientTable::new();
        let mut seq = 0;
        for other in 0..(10 * CLIENT_SLOTS as u64) {
            seq += 1;
            assert_eq!(t.record(1, seq), 0);
            assert_eq!(t.record(1000 + other, 1), 0);
        }
        // Still followed: a gap is still seen.
        assert_eq!(t.record(1, seq + 3), 2);
        // Bounded: the table holds CLIENT_SLOTS entries whatever the number of clients.
        assert_eq!(t.slots.len(), CLIENT_SLOTS);
    }

    #[test]
    fn clients_are_followed_apart() {
        let mut t = ClientTable::new();
        assert_eq!(t.record(1, 1), 0);
        assert_eq!(t.record(2, 1), 0);
        assert_eq!(t.record(1, 2), 0);
        // Client 2 lost 2..=4, client 1 nothing.
        assert_eq!(t.record(2, 5), 3);
        assert_eq!(t.record(1, 3), 0);
    }

    #[test]
    fn a_first_command_with_a_high_sequence_number_proves_no_loss() {
        let mut t = ClientTable::new();
        // A client from before a driver restart: its earlier commands went to that driver.
        assert_eq!(t.record(9, 500), 0);
        assert_eq!(t.record(9, 501), 0);
    }

    #[test]
    fn client_zero_is_never_followed() {
        let mut t = ClientTable::new();
        assert_eq!(t.record(0, 1), 0);
        assert_eq!(t.record(0, 10), 0, "0 marks a free slot, not a client");
    }
}
