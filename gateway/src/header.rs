//! Player's message header (`player_msghdr_t`) in its 40-byte XDR form, and the message
//! types.

use thiserror::Error;

use crate::xdr::{XdrError, XdrReader, XdrWriter};

/// Size of the XDR header.
pub const HEADER_SIZE: usize = 40;
/// The largest message Player accepts, header included (8 MiB).
pub const MAX_MESSAGE_SIZE: usize = 8 * 1024 * 1024;

/// Message types (`player_msghdr.type`).
pub mod msg_type {
    /// Driver to client: a state.
    pub const DATA: u8 = 1;
    /// Client to driver: a command, not answered.
    pub const CMD: u8 = 2;
    /// Client to driver: a request, always answered by RESP_ACK or RESP_NACK.
    pub const REQ: u8 = 3;
    /// A positive reply.
    pub const RESP_ACK: u8 = 4;
    /// The end of a round of data (PULL mode).
    pub const SYNCH: u8 = 5;
    /// A negative reply (empty body).
    pub const RESP_NACK: u8 = 6;
}

/// A device address (`player_devaddr_t`): host, robot (the TCP port), interface code,
/// index.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct DevAddr {
    /// Transport-dependent; clients send 0.
    pub host: u32,
    /// The server's TCP port.
    pub robot: u32,
    /// Player's interface code (53 actarray, 54 limb, 3 gripper, 1 player).
    pub interf: u16,
    /// The device's index among those of its interface.
    pub index: u16,
}

impl DevAddr {
    /// Its XDR form (16 bytes).
    pub fn write(&self, w: &mut XdrWriter) {
        w.u32(self.host)
            .u32(self.robot)
            .u32(self.interf.into())
            .u32(self.index.into());
    }
    /// Reads one.
    pub fn read(r: &mut XdrReader<'_>) -> Result<Self, XdrError> {
        Ok(DevAddr {
            host: r.u32("addr.host")?,
            robot: r.u32("addr.robot")?,
            interf: r.u32("addr.interf")? as u16,
            index: r.u32("addr.index")? as u16,
        })
    }
}

/// The header of a message.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MsgHeader {
    /// The device it concerns.
    pub addr: DevAddr,
    /// [`msg_type`].
    pub mtype: u8,
    /// Its meaning depends on the type and the interface.
    pub subtype: u8,
    /// Seconds since the epoch.
    pub timestamp: f64,
    /// Transport-specific, normally 0.
    pub seq: u32,
    /// The XDR body's size in bytes.
    pub size: u32,
}

/// A header could not be read.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum HeaderError {
    /// Fewer than 40 bytes.
    #[error("a header is 40 bytes: {0}")]
    Xdr(#[from] XdrError),
    /// The body would exceed Player's message size limit.
    #[error("a body of {0} bytes exceeds Player's limit of 8 MiB")]
    TooLarge(u32),
}

impl MsgHeader {
    /// The 40 bytes.
    pub fn encode(&self) -> [u8; HEADER_SIZE] {
        let mut w = XdrWriter::new();
        self.addr.write(&mut w);
        w.u32(self.mtype.into())
            .u32(self.subtype.into())
            .f64(self.timestamp)
            .u32(self.seq)
            .u32(self.size);
        let v = w.finish();
        let mut out = [0u8; HEADER_SIZE];
        out.copy_from_slice(&v);
        out
    }

    /// Reads a header from its 40 bytes; refuses a body larger than Player allows.
    pub fn decode(b: &[u8]) -> Result<Self, HeaderError> {
        let mut r = XdrReader::new(b);
        let h = MsgHeader {
            addr: DevAddr::read(&mut r)?,
            mtype: r.u32("type")? as u8,
            subtype: r.u32("subtype")? as u8,
            timestamp: r.f64("timestamp")?,
            seq: r.u32("seq")?,
            size: r.u32("size")?,
        };
        if h.size as usize > MAX_MESSAGE_SIZE - HEADER_SIZE {
            return Err(HeaderError::TooLarge(h.size));
        }
        Ok(h)
    }
}

/// The wall clock in seconds since the epoch, as Player stamps messages.
pub fn now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// A whole message: header (its size set from the body) and body.
pub fn message(mut h: MsgHeader, body: &[u8]) -> Vec<u8> {
    h.size = u32::try_from(body.len()).unwrap_or(u32::MAX);
    let mut out = Vec::with_capacity(HEADER_SIZE + body.len());
    out.extend_from_slice(&h.encode());
    out.extend_from_slice(body);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference's header (1.2): a REQ DEV (interface 1, index 0, subtype 3) to port
    /// 6665, stamped 1.5 s, with a 88-byte body.
    #[test]
    fn the_header_is_forty_big_endian_bytes_in_the_references_order() {
        let h = MsgHeader {
            addr: DevAddr {
                host: 0,
                robot: 6665,
                interf: 1,
                index: 0,
            },
            mtype: msg_type::REQ,
            subtype: 3,
            timestamp: 1.5,
            seq: 0,
            size: 88,
        };
        let bytes = h.encode();
        assert_eq!(
            bytes,
            [
                0, 0, 0, 0, // host
                0, 0, 0x1A, 0x09, // robot 6665
                0, 0, 0, 1, // interf, widened
                0, 0, 0, 0, // index
                0, 0, 0, 3, // type REQ
                0, 0, 0, 3, // subtype DEV
                0x3F, 0xF8, 0, 0, 0, 0, 0, 0, // 1.5
                0, 0, 0, 0, // seq
                0, 0, 0, 88, // size
            ]
        );
        assert_eq!(MsgHeader::decode(&bytes), Ok(h));
    }

    #[test]
    fn a_short_or_oversized_header_is_an_error() {
        assert!(MsgHeader::decode(&[0; 39]).is_err());
        let mut b = MsgHeader::default().encode();
        b[36..40].copy_from_slice(&u32::MAX.to_be_bytes());
        assert_eq!(MsgHeader::decode(&b), Err(HeaderError::TooLarge(u32::MAX)));
    }
}
