//! The paper's Listing 2: find a block with the laser, pick it up, carry it, put it down,
//! with the ranger, limb and gripper interfaces only. The same code runs on the Pioneer
//! arm and on any simarm chain.
//!
//! Finding the block (the paper's lines 13-40, [`find_block`]): the laser's pose from its
//! geometry; the closest point of the scan; the block's centre is that point plus the
//! block's radius along the same beam; the orientation vector goes from the closest point
//! to the centre. Without a laser ([`Devices::laser`] `None`) the block is where
//! [`PickParams::block`] says and the orientation vector points away from the limb's base.
//!
//! Steps: home; open the gripper; approach 5 cm above the block with the approach vector
//! pointing down and the orientation vector across the block; check that the pose was
//! reachable (out of reach: go home and stop); descend to the grasp height; close the
//! gripper; lift; carry to the drop point (again 5 cm above, then down); release; lift;
//! home.

use std::time::{Duration, Instant};

use limber_services::prelude::*;
use thiserror::Error;

/// Where the block is and where it goes, in the robot frame (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PickParams {
    /// Block centre, x and y (used when the devices have no laser).
    pub block: [f64; 2],
    /// The block's radius: from the closest point the laser sees to its centre (m; the
    /// paper's `BlockRadius`).
    pub block_radius: f64,
    /// Drop point, x and y.
    pub drop: [f64; 2],
    /// Height of the grasp point above the floor (the paper's `HandleHeight`).
    pub grasp_height: f64,
    /// How far above the grasp point to approach and lift (the paper: 5 cm).
    pub clearance: f64,
    /// Horizontal direction of the orientation vector (x, y). `None`: radially outward
    /// from the limb's base (from its geometry) towards the block, which is what a 5-DOF
    /// arm like the Pioneer's can reach with the gripper pointing down, and what the
    /// paper computed from the laser scan.
    pub across: Option<[f64; 2]>,
    /// Time allowed for each motion.
    pub motion_timeout: Duration,
}

impl Default for PickParams {
    fn default() -> Self {
        PickParams {
            block: [0.38, 0.10],
            block_radius: 0.02,
            drop: [0.38, -0.10],
            grasp_height: 0.17,
            clearance: 0.05,
            across: None,
            motion_timeout: Duration::from_secs(30),
        }
    }
}

/// One step of the program, reported as it starts and when it ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// Finding the block in the laser's scan (before the first step; only with a laser).
    Find,
    /// Going home.
    Home,
    /// Opening the gripper.
    OpenGripper,
    /// Moving 5 cm above the block.
    Approach([f64; 3]),
    /// Descending to the grasp pose.
    Descend([f64; 3]),
    /// Closing the gripper on the block.
    Grip,
    /// Lifting the block.
    Lift([f64; 3]),
    /// Carrying it above the drop point.
    Carry([f64; 3]),
    /// Putting it down.
    PutDown([f64; 3]),
    /// Opening the gripper.
    Release,
    /// Moving up and away.
    Retreat([f64; 3]),
    /// Going home at the end.
    HomeAgain,
}

/// What an observer is told.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Event<'a> {
    /// The laser found the block (before the first step).
    Found(Found),
    /// A step starts.
    Start(Step),
    /// A step ended; the limb and gripper states at its end.
    Done(Step, &'a LimbData, &'a GripperData),
    /// A new state arrived while waiting (for live displays).
    Progress(&'a LimbData, &'a GripperData),
}

