//! [`WorldDriver`]: the world on the services layer. It serves the laser as
//! `<robot>/ranger/0` (a new scan at the laser's frequency) and watches the robot's limb
//! and gripper, as any client does, so that the blocks move with the gripper.

use core::ops::ControlFlow;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use limber_interfaces::common::device_flag;
use limber_services::event_loop::{self, LoopError, LoopExit, Wake};
use limber_services::prelude::*;
use limber_services::{DeviceError, HostError, ProcessError, PublishError};

use crate::{Carrier, Laser, LaserConfig, LaserConfigError, World};

/// Name under which the world's devices are offered (shown by `limber list`).
pub const DRIVER_NAME: &str = "world";

/// What the world is given.
#[derive(Debug, Clone)]
pub struct WorldOptions {
    /// The robot whose laser this is (`<robot>/ranger/0`).
    pub robot: String,
    /// The limb whose end effector carries the blocks (`None`: nothing carries them).
    pub limb: Option<String>,
    /// The gripper at the end of that limb.
    pub gripper: Option<String>,
    /// The laser.
    pub laser: LaserConfig,
    /// The seed of the laser's noise.
    pub seed: u64,
    /// How often the tool point and gripper are looked at (20 ms).
    pub tick: Duration,
}

impl WorldOptions {
    /// The options of `robot`'s world: an LMS200 ([`LaserConfig::lms200`]) and the
    /// blocks carried by `limb` and `gripper`.
    pub fn new(robot: &str, limb: &str, gripper: &str) -> Self {
        WorldOptions {
            robot: robot.to_string(),
            limb: Some(limb.to_string()),
            gripper: Some(gripper.to_string()),
            laser: LaserConfig::lms200(),
            seed: 0,
            tick: Duration::from_millis(20),
        }
    }
}

