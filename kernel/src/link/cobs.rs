//! Consistent Overhead Byte Stuffing: removes every 0x00 from a frame so that 0x00 can delimit
//! frames on the wire. Any byte stream, however damaged, resynchronises at the next 0x00.
//!
//! Overhead is one byte per started 254 bytes of payload (plus the code byte itself), so a
//! 1 KiB frame grows by at most 5 bytes.

/// Largest encoded size of `len` payload bytes (without delimiters).
pub const fn max_encoded_len(len: usize) -> usize {
    len + len / 254 + 1
}

/// Streaming COBS encoder writing into a caller buffer; used by the postcard flavor so a message
/// is serialized, checksummed and stuffed in one pass with no intermediate buffer.
pub struct CobsWriter<'a> {
    dst: &'a mut [u8],
    /// Where the code byte of the current block goes.
    code_idx: usize,
    /// Next free position.
    pos: usize,
    /// Code of the current block: 1 + number of data bytes in it.
    code: u8,
}

/// The destination buffer is too small.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BufferFull;

impl<'a> CobsWriter<'a> {
    /// Starts encoding at `dst[start]` (the caller may have put a delimiter before it).
    pub fn new(dst: &'a mut [u8], start: usize) -> Result<Self, BufferFull> {
        if start >= dst.len() {
            return Err(BufferFull);
        }
        Ok(Self {
            dst,
            code_idx: start,
            pos: start + 1,
            code: 1,
        })
    }

    fn put(&mut self, idx: usize, byte: u8) -> Result<(), BufferFull> {
        *self.dst.get_mut(idx).ok_or(BufferFull)? = byte;
        Ok(())
    }

    fn close_block(&mut self) -> Result<(), BufferFull> {
        self.put(self.code_idx, self.code)?;
        self.code_idx = self.pos;
        self.pos += 1;
        self.code = 1;
        Ok(())
    }

    /// Encodes one payload byte.
    pub fn push(&mut self, byte: u8) -> Result<(), BufferFull> {
        if byte == 0 {
            return self.close_block();
        }
        self.put(self.pos, byte)?;
        self.pos += 1;
        self.code += 1;
        if self.code == 0xFF {
            self.close_block()?;
        }
        Ok(())
    }

    /// Writes the last code byte; returns the end position (exclusive) and the buffer back.
    pub fn finish(mut self) -> Result<(usize, &'a mut [u8]), BufferFull> {
        self.put(self.code_idx, self.code)?;
        // `pos` was reserved one past the last code byte.
        Ok((self.pos, self.dst))
    }
}

/// Why a received frame is not valid COBS.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CobsError;

/// Decodes `buf` (one frame without its delimiter) in place; returns the decoded length.
///
/// Decoding only ever shrinks data and writes behind the read position, so in-place is safe.
/// Every access is bounds-checked: a damaged frame yields `Err`, never a panic.
pub fn decode_in_place(buf: &mut [u8]) -> Result<usize, CobsError> {
    let n = buf.len();
    let mut read = 0;
    let mut write = 0;
    while read < n {
        let code = *buf.get(read).ok_or(CobsError)?;
        if code == 0 {
            return Err(CobsError);
        }
        read += 1;
        let len = usize::from(code) - 1;
        let end = read.checked_add(len).filter(|&e| e <= n).ok_or(CobsError)?;
        if buf.get(read..end).ok_or(CobsError)?.contains(&0) {
            return Err(CobsError);
        }
        buf.copy_within(read..end, write);
        write += len;
        read = end;
        if code != 0xFF && read < n {
            *buf.get_mut(write).ok_or(CobsError)? = 0;
            write += 1;
        }
    }
    Ok(write)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode(src: &[u8], dst: &mut [u8]) -> usize {
        let mut w = CobsWriter::new(dst, 0).unwrap();
        for &b in src {
            w.push(b).unwrap();
        }
        w.finish().unwrap().0
    }

    #[test]
    fn known_vectors() {
        // From the COBS paper / Wikipedia examples.
        let cases: &[(&[u8], &[u8])] = &[
            (&[0x00], &[0x01, 0x01]),
            (&[0x00, 0x00], &[0x01, 0x01, 0x01]),
            (&[0x11, 0x22, 0x00, 0x33], &[0x03, 0x11, 0x22, 0x02, 0x33]),
            (&[0x11, 0x22, 0x33, 0x44], &[0x05, 0x11, 0x22, 0x33, 0x44]),
            (&[], &[0x01]),
        ];
        for (raw, enc) in cases {
            let mut buf = [0u8; 16];
            let n = encode(raw, &mut buf);
            assert_eq!(&buf[..n], *enc);
            let m = decode_in_place(&mut buf[..n]).unwrap();
            assert_eq!(&buf[..m], *raw);
        }
    }

    #[test]
    fn long_runs_round_trip() {
        for len in [253usize, 254, 255, 508, 600] {
            let raw: [u8; 600] = core::array::from_fn(|i| (i % 255) as u8 + 1);
            let raw = &raw[..len];
            let mut buf = [0u8; 700];
            let n = encode(raw, &mut buf);
            assert!(n <= max_encoded_len(len));
            assert!(!buf[..n].contains(&0));
            let m = decode_in_place(&mut buf[..n]).unwrap();
            assert_eq!(&buf[..m], raw);
        }
    }

    #[test]
    fn rejects_truncated_block_and_zero() {
        let mut b = [0x05, 0x11, 0x22];
        assert_eq!(decode_in_place(&mut b), Err(CobsError));
        let mut b = [0x03, 0x00, 0x22];
        assert_eq!(decode_in_place(&mut b), Err(CobsError));
    }

    #[test]
    fn encoder_reports_full_buffer() {
        let mut buf = [0u8; 3];
        let mut w = CobsWriter::new(&mut buf, 0).unwrap();
        w.push(1).unwrap();
        w.push(2).unwrap();
        assert_eq!(w.push(3), Err(BufferFull));
    }
}