/// The program stopped.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PickError {
    /// A device could not be reached.
    #[error("cannot connect: {0}")]
    Connect(#[from] ConnectError),
    /// A command could not be sent.
    #[error("cannot send: {0}")]
    Command(#[from] CommandError),
    /// A request failed.
    #[error("request failed: {0}")]
    Request(#[from] RequestError),
    /// The target of a step was out of reach (the arm went home).
    #[error("{step:?}: target out of reach")]
    OutOfReach {
        /// The step.
        step: Step,
    },
    /// A step's command was refused for another reason.
    #[error("{step:?}: refused: {status}")]
    Refused {
        /// The step.
        step: Step,
        /// Why.
        status: Status,
    },
    /// A joint stalled (collision) during a step.
    #[error("{step:?}: the limb is blocked")]
    Blocked {
        /// The step.
        step: Step,
    },
    /// A step did not finish in time.
    #[error("{step:?}: not finished within {timeout:?}")]
    Timeout {
        /// The step.
        step: Step,
        /// The limit.
        timeout: Duration,
    },
    /// The laser saw nothing within its range: no block to pick.
    #[error("the laser sees no block")]
    NothingSeen,
    /// The driver went away.
    #[error("{step:?}: {source}")]
    Wait {
        /// The step.
        step: Step,
        /// What happened.
        source: WaitError,
    },
}

/// Where the laser found the block (the paper's lines 13-40).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found {
    /// The closest point of the scan, x and y in the robot frame (m).
    pub closest: [f64; 2],
    /// The block's centre, x and y in the robot frame (m).
    pub centre: [f64; 2],
    /// The orientation vector: from the closest point to the centre.
    pub orientation: [f64; 3],
}

/// What the program did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Where the laser found the block (`None`: no laser, the block was given).
    pub found: Option<Found>,
    /// Steps carried out.
    pub steps: usize,
    /// Whether the gripper's beams saw the block while it was held.
    pub block_seen: bool,
    /// Where the end effector was when the block was released.
    pub released_at: [f64; 3],
    /// Total time.
    pub elapsed: Duration,
}

/// The devices the program uses.
pub struct Devices {
    /// The limb.
    pub limb: LimbClient,
    /// The gripper at the end of the limb.
    pub gripper: GripperClient,
    /// The laser that finds the block (`None`: the block is where the parameters say).
    pub laser: Option<RangerClient>,
}

impl Devices {
    /// Connects to `limb` and `gripper` (device names) in the context's domain.
    pub fn connect(
        ctx: &Context,
        limb: &str,
        gripper: &str,
        timeout: Duration,
    ) -> Result<Self, ConnectError> {
        Ok(Devices {
            limb: LimbClient::connect_timeout(ctx, limb, timeout)?,
            gripper: GripperClient::connect_timeout(ctx, gripper, timeout)?,
            laser: None,
        })
    }

    /// Connects to `limb`, `gripper` and the laser `laser` (device names).
    pub fn connect_with_laser(
        ctx: &Context,
        limb: &str,
        gripper: &str,
        laser: &str,
        timeout: Duration,
    ) -> Result<Self, ConnectError> {
        let mut d = Devices::connect(ctx, limb, gripper, timeout)?;
        d.laser = Some(RangerClient::connect_timeout(ctx, laser, timeout)?);
        Ok(d)
    }
}

/// The paper's lines 13-40: finds the block in `laser`'s latest scan (waiting up to
/// `timeout` for one). The closest point of the scan, moved to the robot frame by the
/// laser's pose; the centre `radius` further along the same beam; the orientation vector
/// from the closest point to the centre.
pub fn find_block(
    laser: &mut RangerClient,
    radius: f64,
    timeout: Duration,
) -> Result<Found, PickError> {
    let pose = laser.geometry()?.pose;
    let (lx, ly, yaw) = (pose.position.x, pose.position.y, pose.orientation.yaw);
    let scan = *laser.current(timeout).map_err(|source| PickError::Wait {
        step: Step::Find,
        source,
    })?;
    let ranges = scan.ranges();
    // Find the closest point in the laser scan.
    let mut min_index = 0;
    for i in 1..ranges.len() {
        if ranges[i] < ranges[min_index] {
            min_index = i;
        }
    }
    if ranges.is_empty() || ranges[min_index] >= scan.max_range {
        return Err(PickError::NothingSeen);
    }
    // In the robot frame: the laser's heading turns the bearing, its position moves it.
    let to_robot = |range: f64| {
        let b = yaw + scan.bearing(min_index);
        [lx + range * b.cos(), ly + range * b.sin()]
    };
    let closest = to_robot(ranges[min_index]);
    // Calculate a point in the middle of the block.
    let centre = to_robot(ranges[min_index] + radius);
    // The orientation vector: from the closest point to the centre.
    let orientation = [centre[0] - closest[0], centre[1] - closest[1], 0.0];
    Ok(Found {
        closest,
        centre,
        orientation,
    })
}

