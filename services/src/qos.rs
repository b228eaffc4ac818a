//! The quality-of-service settings of every limber service, in one place.
//!
//! Drivers create the services with these values; clients open them with iceoryx2's
//! defaults, which are below them (iceoryx2 treats the opener's values as minimums).

/// Clients per device that a driver admits unless configured otherwise (the Pioneer
/// driver's `max_clients`, `limber pioneer --max-clients N`, `limber simarm --max-clients
/// N`): subscribers of `data` and `outcome`, publishers of `cmd`, clients of `req` and
/// `lease`, notifiers of `wake`, listeners of `notify`. Enough for a robot PC's control
/// program, monitors, loggers, bridges and a few shell commands at once.
/// (Each subscriber slot costs every publish: 64 slots made a 1.3 kB publish 2.4x slower
/// than 1 slot, measured by `limber bench`. A driver that needs the fastest publish and
/// few clients says so with a smaller `max_clients`.)
pub const DEFAULT_MAX_CLIENTS: usize = 64;
/// The largest `max_clients` a driver accepts.
pub const MAX_CLIENTS_LIMIT: usize = 1024;
/// Slots of every device kept beyond `max_clients` for priority clients (the owner's
/// control program: [`PRIORITY_ENV`], [`crate::Context::set_priority`]): an ordinary
/// client refuses to take them, so a device full of ordinary clients still admits them.
pub const RESERVED_CLIENTS: usize = 2;
/// Nodes (processes) that may open one service beyond its client slots: the driver, a dead
/// driver not yet cleaned up, observers.
pub const EXTRA_NODES: usize = 16;
/// The environment variable that makes a process's clients priority clients (`1`): they
/// may take the [`RESERVED_CLIENTS`] slots of a device full of ordinary clients.
pub const PRIORITY_ENV: &str = "LIMBER_PRIORITY";

/// How many clients a driver's devices admit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capacity {
    max_clients: usize,
}

impl Default for Capacity {
    fn default() -> Self {
        Capacity {
            max_clients: DEFAULT_MAX_CLIENTS,
        }
    }
}

/// A capacity out of range.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("max_clients must be between 1 and {MAX_CLIENTS_LIMIT}, not {0}")]
pub struct CapacityError(pub usize);

impl Capacity {
    /// `max_clients` ordinary clients per device (1 to [`MAX_CLIENTS_LIMIT`]), plus the
    /// [`RESERVED_CLIENTS`] slots of priority clients.
    pub fn new(max_clients: usize) -> Result<Self, CapacityError> {
        if (1..=MAX_CLIENTS_LIMIT).contains(&max_clients) {
            Ok(Capacity { max_clients })
        } else {
            Err(CapacityError(max_clients))
        }
    }

    /// Ordinary clients per device.
    pub fn max_clients(&self) -> usize {
        self.max_clients
    }

    /// Every client slot of a device's services: ordinary and reserved.
    pub fn ports(&self) -> usize {
        self.max_clients + RESERVED_CLIENTS
    }

    /// Nodes (processes) that may open one of a device's services.
    pub fn nodes(&self) -> usize {
        self.ports() + EXTRA_NODES
    }
}

