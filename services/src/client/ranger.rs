//! Player's `RangerProxy` (and `LaserProxy`): a ranger has no command, so its client is
//! [`RangerClient`](super::RangerClient) with the calls every client has (its scans by
//! `state`, `wait_state`..., its geometry by `geometry`) and the scan's helpers on
//! [`RangerData`] (`ranges`, `bearing`, `point`).

use limber_interfaces::prelude::*;

use super::{Client, RequestError};

/// Player's `RangerProxy`: the geometry and configuration of the sensor.
impl Client<Ranger> {
    /// REQ GET_GEOM: the sensor's pose on the robot, its size and its configuration
    /// (Player's `RequestGeom` then `GetPose`, `GetMinAngle`...). The same as
    /// [`Client::geometry`].
    pub fn request_geom(&mut self) -> Result<RangerGeom, RequestError> {
        self.geometry()
    }
}
