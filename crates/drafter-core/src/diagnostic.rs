//! Recoverable problems found in input data.
//!
//! Importers and stages push every problem they recover from into a [`Diagnostics`] sink; it keeps one
//! entry per kind with a count and the first example, so a file with a million NaN vertices gives one
//! line, not a million.

use serde::{Deserialize, Serialize};

/// What went wrong, as a closed set so tools can match on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
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
    /// A glTF file without a default scene; every parentless node was taken as a root.
    NoScene,
    /// Triangles of zero area; they get no normal of their own.
    DegenerateTriangle,
    /// Vertices touched only by degenerate triangles; they got the normal +Z.
    FallbackNormal,
    /// Edges bordering a degenerate triangle; never drawn.
    DegenerateEdge,
    /// Manifold edges joining faces of opposite winding; their dihedral angle uses the normals as given.
    InconsistentWinding,
    /// Non-manifold edges that could not be paired into solids; parts are cut there.
    UnpairedNonManifoldEdge,
    /// Non-manifold edges whose faces could be paired into solids only in part; the faces left
    /// over are free edges of their parts.
    PartlyPairedNonManifoldEdge,
    /// Open pieces glued by segmentation to the pieces their free edges lie on (cracks).
    GluedCrack,
    /// Small components merged into a touching neighbour by segmentation.
    MergedSliver,
    /// A mesh whose line stage failed; it has no edges in the output.
    LinesSkipped,
    /// A primitive whose edge visibility could not be encoded.
    EdgesNotWritten,
    /// Something the writer changed or left out of the output (e.g. an unusable input extension).
    Output,
    /// Anything else worth telling the user.
    Other,
}

impl DiagnosticKind {
    /// What the kind is called in a summary line (`degenerate triangles: 10,832 in 25 meshes`).
    pub fn label(self) -> &'static str {
        match self {
            Self::NonFinitePosition => "non-finite positions",
            Self::DroppedFace => "dropped faces",
            Self::IndexOutOfRange => "indices out of range",
            Self::SkippedPrimitive => "skipped primitives (points or lines)",
            Self::MissingMaterialLibrary => "missing material libraries",
            Self::InvalidNormals => "unusable normals",
            Self::InvalidTexcoords => "unusable texture coordinates",
            Self::IncompleteTriangle => "incomplete triangles",
            Self::DegeneratePolygon => "degenerate polygons",
            Self::BadTransform => "bad node transforms",
            Self::NodeCycle => "node cycles",
            Self::Ignored => "ignored input data",
            Self::NoScene => "no default scene",
            Self::DegenerateTriangle => "degenerate triangles",
            Self::FallbackNormal => "vertices with a fallback normal",
            Self::DegenerateEdge => "edges along degenerate triangles",
            Self::InconsistentWinding => "edges between faces of inconsistent winding",
            Self::UnpairedNonManifoldEdge => "unpaired non-manifold edges",
            Self::PartlyPairedNonManifoldEdge => "partly paired non-manifold edges",
            Self::GluedCrack => "open pieces glued across cracks",
            Self::MergedSliver => "small components merged",
            Self::LinesSkipped => "meshes without lines",
            Self::EdgesNotWritten => "primitives without edges",
            Self::Output => "output notes",
            Self::Other => "other notes",
        }
    }
}

/// One aggregated problem: its kind, how often it happened and the first place it happened.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
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

/// All diagnostics of one kind, folded into one line for a terminal.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DiagnosticSummary {
    pub kind: DiagnosticKind,
    /// Occurrences summed over the entries.
    pub total: usize,
    /// How many entries (one per mesh or stage that found some) were folded.
    pub entries: usize,
    /// The first entry's example.
    pub first_example: String,
}

impl std::fmt::Display for DiagnosticSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.kind.label(), thousands(self.total))?;
        if self.entries > 1 {
            write!(f, " in {} places; first: {}", self.entries, self.first_example)
        } else {
            write!(f, "; {}", self.first_example)
        }
    }
}

/// Folds `diagnostics` into one summary per kind, in order of each kind's first entry.
pub fn summarize(diagnostics: &[Diagnostic]) -> Vec<DiagnosticSummary> {
    let mut out: Vec<DiagnosticSummary> = Vec::new();
    for d in diagnostics {
        match out.iter_mut().find(|s| s.kind == d.kind) {
            Some(s) => {
                s.total += d.count;
                s.entries += 1;
            }
            None => out.push(DiagnosticSummary {
                kind: d.kind,
                total: d.count,
                entries: 1,
                first_example: d.first_example.clone(),
            }),
        }
    }
    out
}

/// `10832` → `10,832`.
pub fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
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

    #[test]
    fn summary_folds_entries_of_a_kind() {
        let entry = |kind, count, example: &str| Diagnostic { kind, count, first_example: example.into() };
        let list = [
            entry(DiagnosticKind::DegenerateTriangle, 48, "mesh 'body_24': first: triangle 11"),
            entry(DiagnosticKind::FallbackNormal, 2, "mesh 'body_24': 2 vertices"),
            entry(DiagnosticKind::DegenerateTriangle, 10_784, "mesh 'body_3': first: triangle 0"),
        ];
        let s = summarize(&list);
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].total, s[0].entries), (10_832, 2));
        assert_eq!(
            s[0].to_string(),
            "degenerate triangles: 10,832 in 2 places; first: mesh 'body_24': first: triangle 11"
        );
        assert_eq!(s[1].to_string(), "vertices with a fallback normal: 2; mesh 'body_24': 2 vertices");
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(1_234_567), "1,234,567");
    }
}
