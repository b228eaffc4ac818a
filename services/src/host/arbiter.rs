//! The arbiter of one device: who may command it (the control lease, its heartbeat and its
//! deadman), whose motion a command cuts short (preemption), which commands of a client went
//! missing (the gap table), and what each client is told about its commands (the outcome
//! rules).
//!
//! Plain data in, decisions out: no port, no clock, no log. The
//! [`DeviceHost`](super::DeviceHost) does the I/O around it: it takes the messages from the
//! channels, passes the time in, looks up whether a holder's process is alive when the
//! arbiter asks, stops the device when the arbiter ends a lease, and publishes what the
//! arbiter says to tell.

use limber_interfaces::control::{get_name, put_name};
use limber_interfaces::prelude::*;

use super::gaps::ClientTable;
use super::handler::{Motion, set_bits};

/// The shortest heartbeat timeout a lease may ask for.
pub const MIN_LEASE_TIMEOUT_NS: u64 = 10_000_000;
/// The longest heartbeat timeout a lease may ask for (one hour).
pub const MAX_LEASE_TIMEOUT_NS: u64 = 3_600_000_000_000;
/// How often the host looks whether the holder's node is still alive (listing the nodes
/// of a service costs tens of microseconds: not on every cycle).
pub const HOLDER_CHECK_NS: u64 = 20_000_000;

/// Who holds a device's control lease ([`DeviceHost::holder`](super::DeviceHost::holder)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Holder {
    /// The holder's client id (its commands carry it).
    pub client_id: u64,
    /// The holder's iceoryx2 node id (when that node dies, the lease ends).
    pub node_id: u128,
    /// The heartbeat timeout (ns): no renewal for this long ends the lease.
    pub timeout_ns: u64,
    /// When the holder last renewed (`CLOCK_MONOTONIC` ns).
    pub last_renewal_ns: u64,
    pub(crate) name: [u8; 32],
    /// The tag of the arbiter that granted the lease: of the devices that share it, only
    /// that one's host looks up the holder's node (on its own lease channel, where the
    /// holder's client port is).
    pub(crate) granted_by: u64,
}

impl Holder {
    /// The holder's name, as it gave it (empty if it is not UTF-8).
    pub fn name(&self) -> &str {
        get_name(&self.name).unwrap_or("")
    }
}

/// A command as its outcome names it: the sending client, the client's sequence number of
/// the command, and the command's kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct CmdRef {
    /// The sending client (0: none).
    pub(crate) client_id: u64,
    /// The client's sequence number of the command.
    pub(crate) seq: u64,
    /// The command's kind code.
    pub(crate) kind: u32,
}

/// What one client is told about one of its commands: one outcome sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Told {
    /// The command.
    pub(crate) cmd: CmdRef,
    /// Its outcome.
    pub(crate) status: Status,
    /// The other client the outcome names (0: none): the holder whose lease refused the
    /// command, or the client whose command preempted it.
    pub(crate) other_client: u64,
    /// That client's lease name, when it holds the lease.
    pub(crate) other_name: Option<[u8; 32]>,
}

/// What a lease request changed, for the host's log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LeaseEvent {
    /// The requester acquired (or acquired again) the lease.
    Acquired,
    /// The holder released it.
    Released,
}

/// The answer to one lease request ([`Arbiter::lease_request`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct LeaseAnswer {
    /// The reply's status: ok, [`Status::Leased`] (another client holds the device), or
    /// [`Status::InvalidArgument`].
    pub(crate) status: Status,
    /// Another client (or nobody) holds the lease now: the state's `LEASED` flag follows.
    pub(crate) holder_changed: bool,
    /// What to log.
    pub(crate) event: Option<LeaseEvent>,
}

/// What the deadman must do now ([`Arbiter::deadman`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Deadman {
    /// Nothing: no lease, or its holder renewed in time and was looked up recently.
    Fine,
    /// The holder missed its heartbeat: the lease has ended; stop the device.
    Expired(Holder),
    /// Look up whether the holder's node (this id) is still alive; if not, call
    /// [`Arbiter::holder_died`].
    CheckNode(u128),
}

