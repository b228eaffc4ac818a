//! A test client process. Modes:
//! * `burst N`: send N position commands to `<robot>/actarray/0` as fast as possible;
//! * `basic`: geometry, power, a move with its outcome, the state; prints `ok`;
//! * `hold-request`: send a geometry request and wait (to be killed mid-request);
//! * `flood N`: send N position commands, joint `i % 8` of a 6-joint arm (so a quarter are
//!   refused), then a request as a barrier; prints `sent N`;
//! * `hold-samples`: borrow as many state samples as the service lets a subscriber hold,
//!   print `holding K`, and keep them (to be killed or stopped).
//! * `own`: power on, take the arm's lease as `--name` with a heartbeat of
//!   `--heartbeat-ms`, move joint 0 at 0.1 rad/s, print `owning <client id>`, then renew
//!   the lease (unless `--no-renew`) until killed or stdin closes.

use std::time::Duration;

use clap::Parser;
use limber_services::prelude::*;

#[derive(Parser)]
struct Args {
    /// Robot name.
    #[arg(long, default_value = "test")]
    robot: String,
    /// What to do.
    mode: String,
    /// Count for `burst`.
    #[arg(default_value_t = 64)]
    n: u64,
    /// `own`: the holder's name.
    #[arg(long, default_value = "test-holder")]
    name: String,
    /// `own`: the lease's heartbeat timeout, ms.
    #[arg(long, default_value_t = 1000)]
    heartbeat_ms: u64,
    /// `own`: never renew the lease (to miss the heartbeat).
    #[arg(long)]
    no_renew: bool,
}

fn main() {
    let a = Args::parse();
    let ctx = Context::client_from_env().expect("join domain");
    let dev = format!("{}/actarray/0", a.robot);
    let mut arm =
        ActArrayClient::connect_timeout(&ctx, &dev, Duration::from_secs(5)).expect("connect");
    match a.mode.as_str() {
        "burst" => {
            for i in 0..a.n {
                arm.move_to((i % 6) as usize, (i as f64) * 1e-3)
                    .expect("send");
            }
            // Stay until the driver has applied every one: it drains a client's commands
            // before answering its requests, so a reply is a barrier. (The last outcome
            // itself may be overwritten by the other client's outcomes before it is read.)
            arm.geometry().expect("barrier request");
            println!("sent {}", a.n);
        }
        "basic" => {
            let g = arm.geometry().expect("geometry");
            assert_eq!(g.actuators_count, 6);
            arm.power(true).expect("power");
            let t = arm.move_to(1, 0.25).expect("move");
            assert_eq!(
                arm.wait_outcome(t, Duration::from_secs(5))
                    .expect("outcome"),
                Status::Ok
            );
            let s = arm.wait_state(Duration::from_secs(5)).expect("state");
            assert_eq!(s.actuators[1].position, 0.25);
            println!("ok");
        }
        "flood" => {
            for i in 0..a.n {
                arm.move_to((i % 8) as usize, (i as f64) * 1e-4)
                    .expect("send");
            }
            arm.geometry().expect("barrier request");
            println!("sent {}", a.n);
        }
        "hold-samples" => {
            let dev: DeviceName = dev.parse().expect("device name");
            let sub = ctx
                .node()
                .service_builder(&dev.service_name(limber_services::Channel::Data))
                .publish_subscribe::<ActArrayData>()
                .open()
                .expect("open the state service")
                .subscriber_builder()
                .create()
                .expect("subscriber");
            let mut held = Vec::new();
            let deadline = std::time::Instant::now() + Duration::from_secs(10);
            while held.len() < limber_services::qos::DATA_BORROWED {
                assert!(std::time::Instant::now() < deadline, "no state samples");
                match sub.receive().expect("receive") {
                    Some(s) => held.push(s),
                    None => std::thread::sleep(Duration::from_millis(5)),
                }
            }
            println!("holding {}", held.len());
            loop {
                std::thread::sleep(Duration::from_secs(1));
            }
        }
        "hold-request" => {
            println!("requesting");
            let _ = arm.request_with_timeout(&ActArrayRequest::GetGeom, Duration::from_secs(60));
        }
        "own" => {
            arm.power(true).expect("power");
            arm.acquire(&a.name, Duration::from_millis(a.heartbeat_ms))
                .expect("acquire");
            let t = arm.move_at_speed(0, 0.1).expect("move");
            let st = arm
                .wait_outcome(t, Duration::from_secs(5))
                .expect("outcome");
            assert!(st.is_carried_out(), "{st}");
            println!("owning {}", arm.client_id());
            // Until stdin closes (the test gone) or the process is killed.
            let (tx, rx) = std::sync::mpsc::channel::<()>();
            std::thread::spawn(move || {
                let mut s = String::new();
                let _ = std::io::stdin().read_line(&mut s);
                let _ = tx.send(());
            });
            while rx.try_recv().is_err() {
                if !a.no_renew {
                    arm.keep_lease().expect("renew");
                }
                std::thread::sleep(Duration::from_millis(10));
            }
        }
        m => panic!("unknown mode {m}"),
    }
}
