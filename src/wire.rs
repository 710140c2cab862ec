//! The byte format of plans and partial results: a frame (magic, format version, library
//! version, payload length, payload, checksum) around little-endian fields. Written by hand
//! because the kernel has no serialization crate and the format is small; the checksum
//! (XXH3-64 over everything before it) catches truncation and corruption before a field is
//! read.

use crate::error::{Error, MLT_STATUS_INVALID_ARGUMENT, Result};
use xxhash_rust::xxh3::xxh3_64;

/// Raised with every change to what a frame holds: an older or newer buffer is refused.
pub(crate) const FORMAT_VERSION: u32 = 3;

/// The library that writes and reads a frame: renders from two versions of the kernel need
/// not agree bit for bit.
const LIBRARY_VERSION: &str = env!("CARGO_PKG_VERSION");
/// Bytes the version takes in a frame, zero-padded.
const VERSION_LEN: usize = 16;
const _: () = assert!(LIBRARY_VERSION.len() <= VERSION_LEN);

const HEADER_LEN: usize = 8 + 4 + VERSION_LEN + 8;
const CHECKSUM_LEN: usize = 8;

/// Builds a payload field by field.
#[derive(Default)]
pub(crate) struct Writer {
    bytes: Vec<u8>,
}

impl Writer {
    pub fn u8(&mut self, value: u8) {
        self.bytes.push(value);
    }

    pub fn bool(&mut self, value: bool) {
        self.u8(value as u8);
    }

    pub fn u32(&mut self, value: u32) {
        self.bytes.extend_from_slice(&value.to_le_bytes());
    }

    pub fn u64(&mut self, value: u64) {
        self.bytes.extend_from_slice(&value.to_le_bytes());
    }

    pub fn f32(&mut self, value: f32) {
        self.u32(value.to_bits());
    }

    pub fn f64(&mut self, value: f64) {
        self.u64(value.to_bits());
    }

    /// A length or count, as a u64.
    pub fn len(&mut self, value: usize) {
        self.u64(value as u64);
    }

    /// An i128 as a zigzag LEB128 varint: film sums are mostly far below 2^127 (and zero
    /// outside a job's share), so a pixel takes a few bytes instead of 16.
    pub fn varint_i128(&mut self, value: i128) {
        let mut zigzag = ((value << 1) ^ (value >> 127)) as u128;
        loop {
            let byte = (zigzag & 0x7f) as u8;
            zigzag >>= 7;
            if zigzag == 0 {
                self.u8(byte);
                return;
            }
            self.u8(byte | 0x80);
        }
    }

    /// Wraps the payload in a frame with `magic`.
    pub fn finish(self, magic: &[u8; 8]) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_LEN + self.bytes.len() + CHECKSUM_LEN);
        out.extend_from_slice(magic);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        let mut version = [0u8; VERSION_LEN];
        version[..LIBRARY_VERSION.len()].copy_from_slice(LIBRARY_VERSION.as_bytes());
        out.extend_from_slice(&version);
        out.extend_from_slice(&(self.bytes.len() as u64).to_le_bytes());
        out.extend_from_slice(&self.bytes);
        let checksum = xxh3_64(&out);
        out.extend_from_slice(&checksum.to_le_bytes());
        out
    }
}

/// Reads a payload field by field; every read past its end is an error.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    what: &'static str,
}

fn invalid(message: String) -> Error {
    Error::new(MLT_STATUS_INVALID_ARGUMENT, message)
}

