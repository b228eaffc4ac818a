//! Where outcomes go: each to the client it names, on that client's own stream of the `told`
//! channel, and every one on the `outcome` channel for those who watch them all (a bridge,
//! `limber record`).
//!
//! Why a stream per client: on one channel that every client reads, a client's buffer
//! holds the outcomes of everybody's commands, and a client descheduled while others flood
//! the device found its own overwritten by theirs (safe overflow) and waited out its
//! timeout. A client opens its stream at connect with one request on `told` (request-
//! response: iceoryx2 routes each response to the client that asked, into a buffer of its
//! own); the driver keeps the request and sends every outcome of that client as a response
//! to it. Only the client's own commands can fill its buffer.
//!
//! Who a stream is for comes from the transport: the request names a client id, and the
//! process that sent it (iceoryx2's registry of the service's clients) must be the one the
//! id belongs to (`senders::client_of_process`), so no process takes or displaces another
//! process's stream.
//!
//! A process may also ask for its *process stream* (`context::process_stream_id`): the
//! outcomes of every client id of that process that has no stream of its own. A bridge
//! relays its remote clients' commands under client ids of its own process
//! (`Client::relay_send`) and reads their outcomes there (`Client::relay_own_outcomes`):
//! only the commands it relayed fill it, so a local client flooding the device cannot push
//! a remote client's outcome out, as it could on the shared `outcome` channel.

use core::mem::MaybeUninit;

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::server::Server;
use iceoryx2::port::update_connections::{ConnectionFailure, UpdateConnections};
use iceoryx2::prelude::*;
use iceoryx2::sample_mut_uninit::SampleMutUninit;
use limber_interfaces::prelude::*;

use super::senders::{PortNodes, client_of_process};
use super::{HostStats, PublishError};
use crate::context::{monotonic_ns, process_stream_id};
use crate::error::Iox2Error;
use crate::naming::DeviceName;

/// The `told` service: a client id asks, outcomes answer.
pub(crate) type ToldSvc = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    u64,
    (),
    OutcomeMsg,
    (),
>;

/// The `outcome` service.
pub(crate) type OutcomeSvc =
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, OutcomeMsg, ()>;

type Stream = ActiveRequest<ipc::Service, u64, (), OutcomeMsg, ()>;

/// The outcome ports of a device: the `outcome` publisher and the `told` streams.
pub(crate) struct Outcomes {
    all_svc: OutcomeSvc,
    /// Every outcome, for whoever watches them all.
    pub(super) all: Publisher<ipc::Service, OutcomeMsg, ()>,
    /// A sample of `all` loaned ahead, for the next outcome.
    pub(super) loan: Option<SampleMutUninit<ipc::Service, MaybeUninit<OutcomeMsg>, ()>>,
    /// Whether anybody watches `all`, as looked at when its connections were
    /// ([`Outcomes::update_connections`]), with each state the driver publishes
    /// ([`DeviceHost::publish`](super::DeviceHost::publish)) and after each send, not before
    /// every outcome: iceoryx2 counts a service's subscribers by reading every slot of its
    /// registry and writing the registry's generation counter, a cache line that every
    /// process of the service shares. A watcher that subscribes gets the outcomes from the
    /// driver's next look (each `process`, every few polls when it spins, each tick's state).
    watched: bool,
    pub(super) told_svc: ToldSvc,
    told: Server<ipc::Service, u64, (), OutcomeMsg, ()>,
    senders: PortNodes,
    /// (client id, its stream); room for every stream the service admits, allocated once.
    streams: Vec<(u64, Stream)>,
    /// Stream requests refused: a client id of another process than the sender's.
    forged: u64,
    /// The latest outcomes of clients without a stream (yet), oldest first from `untold_at`:
    /// sent on a client's stream when it opens (a client that met a restarted driver asks
    /// for its stream again after its command went out). Allocated once.
    untold: Box<[OutcomeMsg]>,
    untold_at: usize,
}

/// Outcomes kept for clients whose stream is not open yet ([`Outcomes::accept`]).
const UNTOLD: usize = 64;

impl Outcomes {
    /// The outcome ports of a device whose clients have `ports` slots.
    pub(super) fn new(
        all_svc: OutcomeSvc,
        all: Publisher<ipc::Service, OutcomeMsg, ()>,
        told_svc: ToldSvc,
        told: Server<ipc::Service, u64, (), OutcomeMsg, ()>,
        ports: usize,
    ) -> Self {
        let mut out = Outcomes {
            all_svc,
            all,
            loan: None,
            watched: false,
            told_svc,
            told,
            senders: PortNodes::new(ports),
            // Room for every request the service admits: a process cannot crowd out
            // another's stream by opening more.
            streams: Vec::with_capacity(ports * crate::qos::TOLD_STREAMS),
            forged: 0,
            untold: vec![OutcomeMsg::default(); UNTOLD].into_boxed_slice(),
            untold_at: 0,
        };
        out.look_for_watchers();
        out
    }

    /// Sends `msg`, stamped now, to the client it names and to every watcher
    /// ([`Outcomes::send`]); a failure is counted and logged, never fatal to the loop.
    pub(super) fn publish(
        &mut self,
        stats: &mut HostStats,
        device: &DeviceName,
        mut msg: OutcomeMsg,
    ) {
        msg.stamp_ns = monotonic_ns();
        if let Err(e) = self.send(stats, device, &msg) {
            stats.failed_outcomes += 1;
            tracing::warn!(device = %device, client = msg.client_id, seq = msg.cmd_seq,
                result = msg.result, error = %e, "cannot publish an outcome");
        }
    }

