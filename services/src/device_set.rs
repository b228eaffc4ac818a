//! [`DeviceSet`]: the devices one driver process offers, as one group. A driver says which
//! devices it serves (`actarray/0`, `limb/0`, `gripper/1`, ...), implements
//! [`DeviceSetHandler`] once for all of them, and its loop processes, publishes and waits
//! on the whole set.
//!
//! ## One lease per set of actuators
//!
//! Devices that move the same actuators (an arm's joints, its limb, its gripper) are one
//! thing to own: [`DeviceSet::share_lease`] makes them share one lease. Each host keeps its
//! arbiter (which does no I/O) and its copy of the lease; the set keeps the copies equal by
//! propagation: after each grouped host is processed, what its processing did to the
//! lease (acquired, renewed, released, ended by the deadman) is copied to the others of its
//! group before any of them is processed. The hosts are processed one after another on
//! the driver's one thread, so every host decides on the group's current lease, and the
//! copy is a few words (no allocation). A host whose holder changed publishes its state
//! at once (the `LEASED` flag follows); when the deadman ended the lease on one host (its
//! holder's process died or missed its heartbeat), the set stops the others too (each
//! handler's stop). Only the host that granted the lease looks up the holder's node (on
//! its own lease channel, where the holder's port is); every host sees a missed heartbeat.
//! On the devices of the group other than the one the lease was taken on, the holder is
//! its process (its node): a program that holds the arm's joints commands the limb and
//! the gripper through clients of their own. This was chosen over a lease slot that the
//! set owns and lends to each host: every reader of the lease (the host's own
//! [`DeviceHost::holder`], its publication, its deadman check) would have to be lent it
//! too, whereas a propagated copy is always there.
//!
//! The handler a driver implements, and each device as a [`DeviceHandler`] of its
//! interface, are in `device_set/handler.rs`.
//!
//! ```
//! use limber_services::prelude::*;
//! use limber_services::{DeviceSet, DeviceSetHandler};
//!
//! /// A driver with one gripper that opens and closes at once.
//! struct Hand;
//! impl DeviceSetHandler for Hand {
//!     fn gripper_command(&mut self, _: u16, cmd: &GripperCommand, _: &Origin, s: &mut GripperData) -> Status {
//!         match cmd {
//!             GripperCommand::Open => { s.state = GripperState::Open as u32; Status::Ok }
//!             GripperCommand::Close => { s.state = GripperState::Closed as u32; Status::Ok }
//!             _ => Status::Unsupported,
//!         }
//!     }
//! }
//!
//! # let domain = Domain::unique_for_test();
//! let ctx = Context::new(&domain, Role::Driver, "hand")?;
//! let mut set = DeviceSet::new(&ctx, "demo", "hand", &[(InterfaceKind::Gripper, 0)])?;
//! set.gripper_mut(0).unwrap().state_mut().state = GripperState::Open as u32;
//! set.publish_all(monotonic_ns())?;
//! let mut listeners = set.take_wake_listeners(); // for limber_services::event_loop::run
//! # assert_eq!(listeners.len(), 1);
//! // Hardware that answers later is offered while running; the loop takes its listener.
//! set.add(&ctx, "demo", "hand", &[(InterfaceKind::Gripper, 1)])?;
//! listeners.extend(set.take_wake_listeners());
//! # assert_eq!((listeners.len(), set.len()), (2, 2));
//! set.process(&mut Hand)?; // after each wake-up
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::ipc;
use limber_interfaces::prelude::*;
use thiserror::Error;

use crate::context::Context;
use crate::host::{
    Activity, DeviceHandler, DeviceHost, Holder, HostError, HostStats, ProcessError, PublishError,
};
use crate::naming::DeviceName;

mod handler;
mod motions;
use handler::At;
pub use handler::DeviceSetHandler;

