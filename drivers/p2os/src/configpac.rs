//! The CONFIGpac (packet type 0x20), the controller's answer to the CONFIG command (18,
//! no argument): its type, name and serial number, its FLASH limits and working values,
//! and which accessories it has, among them the body gripper.
//!
//! Layout (the vendor's operations manuals, AROS/ARCOS "Table 8. CONFIGpac contents";
//! the AmigoBot and Pioneer LX manuals give the same order; `int` = 2 bytes little
//! endian, `str` = NUL-terminated):
//!
//! | field | type | | field | type |
//! |---|---|---|---|---|
//! | ROBOT TYPE | str | | GRIPPER | int |
//! | SUBTYPE | str | | FRONTSONAR | int |
//! | SERIALNUM | str | | REARSONAR | byte |
//! | 4MOTS | byte | | LOWBATTERY | int |
//! | ROTVELTOP | int | | REVCOUNT | int |
//! | TRANSVELTOP | int | | WATCHDOG | int |
//! | ROTACCTOP | int | | P2MPACS | byte |
//! | TRANSACCTOP | int | | STALLVAL | int |
//! | PWMMAX | int | | STALLCOUNT | int |
//! | NAME | str | | JOYVEL, JOYRVEL | int |
//! | SIPCYCLE | byte | | ROTVELMAX .. TRANSKI (12) | int |
//! | HOSTBAUD | byte | | AROS 1.6: FRONTBUMPS, REARBUMPS | byte |
//! | AUX1BAUD | byte | | AROS 1.7: CHARGER; 1.8: SONARCYCLE, AUTOBAUD, HASGYRO | byte |
//!
//! Later firmware appends more (drift factor, AUX2/AUX3 baud, ticks per mm, version
//! strings, ...): counted in [`ConfigPacket::extra_len`], not read.
//!
//! **What could not be read in the manual here**: the rows between AUX1BAUD and
//! WATCHDOG. Their widths above are those of two independent programs of the vendor that
//! agree: ARIA's `ArRobotConfigPacketReader` (reads GRIPPER and FRONTSONAR as 2 bytes,
//! REARSONAR as 1) and MobileSim/AMRISim's CONFIG reply (writes them so, with the comment
//! that REARSONAR's single byte "is correct"). Both treat GRIPPER as "has a gripper"
//! (non-zero = yes), as limber does ([`ConfigPacket::has_gripper`]); the gripper's *type*
//! is in the GRIPPERpac (0xE0, see [`crate::GripperPacket`]).
//!
//! [`ConfigPacket::parse`] needs every field of the base table (up to TRANSKI): a packet
//! that ends earlier, or inside a string, is an error naming the field, never a guess.
//! The AROS 1.6/1.7/1.8 groups are read when present, whole.

use super::codec::{EncodeError, Frame, PayloadBuilder};
use super::packet::ptype;
use thiserror::Error;

/// Why a payload is not a CONFIGpac limber can read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum ConfigPacketError {
    /// The payload is empty.
    #[error("empty packet")]
    Empty,
    /// The packet type is not 0x20.
    #[error("packet type {0:#04x} is not a CONFIGpac (0x20)")]
    WrongType(u8),
    /// The payload ends before (or inside) a field the layout requires.
    #[error("CONFIGpac of {len} bytes ends inside field {field} (at byte {offset})")]
    Truncated {
        /// The field (the manual's name).
        field: &'static str,
        /// Where the field starts in the payload.
        offset: usize,
        /// Payload length.
        len: usize,
    },
}

/// The working values of the drive (the manual's ROTVELMAX .. TRANSKI).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ConfigWorking {
    /// ROTVELMAX: current maximum rotational speed, deg/s.
    pub rot_vel_max: u16,
    /// TRANSVELMAX: current maximum translational speed, mm/s.
    pub trans_vel_max: u16,
    /// ROTACC: rotational acceleration, deg/s².
    pub rot_acc: u16,
    /// ROTDECEL: rotational deceleration, deg/s².
    pub rot_decel: u16,
    /// ROTKP: rotation PID proportional term.
    pub rot_kp: u16,
    /// ROTKV: rotation PID derivative term.
    pub rot_kv: u16,
    /// ROTKI: rotation PID integral term.
    pub rot_ki: u16,
    /// TRANSACC: translational acceleration, mm/s².
    pub trans_acc: u16,
    /// TRANSDECEL: translational deceleration, mm/s².
    pub trans_decel: u16,
    /// TRANSKP: translation PID proportional term.
    pub trans_kp: u16,
    /// TRANSKV: translation PID derivative term.
    pub trans_kv: u16,
    /// TRANSKI: translation PID integral term.
    pub trans_ki: u16,
}