/// The arbiter of one device (see the module documentation). Fixed size, no allocation.
#[derive(Debug, Clone)]
pub(crate) struct Arbiter {
    /// Tells this arbiter apart from the others of a lease group (see `Holder::granted_by`).
    tag: u64,
    lease: Option<Holder>,
    /// When the holder's node is looked up next (`CLOCK_MONOTONIC` ns).
    next_holder_check_ns: u64,
    /// Per part of the device (bit i of [`Motion`]): the command that drives it now
    /// (client 0: none).
    drivers: [CmdRef; 64],
    clients: ClientTable,
}

impl Arbiter {
    /// Nobody holds the device, nothing moves, no client is known.
    #[cfg(test)]
    pub(crate) fn new() -> Self {
        Self::with_tag(0)
    }

    /// As [`Arbiter::new`], told apart from the other arbiters of its lease group by `tag`.
    pub(crate) fn with_tag(tag: u64) -> Self {
        Arbiter {
            tag,
            lease: None,
            next_holder_check_ns: 0,
            drivers: [CmdRef::default(); 64],
            clients: ClientTable::new(),
        }
    }

    /// Who holds the lease, if anybody.
    pub(crate) fn holder(&self) -> Option<&Holder> {
        self.lease.as_ref()
    }

    /// The holder of the lease when the sender is not it: the sender's commands, and its
    /// requests that may change the device, are refused ([`Status::Leased`]). The sender is
    /// the client id its message carries *and* the node the transport says sent it
    /// (`node`, from iceoryx2's registry of the service's ports): a client that writes the
    /// holder's id into its messages from another process is not the holder.
    ///
    /// On a device that shares the lease of another (a lease group), the holder is its
    /// process: any client of the holder's node is the holder there (a program that holds
    /// the arm's joints commands the arm's limb and gripper through clients of their own).
    pub(crate) fn refusing(&self, client_id: u64, node: u128) -> Option<&Holder> {
        self.lease.as_ref().filter(|l| {
            if l.granted_by == self.tag {
                l.client_id != client_id || l.node_id != node
            } else {
                l.node_id != node
            }
        })
    }

    /// A command arrived: returns how many earlier commands of its client provably went
    /// missing since its previous one (the gap table).
    pub(crate) fn arrived(&mut self, cmd: CmdRef) -> u64 {
        self.clients.record(cmd.client_id, cmd.seq)
    }

    /// What the sender of `cmd` is told when its command ended with `status`: a command
    /// refused because another client holds the device names that holder.
    pub(crate) fn outcome(&self, cmd: CmdRef, node: u128, status: Status) -> Told {
        match self.refusing(cmd.client_id, node) {
            Some(h) if status == Status::Leased => Told {
                cmd,
                status,
                other_client: h.client_id,
                other_name: Some(h.name),
            },
            _ => Told {
                cmd,
                status,
                other_client: 0,
                other_name: None,
            },
        }
    }

    /// `cmd`, driving `motion`, was carried out: each other client's command whose motion
    /// it cut short is told [`Status::Preempted`] (once, whatever the number of its parts it
    /// cut), naming the client that cut it; the parts `cmd` drives are its own from now on.
    /// A motion of other parts, or of the same client, preempts nothing.
    pub(crate) fn carried_out(&mut self, cmd: CmdRef, motion: Motion, mut tell: impl FnMut(Told)) {
        let name = self
            .lease
            .filter(|l| l.client_id == cmd.client_id)
            .map(|l| l.name);
        // Only the set bits are visited: this runs on every command, and two scans of
        // all 64 bits took some 3 % of a spinning driver's time in a profile.
        for bit in set_bits(motion.cuts) {
            let cut = self.drivers[bit];
            let below = motion.cuts & ((1u64 << bit) - 1);
            let told_already = set_bits(below).any(|b| self.drivers[b] == cut);
            if cut.client_id != 0 && cut.client_id != cmd.client_id && !told_already {
                tell(Told {
                    cmd: cut,
                    status: Status::Preempted,
                    other_client: cmd.client_id,
                    other_name: name,
                });
            }
        }
        for bit in set_bits(motion.drives) {
            self.drivers[bit] = cmd;
        }
    }

