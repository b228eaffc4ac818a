//! How a driver's polls answer: the linger of an event-driven driver
//! (`DeviceHost::process_linger`) answers a client's request on its first poll, where the
//! spinning poll (`process_spin`) looks for requests only on every `SPIN_REQUEST_EVERY`th
//! call; the spinning poll spreads the looks that commands do not need over its calls,
//! one look a call, each still once every `SPIN_REQUEST_EVERY` calls: a request and a
//! lease operation are answered, a command's outcome is sent, within that many polls of
//! their arrival.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use limber_services::host::SPIN_REQUEST_EVERY;
use limber_services::prelude::*;
use limber_services::qos::{EVENT_COMMAND, EVENT_REQUEST};

const T: Duration = Duration::from_secs(5);
const DEVICE: &str = "linger/actarray/0";
const REQUESTS: usize = 40;
const SPIN_DEVICE: &str = "spinlooks/actarray/0";
const ROUNDS: usize = 20;

/// Refuses every command and request: a NACK is a reply like any other, and UNSUPPORTED
/// an outcome like any other.
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

/// What the client did last, for the failure message (of the spinning test).
type Doing = Arc<Mutex<&'static str>>;

#[test]
fn a_spinning_host_answers_requests_leases_and_commands_within_its_look_period() {
    let domain = Domain::unique_for_test();
    let ctx = Context::new(&domain, Role::Driver, "spinlooks").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&ctx, &SPIN_DEVICE.parse().unwrap(), "t").unwrap();
    host.state_mut().actuators_count = 2;
    host.publish().unwrap();
    let wake = host.take_wake_listener().expect("the host's wake listener");
    // The client, in a thread of its own: a request, a lease acquired and released, and a
    // command, each waited for before the next, round after round.
    let (tx, rx) = mpsc::channel();
    let doing: Doing = Arc::new(Mutex::new("connecting"));
    let (client_domain, client_doing) = (domain.clone(), Arc::clone(&doing));
    let client = std::thread::spawn(move || {
        let ctx = Context::new(&client_domain, Role::Client, "spinlooks-client").unwrap();
        let mut arm = ActArrayClient::connect_timeout(&ctx, SPIN_DEVICE, T).unwrap();
        arm.set_request_timeout(T);
        for _ in 0..ROUNDS {
            *client_doing.lock().unwrap() = "a request";
            let reply = arm.geometry();
            *client_doing.lock().unwrap() = "a lease acquired";
            let acquired = arm.acquire("spinlooks", Duration::from_secs(2));
            *client_doing.lock().unwrap() = "a lease released";
            let released = arm.release();
            *client_doing.lock().unwrap() = "a command";
            let outcome = arm
                .move_to(0, 0.1)
                .map_err(|e| e.to_string())
                .and_then(|t| arm.wait_outcome(t, T).map_err(|e| e.to_string()));
            tx.send((reply, acquired.is_ok(), released.is_ok(), outcome))
                .unwrap();
        }
        *client_doing.lock().unwrap() = "done";
    });
    let mut handler = Refuse;
    let deadline = Instant::now() + T * 4;
    // The wake-ups of requests, lease operations and commands taken so far, and the ones
    // of them served. The client sends each before it notifies, and sends the next only
    // when the last was answered: when the wake-ups outnumber what was served, the latest
    // one is pending now, and must be served within one look period. (A wake-up of one
    // that an earlier period served already asks nothing; a client's hello gets the same
    // polls, unchecked.)
    let (mut woken, mut served) = (0usize, 0usize);
    while !client.is_finished() {
        let mut any = false;
        while !any && !client.is_finished() {
            let left = deadline.saturating_duration_since(Instant::now());
            assert!(
                !left.is_zero(),
                "no wake-up from the client ({})",
                doing.lock().unwrap()
            );
            wake.timed_wait(
                |e| {
                    let id = e.id.as_value();
                    any = true;
                    woken += usize::from(id == EVENT_REQUEST || id == EVENT_COMMAND);
                },
                left.min(Duration::from_millis(100)),
            )
            .unwrap();
        }
        let pending = woken > served;
        for _ in 0..SPIN_REQUEST_EVERY {
            let a = host.process_spin(&mut handler).unwrap();
            served += a.requests + a.commands;
        }
        assert!(
            !pending || served >= woken,
            "{}: not served within {SPIN_REQUEST_EVERY} spinning polls",
            doing.lock().unwrap()
        );
    }
    client.join().unwrap();
    let mut rounds = 0;
    while let Ok((reply, acquired, released, outcome)) = rx.try_recv() {
        assert_eq!(reply, Err(RequestError::Nack(Status::Unsupported)));
        assert!(acquired && released, "the lease operations failed");
        assert_eq!(outcome, Ok(Status::Unsupported));
        rounds += 1;
    }
    assert_eq!(rounds, ROUNDS);
    assert!(served >= ROUNDS * 4, "{served} served");
}
