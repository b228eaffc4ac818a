//! The errors of this crate: one enum for decoding raw wire structs into typed views, one
//! for building a message from invalid values.

use thiserror::Error;

/// A value given to a constructor is not acceptable (nothing was built).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum ValueError {
    /// A number is NaN or infinite.
    #[error("{field} is not finite")]
    NotFinite {
        /// The offending field.
        field: &'static str,
    },
    /// More values than the fixed array holds.
    #[error("{field}: {count} values, at most {max} allowed")]
    TooMany {
        /// The offending field.
        field: &'static str,
        /// How many were given.
        count: usize,
        /// The capacity.
        max: usize,
    },
    /// A joint index that cannot exist (negative, or beyond the array capacity).
    #[error("joint {joint} is not a valid joint index (0 to {})", max.saturating_sub(1))]
    BadJoint {
        /// The index given.
        joint: i64,
        /// The array capacity.
        max: usize,
    },
    /// A value that must not be negative is.
    #[error("{field} is negative")]
    Negative {
        /// The offending field.
        field: &'static str,
    },
    /// A direction vector of (near) zero length.
    #[error("{field} has zero length")]
    ZeroVector {
        /// The offending field.
        field: &'static str,
    },
}

/// A raw wire struct could not be turned into its typed view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum DecodeError {
    /// The `kind` field holds a code this interface does not define.
    #[error("unknown {channel} kind {kind}")]
    UnknownKind {
        /// Which channel (e.g. "actarray command").
        channel: &'static str,
        /// The code found.
        kind: u32,
    },
    /// An enumerated field holds a code that is not defined.
    #[error("unknown {field} code {value}")]
    UnknownCode {
        /// The field.
        field: &'static str,
        /// The code found.
        value: i64,
    },
    /// A bit field has bits set that are not defined.
    #[error("{field} has undefined bits {bits:#x}")]
    UnknownBits {
        /// The field.
        field: &'static str,
        /// The undefined bits.
        bits: u32,
    },
    /// The body length does not match the kind.
    #[error("{channel} kind {kind}: body of {got} bytes, expected {expected}")]
    BodyLength {
        /// Which channel.
        channel: &'static str,
        /// The kind.
        kind: u32,
        /// The length the kind requires.
        expected: u32,
        /// The `body_len` found.
        got: u32,
    },
    /// A field's value is invalid (not finite, too many, bad joint, zero vector).
    #[error(transparent)]
    Value(#[from] ValueError),
}

impl DecodeError {
    /// Shorthand for a non-finite field.
    pub(crate) const fn not_finite(field: &'static str) -> Self {
        DecodeError::Value(ValueError::NotFinite { field })
    }
}

impl DecodeError {
    /// The status a driver answers when a message fails to decode.
    pub const fn status(&self) -> crate::common::Status {
        use crate::common::Status;
        match self {
            DecodeError::UnknownKind { .. } => Status::Unsupported,
            DecodeError::Value(ValueError::NotFinite { .. }) => Status::NotFinite,
            DecodeError::Value(ValueError::BadJoint { .. }) => Status::UnknownJoint,
            _ => Status::InvalidArgument,
        }
    }
}

impl ValueError {
    /// The status a driver answers for a message with this invalid value.
    pub const fn status(&self) -> crate::common::Status {
        DecodeError::Value(*self).status()
    }
}
