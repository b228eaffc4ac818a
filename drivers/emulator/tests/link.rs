//! The link and connection state machine against the emulator, over a pty
//! and over TCP: handshake, calibration, arm joints, gripper, lift, faults.

use limber_emulator::{
    Emulator, EmulatorConfig, EmulatorState, Faults, ObjectPlacement, SyncStage, Timing,
    default_arm_info,
};
use limber_p2os::*;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

const WAIT: Duration = Duration::from_secs(5);

/// Fast mode (immediate replies, extra ARMpacs) and a 20 ms cycle: these
/// tests are about the protocol, not the controller's timing.
fn fast_config() -> EmulatorConfig {
    let mut c = EmulatorConfig {
        cycle: Duration::from_millis(20),
        ..EmulatorConfig::fast()
    };
    c.model.lift_stroke = Duration::from_millis(300);
    c.model.paddle_stroke = Duration::from_millis(150);
    c
}

fn opts() -> ConnectOptions {
    ConnectOptions {
        sync_attempts: 3,
        sync_timeout: Duration::from_millis(300),
        close_wait: Duration::from_millis(50),
        first_sip_timeout: Duration::from_secs(2),
        arm_info_timeout: Duration::from_millis(500),
        pulse_interval: Duration::from_millis(200),
        ..ConnectOptions::default()
    }
}

fn localhost0() -> SocketAddr {
    "127.0.0.1:0".parse().unwrap()
}

#[derive(Clone, Copy, Debug)]
enum Wire {
    Pty,
    Tcp,
}

fn start(wire: Wire, cfg: EmulatorConfig) -> Emulator {
    match wire {
        Wire::Pty => Emulator::start_pty(cfg).unwrap(),
        Wire::Tcp => Emulator::start_tcp(cfg, localhost0()).unwrap(),
    }
}

fn connect(emu: &Emulator) -> Connection {
    Connection::open(&emu.link_target(), &opts()).unwrap()
}

fn j(n: u8) -> ArmJoint {
    ArmJoint::new(n).unwrap()
}

fn emu_wait(emu: &Emulator, what: &str, pred: impl FnMut(&EmulatorState) -> bool) -> EmulatorState {
    let (ok, s) = emu.wait_for(WAIT, pred);
    assert!(ok, "emulator never reached: {what}; last state {s:?}");
    s
}

fn wait_sip(c: &mut Connection, what: &str, mut pred: impl FnMut(&Sip) -> bool) {
    let r = c.wait_until(WAIT, |p| matches!(p, RobotPacket::Sip(s) if pred(s)));
    assert!(
        r.is_ok(),
        "no SIP with {what}: {r:?}; last {:?}",
        c.last_sip()
    );
}

fn wait_arm(c: &mut Connection, what: &str, mut pred: impl FnMut(&ArmPacket) -> bool) {
    let r = c.wait_until(WAIT, |p| matches!(p, RobotPacket::Arm(a) if pred(a)));
    assert!(
        r.is_ok(),
        "no ARMpac with {what}: {r:?}; last {:?}",
        c.last_arm()
    );
}

/// The status in the manuals' layout (the emulator's default).
fn st(a: &ArmPacket) -> ArmStatus {
    a.status(ArmpacLayout::Manual)
}

