//! `ranger` (limber) as Player's `laser` (interface 6), the interface libplayerc's
//! `playerc_laser_t`, libplayerc++'s `LaserProxy`, playerv's laser panel and playerprint
//! read. Player 3 marks `laser` deprecated in favour of `ranger` (62), but its programs
//! and tools still use it; a limber ranger is shown as `laser:N` (its limber index).
//!
//! The messages, from Player 3's interface definition (`006_laser.def`; the XDR rules of
//! the reference's section 1.3: scalars in 4-byte words, a variable array as
//! `count, count, elements`, a `uint8_t` array as `count, count, bytes` padded to a word):
//!
//! | type | subtype | name | body | here |
//! |---|---|---|---|---|
//! | DATA | 1 | SCAN | `f32 min_angle, max_angle, resolution, max_range; u32 ranges_count; f32 ranges[]; u32 intensity_count; u8 intensity[]; u32 id` | every new scan |
//! | DATA | 2 | SCANPOSE | a scan and the laser's global 2-D pose | not sent (limber's ranger has no global pose) |
//! | DATA | 3 | SCANANGLE | ranges with an angle each | not sent (SCAN's angles are regular) |
//! | REQ | 1 | GET_GEOM | empty; ACK `pose3d pose (6 × f64: x, y, z, roll, pitch, yaw); bbox3d size (3 × f64: width, length, height)` (72 bytes) | limber's GET_GEOM |
//! | REQ | 2 | SET_CONFIG | `player_laser_config_t` | NACK: limber's ranger cannot be configured |
//! | REQ | 3 | GET_CONFIG | empty; ACK `f32 min_angle, max_angle, resolution, max_range, range_res; u8 intensity; f32 scanning_frequency` (28 bytes) | limber's GET_GEOM |
//! | REQ | 4 | POWER | `u8 state` | NACK: no power switch |
//! | REQ | 5 | GET_ID | empty; ACK `u32 serial_number` | NACK: no serial number |
//! | REQ | 6 | SET_FILTER | filter type and parameters | NACK: no filters |
//!
//! The laser has no command. Conversions: limber's `f64` angles and ranges become
//! Player's `f32`; intensities (sensor units, `f64`) are rounded and clamped to Player's
//! `u8` (0–255); the scan id is the low 32 bits of the state's sequence number; the
//! configuration's `intensity` flag is 1 when the latest scan carried intensities.

use limber_interfaces::prelude::*;
use limber_services::{DeviceClient, Ticket};

use super::{Conventions, MessageError, PlayerDevice, Translator, empty, in_tables, unknown};
use crate::header::msg_type;
use crate::xdr::XdrWriter;

/// Player's `laser` interface code.
pub const LASER_CODE: u16 = 6;

/// Player's laser request subtypes (`PLAYER_LASER_REQ_*`).
pub mod req {
    /// Get the geometry (answered).
    pub const GET_GEOM: u8 = 1;
    /// Set the configuration (NACKed).
    pub const SET_CONFIG: u8 = 2;
    /// Get the configuration (answered).
    pub const GET_CONFIG: u8 = 3;
    /// Power on or off (NACKed).
    pub const POWER: u8 = 4;
    /// Get the serial number (NACKed).
    pub const GET_ID: u8 = 5;
    /// Set the filters (NACKed).
    pub const SET_FILTER: u8 = 6;
}

/// Player's laser DATA subtype of a scan (`PLAYER_LASER_DATA_SCAN`).
pub const DATA_SCAN: u8 = 1;

/// The laser translator (of limber's ranger).
pub static LASER: LaserTranslator = LaserTranslator;

/// Translates `ranger` as Player's `laser`.
#[derive(Debug)]
pub struct LaserTranslator;

const REQS: [u8; 2] = [req::GET_GEOM, req::GET_CONFIG];

impl Translator for LaserTranslator {
    fn kind(&self) -> InterfaceKind {
        InterfaceKind::Ranger
    }
    fn player_code(&self) -> u16 {
        LASER_CODE
    }
    fn player_name(&self) -> &'static str {
        "laser"
    }
    fn open(&self, dev: Box<dyn DeviceClient>, _: Conventions) -> Box<dyn PlayerDevice> {
        Box::new(LaserDevice { dev })
    }
}

