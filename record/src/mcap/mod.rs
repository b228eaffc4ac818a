//! MCAP, written and read from the published specification (<https://mcap.dev/spec>):
//! the records limber needs and nothing else. A file is the magic, a header, schemas,
//! channels and metadata, messages in chunks (lz4-compressed or not) each followed by its
//! message indexes, a data-end record with the data section's CRC-32, a summary (schemas,
//! channels, statistics, chunk indexes, metadata indexes, summary offsets), a footer and
//! the magic again.
//!
//! Written here rather than taken from the `mcap` crate: these few records are ~500
//! lines, where the crate brings binrw, enumset and their derive macros into every cold
//! build (and zstd and lz4 as C builds with its default features); the CRC and lz4 crates
//! used here are in limber's build already (Zenoh's). The tests read the files with the
//! reference Python reader.

mod read;
mod write;

pub use read::{Channel, MAX_RECORD, McapReader, ReadError, Record, Schema};
pub use write::{Compression, McapWriter, WriteError};

/// The magic at the start and at the end of every MCAP file (format version 0).
pub const MAGIC: [u8; 8] = [0x89, b'M', b'C', b'A', b'P', b'0', b'\r', b'\n'];

/// Record opcodes.
pub(crate) mod op {
    pub const HEADER: u8 = 0x01;
    pub const FOOTER: u8 = 0x02;
    pub const SCHEMA: u8 = 0x03;
    pub const CHANNEL: u8 = 0x04;
    pub const MESSAGE: u8 = 0x05;
    pub const CHUNK: u8 = 0x06;
    pub const MESSAGE_INDEX: u8 = 0x07;
    pub const CHUNK_INDEX: u8 = 0x08;
    pub const STATISTICS: u8 = 0x0B;
    pub const METADATA: u8 = 0x0C;
    pub const METADATA_INDEX: u8 = 0x0D;
    pub const SUMMARY_OFFSET: u8 = 0x0E;
    pub const DATA_END: u8 = 0x0F;
}

/// The profile written in the header (no well-known profile: limber's own plus JSON).
pub const PROFILE: &str = "";

/// The schema encoding of limber's own messages: a JSON object with the layout version,
/// the root struct's name and every struct it uses, as `limber layout --json` prints
/// them (name, type name, size, alignment, fields with offsets, sizes, types).
pub const LAYOUT_SCHEMA_ENCODING: &str = "limber-layout";
/// The message encoding of limber's own messages: the wire struct's bytes, little-endian,
/// the fixed layout of limber.h.
pub const WIRE_ENCODING: &str = "limber-wire";