/// The world driver could not start or stopped with an error.
#[derive(Debug, thiserror::Error)]
pub enum WorldDriverError {
    /// The laser's configuration cannot be used.
    #[error("invalid laser: {0}")]
    Laser(#[from] LaserConfigError),
    /// The world's values cannot be used.
    #[error(transparent)]
    World(#[from] crate::WorldError),
    /// The ranger could not be offered.
    #[error(transparent)]
    Host(#[from] HostError),
    /// A context could not be made.
    #[error(transparent)]
    Context(#[from] limber_services::ContextError),
    /// A scan could not be published.
    #[error(transparent)]
    Publish(#[from] DeviceError<PublishError>),
    /// Requests could not be received.
    #[error(transparent)]
    Process(#[from] DeviceError<ProcessError>),
    /// The event loop failed.
    #[error(transparent)]
    Loop(#[from] LoopError),
}

/// Answers the ranger's requests.
struct Serve<'a>(&'a LaserConfig);

impl DeviceSetHandler for Serve<'_> {
    fn ranger_request(
        &mut self,
        _: u16,
        req: &RangerRequest,
        _: &Origin,
        _: &mut RangerData,
    ) -> Result<RangerReply, Status> {
        match req {
            RangerRequest::GetGeom => Ok(RangerReply::Geom(self.0.geometry())),
        }
    }
}

/// The clients that watch the limb and the gripper (connected once their driver offers
/// them), on the world's own node.
struct Watch {
    ctx: Context,
    limb_name: Option<String>,
    gripper_name: Option<String>,
    limb: Option<LimbClient>,
    gripper: Option<GripperClient>,
    next_try: Instant,
}

impl Watch {
    /// The tool point and whether the gripper is closed, once both are known.
    fn look(&mut self) -> Option<([f64; 3], bool)> {
        if (self.limb.is_none() || self.gripper.is_none()) && Instant::now() >= self.next_try {
            self.next_try = Instant::now() + Duration::from_secs(1);
            // Not there yet (the arm answers late): asked again in a second.
            let quick = Duration::from_millis(1);
            if let (None, Some(n)) = (&self.limb, &self.limb_name) {
                self.limb = LimbClient::connect_timeout(&self.ctx, n, quick)
                    .inspect_err(|e| tracing::debug!(device = n, error = %e, "world: no limb yet"))
                    .ok();
            }
            if let (None, Some(n)) = (&self.gripper, &self.gripper_name) {
                self.gripper = GripperClient::connect_timeout(&self.ctx, n, quick)
                    .inspect_err(
                        |e| tracing::debug!(device = n, error = %e, "world: no gripper yet"),
                    )
                    .ok();
            }
        }
        let l = self.limb.as_mut()?.state().copied()?;
        let g = self.gripper.as_mut()?.state().copied()?;
        Some((
            l.position.to_array(),
            g.gripper_state() == Ok(GripperState::Closed),
        ))
    }
}

/// The world of one robot: its blocks and obstacles, its laser served as
/// `<robot>/ranger/0`, and the blocks carried by its gripper.
pub struct WorldDriver {
    world: Arc<Mutex<World>>,
    laser: Laser,
    carrier: Carrier,
    hosts: DeviceSet,
    watch: Watch,
    tick: Duration,
    since_scan: Duration,
}

impl core::fmt::Debug for WorldDriver {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("WorldDriver")
            .field("laser", self.laser.config())
            .finish()
    }
}

impl WorldDriver {
    /// Offers `<robot>/ranger/0` in `domain` for `world` and publishes a first scan.
    pub fn new(
        domain: &Domain,
        world: World,
        options: WorldOptions,
    ) -> Result<Self, WorldDriverError> {
        world.validate()?;
        let laser = Laser::new(options.laser, options.seed)?;
        let ctx = Context::new(domain, Role::Driver, DRIVER_NAME)?;
        let mut hosts = DeviceSet::new(
            &ctx,
            &options.robot,
            DRIVER_NAME,
            &[(InterfaceKind::Ranger, 0)],
        )?;
        hosts.set_flags(device_flag::SIMULATED | device_flag::LINK_UP | device_flag::CALIBRATED);
        // One node for the ranger and the clients that watch the limb and the gripper.
        let watch = Watch {
            ctx: ctx.clone(),
            limb_name: options.limb,
            gripper_name: options.gripper,
            limb: None,
            gripper: None,
            next_try: Instant::now(),
        };
        let mut d = WorldDriver {
            world: Arc::new(Mutex::new(world)),
            laser,
            carrier: Carrier::default(),
            hosts,
            watch,
            tick: options.tick.max(Duration::from_millis(1)),
            since_scan: Duration::ZERO,
        };
        d.scan()?;
        Ok(d)
    }

    /// The world, shared: where its blocks are now (read it; the driver moves them).
    pub fn world(&self) -> Arc<Mutex<World>> {
        Arc::clone(&self.world)
    }

    /// The laser's configuration.
    pub fn laser(&self) -> &LaserConfig {
        self.laser.config()
    }

    /// Scans the world and publishes the scan.
    pub fn scan(&mut self) -> Result<(), DeviceError<PublishError>> {
        if let Some(h) = self.hosts.ranger_mut(0) {
            let w = self.world.lock().unwrap_or_else(PoisonError::into_inner);
            self.laser.scan(&w, h.state_mut());
        }
        self.hosts.publish_all(monotonic_ns())
    }

    /// One tick: the blocks follow the gripper; a scan is published when the laser's
    /// period has passed.
    pub fn tick(&mut self) -> Result<(), DeviceError<PublishError>> {
        if let Some((tool, closed)) = self.watch.look() {
            let mut w = self.world.lock().unwrap_or_else(PoisonError::into_inner);
            self.carrier.update(&mut w, tool, closed);
        }
        self.since_scan += self.tick;
        let period = Duration::from_secs_f64(1.0 / self.laser.config().frequency);
        if self.since_scan >= period {
            self.since_scan = Duration::ZERO;
            self.scan()?;
        }
        Ok(())
    }

    /// Serves until SIGINT/SIGTERM or until `stop` returns true (checked at every
    /// wake-up): ticks, scans and answers the ranger's requests. A failed tick or
    /// request is logged and retried at the next tick.
    pub fn run(&mut self, mut stop: impl FnMut() -> bool) -> Result<LoopExit, WorldDriverError> {
        let listeners = self.hosts.take_wake_listeners();
        let exit = event_loop::run(&listeners, self.tick, None, |wake| {
            let config = *self.laser.config();
            if let Err(e) = self.hosts.process(&mut Serve(&config)) {
                tracing::warn!(error = %e, "world: cannot answer the ranger's clients");
            }
            if let Wake::Tick(_) = wake
                && let Err(e) = self.tick()
            {
                tracing::warn!(error = %e, "world: cannot publish a scan");
            }
            if stop() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })?;
        Ok(exit)
    }
}
