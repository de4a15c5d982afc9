//! STL reader (being written).

use crate::error::ParseError;
use crate::raw::RawMesh;

pub(crate) fn read(_bytes: &[u8]) -> Result<RawMesh, ParseError> {
    Err(ParseError::in_file("STL reader not written yet"))
}

/// True when `bytes` is a binary STL: an 80-byte header, a u32 triangle count and exactly 50 bytes
/// per triangle. This holds even when the header starts with "solid".
pub(crate) fn is_binary(bytes: &[u8]) -> bool {
    if bytes.len() < 84 {
        return false;
    }
    let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    84 + 50 * count == bytes.len() as u64
}