/// An operation on one device of a [`DeviceSet`] failed: which device, and why.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{device}: {source}")]
pub struct DeviceError<E: std::error::Error + 'static> {
    /// The device.
    pub device: DeviceName,
    /// What failed.
    #[source]
    pub source: E,
}

/// The devices of one driver process: any number of actarray, limb, gripper and ranger hosts of
/// one robot, each optional (a driver serves what the robot has), keyed by interface and
/// index.
pub struct DeviceSet {
    actarrays: Vec<DeviceHost<ActArray>>,
    limbs: Vec<DeviceHost<Limb>>,
    grippers: Vec<DeviceHost<Gripper>>,
    rangers: Vec<DeviceHost<Ranger>>,
    /// The devices that move the same actuators, each group with one lease
    /// ([`DeviceSet::share_lease`]).
    groups: Vec<LeaseGroup>,
}

/// Devices that move the same actuators, and their one lease as last made known to all of
/// them.
#[derive(Debug)]
struct LeaseGroup {
    members: Vec<(InterfaceKind, u16)>,
    lease: Option<Holder>,
}

/// [`DeviceSet::share_lease`] failed.
#[derive(Debug, Error)]
pub enum ShareLeaseError {
    /// The device is not served by the set.
    #[error("{kind}/{index} is not served: it cannot share a lease")]
    NotServed {
        /// Its interface.
        kind: InterfaceKind,
        /// Its index.
        index: u16,
    },
    /// The device already shares a lease with other devices.
    #[error("{kind}/{index} already shares a lease with other devices")]
    AlreadyShared {
        /// Its interface.
        kind: InterfaceKind,
        /// Its index.
        index: u16,
    },
    /// The state of a device whose lease changed could not be published.
    #[error(transparent)]
    Publish(#[from] DeviceError<PublishError>),
}

/// What one device of a lease group does after another device of the group was processed.
#[derive(Debug, Clone, Copy)]
enum Follow {
    /// The deadman ended the group's lease (this holder's, for this reason): stop.
    Stop(Holder, &'static str),
    /// The group's lease is now this: take it.
    Lease(Option<Holder>),
}

/// `follow` on one host: see [`Follow`].
fn follow_one<I: Interface, D: DeviceHandler<I>>(
    host: &mut DeviceHost<I>,
    handler: &mut D,
    follow: Follow,
) -> Result<(), ProcessError> {
    match follow {
        Follow::Stop(ended, why) => host.stop_with_group(handler, &ended, why),
        Follow::Lease(lease) => Ok(host.follow_lease(lease)?),
    }
}

impl core::fmt::Debug for DeviceSet {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_list()
            .entries(self.devices().map(|d| d.to_string()))
            .finish()
    }
}

/// How [`DeviceSet::process_as`] polls each device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Drain {
    /// Everything pending ([`DeviceHost::process`]): after a wake-up.
    All,
    /// Commands on every call, each other look (requests, lease operations, new clients,
    /// the lease's check) on one call in 16, one look a call
    /// ([`DeviceHost::process_spin`]): a busy-polling loop, where commands are the hot path.
    Spin,
    /// Commands and requests on every call ([`DeviceHost::process_linger`]): the linger
    /// of an event-driven loop after activity, where a client's next request must not
    /// wait 16 polls.
    Linger,
}

impl DeviceSet {
    /// Offers the devices `serve` (interface and index each) of `robot` as driver
    /// `driver`, in that order. The states are all zero until set and published.
    pub fn new(
        ctx: &Context,
        robot: &str,
        driver: &str,
        serve: &[(InterfaceKind, u16)],
    ) -> Result<Self, HostError> {
        let mut set = DeviceSet {
            actarrays: Vec::new(),
            limbs: Vec::new(),
            grippers: Vec::new(),
            rangers: Vec::new(),
            groups: Vec::new(),
        };
        set.add(ctx, robot, driver, serve)?;
        Ok(set)
    }

