//! Frames: `0x00 · COBS(payload · CRC-32(payload) little-endian) · 0x00`.
//!
//! The leading delimiter costs one byte and buys resynchronisation: if the end of the previous
//! frame was lost (a truncated frame), the next frame's leading 0x00 ends the damaged one, so only
//! the damaged frame is lost, never the good one after it. Empty frames (two 0x00 in a row) are
//! idle filler and are ignored.

use cobs::{EncoderState, PushResult};
use crc::{Crc, Digest, CRC_32_ISO_HDLC};

/// Largest frame content before stuffing: payload plus the 4-byte CRC. Both ends refuse more.
pub const MAX_FRAME_LEN: usize = 1024;
/// Largest payload (postcard message with its request id) in one frame.
pub const MAX_PAYLOAD_LEN: usize = MAX_FRAME_LEN - CRC_LEN;
/// Largest stuffed frame, without delimiters: the receive buffer a decoder needs.
pub const MAX_STUFFED_LEN: usize = max_stuffed_len(MAX_FRAME_LEN);
/// Largest frame on the wire, both delimiters included: the transmit buffer an encoder needs.
pub const MAX_WIRE_LEN: usize = MAX_STUFFED_LEN + 2;
/// A decoder sized for the largest frame of this protocol.
pub type MaxFrameDecoder = FrameDecoder<MAX_STUFFED_LEN>;

const CRC_LEN: usize = 4;

/// The frame checksum, CRC-32/ISO-HDLC (zlib's, PNG's, Ethernet's): the `crc` crate's
/// byte-wise table, built at compile time (1 KiB of flash on the firmware). A `static`, so the
/// table exists once and every digest borrows it.
static CRC32: Crc<u32> = Crc::<u32>::new(&CRC_32_ISO_HDLC);

/// CRC-32 of a whole slice: the frame checksum, also what [`Response::SinkAck`] reports.
///
/// [`Response::SinkAck`]: super::Response::SinkAck
pub fn crc32(bytes: &[u8]) -> u32 {
    CRC32.checksum(bytes)
}

/// Largest stuffed size of `len` content bytes: one code byte per started block of 254, plus
/// one. The encoder writes a code byte after every full block even when nothing follows (that
/// is how the protocol's frames have always been stuffed), so this is one more than
/// `cobs::max_encoding_length` when `len` is a multiple of 254.
const fn max_stuffed_len(len: usize) -> usize {
    len + len / 254 + 1
}

/// Why a received frame was dropped. Each kind is counted separately in the link statistics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// More bytes than the receive buffer holds arrived before a delimiter.
    TooLong,
    /// Not valid COBS, or too short to hold a CRC.
    BadFraming,
    /// The CRC does not match: a flipped or lost byte.
    BadCrc,
}

/// Why a frame could not be encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EncodeError {
    /// The output buffer or [`MAX_PAYLOAD_LEN`] is too small for the message.
    TooLong,
    /// The message could not be serialized (a bug, not a wire condition).
    Serialize,
}

/// Encodes `payload` as one frame into `out`; returns the number of bytes written.
pub fn encode_frame(payload: &[u8], out: &mut [u8]) -> Result<usize, EncodeError> {
    let mut w = FrameWriter::new(out)?;
    for &b in payload {
        w.push(b)?;
    }
    w.finish()
}

/// Writes a frame while its payload is produced: checksums and stuffs byte by byte, so messages
/// go from postcard to wire bytes without an intermediate buffer (it is a postcard flavor).
///
/// The stuffing is the `cobs` crate's streaming [`EncoderState`]; this type only owns the
/// buffer, the delimiters and the payload limit. Every write is bounds-checked: a short buffer
/// is [`EncodeError::TooLong`], never a panic.
pub struct FrameWriter<'a> {
    out: &'a mut [u8],
    /// Next free position in `out`.
    end: usize,
    cobs: EncoderState,
    crc: Digest<'static, u32>,
    payload_len: usize,
}

/// Where the stuffed bytes start in `out`: after the leading delimiter.
const STUFFED_AT: usize = 1;

impl<'a> FrameWriter<'a> {
    /// Starts a frame at the beginning of `out`: the leading delimiter, then the placeholder
    /// for the first code byte that [`EncoderState`] expects.
    pub fn new(out: &'a mut [u8]) -> Result<Self, EncodeError> {
        let mut w = Self {
            out,
            end: 0,
            cobs: EncoderState::default(),
            crc: CRC32.digest(),
            payload_len: 0,
        };
        w.append(0)?;
        w.append(0)?;
        Ok(w)
    }

    fn append(&mut self, byte: u8) -> Result<(), EncodeError> {
        *self.out.get_mut(self.end).ok_or(EncodeError::TooLong)? = byte;
        self.end += 1;
        Ok(())
    }

