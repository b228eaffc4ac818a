//! Typed robot → client packets, with their encoders (used by the emulator).

use super::codec::{EncodeError, Frame, PayloadBuilder};
use super::command::ArmJoint;
use super::gripper_byte::{GripperByteLayout, GripperReading, GripperSwitches};
use super::vendor_conventions as vc;
use thiserror::Error;

/// Robot → client packet types (payload byte 0).
pub mod ptype {
    /// Standard SIP, lowest type value.
    pub const SIP_FIRST: u8 = 0x30;
    /// Standard SIP, motors stopped.
    pub const SIP_STOPPED: u8 = 0x32;
    /// Standard SIP, motors moving.
    pub const SIP_MOVING: u8 = 0x33;
    /// Standard SIP, highest type value.
    pub const SIP_LAST: u8 = 0x34;
    /// CONFIGpac.
    pub const CONFIG: u8 = 0x20;
    /// ARMpac.
    pub const ARM: u8 = 0xA0;
    /// ARMINFOpac.
    pub const ARM_INFO: u8 = 0xA1;
    /// The GRIPPERpac (the Pioneer Gripper manual; ARIA's gripper packet), answering
    /// GRIPREQUEST (37).
    pub const GRIPPER: u8 = 0xE0;
}

/// Why a robot packet could not be parsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum PacketError {
    /// The payload is empty.
    #[error("empty packet")]
    Empty,
    /// The payload is shorter than its type requires.
    #[error("packet type {packet_type:#04x}: {len} bytes is too short (need {need})")]
    TooShort {
        /// Packet type byte.
        packet_type: u8,
        /// Payload length.
        len: usize,
        /// Minimum length.
        need: usize,
    },
    /// An ARMpac whose length is not exactly 9 payload bytes (N = 11).
    #[error("ARMpac payload of {0} bytes (expected 9)")]
    ArmPacketLength(usize),
    /// An ARMINFOpac without the NUL ending its version string.
    #[error("ARMINFOpac version string is not terminated")]
    ArmInfoVersion,
    /// An ARMINFOpac announcing more joints than the arm has (6).
    #[error("ARMINFOpac announces {0} joints (at most 6)")]
    ArmInfoJoints(u8),
    /// A SIP announcing more sonar readings than [`MAX_SONAR`].
    #[error("SIP announces {0} sonar readings (at most {MAX_SONAR})")]
    TooManySonars(u8),
}

/// Maximum number of sonar readings a [`Sip`] holds.
pub const MAX_SONAR: usize = 32;

/// One sonar reading of a SIP.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SonarReading {
    /// Sonar index.
    pub index: u8,
    /// Raw range (× RangeConvFactor = mm).
    pub range: u16,
}

/// A standard SIP (types 0x30..=0x34). Raw units, as on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sip {
    /// Type byte (0x32 stopped, 0x33 moving).
    pub packet_type: u8,
    /// Raw x position.
    pub x: u16,
    /// Raw y position.
    pub y: u16,
    /// Heading (× AngleConvFactor rad).
    pub heading: i16,
    /// Left wheel velocity (× VelConvFactor mm/s).
    pub left_vel: i16,
    /// Right wheel velocity.
    pub right_vel: i16,
    /// Battery, 0.1 V units.
    pub battery: u8,
    /// Bit 0 left stall, bits 1..7 rear bumpers.
    pub left_stall: u8,
    /// Bit 0 right stall, bits 1..7 front bumpers.
    pub right_stall: u8,
    /// Setpoint heading.
    pub control: i16,
    /// PTU (unused).
    pub ptu: u16,
    /// Compass, 2° units.
    pub compass: u8,
    sonar_count: u8,
    sonars: [SonarReading; MAX_SONAR],
    /// "Timer" field; its high byte is the gripper switch byte.
    pub timer: u16,
    /// Selected analog input.
    pub analog: u8,
    /// Digital inputs.
    pub digin: u8,
    /// Digital outputs.
    pub digout: u8,
}