    /// Offers more devices while running (hardware that answered late, such as an arm
    /// whose controller was slow to reply). Their wake listeners are not yet taken: hand
    /// them to the loop with [`DeviceSet::take_wake_listeners`]. On an error, the devices
    /// offered before the failing one stay offered.
    pub fn add(
        &mut self,
        ctx: &Context,
        robot: &str,
        driver: &str,
        serve: &[(InterfaceKind, u16)],
    ) -> Result<(), HostError> {
        for &(kind, index) in serve {
            let name = DeviceName::new(robot, kind, index)?;
            match kind {
                InterfaceKind::ActArray => {
                    self.actarrays.push(DeviceHost::new(ctx, &name, driver)?)
                }
                InterfaceKind::Limb => self.limbs.push(DeviceHost::new(ctx, &name, driver)?),
                InterfaceKind::Gripper => self.grippers.push(DeviceHost::new(ctx, &name, driver)?),
                InterfaceKind::Ranger => self.rangers.push(DeviceHost::new(ctx, &name, driver)?),
            }
        }
        Ok(())
    }

    /// The names of the devices served, actarrays first, then limbs, grippers, rangers.
    pub fn devices(&self) -> impl Iterator<Item = &DeviceName> {
        self.actarrays
            .iter()
            .map(|h| h.device())
            .chain(self.limbs.iter().map(|h| h.device()))
            .chain(self.grippers.iter().map(|h| h.device()))
            .chain(self.rangers.iter().map(|h| h.device()))
    }

    /// How many devices are served.
    pub fn len(&self) -> usize {
        self.actarrays.len() + self.limbs.len() + self.grippers.len() + self.rangers.len()
    }

    /// True when no device is served.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The host of `actarray/<index>`, if served.
    pub fn actarray(&self, index: u16) -> Option<&DeviceHost<ActArray>> {
        self.actarrays.iter().find(|h| h.device().index() == index)
    }

    /// The host of `actarray/<index>`, if served, to update its state.
    pub fn actarray_mut(&mut self, index: u16) -> Option<&mut DeviceHost<ActArray>> {
        self.actarrays
            .iter_mut()
            .find(|h| h.device().index() == index)
    }

    /// The host of `limb/<index>`, if served.
    pub fn limb(&self, index: u16) -> Option<&DeviceHost<Limb>> {
        self.limbs.iter().find(|h| h.device().index() == index)
    }

    /// The host of `limb/<index>`, if served, to update its state.
    pub fn limb_mut(&mut self, index: u16) -> Option<&mut DeviceHost<Limb>> {
        self.limbs.iter_mut().find(|h| h.device().index() == index)
    }

    /// The host of `gripper/<index>`, if served.
    pub fn gripper(&self, index: u16) -> Option<&DeviceHost<Gripper>> {
        self.grippers.iter().find(|h| h.device().index() == index)
    }

    /// The host of `gripper/<index>`, if served, to update its state.
    pub fn gripper_mut(&mut self, index: u16) -> Option<&mut DeviceHost<Gripper>> {
        self.grippers
            .iter_mut()
            .find(|h| h.device().index() == index)
    }

    /// The host of `ranger/<index>`, if served.
    pub fn ranger(&self, index: u16) -> Option<&DeviceHost<Ranger>> {
        self.rangers.iter().find(|h| h.device().index() == index)
    }

    /// The host of `ranger/<index>`, if served, to update its state (a new scan).
    pub fn ranger_mut(&mut self, index: u16) -> Option<&mut DeviceHost<Ranger>> {
        self.rangers
            .iter_mut()
            .find(|h| h.device().index() == index)
    }

    /// Sets the `DEVICE_FLAG` bits of every device (see [`DeviceHost::set_flags`]).
    pub fn set_flags(&mut self, flags: u32) {
        self.actarrays.iter_mut().for_each(|h| h.set_flags(flags));
        self.limbs.iter_mut().for_each(|h| h.set_flags(flags));
        self.grippers.iter_mut().for_each(|h| h.set_flags(flags));
        self.rangers.iter_mut().for_each(|h| h.set_flags(flags));
    }

