//! The emulated controller's state and behaviour, independent of I/O: it
//! takes command payloads and the time, and produces packets.
//!
//! One file over 800 lines, for a stated reason: it is one state machine, the controller's
//! 100 ms cycle, whose SIP, ARMpac and gripper bytes are all built from the same fields in
//! the same step (as the vendor's firmware does); split by device, each part would reach
//! into the others' state every cycle.

use limber_p2os::vendor_conventions as vc;
use limber_p2os::{
    ArmInfo, ArmPacket, ArmStatus, ArmpacLayout, ConfigPacket, ConfigWorking, Frame,
    GripperByteLayout, GripperCommand, GripperPacket, GripperReading, GripperSwitchFacts,
    GripperSwitches, JointCalibration, ReceivedCommand, RobotIdentity, Sip, SonarReading, num,
};
use std::time::{Duration, Instant};

/// Where a simulated object sits in front of the gripper (at floor level,
/// between the paddles).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObjectPlacement {
    /// Between the paddle tips: breaks the outer beam only.
    Outer,
    /// Fully between the paddles: breaks both beams.
    Inner,
}

/// When the emulated controller sends its packets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Timing {
    /// Like a P2OS controller: everything goes out once per cycle (100 ms
    /// by default). SYNC replies, ARMINFOpac and a requested ARMpac leave
    /// at the next cycle boundary; the ARMpac stream sends one per cycle
    /// and nothing in between. The default.
    #[default]
    Controller,
    /// Immediate replies: SYNC, ARM_INFO and ARM_STATUS are answered as soon
    /// as they arrive, and while the ARMpac stream is on an extra ARMpac
    /// goes out after each arm command and whenever a joint starts or
    /// stops. For benchmarks and tests that need speed; no robot does this.
    Fast,
}

/// The sync/connection stage of the emulated controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SyncStage {
    /// Waiting for SYNC0.
    NoSync,
    /// SYNC0 answered.
    AfterSync0,
    /// SYNC1 answered.
    AfterSync1,
    /// SYNC2 answered; waiting for OPEN.
    Synced,
    /// OPEN received: streaming SIPs.
    Open,
}

/// The default arm calibration: 6 joints including the gripper.
pub fn default_arm_info() -> ArmInfo {
    let j = |speed, home, min, centre, max, ticks_per_90| JointCalibration {
        speed,
        home,
        min,
        centre,
        max,
        ticks_per_90,
    };
    ArmInfo::new(
        "limber-emulator P2ARM 1.0",
        &[
            j(20, 128, 28, 128, 228, 80),
            j(20, 200, 40, 120, 220, 85),
            j(20, 40, 30, 128, 225, 90),
            j(20, 128, 10, 128, 245, 85),
            j(20, 128, 40, 128, 215, 80),
            j(10, 160, 100, 128, 200, 80),
        ],
    )
}

/// The arm's autopark watchdog until a client sets it, s (ARIA: 10 minutes).
pub const AUTOPARK_DEFAULT_S: u16 = 600;

/// Physical parameters of the emulated robot.
#[derive(Debug, Clone)]
pub struct ModelConfig {
    /// The SYNC2 identity.
    pub identity: RobotIdentity,
    /// The arm and its calibration; `None` = no arm (arm commands are
    /// ignored silently, like a simulator without an arm).
    pub arm: Option<ArmInfo>,
    /// A body gripper with lift is fitted: said in the CONFIGpac (GRIPPER) and the
    /// GRIPPERpac (type 1, the Pioneer 2/3 gripper). Without one, GRIPPER (33) and
    /// GRIPPERVAL (36) commands are logged and counted as unsupported
    /// ([`RobotState::unsupported_gripper_commands`]) and ignored, as a controller
    /// without a gripper does.
    pub gripper: bool,
    /// Time of a full lift stroke (the reference: 3.5 s).
    pub lift_stroke: Duration,
    /// Time for the paddles to go from closed to open.
    pub paddle_stroke: Duration,
    /// Paddle opening at which they close on an object (0 closed, 1 open).
    pub object_width: f64,
    /// How the ARMpac status bytes are laid out: the vendor's manuals'
    /// (default) or ARIA's.
    pub armpac_layout: ArmpacLayout,
    /// How the gripper state byte (SIP and GRIPPERpac) is written: the vendor's
    /// manual's active-high state bits with the breakbeams in DIGIN (default) or ARIA's
    /// active-low switches.
    pub gripper_byte: GripperByteLayout,
}

