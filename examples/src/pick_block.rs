//! The paper's Listing 2: pick up a block, carry it, put it down, with the limb and
//! gripper interfaces only. The same code runs on the Pioneer arm and on any simarm chain.
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
    /// Block centre, x and y.
    pub block: [f64; 2],
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
    /// The driver went away.
    #[error("{step:?}: {source}")]
    Wait {
        /// The step.
        step: Step,
        /// What happened.
        source: WaitError,
    },
}

/// What the program did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
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
        })
    }
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
    let orient = |x: [f64; 3]| match p.across {
        Some(v) => [v[0], v[1], 0.0],
        None => radial(base, [x[0], x[1]]),
    };
    let above = |xy: [f64; 2]| [xy[0], xy[1], p.grasp_height + p.clearance];
    let at = |xy: [f64; 2]| [xy[0], xy[1], p.grasp_height];

    let mut block_seen = false;
    let mut run_step = |dev: &mut Devices, step: Step| -> Result<(), PickError> {
        observe(Event::Start(step));
        let sent = match step {
            Step::Home | Step::HomeAgain => Some(dev.limb.home()?),
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
        Step::Approach(above(p.block)),
        Step::Descend(at(p.block)),
        Step::Grip,
        Step::Lift(above(p.block)),
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
        Ok(Status::Ok) | Err(WaitError::Missed { .. }) => {}
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