fn full_session(wire: Wire) {
    let emu = start(wire, fast_config());
    let mut c = connect(&emu);
    assert_eq!(c.identity().name, "limber-emulator");
    assert_eq!(c.identity().class, "Pioneer");
    assert_eq!(c.identity().subclass, "p3dx");
    match wire {
        Wire::Pty => assert_eq!(c.baud_rate(), Some(9600)),
        Wire::Tcp => assert_eq!(c.baud_rate(), None),
    }
    assert_eq!(emu.state().robot.stage, SyncStage::Open);
    assert!(!emu.state().robot.sonar, "sonar switched off at set-up");

    // Calibration from ARMINFOpac.
    let cal = *c.arm_calibration().expect("the emulator has an arm");
    assert_eq!(*cal.info(), default_arm_info());
    assert_eq!(cal.num_joints(), 6);
    assert_eq!(emu.state().robot.arm_status_mode, 2, "continuous ARMpac");

    // Power, speed up, and move every joint (including the gripper).
    c.send(&Command::ArmPower(true)).unwrap();
    wait_arm(&mut c, "power", |a| st(a).powered && st(a).connected);
    for joint in ArmJoint::all() {
        c.send(&Command::ArmSpeed {
            joint,
            ms_per_step: 1,
        })
        .unwrap();
    }
    emu_wait(&emu, "speeds set", |s| s.robot.ms_per_step == [1; 6]);
    for joint in ArmJoint::all() {
        let jc = *cal.joint(joint).unwrap();
        let now = emu.state().robot.servo_ticks[joint.index()];
        let target = if now > jc.centre {
            jc.min + 5
        } else {
            jc.max - 5
        };
        // Through the calibration: the angle of the target tick maps back.
        let rad = cal.ticks_to_radians(joint, target).unwrap();
        let tick = cal.radians_to_ticks(joint, rad).unwrap();
        assert!(!tick.clamped);
        c.send(&Command::ArmPos {
            joint,
            tick: tick.tick,
        })
        .unwrap();
        wait_arm(&mut c, &format!("{joint:?} at {target}"), |a| {
            a.tick(joint) == target && !st(a).joint_moving(joint)
        });
        assert_eq!(emu.state().robot.servo_ticks[joint.index()], target);
    }

    // Home all (vendor's 0xFF): every joint back at its home tick.
    c.send(&Command::ArmHome(JointSelection::All)).unwrap();
    let homes: Vec<u8> = cal.info().calibrations().iter().map(|k| k.home).collect();
    wait_arm(&mut c, "home", |a| {
        a.ticks.to_vec() == homes && st(a).moving_mask() == 0
    });

    // Stop: a slow move stopped half way stays where it stopped.
    c.send(&Command::ArmSpeed {
        joint: j(1),
        ms_per_step: 50,
    })
    .unwrap();
    c.send(&Command::ArmPos {
        joint: j(1),
        tick: 228,
    })
    .unwrap();
    wait_arm(&mut c, "joint 1 moving", |a| st(a).joint_moving(j(1)));
    c.send(&Command::ArmStop(JointSelection::All)).unwrap();
    wait_arm(&mut c, "joint 1 stopped", |a| !st(a).joint_moving(j(1)));
    let st = emu.state().robot;
    assert!(st.servo_ticks[0] < 228);
    assert_eq!(st.servo_ticks[0], st.servo_targets[0]);

    // Gripper: open, object in, close on it (breakbeams), lift up and down.
    c.send(&Command::Gripper(GripperCommand::Open)).unwrap();
    wait_sip(&mut c, "paddles open", |s| {
        s.gripper_reading(GripperByteLayout::Manual).paddles == PaddleState::Open
    });
    emu.set_object(Some(ObjectPlacement::Inner));
    wait_sip(&mut c, "both beams broken", |s| {
        let g = s.gripper_reading(GripperByteLayout::Manual);
        g.outer_beam && g.inner_beam
    });
    c.send(&Command::Gripper(GripperCommand::Close)).unwrap();
    wait_sip(&mut c, "closed on the object", |s| {
        s.gripper_reading(GripperByteLayout::Manual).paddles == PaddleState::Closed
    });
    assert!(emu.state().robot.object_in_gripper);
    c.send(&Command::Gripper(GripperCommand::LiftUp)).unwrap();
    wait_sip(&mut c, "lift moving", |s| {
        s.gripper_reading(GripperByteLayout::Manual).lift == LiftState::Moving
    });
    wait_sip(&mut c, "lift up", |s| {
        s.gripper_reading(GripperByteLayout::Manual).lift == LiftState::Up
    });
    let st = emu.state().robot;
    assert!(st.lift >= 1.0 && st.object_in_gripper);
    assert!(
        c.last_sip()
            .unwrap()
            .gripper_reading(GripperByteLayout::Manual)
            .inner_beam,
        "carried object still in the beams"
    );
    c.send(&Command::Gripper(GripperCommand::LiftDown)).unwrap();
    wait_sip(&mut c, "lift moving down", |s| {
        s.gripper_reading(GripperByteLayout::Manual).lift == LiftState::Moving
    });
    wait_sip(&mut c, "lift down", |s| {
        s.gripper_reading(GripperByteLayout::Manual).lift == LiftState::Down
    });
    assert!(emu.state().robot.lift <= 0.0);
    c.send(&Command::Gripper(GripperCommand::Open)).unwrap();
    wait_sip(&mut c, "released", |s| {
        s.gripper_reading(GripperByteLayout::Manual).paddles == PaddleState::Open
    });
    assert!(!emu.state().robot.object_in_gripper);
    emu.set_object(None);
    wait_sip(&mut c, "beams clear", |s| {
        let g = s.gripper_reading(GripperByteLayout::Manual);
        !g.outer_beam && !g.inner_beam
    });
    c.send(&Command::Gripper(GripperCommand::Close)).unwrap();
    wait_sip(&mut c, "closed empty", |s| {
        s.gripper_reading(GripperByteLayout::Manual).paddles == PaddleState::Closed
    });
    assert!(emu.state().robot.paddles <= 0.0);

    // Lift relative move (LIFTcarry + GRIPPERVAL), up then down (ARGNINT).
    let stroke_units = (0.3f64 / 0.02) as i16; // the test stroke is 300 ms
    c.send(&Command::Gripper(GripperCommand::LiftCarry))
        .unwrap();
    c.send(&Command::GripperValue(stroke_units / 2)).unwrap();
    let s = emu_wait(&emu, "lift half way", |s| {
        !s.robot.lift_moving && s.robot.lift > 0.0
    });
    let expected = f64::from(stroke_units / 2) * 0.02 / 0.3;
    assert!((s.robot.lift - expected).abs() < 1e-6, "{}", s.robot.lift);
    c.send(&Command::Gripper(GripperCommand::LiftCarry))
        .unwrap();
    c.send(&Command::GripperValue(-stroke_units)).unwrap();
    emu_wait(&emu, "lift down again", |s| {
        !s.robot.lift_moving && s.robot.lift <= 0.0
    });

    let stats = c.link().stats();
    assert!(stats.decoder.packets_ok > 10);
    assert_eq!(stats.decoder.bad_checksums, 0);
    assert!(stats.bytes_out > 0 && stats.packets_out > 0);
    c.close().unwrap();
    emu_wait(&emu, "back to NO_SYNC after CLOSE", |s| {
        s.robot.stage == SyncStage::NoSync
    });
    emu.stop().unwrap();
}