const DOWN: [f64; 3] = [0.0, 0.0, -1.0];

/// Runs the program; `observe` sees every step and, while waiting, every new state.
pub fn run(
    dev: &mut Devices,
    p: &PickParams,
    observe: &mut dyn FnMut(Event<'_>),
) -> Result<Summary, PickError> {
    let start = Instant::now();
    let mut steps = 0;
    let base = match p.across {
        Some(_) => [0.0; 3],
        None => dev.limb.geometry()?.base_pos.to_array(),
    };
    let found = match dev.laser.as_mut() {
        Some(laser) => {
            let f = find_block(laser, p.block_radius, p.motion_timeout)?;
            observe(Event::Found(f));
            Some(f)
        }
        None => None,
    };
    let block = found.map_or(p.block, |f| f.centre);
    // With the laser, the block is approached along the vector the scan gave, and carried
    // without turning it; without, radially away from the limb's base.
    let orient = |x: [f64; 3]| match (found, p.across) {
        (Some(f), _) => f.orientation,
        (None, Some(v)) => [v[0], v[1], 0.0],
        (None, None) => radial(base, [x[0], x[1]]),
    };
    let above = |xy: [f64; 2]| [xy[0], xy[1], p.grasp_height + p.clearance];
    let at = |xy: [f64; 2]| [xy[0], xy[1], p.grasp_height];

    let mut block_seen = false;
    let mut run_step = |dev: &mut Devices, step: Step| -> Result<(), PickError> {
        observe(Event::Start(step));
        let sent = match step {
            Step::Find | Step::Home | Step::HomeAgain => Some(dev.limb.home()?),
            Step::OpenGripper | Step::Release => {
                let t = dev.gripper.open()?;
                wait_gripper(dev, step, t, GripperState::Open, p.motion_timeout, observe)?;
                None
            }
            Step::Grip => {
                let t = dev.gripper.close()?;
                wait_gripper(
                    dev,
                    step,
                    t,
                    GripperState::Closed,
                    p.motion_timeout,
                    observe,
                )?;
                None
            }
            Step::Approach(x)
            | Step::Descend(x)
            | Step::Lift(x)
            | Step::Carry(x)
            | Step::PutDown(x)
            | Step::Retreat(x) => Some(dev.limb.set_pose(x, DOWN, orient(x))?),
        };
        if let Some(ticket) = sent {
            wait_limb(dev, step, ticket, p.motion_timeout, observe)?;
        }
        let wait = |source| PickError::Wait { step, source };
        let l = *dev.limb.current(p.motion_timeout).map_err(wait)?;
        let g = *dev.gripper.current(p.motion_timeout).map_err(wait)?;
        if matches!(step, Step::Grip | Step::Lift(_) | Step::Carry(_)) && g.beams != 0 {
            block_seen = true;
        }
        observe(Event::Done(step, &l, &g));
        Ok(())
    };

    let plan = [
        Step::Home,
        Step::OpenGripper,
        Step::Approach(above(block)),
        Step::Descend(at(block)),
        Step::Grip,
        Step::Lift(above(block)),
        Step::Carry(above(p.drop)),
        Step::PutDown(at(p.drop)),
        Step::Release,
        Step::Retreat(above(p.drop)),
        Step::HomeAgain,
    ];
    let mut released_at = [0.0; 3];
    for step in plan {
        if let Err(e) = run_step(dev, step) {
            // Like the paper: out of reach (or any failure) sends the limb home first.
            if !matches!(step, Step::Home | Step::HomeAgain) {
                let _ = dev.limb.home();
            }
            return Err(e);
        }
        if step == Step::Release {
            released_at = dev
                .limb
                .state()
                .map(|l| l.position.to_array())
                .unwrap_or_default();
        }
        steps += 1;
    }
    Ok(Summary {
        found,
        steps,
        block_seen,
        released_at,
        elapsed: start.elapsed(),
    })
}

/// The unit horizontal vector from `base` towards `xy` (x forward if they coincide).
pub fn radial(base: [f64; 3], xy: [f64; 2]) -> [f64; 3] {
    let (dx, dy) = (xy[0] - base[0], xy[1] - base[1]);
    let n = (dx * dx + dy * dy).sqrt();
    if n < 1e-9 {
        [1.0, 0.0, 0.0]
    } else {
        [dx / n, dy / n, 0.0]
    }
}

/// Waits for the outcome of a limb command, then until the limb stops moving.
fn wait_limb(
    dev: &mut Devices,
    step: Step,
    ticket: Ticket,
    timeout: Duration,
    observe: &mut dyn FnMut(Event<'_>),
) -> Result<(), PickError> {
    let deadline = Instant::now() + timeout;
    match dev.limb.wait_outcome(ticket, timeout) {
        // "ok", or "ok, orientation adjusted" (a 5-joint arm turns the orientation the
        // laser gave to the nearest one it can hold).
        Ok(s) if s.is_carried_out() => {}
        Err(WaitError::Missed { .. }) => {}
        Ok(Status::OutOfReach) => return Err(PickError::OutOfReach { step }),
        Ok(status) => return Err(PickError::Refused { step, status }),
        Err(source) => return Err(PickError::Wait { step, source }),
    }
    // The state published with the outcome already reflects the command (moving, or
    // idle when there was nothing to do); wait until it is no longer moving.
    loop {
        let l = *dev
            .limb
            .current(timeout)
            .map_err(|source| PickError::Wait { step, source })?;
        match l.limb_state() {
            Ok(LimbState::Idle) | Ok(LimbState::Braked) => return Ok(()),
            Ok(LimbState::OutOfReach) => return Err(PickError::OutOfReach { step }),
            Ok(LimbState::Collision) => return Err(PickError::Blocked { step }),
            Ok(LimbState::Moving) | Err(_) => {}
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(PickError::Timeout { step, timeout });
        }
        match dev.limb.wait_state(left) {
            Ok(_) => {}
            Err(WaitError::Timeout(_)) => return Err(PickError::Timeout { step, timeout }),
            Err(source) => return Err(PickError::Wait { step, source }),
        }
        if let (Some(l), Some(g)) = (dev.limb.last_state().copied(), dev.gripper.state().copied()) {
            observe(Event::Progress(&l, &g));
        }
    }
}

/// Waits for the outcome of a gripper command, then until the gripper reaches `want`
/// (closing on a block counts as closed).
fn wait_gripper(
    dev: &mut Devices,
    step: Step,
    ticket: Ticket,
    want: GripperState,
    timeout: Duration,
    observe: &mut dyn FnMut(Event<'_>),
) -> Result<(), PickError> {
    let deadline = Instant::now() + timeout;
    match dev.gripper.wait_outcome(ticket, timeout) {
        Ok(Status::Ok) | Err(WaitError::Missed { .. }) => {}
        Ok(status) => return Err(PickError::Refused { step, status }),
        Err(source) => return Err(PickError::Wait { step, source }),
    }
    loop {
        let g = *dev
            .gripper
            .current(timeout)
            .map_err(|source| PickError::Wait { step, source })?;
        if g.gripper_state() == Ok(want) {
            return Ok(());
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(PickError::Timeout { step, timeout });
        }
        match dev.gripper.wait_state(left) {
            Ok(_) => {}
            Err(WaitError::Timeout(_)) => return Err(PickError::Timeout { step, timeout }),
            Err(source) => return Err(PickError::Wait { step, source }),
        }
        if let (Some(l), Some(g)) = (dev.limb.state().copied(), dev.gripper.last_state().copied()) {
            observe(Event::Progress(&l, &g));
        }
    }
}