    /// See [`DeviceHost::set_publish_each_outcome`]; for every device.
    pub fn set_publish_each_outcome(&mut self, on: bool) {
        self.actarrays
            .iter_mut()
            .for_each(|h| h.set_publish_each_outcome(on));
        self.limbs
            .iter_mut()
            .for_each(|h| h.set_publish_each_outcome(on));
        self.grippers
            .iter_mut()
            .for_each(|h| h.set_publish_each_outcome(on));
        self.rangers
            .iter_mut()
            .for_each(|h| h.set_publish_each_outcome(on));
    }

    /// Publishes the state of every device, acquired at `stamp_ns` (`CLOCK_MONOTONIC`).
    /// Every device is published even if one fails; the first failure is returned.
    pub fn publish_all(&mut self, stamp_ns: u64) -> Result<(), DeviceError<PublishError>> {
        let mut first = None;
        let mut note = |device: &DeviceName, r: Result<(), PublishError>| {
            if let Err(source) = r {
                tracing::warn!(device = %device, error = %source, "cannot publish the state");
                first.get_or_insert_with(|| DeviceError {
                    device: device.clone(),
                    source,
                });
            }
        };
        for h in &mut self.actarrays {
            let r = h.publish_acquired(stamp_ns);
            note(h.device(), r);
        }
        for h in &mut self.limbs {
            let r = h.publish_acquired(stamp_ns);
            note(h.device(), r);
        }
        for h in &mut self.grippers {
            let r = h.publish_acquired(stamp_ns);
            note(h.device(), r);
        }
        for h in &mut self.rangers {
            let r = h.publish_acquired(stamp_ns);
            note(h.device(), r);
        }
        first.map_or(Ok(()), Err)
    }

    /// Drains the commands and answers the requests of every device with `handler`
    /// ([`DeviceHost::process`]); never blocks. Every device is processed even if one
    /// fails; the first failure is returned.
    pub fn process<H: DeviceSetHandler + ?Sized>(
        &mut self,
        handler: &mut H,
    ) -> Result<Activity, DeviceError<ProcessError>> {
        self.process_as(handler, Drain::All)
    }

    /// For the linger of an event-driven loop after activity: [`DeviceHost::process_linger`]
    /// on every device (requests answered on every call).
    pub fn process_linger<H: DeviceSetHandler + ?Sized>(
        &mut self,
        handler: &mut H,
    ) -> Result<Activity, DeviceError<ProcessError>> {
        self.process_as(handler, Drain::Linger)
    }

    /// For a busy-polling loop: [`DeviceHost::process_spin`] on every device.
    pub fn process_spin<H: DeviceSetHandler + ?Sized>(
        &mut self,
        handler: &mut H,
    ) -> Result<Activity, DeviceError<ProcessError>> {
        self.process_as(handler, Drain::Spin)
    }

