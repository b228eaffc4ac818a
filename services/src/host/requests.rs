//! Answering the `req` channel: each request decoded, refused while another client holds
//! the device (unless it only reads), answered by the handler, the state that shows its
//! effect sent before its reply.

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::prelude::*;
use limber_interfaces::prelude::*;

use super::{DeviceHandler, DeviceHost, Origin, ProcessError, PublishError};
use crate::context::monotonic_ns;
use crate::error::Iox2Error;
use crate::qos;

impl<I: Interface> DeviceHost<I> {
    /// Answers every pending request. A request that does not decode is NACKed with the
    /// matching status without reaching the handler.
    pub fn process_requests<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<usize, ProcessError> {
        let mut n = 0;
        let mut state_result: Option<Result<(), PublishError>> = None;
        loop {
            let active: ActiveRequest<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()> =
                match self.server.receive() {
                    Ok(Some(a)) => a,
                    Ok(None) => break,
                    Err(e) => return Err(ProcessError::Receive(e)),
                };
            let raw: &I::ReqMsg = active.payload();
            let meta = *raw.meta();
            let origin = Origin {
                client_id: meta.client_id,
                seq: meta.seq,
                sent_ns: meta.stamp_ns,
                received_ns: monotonic_ns(),
            };
            let leased = self.arbiter.refusing(meta.client_id).is_some();
            let parsed = I::Request::read(raw);
            let mutating = !matches!(&parsed, Ok(r) if r.is_read_only());
            let reply = match parsed {
                Ok(req) if leased && !req.is_read_only() => {
                    self.stats.leased_refusals += 1;
                    Err(Status::Leased)
                }
                Ok(req) => handler.request(&req, &origin, &mut self.state),
                Err(e) => Err(e.status()),
            };
            // What a request that may change the device (power, brakes, ...) did is in
            // the state sent before its reply, as for commands (the first failure kept).
            if mutating && self.publish_each_outcome {
                let sent = self.send_state();
                if !matches!(state_result, Some(Err(_))) {
                    state_result = Some(sent);
                }
            }
            let sent = match active.loan_uninit() {
                Ok(loan) => {
                    let mut resp = loan.write_payload(I::ReplyMsg::default());
                    let out: &mut I::ReplyMsg = resp.payload_mut();
                    I::Reply::write(meta.kind, reply.as_ref().map_err(|s| *s), out);
                    let m = out.meta_mut();
                    m.client_id = meta.client_id;
                    m.seq = meta.seq;
                    m.stamp_ns = monotonic_ns();
                    resp.send().map_err(Iox2Error::from)
                }
                Err(e) => Err(e.into()),
            };
            if let Err(e) = sent {
                // The client is gone (or gave up): not fatal, counted.
                self.stats.undelivered_replies += 1;
                tracing::debug!(
                    device = %self.device,
                    client = meta.client_id,
                    seq = meta.seq,
                    error = %e,
                    "reply not delivered"
                );
            }
            drop(active);
            self.stats.requests += 1;
            n += 1;
            self.notify_clients(qos::EVENT_REPLY);
        }
        match state_result {
            Some(sent) => {
                sent?;
                self.state_sent();
            }
            // A read-only request's state, as before: the latest, published at once.
            None if n > 0 && self.publish_each_outcome => self.publish()?,
            None => {}
        }
        Ok(n)
    }
}
