//! The MCAP writer: chunked, indexed, with a summary, in bounded memory (one chunk).

use std::collections::BTreeMap;
use std::io::Write;

use thiserror::Error;

use super::{MAGIC, PROFILE, op};

/// How chunks are compressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Compression {
    /// LZ4 frames (MCAP's `lz4`).
    #[default]
    Lz4,
    /// None.
    None,
}

impl Compression {
    fn name(self) -> &'static str {
        match self {
            Compression::Lz4 => "lz4",
            Compression::None => "",
        }
    }
}

/// Writing an MCAP file failed.
#[derive(Debug, Error)]
pub enum WriteError {
    /// The file could not be written.
    #[error("cannot write the MCAP file: {0}")]
    Io(#[from] std::io::Error),
    /// A chunk could not be compressed.
    #[error("cannot compress a chunk: {0}")]
    Compress(#[source] lz4_flex::frame::Error),
    /// More schemas or channels than MCAP's 16-bit ids can name.
    #[error("too many schemas or channels for one MCAP file")]
    TooMany,
}

/// A byte buffer that MCAP's primitive types are written into.
#[derive(Default)]
pub(crate) struct Buf(pub Vec<u8>);

impl Buf {
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    pub fn u16(&mut self, v: u16) -> &mut Self {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    /// A length-prefixed (u32) byte string.
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.u32(b.len() as u32);
        self.0.extend_from_slice(b);
        self
    }
    pub fn str(&mut self, s: &str) -> &mut Self {
        self.bytes(s.as_bytes())
    }
    /// A map of strings (u32 byte length, then key, value, key, value...).
    pub fn str_map(&mut self, m: &[(String, String)]) -> &mut Self {
        let mut inner = Buf::default();
        for (k, v) in m {
            inner.str(k).str(v);
        }
        self.bytes(&inner.0)
    }
    /// Appends this buffer as the body of a record with opcode `op` to `out`.
    pub fn record_into(&self, op: u8, out: &mut Vec<u8>) {
        out.push(op);
        out.extend_from_slice(&(self.0.len() as u64).to_le_bytes());
        out.extend_from_slice(&self.0);
    }
}

/// The output file, with its position and the running CRC of what was written.
struct Out<W: Write> {
    w: W,
    pos: u64,
    crc: crc32fast::Hasher,
}

impl<W: Write> Out<W> {
    fn put(&mut self, b: &[u8]) -> Result<(), WriteError> {
        self.w.write_all(b)?;
        self.crc.update(b);
        self.pos += b.len() as u64;
        Ok(())
    }
    fn record(&mut self, op: u8, body: &Buf) -> Result<(), WriteError> {
        let mut r = Vec::with_capacity(body.0.len() + 9);
        body.record_into(op, &mut r);
        self.put(&r)
    }
    /// Restarts the CRC (the summary's CRC starts at the summary).
    fn restart_crc(&mut self) -> u32 {
        core::mem::take(&mut self.crc).finalize()
    }
}

/// One schema or channel record as it goes into the summary.
struct Kept {
    op: u8,
    body: Buf,
}

/// Writes an MCAP file: schemas and channels as they are added, messages in chunks of
/// about `chunk_size` bytes (the only buffer it holds), the summary at [`McapWriter::finish`].
pub struct McapWriter<W: Write> {
    out: Out<W>,
    compression: Compression,
    chunk_size: usize,
    chunk: Vec<u8>,
    chunk_times: Option<(u64, u64)>,
    /// Per channel, (log time, offset in the chunk) of each message of the current chunk.
    chunk_messages: BTreeMap<u16, Vec<(u64, u64)>>,
    kept: Vec<Kept>,
    next_schema: u16,
    next_channel: u16,
    chunk_indexes: Vec<Buf>,
    metadata_indexes: Vec<Buf>,
    counts: BTreeMap<u16, u64>,
    times: Option<(u64, u64)>,
    sequences: BTreeMap<u16, u32>,
}

impl<W: Write> core::fmt::Debug for McapWriter<W> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("McapWriter")
            .field("pos", &self.out.pos)
            .finish_non_exhaustive()
    }
}