    /// Polls every device the way `drain` says; never blocks. Every device is processed
    /// even if one fails; the first failure is returned.
    pub fn process_as<H: DeviceSetHandler + ?Sized>(
        &mut self,
        handler: &mut H,
        drain: Drain,
    ) -> Result<Activity, DeviceError<ProcessError>> {
        fn one<I: Interface, D: DeviceHandler<I>>(
            host: &mut DeviceHost<I>,
            handler: &mut D,
            drain: Drain,
            total: &mut Activity,
            first: &mut Option<DeviceError<ProcessError>>,
        ) {
            let r = match drain {
                Drain::All => host.process(handler),
                Drain::Spin => host.process_spin(handler),
                Drain::Linger => host.process_linger(handler),
            };
            match r {
                Ok(a) => *total += a,
                Err(source) => {
                    tracing::warn!(device = %host.device(), error = %source, "cannot process clients");
                    first.get_or_insert_with(|| DeviceError {
                        device: host.device().clone(),
                        source,
                    });
                }
            }
        }
        let mut total = Activity::default();
        let mut first = None;
        for i in 0..self.actarrays.len() {
            let h = &mut self.actarrays[i];
            let index = h.device().index();
            let mut at = At {
                handler: &mut *handler,
                index,
            };
            one::<ActArray, _>(h, &mut at, drain, &mut total, &mut first);
            self.spread_lease(InterfaceKind::ActArray, index, handler, &mut first);
        }
        for i in 0..self.limbs.len() {
            let h = &mut self.limbs[i];
            let index = h.device().index();
            let mut at = At {
                handler: &mut *handler,
                index,
            };
            one::<Limb, _>(h, &mut at, drain, &mut total, &mut first);
            self.spread_lease(InterfaceKind::Limb, index, handler, &mut first);
        }
        for i in 0..self.grippers.len() {
            let h = &mut self.grippers[i];
            let index = h.device().index();
            let mut at = At {
                handler: &mut *handler,
                index,
            };
            one::<Gripper, _>(h, &mut at, drain, &mut total, &mut first);
            self.spread_lease(InterfaceKind::Gripper, index, handler, &mut first);
        }
        for i in 0..self.rangers.len() {
            let h = &mut self.rangers[i];
            let index = h.device().index();
            let mut at = At {
                handler: &mut *handler,
                index,
            };
            one::<Ranger, _>(h, &mut at, drain, &mut total, &mut first);
            self.spread_lease(InterfaceKind::Ranger, index, handler, &mut first);
        }
        first.map_or(Ok(total), Err)
    }

    /// Hands the wake listeners of every device (those not yet taken) to the driver's
    /// event loop ([`crate::event_loop::run`]); see [`DeviceHost::take_wake_listener`].
    pub fn take_wake_listeners(&mut self) -> Vec<Listener<ipc::Service>> {
        let mut out = Vec::with_capacity(self.len());
        out.extend(
            self.actarrays
                .iter_mut()
                .filter_map(|h| h.take_wake_listener()),
        );
        out.extend(self.limbs.iter_mut().filter_map(|h| h.take_wake_listener()));
        out.extend(
            self.grippers
                .iter_mut()
                .filter_map(|h| h.take_wake_listener()),
        );
        out.extend(
            self.rangers
                .iter_mut()
                .filter_map(|h| h.take_wake_listener()),
        );
        out
    }

    /// The counters of every device, added up.
    pub fn stats(&self) -> HostStats {
        let mut s = HostStats::default();
        self.actarrays.iter().for_each(|h| s += h.stats());
        self.limbs.iter().for_each(|h| s += h.stats());
        self.grippers.iter().for_each(|h| s += h.stats());
        self.rangers.iter().for_each(|h| s += h.stats());
        s
    }

    /// [`DeviceHost::check_lease`] on every device (the deadman), for a driver that
    /// processes its clients only when they wake it: call it on every tick. Every device is
    /// checked even if one fails; the first failure is returned.
    pub fn check_leases<H: DeviceSetHandler + ?Sized>(
        &mut self,
        handler: &mut H,
    ) -> Result<(), DeviceError<ProcessError>> {
        fn one<I: Interface, D: DeviceHandler<I>>(
            host: &mut DeviceHost<I>,
            handler: &mut D,
            first: &mut Option<DeviceError<ProcessError>>,
        ) {
            if let Err(source) = host.check_lease(handler) {
                tracing::warn!(device = %host.device(), error = %source, "deadman check failed");
                first.get_or_insert_with(|| DeviceError {
                    device: host.device().clone(),
                    source,
                });
            }
        }
        let mut first = None;
        for i in 0..self.actarrays.len() {
            let h = &mut self.actarrays[i];
            let index = h.device().index();
            one::<ActArray, _>(
                h,
                &mut At {
                    handler: &mut *handler,
                    index,
                },
                &mut first,
            );
            self.spread_lease(InterfaceKind::ActArray, index, handler, &mut first);
        }
        for i in 0..self.limbs.len() {
            let h = &mut self.limbs[i];
            let index = h.device().index();
            one::<Limb, _>(
                h,
                &mut At {
                    handler: &mut *handler,
                    index,
                },
                &mut first,
            );
            self.spread_lease(InterfaceKind::Limb, index, handler, &mut first);
        }
        for i in 0..self.grippers.len() {
            let h = &mut self.grippers[i];
            let index = h.device().index();
            one::<Gripper, _>(
                h,
                &mut At {
                    handler: &mut *handler,
                    index,
                },
                &mut first,
            );
            self.spread_lease(InterfaceKind::Gripper, index, handler, &mut first);
        }
        for i in 0..self.rangers.len() {
            let h = &mut self.rangers[i];
            let index = h.device().index();
            one::<Ranger, _>(
                h,
                &mut At {
                    handler: &mut *handler,
                    index,
                },
                &mut first,
            );
            self.spread_lease(InterfaceKind::Ranger, index, handler, &mut first);
        }
        first.map_or(Ok(()), Err)
    }

