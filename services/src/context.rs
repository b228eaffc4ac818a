//! A process's participation in a domain: one iceoryx2 node shared by every client and
//! driver host the process creates.

use std::rc::Rc;
use std::sync::atomic::{AtomicU32, Ordering};

use iceoryx2::node::NodeCreationFailure;
use iceoryx2::prelude::*;
use thiserror::Error;

use crate::domain::Domain;
use crate::naming::{CLIENT_NODE_PREFIX, DRIVER_NODE_PREFIX};

/// The monotonic clock in ns (`CLOCK_MONOTONIC`), the time base of every stamp.
pub fn monotonic_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
    t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64
}

/// What a process is in the domain.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// A driver: owns devices. Its node is named `limber-driver:<name>`.
    Driver,
    /// A client: uses devices. Its node is named `limber-client:<name>`.
    Client,
}

/// Creating the context failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ContextError {
    /// The process name is not a valid node name (at most 100 ASCII characters).
    #[error("invalid process name {0:?}")]
    Name(String),
    /// The domain's files could not be prepared, or belong to another user.
    #[error("cannot join domain {domain}: {source}")]
    Domain {
        /// The domain.
        domain: String,
        /// Why.
        #[source]
        source: Box<crate::domain::DomainError>,
    },
    /// iceoryx2 was refused access to the domain's files (iceoryx2's
    /// `NodeCreationFailure::InsufficientPermissions`): they belong to another user.
    #[error(
        "cannot join domain {domain}: its files under {root} or in /dev/shm belong to another user; a domain is its owner's alone (docs/guide/security.md): run as that user, or use a domain of your own (LIMBER_DOMAIN, LIMBER_RUNTIME_DIR)"
    )]
    Permission {
        /// The domain.
        domain: String,
        /// The iceoryx2 root path of the domain.
        root: String,
        /// iceoryx2's error.
        #[source]
        source: NodeCreationFailure,
    },
    /// iceoryx2 could not number the new node (`UnableToGenerateUniqueNodeId`): the
    /// domain's node counter in /dev/shm cannot be opened or was damaged.
    #[error(
        "cannot join domain {domain}: its node counter /dev/shm/{prefix}*.global_mgmt cannot be used (damaged, or made unreadable); stop the domain's processes and remove it"
    )]
    NodeCounter {
        /// The domain.
        domain: String,
        /// The iceoryx2 prefix of the domain's files.
        prefix: String,
        /// iceoryx2's error.
        #[source]
        source: NodeCreationFailure,
    },
    /// iceoryx2 could not create the node for another reason (a corrupted installation,
    /// files removed under a running domain).
    #[error("cannot join domain {domain}: {source}")]
    Node {
        /// The domain.
        domain: String,
        /// iceoryx2's error.
        #[source]
        source: NodeCreationFailure,
    },
    /// The signal handlers ([`crate::signals`]) could not be installed (driver contexts).
    #[error("cannot install the signal handlers: {0}")]
    Signals(#[source] rustix::io::Errno),
}

pub(crate) struct Inner {
    pub(crate) node: Node<ipc::Service>,
    /// After the node: dropped last, so a test's domain, whose files go when its last
    /// handle does ([`Domain::unique_for_test`]), finds this process's node gone.
    pub(crate) domain: Domain,
    pub(crate) role: Role,
    pub(crate) name: String,
    /// The capacity of the devices this process offers (drivers).
    pub(crate) capacity: core::cell::Cell<crate::qos::Capacity>,
    /// Whether this process's clients may take a device's reserved slots.
    pub(crate) priority: core::cell::Cell<bool>,
}

impl Drop for Inner {
    fn drop(&mut self) {
        // Group mode: the files this process's ports made since they were created (a
        // connection) are opened to the group before the process may end, so that the
        // members who still hold them never wait on them.
        self.domain.widen_now();
    }
}

/// A process's membership of a domain. Cheap to clone; not `Send` (iceoryx2 ports of
/// the `ipc` service are bound to their thread).
#[derive(Clone)]
pub struct Context {
    pub(crate) inner: Rc<Inner>,
}

impl core::fmt::Debug for Context {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Context")
            .field("domain", &self.inner.domain.name())
            .field("role", &self.inner.role)
            .field("name", &self.inner.name)
            .finish()
    }
}

static CLIENT_SEQ: AtomicU32 = AtomicU32::new(1);

/// The low 32 bits of the id of a process's outcome stream: it names no client but every
/// client of its process that has no stream of its own (the remote clients whose commands
/// a bridge relays). Never given to a client.
pub(crate) const EVERY_CLIENT_OF_PROCESS: u32 = u32::MAX;

/// The process a client id was made by: its high 32 bits ([`Context::new_client_id`]).
pub(crate) fn process_of(client_id: u64) -> u32 {
    (client_id >> 32) as u32
}

/// The id of the outcome stream that carries the outcomes of every client of `client_id`'s
/// process without a stream of its own (see `crate::host` `told.rs`).
pub(crate) fn process_stream_id(client_id: u64) -> u64 {
    client_id | u64::from(EVERY_CLIENT_OF_PROCESS)
}

