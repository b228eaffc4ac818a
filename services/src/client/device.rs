//! Any device, whatever its interface: [`DeviceClient`] is the object-safe face of a
//! [`Client<I>`], and [`connect_device`] opens the device a name names. Every generic
//! consumer (the CLI's `echo` and monitor, discovery, the bridge, the C API and through it
//! C++ and Python) holds a `Box<dyn DeviceClient>` and needs no per-interface code for
//! what an interface does not change: states, waits, outcomes, leases, liveness. The typed
//! commands and requests of one interface are reached with `<dyn DeviceClient>::typed`.

use core::any::Any;
use core::time::Duration;

use limber_interfaces::prelude::*;
use limber_interfaces::{InterfaceVisitor, WireBytes};
use zerocopy::IntoBytes;

use super::{
    Client, ConnectError, Done, DoneError, DriverStatus, Freshness, LeaseError, LeaseHolder,
    Outcome, RequestError, Ticket, WaitError, WaitMode,
};
use crate::context::Context;
use crate::naming::DeviceName;

/// A connection to one device of any interface: what every interface shares.
///
/// Implemented by [`Client<I>`] for every interface; the methods mean what the
/// [`Client`] methods of the same names mean. States are given as the interface's wire
/// struct ([`DeviceClient::state_bytes`]: exactly its bytes, the layout of limber.h) and as
/// text and JSON ([`DeviceClient::describe`]).
pub trait DeviceClient {
    /// The device.
    fn device(&self) -> &DeviceName;
    /// Its interface.
    fn kind(&self) -> InterfaceKind;
    /// This client's id (carried in every command and request it sends).
    fn client_id(&self) -> u64;
    /// The size of the interface's state struct, in bytes.
    fn state_size(&self) -> usize;

    /// Takes every state and outcome that arrived; whether a new state came.
    fn refresh(&mut self) -> Result<bool, WaitError>;
    /// The header of the latest state taken.
    fn header(&self) -> Option<&StateHeader>;
    /// The latest state taken, as its wire bytes (read in place from shared memory).
    fn state_bytes(&self) -> Option<&[u8]>;
    /// The latest state taken, to print.
    fn describe(&self) -> Option<&dyn Describe>;
    /// The latest state's bytes, waiting up to `timeout` for a first one.
    fn current_bytes(&mut self, timeout: Duration) -> Result<&[u8], WaitError>;
    /// Waits up to `timeout` for a state newer than the latest taken; its bytes.
    fn wait_state_bytes(&mut self, timeout: Duration) -> Result<&[u8], WaitError>;
    /// Age of the latest state taken.
    fn state_age(&self) -> Option<Duration>;
    /// Fresh, stale, gone, or no data.
    fn freshness(&mut self, max_age: Duration) -> Freshness;
    /// Whether the driver's process lives.
    fn driver_status(&self) -> DriverStatus;

    /// Waits for the outcome of a command, with the other client involved.
    fn wait_outcome_detail(
        &mut self,
        ticket: Ticket,
        timeout: Duration,
    ) -> Result<Outcome, WaitError>;
    /// Whether another client's command cut short the motion of `ticket`'s command.
    fn preempted(&mut self, ticket: Ticket) -> Result<Option<Outcome>, WaitError>;
    /// Waits until the motion of `ticket`'s command has ended ([`Client::wait_done`]).
    fn wait_done(&mut self, ticket: Ticket, timeout: Duration) -> Result<Done, DoneError>;

    /// Takes the device's control lease ([`Client::acquire`]).
    fn acquire(&mut self, name: &str, heartbeat: Duration) -> Result<(), LeaseError>;
    /// The lease's heartbeat.
    fn renew(&mut self) -> Result<(), LeaseError>;
    /// Renews when a third of the heartbeat has passed; whether it did.
    fn keep_lease(&mut self) -> Result<bool, LeaseError>;
    /// Gives the lease back.
    fn release(&mut self) -> Result<(), LeaseError>;
    /// Whether this client holds the lease.
    fn holds_lease(&self) -> bool;
    /// Who holds the device.
    fn holder(&mut self) -> Result<Option<LeaseHolder>, LeaseError>;

