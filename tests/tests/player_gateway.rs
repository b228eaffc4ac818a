//! `limber player-gateway` (issue 29): a Player client written here from the protocol's
//! facts (tests/tests/player) talks to the gateway in front of the emulated Pioneer
//! (`limber pioneer --emulated`) over TCP: the banner, DEVLIST, DRIVERINFO, DEV, PULL and
//! PUSH, every command and request of actarray, limb and gripper, the capability query;
//! the simulated laser (limber's ranger) as Player's `laser:0`;
//! a lease taken through the gateway ends with its session; --read-only refuses; a
//! hostile client gets its session closed, never the gateway's.
//!
//! Each test has its own domain and its own gateway on a port the system picks; every
//! wait is bounded.

use std::f64::consts::FRAC_PI_2;
use std::io::Write;
use std::time::{Duration, Instant};

use limber_services::prelude::*;
use limber_tests::Proc;

mod player;
use player::*;

/// The CLI under test.
const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");

/// The driver and the gateway (ended before the domain, which then removes its files).
struct Setup {
    gateway: Proc,
    _driver: Proc,
    port: u16,
    domain: Domain,
}

fn setup(extra: &[&str]) -> Setup {
    let domain = Domain::unique_for_test();
    let mut driver = Proc::spawn(CLI, domain.name(), &["pioneer", "--emulated"]);
    assert!(
        driver.read_until(|l| l.ends_with("ready")).is_some(),
        "the driver did not start"
    );
    let mut args = vec!["player-gateway", "--listen", "127.0.0.1:0"];
    args.extend_from_slice(extra);
    let mut gateway = Proc::spawn(CLI, domain.name(), &args);
    let line = gateway
        .read_until(|l| l.contains("listening on"))
        .expect("the gateway listens");
    let port = line
        .rsplit(':')
        .next()
        .and_then(|p| p.split_whitespace().next())
        .and_then(|p| p.parse().ok())
        .expect("a port in the line");
    Setup {
        gateway,
        _driver: driver,
        port,
        domain,
    }
}

/// A Player client as libplayerc starts one: banner, then PULL.
fn libplayerc_like(port: u16) -> PlayerClient {
    let (mut c, banner) = PlayerClient::connect(port);
    assert!(banner.starts_with(b"Player v."), "{banner:?}");
    c.datamode(2);
    c
}

fn near(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() < tol
}

