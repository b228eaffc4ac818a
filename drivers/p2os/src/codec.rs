//! Packet framing: checksum, encoding into a fixed buffer, and the streaming
//! [`Decoder`].

use thiserror::Error;

/// First header byte of every P2OS packet.
pub const HEADER0: u8 = 0xFA;
/// Second header byte of every P2OS packet.
pub const HEADER1: u8 = 0xFB;
/// Largest payload a packet can carry: the length byte `N` is `payload + 2`
/// and must fit in one byte.
pub const MAX_PAYLOAD: usize = 253;
/// Largest whole packet: header (2) + length byte (1) + payload + checksum (2).
pub const MAX_FRAME: usize = MAX_PAYLOAD + 5;

/// The P2OS checksum over a payload: sum of big-endian 16-bit words, masked
/// to 16 bits after each addition; a trailing odd byte is XORed in unshifted.
/// Sent high byte first.
pub fn checksum(payload: &[u8]) -> u16 {
    let mut sum: u16 = 0;
    let mut pairs = payload.chunks_exact(2);
    for pair in &mut pairs {
        sum = sum.wrapping_add(u16::from_be_bytes([pair[0], pair[1]]));
    }
    if let [last] = pairs.remainder() {
        sum ^= u16::from(*last);
    }
    sum
}

/// Why a packet could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum EncodeError {
    /// The payload is empty: a packet needs at least its command/type byte.
    #[error("empty payload: a packet needs at least a command byte")]
    Empty,
    /// The payload is longer than [`MAX_PAYLOAD`].
    #[error("payload of {0} bytes exceeds the maximum of {MAX_PAYLOAD}")]
    TooLong(usize),
    /// An integer argument does not fit the 16-bit sign-magnitude encoding.
    #[error("argument {0} is outside -65535..=65535")]
    ArgumentRange(i32),
    /// A string argument is longer than 255 bytes.
    #[error("string argument of {0} bytes is longer than 255")]
    StringTooLong(usize),
}

/// One encoded packet in a fixed buffer (no heap).
#[derive(Clone, Copy)]
pub struct Frame {
    bytes: [u8; MAX_FRAME],
    len: u16,
}

impl Frame {
    /// Frames `payload` (header, length, payload, checksum).
    pub fn new(payload: &[u8]) -> Result<Frame, EncodeError> {
        if payload.is_empty() {
            return Err(EncodeError::Empty);
        }
        if payload.len() > MAX_PAYLOAD {
            return Err(EncodeError::TooLong(payload.len()));
        }
        let mut bytes = [0u8; MAX_FRAME];
        bytes[0] = HEADER0;
        bytes[1] = HEADER1;
        bytes[2] = (payload.len() + 2) as u8;
        bytes[3..3 + payload.len()].copy_from_slice(payload);
        let c = checksum(payload).to_be_bytes();
        bytes[3 + payload.len()] = c[0];
        bytes[4 + payload.len()] = c[1];
        Ok(Frame {
            bytes,
            len: (payload.len() + 5) as u16,
        })
    }

    /// The whole packet as it goes on the wire.
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..usize::from(self.len)]
    }

    /// The payload (command or type byte first).
    pub fn payload(&self) -> &[u8] {
        &self.bytes[3..usize::from(self.len) - 2]
    }

    /// Replaces the checksum by a wrong one (for fault injection and tests).
    pub fn corrupt_checksum(&mut self) {
        let i = usize::from(self.len) - 1;
        self.bytes[i] = self.bytes[i].wrapping_add(1);
    }
}

impl std::fmt::Debug for Frame {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Frame(")?;
        for (i, b) in self.as_bytes().iter().enumerate() {
            if i > 0 {
                write!(f, " ")?;
            }
            write!(f, "{b:02X}")?;
        }
        write!(f, ")")
    }
}

/// A small builder for payloads with P2OS argument encoding, in a fixed
/// buffer.
#[derive(Clone, Copy)]
pub struct PayloadBuilder {
    buf: [u8; MAX_PAYLOAD],
    len: usize,
    overflow: bool,
}

/// Argument type byte: non-negative 16-bit integer, little-endian.
pub const ARGINT: u8 = 0x3B;
/// Argument type byte: negative integer, little-endian magnitude.
pub const ARGNINT: u8 = 0x1B;
/// Argument type byte: string, a length byte then the characters.
pub const ARGSTR: u8 = 0x2B;

impl PayloadBuilder {
    /// Starts a payload with its command (or packet type) byte.
    pub fn new(command: u8) -> PayloadBuilder {
        let mut b = PayloadBuilder {
            buf: [0; MAX_PAYLOAD],
            len: 0,
            overflow: false,
        };
        b.byte(command);
        b
    }

