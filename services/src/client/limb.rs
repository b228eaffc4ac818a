//! Player's `LimbProxy`: the limb conveniences of [`LimbClient`](super::LimbClient).

use limber_interfaces::prelude::*;

use super::{Client, CommandError, RequestError, Ticket};

/// Player's `LimbProxy`: every limb command and request.
impl Client<Limb> {
    /// CMD HOME.
    pub fn home(&mut self) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::Home)
    }
    /// CMD STOP: stop every joint now.
    pub fn stop(&mut self) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::Stop)
    }
    /// CMD SETPOSE: end effector to `position` (robot frame, m) with `approach` and
    /// `orientation` vectors.
    pub fn set_pose(
        &mut self,
        position: [f64; 3],
        approach: [f64; 3],
        orientation: [f64; 3],
    ) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::set_pose(
            position.into(),
            approach.into(),
            orientation.into(),
        )?)
    }
    /// CMD SETPOSITION: end effector to `position`, orientation chosen by the driver.
    pub fn set_position(&mut self, position: [f64; 3]) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::set_position(position.into())?)
    }
    /// CMD VECMOVE: move `length` m along `direction` in a straight line.
    pub fn vec_move(&mut self, direction: [f64; 3], length: f64) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::vec_move(direction.into(), length)?)
    }
    /// CMD LINE (limber's): the tool in a straight line to `position`, its orientation
    /// kept (`None`) or turned evenly to (approach, orientation), at most `speed` m/s (0:
    /// the limb's own). Checked whole before anything moves: a line that leaves the reach
    /// or hits the world is refused (`OUT_OF_REACH`, `PATH_COLLIDES`, ...), the limb
    /// state's `refused_at` saying where. `wait_done` gives its result.
    pub fn line(
        &mut self,
        position: [f64; 3],
        orientation: Option<([f64; 3], [f64; 3])>,
        speed: f64,
    ) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::Line(path(position, orientation, speed)?))
    }
    /// CMD PTP (limber's): the joints interpolated to where the tool is at `position`
    /// with its orientation kept (`None`) or the given one, the fastest joint at most
    /// `speed` rad/s (0: the joints' own); checked and refused as [`line`](Self::line).
    pub fn ptp(
        &mut self,
        position: [f64; 3],
        orientation: Option<([f64; 3], [f64; 3])>,
        speed: f64,
    ) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::Ptp(path(position, orientation, speed)?))
    }
    /// REQ POWER.
    pub fn power(&mut self, on: bool) -> Result<(), RequestError> {
        self.request(&LimbRequest::Power(on)).map(|_| ())
    }
    /// REQ BRAKES.
    pub fn brakes(&mut self, on: bool) -> Result<(), RequestError> {
        self.request(&LimbRequest::Brakes(on)).map(|_| ())
    }
    /// REQ SPEED: end-effector speed, m/s.
    pub fn set_speed(&mut self, speed: f64) -> Result<(), RequestError> {
        self.request(&LimbRequest::speed(speed)?).map(|_| ())
    }
    /// REQ REACH: where a SETPOSE to this pose would end and how much its orientation
    /// would be adjusted; nothing moves. A pose the limb cannot get to is refused with
    /// its cause (`RequestError::Nack`).
    pub fn reach(
        &mut self,
        position: [f64; 3],
        approach: [f64; 3],
        orientation: [f64; 3],
    ) -> Result<LimbReach, RequestError> {
        let req = LimbRequest::reach(position.into(), approach.into(), orientation.into())?;
        match self.request(&req)? {
            LimbReply::Reach(r) => Ok(r),
            LimbReply::Done | LimbReply::Geom(_) => Err(RequestError::Unexpected),
        }
    }
}

/// A path's goal from plain arrays, validated.
fn path(
    position: [f64; 3],
    orientation: Option<([f64; 3], [f64; 3])>,
    speed: f64,
) -> Result<limber_interfaces::limb::LimbPath, ValueError> {
    let o = orientation.map(|(a, o)| (a.into(), o.into()));
    limber_interfaces::limb::LimbPath::new(position.into(), o, speed)
}