#[test]
fn full_session_over_pty() {
    full_session(Wire::Pty);
}

#[test]
fn full_session_over_tcp() {
    full_session(Wire::Tcp);
}

#[test]
fn arm_packets_are_prompt_not_only_per_cycle() {
    // A 30 s cycle: after the first SIP nothing periodic arrives during the
    // test, so every ARMpac seen here was sent because of a command or a
    // motion change.
    let mut cfg = fast_config();
    cfg.cycle = Duration::from_secs(30);
    let emu = start(Wire::Tcp, cfg);
    let mut c = connect(&emu);
    assert!(c.arm_calibration().is_some());
    c.send(&Command::ArmPower(true)).unwrap();
    wait_arm(&mut c, "powered", |a| st(a).powered);
    c.send(&Command::ArmSpeed {
        joint: j(4),
        ms_per_step: 1,
    })
    .unwrap();
    c.send(&Command::ArmPos {
        joint: j(4),
        tick: 100,
    })
    .unwrap();
    wait_arm(&mut c, "moving", |a| st(a).joint_moving(j(4)));
    wait_arm(&mut c, "arrived", |a| {
        a.tick(j(4)) == 100 && st(a).moving_mask() == 0
    });
    assert_eq!(emu.state().stats.sips_out, 1);
    // ARM_STATUS 1 = one ARMpac on demand.
    c.send(&Command::ArmStatus(ArmStatusMode::Stop)).unwrap();
    c.send(&Command::ArmStatus(ArmStatusMode::Once)).unwrap();
    wait_arm(&mut c, "single ARMpac", |a| a.tick(j(4)) == 100);
}

#[test]
fn robot_without_arm_means_no_arm_not_a_hang() {
    let mut cfg = fast_config();
    cfg.model.arm = None;
    for wire in [Wire::Pty, Wire::Tcp] {
        let emu = start(wire, cfg.clone());
        let mut c = connect(&emu);
        assert!(c.arm_calibration().is_none());
        assert!(
            c.request_arm_info(Duration::from_millis(100))
                .unwrap()
                .is_none()
        );
        // SIPs keep coming.
        wait_sip(&mut c, "a SIP", |_| true);
        c.close().unwrap();
    }
}