/// Whether `LIMBER_PRIORITY` asks for priority clients (`1`, `true`, `yes`).
pub fn priority_from_env() -> bool {
    std::env::var(PRIORITY_ENV)
        .map(|v| matches!(v.trim(), "1" | "true" | "yes"))
        .unwrap_or(false)
}
/// Publishers of `data`: the driver, plus one dead driver not yet cleaned up.
pub const DATA_PUBLISHERS: usize = 2;
/// Samples buffered per `data` subscriber (history 1; when full the oldest is replaced).
/// Deep enough that a client sees its own command's outcome even when a few other
/// commands were applied since.
pub const DATA_BUFFER: usize = 16;
/// Samples a `data` subscriber may hold at once (the client keeps the latest one).
pub const DATA_BORROWED: usize = 2;
/// Commands buffered per client for the driver: a burst this long is never lost. Also
/// the most commands the driver takes in one call before it answers requests and ticks.
pub const CMD_BUFFER: usize = 256;
/// Commands of one client the driver holds at once: the most it takes of one client in
/// one round of its fair draining (`DeviceHost::process_commands`).
pub const CMD_BORROWED: usize = 2;
/// Outcomes buffered per watcher of the `outcome` channel (a bridge, a recorder: every
/// outcome of the device); when full the oldest is replaced (safe overflow).
pub const OUTCOME_BUFFER: usize = limber_interfaces::protocol::OUTCOME_BUFFER;
/// Outcomes buffered per client on its own stream (`told`): only its own commands' outcomes
/// and results, so this many of its own may be decided between two looks before the
/// oldest is replaced (safe overflow); nobody else's traffic takes its room.
pub const TOLD_BUFFER: usize = limber_interfaces::protocol::TOLD_BUFFER;
/// Streams a client may have open on `told` at once: its stream, and the one that replaces
/// it when a restarted driver is met (the old one closes).
pub const TOLD_STREAMS: usize = 2;
/// Subscribers of `cmd`: the driver, a dead driver not yet cleaned up, and observers.
pub const CMD_SUBSCRIBERS: usize = 4;
/// Servers of `req`: the driver plus one dead driver not yet cleaned up.
pub const REQ_SERVERS: usize = 2;
/// Requests one client may have in flight per device.
pub const MAX_ACTIVE_REQUESTS: usize = 4;
/// Listeners of `wake`: the driver plus one dead driver not yet cleaned up.
pub const WAKE_LISTENERS: usize = 4;
/// Notifiers of `notify`: the driver plus one dead driver not yet cleaned up.
pub const NOTIFY_NOTIFIERS: usize = 4;

/// Event id on `wake`: a command was sent.
pub const EVENT_COMMAND: usize = limber_interfaces::protocol::WAKE_COMMAND;
/// Event id on `wake`: a request was sent.
pub const EVENT_REQUEST: usize = limber_interfaces::protocol::WAKE_REQUEST;
/// Event id on `wake`: a client connected (the driver hands it the latest state).
pub const EVENT_HELLO: usize = limber_interfaces::protocol::WAKE_HELLO;
/// Event id on `notify`: a state sample was published.
pub const EVENT_STATE: usize = limber_interfaces::protocol::NOTIFY_STATE;
/// Event id on `notify`: a reply was sent.
pub const EVENT_REPLY: usize = limber_interfaces::protocol::NOTIFY_REPLY;

/// The spin budget of a client in event mode when nothing else is configured, on a machine
/// with at least two cores (see [`default_spin_budget`]). Chosen by measurement
/// (`limber bench --only command`): long enough to cover a driver that is awake answering
/// (a few µs), short enough to cost little CPU when it is not.
pub const SPIN_BUDGET: core::time::Duration = core::time::Duration::from_micros(30);

/// The environment variable that sets the clients' spin budget in µs (`0`: block at once).
pub const SPIN_BUDGET_ENV: &str = "LIMBER_SPIN_US";

/// The default spin budget of a client in event mode: `LIMBER_SPIN_US` if set (µs), else
/// [`SPIN_BUDGET`] on a machine with two or more cores and zero on one core (where a
/// spinning client would only delay the driver it waits for).
pub fn default_spin_budget() -> core::time::Duration {
    static BUDGET: std::sync::OnceLock<core::time::Duration> = std::sync::OnceLock::new();
    *BUDGET.get_or_init(|| {
        if let Some(d) = micros_from_env(SPIN_BUDGET_ENV) {
            return d;
        }
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        if cores >= 2 {
            SPIN_BUDGET
        } else {
            core::time::Duration::ZERO
        }
    })
}

/// A time in µs from the environment variable `var` (at most 1 s): `None` when it is not
/// set, or not a number (said in a warning: the caller's default applies). The rule of
/// every µs knob (`LIMBER_SPIN_US`, the bridge's `LIMBER_BRIDGE_LINGER_US`).
pub fn micros_from_env(var: &str) -> Option<core::time::Duration> {
    let v = std::env::var_os(var)?;
    match v.to_str().and_then(|s| s.trim().parse::<u64>().ok()) {
        Some(us) => Some(core::time::Duration::from_micros(us.min(1_000_000))),
        None => {
            tracing::warn!("{var}={v:?} is not a number of microseconds: using the default");
            None
        }
    }
}

/// How long a driver in event mode keeps polling its clients after activity before it goes
/// back to sleep (see [`crate::event_loop::linger`]), so that a client's next command in a
/// tight loop needs no wake-up. Chosen by measurement (`limber bench --only command`).
pub const DRIVER_LINGER: core::time::Duration = core::time::Duration::from_micros(50);
