//! FNV-1a, 64 bits: the hash of a scene's text that render states record, and the
//! checksum of their pixel data. Not for security: for telling renders apart and
//! noticing damage.

/// The hash of nothing: where a hash starts.
pub const START: u64 = 0xcbf2_9ce4_8422_2325;

/// `h` continued over `bytes`.
pub fn fnv1a(bytes: &[u8], mut h: u64) -> u64 {
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
