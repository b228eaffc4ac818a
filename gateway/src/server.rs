//! The listener: accepts Player clients and serves each in a session thread of its own.

use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

use limber_services::Domain;
use thiserror::Error;

use crate::map::MapEntry;
use crate::session::{Session, SessionEnd};
use crate::translate::Conventions;

/// Player's default port.
pub const DEFAULT_PORT: u16 = 6665;
/// The most sessions served at once; a client beyond is closed at once.
pub const MAX_SESSIONS: usize = 64;

/// How the gateway serves.
#[derive(Debug, Clone)]
pub struct GatewayConfig {
    /// Where to listen (loopback by default).
    pub listen: SocketAddr,
    /// Refuse every command and every request that changes a device (and leases).
    pub read_only: bool,
    /// Fixed Player addresses, before the default mapping.
    pub map: Vec<MapEntry>,
    /// Units and conventions.
    pub conventions: Conventions,
    /// The heartbeat of a lease taken through the gateway (renewed by the session while
    /// it lives).
    pub lease_heartbeat: Duration,
    /// How long a write to a client may block before its session is closed.
    pub write_timeout: Duration,
}

impl Default for GatewayConfig {
    fn default() -> Self {
        GatewayConfig {
            listen: SocketAddr::from(([127, 0, 0, 1], DEFAULT_PORT)),
            read_only: false,
            map: Vec::new(),
            conventions: Conventions::default(),
            lease_heartbeat: Duration::from_secs(1),
            write_timeout: Duration::from_secs(5),
        }
    }
}

/// What the gateway reports as it runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum GatewayEvent {
    /// Listening (the actual address, when port 0 was asked for).
    Listening(SocketAddr),
    /// Session `id` opened for a client.
    Opened {
        /// The session.
        id: u64,
        /// The client.
        peer: SocketAddr,
    },
    /// Session `id` ended; everything it held is released.
    Ended {
        /// The session.
        id: u64,
    },
    /// A client was refused: too many sessions.
    Refused(SocketAddr),
}

/// The gateway could not run.
#[derive(Debug, Error)]
pub enum GatewayError {
    /// The address could not be listened on.
    #[error("cannot listen on {addr}: {source}")]
    Listen {
        /// The address.
        addr: SocketAddr,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Accepting a client failed.
    #[error("cannot accept a client: {0}")]
    Accept(#[source] std::io::Error),
}

/// What every session reads.
pub(crate) struct Shared {
    pub(crate) domain: Domain,
    pub(crate) config: GatewayConfig,
    pub(crate) port: u16,
    stop: AtomicBool,
}

impl Shared {
    pub(crate) fn stopping(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }
}

/// Runs the gateway for `domain` until `stop()` says so; then ends every session (their
/// leases released) and returns.
pub fn run(
    domain: &Domain,
    config: &GatewayConfig,
    stop: &dyn Fn() -> bool,
    on_event: &mut dyn FnMut(GatewayEvent),
) -> Result<(), GatewayError> {
    let listen = |source| GatewayError::Listen {
        addr: config.listen,
        source,
    };
    let listener = TcpListener::bind(config.listen).map_err(listen)?;
    let local = listener.local_addr().map_err(listen)?;
    let shared = Arc::new(Shared {
        domain: domain.clone(),
        config: config.clone(),
        port: local.port(),
        stop: AtomicBool::new(false),
    });
    on_event(GatewayEvent::Listening(local));
    let (ended_tx, ended_rx) = std::sync::mpsc::channel::<u64>();
    let mut sessions: Vec<(u64, JoinHandle<()>)> = Vec::new();
    let mut next_id = 1u64;
    let result = loop {
        if stop() {
            break Ok(());
        }
        while let Ok(id) = ended_rx.try_recv() {
            if let Some(i) = sessions.iter().position(|(s, _)| *s == id) {
                let (_, h) = sessions.swap_remove(i);
                if h.join().is_err() {
                    tracing::error!(session = id, "the session's thread panicked");
                }
            }
            on_event(GatewayEvent::Ended { id });
        }
        if !acceptable(&listener, Duration::from_millis(50)) {
            continue;
        }
        let (stream, peer) = match listener.accept() {
            Ok(c) => c,
            Err(e) if transient(&e) => {
                tracing::debug!(error = %e, "accept");
                continue;
            }
            Err(e) => break Err(GatewayError::Accept(e)),
        };
        if sessions.len() >= MAX_SESSIONS {
            tracing::warn!(%peer, "too many sessions: client refused");
            on_event(GatewayEvent::Refused(peer));
            continue;
        }
        let id = next_id;
        next_id += 1;
        on_event(GatewayEvent::Opened { id, peer });
        let shared = Arc::clone(&shared);
        let tx = ended_tx.clone();
        let spawned = std::thread::Builder::new()
            .name(format!("player-session-{id}"))
            .spawn(move || {
                serve(&shared, stream, id, peer);
                if tx.send(id).is_err() {
                    tracing::debug!(session = id, "the gateway ended first");
                }
            });
        match spawned {
            Ok(h) => sessions.push((id, h)),
            Err(e) => {
                tracing::error!(session = id, error = %e, "cannot start a session thread");
                on_event(GatewayEvent::Ended { id });
            }
        }
    };
    shared.stop.store(true, Ordering::Relaxed);
    for (id, h) in sessions {
        if h.join().is_err() {
            tracing::error!(session = id, "the session's thread panicked");
        }
        on_event(GatewayEvent::Ended { id });
    }
    result
}

fn serve(shared: &Shared, stream: TcpStream, id: u64, peer: SocketAddr) {
    let outcome = Session::new(shared, stream, id).and_then(Session::run);
    match outcome {
        Ok(SessionEnd::Closed) => tracing::info!(session = id, %peer, "the client left"),
        Ok(SessionEnd::Stopped) => tracing::info!(session = id, %peer, "stopped"),
        Err(e) => tracing::warn!(session = id, %peer, error = %e, "session closed"),
    }
}

/// Errors of `accept` that concern one client only.
fn transient(e: &std::io::Error) -> bool {
    use std::io::ErrorKind::*;
    matches!(
        e.kind(),
        ConnectionAborted | ConnectionReset | Interrupted | WouldBlock
    )
}

/// Whether a client waits to be accepted, within `timeout`.
fn acceptable(listener: &TcpListener, timeout: Duration) -> bool {
    use rustix::event::{PollFd, PollFlags, Timespec, poll};
    let mut fds = [PollFd::new(listener, PollFlags::IN)];
    let t = Timespec {
        tv_sec: timeout.as_secs() as i64,
        tv_nsec: i64::from(timeout.subsec_nanos()),
    };
    match poll(&mut fds, Some(&t)) {
        Ok(n) => n > 0,
        Err(e) => {
            tracing::debug!(error = %e, "poll");
            false
        }
    }
}
