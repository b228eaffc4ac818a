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

/// Gripper state byte: the layout limber uses unless configured otherwise: the
/// vendor's manual's ([`crate::GripperByteLayout::Manual`]).
///
/// The byte is the high byte of the SIP's "timer" field (just after the sonar
/// readings) and byte 2 of the GRIPPERpac (0xE0). The Pioneer Gripper manual
/// (Table 4 "Gripper State Byte") reads it **active high**: bit 0 paddles
/// open, 1 paddles closed, 2 paddles moving, 3 gripper error, 4 lift up, 5
/// lift down, 6 lift moving, 7 lift error; both bits of a pair equal = that
/// position unknown; the breakbeams are in DIGIN ([`DIGIN_OUTER_BEAM`],
/// [`DIGIN_INNER_BEAM`], 1 = obstructed). Player 2.0 documented the same and
/// Player 3 decodes bits 0..2 that way (its beam test is always 0). ARIA reads
/// the byte as the General-I/O gripper's raw switches, **active low**
/// (`GRIP_SW_*` below); a client reading one layout from a robot writing the
/// other sees a closed gripper OPEN and the lift STALLED. The manual wins;
/// ARIA's stays selectable (`gripper_byte = "aria"` in the driver's
/// configuration, `--gripper-byte aria` on the emulator).
pub const DEFAULT_GRIPPER_BYTE: crate::GripperByteLayout = crate::GripperByteLayout::Manual;

/// Manual's state byte, bit 0: paddles open.
pub const GRIP_PADDLES_OPEN: u8 = 0x01;
/// Manual's state byte, bit 1: paddles closed.
pub const GRIP_PADDLES_CLOSED: u8 = 0x02;
/// Manual's state byte, bit 2: paddles moving.
pub const GRIP_PADDLES_MOVING: u8 = 0x04;
/// Manual's state byte, bit 3: gripper error.
pub const GRIP_ERROR: u8 = 0x08;
/// Manual's state byte, bit 4: lift up.
pub const GRIP_LIFT_UP: u8 = 0x10;
/// Manual's state byte, bit 5: lift down.
pub const GRIP_LIFT_DOWN: u8 = 0x20;
/// Manual's state byte, bit 6: lift moving.
pub const GRIP_LIFT_MOVING: u8 = 0x40;
/// Manual's state byte, bit 7: lift error.
pub const GRIP_LIFT_ERROR: u8 = 0x80;
/// DIGIN bit 2 (the User I/O port): the outer breakbeam is obstructed (the
/// manual: 1 = obstructed; the bit as Player 2.0 documented the beams byte).
pub const DIGIN_OUTER_BEAM: u8 = 0x04;
/// DIGIN bit 3: the inner breakbeam is obstructed.
pub const DIGIN_INNER_BEAM: u8 = 0x08;

/// ARIA's reading of the same byte (the General-I/O gripper's switches,
/// [`crate::GripperByteLayout::Aria`]):
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