struct LaserDevice {
    dev: Box<dyn DeviceClient>,
}

/// An intensity as Player's byte: rounded, clamped to 0–255 (NaN: 0).
fn intensity_byte(v: f64) -> u8 {
    if v.is_nan() {
        0
    } else {
        v.round().clamp(0.0, 255.0) as u8
    }
}

/// The DATA SCAN body of `d`: 4 words, the ranges (count twice, `f32` each), the
/// intensities (count twice, bytes padded to a word), the id.
pub fn data_body(d: &RangerData) -> Vec<u8> {
    let mut w = XdrWriter::new();
    w.f32(d.min_angle as f32)
        .f32(d.max_angle as f32)
        .f32(d.angular_res as f32)
        .f32(d.max_range as f32);
    let ranges = d.ranges();
    w.count(ranges.len());
    for r in ranges {
        w.f32(*r as f32);
    }
    let bytes: Vec<u8> = d.intensities().iter().map(|v| intensity_byte(*v)).collect();
    w.bytes(&bytes);
    w.u32(d.header.seq as u32);
    w.finish()
}

/// The GET_GEOM ACK body of `g` (72 bytes: the pose, then width, length, height).
pub fn geom_body(g: &RangerGeom) -> Vec<u8> {
    let mut w = XdrWriter::new();
    let (p, o) = (g.pose.position, g.pose.orientation);
    w.f64(p.x).f64(p.y).f64(p.z);
    w.f64(o.roll).f64(o.pitch).f64(o.yaw);
    w.f64(g.size.width).f64(g.size.length).f64(g.size.height);
    w.finish()
}

/// The GET_CONFIG ACK body of `g` (28 bytes); `intensity`: whether scans carry
/// intensities.
pub fn config_body(g: &RangerGeom, intensity: bool) -> Vec<u8> {
    XdrWriter::new()
        .f32(g.min_angle as f32)
        .f32(g.max_angle as f32)
        .f32(g.angular_res as f32)
        .f32(g.max_range as f32)
        .f32(g.range_res as f32)
        .u32(intensity.into())
        .f32(g.frequency as f32)
        .finish()
}

impl LaserDevice {
    fn geometry(&mut self) -> Result<RangerGeom, MessageError> {
        let c = super::typed::<Ranger>(self.dev.as_mut())?;
        match c.request(&RangerRequest::GetGeom)? {
            RangerReply::Geom(g) => Ok(g),
        }
    }
}

impl PlayerDevice for LaserDevice {
    fn client(&mut self) -> &mut dyn DeviceClient {
        self.dev.as_mut()
    }
    fn client_ref(&self) -> &dyn DeviceClient {
        self.dev.as_ref()
    }
    fn data(&self) -> Option<Vec<u8>> {
        let c = self.dev.typed_ref::<Ranger>()?;
        c.last_state().map(data_body)
    }
    fn command(&mut self, subtype: u8, _: &[u8]) -> Result<Ticket, MessageError> {
        Err(unknown(msg_type::CMD, subtype))
    }
    fn request(&mut self, subtype: u8, body: &[u8]) -> Result<Vec<u8>, MessageError> {
        match subtype {
            req::GET_GEOM => {
                empty(body)?;
                Ok(geom_body(&self.geometry()?))
            }
            req::GET_CONFIG => {
                empty(body)?;
                let g = self.geometry()?;
                let intensity = self
                    .dev
                    .typed_ref::<Ranger>()
                    .and_then(|c| c.last_state())
                    .is_some_and(|d| d.intensities_count > 0);
                Ok(config_body(&g, intensity))
            }
            _ => Err(unknown(msg_type::REQ, subtype)),
        }
    }
    fn translates(&self, mtype: u8, subtype: u8) -> bool {
        translated(mtype, subtype)
    }
    fn changes(&self, subtype: u8) -> bool {
        changing(subtype)
    }
}

/// Whether the gateway answers `(type, subtype)`: the two readings, GET_GEOM and
/// GET_CONFIG; no command.
fn translated(mtype: u8, subtype: u8) -> bool {
    in_tables(mtype, subtype, &[], &REQS)
}