/// The "done when": a Player client lists the devices, subscribes in PULL and
/// PUSH, reads data, sends every command and request of the three interfaces, and sees
/// the arm, the limb and the grippers move.
#[test]
fn a_player_client_sees_and_moves_the_emulated_pioneer() {
    let s = setup(&[]);
    let mut c = libplayerc_like(s.port);
    // As playerprint does: a replace rule for data.
    c.ack(
        PLAYER,
        0,
        10,
        &Body::default().i32(-1).i32(-1).i32(1).i32(-1).i32(1).0,
    );

    // DEVLIST: every device, Player's addresses.
    let list = c.ack(PLAYER, 0, 1, &[]);
    let mut w = Words(&list, 0);
    let n = w.u32();
    assert_eq!(w.u32(), n, "the count twice");
    let mut addrs = Vec::new();
    for _ in 0..n {
        let (_host, robot, interf, index) = (w.u32(), w.u32(), w.u32(), w.u32());
        assert_eq!(robot, u32::from(s.port));
        addrs.push((interf, index));
    }
    for a in [
        (ACTARRAY, 0),
        (ACTARRAY, 1),
        (LIMB, 0),
        (GRIPPER, 0),
        (GRIPPER, 1),
    ] {
        assert!(addrs.contains(&a), "{a:?} not in {addrs:?}");
    }
    // DRIVERINFO, as playerv asks for each device.
    let info = c.ack(
        PLAYER,
        0,
        2,
        &Body::default()
            .u32(0)
            .u32(s.port.into())
            .u32(ACTARRAY)
            .u32(0)
            .count(0)
            .0,
    );
    assert_eq!(&info[24..31], b"pioneer");
    // The capability query on the server's own interface.
    c.ack(PLAYER, 0, 255, &Body::default().u32(REQ).u32(1).0);
    c.nack(PLAYER, 0, 255, &Body::default().u32(REQ).u32(9).0);

    // DEV: subscriptions; a device that does not exist is NACKed.
    for (i, x) in [(ACTARRAY, 0), (LIMB, 0), (GRIPPER, 0), (GRIPPER, 1)] {
        assert_eq!(c.subscribe(i, x).as_deref(), Some("pioneer"));
    }
    assert_eq!(c.subscribe(ACTARRAY, 9), None);

    // PULL: a round of data ends with a SYNCH and holds each subscribed device.
    c.pull_until(ACTARRAY, 0, "arm data", |b| {
        Words(b, 0).u32() == 6 && b.len() == 12 + 20 * 6
    });
    c.pull_until(LIMB, 0, "limb data", |b| b.len() == 76);
    c.pull_until(GRIPPER, 1, "arm gripper data", |b| b.len() == 12);

    // actarray requests: GET_GEOM, POWER, SPEED; BRAKES and ACCEL are NACKed by the
    // Pioneer (unsupported), each reply echoing the request's address and subtype.
    let geom = c.ack(ACTARRAY, 0, 3, &[]);
    assert_eq!(geom.len(), 56 + 80 * 6);
    assert_eq!(Words(&geom, 0).u32(), 6);
    assert_eq!(Words(&geom, 8).u32(), 2, "rotary");
    c.ack(ACTARRAY, 0, 1, &Body::default().u32(1).0);
    c.ack(ACTARRAY, 0, 4, &Body::default().i32(0).f32(1.0).0);
    c.nack(ACTARRAY, 0, 2, &Body::default().u32(1).0);
    c.nack(ACTARRAY, 0, 5, &Body::default().i32(0).f32(1.0).0);
    // Capability: POS yes, CURRENT not once the driver refused it (below), 99 never.
    c.ack(ACTARRAY, 0, 255, &Body::default().u32(CMD).u32(1).0);
    c.nack(ACTARRAY, 0, 255, &Body::default().u32(CMD).u32(99).0);
    c.nack(ACTARRAY, 0, 255, &Body::default().u32(REQ).u32(2).0);

    // actarray commands: POS moves joint 2.
    c.send(ACTARRAY, 0, CMD, 1, &Body::default().i32(2).f32(0.5).0);
    c.pull_until(ACTARRAY, 0, "joint 2 at 0.5", |b| {
        near(joint(b, 2).into(), 0.5, 0.02)
    });
    // MULTI_POS moves joints 0 and 1.
    c.send(
        ACTARRAY,
        0,
        CMD,
        2,
        &Body::default().count(2).f32(0.3).f32(-0.2).0,
    );
    c.pull_until(ACTARRAY, 0, "joints 0, 1 at 0.3, -0.2", |b| {
        near(joint(b, 0).into(), 0.3, 0.02) && near(joint(b, 1).into(), -0.2, 0.02)
    });
    // SPEED and MULTI_SPEED (0 stops), CURRENT and MULTI_CURRENT (unsupported: the
    // session goes on), then HOME all.
    c.send(ACTARRAY, 0, CMD, 3, &Body::default().i32(0).f32(0.0).0);
    c.send(ACTARRAY, 0, CMD, 4, &Body::default().count(1).f32(0.0).0);
    c.send(ACTARRAY, 0, CMD, 6, &Body::default().i32(0).f32(0.1).0);
    c.send(ACTARRAY, 0, CMD, 7, &Body::default().count(1).f32(0.1).0);
    c.send(ACTARRAY, 0, CMD, 5, &Body::default().i32(-1).0);
    let home: Vec<f32> = (0..6)
        .map(|j| {
            let a = 8 + 80 * j;
            Words(&geom, a + 4 + 4 + 24 + 24 + 4 * 3).f32()
        })
        .collect();
    c.pull_until(ACTARRAY, 0, "the arm at home", |b| {
        (0..5).all(|j| near(joint(b, j).into(), home[j].into(), 0.03))
    });
    // The driver refused CURRENT and MULTI_CURRENT as unsupported: the capability query
    // now says so.
    for sub in [6, 7] {
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            let m = c.request(ACTARRAY, 0, 255, &Body::default().u32(CMD).u32(sub).0);
            if m.mtype == NACK {
                break;
            }
            assert!(
                Instant::now() < deadline,
                "CMD {sub} still reported capable"
            );
            c.pull();
        }
    }

    // limb: GEOM, POWER, SPEED; BRAKES NACKed; SETPOSE, SETPOSITION, VECMOVE, STOP, HOME.
    let base = c.ack(LIMB, 0, 3, &[]);
    assert_eq!(base.len(), 24);
    c.ack(LIMB, 0, 1, &Body::default().u32(1).0);
    c.ack(LIMB, 0, 4, &Body::default().f32(0.1).0);
    c.nack(LIMB, 0, 2, &Body::default().u32(1).0);
    c.send(
        LIMB,
        0,
        CMD,
        3,
        &Body::default()
            .point([0.4, 0.0, 0.2])
            .point([0.0, 0.0, -1.0])
            .point([1.0, 0.0, 0.0])
            .0,
    );
    c.pull_until(LIMB, 0, "the limb at (0.4, 0, 0.2)", |b| {
        let p = limb_position(b);
        near(p[0], 0.4, 0.01) && near(p[1], 0.0, 0.01) && near(p[2], 0.2, 0.01)
    });
    c.send(LIMB, 0, CMD, 4, &Body::default().point([0.4, 0.05, 0.2]).0);
    c.pull_until(LIMB, 0, "the limb at (0.4, 0.05, 0.2)", |b| {
        let p = limb_position(b);
        near(p[0], 0.4, 0.01) && near(p[1], 0.05, 0.01) && near(p[2], 0.2, 0.01)
    });
    c.send(
        LIMB,
        0,
        CMD,
        5,
        &Body::default().point([0.0, 0.0, 1.0]).f32(0.03).0,
    );
    c.pull_until(LIMB, 0, "the limb 3 cm higher", |b| {
        near(limb_position(b)[2], 0.23, 0.01)
    });
    c.send(LIMB, 0, CMD, 2, &[]);
    c.send(LIMB, 0, CMD, 1, &[]);
    c.pull_until(ACTARRAY, 0, "the arm home again", |b| {
        (0..5).all(|j| near(joint(b, j).into(), home[j].into(), 0.03))
    });

    // gripper: GET_GEOM; the arm gripper and the body gripper open and close.
    assert_eq!(c.ack(GRIPPER, 1, 1, &[]).len(), 104);
    for index in [1, 0] {
        c.send(GRIPPER, index, CMD, 2, &[]);
        c.pull_until(GRIPPER, index, "closed", |b| gripper_state(b) == 2);
        c.send(GRIPPER, index, CMD, 1, &[]);
        c.pull_until(GRIPPER, index, "open", |b| gripper_state(b) == 1);
    }
    // STOP, STORE, RETRIEVE reach the driver (the last two unsupported).
    for sub in [3, 4, 5] {
        c.send(GRIPPER, 0, CMD, sub, &[]);
    }

    // PUSH: data comes without asking.
    c.datamode(1);
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut pushed = 0;
    while pushed < 3 {
        assert!(Instant::now() < deadline, "no pushed data");
        if c.read().mtype == DATA {
            pushed += 1;
        }
    }
    c.close(ACTARRAY, 0);
    drop(s);
}

