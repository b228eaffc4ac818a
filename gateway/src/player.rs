//! The `player` interface (code 1): the server's own requests (DEVLIST, DRIVERINFO, DEV,
//! DATA, DATAMODE, ADD_REPLACE_RULE), the universal requests every device answers
//! (capability 255, properties 254..247), and the banner.

use crate::header::DevAddr;
use crate::xdr::{XdrError, XdrReader, XdrWriter};

/// The `player` interface's code.
pub const PLAYER_CODE: u16 = 1;

/// The banner's size.
pub const BANNER_SIZE: usize = 32;
/// What the banner says after `"Player v."` (libplayerc does not parse it).
pub const VERSION: &str = "3.0.2 (limber gateway)";

/// The 32-byte banner: `"Player v." + version`, NUL-padded.
pub fn banner() -> [u8; BANNER_SIZE] {
    let mut b = [0u8; BANNER_SIZE];
    let text = format!("Player v.{VERSION}");
    let n = text.len().min(BANNER_SIZE - 1);
    b[..n].copy_from_slice(&text.as_bytes()[..n]);
    b
}

/// Request subtypes of the `player` interface.
pub mod req {
    /// The list of devices.
    pub const DEVLIST: u8 = 1;
    /// A device's driver name.
    pub const DRIVERINFO: u8 = 2;
    /// Subscribe to or close a device.
    pub const DEV: u8 = 3;
    /// PULL mode: send the waiting data.
    pub const DATA: u8 = 4;
    /// PUSH or PULL.
    pub const DATAMODE: u8 = 5;
    /// Authentication (disabled).
    pub const AUTH: u8 = 7;
    /// Name service (disabled).
    pub const NAMESERVICE: u8 = 8;
    /// A replace rule for the client's queue.
    pub const ADD_REPLACE_RULE: u8 = 10;
}

/// Universal request subtypes, on any device.
pub mod universal {
    /// Is `(type, subtype)` supported? ACK yes, NACK no.
    pub const CAPABILITY: u8 = 255;
    /// Get an integer property.
    pub const GET_INTPROP: u8 = 254;
    /// Set an integer property.
    pub const SET_INTPROP: u8 = 253;
    /// Get a double property.
    pub const GET_DBLPROP: u8 = 252;
    /// Set a double property.
    pub const SET_DBLPROP: u8 = 251;
    /// Get a string property.
    pub const GET_STRPROP: u8 = 250;
    /// Set a string property.
    pub const SET_STRPROP: u8 = 249;
    /// Get a boolean property.
    pub const GET_BOOLPROP: u8 = 248;
    /// Set a boolean property.
    pub const SET_BOOLPROP: u8 = 247;
}

/// SYNCH subtypes.
pub mod synch {
    /// The round of data is complete.
    pub const OK: u8 = 1;
    /// Data was dropped (a u32 count follows).
    pub const OVERFLOW: u8 = 2;
}

/// Access modes of REQ DEV.
pub mod access {
    /// Subscribe.
    pub const OPEN: u8 = 1;
    /// Unsubscribe.
    pub const CLOSE: u8 = 2;
    /// The subscription failed.
    pub const ERROR: u8 = 3;
}

/// Data modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataMode {
    /// Data is sent as it comes (the server's default).
    Push,
    /// Data waits for REQ DATA and ends with a SYNCH.
    Pull,
}

impl DataMode {
    /// From the wire (1 PUSH, 2 PULL).
    pub fn from_code(v: u8) -> Option<Self> {
        match v {
            1 => Some(DataMode::Push),
            2 => Some(DataMode::Pull),
            _ => None,
        }
    }
}

/// The longest driver name Player carries.
pub const DRIVER_NAME_MAX: usize = 64;
/// The most devices a DEVLIST carries.
pub const DEVLIST_MAX: usize = 4096;

