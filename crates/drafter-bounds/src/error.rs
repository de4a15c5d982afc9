//! Error types. Bad input (no points, NaN coordinates, out-of-range parameters) is reported to the
//! caller; internal inconsistencies never surface as errors (the hull degrades instead, see `hull`).

use std::fmt;

/// Why a box or hull could not be computed from the given points.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BoundsError {
    /// No points were given. (An empty part has no box; the caller decides what to write for it.)
    EmptyInput,
    /// Point `index` has a NaN or infinite coordinate.
    NonFinitePoint { index: usize },
    /// More points than 32-bit indices address.
    TooManyPoints { count: usize },
}

impl fmt::Display for BoundsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BoundsError::EmptyInput => write!(f, "no points to bound"),
            BoundsError::NonFinitePoint { index } => write!(f, "point {index} has a non-finite coordinate"),
            BoundsError::TooManyPoints { count } => write!(f, "{count} points exceed the 2^32 - 1 limit"),
        }
    }
}

impl std::error::Error for BoundsError {}

pub use drafter_core::ParamError;