    /// Declares that `devices` (interface and index each, all served) move the same
    /// actuators (an arm's joints, its limb, its gripper): they share one lease. A lease
    /// acquired on any of them holds all of them: other clients' commands and requests that
    /// may change any of them are refused [`Status::Leased`] naming the holder, the
    /// holder's pass; a renewal, release or query on any of them acts on the one lease; the
    /// deadman (the holder's process dead or its heartbeat missed) stops every one of them;
    /// the `LEASED` flag of each one's state follows.
    ///
    /// When some of them are already held, the first one's lease (in the order given)
    /// becomes the group's; a different holder of another one loses its lease (logged).
    pub fn share_lease(&mut self, devices: &[(InterfaceKind, u16)]) -> Result<(), ShareLeaseError> {
        for (n, &(kind, index)) in devices.iter().enumerate() {
            if self.shared_lease_of(kind, index).is_none() {
                return Err(ShareLeaseError::NotServed { kind, index });
            }
            if self.group_of(kind, index).is_some() || devices[..n].contains(&(kind, index)) {
                return Err(ShareLeaseError::AlreadyShared { kind, index });
            }
        }
        let lease = devices
            .iter()
            .find_map(|&(kind, index)| self.shared_lease_of(kind, index).flatten());
        for &(kind, index) in devices {
            if let Some(other) = self.shared_lease_of(kind, index).flatten()
                && lease
                    .is_some_and(|l| (l.client_id, l.node_id) != (other.client_id, other.node_id))
            {
                tracing::warn!(device = %format_args!("{kind}/{index}"), holder = other.name(),
                    "lease ended: the device now shares the lease of the devices that move the same actuators");
            }
            let r = match kind {
                InterfaceKind::ActArray => self
                    .actarray_mut(index)
                    .map(|h| h.join_lease(lease).map_err(|e| (h.device().clone(), e))),
                InterfaceKind::Limb => self
                    .limb_mut(index)
                    .map(|h| h.join_lease(lease).map_err(|e| (h.device().clone(), e))),
                InterfaceKind::Gripper => self
                    .gripper_mut(index)
                    .map(|h| h.join_lease(lease).map_err(|e| (h.device().clone(), e))),
                InterfaceKind::Ranger => self
                    .ranger_mut(index)
                    .map(|h| h.join_lease(lease).map_err(|e| (h.device().clone(), e))),
            };
            if let Some(Err((device, source))) = r {
                return Err(DeviceError { device, source }.into());
            }
        }
        self.groups.push(LeaseGroup {
            members: devices.to_vec(),
            lease,
        });
        Ok(())
    }

    /// The group of devices that share a lease with `kind`/`index`, if any.
    fn group_of(&self, kind: InterfaceKind, index: u16) -> Option<usize> {
        self.groups
            .iter()
            .position(|g| g.members.contains(&(kind, index)))
    }