impl<W: Write> McapWriter<W> {
    /// Starts a file on `w` (the magic and the header), `library` naming the writer.
    pub fn new(
        w: W,
        library: &str,
        compression: Compression,
        chunk_size: usize,
    ) -> Result<Self, WriteError> {
        let mut out = Out {
            w,
            pos: 0,
            crc: crc32fast::Hasher::new(),
        };
        out.put(&MAGIC)?;
        out.record(op::HEADER, Buf::default().str(PROFILE).str(library))?;
        Ok(McapWriter {
            out,
            compression,
            chunk_size: chunk_size.max(1024),
            chunk: Vec::new(),
            chunk_times: None,
            chunk_messages: BTreeMap::new(),
            kept: Vec::new(),
            next_schema: 1,
            next_channel: 0,
            chunk_indexes: Vec::new(),
            metadata_indexes: Vec::new(),
            counts: BTreeMap::new(),
            times: None,
            sequences: BTreeMap::new(),
        })
    }

    /// The bytes written so far (the current chunk not included).
    pub fn written(&self) -> u64 {
        self.out.pos
    }

    /// Adds a schema; its id.
    pub fn add_schema(
        &mut self,
        name: &str,
        encoding: &str,
        data: &[u8],
    ) -> Result<u16, WriteError> {
        let id = self.next_schema;
        self.next_schema = id.checked_add(1).ok_or(WriteError::TooMany)?;
        let mut body = Buf::default();
        body.u16(id).str(name).str(encoding).bytes(data);
        self.out.record(op::SCHEMA, &body)?;
        self.kept.push(Kept {
            op: op::SCHEMA,
            body,
        });
        Ok(id)
    }

    /// Adds a channel on `topic` of schema `schema` (0: none); its id.
    pub fn add_channel(
        &mut self,
        schema: u16,
        topic: &str,
        message_encoding: &str,
        metadata: &[(String, String)],
    ) -> Result<u16, WriteError> {
        let id = self.next_channel;
        self.next_channel = id.checked_add(1).ok_or(WriteError::TooMany)?;
        let mut body = Buf::default();
        body.u16(id)
            .u16(schema)
            .str(topic)
            .str(message_encoding)
            .str_map(metadata);
        self.out.record(op::CHANNEL, &body)?;
        self.kept.push(Kept {
            op: op::CHANNEL,
            body,
        });
        self.counts.insert(id, 0);
        Ok(id)
    }

    /// Writes a metadata record `name` (indexed in the summary).
    pub fn add_metadata(
        &mut self,
        name: &str,
        entries: &[(String, String)],
    ) -> Result<(), WriteError> {
        let offset = self.out.pos;
        let mut body = Buf::default();
        body.str(name).str_map(entries);
        self.out.record(op::METADATA, &body)?;
        let mut index = Buf::default();
        index.u64(offset).u64(self.out.pos - offset).str(name);
        self.metadata_indexes.push(index);
        Ok(())
    }

    /// Writes one message of `channel`: `log_time` when it was received, `publish_time`
    /// when it was acquired (nanoseconds since the Unix epoch).
    pub fn write_message(
        &mut self,
        channel: u16,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), WriteError> {
        let seq = self.sequences.entry(channel).or_insert(0);
        *seq = seq.wrapping_add(1);
        let mut body = Buf(Vec::with_capacity(data.len() + 22));
        body.u16(channel).u32(*seq).u64(log_time).u64(publish_time);
        body.0.extend_from_slice(data);
        let offset = self.chunk.len() as u64;
        body.record_into(op::MESSAGE, &mut self.chunk);
        self.chunk_messages
            .entry(channel)
            .or_default()
            .push((log_time, offset));
        let widen = |t: Option<(u64, u64)>| match t {
            Some((a, b)) => Some((a.min(log_time), b.max(log_time))),
            None => Some((log_time, log_time)),
        };
        self.chunk_times = widen(self.chunk_times);
        self.times = widen(self.times);
        *self.counts.entry(channel).or_insert(0) += 1;
        if self.chunk.len() >= self.chunk_size {
            self.flush_chunk()?;
        }
        Ok(())
    }