    /// Appends raw bytes.
    pub fn bytes(&mut self, data: &[u8]) -> &mut Self {
        if self.len + data.len() > MAX_PAYLOAD {
            self.overflow = true;
        } else {
            self.buf[self.len..self.len + data.len()].copy_from_slice(data);
            self.len += data.len();
        }
        self
    }

    /// Appends one raw byte.
    pub fn byte(&mut self, b: u8) -> &mut Self {
        self.bytes(&[b])
    }

    /// Appends a little-endian u16.
    pub fn u16_le(&mut self, v: u16) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }

    /// Appends an integer argument: `ARGINT` for `v >= 0`, else `ARGNINT`
    /// with the magnitude (sign-magnitude, not two's complement).
    pub fn int_arg(&mut self, v: i32) -> Result<&mut Self, EncodeError> {
        let mag = v.unsigned_abs();
        if mag > 0xFFFF {
            return Err(EncodeError::ArgumentRange(v));
        }
        let ty = if v < 0 { ARGNINT } else { ARGINT };
        Ok(self.byte(ty).u16_le(mag as u16))
    }

    /// Appends a string argument (`ARGSTR`, length byte, characters).
    pub fn str_arg(&mut self, s: &[u8]) -> Result<&mut Self, EncodeError> {
        if s.len() > 255 {
            return Err(EncodeError::StringTooLong(s.len()));
        }
        Ok(self.byte(ARGSTR).byte(s.len() as u8).bytes(s))
    }

    /// The payload built so far.
    pub fn as_slice(&self) -> &[u8] {
        &self.buf[..self.len]
    }

    /// Frames the payload.
    pub fn frame(&self) -> Result<Frame, EncodeError> {
        if self.overflow {
            return Err(EncodeError::TooLong(MAX_PAYLOAD + 1));
        }
        Frame::new(self.as_slice())
    }
}

/// Counters of a [`Decoder`]. All monotonic.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DecoderStats {
    /// Packets delivered with a good checksum.
    pub packets_ok: u64,
    /// Frames dropped because their checksum did not match.
    pub bad_checksums: u64,
    /// Frames whose length byte was impossible (N < 3).
    pub bad_lengths: u64,
    /// Bytes skipped while searching for a header.
    pub garbage_bytes: u64,
    /// Times the decoder had to skip bytes to find the next header.
    pub resyncs: u64,
    /// Bytes fed into the decoder.
    pub bytes_in: u64,
}

/// Size of the decoder's internal buffer: two maximal frames.
pub const DECODER_BUFFER: usize = 2 * MAX_FRAME;

/// A streaming P2OS decoder.
///
/// Feed it bytes as they arrive ([`Decoder::feed`] or [`Decoder::read_from`])
/// and take packets out with [`Decoder::next_packet`]. It never allocates,
/// never panics, slides over garbage to the next `FA FB N` header, and on a bad
/// checksum drops the frame and rescans from the byte after its `0xFA`, so a
/// real packet that hid inside a corrupted one is still found.
#[derive(Clone)]
pub struct Decoder {
    buf: [u8; DECODER_BUFFER],
    start: usize,
    end: usize,
    ignore_checksum: bool,
    /// Length of a validated frame starting at `start`, not yet taken out.
    pending: Option<usize>,
    stats: DecoderStats,
}

impl Default for Decoder {
    fn default() -> Self {
        Decoder::new()
    }
}

impl std::fmt::Debug for Decoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Decoder")
            .field("buffered", &(self.end - self.start))
            .field("stats", &self.stats)
            .finish()
    }
}

impl Decoder {
    /// A decoder that checks checksums.
    pub fn new() -> Decoder {
        Decoder {
            buf: [0; DECODER_BUFFER],
            start: 0,
            end: 0,
            ignore_checksum: false,
            pending: None,
            stats: DecoderStats::default(),
        }
    }

    /// Accept frames whatever their checksum (Player's `ignore_checksum`).
    /// Off by default; bad checksums are still counted.
    pub fn set_ignore_checksum(&mut self, ignore: bool) {
        self.ignore_checksum = ignore;
    }

    /// The counters.
    pub fn stats(&self) -> DecoderStats {
        self.stats
    }

    /// Bytes buffered but not yet consumed.
    pub fn buffered(&self) -> usize {
        self.end - self.start
    }

    /// Drops everything buffered (e.g. after a flush of the line).
    pub fn clear(&mut self) {
        self.pending = None;
        self.start = 0;
        self.end = 0;
    }

    fn compact(&mut self) {
        if self.start > 0 {
            self.buf.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
        }
    }