impl Default for Sip {
    fn default() -> Self {
        Sip {
            packet_type: ptype::SIP_STOPPED,
            x: 0,
            y: 0,
            heading: 0,
            left_vel: 0,
            right_vel: 0,
            battery: 130,
            left_stall: 0,
            right_stall: 0,
            control: 0,
            ptu: 0,
            compass: 0,
            sonar_count: 0,
            sonars: [SonarReading::default(); MAX_SONAR],
            timer: 0,
            analog: 0,
            digin: 0,
            digout: 0,
        }
    }
}

fn le16(p: &[u8], i: usize) -> u16 {
    u16::from_le_bytes([p[i], p[i + 1]])
}

impl Sip {
    /// Minimum payload: fields up to the sonar count (20) + timer, analog,
    /// digin, digout (5).
    pub const MIN_LEN: usize = 25;

    /// Parses a SIP payload (type byte first).
    pub fn parse(p: &[u8]) -> Result<Sip, PacketError> {
        let short = |need: usize| PacketError::TooShort {
            packet_type: p.first().copied().unwrap_or(0),
            len: p.len(),
            need,
        };
        if p.len() < Self::MIN_LEN {
            return Err(short(Self::MIN_LEN));
        }
        let n = p[19];
        if usize::from(n) > MAX_SONAR {
            return Err(PacketError::TooManySonars(n));
        }
        let tail = 20 + 3 * usize::from(n);
        if p.len() < tail + 5 {
            return Err(short(tail + 5));
        }
        let mut sonars = [SonarReading::default(); MAX_SONAR];
        for (k, s) in sonars.iter_mut().take(usize::from(n)).enumerate() {
            let o = 20 + 3 * k;
            *s = SonarReading {
                index: p[o],
                range: le16(p, o + 1),
            };
        }
        Ok(Sip {
            packet_type: p[0],
            x: le16(p, 1),
            y: le16(p, 3),
            heading: le16(p, 5) as i16,
            left_vel: le16(p, 7) as i16,
            right_vel: le16(p, 9) as i16,
            battery: p[11],
            left_stall: p[12],
            right_stall: p[13],
            control: le16(p, 14) as i16,
            ptu: le16(p, 16),
            compass: p[18],
            sonar_count: n,
            sonars,
            timer: le16(p, tail),
            analog: p[tail + 2],
            digin: p[tail + 3],
            digout: p[tail + 4],
        })
    }

    /// The sonar readings.
    pub fn sonars(&self) -> &[SonarReading] {
        &self.sonars[..usize::from(self.sonar_count).min(MAX_SONAR)]
    }

    /// Replaces the sonar readings (at most [`MAX_SONAR`] are kept).
    pub fn set_sonars(&mut self, readings: &[SonarReading]) {
        let n = readings.len().min(MAX_SONAR);
        self.sonars[..n].copy_from_slice(&readings[..n]);
        self.sonar_count = n as u8;
    }

    /// The base motors are moving (type 0x33).
    pub fn motors_moving(&self) -> bool {
        self.packet_type == ptype::SIP_MOVING
    }

    /// The gripper switch byte (high byte of the timer field).
    pub fn gripper_switches(&self) -> GripperSwitches {
        GripperSwitches((self.timer >> 8) as u8)
    }

    /// The gripper's state and breakbeams as `layout` reads the switch byte (the
    /// manual's: the beams in [`Sip::digin`]; ARIA's: in the byte).
    pub fn gripper_reading(&self, layout: GripperByteLayout) -> GripperReading {
        self.gripper_switches().read(layout, self.digin)
    }

    /// Encodes the SIP (type byte first).
    pub fn encode(&self) -> Result<Frame, EncodeError> {
        let mut b = PayloadBuilder::new(self.packet_type);
        b.u16_le(self.x)
            .u16_le(self.y)
            .u16_le(self.heading as u16)
            .u16_le(self.left_vel as u16)
            .u16_le(self.right_vel as u16)
            .byte(self.battery)
            .byte(self.left_stall)
            .byte(self.right_stall)
            .u16_le(self.control as u16)
            .u16_le(self.ptu)
            .byte(self.compass)
            .byte(self.sonar_count);
        for s in self.sonars() {
            b.byte(s.index).u16_le(s.range);
        }
        b.u16_le(self.timer)
            .byte(self.analog)
            .byte(self.digin)
            .byte(self.digout);
        b.frame()
    }
}