    /// Applies one lease request (acquire, renew, release, query) at `now_ns`, sent from
    /// node `node` as the transport says (0: not known; never the node id the request
    /// carries, which the client writes itself).
    pub(crate) fn lease_request(&mut self, req: &LeaseReq, node: u128, now_ns: u64) -> LeaseAnswer {
        let before = self.lease.map(|l| l.client_id);
        let (status, event) = self.lease_op(req, node, now_ns);
        LeaseAnswer {
            status,
            holder_changed: before != self.lease.map(|l| l.client_id),
            event,
        }
    }

    fn lease_op(
        &mut self,
        req: &LeaseReq,
        node: u128,
        now_ns: u64,
    ) -> (Status, Option<LeaseEvent>) {
        let other = self.refusing(req.client_id, node).is_some();
        match req.op {
            lease_op::ACQUIRE => {
                if other {
                    return (Status::Leased, None);
                }
                if req.client_id == 0
                    || node == 0
                    || !(MIN_LEASE_TIMEOUT_NS..=MAX_LEASE_TIMEOUT_NS).contains(&req.timeout_ns)
                    || get_name(&req.name).is_err()
                {
                    return (Status::InvalidArgument, None);
                }
                let mut name = [0u8; 32];
                put_name(&mut name, get_name(&req.name).unwrap_or(""));
                self.lease = Some(Holder {
                    client_id: req.client_id,
                    node_id: node,
                    timeout_ns: req.timeout_ns,
                    last_renewal_ns: now_ns,
                    name,
                    granted_by: self.tag,
                });
                (Status::Ok, Some(LeaseEvent::Acquired))
            }
            lease_op::RENEW => {
                if other {
                    return (Status::Leased, None);
                }
                // Not held (ended or never taken): the reply names no holder.
                if let Some(l) = self.lease.as_mut() {
                    l.last_renewal_ns = now_ns;
                }
                (Status::Ok, None)
            }
            lease_op::RELEASE => {
                if other {
                    return (Status::Leased, None);
                }
                let event = self.lease.take().map(|_| LeaseEvent::Released);
                (Status::Ok, event)
            }
            lease_op::QUERY => (Status::Ok, None),
            _ => (Status::InvalidArgument, None),
        }
    }

    /// The reply to `req`, answered `status`: who holds the device now.
    pub(crate) fn lease_reply(&self, req: &LeaseReq, status: Status) -> LeaseReply {
        let mut reply = LeaseReply {
            seq: req.seq,
            status: status.code(),
            ..LeaseReply::default()
        };
        if let Some(l) = &self.lease {
            reply.holder_client = l.client_id;
            reply.set_holder_node(l.node_id);
            reply.timeout_ns = l.timeout_ns;
            reply.holder_name = l.name;
        }
        reply
    }

    /// The lease as the devices that share it hold it: a copy for the others of the group.
    pub(crate) fn shared(&self) -> Option<Holder> {
        self.lease
    }

    /// Takes the lease of the group (acquired, renewed or released on another device of
    /// it); returns whether another client (or nobody) holds it now, so the state's
    /// `LEASED` flag must follow.
    pub(crate) fn share(&mut self, lease: Option<Holder>) -> bool {
        let before = self.lease.map(|l| (l.client_id, l.node_id));
        self.lease = lease;
        before != lease.map(|l| (l.client_id, l.node_id))
    }

    /// The deadman ended the group's lease on another device: this one stops too, so no
    /// command drives anything any more.
    pub(crate) fn ended_elsewhere(&mut self) {
        self.end_lease();
    }

