//! Gripper goals (issue 28, item 4) on the Pioneer's body gripper, fed by the emulated
//! P2OS controller: its paddles only open or close fully, at one speed, with no force
//! setting (P2OS's GRIPpress sets a grip time, not a force). A goal of gap 0 closes them, a
//! goal of their full width (or more: clamped, and said so) opens them; a gap in between,
//! an effort or a speed is refused with the reason and nothing is sent. Closing on an
//! object stalls on it, and the breakbeams put "object present" in the result.

use std::time::{Duration, Instant};

use limber_emulator::{ModelConfig, ObjectPlacement, Robot, Timing};
use limber_interfaces::prelude::*;
use limber_p2os::{Command, Frame, GripperCommand as P2, RobotPacket};
use limber_pioneer::{PioneerConfig, RobotModel};
use limber_services::Origin;

const FROM: Origin = Origin {
    client_id: 7,
    seq: 1,
    sent_ns: 0,
    received_ns: 0,
};

/// The emulated controller (immediate replies) and limber's robot model, linked by hand:
/// what the model queues goes to the controller, the controller's SIP to the model.
struct Bench {
    robot: Robot,
    model: RobotModel,
    t0: Instant,
    at: u64,
    out: Vec<Frame>,
}

impl Bench {
    fn new(object: Option<ObjectPlacement>) -> Bench {
        let t0 = Instant::now();
        let mut robot = Robot::new(ModelConfig::default(), t0);
        robot.set_timing(Timing::Fast);
        robot.set_object(object);
        let mut model = RobotModel::new(PioneerConfig::default());
        model.link_up(t0);
        model.set_body_gripper(true);
        let mut b = Bench {
            robot,
            model,
            t0,
            at: 0,
            out: Vec::new(),
        };
        for c in [
            Command::Sync0,
            Command::Sync1,
            Command::Sync2,
            Command::Open,
        ] {
            b.send_robot(&c);
        }
        b
    }

    fn now(&self) -> Instant {
        self.t0 + Duration::from_millis(self.at)
    }

    fn send_robot(&mut self, c: &Command) {
        let f = c.encode().unwrap();
        let now = self.now();
        self.out.clear();
        self.robot.handle(f.payload(), now, &mut self.out);
    }

    /// A goal to the model; what it queued, sent on to the controller.
    fn goal(&mut self, gap: f64, effort: f64, speed: f64) -> (Status, Vec<Command>) {
        let cmd = GripperCommand::goal(gap, effort, speed).unwrap();
        let st = self.model.gripper_command(&cmd, &FROM);
        let mut sent = Vec::new();
        while let Some(q) = self.model.outbox_mut().pop() {
            sent.push(q.cmd);
        }
        for c in &sent {
            self.send_robot(c);
        }
        (st, sent)
    }

    /// Runs the controller until the model says the paddles' motion ended (bounded).
    fn progress_at_end(&mut self) -> limber_services::Progress {
        for _ in 0..200 {
            self.at += 50;
            let now = self.now();
            self.out.clear();
            self.robot.advance(now, &mut self.out);
            self.model
                .on_packet(&RobotPacket::Sip(self.robot.sip()), now);
            let p = self.model.gripper_progress();
            if p.end.is_some() {
                return p;
            }
        }
        panic!("the paddles' motion never ended");
    }
}

#[test]
fn the_paddles_open_or_close_fully_and_refuse_the_rest() {
    let mut b = Bench::new(None);
    // What the P2OS gripper cannot set is refused, with the reason, and nothing is sent.
    for (gap, effort, speed, why) in [
        (0.05, 0.0, 0.0, Status::GapNotSettable),
        (0.0, 5.0, 0.0, Status::EffortNotSettable),
        (0.0, 0.0, 0.05, Status::SpeedNotSettable),
    ] {
        let (st, sent) = b.goal(gap, effort, speed);
        assert_eq!(st, why, "gap {gap} effort {effort} speed {speed}");
        assert!(sent.is_empty(), "nothing sent for a refused goal: {sent:?}");
    }
    // Gap 0: GRIPclose; nothing between the paddles: reached.
    let (st, sent) = b.goal(0.0, 0.0, 0.0);
    assert_eq!(st, Status::Ok);
    assert_eq!(sent, [Command::Gripper(P2::Close)]);
    let p = b.progress_at_end();
    assert_eq!(p.end, Some((MotionResult::Reached, Status::Ok)));
    // Wider than the paddles open: GRIPopen, clamped and said so.
    let width = PioneerConfig::default().gripper.inner[0];
    let (st, sent) = b.goal(width + 0.1, 0.0, 0.0);
    assert_eq!(st, Status::Clamped);
    assert_eq!(sent, [Command::Gripper(P2::Open)]);
    let p = b.progress_at_end();
    assert_eq!(p.end, Some((MotionResult::Reached, Status::Ok)));
    // Exactly their width: GRIPopen, ok.
    let (st, sent) = b.goal(width, 0.0, 0.0);
    assert_eq!(
        (st, sent.as_slice()),
        (Status::Ok, &[Command::Gripper(P2::Open)][..])
    );
}

#[test]
fn closing_on_an_object_stalls_with_the_object_present() {
    let mut b = Bench::new(Some(ObjectPlacement::Inner));
    let (st, _) = b.goal(0.0, 0.0, 0.0);
    assert_eq!(st, Status::Ok);
    let p = b.progress_at_end();
    assert_eq!(
        p.end,
        Some((MotionResult::Stalled, Status::ObjectPresent)),
        "the paddles stop on the object; the beams see it"
    );
    // Opened again with the object still between the paddles: reached, present.
    let width = PioneerConfig::default().gripper.inner[0];
    b.goal(width, 0.0, 0.0);
    let p = b.progress_at_end();
    assert_eq!(p.end, Some((MotionResult::Reached, Status::ObjectPresent)));
}
