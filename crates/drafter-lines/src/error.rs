//! Error types: [`LinesError`] for arguments that do not fit together (caller bugs),
//! [`ArraysError`] for serialised hierarchies that fail validation (bad input).

/// Arguments that do not fit together.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LinesError {
    #[error("{parts} part ids for {faces} faces")]
    PartCount { parts: usize, faces: usize },
    #[error("{labels} input-face labels for {faces} faces")]
    InputFaceCount { labels: usize, faces: usize },
}

/// A serialised hierarchy that is inconsistent or does not bound its candidates.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ArraysError {
    #[error("array `{array}` has {found} entries, {expected} expected")]
    Length { array: &'static str, expected: usize, found: usize },
    #[error("array `{array}` has the invalid value {value} at {index}")]
    Value { array: &'static str, index: usize, value: f64 },
    #[error("node {node} breaks the breadth-first tree structure")]
    Tree { node: usize },
    #[error("the bound of node {node} does not hold candidate {candidate}")]
    NotConservative { node: usize, candidate: u32 },
}