    /// The deadman at `now_ns`: ends the lease whose holder missed its heartbeat (more than
    /// its timeout since the last renewal), or asks for the holder's node to be looked up
    /// (at most every [`HOLDER_CHECK_NS`]; only by the arbiter that granted the lease, when
    /// several devices share it).
    pub(crate) fn deadman(&mut self, now_ns: u64) -> Deadman {
        let Some(l) = self.lease else {
            return Deadman::Fine;
        };
        if now_ns.saturating_sub(l.last_renewal_ns) > l.timeout_ns {
            self.end_lease();
            return Deadman::Expired(l);
        }
        if l.granted_by == self.tag && now_ns >= self.next_holder_check_ns {
            self.next_holder_check_ns = now_ns.saturating_add(HOLDER_CHECK_NS);
            return Deadman::CheckNode(l.node_id);
        }
        Deadman::Fine
    }

    /// The node `node_id` is gone: when it is the holder's, its lease ends (returned: stop
    /// the device).
    pub(crate) fn holder_died(&mut self, node_id: u128) -> Option<Holder> {
        let l = self.lease.filter(|l| l.node_id == node_id)?;
        self.end_lease();
        Some(l)
    }

    /// Ends the lease by the deadman: the device stops, so no command drives anything any
    /// more.
    fn end_lease(&mut self) {
        self.lease = None;
        self.drivers = [CmdRef::default(); 64];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;
    const HOLDER: u64 = 0xA;
    const OTHER: u64 = 0xB;

    fn lease(op: u32, client_id: u64, timeout_ns: u64, name: &str) -> LeaseReq {
        let mut req = LeaseReq {
            client_id,
            seq: 1,
            timeout_ns,
            op,
            ..LeaseReq::default()
        };
        req.set_node_id(u128::from(client_id) << 64 | 7);
        put_name(&mut req.name, name);
        req
    }

    fn acquire(a: &mut Arbiter, client: u64, timeout_ns: u64, now: u64) -> LeaseAnswer {
        let req = lease(lease_op::ACQUIRE, client, timeout_ns, "holder");
        a.lease_request(&req, req.node_id(), now)
    }

    /// The node of a client in these tests (as `lease` puts it in the request).
    fn node(client_id: u64) -> u128 {
        u128::from(client_id) << 64 | 7
    }

    fn cmd(client_id: u64, seq: u64) -> CmdRef {
        CmdRef {
            client_id,
            seq,
            kind: 1,
        }
    }

    /// Every outcome `cmd` with `motion` makes the arbiter tell.
    fn carry(a: &mut Arbiter, c: CmdRef, motion: Motion) -> Vec<Told> {
        let mut told = Vec::new();
        a.carried_out(c, motion, |t| told.push(t));
        told
    }

    #[test]
    fn a_free_device_is_acquired_and_the_reply_names_the_holder() {
        let mut a = Arbiter::new();
        let ans = acquire(&mut a, HOLDER, 100 * MS, 0);
        assert_eq!(ans.status, Status::Ok);
        assert!(ans.holder_changed);
        assert_eq!(ans.event, Some(LeaseEvent::Acquired));
        let h = a.holder().unwrap();
        assert_eq!(
            (h.client_id, h.name(), h.timeout_ns),
            (HOLDER, "holder", 100 * MS)
        );
        let req = lease(lease_op::QUERY, OTHER, 0, "");
        let reply = a.lease_reply(&req, Status::Ok);
        assert_eq!(reply.holder_client, HOLDER);
        assert_eq!(get_name(&reply.holder_name).unwrap(), "holder");
        assert_eq!(reply.timeout_ns, 100 * MS);
    }

    #[test]
    fn acquiring_a_held_device_is_refused_and_the_reply_names_the_holder() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        let req = lease(lease_op::ACQUIRE, OTHER, 100 * MS, "other");
        let ans = a.lease_request(&req, req.node_id(), 1);
        assert_eq!(ans.status, Status::Leased);
        assert!(!ans.holder_changed);
        assert_eq!(ans.event, None);
        let reply = a.lease_reply(&req, ans.status);
        assert_eq!(reply.status, Status::Leased.code());
        assert_eq!(reply.holder_client, HOLDER);
        assert_eq!(get_name(&reply.holder_name).unwrap(), "holder");
    }