/// A lease taken through the gateway (the boolean property `limber.lease`) is the
/// session's: other limber clients are refused while it holds it, and it ends with the
/// session.
#[test]
fn a_lease_taken_through_the_gateway_ends_with_its_session() {
    let mut s = setup(&[]);
    let ctx = Context::new(&s.domain, Role::Client, "lease-test").expect("join");
    let mut arm =
        ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", Duration::from_secs(10))
            .expect("the arm");
    arm.current(Duration::from_secs(10)).expect("a state");

    let mut c = libplayerc_like(s.port);
    assert!(c.subscribe(ACTARRAY, 0).is_some());
    let prop = |v: u32| {
        Body::default()
            .count(13)
            .0
            .into_iter()
            .chain(*b"limber.lease\0\0\0\0")
            .chain(v.to_be_bytes())
            .collect::<Vec<u8>>()
    };
    c.ack(ACTARRAY, 0, 247, &prop(1));
    let got = c.ack(ACTARRAY, 0, 248, &prop(0));
    assert_eq!(&got[got.len() - 4..], &[0, 0, 0, 1], "the session holds it");
    let holder = arm.holder().expect("the holder").expect("held");
    assert_eq!(holder.name, "player-session-1");
    let t = arm.move_to(2, 0.3).expect("send");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome"),
        Status::Leased
    );

    // The Player client goes away: its session ends, and the lease with it.
    c.stream
        .shutdown(std::net::Shutdown::Both)
        .expect("close the connection");
    drop(c);
    s.gateway
        .read_until(|l| l == "session 1 ended")
        .expect("the session ends");
    assert_eq!(arm.holder().expect("the holder"), None);
    let t = arm.move_to(2, 0.3).expect("send");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome"),
        Status::Ok
    );

    // The other way round: while a limber client holds the arm, a Player client's
    // changing request is NACKed and its command refused as LEASED (in the driver's state,
    // under the session's own client id).
    arm.acquire("tester", Duration::from_secs(5))
        .expect("the lease");
    let mut c = libplayerc_like(s.port);
    assert!(c.subscribe(ACTARRAY, 0).is_some());
    c.nack(ACTARRAY, 0, 1, &Body::default().u32(1).0);
    c.send(ACTARRAY, 0, CMD, 1, &Body::default().i32(2).f32(0.1).0);
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let st = arm.wait_state(Duration::from_secs(5)).expect("a state");
        let last = st.header.last_cmd;
        if last.client_id != arm.client_id() && last.kind == 1 {
            assert_eq!(last.status, Status::Leased.code());
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the Player command never reached the driver"
        );
        arm.renew().expect("renew");
    }
}

