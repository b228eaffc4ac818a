//! The `driver` channel: a driver's loop, link and robot facts ([`DriverStats`]), published
//! on `limber/<robot>/driver/0/data` (history 1) and read by `limber echo <robot>/driver`.
//!
//! Every driver (the Pioneer driver, simarm) publishes the same way: a [`StatsPublisher`]
//! made at start, a first publication then (a reader finds it at once, from the history)
//! and one every [`PUBLISH_PERIOD`] while it runs ([`StatsPublisher::due`]), the fields
//! they share filled by [`put_loop`] and [`put_clients`].

use core::time::Duration;
use std::time::Instant;

use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::{ReceiveError, SendError};
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;
use limber_interfaces::diagnostics::DriverStats;
use thiserror::Error;

use crate::context::{Context, monotonic_ns};
use crate::error::Iox2Error;
use crate::host::HostStats;
use crate::loop_stats::TickStats;
use crate::qos;

/// How often a running driver publishes its statistics: about once a second.
pub const PUBLISH_PERIOD: Duration = Duration::from_secs(1);

/// Fills the loop's fields of `stats`: `loop_mode` (a
/// [`loop_mode`](limber_interfaces::diagnostics::loop_mode) value) and, from the loop's
/// timer cycles `ticks`, the cycles, the overruns, the period's p50, p99 and maximum and
/// the jitter's p99 (the latest [`RING`](crate::loop_stats::RING) periods; zeros before
/// the second tick).
pub fn put_loop(stats: &mut DriverStats, mode: u32, ticks: &TickStats) {
    stats.loop_mode = mode;
    stats.cycles = ticks.cycles;
    stats.overruns = ticks.overruns;
    (
        stats.period_p50_ns,
        stats.period_p99_ns,
        stats.period_max_ns,
    ) = ticks.period.summary();
    stats.jitter_p99_ns = ticks.jitter.summary().1;
}

/// Fills the client counters of `stats` (commands, refused, requests, overflows) from the
/// counters of the driver's devices added up ([`DeviceSet::stats`](crate::DeviceSet::stats)).
pub fn put_clients(stats: &mut DriverStats, hosts: &HostStats) {
    stats.commands = hosts.commands;
    stats.refused = hosts.refused;
    stats.requests = hosts.requests;
    stats.cmd_overflows = hosts.overflows;
}

/// The service name of a robot's driver statistics.
pub fn service_name(robot: &str) -> Result<ServiceName, DiagnosticsError> {
    if !robot
        .bytes()
        .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
        || robot.is_empty()
        || robot.len() > crate::naming::MAX_ROBOT_LEN
    {
        return Err(DiagnosticsError::Name(robot.to_string()));
    }
    ServiceName::new(&format!("limber/{robot}/driver/0/data"))
        .map_err(|_| DiagnosticsError::Name(robot.to_string()))
}

/// The robots of `domain` whose driver publishes statistics (a `driver` channel), sorted.
/// A driver that died is listed until its services are cleaned up.
pub fn list_drivers(domain: &crate::Domain) -> Result<Vec<String>, crate::ListError> {
    let mut out = Vec::new();
    let config = domain.config().map_err(|e| crate::ListError::Domain {
        domain: domain.name().to_string(),
        source: Box::new(e),
    })?;
    ipc::Service::list(config, |details| {
        let name = details.static_details.name().as_str();
        if let Some(robot) = name
            .strip_prefix("limber/")
            .and_then(|r| r.strip_suffix("/driver/0/data"))
            && service_name(robot).is_ok()
        {
            out.push(robot.to_string());
        }
        CallbackProgression::Continue
    })
    .map_err(|e| crate::ListError::Transport {
        domain: domain.name().to_string(),
        source: e,
    })?;
    out.sort();
    out.dedup();
    Ok(out)
}

/// Opening or using the driver channel failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DiagnosticsError {
    /// The robot name is invalid.
    #[error("invalid robot name {0:?}")]
    Name(String),
    /// No driver publishes statistics for this robot.
    #[error("no driver statistics for robot {0} (is its driver running?)")]
    NoDriver(String),
    /// The statistics channel could not be offered (creating its service or publisher).
    #[error("cannot offer the driver statistics of robot {robot}: {source}")]
    Offer {
        /// The robot.
        robot: String,
        /// iceoryx2's error.
        #[source]
        source: Iox2Error,
    },
    /// The statistics channel exists but could not be opened (or subscribed to).
    #[error("cannot open the driver statistics of robot {robot}: {source}")]
    Open {
        /// The robot.
        robot: String,
        /// iceoryx2's error.
        #[source]
        source: Iox2Error,
    },
    /// A statistics sample could not be published.
    #[error("cannot publish driver statistics: {0}")]
    Publish(#[source] SendError),
    /// Statistics could not be received.
    #[error("cannot receive driver statistics: {0}")]
    Receive(#[source] ReceiveError),
    /// Nothing new within the timeout.
    #[error("no new driver statistics within {0:?}")]
    Timeout(Duration),
}

/// Publishes a driver's statistics.
pub struct StatsPublisher {
    publisher: Publisher<ipc::Service, DriverStats, ()>,
    seq: u64,
    /// When the last sample was published (`None` before the first).
    last: Option<Instant>,
}

impl core::fmt::Debug for StatsPublisher {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("StatsPublisher")
            .field("seq", &self.seq)
            .finish()
    }
}