    #[test]
    fn the_holder_may_acquire_again_without_a_change_of_holder() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        let ans = acquire(&mut a, HOLDER, 200 * MS, 5 * MS);
        assert_eq!(ans.status, Status::Ok);
        assert!(!ans.holder_changed);
        assert_eq!(a.holder().unwrap().timeout_ns, 200 * MS);
    }

    #[test]
    fn a_bad_acquire_is_an_invalid_argument_and_takes_nothing() {
        let mut a = Arbiter::new();
        for timeout in [MIN_LEASE_TIMEOUT_NS - 1, MAX_LEASE_TIMEOUT_NS + 1, 0] {
            let ans = acquire(&mut a, HOLDER, timeout, 0);
            assert_eq!(ans.status, Status::InvalidArgument, "timeout {timeout}");
        }
        assert_eq!(
            acquire(&mut a, 0, 100 * MS, 0).status,
            Status::InvalidArgument
        );
        let mut no_node = lease(lease_op::ACQUIRE, HOLDER, 100 * MS, "x");
        no_node.set_node_id(0);
        assert_eq!(
            a.lease_request(&no_node, no_node.node_id(), 0).status,
            Status::InvalidArgument
        );
        let mut bad_name = lease(lease_op::ACQUIRE, HOLDER, 100 * MS, "x");
        bad_name.name = [0xff; 32];
        assert_eq!(
            a.lease_request(&bad_name, bad_name.node_id(), 0).status,
            Status::InvalidArgument
        );
        let unknown = lease(99, HOLDER, 100 * MS, "x");
        assert_eq!(
            a.lease_request(&unknown, unknown.node_id(), 0).status,
            Status::InvalidArgument
        );
        assert!(a.holder().is_none());
        // The bounds themselves are accepted.
        assert_eq!(
            acquire(&mut a, HOLDER, MIN_LEASE_TIMEOUT_NS, 0).status,
            Status::Ok
        );
        assert_eq!(
            acquire(&mut a, HOLDER, MAX_LEASE_TIMEOUT_NS, 0).status,
            Status::Ok
        );
    }

    #[test]
    fn a_lease_expires_when_its_holder_misses_its_heartbeat() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 1000 * MS);
        a.deadman(1000 * MS); // the first look-up of the node
        // Exactly the timeout: still held.
        assert_eq!(
            a.deadman(1100 * MS),
            Deadman::CheckNode(a.holder().unwrap().node_id)
        );
        assert!(a.holder().is_some());
        match a.deadman(1100 * MS + 1) {
            Deadman::Expired(h) => assert_eq!(h.client_id, HOLDER),
            other => panic!("{other:?}"),
        }
        assert!(a.holder().is_none());
        assert_eq!(a.deadman(2000 * MS), Deadman::Fine, "ended once");
    }

    #[test]
    fn renewals_keep_the_lease() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        for t in 1..=10 {
            let now = t * 80 * MS;
            assert!(!matches!(a.deadman(now), Deadman::Expired(_)), "at {now}");
            let renew = lease(lease_op::RENEW, HOLDER, 100 * MS, "");
            let ans = a.lease_request(&renew, renew.node_id(), now);
            assert_eq!((ans.status, ans.holder_changed), (Status::Ok, false));
        }
        assert_eq!(a.holder().unwrap().last_renewal_ns, 800 * MS);
        assert!(matches!(a.deadman(901 * MS), Deadman::Expired(_)));
    }

    #[test]
    fn another_clients_renewal_is_refused_and_does_not_keep_the_lease() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        let renew = lease(lease_op::RENEW, OTHER, 100 * MS, "");
        assert_eq!(
            a.lease_request(&renew, renew.node_id(), 90 * MS).status,
            Status::Leased
        );
        assert!(matches!(a.deadman(101 * MS), Deadman::Expired(_)));
    }

    #[test]
    fn renewing_a_lease_nobody_holds_is_ok_and_takes_nothing() {
        let mut a = Arbiter::new();
        let renew = lease(lease_op::RENEW, HOLDER, 100 * MS, "");
        let ans = a.lease_request(&renew, renew.node_id(), 0);
        assert_eq!((ans.status, ans.holder_changed), (Status::Ok, false));
        assert!(a.holder().is_none());
        assert_eq!(a.lease_reply(&renew, ans.status).holder_client, 0);
    }

    #[test]
    fn the_holders_node_is_looked_up_at_most_every_check_period() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, MAX_LEASE_TIMEOUT_NS, 0);
        let node = a.holder().unwrap().node_id;
        assert_eq!(a.deadman(0), Deadman::CheckNode(node));
        assert_eq!(a.deadman(HOLDER_CHECK_NS - 1), Deadman::Fine);
        assert_eq!(a.deadman(HOLDER_CHECK_NS), Deadman::CheckNode(node));
        assert_eq!(a.deadman(HOLDER_CHECK_NS + 1), Deadman::Fine);
    }

    #[test]
    fn the_holders_death_ends_the_lease_and_another_nodes_does_not() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        let node = a.holder().unwrap().node_id;
        assert_eq!(a.holder_died(node + 1), None);
        assert!(a.holder().is_some());
        assert_eq!(a.holder_died(node).map(|h| h.client_id), Some(HOLDER));
        assert!(a.holder().is_none());
        assert_eq!(a.holder_died(node), None, "ended once");
        // The device is free for another client.
        assert_eq!(acquire(&mut a, OTHER, 100 * MS, 1).status, Status::Ok);
    }

    #[test]
    fn the_holder_releases_and_others_may_not() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        let by_other = lease(lease_op::RELEASE, OTHER, 0, "");
        assert_eq!(
            a.lease_request(&by_other, by_other.node_id(), 1).status,
            Status::Leased
        );
        assert!(a.holder().is_some());
        let by_holder = lease(lease_op::RELEASE, HOLDER, 0, "");
        let ans = a.lease_request(&by_holder, by_holder.node_id(), 2);
        assert_eq!(ans.status, Status::Ok);
        assert!(ans.holder_changed);
        assert_eq!(ans.event, Some(LeaseEvent::Released));
        // Released twice: ok, nothing to log.
        let again = a.lease_request(&by_holder, by_holder.node_id(), 3);
        assert_eq!((again.status, again.event), (Status::Ok, None));
        assert_eq!(
            a.deadman(10_000 * MS),
            Deadman::Fine,
            "no deadman without a lease"
        );
    }

    #[test]
    fn a_query_changes_nothing() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        let q = lease(lease_op::QUERY, OTHER, 0, "");
        let ans = a.lease_request(&q, q.node_id(), 50 * MS);
        assert_eq!(
            (ans.status, ans.holder_changed, ans.event),
            (Status::Ok, false, None)
        );
        assert_eq!(a.holder().unwrap().last_renewal_ns, 0, "not a renewal");
    }

    #[test]
    fn a_held_device_refuses_others_naming_the_holder_and_admits_the_holder() {
        let mut a = Arbiter::new();
        assert!(
            a.refusing(OTHER, node(OTHER)).is_none(),
            "no lease: last writer wins"
        );
        acquire(&mut a, HOLDER, 100 * MS, 0);
        assert!(a.refusing(HOLDER, node(HOLDER)).is_none());
        assert_eq!(
            a.refusing(OTHER, node(OTHER)).map(|h| h.client_id),
            Some(HOLDER)
        );
        let told = a.outcome(cmd(OTHER, 3), node(OTHER), Status::Leased);
        assert_eq!(told.status, Status::Leased);
        assert_eq!(told.other_client, HOLDER);
        assert_eq!(get_name(&told.other_name.unwrap()).unwrap(), "holder");
        assert_eq!(told.cmd, cmd(OTHER, 3));
    }

    #[test]
    fn outcomes_other_than_a_lease_refusal_name_nobody() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        for status in [Status::Ok, Status::BeyondLimits, Status::Unsupported] {
            let told = a.outcome(cmd(HOLDER, 1), node(HOLDER), status);
            assert_eq!((told.other_client, told.other_name), (0, None), "{status}");
        }
        // The holder's own command is never refused by its lease.
        let told = a.outcome(cmd(HOLDER, 2), node(HOLDER), Status::Leased);
        assert_eq!(told.other_client, 0);
    }

    #[test]
    fn a_motion_cut_short_by_another_client_is_preempted() {
        let mut a = Arbiter::new();
        assert!(carry(&mut a, cmd(1, 1), Motion::of(0b100, 0)).is_empty());
        let told = carry(&mut a, cmd(2, 1), Motion::of(0b100, 0b100));
        assert_eq!(
            told,
            vec![Told {
                cmd: cmd(1, 1),
                status: Status::Preempted,
                other_client: 2,
                other_name: None,
            }]
        );
    }

    #[test]
    fn a_motion_of_another_joint_preempts_nothing() {
        let mut a = Arbiter::new();
        carry(&mut a, cmd(1, 1), Motion::of(0b001, 0));
        // Joint 1 is moving, but client 1 drives joint 0: nobody to tell.
        assert!(carry(&mut a, cmd(2, 1), Motion::of(0b010, 0b011)).is_empty());
        // Joint 0 is still client 1's.
        assert_eq!(carry(&mut a, cmd(3, 1), Motion::of(0b001, 0b001)).len(), 1);
    }

    #[test]
    fn a_clients_own_next_motion_preempts_nothing() {
        let mut a = Arbiter::new();
        carry(&mut a, cmd(1, 1), Motion::of(0b1, 0));
        assert!(carry(&mut a, cmd(1, 2), Motion::of(0b1, 0b1)).is_empty());
        // Now the latest command of client 1 drives joint 0.
        let told = carry(&mut a, cmd(2, 1), Motion::of(0b1, 0b1));
        assert_eq!(told[0].cmd, cmd(1, 2));
    }

    #[test]
    fn a_motion_that_ended_is_not_preempted() {
        let mut a = Arbiter::new();
        carry(&mut a, cmd(1, 1), Motion::of(0b1, 0));
        // The joint is no longer moving: a new command drives it without cutting.
        assert!(carry(&mut a, cmd(2, 1), Motion::of(0b1, 0)).is_empty());
    }

    #[test]
    fn a_command_of_several_joints_is_told_once() {
        let mut a = Arbiter::new();
        carry(&mut a, cmd(1, 1), Motion::of(0b111, 0));
        let told = carry(&mut a, cmd(2, 1), Motion::of(0b111, 0b111));
        assert_eq!(told.len(), 1, "{told:?}");
    }

    #[test]
    fn every_client_cut_short_is_told() {
        let mut a = Arbiter::new();
        carry(&mut a, cmd(1, 1), Motion::of(0b01, 0));
        carry(&mut a, cmd(2, 1), Motion::of(0b10, 0));
        let told = carry(&mut a, cmd(3, 1), Motion::of(0b11, 0b11));
        let cut: Vec<u64> = told.iter().map(|t| t.cmd.client_id).collect();
        assert_eq!(cut, vec![1, 2]);
        assert!(told.iter().all(|t| t.other_client == 3));
    }

    #[test]
    fn a_preemption_by_the_holder_names_it() {
        let mut a = Arbiter::new();
        carry(&mut a, cmd(OTHER, 1), Motion::of(0b1, 0));
        acquire(&mut a, HOLDER, 100 * MS, 0);
        let told = carry(&mut a, cmd(HOLDER, 1), Motion::of(0b1, 0b1));
        assert_eq!(told[0].other_client, HOLDER);
        assert_eq!(get_name(&told[0].other_name.unwrap()).unwrap(), "holder");
    }

    #[test]
    fn after_the_deadman_nothing_is_preempted() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        carry(&mut a, cmd(HOLDER, 1), Motion::of(0b1, 0));
        assert!(matches!(a.deadman(200 * MS), Deadman::Expired(_)));
        // The device was stopped: the holder's motion is no more.
        assert!(carry(&mut a, cmd(OTHER, 1), Motion::of(0b1, 0b1)).is_empty());
    }

    #[test]
    fn lost_commands_are_counted_per_client() {
        let mut a = Arbiter::new();
        assert_eq!(a.arrived(cmd(1, 1)), 0);
        assert_eq!(a.arrived(cmd(2, 1)), 0);
        assert_eq!(a.arrived(cmd(1, 4)), 2);
        assert_eq!(a.arrived(cmd(2, 2)), 0);
        assert_eq!(a.arrived(cmd(2, 10)), 7);
    }

    #[test]
    fn the_holders_id_written_by_another_process_is_not_the_holder() {
        let mut a = Arbiter::new();
        acquire(&mut a, HOLDER, 100 * MS, 0);
        let forger = node(OTHER);
        // A command carrying the holder's client id, from another node: refused, naming the
        // holder.
        assert_eq!(
            a.refusing(HOLDER, forger).map(|h| h.client_id),
            Some(HOLDER)
        );
        let told = a.outcome(cmd(HOLDER, 9), forger, Status::Leased);
        assert_eq!(told.other_client, HOLDER);
        // Its RELEASE and RENEW as the holder are refused and the lease stays.
        for op in [lease_op::RELEASE, lease_op::RENEW] {
            let req = lease(op, HOLDER, 100 * MS, "holder");
            let ans = a.lease_request(&req, forger, 1);
            assert_eq!(ans.status, Status::Leased, "op {op}");
        }
        assert_eq!(a.holder().map(|h| h.node_id), Some(node(HOLDER)));
        // An ACQUIRE whose request carries the holder's node but comes from the forger's.
        let mut req = lease(lease_op::ACQUIRE, OTHER, 100 * MS, "mallory");
        req.set_node_id(node(HOLDER));
        assert_eq!(a.lease_request(&req, forger, 2).status, Status::Leased);
        // Nobody holds: the lease is bound to the node the transport names, not the one the
        // request carries.
        let mut b = Arbiter::new();
        let mut req = lease(lease_op::ACQUIRE, OTHER, 100 * MS, "mallory");
        req.set_node_id(node(HOLDER));
        assert_eq!(b.lease_request(&req, forger, 0).status, Status::Ok);
        assert_eq!(b.holder().map(|h| h.node_id), Some(forger));
    }

    #[test]
    fn a_shared_lease_admits_the_holders_process_and_refuses_others_on_every_device() {
        let mut arm = Arbiter::with_tag(1);
        let mut limb = Arbiter::with_tag(2);
        acquire(&mut arm, HOLDER, 100 * MS, 0);
        assert!(limb.share(arm.shared()), "the limb's holder changed");
        // On the arm, the holder is its client; on the limb, any client of its process.
        assert!(arm.refusing(HOLDER + 1, node(HOLDER)).is_some());
        assert!(limb.refusing(HOLDER + 1, node(HOLDER)).is_none());
        assert_eq!(
            limb.refusing(OTHER, node(OTHER)).map(|h| h.name()),
            Some("holder")
        );
        let told = limb.outcome(cmd(OTHER, 1), node(OTHER), Status::Leased);
        assert_eq!(told.other_client, HOLDER);
        // Only the arbiter that granted the lease looks up the holder's node; both end it
        // when its heartbeat is missed.
        assert_eq!(limb.deadman(0), Deadman::Fine);
        assert!(matches!(arm.deadman(0), Deadman::CheckNode(_)));
        assert!(matches!(limb.deadman(101 * MS), Deadman::Expired(_)));
        assert!(matches!(arm.deadman(101 * MS), Deadman::Expired(_)));
        // Released: the lease is shared as none.
        assert!(limb.share(None) || limb.holder().is_none());
        assert!(limb.holder().is_none());
    }
}