/// `--read-only`: states, the list and the geometry pass; commands, changing requests
/// and leases are refused (and the capability query says so).
#[test]
fn a_read_only_gateway_refuses_commands_and_changing_requests() {
    let s = setup(&["--read-only"]);
    let ctx = Context::new(&s.domain, Role::Client, "read-only-test").expect("join");
    let mut arm =
        ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", Duration::from_secs(10))
            .expect("the arm");
    let before = arm
        .current(Duration::from_secs(10))
        .expect("a state")
        .header
        .last_cmd;

    let mut c = libplayerc_like(s.port);
    assert!(c.subscribe(ACTARRAY, 0).is_some());
    c.pull_until(ACTARRAY, 0, "arm data", |b| b.len() == 12 + 20 * 6);
    assert_eq!(c.ack(ACTARRAY, 0, 3, &[]).len(), 56 + 80 * 6);
    c.nack(ACTARRAY, 0, 1, &Body::default().u32(1).0);
    c.nack(ACTARRAY, 0, 4, &Body::default().i32(0).f32(1.0).0);
    c.nack(ACTARRAY, 0, 255, &Body::default().u32(CMD).u32(1).0);
    c.ack(ACTARRAY, 0, 255, &Body::default().u32(REQ).u32(3).0);
    c.send(ACTARRAY, 0, CMD, 1, &Body::default().i32(2).f32(0.5).0);
    // The session handles its messages in order: once this reply is in, the command was
    // handled (and refused). Three new states later the driver still shows no command.
    c.ack(ACTARRAY, 0, 3, &[]);
    for _ in 0..3 {
        let st = arm.wait_state(Duration::from_secs(5)).expect("a state");
        assert_eq!(st.header.last_cmd, before, "a command reached the driver");
    }
}

/// Garbage from a client closes its session, never the gateway: a malformed body is
/// NACKed, an impossible header ends the session, and the next client is served.
#[test]
fn a_hostile_client_loses_its_session_and_the_gateway_serves_on() {
    let mut s = setup(&[]);
    let mut c = libplayerc_like(s.port);
    assert!(c.subscribe(ACTARRAY, 0).is_some());
    // A POWER request with a 2-byte body: NACKed; the session lives.
    c.nack(ACTARRAY, 0, 1, &[0, 1]);
    c.nack(ACTARRAY, 0, 1, &Body::default().u32(7).0);
    // A DEV request with a count larger than its body.
    c.nack(
        PLAYER,
        0,
        3,
        &Body::default()
            .u32(0)
            .u32(0)
            .u32(53)
            .u32(0)
            .u32(1)
            .count(1 << 30)
            .0,
    );
    c.ack(ACTARRAY, 0, 3, &[]);
    // A header announcing a body beyond Player's 8 MiB: the session is closed.
    let bad = Body::default()
        .u32(0)
        .u32(0)
        .u32(ACTARRAY)
        .u32(0)
        .u32(REQ)
        .u32(3)
        .f64(0.0)
        .u32(0)
        .u32(u32::MAX)
        .0;
    c.stream.write_all(&bad).expect("send garbage");
    let mut rest = Vec::new();
    match std::io::Read::read_to_end(&mut c.stream, &mut rest) {
        Ok(_) => {}
        Err(e) if e.kind() == std::io::ErrorKind::ConnectionReset => {}
        Err(e) => panic!("the gateway did not close the session: {e}"),
    }
    s.gateway
        .read_until(|l| l == "session 1 ended")
        .expect("the session ends");
    // The gateway serves the next client.
    let mut d = libplayerc_like(s.port);
    assert!(d.subscribe(GRIPPER, 1).is_some());
    d.pull_until(GRIPPER, 1, "gripper data", |b| b.len() == 12);
}

