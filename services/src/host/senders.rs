//! Who sent a message, as the transport knows it: the node (process) that owns the port it
//! came from, from iceoryx2's registry of the service's ports (the publishers of `cmd`, the
//! clients of `req` and `lease`), never from the bytes a client writes into the message.
//! The arbiter binds a lease to that node, so a client that writes the holder's client id
//! into its commands from another process is not the holder.
//!
//! A fixed table per channel, no allocation: a port seen before is found in it; a new one
//! refills the table from the registry (once per new port).
//!
//! The table also keeps the process id of each node (iceoryx2 records it in the node id):
//! a client id carries the id of the process that made it ([`crate::Context::new_client_id`]),
//! so a command whose client id names another process than its sender's is a forgery
//! ([`client_of_process`]).

use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::{publish_subscribe, request_response};

/// Who sent a message: its node, and that node's process id (0: not known).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Sender {
    /// The iceoryx2 node id (0: the registry does not know the port).
    pub(crate) node: u128,
    /// The process id iceoryx2 recorded for the node (0: not known).
    pub(crate) pid: u32,
}

/// Whether `client_id` can be a client id of process `pid`: its high 32 bits are the
/// process id of the process that made it ([`crate::Context::new_client_id`]). An unknown
/// process (0) is given the benefit of the doubt.
pub(crate) fn client_of_process(client_id: u64, pid: u32) -> bool {
    pid == 0 || crate::context::process_of(client_id) == pid
}

/// Port id → sender of one channel.
#[derive(Debug, Clone)]
pub(crate) struct PortNodes {
    /// Allocated once, when the device is offered.
    entries: Box<[(u128, Sender)]>,
    len: usize,
}

impl PortNodes {
    /// A table for a channel of `ports` client slots ([`crate::qos::Capacity::ports`]),
    /// with room for as many dead ports not yet cleaned up.
    pub(crate) fn new(ports: usize) -> Self {
        PortNodes {
            entries: vec![(0, Sender { node: 0, pid: 0 }); 2 * ports].into_boxed_slice(),
            len: 0,
        }
    }

    fn find(&self, port: u128) -> Option<Sender> {
        self.entries[..self.len]
            .iter()
            .find(|(p, _)| *p == port)
            .map(|(_, n)| *n)
    }

    /// The sender of `port`; on a miss, `fill` lists the registry's (port, sender) pairs
    /// again. Node 0 when the registry does not know the port (it left meanwhile).
    fn node_of(&mut self, port: u128, fill: impl FnOnce(&mut dyn FnMut(u128, Sender))) -> Sender {
        if let Some(n) = self.find(port) {
            return n;
        }
        self.len = 0;
        let (entries, len) = (&mut self.entries, &mut self.len);
        fill(&mut |p, n| {
            if let Some(e) = entries.get_mut(*len) {
                *e = (p, n);
                *len += 1;
            }
        });
        self.find(port).unwrap_or(Sender { node: 0, pid: 0 })
    }

    /// The sender of the publisher `port` of the pub/sub service `svc`.
    pub(crate) fn publisher<P: core::fmt::Debug + ZeroCopySend>(
        &mut self,
        port: u128,
        svc: &publish_subscribe::PortFactory<ipc::Service, P, ()>,
    ) -> Sender {
        self.node_of(port, |add| {
            svc.dynamic_config().list_publishers(|d| {
                add(d.publisher_id.value(), sender(&d.node_id));
                CallbackProgression::Continue
            });
        })
    }

    /// The node of the client `port` of the request-response service `svc`.
    pub(crate) fn client<Req, Res>(
        &mut self,
        port: u128,
        svc: &request_response::PortFactory<ipc::Service, Req, (), Res, ()>,
    ) -> u128
    where
        Req: core::fmt::Debug + ZeroCopySend,
        Res: core::fmt::Debug + ZeroCopySend,
    {
        self.client_sender(port, svc).node
    }

    /// The sender of the client `port` of the request-response service `svc`.
    pub(crate) fn client_sender<Req, Res>(
        &mut self,
        port: u128,
        svc: &request_response::PortFactory<ipc::Service, Req, (), Res, ()>,
    ) -> Sender
    where
        Req: core::fmt::Debug + ZeroCopySend,
        Res: core::fmt::Debug + ZeroCopySend,
    {
        self.node_of(port, |add| {
            svc.dynamic_config().list_clients(|d| {
                add(d.client_id.value(), sender(&d.node_id));
                CallbackProgression::Continue
            });
        })
    }
}

/// The sender of a node of the registry.
pub(crate) fn sender(node: &iceoryx2::identifiers::UniqueNodeId) -> Sender {
    Sender {
        node: node.value(),
        pid: node
            .pid::<ipc::Service>()
            .map_or(0, |p| u32::try_from(p.value()).unwrap_or(0)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_known_port_is_found_and_a_new_one_refills_the_table() {
        let mut t = PortNodes::new(4);
        let mut fills = 0;
        let mut registry = vec![(1u128, 10u128), (2, 20)];
        let look = |t: &mut PortNodes, port: u128, registry: &[(u128, u128)], fills: &mut u32| {
            t.node_of(port, |add| {
                *fills += 1;
                for (p, n) in registry {
                    add(*p, Sender { node: *n, pid: 7 });
                }
            })
            .node
        };
        assert_eq!(look(&mut t, 2, &registry, &mut fills), 20);
        assert_eq!(look(&mut t, 1, &registry, &mut fills), 10);
        assert_eq!(fills, 1, "the second port was in the first fill");
        registry.push((3, 30));
        assert_eq!(look(&mut t, 3, &registry, &mut fills), 30);
        assert_eq!(look(&mut t, 9, &registry, &mut fills), 0, "unknown port");
        assert_eq!(fills, 3);
    }

    #[test]
    fn a_client_id_belongs_to_the_process_that_made_it() {
        assert!(client_of_process(42 << 32 | 7, 42));
        assert!(!client_of_process(43 << 32 | 7, 42));
        assert!(
            client_of_process(43 << 32 | 7, 0),
            "an unknown process is not judged"
        );
    }
}