    /// Writes the current chunk (if any) and its message indexes.
    pub fn flush_chunk(&mut self) -> Result<(), WriteError> {
        let Some((start, end)) = self.chunk_times.take() else {
            return Ok(());
        };
        let raw = core::mem::take(&mut self.chunk);
        let crc = crc32fast::hash(&raw);
        let compressed;
        let data: &[u8] = match self.compression {
            Compression::None => &raw,
            Compression::Lz4 => {
                let mut enc = lz4_flex::frame::FrameEncoder::new(Vec::new());
                enc.write_all(&raw)?;
                compressed = enc.finish().map_err(WriteError::Compress)?;
                &compressed
            }
        };
        let chunk_start = self.out.pos;
        let mut body = Buf(Vec::with_capacity(data.len() + 64));
        body.u64(start)
            .u64(end)
            .u64(raw.len() as u64)
            .u32(crc)
            .str(self.compression.name())
            .u64(data.len() as u64);
        body.0.extend_from_slice(data);
        self.out.record(op::CHUNK, &body)?;
        let chunk_length = self.out.pos - chunk_start;
        let index_start = self.out.pos;
        let mut offsets = Buf::default();
        for (channel, entries) in core::mem::take(&mut self.chunk_messages) {
            offsets.u16(channel).u64(self.out.pos);
            let mut list = Buf::default();
            for (t, o) in entries {
                list.u64(t).u64(o);
            }
            let mut index = Buf::default();
            index.u16(channel).bytes(&list.0);
            self.out.record(op::MESSAGE_INDEX, &index)?;
        }
        let mut ci = Buf::default();
        ci.u64(start)
            .u64(end)
            .u64(chunk_start)
            .u64(chunk_length)
            .bytes(&offsets.0)
            .u64(self.out.pos - index_start)
            .str(self.compression.name())
            .u64(data.len() as u64)
            .u64(raw.len() as u64);
        self.chunk_indexes.push(ci);
        // Keep the buffer's capacity for the next chunk.
        self.chunk = raw;
        self.chunk.clear();
        Ok(())
    }

    /// Messages written per channel so far.
    pub fn counts(&self) -> &BTreeMap<u16, u64> {
        &self.counts
    }

    /// Ends the file: the last chunk, the data end, the summary and the footer; returns
    /// the writer.
    pub fn finish(mut self) -> Result<W, WriteError> {
        self.flush_chunk()?;
        let data_crc = self.out.restart_crc();
        self.out
            .record(op::DATA_END, Buf::default().u32(data_crc))?;
        self.out.restart_crc();
        let summary_start = self.out.pos;
        let mut groups: Vec<(u8, u64, u64)> = Vec::new();
        let kept = core::mem::take(&mut self.kept);
        for wanted in [op::SCHEMA, op::CHANNEL] {
            let start = self.out.pos;
            for k in kept.iter().filter(|k| k.op == wanted) {
                self.out.record(k.op, &k.body)?;
            }
            if self.out.pos > start {
                groups.push((wanted, start, self.out.pos - start));
            }
        }
        let (t0, t1) = self.times.unwrap_or((0, 0));
        let mut counts = Buf::default();
        for (c, n) in &self.counts {
            counts.u16(*c).u64(*n);
        }
        let mut stats = Buf::default();
        stats
            .u64(self.counts.values().sum())
            .u16(kept.iter().filter(|k| k.op == op::SCHEMA).count() as u16)
            .u32(kept.iter().filter(|k| k.op == op::CHANNEL).count() as u32)
            .u32(0)
            .u32(self.metadata_indexes.len() as u32)
            .u32(self.chunk_indexes.len() as u32)
            .u64(t0)
            .u64(t1)
            .bytes(&counts.0);
        let start = self.out.pos;
        self.out.record(op::STATISTICS, &stats)?;
        groups.push((op::STATISTICS, start, self.out.pos - start));
        for (opcode, records) in [
            (op::CHUNK_INDEX, core::mem::take(&mut self.chunk_indexes)),
            (
                op::METADATA_INDEX,
                core::mem::take(&mut self.metadata_indexes),
            ),
        ] {
            let start = self.out.pos;
            for r in &records {
                self.out.record(opcode, r)?;
            }
            if self.out.pos > start {
                groups.push((opcode, start, self.out.pos - start));
            }
        }
        let summary_offset_start = self.out.pos;
        for (opcode, start, len) in groups {
            self.out.record(
                op::SUMMARY_OFFSET,
                Buf::default().u8(opcode).u64(start).u64(len),
            )?;
        }
        // The footer's CRC covers the summary and the footer up to the CRC itself.
        let mut head = Vec::new();
        head.push(op::FOOTER);
        head.extend_from_slice(&20u64.to_le_bytes());
        head.extend_from_slice(&summary_start.to_le_bytes());
        head.extend_from_slice(&summary_offset_start.to_le_bytes());
        self.out.put(&head)?;
        let crc = self.out.restart_crc();
        self.out.put(&crc.to_le_bytes())?;
        self.out.put(&MAGIC)?;
        self.out.w.flush()?;
        Ok(self.out.w)
    }
}
