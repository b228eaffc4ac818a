//! Opening the Zenoh session: peer mode on the given endpoints, multicast scouting off and
//! gossip's autoconnect empty (a bridge talks to the endpoints it is given, and to nobody
//! they tell it of).

use thiserror::Error;

use crate::access::AccessError;
use std::collections::HashMap;

use zenoh::pubsub::Publisher;
use zenoh::qos::{CongestionControl, Priority};
use zenoh::{Config, Session, Wait};

/// Where a bridge listens and what it connects to (Zenoh endpoints, e.g.
/// `tcp/127.0.0.1:7447`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct NetConfig {
    /// Endpoints to listen on. For `expose`, none means the domain's private Unix socket
    /// ([`crate::access::private_socket`]); a mirror listens on none (it only connects).
    pub listen: Vec<String>,
    /// Endpoints to connect to.
    pub connect: Vec<String>,
    /// A Zenoh configuration file (JSON5) to start from (TLS, user/password, ...); the
    /// endpoints above and the scouting setting are applied on top of it.
    pub config_file: Option<std::path::PathBuf>,
}

/// The Zenoh session could not be opened.
#[derive(Debug, Error)]
pub enum SessionError {
    /// The configuration file could not be read or is invalid.
    #[error("cannot load the Zenoh configuration {path}: {source}")]
    ConfigFile {
        /// The file.
        path: String,
        /// Zenoh's error.
        #[source]
        source: zenoh::Error,
    },
    /// An endpoint or setting was refused.
    #[error("invalid Zenoh setting {key} = {value}: {source}")]
    Setting {
        /// The setting.
        key: &'static str,
        /// Its value.
        value: String,
        /// Zenoh's error.
        #[source]
        source: zenoh::Error,
    },
    /// The session could not be opened (an endpoint to listen on is taken, ...).
    #[error("cannot open the Zenoh session: {0}")]
    Open(#[source] zenoh::Error),
    /// A listener or principal was refused (who may reach the bridge).
    #[error(transparent)]
    Access(#[from] AccessError),
}

fn json_list(items: &[String]) -> String {
    let quoted: Vec<String> = items
        .iter()
        .map(|s| format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\"")))
        .collect();
    format!("[{}]", quoted.join(","))
}

/// The Zenoh configuration of `net`: its file, or Zenoh's defaults.
pub(crate) fn base_config(net: &NetConfig) -> Result<Config, SessionError> {
    match &net.config_file {
        Some(p) => Config::from_file(p).map_err(|source| SessionError::ConfigFile {
            path: p.display().to_string(),
            source,
        }),
        None => Ok(Config::default()),
    }
}

/// Sets `key` to `value` (JSON5) in `config`.
pub(crate) fn set(
    config: &mut Config,
    key: &'static str,
    value: String,
) -> Result<(), SessionError> {
    config
        .insert_json5(key, &value)
        .map_err(|source| SessionError::Setting { key, value, source })
}

/// Opens a peer session with `config` (from [`base_config`], with what the caller added),
/// listening on `listen` and connecting to `net`'s endpoints.
pub(crate) fn open(
    net: &NetConfig,
    mut config: Config,
    listen: &[String],
) -> Result<Session, SessionError> {
    let settings: [(&'static str, String); 7] = [
        ("mode", "\"peer\"".into()),
        ("listen/endpoints", json_list(listen)),
        ("connect/endpoints", json_list(&net.connect)),
        ("scouting/multicast/enabled", "false".into()),
        // Gossip stays on (Zenoh's routing among peers needs it) but connects to nobody it
        // hears of: a peer's gossip must not make a bridge connect elsewhere.
        ("scouting/gossip/autoconnect", "[]".into()),
        // A peer that vanishes without closing its connection is declared gone after
        // this long (its liveliness tokens with it).
        ("transport/link/tx/lease", "3000".into()),
        // Do not wait for the connect endpoints at start: retry them in the background.
        ("connect/exit_on_failure", "false".into()),
    ];
    for (key, value) in settings {
        set(&mut config, key, value)?;
    }
    zenoh::open(config).wait().map_err(SessionError::Open)
}

/// Closes `session`; a failure is logged (the bridge is ending anyway).
pub(crate) fn close(session: &Session) {
    if let Err(e) = session.close().wait() {
        tracing::warn!(error = %e, "cannot close the Zenoh session");
    }
}

/// The priority of commands and outcomes on Zenoh: a queue of their own, ahead of the
/// states (`Data`, Zenoh's default), so a burst of states never holds one back or takes the
/// room it needs.
pub(crate) const CONTROL_PRIORITY: Priority = Priority::InteractiveHigh;

/// The most keys a [`ControlPublishers`] keeps a publisher for; past it they are declared
/// anew as they are used.
const MAX_CONTROL_KEYS: usize = 256;

/// Puts commands or outcomes of one type, each key's through a publisher declared at its
/// first put and kept: `express` (not batched, handed to Zenoh's TX task at once) at
/// [`CONTROL_PRIORITY`]. Without `express`, a put that found the previous one (a state)
/// still in the batch being filled waited for the TX task's backoff, a Tokio timer of 1 ms
/// resolution: a command through the bridge pair took 1.3 ms in 1 of 50 round trips
/// (`limber bench --only bridge`). A declared publisher keeps its key and routes, where a
/// `Session::put` checks the key and finds the routes on every put (a command's round trip
/// through the pair, p50, 143-146 µs against 148-155 µs in alternating runs of `limber
/// bench --only bridge` on the project's 2-core VM). Congestion control stays Zenoh's default, `Drop` after 1 ms without room: a peer
/// that does not read cannot stall the loop that puts.
pub(crate) struct ControlPublishers {
    type_name: &'static str,
    publishers: HashMap<String, Publisher<'static>>,
}

impl ControlPublishers {
    /// Publishers of payloads whose encoding's schema is `type_name`.
    pub(crate) fn new(type_name: &'static str) -> Self {
        ControlPublishers {
            type_name,
            publishers: HashMap::new(),
        }
    }

    /// Puts `payload` on `key`.
    pub(crate) fn put(
        &mut self,
        session: &Session,
        key: &str,
        payload: Vec<u8>,
    ) -> zenoh::Result<()> {
        if let Some(p) = self.publishers.get(key) {
            return p.put(payload).wait();
        }
        if self.publishers.len() >= MAX_CONTROL_KEYS {
            self.publishers.clear();
        }
        let publisher = session
            .declare_publisher(key.to_string())
            .encoding(crate::keys::encoding(self.type_name))
            .express(true)
            .priority(CONTROL_PRIORITY)
            .congestion_control(CongestionControl::Drop)
            .wait()?;
        let put = publisher.put(payload).wait();
        self.publishers.insert(key.to_string(), publisher);
        put
    }
}