    /// Free space for new bytes, after compaction. Always at least
    /// `MAX_FRAME` bytes once pending packets have been taken out.
    fn spare(&mut self) -> &mut [u8] {
        self.compact();
        &mut self.buf[self.end..]
    }

    /// Copies as many bytes of `data` as fit into the buffer and returns how
    /// many it took. Take packets out with [`Decoder::next_packet`] until it
    /// returns `None`, then feed the rest. [`Decoder::decode`] does both.
    pub fn feed(&mut self, data: &[u8]) -> usize {
        let spare = self.spare();
        let n = spare.len().min(data.len());
        spare[..n].copy_from_slice(&data[..n]);
        self.end += n;
        self.stats.bytes_in += n as u64;
        n
    }

    /// Reads once from `r` straight into the buffer. Returns the byte count
    /// (0 = end of stream) or the reader's error (`WouldBlock` for a
    /// nonblocking source with nothing to read).
    pub fn read_from<R: std::io::Read + ?Sized>(&mut self, r: &mut R) -> std::io::Result<usize> {
        if self.end - self.start == DECODER_BUFFER {
            // The caller did not take packets out: drop the oldest byte.
            self.pending = None;
            self.skip(1);
        }
        let spare = self.spare();
        let n = r.read(spare)?;
        let n = n.min(DECODER_BUFFER - self.end);
        self.end += n;
        self.stats.bytes_in += n as u64;
        Ok(n)
    }

    /// Feeds all of `data`, calling `on_packet` with each payload found.
    pub fn decode(&mut self, mut data: &[u8], mut on_packet: impl FnMut(&[u8])) {
        loop {
            while let Some(p) = self.next_packet() {
                on_packet(p);
            }
            if data.is_empty() {
                break;
            }
            let n = self.feed(data);
            data = &data[n..];
        }
    }

    fn skip(&mut self, n: usize) {
        self.start += n;
        self.stats.garbage_bytes += n as u64;
    }

    /// Whether a complete, valid packet is ready (skipping garbage and bad
    /// frames to find it).
    pub fn has_packet(&mut self) -> bool {
        if self.pending.is_none() {
            self.pending = self.scan();
        }
        self.pending.is_some()
    }

    /// The next valid packet's payload without taking it out.
    pub fn peek_packet(&mut self) -> Option<&[u8]> {
        if !self.has_packet() {
            return None;
        }
        let len = self.pending?;
        Some(&self.buf[self.start + 3..self.start + len - 2])
    }

    /// The next complete, valid packet's payload (type byte first), or
    /// `None` when more bytes are needed.
    pub fn next_packet(&mut self) -> Option<&[u8]> {
        if !self.has_packet() {
            return None;
        }
        let len = self.pending.take()?;
        let a = self.start;
        self.start += len;
        Some(&self.buf[a + 3..a + len - 2])
    }

    /// Finds the next valid frame; it starts at `self.start` and its length
    /// is returned. Counts it as delivered.
    fn scan(&mut self) -> Option<usize> {
        loop {
            let avail = &self.buf[self.start..self.end];
            // Find FA FB.
            let mut i = 0;
            let mut found = false;
            while i + 1 < avail.len() {
                if avail[i] == HEADER0 && avail[i + 1] == HEADER1 {
                    found = true;
                    break;
                }
                i += 1;
            }
            if !found {
                // Keep a trailing FA: it may start the next header.
                let keep = usize::from(avail.last() == Some(&HEADER0));
                let drop = avail.len() - keep;
                if drop > 0 {
                    self.stats.resyncs += 1;
                    self.skip(drop);
                }
                if self.start == self.end {
                    self.start = 0;
                    self.end = 0;
                }
                return None;
            }
            if i > 0 {
                self.stats.resyncs += 1;
                self.skip(i);
            }
            let avail = &self.buf[self.start..self.end];
            if avail.len() < 3 {
                return None;
            }
            let n = usize::from(avail[2]);
            if n < 3 {
                self.stats.bad_lengths += 1;
                self.skip(1);
                continue;
            }
            if avail.len() < 3 + n {
                return None;
            }
            let payload = &avail[3..1 + n];
            let sum = u16::from_be_bytes([avail[1 + n], avail[2 + n]]);
            let ok = checksum(payload) == sum;
            if ok || self.ignore_checksum {
                if !ok {
                    self.stats.bad_checksums += 1;
                }
                self.stats.packets_ok += 1;
                return Some(3 + n);
            }
            self.stats.bad_checksums += 1;
            // Rescan from the byte after this frame's 0xFA.
            self.skip(1);
        }
    }
}
