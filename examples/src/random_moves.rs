//! The paper's Listing 1: move every joint of an actuator array to random positions
//! within the limits that the array reports in its geometry, round after round.

use std::time::{Duration, Instant};

use limber_services::prelude::*;
use rand::rngs::SmallRng;
use rand::{Rng as _, SeedableRng};
use thiserror::Error;

/// Parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RandomParams {
    /// Rounds (each moves every joint once).
    pub rounds: usize,
    /// Keep targets this far inside each limit (rad or m).
    pub margin: f64,
    /// Seed of the random generator (the same seed gives the same moves).
    pub seed: u64,
    /// Time allowed for one round to settle.
    pub round_timeout: Duration,
}

impl Default for RandomParams {
    fn default() -> Self {
        RandomParams {
            rounds: 3,
            margin: 0.05,
            seed: 2006,
            round_timeout: Duration::from_secs(30),
        }
    }
}

/// The program stopped.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RandomError {
    /// A command could not be sent.
    #[error("cannot send: {0}")]
    Command(#[from] CommandError),
    /// The geometry request failed.
    #[error("geometry request failed: {0}")]
    Request(#[from] RequestError),
    /// The driver refused a target inside its own limits.
    #[error("joint {joint}: target {target:.4} refused: {status}")]
    Refused {
        /// The joint.
        joint: usize,
        /// The target.
        target: f64,
        /// Why.
        status: Status,
    },
    /// A round did not settle in time.
    #[error("round {round}: joints still moving after {timeout:?}")]
    Timeout {
        /// The round.
        round: usize,
        /// The limit.
        timeout: Duration,
    },
    /// The driver went away.
    #[error("{0}")]
    Wait(#[from] WaitError),
}

/// One move, as reported to the observer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// The round.
    pub round: usize,
    /// The joint.
    pub joint: usize,
    /// Its target.
    pub target: f64,
    /// The joint's limits.
    pub limits: (f64, f64),
}

/// Runs the program on `arm`; returns the final joint positions. `observe` sees each
/// move as it is sent and, after each round, the state.
pub fn run(
    arm: &mut ActArrayClient,
    p: &RandomParams,
    observe: &mut dyn FnMut(Option<Move>, &ActArrayData),
) -> Result<Vec<f64>, RandomError> {
    let geom = arm.geometry()?;
    // Seeded, so runs are repeatable.
    let mut rng = SmallRng::seed_from_u64(p.seed);
    for round in 0..p.rounds {
        for (joint, g) in geom.actuators().iter().enumerate() {
            // The geometry reports min <= max; stay a margin inside, as the paper's
            // program stays clear of the limits.
            let (lo, hi) = (g.min.min(g.max), g.min.max(g.max));
            let m = p.margin.min((hi - lo) / 4.0);
            let target = lo + m + rng.random::<f64>() * (hi - lo - 2.0 * m);
            let t = arm.move_to(joint, target)?;
            if let Some(s) = arm.state() {
                observe(
                    Some(Move {
                        round,
                        joint,
                        target,
                        limits: (lo, hi),
                    }),
                    s,
                );
            }
            match arm.wait_outcome(t, p.round_timeout) {
                Ok(Status::Ok) | Err(WaitError::Missed { .. }) => {}
                Ok(status) => {
                    return Err(RandomError::Refused {
                        joint,
                        target,
                        status,
                    });
                }
                Err(e) => return Err(e.into()),
            }
        }
        wait_settled(arm, round, p.round_timeout)?;
        if let Some(s) = arm.state() {
            observe(None, s);
        }
    }
    Ok(arm
        .state()
        .map(|s| s.actuators().iter().map(|a| a.position).collect())
        .unwrap_or_default())
}

/// Waits until no actuator reports MOVING.
fn wait_settled(
    arm: &mut ActArrayClient,
    round: usize,
    timeout: Duration,
) -> Result<(), RandomError> {
    let deadline = Instant::now() + timeout;
    loop {
        let moving = arm.state().is_some_and(|s| {
            s.actuators()
                .iter()
                .any(|a| a.state & ActuatorFlags::MOVING.bits() != 0)
        });
        if !moving {
            return Ok(());
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(RandomError::Timeout { round, timeout });
        }
        match arm.wait_state(left) {
            Ok(_) => {}
            Err(WaitError::Timeout(_)) => return Err(RandomError::Timeout { round, timeout }),
            Err(e) => return Err(e.into()),
        }
    }
}