    /// Sends `msg` as given on the stream of the client it names (if that client opened
    /// one: see [`Outcomes::tell`]) and on the `outcome` channel if anybody watches it;
    /// fails if the latter fails. Counts it in `stats` when sent.
    pub(crate) fn send(
        &mut self,
        stats: &mut HostStats,
        device: &DeviceName,
        msg: &OutcomeMsg,
    ) -> Result<(), PublishError> {
        let told = self.tell(device, msg);
        // A sample only for watchers (usually nobody).
        if self.watched {
            let loan = match self.loan.take() {
                Some(l) => l,
                None => self.all.loan_uninit().map_err(PublishError::Loan)?,
            };
            let reached = loan
                .write_payload(*msg)
                .send()
                .map_err(PublishError::Send)?;
            // The last watcher left: none is looked for until the next look.
            self.watched = reached != 0;
        }
        stats.outcomes += 1;
        stats.told += u64::from(told);
        Ok(())
    }

    /// Loans the next outcome's sample, off the clients' path.
    pub(super) fn loan_ahead(&mut self, device: &DeviceName) {
        if self.loan.is_none() {
            self.loan = super::loan_ahead(&self.all, device, "outcome");
        }
    }

    /// Connects the `outcome` publisher to watchers that came since the last call, and
    /// looks whether anybody watches.
    pub(crate) fn update_connections(&mut self) -> Result<(), ConnectionFailure> {
        self.look_for_watchers();
        self.all.update_connections()
    }

    /// Looks whether anybody watches the `outcome` channel.
    pub(super) fn look_for_watchers(&mut self) {
        self.watched = self.all_svc.dynamic_config().number_of_subscribers() != 0;
    }

    /// Sends `msg` on the stream of the client it names. A client whose stream is not
    /// known yet may have asked since the last look: the requests are taken first (a
    /// client asks before it sends its first command, so the request of a client whose
    /// command was taken is there).
    fn tell(&mut self, device: &DeviceName, msg: &OutcomeMsg) -> bool {
        let i = match self.stream_for(msg.client_id) {
            Some(i) => i,
            None => {
                self.accept(device);
                match self.stream_for(msg.client_id) {
                    Some(i) => i,
                    // Kept for the client's stream to come (a client that met a restarted
                    // driver), or for nobody (a bridge relaying the commands of remote
                    // clients reads the `outcome` channel): overwritten in time.
                    None => {
                        self.untold[self.untold_at] = *msg;
                        self.untold_at = (self.untold_at + 1) % UNTOLD;
                        return false;
                    }
                }
            }
        };
        if let Err(e) = send_on(&self.streams[i].1, msg) {
            // The client closed its stream or died: forgotten (a client that is alive
            // asks again).
            tracing::debug!(device = %device, client = msg.client_id, error = %e,
                "cannot send an outcome on the client's stream: stream closed");
            self.streams.swap_remove(i);
            return false;
        }
        true
    }

    fn find(&self, client_id: u64) -> Option<usize> {
        self.streams.iter().position(|(c, _)| *c == client_id)
    }

    /// The stream of `client_id`: its own, else its process's.
    fn stream_for(&self, client_id: u64) -> Option<usize> {
        self.find(client_id)
            .or_else(|| self.find(process_stream_id(client_id)))
    }

    /// Takes the stream requests that arrived: each replaces that client's earlier stream
    /// and is sent the client's outcomes kept since it had none; a request whose client id
    /// is another process's is refused (dropped, which closes it). The host looks on each
    /// `process` call (a waiting client asks again when it finds its stream closed), and
    /// when it meets a client without a stream.
    pub(super) fn accept(&mut self, device: &DeviceName) {
        loop {
            let active = match self.told.receive() {
                Ok(Some(a)) => a,
                Ok(None) => return,
                Err(e) => {
                    tracing::warn!(device = %device, error = %e, "cannot take the clients' outcome streams");
                    return;
                }
            };
            let client_id = *active.payload();
            let sender = self
                .senders
                .client_sender(active.origin().value(), &self.told_svc);
            if !client_of_process(client_id, sender.pid) {
                self.forged += 1;
                if self.forged % 1000 == 1 {
                    tracing::warn!(device = %device, client_id, sender_pid = sender.pid,
                        forged = self.forged,
                        "an outcome stream asked for another process's client id: refused");
                }
                continue;
            }
            self.send_untold(device, client_id, &active);
            if let Some(i) = self.find(client_id) {
                self.streams[i].1 = active;
                continue;
            }
            if self.streams.len() == self.streams.capacity() {
                self.streams.retain(|(_, s)| s.is_connected());
            }
            if self.streams.len() < self.streams.capacity() {
                self.streams.push((client_id, active));
            } else {
                tracing::warn!(device = %device, client_id,
                    "every outcome stream is taken: this client's outcomes go to the `outcome` channel only");
            }
        }
    }

    /// Sends the kept outcomes of `client_id` (of a process stream: of every client id of
    /// its process) on its new stream, oldest first, and forgets them.
    fn send_untold(&mut self, device: &DeviceName, client_id: u64, stream: &Stream) {
        for k in 0..UNTOLD {
            let m = &mut self.untold[(self.untold_at + k) % UNTOLD];
            let for_it = m.client_id == client_id || process_stream_id(m.client_id) == client_id;
            if !for_it || m.cmd_seq == 0 {
                continue;
            }
            if let Err(e) = send_on(stream, m) {
                tracing::debug!(device = %device, client = client_id, error = %e,
                    "cannot send a kept outcome on the client's new stream");
            }
            *m = OutcomeMsg::default();
        }
    }
}

/// Sends `msg` on one client's stream.
fn send_on(stream: &Stream, msg: &OutcomeMsg) -> Result<(), Iox2Error> {
    stream.loan_uninit()?.write_payload(*msg).send()?;
    Ok(())
}
