//! Requests: a typed request, a typed reply (ACK) or refusal (NACK), always with a timeout.

use core::time::Duration;
use std::time::Instant;

use limber_interfaces::prelude::*;

use super::{Client, DriverStatus, LIVENESS_PERIOD, RequestError};
use crate::context::monotonic_ns;
use crate::qos;

impl<I: Interface> Client<I> {
    // ----- requests ---------------------------------------------------------------------

    /// Sends a typed request and waits for the reply (up to the request timeout).
    pub fn request(&mut self, req: &I::Request) -> Result<I::Reply, RequestError> {
        let timeout = self.request_timeout;
        self.request_with_timeout(req, timeout)
    }

    /// Asks for the device's geometry ([`Interface::GEOMETRY`]: GET_GEOM, or the limb's
    /// GEOM), waiting up to the request timeout.
    pub fn geometry(&mut self) -> Result<I::Geom, RequestError> {
        I::geometry_of(self.request(&I::GEOMETRY)?).ok_or(RequestError::Unexpected)
    }

    /// Sends a typed request and waits up to `timeout` for the reply.
    pub fn request_with_timeout(
        &mut self,
        req: &I::Request,
        timeout: Duration,
    ) -> Result<I::Reply, RequestError> {
        let loan = self
            .requests
            .loan_uninit()
            .map_err(|e| RequestError::Transport(e.into()))?;
        let mut r = loan.write_payload(I::ReqMsg::default());
        let raw: &mut I::ReqMsg = r.payload_mut();
        req.write(raw);
        self.req_seq += 1;
        let m = raw.meta_mut();
        m.client_id = self.client_id;
        m.seq = self.req_seq;
        m.stamp_ns = monotonic_ns();
        let pending = r.send().map_err(|e| RequestError::Transport(e.into()))?;
        if pending.number_of_server_connections() == 0 {
            return Err(RequestError::NoDriver);
        }
        if self.wake_driver {
            self.wake_driver_with(qos::EVENT_REQUEST);
        }
        self.sent();
        let deadline = Instant::now() + timeout;
        let mut next_check = Instant::now() + LIVENESS_PERIOD;
        loop {
            match pending.receive() {
                Ok(Some(resp)) => {
                    return decode_reply::<I>(resp.payload());
                }
                Ok(None) => {}
                Err(e) => return Err(RequestError::Transport(e.into())),
            }
            if !pending.is_connected() {
                // The server may have answered and closed in between: look once more.
                return match pending.receive() {
                    Ok(Some(resp)) => decode_reply::<I>(resp.payload()),
                    Ok(None) => Err(RequestError::DriverGone),
                    Err(e) => {
                        tracing::debug!(device = %self.device, error = %e,
                            "cannot receive from a disconnected driver");
                        Err(RequestError::DriverGone)
                    }
                };
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(RequestError::Timeout(timeout));
            }
            if now >= next_check {
                next_check = now + LIVENESS_PERIOD;
                if self.driver_status() != DriverStatus::Alive {
                    return Err(RequestError::DriverGone);
                }
            }
            self.pause(deadline.min(next_check))
                .map_err(RequestError::Transport)?;
        }
    }
}

/// A reply as the caller sees it: the ACK's payload, or the NACK's reason.
fn decode_reply<I: Interface>(raw: &I::ReplyMsg) -> Result<I::Reply, RequestError> {
    match I::Reply::read(raw) {
        Ok(Ok(reply)) => Ok(reply),
        Ok(Err(status)) => Err(RequestError::Nack(status)),
        Err(e) => Err(RequestError::Decode(e)),
    }
}
