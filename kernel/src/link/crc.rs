//! CRC-32 (IEEE 802.3, the one of zlib/PNG/Ethernet) over each frame's payload.
//!
//! Written out here rather than pulled from a crate because it is twenty lines, must be `const`
//! and allocation-free on the firmware, and the firmware and host must agree on it bit for bit.
//! Parameters: reflected polynomial 0xEDB88320, initial value and final XOR 0xFFFF_FFFF.

/// One byte-wise lookup table, built at compile time (1 KiB of flash on the firmware).
const TABLE: [u32; 256] = build_table();

const fn build_table() -> [u32; 256] {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        table[i] = c;
        i += 1;
    }
    table
}

/// Incremental CRC-32, so frames can be checksummed while they are serialized or received,
/// without a second buffer.
#[derive(Clone, Copy, Debug)]
pub struct Crc32 {
    state: u32,
}

impl Default for Crc32 {
    fn default() -> Self {
        Self::new()
    }
}

impl Crc32 {
    /// A fresh checksum (of the empty message).
    pub const fn new() -> Self {
        Self { state: 0xFFFF_FFFF }
    }

    /// Folds one byte in.
    #[inline]
    pub fn push(&mut self, byte: u8) {
        // `as u8` keeps the index below 256, so this lookup cannot fail.
        let idx = (self.state as u8 ^ byte) as usize;
        self.state = TABLE[idx] ^ (self.state >> 8);
    }

    /// Folds a slice in.
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.push(b);
        }
    }

    /// The checksum of everything pushed so far.
    pub const fn finish(&self) -> u32 {
        self.state ^ 0xFFFF_FFFF
    }
}

/// CRC-32 of a whole slice.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut c = Crc32::new();
    c.update(bytes);
    c.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_value_of_the_standard() {
        // The "check" value of CRC-32/ISO-HDLC in every CRC catalogue.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
    }

    #[test]
    fn incremental_equals_whole() {
        let mut c = Crc32::new();
        c.update(b"1234");
        c.update(b"56789");
        assert_eq!(c.finish(), 0xCBF4_3926);
    }
}
