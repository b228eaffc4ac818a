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
        let mut note = |port: u128, node: &iceoryx2::identifiers::UniqueNodeId| {
            if !process_exists(super::senders::sender(node).pid) {
                gone.push(port);
            }
            CallbackProgression::Continue
        };
        self.data_svc
            .dynamic_config()
            .list_subscribers(|d| note(d.subscriber_id.value(), &d.node_id));
        self.cmd_svc
            .dynamic_config()
            .list_publishers(|d| note(d.publisher_id.value(), &d.node_id));
        self.req_svc
            .dynamic_config()
            .list_clients(|d| note(d.client_id.value(), &d.node_id));
        self.lease_svc
            .dynamic_config()
            .list_clients(|d| note(d.client_id.value(), &d.node_id));
        self.out
            .told_svc
            .dynamic_config()
            .list_clients(|d| note(d.client_id.value(), &d.node_id));
        if gone.is_empty() {
            return;
        }
        let removed = crate::domain::cleanup::remove_half_made_of(prefix, |p| gone.contains(&p));
        if removed > 0 {
            tracing::warn!(device = %self.device, removed,
                "a client that is gone left segments half made: removed before connecting");
        }
    }
}
