//! OFF reader (being written).

use crate::error::ParseError;
use crate::raw::RawMesh;

pub(crate) fn read(_bytes: &[u8]) -> Result<RawMesh, ParseError> {
    Err(ParseError::in_file("OFF reader not written yet"))
}
