//! The linger of an event-driven driver (`DeviceHost::process_linger`) answers a client's
//! request on its first poll, where the spinning poll (`process_spin`) looks for requests
//! only on every `SPIN_REQUEST_EVERY`th call.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, mpsc};
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
    // reply, and what each got sent back; `sent` counts the requests sent.
    let (tx, rx) = mpsc::channel();
    let sent = Arc::new(AtomicUsize::new(0));
    let (client_domain, client_sent) = (domain.clone(), Arc::clone(&sent));
    let client = std::thread::spawn(move || {
        let ctx = Context::new(&client_domain, Role::Client, "linger-client").unwrap();
        let mut arm = ActArrayClient::connect_timeout(&ctx, DEVICE, T).unwrap();
        arm.set_request_timeout(T);
        for _ in 0..REQUESTS {
            client_sent.fetch_add(1, Ordering::SeqCst);
            tx.send(arm.geometry()).unwrap();
        }
    });
    let mut handler = Refuse;
    let mut answered = 0;
    let deadline = Instant::now() + T * 4;
    while answered < REQUESTS {
        // The client notifies after sending: once a request event is here, every request
        // the client has sent is waiting in the driver's queue (or was answered), and it
        // sends no other before its reply.
        let mut requested = false;
        while !requested {
            let left = deadline.saturating_duration_since(Instant::now());
            assert!(
                !left.is_zero(),
                "after {answered} replies: no wake-up from the client"
            );
            wake.timed_wait(
                |e| requested |= e.id.as_value() == EVENT_REQUEST,
                left.min(Duration::from_millis(100)),
            )
            .unwrap();
        }
        let waiting = sent.load(Ordering::SeqCst);
        answered += host.process_linger(&mut handler).unwrap().requests;
        // The first poll answers them all (one poll may also find the client's next one,
        // sent on the other core as soon as its reply came).
        assert!(
            answered >= waiting,
            "request {waiting}: not answered by the first poll of the linger ({answered} answered)"
        );
    }
    for _ in 0..REQUESTS {
        let reply = rx.recv_timeout(T).expect("the client's reply");
        assert_eq!(reply, Err(RequestError::Nack(Status::Unsupported)));
    }
    client.join().unwrap();
}