/// Whether a request would change the laser (all but the readings and GET_ID).
fn changing(subtype: u8) -> bool {
    !matches!(subtype, req::GET_GEOM | req::GET_CONFIG | req::GET_ID)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(v: &[u32]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_be_bytes()).collect()
    }

    fn f32s(v: &[f32]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_be_bytes()).collect()
    }

    fn f64s(v: &[f64]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_be_bytes()).collect()
    }

    fn scan(ranges: &[f64], intensities: &[f64]) -> RangerData {
        let mut d = RangerData {
            min_angle: -1.5,
            max_angle: 1.5,
            angular_res: 1.5,
            max_range: 8.0,
            ranges_count: ranges.len() as u32,
            intensities_count: intensities.len() as u32,
            ..Default::default()
        };
        d.header.seq = 0x1_0000_0007;
        d.ranges[..ranges.len()].copy_from_slice(ranges);
        d.intensities[..intensities.len()].copy_from_slice(intensities);
        d
    }

    #[test]
    fn a_scan_is_players_bytes() {
        let body = data_body(&scan(&[0.5, 8.0, 0.25], &[]));
        let mut want = f32s(&[-1.5, 1.5, 1.5, 8.0]);
        want.extend(words(&[3, 3]));
        want.extend(f32s(&[0.5, 8.0, 0.25]));
        want.extend(words(&[0, 0]));
        want.extend(words(&[7]));
        assert_eq!(body, want);
        assert_eq!(body.len(), 16 + 8 + 12 + 8 + 4);
    }

    #[test]
    fn intensities_are_bytes_padded_to_a_word() {
        let body = data_body(&scan(&[1.0, 2.0, 3.0], &[0.4, 300.0, f64::NAN]));
        let tail = &body[16 + 8 + 12..];
        let mut want = words(&[3, 3]);
        want.extend([0, 255, 0, 0]);
        want.extend(words(&[7]));
        assert_eq!(tail, want);
        assert_eq!(intensity_byte(-3.0), 0);
        assert_eq!(intensity_byte(41.6), 42);
    }

    fn geom() -> RangerGeom {
        let mut g = RangerGeom {
            min_angle: -1.5,
            max_angle: 1.5,
            angular_res: 0.5,
            min_range: 0.02,
            max_range: 8.0,
            range_res: 0.25,
            frequency: 10.0,
            ranges_count: 7,
            ..Default::default()
        };
        g.pose.position = Vec3::new(0.16, 0.0, 0.2);
        g.pose.orientation.yaw = 0.5;
        g.size.width = 0.15;
        g.size.length = 0.25;
        g.size.height = 0.2;
        g
    }

    #[test]
    fn geometry_is_a_pose_and_a_size() {
        let mut want = f64s(&[0.16, 0.0, 0.2, 0.0, 0.0, 0.5]);
        want.extend(f64s(&[0.15, 0.25, 0.2]));
        assert_eq!(geom_body(&geom()), want);
        assert_eq!(want.len(), 72);
    }

    #[test]
    fn configuration_is_seven_words() {
        let mut want = f32s(&[-1.5, 1.5, 0.5, 8.0, 0.25]);
        want.extend(words(&[1]));
        want.extend(f32s(&[10.0]));
        assert_eq!(config_body(&geom(), true), want);
        assert_eq!(config_body(&geom(), false)[20..24], [0, 0, 0, 0]);
    }

    #[test]
    fn only_the_two_readings_are_translated() {
        assert!(translated(msg_type::REQ, req::GET_GEOM));
        assert!(translated(msg_type::REQ, req::GET_CONFIG));
        for s in [req::SET_CONFIG, req::POWER, req::GET_ID, req::SET_FILTER] {
            assert!(!translated(msg_type::REQ, s), "{s}");
        }
        assert!(!translated(msg_type::CMD, 1));
        assert!(changing(req::SET_CONFIG) && changing(req::POWER));
        assert!(!changing(req::GET_GEOM) && !changing(req::GET_CONFIG));
    }
}