/// REQ DEV (`{devaddr; u8 access; driver_name}`), both ways.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DevReq {
    /// The device.
    pub addr: DevAddr,
    /// [`access`].
    pub access: u8,
    /// The driver's name (empty in a request).
    pub driver_name: String,
}

impl DevReq {
    /// Reads a request body.
    pub fn read(body: &[u8]) -> Result<Self, XdrError> {
        let mut r = XdrReader::new(body);
        let addr = DevAddr::read(&mut r)?;
        let access = r.u8("access")?;
        let name = r.bytes("driver_name", DRIVER_NAME_MAX)?;
        r.end()?;
        Ok(DevReq {
            addr,
            access,
            driver_name: String::from_utf8_lossy(name)
                .trim_end_matches('\0')
                .to_string(),
        })
    }
    /// Its body.
    pub fn write(&self) -> Vec<u8> {
        let mut w = XdrWriter::new();
        self.addr.write(&mut w);
        w.u32(self.access.into());
        w.bytes(truncated(&self.driver_name));
        w.finish()
    }
}

fn truncated(name: &str) -> &[u8] {
    let b = name.as_bytes();
    &b[..b.len().min(DRIVER_NAME_MAX - 1)]
}

/// The DEVLIST reply body.
pub fn devlist(devices: &[DevAddr]) -> Vec<u8> {
    let mut w = XdrWriter::new();
    let n = devices.len().min(DEVLIST_MAX);
    w.count(n);
    for d in &devices[..n] {
        d.write(&mut w);
    }
    w.finish()
}

/// The DRIVERINFO request's device.
pub fn read_driverinfo(body: &[u8]) -> Result<DevAddr, XdrError> {
    let mut r = XdrReader::new(body);
    let addr = DevAddr::read(&mut r)?;
    // The name of a request is empty; read it when it is there.
    if r.remaining() > 0 {
        r.bytes("driver_name", DRIVER_NAME_MAX)?;
    }
    r.end()?;
    Ok(addr)
}

/// The DRIVERINFO reply body.
pub fn driverinfo(addr: DevAddr, driver: &str) -> Vec<u8> {
    let mut w = XdrWriter::new();
    addr.write(&mut w);
    w.bytes(truncated(driver));
    w.finish()
}

/// A replace rule (`{i32 interf, index, type, subtype, replace}`, -1 = any).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReplaceRule {
    /// Interface code, or -1.
    pub interf: i32,
    /// Index, or -1.
    pub index: i32,
    /// Message type, or -1.
    pub mtype: i32,
    /// Subtype, or -1.
    pub subtype: i32,
    /// Non-zero: a new message replaces a waiting one of the same address, type and
    /// subtype.
    pub replace: bool,
}

impl ReplaceRule {
    /// Reads a body.
    pub fn read(body: &[u8]) -> Result<Self, XdrError> {
        let mut r = XdrReader::new(body);
        let rule = ReplaceRule {
            interf: r.i32("interf")?,
            index: r.i32("index")?,
            mtype: r.i32("type")?,
            subtype: r.i32("subtype")?,
            replace: r.i32("replace")? != 0,
        };
        r.end()?;
        Ok(rule)
    }

    /// Whether it applies to a message.
    pub fn matches(&self, addr: DevAddr, mtype: u8, subtype: u8) -> bool {
        let m = |rule: i32, v: i64| rule == -1 || i64::from(rule) == v;
        m(self.interf, addr.interf.into())
            && m(self.index, addr.index.into())
            && m(self.mtype, mtype.into())
            && m(self.subtype, subtype.into())
    }
}

/// The DATAMODE request's mode.
pub fn read_datamode(body: &[u8]) -> Result<u8, XdrError> {
    let mut r = XdrReader::new(body);
    let m = r.u8("mode")?;
    r.end()?;
    Ok(m)
}

/// The capability request's `(type, subtype)`.
pub fn read_capability(body: &[u8]) -> Result<(u32, u32), XdrError> {
    let mut r = XdrReader::new(body);
    let t = r.u32("type")?;
    let s = r.u32("subtype")?;
    r.end()?;
    Ok((t, s))
}