impl<'a> Reader<'a> {
    /// Checks the frame around a `what` (named in errors) and returns a reader of its
    /// payload.
    pub fn open(bytes: &'a [u8], magic: &[u8; 8], what: &'static str) -> Result<Self> {
        if bytes.len() < HEADER_LEN + CHECKSUM_LEN || &bytes[..8] != magic {
            return Err(invalid(format!(
                "this buffer of {} bytes is not an mlt {what}",
                bytes.len()
            )));
        }
        let format = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
        if format != FORMAT_VERSION {
            return Err(invalid(format!(
                "the {what} is in format {format}, this library (mlt {LIBRARY_VERSION}) reads format {FORMAT_VERSION}"
            )));
        }
        let version = &bytes[12..12 + VERSION_LEN];
        let version_end = version.iter().position(|&b| b == 0).unwrap_or(VERSION_LEN);
        let library = String::from_utf8_lossy(&version[..version_end]);
        if library != LIBRARY_VERSION {
            return Err(invalid(format!(
                "the {what} was made by mlt {library}, this is mlt {LIBRARY_VERSION}: every job of a render must run the same version"
            )));
        }
        let length = u64::from_le_bytes(bytes[12 + VERSION_LEN..HEADER_LEN].try_into().unwrap());
        let expected = (HEADER_LEN + CHECKSUM_LEN) as u64;
        if length.checked_add(expected) != Some(bytes.len() as u64) {
            return Err(invalid(format!(
                "the {what} is {} bytes long but its header says {}: it was truncated or padded",
                bytes.len(),
                length.saturating_add(expected)
            )));
        }
        let (framed, checksum) = bytes.split_at(bytes.len() - CHECKSUM_LEN);
        if xxh3_64(framed).to_le_bytes() != checksum {
            return Err(invalid(format!(
                "the {what}'s checksum does not match: the buffer was corrupted"
            )));
        }
        Ok(Reader {
            bytes: &framed[HEADER_LEN..],
            what,
        })
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if self.bytes.len() < n {
            return Err(self.malformed("it ends early"));
        }
        let (head, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        Ok(head)
    }

    /// An error for a payload that passed the checksum but does not parse: a buffer written
    /// by a different build of the same version.
    pub fn malformed(&self, why: &str) -> Error {
        invalid(format!("the {} is malformed: {why}", self.what))
    }

    pub fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    pub fn bool(&mut self) -> Result<bool> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(self.malformed("a flag is neither 0 nor 1")),
        }
    }

    pub fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }

    pub fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }

    pub fn f32(&mut self) -> Result<f32> {
        Ok(f32::from_bits(self.u32()?))
    }

    pub fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_bits(self.u64()?))
    }

    /// A length of items of at least `min_item_bytes` each: more than the rest of the
    /// payload could hold is an error, so a bad length never allocates.
    pub fn len(&mut self, min_item_bytes: usize) -> Result<usize> {
        let n = self.u64()?;
        if n.saturating_mul(min_item_bytes.max(1) as u64) > self.bytes.len() as u64 {
            return Err(self.malformed("a length exceeds the buffer"));
        }
        Ok(n as usize)
    }

    pub fn varint_i128(&mut self) -> Result<i128> {
        let mut zigzag = 0u128;
        for shift in (0..133).step_by(7) {
            let byte = self.u8()?;
            if shift == 126 && byte > 0x03 {
                break;
            }
            zigzag |= ((byte & 0x7f) as u128) << shift;
            if byte & 0x80 == 0 {
                return Ok((zigzag >> 1) as i128 ^ -((zigzag & 1) as i128));
            }
        }
        Err(self.malformed("a varint is too long"))
    }

    /// Every byte must have been read.
    pub fn end(self) -> Result<()> {
        if self.bytes.is_empty() {
            Ok(())
        } else {
            Err(self.malformed("bytes are left over"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MAGIC: &[u8; 8] = b"MLTTEST\0";

    #[test]
    fn fields_round_trip_and_varints_cover_i128() {
        let values = [0i128, 1, -1, 63, -64, 64, 1 << 70, i128::MAX, i128::MIN];
        let mut w = Writer::default();
        w.u32(7);
        w.f64(-0.5);
        w.bool(true);
        for v in values {
            w.varint_i128(v);
        }
        let bytes = w.finish(MAGIC);
        let mut r = Reader::open(&bytes, MAGIC, "test").unwrap();
        assert_eq!(r.u32().unwrap(), 7);
        assert_eq!(r.f64().unwrap(), -0.5);
        assert!(r.bool().unwrap());
        for v in values {
            assert_eq!(r.varint_i128().unwrap(), v);
        }
        r.end().unwrap();
    }

    #[test]
    fn every_corruption_and_truncation_is_refused() {
        let mut w = Writer::default();
        for i in 0..20 {
            w.u64(i * 0x0123_4567_89ab);
        }
        let bytes = w.finish(MAGIC);
        for at in 0..bytes.len() {
            let mut flipped = bytes.clone();
            flipped[at] ^= 0x10;
            assert!(Reader::open(&flipped, MAGIC, "test").is_err(), "byte {at}");
            assert!(Reader::open(&bytes[..at], MAGIC, "test").is_err());
        }
        assert!(Reader::open(&bytes, b"MLTOTHR\0", "test").is_err());
        // Reading past the payload's end is an error, not a panic.
        let mut r = Reader::open(&bytes, MAGIC, "test").unwrap();
        for i in 0..20 {
            assert_eq!(r.u64().unwrap(), i * 0x0123_4567_89ab);
        }
        assert!(r.u8().is_err());
    }
}