#[test]
fn silent_robot_is_an_error_not_a_hang() {
    for wire in [Wire::Pty, Wire::Tcp] {
        let mut cfg = fast_config();
        cfg.faults.silent = true;
        let emu = start(wire, cfg);
        let mut o = opts();
        o.sync_attempts = 2;
        o.sync_timeout = Duration::from_millis(50);
        o.baud_rates = vec![9600, 38400];
        let err = Connection::open(&emu.link_target(), &o).unwrap_err();
        match (wire, err) {
            (Wire::Pty, e @ ConnectError::NoSync { .. }) => {
                assert_eq!(
                    e.to_string(),
                    "no sync reply after 4 attempts at baud rates [9600, 38400]"
                );
                let ConnectError::NoSync { attempts, bauds } = e else {
                    unreachable!()
                };
                assert_eq!(attempts, 4);
                assert_eq!(bauds, vec![9600, 38400]);
            }
            (Wire::Tcp, e @ ConnectError::NoSync { .. }) => {
                // Issue 13 item 5: no baud rates over TCP, in the message either.
                assert_eq!(e.to_string(), "no sync reply after 2 attempts");
                let ConnectError::NoSync { attempts, bauds } = e else {
                    unreachable!()
                };
                assert_eq!(attempts, 2);
                assert!(bauds.is_empty());
            }
            (_, e) => panic!("unexpected {e:?}"),
        }

        // Going silent after the handshake: receive times out.
        emu.set_faults(Faults::default());
        let mut c = connect(&emu);
        emu.set_faults(Faults {
            silent: true,
            ..Faults::default()
        });
        // Drain what was in flight, then nothing more arrives.
        let mut timed_out = false;
        for _ in 0..100 {
            match c.recv(Duration::from_millis(150)) {
                Ok(_) => {}
                Err(LinkError::Timeout(_)) => {
                    timed_out = true;
                    break;
                }
                Err(e) => panic!("{e:?}"),
            }
        }
        assert!(timed_out, "{wire:?}: a silent robot must time out");
    }
}

#[test]
fn sync_walks_the_baud_rates_in_order() {
    let mut cfg = fast_config();
    cfg.baud = Some(115200);
    let emu = start(Wire::Pty, cfg);
    let mut o = opts();
    o.sync_attempts = 2;
    o.sync_timeout = Duration::from_millis(60);
    let c = Connection::open(&emu.link_target(), &o).unwrap();
    assert_eq!(c.baud_rate(), Some(115200));
    assert_eq!(c.link().baud_rate(), Some(115200));
    // It was asked at the earlier rates (9600, 38400, 19200) and ignored them.
    assert!(emu.state().stats.wrong_baud_bytes >= 3 * 2 * 6);

    // A robot at a rate not in the list: no sync.
    let mut cfg = fast_config();
    cfg.baud = Some(57600);
    let emu = start(Wire::Pty, cfg);
    o.baud_rates = vec![9600, 19200];
    assert!(matches!(
        Connection::open(&emu.link_target(), &o),
        Err(ConnectError::NoSync { attempts: 4, .. })
    ));
}

#[test]
fn disconnect_is_reported() {
    for wire in [Wire::Pty, Wire::Tcp] {
        let emu = start(wire, fast_config());
        let mut c = connect(&emu);
        emu.disconnect();
        let mut outcome = None;
        for _ in 0..200 {
            match c.recv(Duration::from_millis(100)) {
                Ok(_) => {}
                Err(e) => {
                    outcome = Some(e);
                    break;
                }
            }
        }
        match outcome {
            Some(LinkError::Closed) | Some(LinkError::Io(_)) => {}
            other => panic!("{wire:?}: expected a closed link, got {other:?}"),
        }
        // Over TCP the emulator accepts a new client afterwards.
        if let Wire::Tcp = wire {
            let c2 = connect(&emu);
            assert_eq!(c2.identity().class, "Pioneer");
            assert_eq!(emu.state().stats.connections, 2);
        }
    }
}

#[test]
fn bad_checksums_are_dropped_and_counted() {
    for wire in [Wire::Pty, Wire::Tcp] {
        let emu = start(wire, fast_config());
        let mut c = connect(&emu);
        emu.set_faults(Faults {
            bad_checksum_rate: 0.5,
            ..Faults::default()
        });
        emu_wait(&emu, "bad checksums sent", |s| {
            s.stats.bad_checksums_out >= 5
        });
        // Good packets still get through; the bad ones are counted.
        let mut sips = 0;
        for _ in 0..10_000 {
            if c.link().stats().decoder.bad_checksums >= 5 {
                break;
            }
            if let Ok(RobotPacket::Sip(_)) = c.recv(WAIT) {
                sips += 1;
            }
        }
        assert!(c.link().stats().decoder.bad_checksums >= 5);
        assert!(sips > 0);
        emu.set_faults(Faults::default());
        wait_sip(&mut c, "clean SIP", |_| true);

        // And the robot side drops our bad checksums silently.
        let mut f = Command::ArmPower(true).encode().unwrap();
        f.corrupt_checksum();
        c.link_mut().send_frame(&f).unwrap();
        emu_wait(&emu, "command dropped", |s| s.stats.bad_checksums_in == 1);
        assert!(!emu.state().robot.arm_powered);
    }
}

