//! Every place where Player's p2os driver, the vendor's SDK (ARIA) and the
//! vendor's own manuals read the protocol differently, and the reading limber
//! follows. **Where the vendor's manuals speak, they win** (the protocol is
//! theirs, and two of their documents agree); an SDK's different reading is
//! kept as an option where it matters ([`crate::ArmpacLayout`]). Where the
//! manuals are silent, limber follows ARIA (the vendor's code) over Player.
//!
//! Both the decoder in this crate and the emulator (`limber-emulator`) take
//! their bit layouts and magic numbers from here, so a change of mind is one
//! edit. Each item says what Player and ARIA do (see the reference,
//! `player-reference.md` sections 3.3, 3.7, 3.8, 3.9 and 6).

/// ARM_HOME / ARM_STOP argument meaning "all joints", as limber sends it.
///
/// The manuals (Table 2): HOME 75 takes 1..6, or **any value above 6** for
/// all joints; STOP 79 takes 1..6 or 255. Player sends 7 for HOME, ARIA
/// 0xFF. 0xFF is valid for both commands, so limber sends it; the emulator
/// accepts every value the manual allows ([`arm_home_all`], [`arm_stop_all`]).
pub const ARM_ALL_JOINTS: u8 = 0xFF;

/// ARM_HOME's argument means "all joints" (the manuals: any value > 6).
pub fn arm_home_all(arg: u16) -> bool {
    arg > 6
}

/// ARM_STOP's argument means "all joints" (the manuals: 255 only).
pub fn arm_stop_all(arg: u16) -> bool {
    arg == 0xFF
}

/// ARMpac status: the layout limber uses unless configured otherwise: the
/// vendor's manuals' ([`crate::ArmpacLayout::Manual`]).
///
/// The manuals (Pioneer 2 Arm manual, 2001; Pioneer Arm Manual v7.1, 2007,
/// Table 4 "ARMpac contents") say byte 2 (the byte after the type) holds
/// servo power (b0) and the connection between arm and robot controller
/// (b1), and byte 3 the per-joint motion bits (b0..b5 = joints 1..6).
/// Player reads it that way. ARIA's ArP2Arm reads the two bytes as one
/// little-endian word with the motion bits first (low byte) and
/// good/inited/powered/homing in the high byte: the bytes are swapped.
/// Two documents of the protocol's owner outweigh one SDK's code, so the
/// manuals' layout is the default; ARIA's stays selectable (`armpac_layout =
/// "aria"` in the driver's configuration, `--armpac-layout aria` on the
/// emulator) until hardware settles it. The driver warns when packets only
/// make sense in the other layout ([`crate::ArmPacket::suggests_other_layout`]).
pub const DEFAULT_ARMPAC_LAYOUT: crate::ArmpacLayout = crate::ArmpacLayout::Manual;

/// ARMpac motion bits (byte B in the manuals' layout, byte A in ARIA's):
/// bit `j` (0..5) set = joint `j + 1` moving.
pub const ARM_MOVING_MASK: u8 = 0x3F;
/// Manuals' layout, byte A bit 0: servo power on.
pub const MANUAL_A_POWER: u8 = 0x01;
/// Manuals' layout, byte A bit 1: the arm controller is connected to the
/// robot controller.
pub const MANUAL_A_CONNECTED: u8 = 0x02;
/// ARIA's layout, byte B (high byte) bit 0: the arm is good (communicating).
pub const ARIA_HI_GOOD: u8 = 0x01;
/// ARIA's layout, byte B bit 1: the arm controller is initialised.
pub const ARIA_HI_INITED: u8 = 0x02;
/// ARIA's layout, byte B bit 2: the arm servos are powered.
pub const ARIA_HI_POWERED: u8 = 0x04;
/// ARIA's layout, byte B bit 3: the arm is homing.
pub const ARIA_HI_HOMING: u8 = 0x08;

/// Gripper switch byte (General-I/O gripper: high byte of the SIP "timer"
/// field, and byte 2 of the 0xE0 gripper packet), ARIA's **active-low**
/// reading. Player 3 instead reads bit0 = open, bit1 = closed, bit2 = moving
/// (active-high), and its breakbeam test is always 0.
///
/// Bit 0 **clear** = the paddles are fully open (inner limit switch).
pub const GRIP_SW_OPEN_LIMIT_N: u8 = 0x01;
/// Bit 1 **clear** = the lift is at a limit (top or bottom; which one is
/// known from the last lift command).
pub const GRIP_SW_LIFT_LIMIT_N: u8 = 0x02;
/// Bit 2 set = the outer breakbeam is broken.
pub const GRIP_SW_OUTER_BEAM: u8 = 0x04;
/// Bit 3 set = the inner breakbeam is broken.
pub const GRIP_SW_INNER_BEAM: u8 = 0x08;
/// Bit 4 **clear** = the left paddle touches something (closed on an object
/// or on the other paddle).
pub const GRIP_SW_LEFT_CONTACT_N: u8 = 0x10;
/// Bit 5 **clear** = the right paddle touches something.
pub const GRIP_SW_RIGHT_CONTACT_N: u8 = 0x20;
/// Bit 6 set = the lift is moving.
pub const GRIP_SW_LIFT_MOVING: u8 = 0x40;
/// Bit 7 set = the paddles are moving (General-I/O gripper).
pub const GRIP_SW_PADDLES_MOVING: u8 = 0x80;

/// Lift relative moves (GRIPPERVAL after LIFTcarry) with a negative value
/// (downwards) are sent as `ARGNINT` with the magnitude, as ARIA does.
/// Player sends the 16-bit two's complement as `ARGINT`.
pub const LIFT_CARRY_NEGATIVE_AS_ARGNINT: bool = true;

/// ARIA's arm speed range: the "ms per step" byte is 1..=255 (ARIA: 0 is the
/// fastest, 255 the slowest). Player clamps to 1..=127. limber clamps
/// rad/s → ms/step conversions to `[ARM_SPEED_MS_MIN, ARM_SPEED_MS_MAX]`
/// (0 is avoided: its meaning differs between firmware versions).
pub const ARM_SPEED_MS_MIN: u8 = 1;
/// Upper clamp of the "ms per step" byte (ARIA: 255 is the slowest).
pub const ARM_SPEED_MS_MAX: u8 = 255;

/// Tick → angle sign per joint index 0..5 (ARIA and Player agree): joints 0, 1
/// and 2 are negated.
pub const JOINT_SIGN: [f64; 6] = [-1.0, -1.0, -1.0, 1.0, 1.0, 1.0];

/// ARIA treats joint 6 (the gripper servo) as raw ticks; Player converts it
/// to an angle like the others. limber's [`crate::ArmCalibration`]
/// offers both (`ticks_to_radians` for any joint, raw ticks via
/// [`crate::JointCalibration`]); drivers should command the gripper
/// joint in raw ticks (open = max, close = min).
pub const GRIPPER_JOINT_RAW_TICKS: bool = true;

/// Command number of ARIA's gripper packet request (37): ARGINT 2 starts a
/// 0xE0 gripper packet every cycle, 0 stops it. Player never sends it.
pub const GRIPPER_PACKET_REQUEST: u8 = 37;