/// How the two status bytes of an ARMpac are read (see [`vc`] and the
/// reference, section 3.8). The vendor's manuals and ARIA disagree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum ArmpacLayout {
    /// The vendor's manuals (Pioneer 2 Arm manual, 2001; Pioneer Arm Manual
    /// v7.1, 2007, Table 4), which Player also reads: byte A bit 0 = servo
    /// power, bit 1 = arm controller connected; byte B bits 0..5 = joint
    /// 1..6 moving. The default.
    #[default]
    Manual,
    /// ARIA's ArP2Arm: A and B form one little-endian word. A (low) bits
    /// 0..5 = joint 1..6 moving; B (high) bit 0 = good, 1 = initialised,
    /// 2 = powered, 3 = homing.
    Aria,
}

impl ArmpacLayout {
    /// The other reading.
    pub fn other(self) -> ArmpacLayout {
        match self {
            ArmpacLayout::Manual => ArmpacLayout::Aria,
            ArmpacLayout::Aria => ArmpacLayout::Manual,
        }
    }

    /// The name used in configurations and on command lines (`manual`, `aria`).
    pub fn name(self) -> &'static str {
        match self {
            ArmpacLayout::Manual => "manual",
            ArmpacLayout::Aria => "aria",
        }
    }

    /// Parses [`ArmpacLayout::name`] (case-insensitive).
    pub fn from_name(s: &str) -> Option<ArmpacLayout> {
        if s.eq_ignore_ascii_case("manual") {
            Some(ArmpacLayout::Manual)
        } else if s.eq_ignore_ascii_case("aria") {
            Some(ArmpacLayout::Aria)
        } else {
            None
        }
    }
}

impl std::fmt::Display for ArmpacLayout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The arm status an ARMpac carries, independent of the byte layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ArmStatus {
    /// Bits 0..5: joints 1..6 moving.
    pub moving: u8,
    /// The arm servos are powered.
    pub powered: bool,
    /// The arm controller is in contact with the robot controller (the
    /// manuals' "connection"; ARIA's "good").
    pub connected: bool,
    /// ARIA only: the arm controller is initialised (read as `connected`
    /// in the manuals' layout, which has no such bit).
    pub inited: bool,
    /// ARIA only: the arm is homing (always false in the manuals' layout,
    /// where a homing arm shows as moving joints).
    pub homing: bool,
}

impl ArmStatus {
    /// The joint is moving.
    pub fn joint_moving(&self, joint: ArmJoint) -> bool {
        self.moving & (1 << joint.index()) != 0
    }

    /// Bits 0..5: joints 1..6 moving.
    pub fn moving_mask(&self) -> u8 {
        self.moving & vc::ARM_MOVING_MASK
    }
}

/// An ARMpac (0xA0): the two raw status bytes and the current tick of each
/// joint. Read the status with [`ArmPacket::status`] and a layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ArmPacket {
    /// Status bytes A and B (payload bytes 1 and 2), as on the wire.
    pub status_bytes: [u8; 2],
    /// Current tick of joints 1..6 (index 0..5).
    pub ticks: [u8; 6],
}

impl ArmPacket {
    /// Payload length of an ARMpac (N = 11).
    pub const LEN: usize = 9;

    /// Builds an ARMpac carrying `status` in `layout`.
    pub fn new(status: ArmStatus, layout: ArmpacLayout, ticks: [u8; 6]) -> ArmPacket {
        let moving = status.moving & vc::ARM_MOVING_MASK;
        let flag = |b: bool, bit: u8| if b { bit } else { 0 };
        let status_bytes = match layout {
            ArmpacLayout::Manual => [
                flag(status.powered, vc::MANUAL_A_POWER)
                    | flag(status.connected, vc::MANUAL_A_CONNECTED),
                moving,
            ],
            ArmpacLayout::Aria => [
                moving,
                flag(status.connected, vc::ARIA_HI_GOOD)
                    | flag(status.inited, vc::ARIA_HI_INITED)
                    | flag(status.powered, vc::ARIA_HI_POWERED)
                    | flag(status.homing, vc::ARIA_HI_HOMING),
            ],
        };
        ArmPacket {
            status_bytes,
            ticks,
        }
    }