#[test]
fn corrupted_dropped_and_garbage_bytes_are_survived() {
    for wire in [Wire::Pty, Wire::Tcp] {
        let emu = start(wire, fast_config());
        let mut c = connect(&emu);
        emu.set_faults(Faults {
            drop_rate: 0.01,
            corrupt_rate: 0.01,
            garbage_rate: 0.3,
            ..Faults::default()
        });
        emu_wait(&emu, "faults injected", |s| {
            s.stats.bytes_dropped > 3 && s.stats.bytes_corrupted > 3 && s.stats.garbage_out > 20
        });
        let before = c.link().stats().decoder;
        // Keep receiving while the faults go on: packets still arrive.
        let mut n = 0;
        while n < 20 {
            c.recv(WAIT).unwrap();
            n += 1;
        }
        let after = c.link().stats().decoder;
        assert!(after.packets_ok >= before.packets_ok + 20);
        assert!(after.garbage_bytes > before.garbage_bytes, "{after:?}");
        assert!(after.resyncs > before.resyncs);
        emu.set_faults(Faults::default());
        // Still usable: a command round trip.
        c.send(&Command::ArmPower(true)).unwrap();
        wait_arm(&mut c, "power after faults", |a| st(a).powered);
    }
}

#[test]
fn slow_wire_still_works() {
    for wire in [Wire::Pty, Wire::Tcp] {
        let mut cfg = fast_config();
        cfg.cycle = Duration::from_millis(50);
        cfg.faults.slow_wire_baud = Some(38400);
        let emu = start(wire, cfg);
        let mut c = connect(&emu);
        c.send(&Command::ArmPower(true)).unwrap();
        wait_arm(&mut c, "powered over a slow wire", |a| st(a).powered);
        assert!(emu.state().stats.bytes_out > 0);
    }
}

#[test]
fn a_robot_still_running_gets_one_close_then_syncs() {
    let emu = start(Wire::Pty, fast_config());
    let c = connect(&emu);
    // The client vanishes without CLOSE: the robot keeps streaming.
    drop(c);
    emu_wait(&emu, "still streaming", |s| {
        s.robot.stage == SyncStage::Open
    });
    let sips = emu.state().stats.sips_out;
    emu_wait(&emu, "more SIPs", |s| s.stats.sips_out > sips + 2);
    // A new connection sees SIPs instead of a sync reply, sends CLOSE once,
    // and syncs.
    let c = connect(&emu);
    assert_eq!(c.identity().name, "limber-emulator");
    assert_eq!(emu.state().robot.stage, SyncStage::Open);
    c.close().unwrap();
}

#[test]
fn tcp_close_drops_the_connection_and_reconnect_works() {
    let emu = start(Wire::Tcp, fast_config());
    let c = connect(&emu);
    let mut link = {
        c.close().unwrap();
        Link::connect_tcp(&emu.tcp_addr().unwrap().to_string(), WAIT).unwrap()
    };
    emu_wait(&emu, "second client", |s| s.stats.connections == 2);
    // Nothing is streamed to a client that has not synced.
    assert!(matches!(
        link.recv(Duration::from_millis(100)),
        Err(LinkError::Timeout(_))
    ));
    let c = Connection::establish(link, &opts()).unwrap();
    assert!(c.arm_calibration().is_some());
    // Keep-alive: PULSE goes out when nothing was sent for a while.
    let mut c = c;
    let deadline = Instant::now() + WAIT;
    while !c.keep_alive().unwrap() {
        assert!(Instant::now() < deadline, "no PULSE within {WAIT:?}");
        std::thread::sleep(Duration::from_millis(5));
    }
    // Just sent: not due again at once.
    assert!(!c.keep_alive().unwrap());
    // An unroutable command is ignored by the robot; the link stays up.
    c.send(&Command::Custom {
        number: 200,
        arg: Some(-3),
    })
    .unwrap();
    wait_sip(&mut c, "after unknown command", |_| true);
    link = c.into_link();
    assert!(link.stats().packets_out > 5);
}

