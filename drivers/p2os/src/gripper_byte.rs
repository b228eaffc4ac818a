//! The gripper state byte (the high byte of the SIP's "timer" field and byte 2 of the
//! GRIPPERpac) in the two readings that disagree: the vendor's Pioneer Gripper manual
//! (active-high state bits, the beams in DIGIN; the default) and ARIA's General-I/O
//! switches (active low, the beams in the byte). The bits are in [`vc`].

use super::vendor_conventions as vc;

/// How the gripper state byte is written and read (see [`vc::DEFAULT_GRIPPER_BYTE`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum GripperByteLayout {
    /// The Pioneer Gripper manual, Table 4: bit 0 paddles open, 1 closed, 2 moving,
    /// 3 gripper error, 4 lift up, 5 lift down, 6 lift moving, 7 lift error (set = true;
    /// both bits of a pair equal = position unknown); the breakbeams in DIGIN. The
    /// default.
    #[default]
    Manual,
    /// ARIA's General-I/O gripper: the raw switches, active low (`vc::GRIP_SW_*`),
    /// the breakbeams in the byte.
    Aria,
}

impl GripperByteLayout {
    /// The name used in configurations and on command lines (`manual`, `aria`).
    pub fn name(self) -> &'static str {
        match self {
            GripperByteLayout::Manual => "manual",
            GripperByteLayout::Aria => "aria",
        }
    }

    /// Parses [`GripperByteLayout::name`] (case-insensitive).
    pub fn from_name(s: &str) -> Option<GripperByteLayout> {
        if s.eq_ignore_ascii_case("manual") {
            Some(GripperByteLayout::Manual)
        } else if s.eq_ignore_ascii_case("aria") {
            Some(GripperByteLayout::Aria)
        } else {
            None
        }
    }
}

/// The gripper state byte as it comes off the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GripperSwitches(pub u8);

/// The paddles' state as read from the byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PaddleState {
    /// Fully open.
    Open,
    /// Closed (on each other or on an object).
    Closed,
    /// Moving.
    Moving,
    /// Stopped in between, or the position unknown (the manual: both bits equal).
    Between,
    /// The gripper reports an error (the manual's bit 3).
    Error,
}

/// The lift's state as read from the byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LiftState {
    /// At the top.
    Up,
    /// At the bottom.
    Down,
    /// At a limit, which one unknown (ARIA's reading has one limit switch bit).
    AtLimit,
    /// Moving.
    Moving,
    /// Stopped in between, or the position unknown.
    Between,
    /// The lift reports an error (the manual's bit 7).
    Error,
}

/// What a gripper state byte (and, in the manual's layout, DIGIN) says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GripperReading {
    /// The paddles.
    pub paddles: PaddleState,
    /// The lift.
    pub lift: LiftState,
    /// The outer breakbeam is obstructed.
    pub outer_beam: bool,
    /// The inner breakbeam is obstructed.
    pub inner_beam: bool,
}

/// The facts the emulated controller writes into the byte (and DIGIN).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GripperSwitchFacts {
    /// Paddles fully open.
    pub paddles_open: bool,
    /// Left paddle contact (closed on the other paddle or on an object).
    pub left_contact: bool,
    /// Right paddle contact.
    pub right_contact: bool,
    /// Paddles moving.
    pub paddles_moving: bool,
    /// Lift at the top.
    pub lift_up: bool,
    /// Lift at the bottom.
    pub lift_down: bool,
    /// Lift moving.
    pub lift_moving: bool,
    /// Outer breakbeam obstructed.
    pub outer_beam: bool,
    /// Inner breakbeam obstructed.
    pub inner_beam: bool,
    /// The gripper is in error.
    pub gripper_error: bool,
    /// The lift is in error.
    pub lift_error: bool,
}

fn bit(on: bool, b: u8) -> u8 {
    if on { b } else { 0 }
}

