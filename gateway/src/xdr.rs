//! XDR as Player's generator writes it: every scalar a big-endian 4-byte word (`u8`,
//! `u16` and `char` widened), `f64` 8 bytes, and each variable array as `count, count,
//! elements` (the struct's `_count` member, then `xdr_array`'s own count). Byte arrays
//! are padded to a multiple of 4.
//!
//! [`XdrWriter`] appends to a `Vec<u8>`; [`XdrReader`] reads a body and fails with an
//! [`XdrError`] (never a panic) on anything short, inconsistent or oversized.

use thiserror::Error;

/// A body could not be decoded.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum XdrError {
    /// The body ended before a field.
    #[error("the body ends before {field} ({needed} more bytes needed)")]
    Short {
        /// The field being read.
        field: &'static str,
        /// Bytes it needs beyond the end.
        needed: usize,
    },
    /// The two counts of an array differ.
    #[error("{field}: the two counts differ ({first} and {second})")]
    CountMismatch {
        /// The array.
        field: &'static str,
        /// The struct's count.
        first: u32,
        /// `xdr_array`'s count.
        second: u32,
    },
    /// An array longer than the message allows.
    #[error("{field}: {count} elements, at most {max}")]
    TooLong {
        /// The array.
        field: &'static str,
        /// Its count.
        count: u32,
        /// The limit.
        max: usize,
    },
    /// Bytes left after the last field.
    #[error("{0} bytes after the last field")]
    Trailing(usize),
}

/// Writes XDR words.
#[derive(Debug, Default, Clone)]
pub struct XdrWriter {
    buf: Vec<u8>,
}

impl XdrWriter {
    /// An empty body.
    pub fn new() -> Self {
        XdrWriter::default()
    }
    /// A `u32` (and any `u8`/`u16` widened to it).
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.buf.extend_from_slice(&v.to_be_bytes());
        self
    }
    /// An `i32`.
    pub fn i32(&mut self, v: i32) -> &mut Self {
        self.buf.extend_from_slice(&v.to_be_bytes());
        self
    }
    /// An `f32`.
    pub fn f32(&mut self, v: f32) -> &mut Self {
        self.buf.extend_from_slice(&v.to_be_bytes());
        self
    }
    /// An `f64`.
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.buf.extend_from_slice(&v.to_be_bytes());
        self
    }
    /// The header of a variable array of `n` elements: its count twice.
    pub fn count(&mut self, n: usize) -> &mut Self {
        let n = u32::try_from(n).unwrap_or(u32::MAX);
        self.u32(n).u32(n)
    }
    /// A byte array with its count (twice), padded to a multiple of 4.
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.count(b.len());
        self.buf.extend_from_slice(b);
        let pad = (4 - b.len() % 4) % 4;
        self.buf.extend(core::iter::repeat_n(0u8, pad));
        self
    }
    /// The body written.
    pub fn finish(&mut self) -> Vec<u8> {
        core::mem::take(&mut self.buf)
    }
}

