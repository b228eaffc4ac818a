//! Draws a square with the limb's tool (issue 28): a point-to-point move (PTP) to the first
//! corner with the tool pointing down, then each edge a straight line (LINE) at a speed
//! limit, each motion followed to its result with `wait_done`. The driver checks each path
//! whole before it moves; a refused one stops the program with the reason.

use std::time::Duration;

use limber_services::prelude::*;
use thiserror::Error;

/// The square.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SquareParams {
    /// Its centre, m (robot frame); the square lies in the horizontal plane through it.
    pub centre: [f64; 3],
    /// Its side, m.
    pub side: f64,
    /// The tool's speed along the edges, m/s (0: the limb's own).
    pub speed: f64,
    /// How long one motion may take.
    pub timeout: Duration,
}

impl Default for SquareParams {
    fn default() -> Self {
        SquareParams {
            centre: [0.4, 0.0, 0.25],
            side: 0.1,
            speed: 0.05,
            timeout: Duration::from_secs(60),
        }
    }
}

/// The program stopped.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SquareError {
    /// A command could not be sent (an invalid value).
    #[error("cannot send: {0}")]
    Command(#[from] CommandError),
    /// A motion was refused, or its result never came.
    #[error("motion {motion}: {source}")]
    Done {
        /// 0 the move to the first corner, 1 to 4 the edges.
        motion: usize,
        /// Why.
        #[source]
        source: DoneError,
    },
    /// A motion ended short of its goal.
    #[error("motion {motion}: {result}")]
    NotReached {
        /// 0 the move to the first corner, 1 to 4 the edges.
        motion: usize,
        /// How it ended, in words.
        result: String,
    },
}

/// One motion of the square and how it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    /// 0 the move to the first corner, 1 to 4 the edges.
    pub motion: usize,
    /// The corner it went to.
    pub corner: [f64; 3],
    /// Its result.
    pub done: Done,
}

/// The square's corners, counter-clockwise seen from above, the first at the back right.
pub fn corners(p: &SquareParams) -> [[f64; 3]; 4] {
    let [x, y, z] = p.centre;
    let h = p.side / 2.0;
    [
        [x - h, y - h, z],
        [x + h, y - h, z],
        [x + h, y + h, z],
        [x - h, y + h, z],
    ]
}

/// The tool pointing down, fingers along x.
const DOWN: ([f64; 3], [f64; 3]) = ([0.0, 0.0, -1.0], [1.0, 0.0, 0.0]);

/// Draws the square with `limb`; `observe` sees each motion as it ends. Every motion's
/// result, in order.
pub fn run(
    limb: &mut LimbClient,
    p: &SquareParams,
    observe: &mut dyn FnMut(&Stroke),
) -> Result<Vec<Stroke>, SquareError> {
    let c = corners(p);
    let mut out = Vec::with_capacity(5);
    // The first corner by PTP, then the four edges (back to the first) by LINE.
    for motion in 0..5 {
        let corner = c[motion % 4];
        let ticket = if motion == 0 {
            limb.ptp(corner, Some(DOWN), 0.0)?
        } else {
            limb.line(corner, None, p.speed)?
        };
        let done = limb
            .wait_done(ticket, p.timeout)
            .map_err(|source| SquareError::Done { motion, source })?;
        let stroke = Stroke {
            motion,
            corner,
            done,
        };
        observe(&stroke);
        if !stroke.done.reached() {
            return Err(SquareError::NotReached {
                motion,
                result: stroke.done.to_string(),
            });
        }
        out.push(stroke);
    }
    Ok(out)
}
