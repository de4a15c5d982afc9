//! Error types. An option outside its documented range is bad input ([`OptionError`], from
//! [`crate::TextureRequest::validate`]); [`crate::bake_textures`] never fails and clamps instead. Encoding and
//! writing PNG files can fail for other reasons ([`PngError`]).

use std::fmt;
use std::path::PathBuf;

/// An option outside its documented range.
#[derive(Clone, Debug, PartialEq)]
pub struct OptionError {
    /// Where the option lives, e.g. `"metal.exponent"` or `"cel_tables[2].steps"`.
    pub name: String,
    /// The rejected value, formatted.
    pub value: String,
    /// The accepted range, e.g. `"an integer in [2, 4]"`.
    pub expected: &'static str,
}

impl fmt::Display for OptionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {} is out of range; expected {}", self.name, self.value, self.expected)
    }
}

impl std::error::Error for OptionError {}

/// Why a texture could not be encoded or written as PNG.
#[derive(Debug)]
pub enum PngError {
    /// The texture has no such mip level.
    NoSuchLevel {
        /// The texture's name.
        texture: String,
        /// The requested level.
        level: usize,
        /// How many levels it has.
        levels: usize,
    },
    /// A level's byte count does not match `width × height × layers × channels` (a bug in the
    /// code that built the texture, not bad input).
    Malformed {
        /// The texture's name.
        texture: String,
        /// What is wrong.
        reason: String,
    },
    /// The `png` crate refused to encode.
    Encode(png::EncodingError),
    /// Writing the file failed.
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

impl fmt::Display for PngError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PngError::NoSuchLevel { texture, level, levels } => {
                write!(f, "texture {texture:?} has {levels} mip levels; level {level} does not exist")
            }
            PngError::Malformed { texture, reason } => write!(f, "texture {texture:?} is malformed: {reason}"),
            PngError::Encode(e) => write!(f, "PNG encoding failed: {e}"),
            PngError::Io { path, source } => write!(f, "writing {}: {source}", path.display()),
        }
    }
}

impl std::error::Error for PngError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            PngError::Encode(e) => Some(e),
            PngError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl From<png::EncodingError> for PngError {
    fn from(e: png::EncodingError) -> Self {
        PngError::Encode(e)
    }
}
