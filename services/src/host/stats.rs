//! What a host counts: [`HostStats`] since it started, [`Activity`] per call.

/// Counters of a host since it started.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HostStats {
    /// Commands received.
    pub commands: u64,
    /// Commands refused (any status but ok and clamped: see `Status::is_carried_out`).
    pub refused: u64,
    /// Commands lost before the driver saw them: gaps in the sequence numbers of one of
    /// the [`CLIENT_SLOTS`](super::CLIENT_SLOTS) most recently active clients (only gaps
    /// that can be proven).
    pub overflows: u64,
    /// Requests answered.
    pub requests: u64,
    /// Replies that could not be delivered (client gone).
    pub undelivered_replies: u64,
    /// State samples published.
    pub published: u64,
    /// Outcome samples published (one per command, and one per preemption).
    pub outcomes: u64,
    /// Outcomes (and results) also sent on the stream of the client they name (`told`).
    pub told: u64,
    /// Notifications to waiting clients that failed (new state or reply ready; a client
    /// waiting with a timeout re-checks anyway, so each is a delay, not a loss).
    pub failed_notifies: u64,
    /// Failed attempts to connect the state publisher to new clients (retried at the
    /// next publication or `process` call).
    pub failed_connection_updates: u64,
    /// Outcomes that could not be published on the `outcome` channel (that client then
    /// waits for it in vain, up to its timeout).
    pub failed_outcomes: u64,
    /// Commands whose motion another client's command cut short (told `Preempted`).
    pub preempted: u64,
    /// Commands and requests refused because another client held the device.
    pub leased_refusals: u64,
    /// Lease requests answered.
    pub lease_requests: u64,
    /// Deadman stops: the holder of the lease died or missed its heartbeat.
    pub deadman_stops: u64,
    /// Motion results published (one per command carried out, when its motion ended).
    pub results: u64,
}

impl core::ops::AddAssign for HostStats {
    fn add_assign(&mut self, o: HostStats) {
        self.commands += o.commands;
        self.refused += o.refused;
        self.overflows += o.overflows;
        self.requests += o.requests;
        self.undelivered_replies += o.undelivered_replies;
        self.published += o.published;
        self.outcomes += o.outcomes;
        self.told += o.told;
        self.failed_notifies += o.failed_notifies;
        self.failed_connection_updates += o.failed_connection_updates;
        self.failed_outcomes += o.failed_outcomes;
        self.preempted += o.preempted;
        self.leased_refusals += o.leased_refusals;
        self.lease_requests += o.lease_requests;
        self.deadman_stops += o.deadman_stops;
        self.results += o.results;
    }
}

impl core::ops::AddAssign for Activity {
    fn add_assign(&mut self, o: Activity) {
        self.commands += o.commands;
        self.requests += o.requests;
    }
}

impl Activity {
    /// Commands plus requests.
    pub fn total(&self) -> usize {
        self.commands + self.requests
    }
}

/// How many commands and requests one call of
/// [`DeviceHost::process`](super::DeviceHost::process) handled.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Activity {
    /// Commands handled.
    pub commands: usize,
    /// Requests answered.
    pub requests: usize,
}