    /// Sets the code byte at `idx` of the stuffed part.
    fn set_code(&mut self, idx: usize, code: u8) -> Result<(), EncodeError> {
        let slot = self.out.get_mut(STUFFED_AT + idx);
        *slot.ok_or(EncodeError::TooLong)? = code;
        Ok(())
    }

    /// Stuffs one content byte (payload or CRC); a closed block leaves a placeholder for the
    /// next code byte.
    fn stuff(&mut self, byte: u8) -> Result<(), EncodeError> {
        match self.cobs.push(byte) {
            PushResult::AddSingle(b) => self.append(b),
            PushResult::ModifyFromStartAndSkip((idx, code)) => {
                self.set_code(idx, code)?;
                self.append(0)
            }
            PushResult::ModifyFromStartAndPushAndSkip((idx, code, b)) => {
                self.set_code(idx, code)?;
                self.append(b)?;
                self.append(0)
            }
        }
    }

    /// Appends one payload byte.
    pub fn push(&mut self, byte: u8) -> Result<(), EncodeError> {
        if self.payload_len >= MAX_PAYLOAD_LEN {
            return Err(EncodeError::TooLong);
        }
        self.payload_len += 1;
        self.crc.update(core::slice::from_ref(&byte));
        self.stuff(byte)
    }

    /// Appends the CRC and the trailing delimiter; returns the frame's length in `out`.
    pub fn finish(mut self) -> Result<usize, EncodeError> {
        let crc = self.crc.clone().finalize();
        for b in crc.to_le_bytes() {
            self.stuff(b)?;
        }
        let (idx, code) = self.cobs.clone().finalize();
        self.set_code(idx, code)?;
        self.append(0)?;
        Ok(self.end)
    }
}

impl postcard::ser_flavors::Flavor for FrameWriter<'_> {
    type Output = usize;

    fn try_push(&mut self, data: u8) -> postcard::Result<()> {
        self.push(data)
            .map_err(|_| postcard::Error::SerializeBufferFull)
    }

    fn finalize(self) -> postcard::Result<usize> {
        self.finish()
            .map_err(|_| postcard::Error::SerializeBufferFull)
    }
}

/// Streaming frame decoder with a fixed buffer of `N` stuffed bytes.
///
/// Feed it every received byte; at each delimiter it yields the payload of a good frame or the
/// reason the frame was dropped. It never allocates, never panics, and after any error it is ready
/// for the next frame: over-long input is discarded up to the next delimiter.
pub struct FrameDecoder<const N: usize> {
    buf: [u8; N],
    len: usize,
    overflowed: bool,
}

impl<const N: usize> Default for FrameDecoder<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> FrameDecoder<N> {
    /// An empty decoder.
    pub const fn new() -> Self {
        Self {
            buf: [0; N],
            len: 0,
            overflowed: false,
        }
    }

    /// Drops any partial frame (e.g. after a link reset).
    pub fn clear(&mut self) {
        self.len = 0;
        self.overflowed = false;
    }

    /// True while the decoder holds part of a frame.
    pub fn in_frame(&self) -> bool {
        self.len > 0 || self.overflowed
    }

    /// Consumes one byte. Returns `Some` when the byte was a delimiter that ended a non-empty
    /// frame: its payload (CRC checked and stripped) or why it was dropped.
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], FrameError>> {
        if byte != 0 {
            if self.overflowed {
                return None;
            }
            match self.buf.get_mut(self.len) {
                Some(slot) => {
                    *slot = byte;
                    self.len += 1;
                }
                None => self.overflowed = true,
            }
            return None;
        }
        let len = core::mem::replace(&mut self.len, 0);
        if core::mem::replace(&mut self.overflowed, false) {
            return Some(Err(FrameError::TooLong));
        }
        if len == 0 {
            return None;
        }
        Some(self.finish_frame(len))
    }

    fn finish_frame(&mut self, len: usize) -> Result<&[u8], FrameError> {
        let stuffed = self.buf.get_mut(..len).ok_or(FrameError::TooLong)?;
        // The buffer holds no zero (delimiters end frames before they are stored), so the
        // crate's decoder sees the whole frame; it checks every block length against it.
        let n = cobs::decode_in_place(stuffed).map_err(|_| FrameError::BadFraming)?;
        let payload_len = n.checked_sub(CRC_LEN).ok_or(FrameError::BadFraming)?;
        let frame = self.buf.get(..n).ok_or(FrameError::BadFraming)?;
        let (payload, crc) = frame.split_at(payload_len);
        let mut want = [0u8; CRC_LEN];
        want.copy_from_slice(crc);
        if crc32(payload) != u32::from_le_bytes(want) {
            return Err(FrameError::BadCrc);
        }
        Ok(payload)
    }
}