/// playerjoy's habit: the lift as `actarray:0` joint 0 (`--map`), normalised as Player's
/// p2os driver shows it, 0 down and 1 up; the arm then answers at `actarray:1`.
#[test]
fn the_lift_mapped_to_actarray_0_moves_from_0_down_to_1_up() {
    let s = setup(&["--map", "pioneer/actarray/1=actarray:0"]);
    let mut c = libplayerc_like(s.port);
    assert!(c.subscribe(ACTARRAY, 0).is_some());
    assert!(c.subscribe(ACTARRAY, 1).is_some());
    let geom = c.ack(ACTARRAY, 0, 3, &[]);
    assert_eq!(geom.len(), 56 + 80, "one actuator");
    let mut w = Words(&geom, 8);
    assert_eq!(w.u32(), 1, "linear");
    let mut w = Words(&geom, 8 + 4 + 4 + 24 + 24);
    assert_eq!(
        (w.f32(), w.f32(), w.f32()),
        (0.0, 0.5, 1.0),
        "min, centre, max"
    );
    assert_eq!(Words(&c.ack(ACTARRAY, 1, 3, &[]), 0).u32(), 6, "the arm");

    // As playerjoy: MoveTo(0, 0.0) down, MoveTo(0, 1.0) up.
    c.send(ACTARRAY, 0, CMD, 1, &Body::default().i32(0).f32(0.0).0);
    c.pull_until(ACTARRAY, 0, "the lift down", |b| {
        near(joint(b, 0).into(), 0.0, 0.02)
    });
    c.send(ACTARRAY, 0, CMD, 1, &Body::default().i32(0).f32(1.0).0);
    c.pull_until(ACTARRAY, 0, "the lift up", |b| {
        near(joint(b, 0).into(), 1.0, 0.02)
    });
}

/// simarm beside the Pioneer in one domain: its `simarm/actarray/0` collides with the
/// Pioneer's arm and lift and takes the lowest free index, `actarray:2`, with its driver's
/// name; two Player clients at once, one in PULL commanding it, one in PUSH watching it
/// move.
#[test]
fn two_player_clients_share_simarm_beside_the_pioneer() {
    let s = setup(&[]);
    let mut simarm = Proc::spawn(CLI, s.domain.name(), &["simarm"]);
    assert!(
        simarm.read_until(|l| l.ends_with("ready")).is_some(),
        "simarm did not start"
    );
    let mut a = libplayerc_like(s.port);
    let (mut b, _) = PlayerClient::connect(s.port);
    let info = a.ack(
        PLAYER,
        0,
        2,
        &Body::default()
            .u32(0)
            .u32(s.port.into())
            .u32(ACTARRAY)
            .u32(2)
            .count(0)
            .0,
    );
    assert_eq!(&info[24..30], b"simarm", "{info:?}");
    assert!(a.subscribe(ACTARRAY, 2).is_some());
    assert!(b.subscribe(ACTARRAY, 2).is_some());
    let n = Words(&a.ack(ACTARRAY, 2, 3, &[]), 0).u32();
    assert!(n >= 5, "{n} actuators");
    a.ack(ACTARRAY, 2, 1, &Body::default().u32(1).0);
    // -0.4: since simarm stops at the floor or an obstacle (COLLISION), joint 1 sent to
    // +0.4 stops near 0.12 in the default world.
    a.send(ACTARRAY, 2, CMD, 1, &Body::default().i32(1).f32(-0.4).0);
    // B reads in PUSH mode (the server's default): data comes without asking.
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let m = b.read();
        if m.mtype == DATA && m.index == 2 && near(joint(&m.body, 1).into(), -0.4, 0.02) {
            break;
        }
        assert!(Instant::now() < deadline, "B never saw joint 1 at -0.4");
    }
    a.pull_until(ACTARRAY, 2, "A sees joint 1 at -0.4", |b| {
        near(joint(b, 1).into(), -0.4, 0.02)
    });
}

