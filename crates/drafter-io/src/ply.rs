//! PLY reader (being written).

use crate::error::ParseError;
use crate::raw::RawMesh;

pub(crate) fn read(_bytes: &[u8]) -> Result<RawMesh, ParseError> {
    Err(ParseError::in_file("PLY reader not written yet"))
}