    /// A file descriptor that becomes readable when the driver notifies this client (a new
    /// state, an outcome, a reply): for a program that waits on several devices, or on
    /// other things too, with `poll(2)`/`epoll(7)`. When it is readable, call
    /// [`DeviceClient::take_notifications`] and then read what arrived. The descriptor
    /// belongs to the client: valid while it lives, never to be closed by the caller.
    fn notification_fd(&mut self) -> Result<i32, WaitError>;
    /// Takes the pending notifications (the descriptor of
    /// [`DeviceClient::notification_fd`] is not readable afterwards until the next one);
    /// never waits.
    fn take_notifications(&mut self) -> Result<(), WaitError>;

    /// Asks for the device's geometry, waiting up to `timeout`.
    fn geometry_within(&mut self, timeout: Duration) -> Result<AnyGeom, RequestError>;

    /// How to wait for states and replies.
    fn set_wait_mode(&mut self, mode: WaitMode);
    /// The busy-poll window after a send, in [`WaitMode::Event`].
    fn set_spin_budget(&mut self, budget: Duration);
    /// The timeout of requests.
    fn set_request_timeout(&mut self, timeout: Duration);

    /// The typed client, to send this interface's commands and requests (downcast it with
    /// `<dyn DeviceClient>::typed`).
    fn as_any_mut(&mut self) -> &mut dyn Any;
    /// The typed client, read-only.
    fn as_any(&self) -> &dyn Any;
}

impl dyn DeviceClient {
    /// The typed client of interface `I`, or `None` when the device is of another one.
    pub fn typed<I: Interface>(&mut self) -> Option<&mut Client<I>> {
        self.as_any_mut().downcast_mut::<Client<I>>()
    }

    /// The typed client of interface `I`, read-only.
    pub fn typed_ref<I: Interface>(&self) -> Option<&Client<I>> {
        self.as_any().downcast_ref::<Client<I>>()
    }

    /// Waits for the outcome of a command.
    pub fn wait_outcome(&mut self, ticket: Ticket, timeout: Duration) -> Result<Status, WaitError> {
        self.wait_outcome_detail(ticket, timeout).map(|o| o.status)
    }
}

/// A device's geometry, of whatever interface ([`DeviceClient::geometry_within`]).
pub struct AnyGeom {
    value: Box<dyn Any>,
    bytes: Vec<u8>,
}

impl AnyGeom {
    /// The typed geometry (`ActArrayGeom`, `LimbGeom`, `GripperGeom`, ...), if it is a `G`.
    pub fn get<G: 'static>(&self) -> Option<&G> {
        self.value.downcast_ref()
    }
    /// Its wire bytes (the layout of limber.h).
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }
}

impl core::fmt::Debug for AnyGeom {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("AnyGeom")
            .field("bytes", &self.bytes.len())
            .finish()
    }
}

fn bytes<D: WireBytes>(d: &D) -> &[u8] {
    d.as_bytes()
}