impl GripperSwitches {
    /// Encodes the facts in `layout`: the state byte, and the DIGIN bits that carry the
    /// breakbeams in the manual's layout (0 in ARIA's, where they are in the byte).
    /// ARIA's byte has no error bits and one lift limit bit for both ends.
    ///
    /// In the manual's layout a position between the ends is "unknown" (both bits of
    /// the pair equal); it is written as both bits clear for the paddles and both set
    /// for a lift stopped in between, the two forms Player's p2os reads as "moving" (the
    /// paddles' moving bit alone) and "idle in between" (the lift); a moving lift has
    /// both clear (Player reads 0x30 with 0x40 as in between, not moving).
    pub fn encode(f: GripperSwitchFacts, layout: GripperByteLayout) -> (GripperSwitches, u8) {
        match layout {
            GripperByteLayout::Manual => {
                let lift_between = !f.lift_up && !f.lift_down && !f.lift_moving;
                let b = bit(f.paddles_open, vc::GRIP_PADDLES_OPEN)
                    | bit(f.left_contact && f.right_contact, vc::GRIP_PADDLES_CLOSED)
                    | bit(f.paddles_moving, vc::GRIP_PADDLES_MOVING)
                    | bit(f.gripper_error, vc::GRIP_ERROR)
                    | bit(f.lift_up, vc::GRIP_LIFT_UP)
                    | bit(f.lift_down, vc::GRIP_LIFT_DOWN)
                    | bit(f.lift_moving, vc::GRIP_LIFT_MOVING)
                    | bit(lift_between, vc::GRIP_LIFT_UP | vc::GRIP_LIFT_DOWN)
                    | bit(f.lift_error, vc::GRIP_LIFT_ERROR);
                let digin = bit(f.outer_beam, vc::DIGIN_OUTER_BEAM)
                    | bit(f.inner_beam, vc::DIGIN_INNER_BEAM);
                (GripperSwitches(b), digin)
            }
            GripperByteLayout::Aria => {
                let at_limit = (f.lift_up || f.lift_down) && !f.lift_moving;
                let b = bit(!f.paddles_open, vc::GRIP_SW_OPEN_LIMIT_N)
                    | bit(!at_limit, vc::GRIP_SW_LIFT_LIMIT_N)
                    | bit(f.outer_beam, vc::GRIP_SW_OUTER_BEAM)
                    | bit(f.inner_beam, vc::GRIP_SW_INNER_BEAM)
                    | bit(!f.left_contact, vc::GRIP_SW_LEFT_CONTACT_N)
                    | bit(!f.right_contact, vc::GRIP_SW_RIGHT_CONTACT_N)
                    | bit(f.lift_moving, vc::GRIP_SW_LIFT_MOVING)
                    | bit(f.paddles_moving, vc::GRIP_SW_PADDLES_MOVING);
                (GripperSwitches(b), 0)
            }
        }
    }

    /// Reads the byte in `layout`; `digin` is the SIP's DIGIN (the manual's
    /// breakbeams; unused in ARIA's layout).
    pub fn read(self, layout: GripperByteLayout, digin: u8) -> GripperReading {
        let b = self.0;
        let on = |m: u8| b & m != 0;
        match layout {
            GripperByteLayout::Manual => {
                let paddles = if on(vc::GRIP_ERROR) {
                    PaddleState::Error
                } else if on(vc::GRIP_PADDLES_MOVING) {
                    PaddleState::Moving
                } else {
                    match (on(vc::GRIP_PADDLES_OPEN), on(vc::GRIP_PADDLES_CLOSED)) {
                        (true, false) => PaddleState::Open,
                        (false, true) => PaddleState::Closed,
                        // Both equal: the position is unknown.
                        _ => PaddleState::Between,
                    }
                };
                let lift = if on(vc::GRIP_LIFT_ERROR) {
                    LiftState::Error
                } else if on(vc::GRIP_LIFT_MOVING) {
                    LiftState::Moving
                } else {
                    match (on(vc::GRIP_LIFT_UP), on(vc::GRIP_LIFT_DOWN)) {
                        (true, false) => LiftState::Up,
                        (false, true) => LiftState::Down,
                        _ => LiftState::Between,
                    }
                };
                GripperReading {
                    paddles,
                    lift,
                    outer_beam: digin & vc::DIGIN_OUTER_BEAM != 0,
                    inner_beam: digin & vc::DIGIN_INNER_BEAM != 0,
                }
            }
            GripperByteLayout::Aria => {
                let paddles = if on(vc::GRIP_SW_PADDLES_MOVING) {
                    PaddleState::Moving
                } else if !on(vc::GRIP_SW_OPEN_LIMIT_N) {
                    PaddleState::Open
                } else if !on(vc::GRIP_SW_LEFT_CONTACT_N) && !on(vc::GRIP_SW_RIGHT_CONTACT_N) {
                    PaddleState::Closed
                } else {
                    PaddleState::Between
                };
                let lift = if on(vc::GRIP_SW_LIFT_MOVING) {
                    LiftState::Moving
                } else if !on(vc::GRIP_SW_LIFT_LIMIT_N) {
                    LiftState::AtLimit
                } else {
                    LiftState::Between
                };
                GripperReading {
                    paddles,
                    lift,
                    outer_beam: on(vc::GRIP_SW_OUTER_BEAM),
                    inner_beam: on(vc::GRIP_SW_INNER_BEAM),
                }
            }
        }
    }
}