impl StatsPublisher {
    /// Offers the statistics of `robot`'s driver.
    pub fn new(ctx: &Context, robot: &str) -> Result<Self, DiagnosticsError> {
        let offer = |source: Iox2Error| DiagnosticsError::Offer {
            robot: robot.to_string(),
            source,
        };
        let svc = ctx
            .node()
            .service_builder(&service_name(robot)?)
            .publish_subscribe::<DriverStats>()
            .history_size(1)
            .subscriber_max_buffer_size(qos::DATA_BUFFER)
            .max_publishers(qos::DATA_PUBLISHERS)
            .max_subscribers(ctx.capacity().ports())
            .max_nodes(ctx.capacity().nodes())
            .open_or_create()
            .map_err(|e| offer(e.into()))?;
        let publisher = svc
            .publisher_builder()
            .create()
            .map_err(|e| offer(e.into()))?;
        Ok(StatsPublisher {
            publisher,
            seq: 0,
            last: None,
        })
    }

    /// True when statistics are due at `now`: none was published yet, or the last
    /// publication is [`PUBLISH_PERIOD`] old or more (a failed publication counts: it is
    /// retried a period later, not at every cycle).
    pub fn due(&self, now: Instant) -> bool {
        self.last
            .is_none_or(|last| now.saturating_duration_since(last) >= PUBLISH_PERIOD)
    }

    /// Publishes `stats` (stamping its header's sequence number and time) and notes the
    /// time for [`due`](Self::due).
    pub fn publish(&mut self, stats: &mut DriverStats) -> Result<(), DiagnosticsError> {
        self.last = Some(Instant::now());
        self.seq += 1;
        stats.header.seq = self.seq;
        stats.header.stamp_ns = monotonic_ns();
        self.publisher
            .send_copy(*stats)
            .map(|_| ())
            .map_err(DiagnosticsError::Publish)
    }
}

/// Reads a driver's statistics.
pub struct StatsReader {
    subscriber: Subscriber<ipc::Service, DriverStats, ()>,
    latest: Option<Sample<ipc::Service, DriverStats, ()>>,
}

impl core::fmt::Debug for StatsReader {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("StatsReader").finish()
    }
}

impl StatsReader {
    /// Opens the statistics of `robot`'s driver.
    pub fn open(ctx: &Context, robot: &str) -> Result<Self, DiagnosticsError> {
        let svc = ctx
            .node()
            .service_builder(&service_name(robot)?)
            .publish_subscribe::<DriverStats>()
            .open()
            .map_err(|e| match e {
                PublishSubscribeOpenError::DoesNotExist => {
                    DiagnosticsError::NoDriver(robot.to_string())
                }
                e => DiagnosticsError::Open {
                    robot: robot.to_string(),
                    source: e.into(),
                },
            })?;
        let subscriber = svc
            .subscriber_builder()
            .create()
            .map_err(|e| DiagnosticsError::Open {
                robot: robot.to_string(),
                source: e.into(),
            })?;
        Ok(StatsReader {
            subscriber,
            latest: None,
        })
    }

    /// Takes what arrived; true if there was something new.
    pub fn refresh(&mut self) -> Result<bool, DiagnosticsError> {
        let mut got = false;
        while let Some(s) = self
            .subscriber
            .receive()
            .map_err(DiagnosticsError::Receive)?
        {
            self.latest = Some(s);
            got = true;
        }
        Ok(got)
    }

    /// The latest statistics.
    pub fn latest(&self) -> Option<&DriverStats> {
        self.latest.as_deref()
    }

    /// Waits (polling every 5 ms) for new statistics.
    pub fn wait(&mut self, timeout: Duration) -> Result<&DriverStats, DiagnosticsError> {
        let deadline = Instant::now() + timeout;
        loop {
            if self.refresh()? {
                return Ok(self.latest.as_deref().expect("just received"));
            }
            if Instant::now() >= deadline {
                return Err(DiagnosticsError::Timeout(timeout));
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}
