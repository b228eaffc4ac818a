//! Player's messages of each interface, translated to limber's and back.
//!
//! One module per interface ([`actarray`], [`limb`], [`gripper`], and [`laser`] for
//! limber's ranger), each a [`Translator`]
//! in [`TRANSLATORS`]: it opens a [`PlayerDevice`] over a limber client of its interface
//! (a `Box<dyn DeviceClient>` from [`limber_services::connect_device`]), which turns
//! Player commands and requests into limber ones and limber states into Player DATA. A
//! new interface is one more module and one more entry.

use limber_interfaces::prelude::*;
use limber_services::{Client, CommandError, DeviceClient, RequestError, Ticket};
use thiserror::Error;

use crate::header::msg_type;
use crate::xdr::{XdrError, XdrReader, XdrWriter};

pub mod actarray;
pub mod gripper;
pub mod laser;
pub mod limb;

/// How states and commands are presented to Player's clients.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Conventions {
    /// Show an actuator array of one linear actuator (the Pioneer's lift) as Player's
    /// p2os driver does, normalised: 0 at its lower limit, 1 at its upper limit (positions,
    /// speeds and the geometry alike). Off: metres.
    pub normalise_lift: bool,
}

impl Default for Conventions {
    fn default() -> Self {
        Conventions {
            normalise_lift: true,
        }
    }
}

/// The translation of one interface.
pub trait Translator: Sync {
    /// The limber interface it translates.
    fn kind(&self) -> InterfaceKind;
    /// The Player interface it presents (by default the limber interface's
    /// [`InterfaceKind::player_code`]; `laser`, 6, for a ranger).
    fn player_code(&self) -> u16 {
        self.kind().player_code()
    }
    /// The Player interface's name, as `--map` entries write it.
    fn player_name(&self) -> &'static str {
        self.kind().name()
    }
    /// Wraps a connected client of this interface.
    fn open(&self, dev: Box<dyn DeviceClient>, conv: Conventions) -> Box<dyn PlayerDevice>;
}

/// Every interface the gateway translates.
pub static TRANSLATORS: &[&dyn Translator] = &[
    &actarray::ACTARRAY,
    &limb::LIMB,
    &gripper::GRIPPER,
    &laser::LASER,
];

/// The translator of `kind`, if the gateway has one.
pub fn translator(kind: InterfaceKind) -> Option<&'static dyn Translator> {
    TRANSLATORS.iter().copied().find(|t| t.kind() == kind)
}

/// The Player interface code a device of `kind` is shown as.
pub fn player_code(kind: InterfaceKind) -> u16 {
    translator(kind).map_or(kind.player_code(), |t| t.player_code())
}

/// The Player interface name a device of `kind` is shown as.
pub fn player_name(kind: InterfaceKind) -> &'static str {
    translator(kind).map_or(kind.name(), |t| t.player_name())
}

/// A subscribed device, as Player's clients see it.
pub trait PlayerDevice {
    /// The limber client underneath (leases, refresh, liveness).
    fn client(&mut self) -> &mut dyn DeviceClient;
    /// The limber client, read-only.
    fn client_ref(&self) -> &dyn DeviceClient;
    /// The DATA (subtype STATE = 1) body of the latest state taken, if any.
    fn data(&self) -> Option<Vec<u8>>;
    /// Sends a Player command; its ticket, to see its outcome.
    fn command(&mut self, subtype: u8, body: &[u8]) -> Result<Ticket, MessageError>;
    /// Sends a Player request; the ACK's body, or why it is NACKed.
    fn request(&mut self, subtype: u8, body: &[u8]) -> Result<Vec<u8>, MessageError>;
    /// Whether the gateway translates this `(type, subtype)` (CMD or REQ).
    fn translates(&self, mtype: u8, subtype: u8) -> bool;
    /// Whether a request changes the device (refused by a read-only gateway).
    fn changes(&self, subtype: u8) -> bool;
}

