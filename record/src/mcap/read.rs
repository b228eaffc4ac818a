//! The MCAP reader: the records of a file in order, chunks decompressed one at a time
//! (bounded memory), every length checked against what is left (a malformed or truncated
//! file is an error, never a panic or a huge allocation).

use std::collections::VecDeque;
use std::io::{BufReader, Read};

use thiserror::Error;

use super::{MAGIC, op};

/// The largest record or decompressed chunk accepted (a hostile length is refused before
/// anything is allocated for it).
pub const MAX_RECORD: u64 = 256 << 20;

/// Reading an MCAP file failed.
#[derive(Debug, Error)]
pub enum ReadError {
    /// The file could not be read.
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    /// It does not start with the MCAP magic.
    #[error("not an MCAP file (no MCAP magic at the start)")]
    NotMcap,
    /// It ends in the middle of a record (a recording that was killed?).
    #[error("the file is truncated at byte {0}")]
    Truncated(u64),
    /// A record is malformed.
    #[error("malformed {what} record at byte {at}")]
    Malformed {
        /// Which record.
        what: &'static str,
        /// Where.
        at: u64,
    },
    /// A record longer than [`MAX_RECORD`].
    #[error("a record of {len} bytes at byte {at} (at most {MAX_RECORD} accepted)")]
    TooLong {
        /// Its length.
        len: u64,
        /// Where.
        at: u64,
    },
    /// A chunk compressed in a way this reader does not know.
    #[error("a chunk compressed with {0:?} (only lz4 and none are supported)")]
    Compression(String),
    /// A chunk could not be decompressed or its CRC does not match.
    #[error("a corrupt chunk at byte {0}")]
    CorruptChunk(u64),
}

/// A schema.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Schema {
    /// Its id.
    pub id: u16,
    /// Its name (for limber's messages, the wire struct's type name).
    pub name: String,
    /// Its encoding.
    pub encoding: String,
    /// Its text.
    pub data: Vec<u8>,
}

/// A channel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Channel {
    /// Its id.
    pub id: u16,
    /// Its schema's id (0: none).
    pub schema_id: u16,
    /// Its topic.
    pub topic: String,
    /// How its messages are encoded.
    pub message_encoding: String,
    /// Its metadata.
    pub metadata: Vec<(String, String)>,
}

/// One record of interest, in file order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Record {
    /// A schema.
    Schema(Schema),
    /// A channel.
    Channel(Channel),
    /// A message.
    Message {
        /// Its channel.
        channel: u16,
        /// Its sequence number on the channel.
        sequence: u32,
        /// When it was received (ns since the Unix epoch).
        log_time: u64,
        /// When it was acquired (ns since the Unix epoch).
        publish_time: u64,
        /// Its bytes.
        data: Vec<u8>,
    },
    /// A metadata record.
    Metadata {
        /// Its name.
        name: String,
        /// Its entries.
        entries: Vec<(String, String)>,
    },
}

/// A cursor over one record's body.
struct Body<'a> {
    b: &'a [u8],
    what: &'static str,
    at: u64,
}

impl<'a> Body<'a> {
    fn bad(&self) -> ReadError {
        ReadError::Malformed {
            what: self.what,
            at: self.at,
        }
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], ReadError> {
        if self.b.len() < n {
            return Err(self.bad());
        }
        let (h, t) = self.b.split_at(n);
        self.b = t;
        Ok(h)
    }
    fn u16(&mut self) -> Result<u16, ReadError> {
        let b = self.take(2)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    fn u32(&mut self) -> Result<u32, ReadError> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn u64(&mut self) -> Result<u64, ReadError> {
        let mut a = [0u8; 8];
        a.copy_from_slice(self.take(8)?);
        Ok(u64::from_le_bytes(a))
    }
    fn bytes(&mut self) -> Result<&'a [u8], ReadError> {
        let n = self.u32()? as usize;
        self.take(n)
    }
    fn string(&mut self) -> Result<String, ReadError> {
        let b = self.bytes()?;
        String::from_utf8(b.to_vec()).map_err(|_| self.bad())
    }
    fn str_map(&mut self) -> Result<Vec<(String, String)>, ReadError> {
        let inner = self.bytes()?;
        let mut m = Body {
            b: inner,
            what: self.what,
            at: self.at,
        };
        let mut out = Vec::new();
        while !m.b.is_empty() {
            out.push((m.string()?, m.string()?));
        }
        Ok(out)
    }
}