/// The longest property key read.
pub const KEY_MAX: usize = 256;

/// A boolean property request (`{key_count; char *key; u8 value}`), both ways.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BoolProp {
    /// The key.
    pub key: String,
    /// The value.
    pub value: bool,
}

impl BoolProp {
    /// Reads a body.
    pub fn read(body: &[u8]) -> Result<Self, XdrError> {
        let mut r = XdrReader::new(body);
        let key = r.bytes("key", KEY_MAX)?;
        let value = r.u8("value")? != 0;
        r.end()?;
        Ok(BoolProp {
            key: String::from_utf8_lossy(key)
                .trim_end_matches('\0')
                .to_string(),
            value,
        })
    }
    /// Its body (the key with its terminating NUL, as C clients send it).
    pub fn write(&self) -> Vec<u8> {
        let mut key = self.key.as_bytes().to_vec();
        key.push(0);
        XdrWriter::new().bytes(&key).u32(self.value.into()).finish()
    }
}

/// The key of the gateway's lease property (`limber.lease`, boolean): set true to take
/// the device's control lease for this session, false to give it back; get says whether
/// this session holds it.
pub const LEASE_KEY: &str = "limber.lease";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_banner_is_32_bytes_starting_player_v() {
        let b = banner();
        assert!(b.starts_with(b"Player v."));
        assert_eq!(b[BANNER_SIZE - 1], 0);
    }

    /// REQ DEV for actarray:0, OPEN, empty name: devaddr (4 words), access widened, the
    /// name's count twice (0) and no bytes.
    #[test]
    fn a_dev_request_is_devaddr_access_and_a_counted_name() {
        let body = [
            0, 0, 0, 0, 0, 0, 0x1A, 0x09, 0, 0, 0, 53, 0, 0, 0, 0, // devaddr
            0, 0, 0, 1, // OPEN
            0, 0, 0, 0, 0, 0, 0, 0, // name count, count
        ];
        let req = DevReq::read(&body).expect("a DEV request");
        assert_eq!(req.addr.interf, 53);
        assert_eq!(req.access, access::OPEN);
        assert_eq!(req.driver_name, "");
        // The reply names the driver: "pioneer" is 7 bytes, padded to 8.
        let reply = DevReq {
            driver_name: "pioneer".into(),
            ..req
        }
        .write();
        assert_eq!(&reply[20..28], &[0, 0, 0, 7, 0, 0, 0, 7]);
        assert_eq!(&reply[28..], b"pioneer\0");
    }

    #[test]
    fn a_devlist_is_counted_twice() {
        let d = DevAddr {
            host: 0,
            robot: 6665,
            interf: 3,
            index: 1,
        };
        let body = devlist(&[d]);
        assert_eq!(
            body,
            [
                0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0x1A, 0x09, 0, 0, 0, 3, 0, 0, 0, 1
            ]
        );
    }

    #[test]
    fn replace_rules_match_with_wildcards() {
        let body: Vec<u8> = [-1i32, -1, 1, -1, 1]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        let rule = ReplaceRule::read(&body).expect("a rule");
        let a = DevAddr {
            interf: 53,
            ..DevAddr::default()
        };
        assert!(rule.replace);
        assert!(rule.matches(a, 1, 1));
        assert!(!rule.matches(a, 4, 1));
    }

    #[test]
    fn a_bool_property_round_trips() {
        let p = BoolProp {
            key: LEASE_KEY.into(),
            value: true,
        };
        let body = p.write();
        // "limber.lease\0" is 13 bytes: counts 13, padded to 16, then the value word.
        assert_eq!(&body[..8], &[0, 0, 0, 13, 0, 0, 0, 13]);
        assert_eq!(body.len(), 8 + 16 + 4);
        assert_eq!(BoolProp::read(&body), Ok(p));
    }
}