/// A Player message could not be carried out.
#[derive(Debug, Error)]
pub enum MessageError {
    /// Its body is not the interface's XDR form.
    #[error("malformed body: {0}")]
    Xdr(#[from] XdrError),
    /// A value limber refuses (a joint index beyond the array, a NaN).
    #[error("invalid value: {0}")]
    Value(#[from] ValueError),
    /// A value that is not one of the field's codes (power 2).
    #[error("invalid value: {0}")]
    Decode(#[from] DecodeError),
    /// Not a message of this interface.
    #[error("no message of type {mtype} subtype {subtype} in this interface")]
    Unknown {
        /// Its type.
        mtype: u8,
        /// Its subtype.
        subtype: u8,
    },
    /// The command could not be sent.
    #[error("the command could not be sent: {0}")]
    Command(#[from] CommandError),
    /// The request failed or was refused.
    #[error("the request failed: {0}")]
    Request(#[from] RequestError),
    /// The limber client is not of the interface its translator expects (a bug).
    #[error("the device's client is not {0}")]
    WrongInterface(&'static str),
}

impl MessageError {
    /// The status a refusal by the driver carried, if it was one.
    pub fn refusal(&self) -> Option<Status> {
        match self {
            MessageError::Request(RequestError::Nack(s)) => Some(*s),
            _ => None,
        }
    }
}

/// The typed client of `dev`.
pub(crate) fn typed<'a, I: Interface>(
    dev: &'a mut (dyn DeviceClient + 'static),
) -> Result<&'a mut Client<I>, MessageError> {
    dev.typed::<I>()
        .ok_or(MessageError::WrongInterface(I::KIND.with_article()))
}

/// Reads a message without a body.
pub(crate) fn empty(body: &[u8]) -> Result<(), MessageError> {
    XdrReader::new(body).end().map_err(MessageError::from)
}

/// Reads a `point_3d` (3 × f64).
pub(crate) fn read_vec3(r: &mut XdrReader<'_>, field: &'static str) -> Result<Vec3, XdrError> {
    Ok(Vec3::new(r.f64(field)?, r.f64(field)?, r.f64(field)?))
}

/// Writes a `point_3d`.
pub(crate) fn write_vec3(w: &mut XdrWriter, v: Vec3) {
    w.f64(v.x).f64(v.y).f64(v.z);
}

/// The unknown-message error for a command or request.
pub(crate) fn unknown(mtype: u8, subtype: u8) -> MessageError {
    MessageError::Unknown { mtype, subtype }
}

/// Reads an on/off byte (0 or 1).
pub(crate) fn on_off(r: &mut XdrReader<'_>, field: &'static str) -> Result<bool, MessageError> {
    match r.u8(field)? {
        0 => Ok(false),
        1 => Ok(true),
        v => Err(MessageError::Decode(DecodeError::UnknownCode {
            field,
            value: v.into(),
        })),
    }
}

/// Whether `mtype` is CMD with a subtype in `cmds`, or REQ with one in `reqs`.
pub(crate) fn in_tables(mtype: u8, subtype: u8, cmds: &[u8], reqs: &[u8]) -> bool {
    match mtype {
        msg_type::CMD => cmds.contains(&subtype),
        msg_type::REQ => reqs.contains(&subtype),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::MsgHeader;
    use crate::player::{BoolProp, DevReq, ReplaceRule};

    /// A fixed-seed generator (xorshift), enough for random bodies.
    struct Bytes(u64);
    impl Bytes {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn body(&mut self) -> Vec<u8> {
            let n = (self.next() % 160) as usize;
            let mut b: Vec<u8> = (0..n).map(|_| self.next() as u8).collect();
            // Now and then a plausible count word, to reach the arrays.
            if n >= 8 && self.next().is_multiple_of(3) {
                let c = (self.next() % 40) as u32;
                b[..4].copy_from_slice(&c.to_be_bytes());
                b[4..8].copy_from_slice(&c.to_be_bytes());
            }
            b
        }
    }

    /// Whatever a client sends, decoding gives a value or an error, never a panic.
    #[test]
    fn random_bodies_are_values_or_errors() {
        let mut r = Bytes(0x9E37_79B9_7F4A_7C15);
        let mut decoded = 0usize;
        for _ in 0..20_000 {
            let body = r.body();
            let sub = (r.next() % 12) as u8;
            let results = [
                actarray::command_of(sub, &body, None).is_ok(),
                actarray::request_of(sub, &body, None).is_ok(),
                limb::command_of(sub, &body).is_ok(),
                limb::request_of(sub, &body).is_ok(),
                gripper::command_of(sub, &body).is_ok(),
                DevReq::read(&body).is_ok(),
                BoolProp::read(&body).is_ok(),
                ReplaceRule::read(&body).is_ok(),
                crate::player::read_driverinfo(&body).is_ok(),
                MsgHeader::decode(&body).is_ok(),
            ];
            decoded += results.iter().filter(|ok| **ok).count();
        }
        // Some random bodies are valid messages (a gripper command without a body, a
        // replace rule of five words...): the decoders were reached, not refused at once.
        assert!(decoded > 100, "{decoded} decoded");
    }
}