    /// Parses an ARMpac payload.
    pub fn parse(p: &[u8]) -> Result<ArmPacket, PacketError> {
        if p.len() != Self::LEN {
            return Err(PacketError::ArmPacketLength(p.len()));
        }
        let mut ticks = [0u8; 6];
        ticks.copy_from_slice(&p[3..9]);
        Ok(ArmPacket {
            status_bytes: [p[1], p[2]],
            ticks,
        })
    }

    /// Encodes the ARMpac.
    pub fn encode(&self) -> Result<Frame, EncodeError> {
        let mut pb = PayloadBuilder::new(ptype::ARM);
        pb.bytes(&self.status_bytes).bytes(&self.ticks);
        pb.frame()
    }

    /// The status, read in `layout`.
    pub fn status(&self, layout: ArmpacLayout) -> ArmStatus {
        let [a, b] = self.status_bytes;
        match layout {
            ArmpacLayout::Manual => {
                let connected = a & vc::MANUAL_A_CONNECTED != 0;
                ArmStatus {
                    moving: b & vc::ARM_MOVING_MASK,
                    powered: a & vc::MANUAL_A_POWER != 0,
                    connected,
                    inited: connected,
                    homing: false,
                }
            }
            ArmpacLayout::Aria => ArmStatus {
                moving: a & vc::ARM_MOVING_MASK,
                powered: b & vc::ARIA_HI_POWERED != 0,
                connected: b & vc::ARIA_HI_GOOD != 0,
                inited: b & vc::ARIA_HI_INITED != 0,
                homing: b & vc::ARIA_HI_HOMING != 0,
            },
        }
    }

    /// Whether the status bytes describe a possible arm in `layout`: no bit
    /// outside the layout's fields is set, and joints move only while the
    /// arm is connected and powered (the manuals: the arm neither moves nor
    /// updates positions otherwise). A powered, idle arm, and an unpowered
    /// but connected one, are told apart by this: each layout reads the
    /// other's bytes as joints moving on an arm that is off or absent.
    pub fn plausible(&self, layout: ArmpacLayout) -> bool {
        let [a, b] = self.status_bytes;
        let (unknown, s) = match layout {
            ArmpacLayout::Manual => (
                a & !(vc::MANUAL_A_POWER | vc::MANUAL_A_CONNECTED) != 0
                    || b & !vc::ARM_MOVING_MASK != 0,
                self.status(layout),
            ),
            ArmpacLayout::Aria => (
                a & !vc::ARM_MOVING_MASK != 0
                    || b & !(vc::ARIA_HI_GOOD
                        | vc::ARIA_HI_INITED
                        | vc::ARIA_HI_POWERED
                        | vc::ARIA_HI_HOMING)
                        != 0,
                self.status(layout),
            ),
        };
        !unknown && (s.moving == 0 || (s.powered && s.connected))
    }

    /// The packet cannot come from an arm in `layout` but can in the other:
    /// the robot most likely uses the other layout.
    pub fn suggests_other_layout(&self, layout: ArmpacLayout) -> bool {
        !self.plausible(layout) && self.plausible(layout.other())
    }

    /// Tick of a joint.
    pub fn tick(&self, joint: ArmJoint) -> u8 {
        self.ticks[joint.index()]
    }
}

/// Calibration of one arm joint from ARMINFOpac (all raw ticks).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct JointCalibration {
    /// Default speed, ms per step.
    pub speed: u8,
    /// Home tick.
    pub home: u8,
    /// Minimum tick.
    pub min: u8,
    /// Centre tick (angle 0).
    pub centre: u8,
    /// Maximum tick.
    pub max: u8,
    /// Ticks per 90 degrees.
    pub ticks_per_90: u8,
}

/// Longest ARMINFOpac version string kept.
pub const MAX_VERSION: usize = 64;

