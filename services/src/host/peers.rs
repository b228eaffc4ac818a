//! New peers and what a dead one left half made.
//!
//! A client killed between iceoryx2's creating one of its connection segments and sizing it
//! leaves an empty, unreadable file. The driver's ports connect to a new peer inside the
//! next `send`, `receive` or `update_connections`; iceoryx2 0.10 then opens that file and,
//! as root, retries it every millisecond for ever (`posix_shared_memory::open_impl`: root
//! may open it, its size is zero, and that case never reaches the timeout): the driver's
//! loop froze in its next state publication. So before its ports connect, whenever a
//! client came or went, the host removes the half-made segments that name a port whose
//! process is gone (nobody will finish them); iceoryx2 then makes the connection afresh, to
//! a peer its cleanup removes later. (A client killed in the microseconds between the
//! host's look and iceoryx2's connection is not covered: the look cannot see the future.)

use iceoryx2::prelude::*;
use limber_interfaces::Interface;

use super::DeviceHost;

/// Whether process `pid` exists (0: not known, taken as existing).
fn process_exists(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return true;
    };
    if pid == 0 {
        return true;
    }
    // SAFETY: kill with signal 0 sends nothing; it only checks that the process exists
    // (EPERM: it exists, another user's).
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

impl<I: Interface> DeviceHost<I> {
    /// Before this host's ports connect to new peers: when the number of the state's
    /// subscribers changed (every client subscribes to it when it connects, before its other
    /// ports), removes the segments half made by a peer whose process is gone, on every
    /// service of the device (see the module's text). Counting reads each of the service's
    /// registry slots (some 40 ns for 66 slots): called before a state is sent, when the
    /// connections are updated and by `process`, not on every poll of a spinning loop (it
    /// updates its connections every [`super::SPIN_REQUEST_EVERY`] polls).
    pub(crate) fn guard_new_peers(&mut self) {
        let n = self.data_svc.dynamic_config().number_of_subscribers();
        if n == self.peers_seen {
            return;
        }
        self.peers_seen = n;
        let Ok(prefix) = self.domain.prefix() else {
            return;
        };
        let mut gone: Vec<u128> = Vec::new();
        self.for_each_peer_port(|port, node| {
            if !process_exists(super::senders::sender(node).pid) {
                gone.push(port);
            }
        });
        if gone.is_empty() {
            return;
        }
        let removed = crate::domain::cleanup::remove_half_made_of(prefix, |p| gone.contains(&p));
        if removed > 0 {
            tracing::warn!(device = %self.device, removed,
                "a client that is gone left segments half made: removed before connecting");
        }
    }

    /// Calls `f` with every port of the device's five services that a client owns (the
    /// state's subscribers, the publishers of commands, the clients of requests, leases
    /// and outcomes), and its node: from iceoryx2's registries in shared memory, no file
    /// read.
    fn for_each_peer_port(&self, mut f: impl FnMut(u128, &iceoryx2::identifiers::UniqueNodeId)) {
        self.data_svc.dynamic_config().list_subscribers(|d| {
            f(d.subscriber_id.value(), &d.node_id);
            CallbackProgression::Continue
        });
        self.cmd_svc.dynamic_config().list_publishers(|d| {
            f(d.publisher_id.value(), &d.node_id);
            CallbackProgression::Continue
        });
        self.req_svc.dynamic_config().list_clients(|d| {
            f(d.client_id.value(), &d.node_id);
            CallbackProgression::Continue
        });
        self.lease_svc.dynamic_config().list_clients(|d| {
            f(d.client_id.value(), &d.node_id);
            CallbackProgression::Continue
        });
        self.out.told_svc.dynamic_config().list_clients(|d| {
            f(d.client_id.value(), &d.node_id);
            CallbackProgression::Continue
        });
    }

    /// Whether a port of the device's services belongs to a process that is gone (a client
    /// that crashed or was killed, its ports left behind): iceoryx2 records each node's
    /// process id in its node id, so this is a look at the registries and one `kill(pid, 0)`
    /// per process, where iceoryx2's own look at a service's nodes reads every node's files
    /// (1 ms with 64 clients, up to 15 ms, measured on the project's 2-core VM). A process id
    /// iceoryx2 did not record is taken as alive.
    pub(crate) fn a_peer_is_gone(&self) -> bool {
        const SEEN: usize = 128;
        let own = std::process::id();
        // The processes seen alive in this look: each is asked once, not once per port.
        let mut alive = [0u32; SEEN];
        let mut n = 0;
        let mut gone = false;
        self.for_each_peer_port(|_, node| {
            let pid = super::senders::sender(node).pid;
            if gone || pid == own || alive[..n].contains(&pid) {
                return;
            }
            if process_exists(pid) {
                if n < SEEN {
                    alive[n] = pid;
                    n += 1;
                }
            } else {
                gone = true;
            }
        });
        gone
    }
}