#[test]
fn gripper_packet_stream_and_body_gripper_store_deploy() {
    let emu = start(Wire::Tcp, fast_config());
    let mut c = connect(&emu);
    c.send(&Command::GripperPacketRequest(2)).unwrap();
    let r = c.wait_until(
        WAIT,
        |p| matches!(p, RobotPacket::Gripper(g) if g.gripper_type == 1),
    );
    assert!(r.is_ok());
    c.send(&Command::Gripper(GripperCommand::Deploy)).unwrap();
    let r = c.wait_until(WAIT, |p| {
        matches!(p, RobotPacket::Gripper(g) if {
            let r = g.reading(GripperByteLayout::Manual, 0);
            r.paddles == PaddleState::Open && r.lift == LiftState::Down
        })
    });
    assert!(r.is_ok());
    c.send(&Command::Gripper(GripperCommand::Store)).unwrap();
    emu_wait(&emu, "stored", |s| {
        s.robot.lift >= 1.0 && s.robot.paddles <= 0.0 && !s.robot.lift_moving
    });
    assert!(c.last_gripper().is_some());
}

#[test]
fn emulator_stops_and_reports_its_endpoint() {
    let emu = start(Wire::Pty, fast_config());
    assert!(emu.pty_path().unwrap().exists());
    assert!(emu.tcp_addr().is_none());
    assert!(emu.is_running());
    emu.stop().unwrap();
    let emu = start(Wire::Tcp, fast_config());
    assert_ne!(emu.tcp_addr().unwrap().port(), 0);
    assert!(matches!(emu.link_target(), LinkTarget::Tcp(_)));
    drop(emu);
}

#[test]
fn keep_alive_beats_the_watchdog_and_silence_trips_it() {
    let mut cfg = fast_config();
    cfg.watchdog = Some(Duration::from_millis(500));
    let emu = start(Wire::Tcp, cfg);
    let mut c = connect(&emu);
    // Connection::recv sends PULSE every 200 ms: 60 SIPs (over 1 s, two
    // watchdog periods) arrive without a gap.
    let mut sips = 0;
    while sips < 60 {
        if let RobotPacket::Sip(_) = c.recv(WAIT).unwrap() {
            sips += 1;
        }
    }
    assert_eq!(emu.state().stats.watchdog_trips, 0);
    // A bare link sends nothing: the stream stops.
    let mut link = c.into_link();
    let mut stopped = false;
    for _ in 0..1000 {
        if let Err(e) = link.recv(Duration::from_secs(1)) {
            assert!(matches!(e, LinkError::Timeout(_)), "{e:?}");
            stopped = true;
            break;
        }
    }
    assert!(stopped);
    assert_eq!(emu.state().stats.watchdog_trips, 1);
    assert!(link.last_receive().is_some());
}

#[test]
fn event_loop_style_polling() {
    use std::os::fd::AsRawFd;
    let emu = start(Wire::Pty, fast_config());
    let mut c = connect(&emu);
    assert!(c.as_raw_fd() >= 0);
    assert_eq!(c.as_raw_fd(), c.link().as_raw_fd());
    // Nonblocking polls, as an epoll loop would do when the fd is readable.
    let mut sips = 0;
    for _ in 0..20_000 {
        match c.poll().unwrap() {
            Some(RobotPacket::Sip(_)) => sips += 1,
            Some(_) => {}
            None => std::thread::sleep(Duration::from_millis(1)),
        }
        c.keep_alive().unwrap();
        if sips == 5 {
            break;
        }
    }
    assert_eq!(sips, 5);
    assert!(c.last_sip().is_some());
    // "No limit" does not overflow.
    assert!(c.recv(Duration::MAX).is_ok());
}