/// limber's ranger as Player's laser: `laser:0` of the emulated Pioneer (its simulated
/// world has a block at (0.38, 0.10)) is listed and subscribed; its scans are Player's
/// SCAN bytes whose closest range is the block, with increasing ids; GET_GEOM and
/// GET_CONFIG answer; what limber cannot do (SET_CONFIG, POWER, GET_ID, SET_FILTER) is
/// NACKed, and the capability query says so.
#[test]
fn the_simulated_laser_is_players_laser_0() {
    let s = setup(&[]);
    let mut c = libplayerc_like(s.port);
    let list = c.ack(PLAYER, 0, 1, &[]);
    let n = Words(&list, 0).u32() as usize;
    let listed = (0..n).any(|i| {
        let mut w = Words(&list, 8 + 16 * i + 8);
        (w.u32(), w.u32()) == (LASER, 0)
    });
    assert!(listed, "laser:0 not in the device list");
    // The simulated laser is served by the world driver inside `limber pioneer --emulated`.
    assert_eq!(c.subscribe(LASER, 0).as_deref(), Some("world"));

    // A scan: 181 ranges over 180 degrees, 8 m; the closest is the block's near side.
    let body = c.pull_until(LASER, 0, "a scan of 181 ranges", |b| {
        Scan::read(b).is_some_and(|s| s.ranges.len() == 181)
    });
    let scan = Scan::read(&body).expect("a scan");
    assert!(near(scan.min_angle.into(), -FRAC_PI_2, 1e-4), "{scan:?}");
    assert!(near(scan.max_angle.into(), FRAC_PI_2, 1e-4), "{scan:?}");
    assert!(near(scan.resolution.into(), 1f64.to_radians(), 1e-5));
    assert_eq!(scan.max_range, 8.0);
    let (i, closest) = scan
        .ranges
        .iter()
        .copied()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("ranges");
    let expected = (0.38f64 - 0.16).hypot(0.10) - 0.02;
    assert!(
        near(closest.into(), expected, 0.015),
        "closest {closest} m, not {expected}"
    );
    // The block's direction: the middle of the beams that hit it (the closest beam alone
    // may be a neighbour, by the simulated 2 mm of noise).
    let hits: Vec<usize> = (0..scan.ranges.len())
        .filter(|j| scan.ranges[*j] < 0.5)
        .collect();
    assert!(hits.contains(&i), "{hits:?}");
    let middle = (hits[0] + hits[hits.len() - 1]) as f64 / 2.0;
    let bearing = f64::from(scan.min_angle) + f64::from(scan.resolution) * middle;
    assert!(
        near(bearing, 0.10f64.atan2(0.22), 0.03),
        "bearing {bearing}, beams {hits:?}: {:?}",
        &scan.ranges[hits[0]..=hits[hits.len() - 1]]
    );
    // The next scan has a greater id.
    let next = c.pull_until(LASER, 0, "the next scan", |b| {
        Scan::read(b).is_some_and(|s| s.id != scan.id)
    });
    assert!(Scan::read(&next).expect("a scan").id > scan.id);

    // GET_GEOM: the pose (0.16, 0, 0.20) and a size; GET_CONFIG: the scan's numbers.
    let geom = c.ack(LASER, 0, 1, &[]);
    assert_eq!(geom.len(), 72);
    let mut w = Words(&geom, 0);
    let pose: Vec<f64> = (0..6).map(|_| w.f64()).collect();
    assert_eq!(pose, [0.16, 0.0, 0.20, 0.0, 0.0, 0.0]);
    let size: Vec<f64> = (0..3).map(|_| w.f64()).collect();
    assert!(size.iter().all(|v| *v > 0.0), "size {size:?}");
    let config = c.ack(LASER, 0, 3, &[]);
    assert_eq!(config.len(), 28);
    let mut w = Words(&config, 0);
    let (min, max, res, range) = (w.f32(), w.f32(), w.f32(), w.f32());
    assert_eq!(
        (min, max, res, range),
        (scan.min_angle, scan.max_angle, scan.resolution, 8.0)
    );
    let (_range_res, intensity, frequency) = (w.f32(), w.u32(), w.f32());
    assert_eq!((intensity, frequency), (0, 10.0));

    // What limber cannot do is NACKed, and the capability query says so.
    c.nack(LASER, 0, 2, &config);
    c.nack(LASER, 0, 4, &Body::default().u32(1).0);
    c.nack(LASER, 0, 5, &[]);
    c.nack(LASER, 0, 6, &Body::default().u32(1).count(0).0);
    for sub in [1, 3] {
        c.ack(LASER, 0, 255, &Body::default().u32(REQ).u32(sub).0);
    }
    for sub in [2, 4, 5, 6] {
        c.nack(LASER, 0, 255, &Body::default().u32(REQ).u32(sub).0);
    }
    c.nack(LASER, 0, 255, &Body::default().u32(CMD).u32(1).0);
    c.close(LASER, 0);
    drop(s);
}