impl Default for ModelConfig {
    fn default() -> Self {
        ModelConfig {
            identity: RobotIdentity {
                name: "limber-emulator".into(),
                class: "Pioneer".into(),
                subclass: "p3dx".into(),
            },
            arm: Some(default_arm_info()),
            gripper: true,
            lift_stroke: Duration::from_millis(3500),
            paddle_stroke: Duration::from_millis(1500),
            object_width: 0.35,
            armpac_layout: ArmpacLayout::default(),
            gripper_byte: GripperByteLayout::default(),
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Servo {
    tick: u8,
    target: u8,
    ms: u8,
    next_step: Option<Instant>,
}

/// A linear actuator moving at a constant rate (paddles, lift), 0..1.
#[derive(Debug, Clone, Copy)]
struct Axis {
    pos: f64,
    target: f64,
    last: Instant,
}

impl Axis {
    fn moving(&self) -> bool {
        (self.pos - self.target).abs() > 1e-9
    }

    fn advance(&mut self, now: Instant, stroke: Duration) {
        let dt = now.saturating_duration_since(self.last).as_secs_f64();
        self.last = now;
        let step = dt / stroke.as_secs_f64().max(1e-6);
        if self.pos < self.target {
            self.pos = (self.pos + step).min(self.target);
        } else if self.pos > self.target {
            self.pos = (self.pos - step).max(self.target);
        }
    }

    fn set_target(&mut self, t: f64, now: Instant) {
        if !self.moving() {
            self.last = now;
        }
        self.target = t.clamp(0.0, 1.0);
    }

    fn stop(&mut self) {
        self.target = self.pos;
    }
}

const LIFT_FLOOR: f64 = 0.05;

/// A snapshot of the emulated robot, for tests and tools.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotState {
    /// Connection stage.
    pub stage: SyncStage,
    /// An arm is fitted.
    pub has_arm: bool,
    /// Arm servo power.
    pub arm_powered: bool,
    /// Current tick of joints 1..6.
    pub servo_ticks: [u8; 6],
    /// Target tick of joints 1..6.
    pub servo_targets: [u8; 6],
    /// Speed (ms per step) of joints 1..6.
    pub ms_per_step: [u8; 6],
    /// ARMpac stream mode (0 off, 2 continuous).
    pub arm_status_mode: u8,
    /// The arm is homing.
    pub homing: bool,
    /// Paddle opening, 0 closed .. 1 open.
    pub paddles: f64,
    /// Paddles moving.
    pub paddles_moving: bool,
    /// Lift position, 0 down .. 1 up.
    pub lift: f64,
    /// Lift moving.
    pub lift_moving: bool,
    /// The simulated object in front of the gripper.
    pub object: Option<ObjectPlacement>,
    /// The object is held between the paddles.
    pub object_in_gripper: bool,
    /// The gripper state byte as sent.
    pub switches: GripperSwitches,
    /// What the byte (and DIGIN) says, read in the configured layout.
    pub gripper: GripperReading,
    /// Sonar on.
    pub sonar: bool,
    /// Valid commands received.
    pub commands: u64,
    /// The autopark watchdog, s (AUTOPARK; 0 disabled).
    pub autopark_s: u16,
    /// Times the autopark watchdog parked the arm (homed it and powered it off).
    pub autoparks: u64,
    /// CONFIG (18) commands answered with a CONFIGpac.
    pub config_requests: u64,
    /// GRIPPER (33) and GRIPPERVAL (36) commands received after OPEN, with or without a
    /// gripper.
    pub gripper_commands: u64,
    /// GRIPPER (33) commands received by a robot without a gripper (ignored).
    pub unsupported_gripper_commands: u64,
    /// GRIPPERVAL (36) commands received by a robot without a gripper (ignored).
    pub unsupported_gripperval_commands: u64,
}

/// The emulated controller.
#[derive(Debug, Clone)]
pub struct Robot {
    cfg: ModelConfig,
    stage: SyncStage,
    arm_powered: bool,
    homing: bool,
    parking: bool,
    servos: [Servo; 6],
    arm_status: u8,
    paddles: Axis,
    lift: Axis,
    object: Option<ObjectPlacement>,
    gripped: bool,
    pending_carry: bool,
    gripper_pac: u8,
    sonar: bool,
    commands: u64,
    last_moving: u8,
    wants_arm_pac: bool,
    timing: Timing,
    /// Replies waiting for the next cycle boundary (controller timing).
    deferred: Vec<Frame>,
    /// An ARMpac was requested (ARM_STATUS 1) for the next cycle.
    arm_pac_once: bool,
    /// A 0xE0 gripper packet was requested once for the next cycle.
    gripper_pac_once: bool,
    /// The last command (any, PULSE included) from the client.
    last_contact: Instant,
    autopark_s: u16,
    autoparks: u64,
    cycle: Duration,
    watchdog: Option<Duration>,
    config_requests: u64,
    gripper_commands: u64,
    unsupported_gripper: u64,
    unsupported_gripperval: u64,
}

impl Robot {
    /// A robot at rest: arm unpowered at its home ticks, paddles closed,
    /// lift down.
    pub fn new(cfg: ModelConfig, now: Instant) -> Robot {
        let mut servos = [Servo {
            tick: 128,
            target: 128,
            ms: 20,
            next_step: None,
        }; 6];
        if let Some(info) = &cfg.arm {
            for (s, c) in servos.iter_mut().zip(info.calibrations()) {
                s.tick = c.home;
                s.target = c.home;
                s.ms = c.speed;
            }
        }
        let axis = |pos| Axis {
            pos,
            target: pos,
            last: now,
        };
        Robot {
            cfg,
            stage: SyncStage::NoSync,
            arm_powered: false,
            homing: false,
            parking: false,
            servos,
            arm_status: 0,
            paddles: axis(0.0),
            lift: axis(0.0),
            object: None,
            gripped: false,
            pending_carry: false,
            gripper_pac: 0,
            sonar: false,
            commands: 0,
            last_moving: 0,
            wants_arm_pac: false,
            last_contact: now,
            autopark_s: AUTOPARK_DEFAULT_S,
            autoparks: 0,
            timing: Timing::default(),
            deferred: Vec::new(),
            arm_pac_once: false,
            gripper_pac_once: false,
            cycle: Duration::from_millis(100),
            watchdog: None,
            config_requests: 0,
            gripper_commands: 0,
            unsupported_gripper: 0,
            unsupported_gripperval: 0,
        }
    }

    /// The controller's cycle and command watchdog, as the CONFIGpac reports them
    /// (SIPCYCLE, WATCHDOG); 100 ms and none until set.
    pub fn set_controller(&mut self, cycle: Duration, watchdog: Option<Duration>) {
        self.cycle = cycle;
        self.watchdog = watchdog;
    }

    /// The CONFIGpac this robot answers CONFIG with: the identity's class, subclass and
    /// name, the cycle and watchdog, GRIPPER 1 with the body gripper (0 without), the
    /// front sonar ring; the drive's limits are those of a Pioneer 3-DX, illustrative
    /// (the emulator has no drive).
    pub fn config_packet(&self) -> ConfigPacket {
        let id = &self.cfg.identity;
        let ms = |d: Duration| u16::try_from(d.as_millis()).unwrap_or(u16::MAX);
        ConfigPacket {
            robot_type: id.class.clone(),
            subtype: id.subclass.clone(),
            serial_number: "EMU-0001".into(),
            four_mots: 0,
            rot_vel_top: 360,
            trans_vel_top: 2200,
            rot_acc_top: 300,
            trans_acc_top: 2000,
            pwm_max: 400,
            name: id.name.clone(),
            sip_cycle_ms: u8::try_from(self.cycle.as_millis()).unwrap_or(u8::MAX),
            host_baud: 0,
            aux1_baud: 0,
            gripper: u16::from(self.cfg.gripper),
            front_sonar: 1,
            rear_sonar: 0,
            low_battery: 115,
            rev_count: 16570,
            watchdog_ms: self.watchdog.map_or(0, ms),
            p2mpacs: 0,
            stall_val: 450,
            stall_count: 100,
            joy_vel: 300,
            joy_rot_vel: 60,
            working: ConfigWorking {
                rot_vel_max: 300,
                trans_vel_max: 1500,
                rot_acc: 100,
                rot_decel: 100,
                rot_kp: 40,
                rot_kv: 20,
                rot_ki: 0,
                trans_acc: 300,
                trans_decel: 300,
                trans_kp: 40,
                trans_kv: 30,
                trans_ki: 0,
            },
            bumpers: Some((5, 5)),
            charger: Some(0),
            aros18: Some((40, 2, 0)),
            extra_len: 0,
        }
    }

    /// A command a controller without the hardware ignores: logged and counted.
    fn unsupported(&mut self, number: u8) {
        let (count, what) = match number {
            num::GRIPPER => (&mut self.unsupported_gripper, "GRIPPER"),
            _ => (&mut self.unsupported_gripperval, "GRIPPERVAL"),
        };
        *count += 1;
        tracing::warn!(
            "received unsupported command {number} ({what}: this robot has no gripper); ignored              ({count} so far)"
        );
    }

    /// Sets when packets go out (controller timing by default).
    pub fn set_timing(&mut self, timing: Timing) {
        self.timing = timing;
    }

    /// When packets go out.
    pub fn timing(&self) -> Timing {
        self.timing
    }

    /// A reply: at once in fast mode, else at the next cycle boundary.
    fn reply(&mut self, f: Result<Frame, limber_p2os::EncodeError>, out: &mut Vec<Frame>) {
        match self.timing {
            Timing::Fast => push(out, f),
            Timing::Controller => push(&mut self.deferred, f),
        }
    }

    /// The connection stage.
    pub fn stage(&self) -> SyncStage {
        self.stage
    }

    /// Forgets the client (a new TCP connection, or after CLOSE): back to
    /// NO_SYNC, streams off. The physical state stays.
    pub fn reset_connection(&mut self) {
        self.stage = SyncStage::NoSync;
        self.arm_status = 0;
        self.gripper_pac = 0;
        self.sonar = false;
        self.deferred.clear();
        self.arm_pac_once = false;
        self.gripper_pac_once = false;
    }

    /// Places or removes the simulated object.
    pub fn set_object(&mut self, o: Option<ObjectPlacement>) {
        self.object = o;
        if o.is_none() {
            self.gripped = false;
        }
    }

    fn has_arm(&self) -> bool {
        self.cfg.arm.is_some()
    }

    fn calib(&self, idx: usize) -> Option<JointCalibration> {
        self.cfg.arm.as_ref()?.calibrations().get(idx).copied()
    }

    fn joint_count(&self) -> usize {
        self.cfg.arm.as_ref().map_or(0, |a| a.calibrations().len())
    }

    /// The joint numbered `arg` (1..6, if fitted), else none.
    fn one_joint(&self, arg: i32) -> std::ops::Range<usize> {
        match usize::try_from(arg) {
            Ok(j @ 1..=6) if j <= self.joint_count() => j - 1..j,
            _ => 0..0,
        }
    }

    /// The joints an ARM_HOME or ARM_STOP argument selects, per the manuals'
    /// Table 2: 1..6 one joint; "all" is any value above 6 for HOME, 255
    /// for STOP. Anything else (0, negative) selects nothing.
    fn selected_joints(&self, arg: i32, all: fn(u16) -> bool) -> std::ops::Range<usize> {
        match u16::try_from(arg) {
            Ok(a) if all(a) => 0..self.joint_count(),
            _ => self.one_joint(arg),
        }
    }

    fn set_servo_target(&mut self, idx: usize, target: u8, now: Instant) {
        let Some(c) = self.calib(idx) else { return };
        let target = target.clamp(c.min.min(c.max), c.max.max(c.min));
        let s = &mut self.servos[idx];
        s.target = target;
        if s.next_step.is_none() && s.tick != target {
            s.next_step = Some(now + step_time(s.ms));
        }
    }

    /// Handles one command payload. In [`Timing::Fast`] replies (and an
    /// ARMpac when the command changed the arm's state and the stream is on)
    /// go to `out` at once; in [`Timing::Controller`] they wait for the next
    /// [`Robot::cycle`].
    pub fn handle(&mut self, payload: &[u8], now: Instant, out: &mut Vec<Frame>) {
        let Some(cmd) = ReceivedCommand::parse(payload) else {
            return;
        };
        self.advance(now, out);
        self.commands += 1;
        self.last_contact = now;
        let arg = cmd.int();
        let open = self.stage == SyncStage::Open;
        if open && matches!(cmd.number, num::GRIPPER | num::GRIPPERVAL) {
            self.gripper_commands += 1;
        }
        match cmd.number {
            num::SYNC0 if !open => {
                self.stage = SyncStage::AfterSync0;
                self.reply(Frame::new(&[0]), out);
            }
            num::SYNC1 if !open => {
                if self.stage == SyncStage::Synced {
                    self.stage = SyncStage::Open;
                } else {
                    self.stage = SyncStage::AfterSync1;
                    self.reply(Frame::new(&[1]), out);
                }
            }
            num::SYNC2 if !open && self.stage == SyncStage::AfterSync1 => {
                self.stage = SyncStage::Synced;
                let f = self.cfg.identity.encode_sync2();
                self.reply(f, out);
            }
            num::SYNC2 if !open => {}
            num::PULSE => {}
            num::CLOSE => self.reset_connection(),
            _ if !open => {}
            num::SONAR => self.sonar = arg.unwrap_or(0) != 0,
            num::CONFIG => {
                self.config_requests += 1;
                let f = self.config_packet().encode();
                self.reply(f, out);
            }
            num::GRIPPER | num::GRIPPERVAL if !self.cfg.gripper => self.unsupported(cmd.number),
            num::GRIPPER => {
                if let Some(g) = arg.and_then(|a| u8::try_from(a & 0xFF).ok()) {
                    self.gripper_command(g, now);
                }
            }
            num::GRIPPERVAL if self.pending_carry => {
                self.pending_carry = false;
                let v = f64::from(arg.unwrap_or(0));
                let travel = v * 0.020 / self.cfg.lift_stroke.as_secs_f64().max(1e-6);
                let t = self.lift.pos + travel;
                self.lift.set_target(t, now);
            }
            // Answered with or without a gripper: HAS GRIPPER says which.
            num::GRIPPERPACREQUEST => {
                let a = arg.unwrap_or(0);
                if a == 1 {
                    match self.timing {
                        Timing::Fast => push(out, self.gripper_packet().encode()),
                        Timing::Controller => self.gripper_pac_once = true,
                    }
                } else {
                    self.gripper_pac = u8::from(a == 2);
                }
            }
            n if self.has_arm() && (num::ARM_INFO..=num::ARM_GRIPPARK).contains(&n) => {
                self.arm_command(n, arg, now, out);
            }
            _ => {}
        }
    }

    fn gripper_command(&mut self, g: u8, now: Instant) {
        let Some(g) = GripperCommand::from_u8(g) else {
            return;
        };
        self.pending_carry = false;
        match g {
            GripperCommand::Open => self.paddles.set_target(1.0, now),
            GripperCommand::Close | GripperCommand::Press => self.paddles.set_target(0.0, now),
            GripperCommand::Stop => self.paddles.stop(),
            GripperCommand::LiftUp => self.lift.set_target(1.0, now),
            GripperCommand::LiftDown => self.lift.set_target(0.0, now),
            GripperCommand::LiftStop => self.lift.stop(),
            GripperCommand::Store => {
                self.paddles.set_target(0.0, now);
                self.lift.set_target(1.0, now);
            }
            GripperCommand::Deploy => {
                self.paddles.set_target(1.0, now);
                self.lift.set_target(0.0, now);
            }
            GripperCommand::Halt => {
                self.paddles.stop();
                self.lift.stop();
            }
            GripperCommand::LiftCarry => self.pending_carry = true,
        }
    }

    fn arm_command(&mut self, n: u8, arg: Option<i32>, now: Instant, out: &mut Vec<Frame>) {
        let a = arg.unwrap_or(0);
        let [lsb, msb] = (a.clamp(0, 0xFFFF) as u16).to_le_bytes();
        match n {
            num::ARM_INFO => {
                if let Some(f) = self.cfg.arm.as_ref().map(ArmInfo::encode) {
                    self.reply(f, out);
                }
                return;
            }
            num::ARM_STATUS => {
                match a {
                    1 | 2 => {
                        if a == 2 {
                            self.arm_status = 2;
                        }
                        match self.timing {
                            Timing::Fast => push(out, self.arm_packet().encode()),
                            // The stream's own packet serves as the reply.
                            Timing::Controller => self.arm_pac_once |= a == 1,
                        }
                    }
                    _ => self.arm_status = 0,
                }
                return;
            }
            // The manuals: POWER takes 0 or 1; anything else is ignored.
            num::ARM_POWER if a == 0 || a == 1 => {
                self.arm_powered = a != 0;
                if !self.arm_powered {
                    for s in &mut self.servos {
                        s.target = s.tick;
                        s.next_step = None;
                    }
                    self.homing = false;
                    self.parking = false;
                }
            }
            num::ARM_HOME | num::ARM_PARK if self.arm_powered => {
                let js = if n == num::ARM_PARK {
                    0..self.joint_count()
                } else {
                    self.selected_joints(a, vc::arm_home_all)
                };
                if js.is_empty() {
                    // Not a joint the manual names: ignored, no homing.
                    return;
                }
                for j in js {
                    if let Some(c) = self.calib(j) {
                        self.set_servo_target(j, c.home, now);
                    }
                }
                self.homing = true;
                self.parking = n == num::ARM_PARK;
            }
            num::ARM_POS if self.arm_powered => {
                for j in self.one_joint(i32::from(msb)) {
                    self.set_servo_target(j, lsb, now);
                }
            }
            num::ARM_AUTOPARK => {
                self.autopark_s = a.clamp(0, 0xFFFF) as u16;
                return;
            }
            num::ARM_SPEED => {
                for j in self.one_joint(i32::from(msb)) {
                    self.servos[j].ms = lsb;
                }
            }
            num::ARM_STOP => {
                for j in self.selected_joints(a, vc::arm_stop_all) {
                    let s = &mut self.servos[j];
                    s.target = s.tick;
                    s.next_step = None;
                }
            }
            _ => return,
        }
        self.wants_arm_pac = true;
        self.flush_arm_pac(out);
    }

    fn flush_arm_pac(&mut self, out: &mut Vec<Frame>) {
        if self.wants_arm_pac
            && self.timing == Timing::Fast
            && self.arm_status == 2
            && self.stage == SyncStage::Open
        {
            push(out, self.arm_packet().encode());
            // The client now knows which joints move.
            self.last_moving = self.moving_mask();
        }
        self.wants_arm_pac = false;
    }

    fn moving_mask(&self) -> u8 {
        let mut m = 0u8;
        for (i, s) in self.servos.iter().enumerate() {
            if s.tick != s.target {
                m |= 1 << i;
            }
        }
        m
    }

    /// Advances the servos, paddles and lift to `now`. In [`Timing::Fast`],
    /// when a joint starts or stops and the ARMpac stream is on, an ARMpac
    /// goes to `out` at once.
    pub fn advance(&mut self, now: Instant, out: &mut Vec<Frame>) {
        self.autopark(now);
        if self.arm_powered {
            for s in &mut self.servos {
                while s.tick != s.target {
                    let Some(due) = s.next_step else {
                        s.next_step = Some(now + step_time(s.ms));
                        break;
                    };
                    if now < due {
                        break;
                    }
                    s.tick = if s.tick < s.target {
                        s.tick + 1
                    } else {
                        s.tick - 1
                    };
                    s.next_step = Some(due + step_time(s.ms));
                }
                if s.tick == s.target {
                    s.next_step = None;
                }
            }
        }
        let moving = self.moving_mask();
        if moving == 0 && (self.homing || self.parking) {
            self.homing = false;
            if self.parking {
                self.parking = false;
                self.arm_powered = false;
            }
            self.wants_arm_pac = true;
        }
        if moving != self.last_moving {
            // A joint started or finished: tell the client now.
            self.wants_arm_pac = true;
            self.last_moving = moving;
        }
        self.flush_arm_pac(out);

        let was_closing = self.paddles.target < self.paddles.pos;
        self.paddles.advance(now, self.cfg.paddle_stroke);
        self.lift.advance(now, self.cfg.lift_stroke);
        let visible = self.object_visible();
        if was_closing && visible && !self.gripped && self.paddles.pos <= self.cfg.object_width {
            self.paddles.pos = self.cfg.object_width;
            self.paddles.stop();
            self.gripped = true;
        }
        if self.gripped && self.paddles.pos > self.cfg.object_width + 1e-9 {
            // Opened: the object is released (and falls if lifted).
            self.gripped = false;
        }
    }

    /// The autopark watchdog (Pioneer Arm Manual: "if contact is lost while powered, the
    /// arm reverts to HOME with power off"): no command for `autopark_s` seconds while
    /// powered parks the arm.
    fn autopark(&mut self, now: Instant) {
        if !self.arm_powered
            || self.parking
            || self.autopark_s == 0
            || now.saturating_duration_since(self.last_contact)
                < Duration::from_secs(u64::from(self.autopark_s))
        {
            return;
        }
        for j in 0..self.joint_count() {
            if let Some(c) = self.calib(j) {
                self.set_servo_target(j, c.home, now);
            }
        }
        self.homing = true;
        self.parking = true;
        self.autoparks += 1;
    }

    fn object_visible(&self) -> bool {
        self.gripped || (self.object.is_some() && self.lift.pos <= LIFT_FLOOR)
    }

    /// The earliest time something changes by itself, for the I/O loop's
    /// wait (`None`: nothing moves).
    pub fn next_event(&self, now: Instant) -> Option<Instant> {
        let servo = self
            .servos
            .iter()
            .filter(|s| self.arm_powered && s.tick != s.target)
            .filter_map(|s| s.next_step)
            .min();
        let axes =
            (self.paddles.moving() || self.lift.moving()).then(|| now + Duration::from_millis(5));
        match (servo, axes) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// The packets of one controller cycle: the replies deferred to this
    /// boundary (controller timing), then after OPEN the SIP, and the
    /// ARMpac and gripper packet when streaming or requested once.
    pub fn cycle(&mut self, now: Instant, out: &mut Vec<Frame>) {
        self.advance(now, out);
        out.append(&mut self.deferred);
        if self.stage != SyncStage::Open {
            return;
        }
        push(out, self.sip().encode());
        if (self.arm_status == 2 || std::mem::take(&mut self.arm_pac_once)) && self.has_arm() {
            push(out, self.arm_packet().encode());
        }
        if self.gripper_pac == 1 || std::mem::take(&mut self.gripper_pac_once) {
            push(out, self.gripper_packet().encode());
        }
    }

    fn switch_facts(&self) -> GripperSwitchFacts {
        let closed = self.paddles.pos <= 1e-9 || self.gripped;
        let visible = self.object_visible();
        GripperSwitchFacts {
            paddles_open: self.paddles.pos >= 1.0 - 1e-9,
            left_contact: closed,
            right_contact: closed,
            paddles_moving: self.paddles.moving(),
            lift_up: !self.lift.moving() && self.lift.pos >= 1.0 - 1e-9,
            lift_down: !self.lift.moving() && self.lift.pos <= 1e-9,
            lift_moving: self.lift.moving(),
            outer_beam: visible,
            inner_beam: visible && (self.gripped || self.object == Some(ObjectPlacement::Inner)),
            gripper_error: false,
            lift_error: false,
        }
    }

    /// The gripper state byte and the DIGIN bits in the configured layout (nothing
    /// without a gripper).
    fn switches_and_digin(&self) -> (GripperSwitches, u8) {
        if self.cfg.gripper {
            GripperSwitches::encode(self.switch_facts(), self.cfg.gripper_byte)
        } else {
            (GripperSwitches(0), 0)
        }
    }

    fn switches(&self) -> GripperSwitches {
        self.switches_and_digin().0
    }

    /// The current standard SIP.
    pub fn sip(&self) -> Sip {
        let mut sip = Sip::default();
        let (switches, digin) = self.switches_and_digin();
        sip.timer = u16::from(switches.0) << 8;
        sip.digin = digin;
        if self.sonar {
            let readings: [SonarReading; 8] = std::array::from_fn(|i| SonarReading {
                index: i as u8,
                range: 5000,
            });
            sip.set_sonars(&readings);
        }
        sip
    }

    /// The current ARMpac, in the configured layout.
    pub fn arm_packet(&self) -> ArmPacket {
        let status = ArmStatus {
            moving: self.moving_mask(),
            powered: self.arm_powered,
            connected: true,
            inited: true,
            homing: self.homing,
        };
        let mut ticks = [0u8; 6];
        for (t, s) in ticks.iter_mut().zip(&self.servos) {
            *t = s.tick;
        }
        ArmPacket::new(status, self.cfg.armpac_layout, ticks)
    }

    /// The ARMpac layout in use.
    pub fn armpac_layout(&self) -> ArmpacLayout {
        self.cfg.armpac_layout
    }

    /// The current 0xE0 gripper packet.
    pub fn gripper_packet(&self) -> GripperPacket {
        GripperPacket {
            gripper_type: u8::from(self.cfg.gripper),
            switches: self.switches(),
            grasp_time: 10,
        }
    }

    /// A snapshot of the state.
    pub fn state(&self) -> RobotState {
        let mut ticks = [0u8; 6];
        let mut targets = [0u8; 6];
        let mut ms = [0u8; 6];
        for (i, s) in self.servos.iter().enumerate() {
            ticks[i] = s.tick;
            targets[i] = s.target;
            ms[i] = s.ms;
        }
        RobotState {
            stage: self.stage,
            has_arm: self.has_arm(),
            arm_powered: self.arm_powered,
            servo_ticks: ticks,
            servo_targets: targets,
            ms_per_step: ms,
            arm_status_mode: self.arm_status,
            homing: self.homing,
            paddles: self.paddles.pos,
            paddles_moving: self.paddles.moving(),
            lift: self.lift.pos,
            lift_moving: self.lift.moving(),
            object: self.object,
            object_in_gripper: self.gripped,
            switches: self.switches(),
            gripper: {
                let (b, digin) = self.switches_and_digin();
                b.read(self.cfg.gripper_byte, digin)
            },
            sonar: self.sonar,
            commands: self.commands,
            autopark_s: self.autopark_s,
            autoparks: self.autoparks,
            config_requests: self.config_requests,
            gripper_commands: self.gripper_commands,
            unsupported_gripper_commands: self.unsupported_gripper,
            unsupported_gripperval_commands: self.unsupported_gripperval,
        }
    }
}

fn step_time(ms: u8) -> Duration {
    Duration::from_millis(u64::from(ms.max(1)))
}

fn push(out: &mut Vec<Frame>, f: Result<Frame, limber_p2os::EncodeError>) {
    // Every frame the model builds is far below the size limit.
    if let Ok(f) = f {
        out.push(f);
    }
}