/// Reads the records of an MCAP file in order ([`McapReader::next_record`]).
pub struct McapReader<R: Read> {
    r: BufReader<R>,
    pos: u64,
    /// Records of the chunk being read, decoded.
    pending: VecDeque<Record>,
    ended: bool,
}

impl<R: Read> core::fmt::Debug for McapReader<R> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("McapReader")
            .field("pos", &self.pos)
            .finish_non_exhaustive()
    }
}

impl<R: Read> McapReader<R> {
    /// Checks the magic of `r`.
    pub fn new(r: R) -> Result<Self, ReadError> {
        let mut r = BufReader::new(r);
        let mut magic = [0u8; 8];
        match r.read_exact(&mut magic) {
            Ok(()) if magic == MAGIC => {}
            Ok(()) => return Err(ReadError::NotMcap),
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                return Err(ReadError::NotMcap);
            }
            Err(e) => return Err(e.into()),
        }
        Ok(McapReader {
            r,
            pos: 8,
            pending: VecDeque::new(),
            ended: false,
        })
    }

    fn fill(&mut self, buf: &mut [u8]) -> Result<(), ReadError> {
        match self.r.read_exact(buf) {
            Ok(()) => {
                self.pos += buf.len() as u64;
                Ok(())
            }
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                Err(ReadError::Truncated(self.pos))
            }
            Err(e) => Err(e.into()),
        }
    }

    /// The next schema, channel, message or metadata record; `None` at the end of the
    /// data section.
    pub fn next_record(&mut self) -> Result<Option<Record>, ReadError> {
        loop {
            if let Some(r) = self.pending.pop_front() {
                return Ok(Some(r));
            }
            if self.ended {
                return Ok(None);
            }
            let at = self.pos;
            let mut head = [0u8; 9];
            self.fill(&mut head)?;
            let opcode = head[0];
            let mut len = [0u8; 8];
            len.copy_from_slice(&head[1..]);
            let len = u64::from_le_bytes(len);
            if len > MAX_RECORD {
                return Err(ReadError::TooLong { len, at });
            }
            // Read as it comes: a hostile length costs only what the file really holds.
            let mut body = Vec::new();
            let got = (&mut self.r).take(len).read_to_end(&mut body)?;
            self.pos += got as u64;
            if got as u64 != len {
                return Err(ReadError::Truncated(self.pos));
            }
            match opcode {
                op::DATA_END | op::FOOTER => {
                    self.ended = true;
                }
                op::CHUNK => self.chunk(&body, at)?,
                _ => {
                    if let Some(r) = decode(opcode, &body, at)? {
                        return Ok(Some(r));
                    }
                }
            }
        }
    }

    fn chunk(&mut self, body: &[u8], at: u64) -> Result<(), ReadError> {
        let mut b = Body {
            b: body,
            what: "chunk",
            at,
        };
        let _start = b.u64()?;
        let _end = b.u64()?;
        let size = b.u64()?;
        let crc = b.u32()?;
        let compression = b.string()?;
        let n = b.u64()?;
        let data = b.take(usize::try_from(n).map_err(|_| b.bad())?)?;
        if size > MAX_RECORD {
            return Err(ReadError::TooLong { len: size, at });
        }
        let raw = match compression.as_str() {
            "" => data.to_vec(),
            "lz4" => {
                let mut out = Vec::new();
                lz4_flex::frame::FrameDecoder::new(data)
                    .take(size + 1)
                    .read_to_end(&mut out)
                    .map_err(|_| ReadError::CorruptChunk(at))?;
                out
            }
            other => return Err(ReadError::Compression(other.to_string())),
        };
        if raw.len() as u64 != size || (crc != 0 && crc32fast::hash(&raw) != crc) {
            return Err(ReadError::CorruptChunk(at));
        }
        let mut rest = raw.as_slice();
        while !rest.is_empty() {
            if rest.len() < 9 {
                return Err(ReadError::CorruptChunk(at));
            }
            let opcode = rest[0];
            let mut len = [0u8; 8];
            len.copy_from_slice(&rest[1..9]);
            let len = usize::try_from(u64::from_le_bytes(len)).unwrap_or(usize::MAX);
            if rest.len() - 9 < len {
                return Err(ReadError::CorruptChunk(at));
            }
            if let Some(r) = decode(opcode, &rest[9..9 + len], at)? {
                self.pending.push_back(r);
            }
            rest = &rest[9 + len..];
        }
        Ok(())
    }
}

