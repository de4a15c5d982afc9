//! Recoverable problems found in input data.
//!
//! Importers and stages push every problem they recover from into a [`Diagnostics`] sink; it keeps one
//! entry per kind with a count and the first example, so a file with a million NaN vertices gives one
//! line, not a million.

use serde::Serialize;

/// What went wrong, as a closed set so tools can match on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiagnosticKind {
    /// A vertex position with a NaN or infinite coordinate; faces using it were dropped.
    NonFinitePosition,
    /// A face dropped because it used a non-finite position.
    DroppedFace,
    /// A face whose vertex index is outside the vertex array; the face was dropped.
    IndexOutOfRange,
    /// A primitive of a mode we do not turn into triangles (points, lines); skipped.
    SkippedPrimitive,
    /// A material library (OBJ .mtl) that could not be read; default materials used.
    MissingMaterialLibrary,
    /// A normal array that was unusable (wrong count, non-finite); ignored.
    InvalidNormals,
    /// A texture-coordinate array that was unusable; ignored.
    InvalidTexcoords,
    /// A trailing index count not divisible by three; the incomplete triangle was dropped.
    IncompleteTriangle,
    /// A polygon with fewer than three vertices; dropped.
    DegeneratePolygon,
    /// A node whose transform is not invertible or not finite.
    BadTransform,
    /// A node reached twice while walking the hierarchy (a cycle or a shared child); the repeat was skipped.
    NodeCycle,
    /// Data of the input that the importer ignored (animations, skins, morph targets, ...).
    Ignored,
    /// Anything else worth telling the user.
    Other,
}

/// One aggregated problem: its kind, how often it happened and the first place it happened.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    pub kind: DiagnosticKind,
    pub count: usize,
    /// A human-readable description of the first occurrence, naming the place (mesh, line, accessor).
    pub first_example: String,
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?} x{}: {}", self.kind, self.count, self.first_example)
    }
}

/// An order-preserving sink that aggregates diagnostics by kind.
#[derive(Clone, Debug, Default)]
pub struct Diagnostics {
    entries: Vec<Diagnostic>,
}

impl Diagnostics {
    pub fn new() -> Self {
        Self::default()
    }

    /// Records `count` occurrences of `kind`; `example` is kept only for the first one.
    pub fn push(&mut self, kind: DiagnosticKind, count: usize, example: impl FnOnce() -> String) {
        if count == 0 {
            return;
        }
        if let Some(entry) = self.entries.iter_mut().find(|d| d.kind == kind) {
            entry.count += count;
        } else {
            self.entries.push(Diagnostic { kind, count, first_example: example() });
        }
    }

    /// Count recorded for `kind` (0 if none).
    pub fn count(&self, kind: DiagnosticKind) -> usize {
        self.entries.iter().find(|d| d.kind == kind).map_or(0, |d| d.count)
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    pub fn into_vec(self) -> Vec<Diagnostic> {
        self.entries
    }

    pub fn as_slice(&self) -> &[Diagnostic] {
        &self.entries
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aggregates_by_kind_and_keeps_first_example() {
        let mut d = Diagnostics::new();
        d.push(DiagnosticKind::DroppedFace, 2, || "face 7".into());
        d.push(DiagnosticKind::IndexOutOfRange, 1, || "face 9".into());
        d.push(DiagnosticKind::DroppedFace, 3, || "face 8".into());
        d.push(DiagnosticKind::Other, 0, || "never".into());
        let v = d.into_vec();
        assert_eq!(v.len(), 2);
        assert_eq!(v[0].count, 5);
        assert_eq!(v[0].first_example, "face 7");
    }
}
