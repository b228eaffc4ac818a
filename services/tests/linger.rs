//! The linger of an event-driven driver (`DeviceHost::process_linger`) answers a client's
//! request on its first poll, where the spinning poll (`process_spin`) looks for requests
//! only on every `SPIN_REQUEST_EVERY`th call.

use std::sync::mpsc;
use std::time::{Duration, Instant};

use limber_services::prelude::*;
use limber_services::qos::EVENT_REQUEST;

const T: Duration = Duration::from_secs(5);
const DEVICE: &str = "linger/actarray/0";
const REQUESTS: usize = 40;

/// Refuses every command and request: a NACK is a reply like any other.
struct Refuse;

impl DeviceHandler<ActArray> for Refuse {
    fn command(&mut self, _: &ActArrayCommand, _: &Origin, _: &mut ActArrayData) -> Status {
        Status::Unsupported
    }
    fn request(
        &mut self,
        _: &ActArrayRequest,
        _: &Origin,
        _: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        Err(Status::Unsupported)
    }
}

#[test]
fn a_lingering_driver_answers_each_request_on_its_first_poll() {
    let domain = Domain::unique_for_test();
    let ctx = Context::new(&domain, Role::Driver, "linger").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
    host.publish().unwrap();
    let wake = host.take_wake_listener().expect("the host's wake listener");
    // The client, in a thread of its own: one request after the other, each waiting for its
    // reply, and what each got sent back.
    let (tx, rx) = mpsc::channel();
    let client_domain = domain.clone();
    let client = std::thread::spawn(move || {
        let ctx = Context::new(&client_domain, Role::Client, "linger-client").unwrap();
        let mut arm = ActArrayClient::connect_timeout(&ctx, DEVICE, T).unwrap();
        arm.set_request_timeout(T);
        for _ in 0..REQUESTS {
            tx.send(arm.geometry()).unwrap();
        }
    });
    let mut handler = Refuse;
    for i in 0..REQUESTS {
        // The client notifies after sending: once the request event is here, the request
        // is waiting in the driver's queue.
        let deadline = Instant::now() + T;
        let mut requested = false;
        while !requested {
            let left = deadline.saturating_duration_since(Instant::now());
            assert!(!left.is_zero(), "request {i}: no wake-up from the client");
            wake.timed_wait(
                |e| requested |= e.id.as_value() == EVENT_REQUEST,
                left.min(Duration::from_millis(100)),
            )
            .unwrap();
        }
        let a = host.process_linger(&mut handler).unwrap();
        assert_eq!(
            a.requests, 1,
            "request {i}: not answered by the first poll of the linger"
        );
        let reply = rx.recv_timeout(T).expect("the client's reply");
        assert_eq!(reply, Err(RequestError::Nack(Status::Unsupported)));
    }
    client.join().unwrap();
}