/// An ARMINFOpac (0xA1): firmware version and per-joint calibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArmInfo {
    version: [u8; MAX_VERSION],
    version_len: u8,
    /// Number of joints (6 on the Pioneer arm, including the gripper).
    pub num_joints: u8,
    /// Calibration of joints 1..num_joints (index 0..).
    pub joints: [JointCalibration; 6],
}

impl ArmInfo {
    /// Builds an ARMINFOpac (the version is cut at [`MAX_VERSION`] bytes and
    /// at any NUL).
    pub fn new(version: &str, joints: &[JointCalibration]) -> ArmInfo {
        let v = version.as_bytes();
        let v = &v[..v.iter().position(|&c| c == 0).unwrap_or(v.len())];
        let n = v.len().min(MAX_VERSION);
        let mut buf = [0u8; MAX_VERSION];
        buf[..n].copy_from_slice(&v[..n]);
        let mut js = [JointCalibration::default(); 6];
        let nj = joints.len().min(6);
        js[..nj].copy_from_slice(&joints[..nj]);
        ArmInfo {
            version: buf,
            version_len: n as u8,
            num_joints: nj as u8,
            joints: js,
        }
    }

    /// Parses an ARMINFOpac payload.
    pub fn parse(p: &[u8]) -> Result<ArmInfo, PacketError> {
        let rest = p.get(1..).ok_or(PacketError::Empty)?;
        let nul = rest
            .iter()
            .position(|&c| c == 0)
            .ok_or(PacketError::ArmInfoVersion)?;
        let version = &rest[..nul];
        let rest = &rest[nul + 1..];
        let (&nj, rest) = rest.split_first().ok_or(PacketError::TooShort {
            packet_type: ptype::ARM_INFO,
            len: p.len(),
            need: p.len() + 1,
        })?;
        if nj > 6 {
            return Err(PacketError::ArmInfoJoints(nj));
        }
        if rest.len() < 6 * usize::from(nj) {
            return Err(PacketError::TooShort {
                packet_type: ptype::ARM_INFO,
                len: p.len(),
                need: p.len() - rest.len() + 6 * usize::from(nj),
            });
        }
        let mut joints = [JointCalibration::default(); 6];
        for (j, c) in rest.chunks_exact(6).take(usize::from(nj)).enumerate() {
            joints[j] = JointCalibration {
                speed: c[0],
                home: c[1],
                min: c[2],
                centre: c[3],
                max: c[4],
                ticks_per_90: c[5],
            };
        }
        let mut info = ArmInfo::new("", &joints[..usize::from(nj)]);
        let n = version.len().min(MAX_VERSION);
        info.version[..n].copy_from_slice(&version[..n]);
        info.version_len = n as u8;
        Ok(info)
    }

    /// Encodes the ARMINFOpac.
    pub fn encode(&self) -> Result<Frame, EncodeError> {
        let mut b = PayloadBuilder::new(ptype::ARM_INFO);
        b.bytes(self.version_bytes()).byte(0).byte(self.num_joints);
        for c in self.calibrations() {
            b.bytes(&[c.speed, c.home, c.min, c.centre, c.max, c.ticks_per_90]);
        }
        b.frame()
    }

    /// The raw version string.
    pub fn version_bytes(&self) -> &[u8] {
        &self.version[..usize::from(self.version_len)]
    }

    /// The version string, lossily decoded.
    pub fn version(&self) -> String {
        String::from_utf8_lossy(self.version_bytes()).into_owned()
    }

    /// Calibrations of the joints announced.
    pub fn calibrations(&self) -> &[JointCalibration] {
        &self.joints[..usize::from(self.num_joints).min(6)]
    }
}

/// The GRIPPERpac (0xE0), sent once after GRIPREQUEST (37) with argument 1, every cycle
/// with 2 (the Pioneer Gripper manual; ARIA's ArGripper reads it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GripperPacket {
    /// HAS GRIPPER, the gripper type (the Pioneer Gripper manual): 0 none, 1 the Pioneer
    /// 2/3 gripper, 2 the PeopleBot's.
    pub gripper_type: u8,
    /// The switch byte.
    pub switches: GripperSwitches,
    /// Grasp time, 20 ms units.
    pub grasp_time: u8,
}