impl Context {
    /// Joins `domain` as a driver or a client named `name` (shown by `limber list`).
    ///
    /// iceoryx2's own log output is limited to errors unless `IOX2_LOG_LEVEL` says
    /// otherwise. A client context leaves signals to the program; a driver context installs
    /// [`crate::signals`]: the termination signals (SIGINT, SIGTERM, SIGHUP, SIGQUIT,
    /// SIGXCPU, SIGPWR) let the driver loop stop its hardware and end cleanly (see
    /// [`Context::termination_requested`]); the other signals that would end a process are
    /// ignored.
    pub fn new(domain: &Domain, role: Role, name: &str) -> Result<Self, ContextError> {
        set_log_level_from_env_or(LogLevel::Error);
        let prefix = match role {
            Role::Driver => DRIVER_NODE_PREFIX,
            Role::Client => CLIENT_NODE_PREFIX,
        };
        let node_name: NodeName = format!("{prefix}{name}")
            .as_str()
            .try_into()
            .map_err(|_| ContextError::Name(name.to_string()))?;
        let mode = match role {
            Role::Driver => {
                crate::signals::install().map_err(ContextError::Signals)?;
                SignalHandlingMode::HandleTerminationRequests
            }
            Role::Client => SignalHandlingMode::Disabled,
        };
        let domain_err = |e| ContextError::Domain {
            domain: domain.name().to_string(),
            source: Box::new(e),
        };
        let config = domain.config().map_err(domain_err)?;
        domain
            .before_join(role == Role::Driver)
            .map_err(domain_err)?;
        let iox_prefix = domain.prefix().map_err(domain_err)?;
        let node = NodeBuilder::new()
            .name(&node_name)
            .config(config)
            .signal_handling_mode(mode)
            .create::<ipc::Service>()
            .map_err(|e: NodeCreationFailure| {
                let domain = domain.name().to_string();
                match e {
                    NodeCreationFailure::InsufficientPermissions => ContextError::Permission {
                        domain,
                        root: config.global.root_path().to_string(),
                        source: e,
                    },
                    NodeCreationFailure::UnableToGenerateUniqueNodeId => {
                        ContextError::NodeCounter {
                            domain,
                            prefix: iox_prefix.to_string(),
                            source: e,
                        }
                    }
                    _ => ContextError::Node { domain, source: e },
                }
            })?;
        // iceoryx2 makes the domain's node counter world-writable (0666).
        domain.after_join().map_err(domain_err)?;
        Ok(Context {
            inner: Rc::new(Inner {
                domain: domain.clone(),
                node,
                role,
                name: name.to_string(),
                capacity: core::cell::Cell::new(crate::qos::Capacity::default()),
                priority: core::cell::Cell::new(crate::qos::priority_from_env()),
            }),
        })
    }

    /// A client context in the domain of `LIMBER_DOMAIN` (default `limber`), named after
    /// the executable.
    pub fn client_from_env() -> Result<Self, crate::ConnectError> {
        let domain = Domain::from_env()?;
        let name = std::env::args()
            .next()
            .and_then(|a| {
                std::path::Path::new(&a)
                    .file_name()
                    .map(|s| s.to_string_lossy().to_string())
            })
            .unwrap_or_else(|| "client".to_string());
        Ok(Context::new(&domain, Role::Client, &name)?)
    }

    /// The domain.
    pub fn domain(&self) -> &Domain {
        &self.inner.domain
    }

    /// The role.
    pub fn role(&self) -> Role {
        self.inner.role
    }

    /// The iceoryx2 node (for advanced use: extra services, WaitSets).
    pub fn node(&self) -> &Node<ipc::Service> {
        &self.inner.node
    }

    /// True once a termination signal ([`crate::signals::TERMINATION_SIGNALS`]) arrived
    /// (driver contexts only; always false for clients, whose signals are the program's
    /// own). Other signals never make it true.
    pub fn termination_requested(&self) -> bool {
        self.inner.role == Role::Driver && crate::signals::termination_requested()
    }

    /// The capacity of the devices this process offers from now on (default
    /// [`crate::qos::DEFAULT_MAX_CLIENTS`] clients each): a driver sets it before it
    /// offers its devices. Published as the services' attributes, so that a client refused
    /// for a full device can say the limit.
    pub fn set_capacity(&self, capacity: crate::qos::Capacity) {
        self.inner.capacity.set(capacity);
    }

    /// The capacity of the devices this process offers.
    pub fn capacity(&self) -> crate::qos::Capacity {
        self.inner.capacity.get()
    }

    /// Makes this process's clients priority clients (or ordinary ones again): the owner's
    /// control program, which must get in even when a device is full of other clients.
    /// They may take the [`crate::qos::RESERVED_CLIENTS`] slots that ordinary clients leave
    /// free. Default: `LIMBER_PRIORITY=1` in the environment.
    ///
    /// This is cooperation among one user's processes, not protection: every process of the
    /// domain's owner (or group) can map the domain's memory anyway, and one that does not
    /// use limber's client can take any slot.
    pub fn set_priority(&self, priority: bool) {
        self.inner.priority.set(priority);
    }

    /// Whether this process's clients are priority clients ([`Context::set_priority`]).
    pub fn priority(&self) -> bool {
        self.inner.priority.get()
    }

    /// A new client id, unique in the domain while this process lives: the process id in
    /// the high 32 bits (as iceoryx2 records it in this process's node id, so that a driver
    /// can tell a client id of another process from the sender's own: see the host's
    /// `senders`), a per-process counter in the low 32 bits. Never 0, never a process's
    /// outcome stream id (the low 32 bits all ones).
    pub fn new_client_id(&self) -> u64 {
        let mut n = CLIENT_SEQ.fetch_add(1, Ordering::Relaxed);
        while n == EVERY_CLIENT_OF_PROCESS || n == 0 {
            n = CLIENT_SEQ.fetch_add(1, Ordering::Relaxed);
        }
        let pid = self
            .node()
            .id()
            .pid::<ipc::Service>()
            .ok()
            .and_then(|p| u32::try_from(p.value()).ok())
            .unwrap_or_else(std::process::id);
        (u64::from(pid) << 32) | u64::from(n)
    }
}