/// A CONFIGpac (0x20): the fields in the manual's order, raw units.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ConfigPacket {
    /// ROBOT TYPE, e.g. "Pioneer".
    pub robot_type: String,
    /// SUBTYPE, e.g. "p3dx-sh".
    pub subtype: String,
    /// SERIALNUM.
    pub serial_number: String,
    /// 4MOTS (1 = a P2AT with P2OS; antiquated).
    pub four_mots: u8,
    /// ROTVELTOP: maximum rotational speed, deg/s.
    pub rot_vel_top: u16,
    /// TRANSVELTOP: maximum translational speed, mm/s.
    pub trans_vel_top: u16,
    /// ROTACCTOP: maximum rotational (de)acceleration, deg/s².
    pub rot_acc_top: u16,
    /// TRANSACCTOP: maximum translational (de)acceleration, mm/s².
    pub trans_acc_top: u16,
    /// PWMMAX: maximum motor PWM.
    pub pwm_max: u16,
    /// NAME: the robot's name.
    pub name: String,
    /// SIPCYCLE: server information packet cycle, ms.
    pub sip_cycle_ms: u8,
    /// HOSTBAUD: 0 = 9600, 1 = 19200, 2 = 38400, 3 = 57600, 4 = 115200.
    pub host_baud: u8,
    /// AUX1BAUD (same code as HOSTBAUD).
    pub aux1_baud: u8,
    /// GRIPPER: non-zero = the body gripper is fitted (see the module's note on width).
    pub gripper: u16,
    /// FRONTSONAR: non-zero = the front sonar ring is fitted.
    pub front_sonar: u16,
    /// REARSONAR: non-zero = the rear sonar ring is fitted.
    pub rear_sonar: u8,
    /// LOWBATTERY: low-battery alarm, decivolts.
    pub low_battery: u16,
    /// REVCOUNT: encoder counts per wheel revolution.
    pub rev_count: u16,
    /// WATCHDOG: ms without a client command before the robot stops.
    pub watchdog_ms: u16,
    /// P2MPACS: 1 enables the alternative SIP.
    pub p2mpacs: u8,
    /// STALLVAL: PWM above which a stall is declared.
    pub stall_val: u16,
    /// STALLCOUNT: ms of recovery after a stall.
    pub stall_count: u16,
    /// JOYVEL: joystick translational speed, mm/s.
    pub joy_vel: u16,
    /// JOYRVEL: joystick rotational speed, deg/s.
    pub joy_rot_vel: u16,
    /// ROTVELMAX .. TRANSKI.
    pub working: ConfigWorking,
    /// AROS 1.6: FRONTBUMPS and REARBUMPS (bumper segments), when sent.
    pub bumpers: Option<(u8, u8)>,
    /// AROS 1.7: CHARGER (0 none, 1 P3, 2 PowerBot), when sent.
    pub charger: Option<u8>,
    /// AROS 1.8: SONARCYCLE (ms), AUTOBAUD, HASGYRO, when sent.
    pub aros18: Option<(u8, u8, u8)>,
    /// Bytes after the last field read (later firmware's additions), not interpreted.
    pub extra_len: usize,
}

struct Reader<'a> {
    p: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn short(&self, field: &'static str) -> ConfigPacketError {
        ConfigPacketError::Truncated {
            field,
            offset: self.at,
            len: self.p.len(),
        }
    }

    fn left(&self) -> usize {
        self.p.len() - self.at
    }

    fn byte(&mut self, field: &'static str) -> Result<u8, ConfigPacketError> {
        let b = *self.p.get(self.at).ok_or_else(|| self.short(field))?;
        self.at += 1;
        Ok(b)
    }

    fn int(&mut self, field: &'static str) -> Result<u16, ConfigPacketError> {
        match self.p.get(self.at..self.at + 2) {
            Some(&[lo, hi]) => {
                self.at += 2;
                Ok(u16::from_le_bytes([lo, hi]))
            }
            _ => Err(self.short(field)),
        }
    }

    fn string(&mut self, field: &'static str) -> Result<String, ConfigPacketError> {
        let rest = self.p.get(self.at..).unwrap_or_default();
        let nul = rest
            .iter()
            .position(|&c| c == 0)
            .ok_or_else(|| self.short(field))?;
        let s = String::from_utf8_lossy(&rest[..nul]).into_owned();
        self.at += nul + 1;
        Ok(s)
    }
}