impl<I: Interface> DeviceClient for Client<I> {
    fn device(&self) -> &DeviceName {
        Client::device(self)
    }
    fn kind(&self) -> InterfaceKind {
        I::KIND
    }
    fn client_id(&self) -> u64 {
        Client::client_id(self)
    }
    fn state_size(&self) -> usize {
        size_of::<I::Data>()
    }
    fn refresh(&mut self) -> Result<bool, WaitError> {
        Client::refresh(self)
    }
    fn header(&self) -> Option<&StateHeader> {
        self.last_state().map(HasHeader::header)
    }
    fn state_bytes(&self) -> Option<&[u8]> {
        self.last_state().map(bytes)
    }
    fn describe(&self) -> Option<&dyn Describe> {
        self.last_state().map(|d| d as &dyn Describe)
    }
    fn current_bytes(&mut self, timeout: Duration) -> Result<&[u8], WaitError> {
        self.current(timeout).map(bytes)
    }
    fn wait_state_bytes(&mut self, timeout: Duration) -> Result<&[u8], WaitError> {
        self.wait_state(timeout).map(bytes)
    }
    fn state_age(&self) -> Option<Duration> {
        Client::state_age(self)
    }
    fn freshness(&mut self, max_age: Duration) -> Freshness {
        Client::freshness(self, max_age)
    }
    fn driver_status(&self) -> DriverStatus {
        Client::driver_status(self)
    }
    fn wait_outcome_detail(
        &mut self,
        ticket: Ticket,
        timeout: Duration,
    ) -> Result<Outcome, WaitError> {
        Client::wait_outcome_detail(self, ticket, timeout)
    }
    fn preempted(&mut self, ticket: Ticket) -> Result<Option<Outcome>, WaitError> {
        Client::preempted(self, ticket)
    }
    fn wait_done(&mut self, ticket: Ticket, timeout: Duration) -> Result<Done, DoneError> {
        Client::wait_done(self, ticket, timeout)
    }
    fn acquire(&mut self, name: &str, heartbeat: Duration) -> Result<(), LeaseError> {
        Client::acquire(self, name, heartbeat)
    }
    fn renew(&mut self) -> Result<(), LeaseError> {
        Client::renew(self)
    }
    fn keep_lease(&mut self) -> Result<bool, LeaseError> {
        Client::keep_lease(self)
    }
    fn release(&mut self) -> Result<(), LeaseError> {
        Client::release(self)
    }
    fn holds_lease(&self) -> bool {
        Client::holds_lease(self)
    }
    fn holder(&mut self) -> Result<Option<LeaseHolder>, LeaseError> {
        Client::holder(self)
    }
    fn notification_fd(&mut self) -> Result<i32, WaitError> {
        use iceoryx2_bb_posix::file_descriptor::FileDescriptorBased;
        if self.notify.is_none() {
            let l = self
                .notify_svc
                .listener_builder()
                .create()
                .map_err(|e| WaitError::Transport(e.into()))?;
            self.notify = Some(l);
        }
        let l = self.notify.as_ref().ok_or(WaitError::DriverGone)?;
        // SAFETY: reading the descriptor's number; it stays owned by the listener, which
        // lives as long as this client (documented for the caller).
        Ok(unsafe { l.file_descriptor().native_handle() })
    }
    fn take_notifications(&mut self) -> Result<(), WaitError> {
        if let Some(l) = &self.notify {
            l.try_wait(|_| {})
                .map_err(|e| WaitError::Transport(e.into()))?;
        }
        Ok(())
    }
    fn geometry_within(&mut self, timeout: Duration) -> Result<AnyGeom, RequestError> {
        let reply = self.request_with_timeout(&I::GEOMETRY, timeout)?;
        let g = I::geometry_of(reply).ok_or(RequestError::Unexpected)?;
        Ok(AnyGeom {
            bytes: g.as_bytes().to_vec(),
            value: Box::new(g),
        })
    }
    fn set_wait_mode(&mut self, mode: WaitMode) {
        Client::set_wait_mode(self, mode)
    }
    fn set_spin_budget(&mut self, budget: Duration) {
        Client::set_spin_budget(self, budget)
    }
    fn set_request_timeout(&mut self, timeout: Duration) {
        Client::set_request_timeout(self, timeout)
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// Connects to `device` ("robot/interface/index"), whatever its interface, waiting up to
/// `timeout` for a driver to offer it (zero: fails at once with
/// [`ConnectError::NoDriver`] if none does). As [`Client::connect_timeout`].
pub fn connect_device(
    ctx: &Context,
    device: &str,
    timeout: Duration,
) -> Result<Box<dyn DeviceClient>, ConnectError> {
    struct Connect<'a> {
        ctx: &'a Context,
        device: &'a str,
        timeout: Duration,
    }
    impl InterfaceVisitor for Connect<'_> {
        type Output = Result<Box<dyn DeviceClient>, ConnectError>;
        fn visit<I: Interface>(self) -> Self::Output {
            let c = if self.timeout.is_zero() {
                Client::<I>::connect(self.ctx, self.device)?
            } else {
                Client::<I>::connect_timeout(self.ctx, self.device, self.timeout)?
            };
            Ok(Box::new(c))
        }
    }
    let name: DeviceName = device.parse()?;
    name.interface().visit(Connect {
        ctx,
        device,
        timeout,
    })
}
