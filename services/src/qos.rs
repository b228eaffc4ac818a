//! The quality-of-service settings of every limber service, in one place.
//!
//! Drivers create the services with these values; clients open them with iceoryx2's
//! defaults, which are below them (iceoryx2 treats the opener's values as minimums).

/// Clients (processes) per device: subscribers of `data`, publishers of `cmd`, clients of
/// `req`, notifiers of `wake`, listeners of `notify`.
/// (Each subscriber slot costs every publish: 64 slots made a 1.3 kB publish 2.4x slower
/// than 1 slot, measured by `limber bench`.)
pub const MAX_CLIENTS: usize = 32;
/// Nodes (processes) that may open one service.
pub const MAX_NODES: usize = 80;
/// Publishers of `data`: the driver, plus one dead driver not yet cleaned up.
pub const DATA_PUBLISHERS: usize = 2;
/// Samples buffered per `data` subscriber (history 1; when full the oldest is replaced).
/// Deep enough that a client sees its own command's outcome even when a few other
/// commands were applied since.
pub const DATA_BUFFER: usize = 16;
/// Samples a `data` subscriber may hold at once (the client keeps the latest one).
pub const DATA_BORROWED: usize = 2;
/// Commands buffered per client for the driver: a burst this long is never lost.
pub const CMD_BUFFER: usize = 256;
/// Outcomes buffered per client (every client sees every outcome of the device and keeps
/// its own): this many commands of all clients may be decided between two looks of a
/// waiting client before its outcome is overwritten (safe overflow).
pub const OUTCOME_BUFFER: usize = 256;
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
pub const EVENT_COMMAND: usize = 1;
/// Event id on `wake`: a request was sent.
pub const EVENT_REQUEST: usize = 2;
/// Event id on `wake`: a client connected (the driver hands it the latest state).
pub const EVENT_HELLO: usize = 3;
/// Event id on `notify`: a state sample was published.
pub const EVENT_STATE: usize = 1;
/// Event id on `notify`: a reply was sent.
pub const EVENT_REPLY: usize = 2;
