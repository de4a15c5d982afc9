use std::path::Path;

use drafter_core::{Diagnostics, Scene};

use crate::error::{ImportError, ParseError};

pub(crate) fn import(path: &Path, _bytes: &[u8], _diagnostics: &mut Diagnostics) -> Result<Scene, ImportError> {
    Err(ParseError::in_file("glTF importer not written yet").in_path(path))
}
