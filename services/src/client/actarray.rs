//! Player's `ActArrayProxy`: the actarray conveniences of [`ActArrayClient`](super::ActArrayClient).

use limber_interfaces::prelude::*;

use super::{Client, CommandError, RequestError, Ticket, TrajectorySendError};

fn joint_index(j: usize) -> i64 {
    j.min(i64::MAX as usize) as i64
}

/// Player's `ActArrayProxy`: every actarray command and request.
impl Client<ActArray> {
    /// CMD POS: move `joint` to `position` (rad or m).
    pub fn move_to(&mut self, joint: usize, position: f64) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::position(joint_index(joint), position)?)
    }
    /// CMD MULTI_POS: move joints 0..n to `positions`.
    pub fn move_to_multi(&mut self, positions: &[f64]) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::multi_position(positions)?)
    }
    /// CMD SPEED: move `joint` at `speed` (rad/s or m/s).
    pub fn move_at_speed(&mut self, joint: usize, speed: f64) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::speed(joint_index(joint), speed)?)
    }
    /// CMD MULTI_SPEED: move joints 0..n at `speeds`.
    pub fn move_at_speed_multi(&mut self, speeds: &[f64]) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::multi_speed(speeds)?)
    }
    /// CMD HOME: home `joint`, or every joint with `None`.
    pub fn home(&mut self, joint: Option<usize>) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::home(
            joint.map(joint_index).unwrap_or(-1),
        )?)
    }
    /// CMD CURRENT: drive `joint` (or all with `None`) with `current` A.
    pub fn set_current(
        &mut self,
        joint: Option<usize>,
        current: f64,
    ) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::current(
            joint.map(joint_index).unwrap_or(-1),
            current,
        )?)
    }
    /// CMD MULTI_CURRENT: drive joints 0..n with `currents` A.
    pub fn set_current_multi(&mut self, currents: &[f64]) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::multi_current(currents)?)
    }
    /// TRAJ: uploads joint trajectory `traj` (as `TRAJ_CHUNK`s; see
    /// [`JointTrajectory::commands`]) and runs it; the ticket is the `TRAJ`'s, so
    /// [`Client::wait_outcome`] says whether it was accepted (or why not) and
    /// [`Client::wait_done`] returns its result. It replaces a running trajectory from its
    /// start time. Validated here first (nothing is sent when it is invalid).
    pub fn follow_trajectory(
        &mut self,
        traj: &JointTrajectory,
    ) -> Result<Ticket, TrajectorySendError> {
        let commands = traj.commands()?;
        let mut ticket = None;
        for c in &commands {
            ticket = Some(self.send(c)?);
        }
        ticket.ok_or(TrajectorySendError::Invalid(TrajectoryError::PointCount(0)))
    }
    /// TRAJ_SCALE: the speed scaling of trajectories (0 pauses, 1 is nominal; above 1 is
    /// clamped to 1 and answered CLAMPED).
    pub fn set_trajectory_scale(&mut self, scale: f64) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::traj_scale(scale)?)
    }
    /// REQ POWER.
    pub fn power(&mut self, on: bool) -> Result<(), RequestError> {
        self.request(&ActArrayRequest::Power(on)).map(|_| ())
    }
    /// REQ BRAKES.
    pub fn brakes(&mut self, on: bool) -> Result<(), RequestError> {
        self.request(&ActArrayRequest::Brakes(on)).map(|_| ())
    }
    /// REQ SPEED: the speed of `joint` for later moves.
    pub fn set_speed_config(&mut self, joint: usize, speed: f64) -> Result<(), RequestError> {
        self.request(&ActArrayRequest::speed(joint_index(joint), speed)?)
            .map(|_| ())
    }
    /// REQ ACCEL: the acceleration of `joint` for later moves.
    pub fn set_accel_config(&mut self, joint: usize, accel: f64) -> Result<(), RequestError> {
        self.request(&ActArrayRequest::accel(joint_index(joint), accel)?)
            .map(|_| ())
    }
}