/// Issue 13 item 3: the default emulator keeps the controller's timing
/// (replies at the cycle boundary, one ARMpac per cycle), and the
/// connection's default timeouts still work with it.
#[test]
fn controller_timing_by_default_and_the_handshake_copes() {
    let cfg = EmulatorConfig::default();
    assert_eq!(cfg.timing, Timing::Controller);
    assert_eq!(cfg.cycle, Duration::from_millis(100));
    let emu = start(Wire::Pty, cfg);
    let mut c = Connection::open(&emu.link_target(), &ConnectOptions::default()).unwrap();
    assert!(
        c.arm_calibration().is_some(),
        "ARMINFOpac at the cycle boundary"
    );
    c.send(&Command::ArmPower(true)).unwrap();
    wait_arm(&mut c, "powered", |a| st(a).powered);
    c.send(&Command::ArmPos {
        joint: j(4),
        tick: 120,
    })
    .unwrap();
    wait_arm(&mut c, "arrived", |a| {
        a.tick(j(4)) == 120 && st(a).moving_mask() == 0
    });
    // No ARMpac outside the cycle: never more ARMpacs than SIPs.
    let stats = emu.state().stats;
    assert!(
        stats.arm_packets_out <= stats.sips_out,
        "{} ARMpacs for {} SIPs",
        stats.arm_packets_out,
        stats.sips_out
    );
    c.close().unwrap();
}

/// Like a P2OS simulator, the TCP endpoint serves one client at a time: a second client
/// is closed before any reply (the handshake says the endpoint is held, it does not take it
/// over), the first keeps its link, and once it leaves the next client is served.
#[test]
fn a_tcp_endpoint_serves_one_client_at_a_time() {
    let emu = start(Wire::Tcp, fast_config());
    let mut first = connect(&emu);
    let err = Connection::open(&emu.link_target(), &opts()).unwrap_err();
    assert!(
        matches!(err, ConnectError::ClosedBeforeSync),
        "unexpected {err:?}"
    );
    assert!(err.to_string().contains("held by another client"), "{err}");
    let st = emu_wait(&emu, "the refusal counted", |s| {
        s.stats.refused_clients == 1
    });
    assert_eq!(st.stats.connections, 1);
    // The first client still has its link: it keeps reading SIPs sent after the refusal
    // (one already queued when `before` was read may come first).
    let before = emu.state().stats.sips_out;
    let mut fresh = false;
    for _ in 0..50 {
        wait_sip(&mut first, "a SIP after the refusal", |_| true);
        if emu.state().stats.sips_out > before {
            fresh = true;
            break;
        }
    }
    assert!(
        fresh,
        "no SIP sent after the refusal reached the first client"
    );
    first.close().unwrap();
    // Gone: the next client is served.
    emu_wait(&emu, "the first client gone", |s| !s.connected);
    let second = connect(&emu);
    assert_eq!(emu.state().stats.connections, 2);
    second.close().unwrap();
}

/// The handshake's CONFIG probe, in the controller's timing: a robot with the body gripper
/// says so, one without says so, and one that never answers CONFIG is `Unanswered` after
/// the attempts, with the connection still usable.
#[test]
fn the_handshake_reads_what_the_robot_has_from_its_configpac() {
    let probe = ConnectOptions {
        config: true,
        config_timeout: Duration::from_millis(400),
        config_attempts: 2,
        ..opts()
    };
    for gripper in [true, false] {
        let mut cfg = EmulatorConfig {
            cycle: Duration::from_millis(20),
            ..EmulatorConfig::default()
        };
        cfg.model.gripper = gripper;
        let emu = start(Wire::Pty, cfg);
        let c = Connection::open(&emu.link_target(), &probe).unwrap();
        match c.config() {
            ConfigProbe::Answered(p) => {
                assert_eq!(p.has_gripper(), gripper);
                assert_eq!(p.sip_cycle_ms, 20);
                assert_eq!(p.robot_type, "Pioneer");
            }
            other => panic!("gripper {gripper}: {other:?}"),
        }
        assert!(c.arm_calibration().is_some());
        assert_eq!(emu.state().robot.config_requests, 1);
    }
    let mut cfg = EmulatorConfig {
        cycle: Duration::from_millis(20),
        ..EmulatorConfig::default()
    };
    cfg.faults.no_config = true;
    let emu = start(Wire::Tcp, cfg);
    let mut c = Connection::open(&emu.link_target(), &probe).unwrap();
    assert_eq!(c.config(), &ConfigProbe::Unanswered { attempts: 2 });
    assert_eq!(emu.state().stats.config_dropped, 2);
    assert!(c.arm_calibration().is_some());
    wait_sip(&mut c, "after the unanswered probe", |_| true);
    // Not asked unless the options say so.
    drop(c);
    let c = Connection::open(&emu.link_target(), &opts()).unwrap();
    assert_eq!(c.config(), &ConfigProbe::NotAsked);
}