impl ConfigPacket {
    /// Parses a CONFIGpac payload (type byte first). Every field of the base table is
    /// required; the AROS 1.6/1.7/1.8 groups are read when the packet carries them whole;
    /// further bytes are counted in [`ConfigPacket::extra_len`].
    pub fn parse(p: &[u8]) -> Result<ConfigPacket, ConfigPacketError> {
        let &t = p.first().ok_or(ConfigPacketError::Empty)?;
        if t != ptype::CONFIG {
            return Err(ConfigPacketError::WrongType(t));
        }
        let mut r = Reader { p, at: 1 };
        let mut c = ConfigPacket {
            robot_type: r.string("ROBOT TYPE")?,
            subtype: r.string("SUBTYPE")?,
            serial_number: r.string("SERIALNUM")?,
            four_mots: r.byte("4MOTS")?,
            rot_vel_top: r.int("ROTVELTOP")?,
            trans_vel_top: r.int("TRANSVELTOP")?,
            rot_acc_top: r.int("ROTACCTOP")?,
            trans_acc_top: r.int("TRANSACCTOP")?,
            pwm_max: r.int("PWMMAX")?,
            name: r.string("NAME")?,
            sip_cycle_ms: r.byte("SIPCYCLE")?,
            host_baud: r.byte("HOSTBAUD")?,
            aux1_baud: r.byte("AUX1BAUD")?,
            gripper: r.int("GRIPPER")?,
            front_sonar: r.int("FRONTSONAR")?,
            rear_sonar: r.byte("REARSONAR")?,
            low_battery: r.int("LOWBATTERY")?,
            rev_count: r.int("REVCOUNT")?,
            watchdog_ms: r.int("WATCHDOG")?,
            p2mpacs: r.byte("P2MPACS")?,
            stall_val: r.int("STALLVAL")?,
            stall_count: r.int("STALLCOUNT")?,
            joy_vel: r.int("JOYVEL")?,
            joy_rot_vel: r.int("JOYRVEL")?,
            working: ConfigWorking {
                rot_vel_max: r.int("ROTVELMAX")?,
                trans_vel_max: r.int("TRANSVELMAX")?,
                rot_acc: r.int("ROTACC")?,
                rot_decel: r.int("ROTDECEL")?,
                rot_kp: r.int("ROTKP")?,
                rot_kv: r.int("ROTKV")?,
                rot_ki: r.int("ROTKI")?,
                trans_acc: r.int("TRANSACC")?,
                trans_decel: r.int("TRANSDECEL")?,
                trans_kp: r.int("TRANSKP")?,
                trans_kv: r.int("TRANSKV")?,
                trans_ki: r.int("TRANSKI")?,
            },
            bumpers: None,
            charger: None,
            aros18: None,
            extra_len: 0,
        };
        // The later groups, each read only when the packet goes on (a group cut short
        // is an error like any other truncation).
        if r.left() > 0 {
            c.bumpers = Some((r.byte("FRONTBUMPS")?, r.byte("REARBUMPS")?));
        }
        if r.left() > 0 {
            c.charger = Some(r.byte("CHARGER")?);
        }
        if r.left() > 0 {
            c.aros18 = Some((
                r.byte("SONARCYCLE")?,
                r.byte("AUTOBAUD")?,
                r.byte("HASGYRO")?,
            ));
        }
        c.extra_len = r.left();
        Ok(c)
    }

    /// The body gripper is fitted (GRIPPER non-zero).
    pub fn has_gripper(&self) -> bool {
        self.gripper != 0
    }

    /// Encodes the CONFIGpac: the base table, then the AROS groups up to the first one
    /// absent (a later group without an earlier one cannot be expressed on the wire), then
    /// `extra_len` zero bytes. Strings are cut at any NUL.
    pub fn encode(&self) -> Result<Frame, EncodeError> {
        fn s(b: &mut PayloadBuilder, v: &str) {
            let v = v.as_bytes();
            let end = v.iter().position(|&c| c == 0).unwrap_or(v.len());
            b.bytes(&v[..end]).byte(0);
        }
        let mut b = PayloadBuilder::new(ptype::CONFIG);
        s(&mut b, &self.robot_type);
        s(&mut b, &self.subtype);
        s(&mut b, &self.serial_number);
        b.byte(self.four_mots);
        for v in [
            self.rot_vel_top,
            self.trans_vel_top,
            self.rot_acc_top,
            self.trans_acc_top,
            self.pwm_max,
        ] {
            b.u16_le(v);
        }
        s(&mut b, &self.name);
        b.byte(self.sip_cycle_ms)
            .byte(self.host_baud)
            .byte(self.aux1_baud)
            .u16_le(self.gripper)
            .u16_le(self.front_sonar)
            .byte(self.rear_sonar)
            .u16_le(self.low_battery)
            .u16_le(self.rev_count)
            .u16_le(self.watchdog_ms)
            .byte(self.p2mpacs);
        let w = &self.working;
        for v in [
            self.stall_val,
            self.stall_count,
            self.joy_vel,
            self.joy_rot_vel,
            w.rot_vel_max,
            w.trans_vel_max,
            w.rot_acc,
            w.rot_decel,
            w.rot_kp,
            w.rot_kv,
            w.rot_ki,
            w.trans_acc,
            w.trans_decel,
            w.trans_kp,
            w.trans_kv,
            w.trans_ki,
        ] {
            b.u16_le(v);
        }
        if let Some((f, r)) = self.bumpers {
            b.byte(f).byte(r);
            if let Some(ch) = self.charger {
                b.byte(ch);
                if let Some((sc, ab, gy)) = self.aros18 {
                    b.byte(sc).byte(ab).byte(gy);
                }
            }
        }
        for _ in 0..self.extra_len.min(super::codec::MAX_PAYLOAD + 1) {
            b.byte(0);
        }
        b.frame()
    }
}