/// Decodes one record of interest (`None` for the others).
fn decode(opcode: u8, body: &[u8], at: u64) -> Result<Option<Record>, ReadError> {
    let what = match opcode {
        op::SCHEMA => "schema",
        op::CHANNEL => "channel",
        op::MESSAGE => "message",
        op::METADATA => "metadata",
        _ => return Ok(None),
    };
    let mut b = Body { b: body, what, at };
    Ok(Some(match opcode {
        op::SCHEMA => Record::Schema(Schema {
            id: b.u16()?,
            name: b.string()?,
            encoding: b.string()?,
            data: b.bytes()?.to_vec(),
        }),
        op::CHANNEL => Record::Channel(Channel {
            id: b.u16()?,
            schema_id: b.u16()?,
            topic: b.string()?,
            message_encoding: b.string()?,
            metadata: b.str_map()?,
        }),
        op::MESSAGE => Record::Message {
            channel: b.u16()?,
            sequence: b.u32()?,
            log_time: b.u64()?,
            publish_time: b.u64()?,
            data: b.b.to_vec(),
        },
        _ => Record::Metadata {
            name: b.string()?,
            entries: b.str_map()?,
        },
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap::{Compression, McapWriter};

    fn file(compression: Compression) -> Vec<u8> {
        let mut w = McapWriter::new(Vec::new(), "test", compression, 1024).unwrap();
        w.add_metadata("m", &[("k".into(), "v".into())]).unwrap();
        let s = w.add_schema("S", "enc", b"{}").unwrap();
        let c = w.add_channel(s, "/t", "raw", &[]).unwrap();
        for i in 0..200u64 {
            w.write_message(c, i, i, &i.to_le_bytes()).unwrap();
        }
        w.finish().unwrap()
    }

    fn read_all(bytes: &[u8]) -> Result<Vec<Record>, ReadError> {
        let mut r = McapReader::new(bytes)?;
        let mut out = Vec::new();
        while let Some(rec) = r.next_record()? {
            out.push(rec);
        }
        Ok(out)
    }

    #[test]
    fn what_is_written_reads_back_in_order() {
        for c in [Compression::Lz4, Compression::None] {
            let recs = read_all(&file(c)).unwrap();
            let data: Vec<u64> = recs
                .iter()
                .filter_map(|r| match r {
                    Record::Message { data, .. } => {
                        Some(u64::from_le_bytes(data.as_slice().try_into().unwrap()))
                    }
                    _ => None,
                })
                .collect();
            assert_eq!(data, (0..200).collect::<Vec<_>>());
        }
    }

    #[test]
    fn truncated_and_corrupted_files_are_errors_never_panics() {
        let good = file(Compression::Lz4);
        // Any prefix reads whole (cut in the summary) or fails with an error.
        let cuts = (0..good.len()).step_by(7);
        let tried = cuts.clone().count();
        let cut_short = cuts.filter(|cut| read_all(&good[..*cut]).is_err()).count();
        assert!(cut_short > tried / 4, "{cut_short} of {tried}");
        assert!(matches!(
            read_all(b"not an mcap file"),
            Err(ReadError::NotMcap)
        ));
        let refused = (8..good.len())
            .step_by(11)
            .filter(|i| {
                let mut bad = good.clone();
                bad[*i] ^= 0x5a;
                read_all(&bad).is_err()
            })
            .count();
        assert!(refused > 0);
        // A record that claims more than is allowed is refused before it is read.
        let mut huge = MAGIC.to_vec();
        huge.push(op::MESSAGE);
        huge.extend_from_slice(&u64::MAX.to_le_bytes());
        assert!(matches!(read_all(&huge), Err(ReadError::TooLong { .. })));
    }
}