/// Reads XDR words from a body.
#[derive(Debug, Clone)]
pub struct XdrReader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> XdrReader<'a> {
    /// Reads `buf`.
    pub fn new(buf: &'a [u8]) -> Self {
        XdrReader { buf, pos: 0 }
    }

    fn take<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], XdrError> {
        let end = self.pos + N;
        let Some(s) = self.buf.get(self.pos..end) else {
            return Err(XdrError::Short {
                field,
                needed: end - self.buf.len(),
            });
        };
        self.pos = end;
        let mut out = [0u8; N];
        out.copy_from_slice(s);
        Ok(out)
    }

    /// A `u32` word.
    pub fn u32(&mut self, field: &'static str) -> Result<u32, XdrError> {
        self.take::<4>(field).map(u32::from_be_bytes)
    }
    /// An `i32` word.
    pub fn i32(&mut self, field: &'static str) -> Result<i32, XdrError> {
        self.take::<4>(field).map(i32::from_be_bytes)
    }
    /// A `u8` widened to a word (the low byte; XDR keeps it in the word's last byte).
    pub fn u8(&mut self, field: &'static str) -> Result<u8, XdrError> {
        self.u32(field).map(|v| v as u8)
    }
    /// An `f32` word.
    pub fn f32(&mut self, field: &'static str) -> Result<f32, XdrError> {
        self.take::<4>(field).map(f32::from_be_bytes)
    }
    /// An `f64`.
    pub fn f64(&mut self, field: &'static str) -> Result<f64, XdrError> {
        self.take::<8>(field).map(f64::from_be_bytes)
    }
    /// The two counts of a variable array; the count when they agree and it is at most
    /// `max` (and the body can hold `count` elements of at least `min_elem` bytes).
    pub fn count(
        &mut self,
        field: &'static str,
        max: usize,
        min_elem: usize,
    ) -> Result<usize, XdrError> {
        let first = self.u32(field)?;
        let second = self.u32(field)?;
        if first != second {
            return Err(XdrError::CountMismatch {
                field,
                first,
                second,
            });
        }
        let n = first as usize;
        if n > max {
            return Err(XdrError::TooLong {
                field,
                count: first,
                max,
            });
        }
        let needed = n.saturating_mul(min_elem);
        if needed > self.remaining() {
            return Err(XdrError::Short {
                field,
                needed: needed - self.remaining(),
            });
        }
        Ok(n)
    }
    /// A byte array (counts, bytes, padding) of at most `max` bytes.
    pub fn bytes(&mut self, field: &'static str, max: usize) -> Result<&'a [u8], XdrError> {
        let n = self.count(field, max, 1)?;
        let padded = n + (4 - n % 4) % 4;
        let end = self.pos + padded;
        let Some(s) = self.buf.get(self.pos..end) else {
            return Err(XdrError::Short {
                field,
                needed: end - self.buf.len(),
            });
        };
        self.pos = end;
        Ok(&s[..n])
    }
    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.buf.len() - self.pos
    }
    /// Fails when bytes are left.
    pub fn end(&self) -> Result<(), XdrError> {
        match self.remaining() {
            0 => Ok(()),
            n => Err(XdrError::Trailing(n)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalars_are_big_endian_words_and_arrays_carry_their_count_twice() {
        let body = XdrWriter::new()
            .u32(7)
            .i32(-1)
            .f32(1.0)
            .f64(-2.0)
            .count(2)
            .f32(0.5)
            .f32(0.25)
            .finish();
        assert_eq!(
            body,
            [
                0, 0, 0, 7, // u32
                0xFF, 0xFF, 0xFF, 0xFF, // i32 -1
                0x3F, 0x80, 0, 0, // f32 1.0
                0xC0, 0, 0, 0, 0, 0, 0, 0, // f64 -2.0
                0, 0, 0, 2, 0, 0, 0, 2, // count, count
                0x3F, 0, 0, 0, 0x3E, 0x80, 0, 0, // 0.5, 0.25
            ]
        );
        let mut r = XdrReader::new(&body);
        assert_eq!(r.u32("a"), Ok(7));
        assert_eq!(r.i32("b"), Ok(-1));
        assert_eq!(r.f32("c"), Ok(1.0));
        assert_eq!(r.f64("d"), Ok(-2.0));
        assert_eq!(r.count("e", 8, 4), Ok(2));
        assert_eq!(r.f32("e"), Ok(0.5));
        assert_eq!(r.f32("e"), Ok(0.25));
        assert_eq!(r.end(), Ok(()));
    }

    #[test]
    fn byte_arrays_are_padded_to_a_word() {
        let body = XdrWriter::new().bytes(b"limber").finish();
        assert_eq!(
            body,
            [
                0, 0, 0, 6, 0, 0, 0, 6, b'l', b'i', b'm', b'b', b'e', b'r', 0, 0
            ]
        );
        let mut r = XdrReader::new(&body);
        assert_eq!(r.bytes("name", 64), Ok(&b"limber"[..]));
        assert_eq!(r.end(), Ok(()));
    }

    #[test]
    fn bad_bodies_are_errors() {
        assert!(matches!(
            XdrReader::new(&[0, 0, 1]).u32("x"),
            Err(XdrError::Short { .. })
        ));
        let mismatch = XdrWriter::new().u32(2).u32(3).finish();
        assert!(matches!(
            XdrReader::new(&mismatch).count("x", 8, 4),
            Err(XdrError::CountMismatch { .. })
        ));
        // A count the body cannot hold is refused before anything is allocated.
        let huge = XdrWriter::new().count(1 << 30).finish();
        assert!(matches!(
            XdrReader::new(&huge).count("x", usize::MAX, 4),
            Err(XdrError::Short { .. })
        ));
        assert!(matches!(
            XdrReader::new(&huge).count("x", 32, 4),
            Err(XdrError::TooLong { .. })
        ));
        assert_eq!(XdrReader::new(&[0; 4]).end(), Err(XdrError::Trailing(4)));
    }
}