impl GripperPacket {
    /// Parses a 0xE0 payload (extra trailing bytes are ignored).
    pub fn parse(p: &[u8]) -> Result<GripperPacket, PacketError> {
        if p.len() < 4 {
            return Err(PacketError::TooShort {
                packet_type: ptype::GRIPPER,
                len: p.len(),
                need: 4,
            });
        }
        Ok(GripperPacket {
            gripper_type: p[1],
            switches: GripperSwitches(p[2]),
            grasp_time: p[3],
        })
    }

    /// The gripper's state as `layout` reads the packet's switch byte; the manual's
    /// layout takes the breakbeams from `digin` (the SIP's DIGIN), which this packet
    /// does not carry.
    pub fn reading(&self, layout: GripperByteLayout, digin: u8) -> GripperReading {
        self.switches.read(layout, digin)
    }

    /// Encodes the gripper packet.
    pub fn encode(&self) -> Result<Frame, EncodeError> {
        let mut b = PayloadBuilder::new(ptype::GRIPPER);
        b.byte(self.gripper_type)
            .byte(self.switches.0)
            .byte(self.grasp_time);
        b.frame()
    }
}

/// The identity strings of a SYNC2 reply.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RobotIdentity {
    /// Robot (or simulator) name.
    pub name: String,
    /// Robot class, e.g. "Pioneer".
    pub class: String,
    /// Robot subclass, e.g. "p3dx".
    pub subclass: String,
}

impl RobotIdentity {
    /// Parses the bytes after the SYNC2 command byte: three NUL-terminated
    /// strings (missing ones are empty).
    pub fn parse(bytes: &[u8]) -> RobotIdentity {
        let mut parts = bytes
            .split(|&b| b == 0)
            .map(|s| String::from_utf8_lossy(s).into_owned());
        RobotIdentity {
            name: parts.next().unwrap_or_default(),
            class: parts.next().unwrap_or_default(),
            subclass: parts.next().unwrap_or_default(),
        }
    }

    /// Encodes a SYNC2 reply carrying this identity.
    pub fn encode_sync2(&self) -> Result<Frame, EncodeError> {
        let mut b = PayloadBuilder::new(2);
        for s in [&self.name, &self.class, &self.subclass] {
            b.bytes(s.as_bytes()).byte(0);
        }
        b.frame()
    }
}

/// A robot → client packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RobotPacket<'a> {
    /// Reply to SYNC0/1/2 (step 0..2); for step 2 `rest` holds the identity
    /// (see [`RobotIdentity::parse`]).
    Sync {
        /// Sync step 0, 1 or 2.
        step: u8,
        /// Bytes after the step byte.
        rest: &'a [u8],
    },
    /// A standard SIP.
    Sip(Sip),
    /// An ARMpac.
    Arm(ArmPacket),
    /// An ARMINFOpac.
    ArmInfo(ArmInfo),
    /// A 0xE0 gripper packet.
    Gripper(GripperPacket),
    /// Any other packet type.
    Other {
        /// Type byte.
        packet_type: u8,
        /// Whole payload.
        payload: &'a [u8],
    },
}

impl<'a> RobotPacket<'a> {
    /// Parses a payload (type byte first). Does not allocate.
    pub fn parse(p: &'a [u8]) -> Result<RobotPacket<'a>, PacketError> {
        let &t = p.first().ok_or(PacketError::Empty)?;
        Ok(match t {
            0..=2 => RobotPacket::Sync {
                step: t,
                rest: &p[1..],
            },
            ptype::SIP_FIRST..=ptype::SIP_LAST => RobotPacket::Sip(Sip::parse(p)?),
            ptype::ARM => RobotPacket::Arm(ArmPacket::parse(p)?),
            ptype::ARM_INFO => RobotPacket::ArmInfo(ArmInfo::parse(p)?),
            ptype::GRIPPER => RobotPacket::Gripper(GripperPacket::parse(p)?),
            _ => RobotPacket::Other {
                packet_type: t,
                payload: p,
            },
        })
    }
}