    /// The lease of `kind`/`index` as its host holds it (`None`: not served).
    fn shared_lease_of(&self, kind: InterfaceKind, index: u16) -> Option<Option<Holder>> {
        match kind {
            InterfaceKind::ActArray => self.actarray(index).map(|h| h.shared_lease()),
            InterfaceKind::Limb => self.limb(index).map(|h| h.shared_lease()),
            InterfaceKind::Gripper => self.gripper(index).map(|h| h.shared_lease()),
            InterfaceKind::Ranger => self.ranger(index).map(|h| h.shared_lease()),
        }
    }

    /// After `kind`/`index` was processed: when it shares a lease, what its processing did
    /// to the lease reaches the other devices of its group (a deadman's end stops them, a
    /// new holder, renewal or release is taken by them). No allocation.
    fn spread_lease<H: DeviceSetHandler + ?Sized>(
        &mut self,
        kind: InterfaceKind,
        index: u16,
        handler: &mut H,
        first: &mut Option<DeviceError<ProcessError>>,
    ) {
        let Some(g) = self.group_of(kind, index) else {
            return;
        };
        let (lease, ended) = match kind {
            InterfaceKind::ActArray => self
                .actarray_mut(index)
                .map(|h| (h.shared_lease(), h.take_lease_ended())),
            InterfaceKind::Limb => self
                .limb_mut(index)
                .map(|h| (h.shared_lease(), h.take_lease_ended())),
            InterfaceKind::Gripper => self
                .gripper_mut(index)
                .map(|h| (h.shared_lease(), h.take_lease_ended())),
            InterfaceKind::Ranger => self
                .ranger_mut(index)
                .map(|h| (h.shared_lease(), h.take_lease_ended())),
        }
        .unwrap_or((None, None));
        if ended.is_none() && lease == self.groups[g].lease {
            return;
        }
        self.groups[g].lease = lease;
        for m in 0..self.groups[g].members.len() {
            let (k, i) = self.groups[g].members[m];
            if (k, i) == (kind, index) {
                continue;
            }
            if let Some((holder, why)) = ended {
                self.follow(k, i, handler, Follow::Stop(holder, why), first);
            }
            self.follow(k, i, handler, Follow::Lease(lease), first);
        }
    }

    /// [`Follow`] on `kind`/`index`; a failure is logged and the first one kept.
    fn follow<H: DeviceSetHandler + ?Sized>(
        &mut self,
        kind: InterfaceKind,
        index: u16,
        handler: &mut H,
        follow: Follow,
        first: &mut Option<DeviceError<ProcessError>>,
    ) {
        let at = &mut At { handler, index };
        let r = match kind {
            InterfaceKind::ActArray => self
                .actarray_mut(index)
                .map(|h| (follow_one::<ActArray, _>(h, at, follow), h.device())),
            InterfaceKind::Limb => self
                .limb_mut(index)
                .map(|h| (follow_one::<Limb, _>(h, at, follow), h.device())),
            InterfaceKind::Gripper => self
                .gripper_mut(index)
                .map(|h| (follow_one::<Gripper, _>(h, at, follow), h.device())),
            InterfaceKind::Ranger => self
                .ranger_mut(index)
                .map(|h| (follow_one::<Ranger, _>(h, at, follow), h.device())),
        };
        if let Some((Err(source), device)) = r {
            tracing::warn!(device = %device, error = %source, "cannot follow the shared lease");
            first.get_or_insert_with(|| DeviceError {
                device: device.clone(),
                source,
            });
        }
    }

    /// [`DeviceHost::cleanup_dead`] on every device (a 1 Hz housekeeping tick).
    pub fn cleanup_dead(&self) {
        self.actarrays.iter().for_each(|h| h.cleanup_dead());
        self.limbs.iter().for_each(|h| h.cleanup_dead());
        self.grippers.iter().for_each(|h| h.cleanup_dead());
        self.rangers.iter().for_each(|h| h.cleanup_dead());
    }
}
