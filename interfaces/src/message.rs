//! How typed views map onto the channel envelopes: every command, request and reply
//! travels as `{meta, body}` where `body` holds exactly one of the interface's per-message
//! structs, selected by `meta.kind`.

use zerocopy::{FromBytes, Immutable, IntoBytes};

use crate::common::{MsgMeta, ReplyMeta, Status};
use crate::error::DecodeError;

/// A channel envelope with [`MsgMeta`] in front (commands and requests).
pub trait Envelope: Default + Copy + Send + 'static {
    /// The metadata.
    fn meta(&self) -> &MsgMeta;
    /// The metadata, mutable.
    fn meta_mut(&mut self) -> &mut MsgMeta;
}

/// A reply envelope with [`ReplyMeta`] in front.
pub trait ReplyEnvelope: Default + Copy + Send + 'static {
    /// The metadata.
    fn meta(&self) -> &ReplyMeta;
    /// The metadata, mutable.
    fn meta_mut(&mut self) -> &mut ReplyMeta;
}

/// A typed command or request that is carried in envelope `Raw`.
pub trait Message: Sized + Copy {
    /// The envelope.
    type Raw: Envelope;
    /// Channel name for error messages (e.g. `"actarray command"`).
    const CHANNEL: &'static str;
    /// The kind code of this message.
    fn kind(&self) -> u32;
    /// Writes kind, body length and body into `raw` (metadata other than `kind` and
    /// `body_len` is left to the sender). Does not allocate.
    fn write(&self, raw: &mut Self::Raw);
    /// Decodes and validates `raw`.
    fn read(raw: &Self::Raw) -> Result<Self, DecodeError>;
    /// True when the message only reads the device (e.g. a geometry request): allowed
    /// while another client holds the device's control lease. Default: it changes the
    /// device.
    fn is_read_only(&self) -> bool {
        false
    }
    /// True for a piece of a larger command (a trajectory upload's chunk): it has an
    /// outcome but no motion result of its own (the command it belongs to has). Default:
    /// false.
    fn is_piece(&self) -> bool {
        false
    }
}

/// A typed reply body (the payload of an ACK) carried in envelope `Raw`.
pub trait ReplyBody: Sized + Copy {
    /// The envelope.
    type Raw: ReplyEnvelope;
    /// Writes the reply to request `kind`: `Ok(body)` is an ACK, `Err(status)` a NACK.
    fn write(kind: u32, reply: Result<&Self, Status>, raw: &mut Self::Raw);
    /// Decodes a reply: `Ok(Ok(body))` for an ACK, `Ok(Err(status))` for a NACK.
    fn read(raw: &Self::Raw) -> Result<Result<Self, Status>, DecodeError>;
}

/// Copies `v` into the front of `body`; returns its length.
pub(crate) fn put<T: IntoBytes + Immutable>(body: &mut [u8], v: &T) -> u32 {
    let bytes = v.as_bytes();
    body[..bytes.len()].copy_from_slice(bytes);
    body[bytes.len()..].fill(0);
    bytes.len() as u32
}

/// Reads a `T` from the front of `body`, checking `body_len`.
pub(crate) fn get<T: FromBytes>(
    channel: &'static str,
    kind: u32,
    body: &[u8],
    body_len: u32,
) -> Result<T, DecodeError> {
    let expected = core::mem::size_of::<T>() as u32;
    if body_len != expected {
        return Err(DecodeError::BodyLength {
            channel,
            kind,
            expected,
            got: body_len,
        });
    }
    T::read_from_prefix(body)
        .map(|(v, _)| v)
        .map_err(|_| DecodeError::BodyLength {
            channel,
            kind,
            expected,
            got: body.len() as u32,
        })
}

/// Checks that a message without body has `body_len == 0`.
pub(crate) fn empty(channel: &'static str, kind: u32, body_len: u32) -> Result<(), DecodeError> {
    if body_len == 0 {
        Ok(())
    } else {
        Err(DecodeError::BodyLength {
            channel,
            kind,
            expected: 0,
            got: body_len,
        })
    }
}

/// Reads the status of a reply.
pub(crate) fn reply_status(meta: &ReplyMeta) -> Result<Status, DecodeError> {
    Status::try_from(meta.status)
}

macro_rules! envelope {
    ($t:ty) => {
        impl $crate::message::Envelope for $t {
            fn meta(&self) -> &$crate::common::MsgMeta {
                &self.meta
            }
            fn meta_mut(&mut self) -> &mut $crate::common::MsgMeta {
                &mut self.meta
            }
        }
    };
}
macro_rules! reply_envelope {
    ($t:ty) => {
        impl $crate::message::ReplyEnvelope for $t {
            fn meta(&self) -> &$crate::common::ReplyMeta {
                &self.meta
            }
            fn meta_mut(&mut self) -> &mut $crate::common::ReplyMeta {
                &mut self.meta
            }
        }
    };
}
pub(crate) use envelope;
pub(crate) use reply_envelope;
