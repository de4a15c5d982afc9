//! The glTF 2.0 document as drafter reads it, typed: primitive modes and the one rule for how many
//! triangles a primitive lists.
//!
//! The triangle count is needed before any accessor is read — by the importer's triangle limit
//! (drafter-io), by a batch's memory estimate (drafter-catalog) and by the reader of baked files,
//! which numbers a mesh's triangles across its primitives — so the three count alike here.

/// A primitive's `mode` (glTF 2.0, "meshes": the topology of its vertices).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Points,
    Lines,
    LineLoop,
    LineStrip,
    Triangles,
    TriangleStrip,
    TriangleFan,
}

impl Mode {
    /// The mode of a `mode` code (0 POINTS … 6 TRIANGLE_FAN); `None` for any other number.
    pub fn from_code(code: u64) -> Option<Self> {
        Some(match code {
            0 => Self::Points,
            1 => Self::Lines,
            2 => Self::LineLoop,
            3 => Self::LineStrip,
            4 => Self::Triangles,
            5 => Self::TriangleStrip,
            6 => Self::TriangleFan,
            _ => return None,
        })
    }

    /// Triangles that `vertices` listed vertices make in this mode: `n / 3` for a list, `n − 2` for
    /// a strip or a fan (none below three vertices), none for points and lines.
    pub fn triangles(self, vertices: u64) -> u64 {
        match self {
            Self::Triangles => vertices / 3,
            Self::TriangleStrip | Self::TriangleFan => vertices.saturating_sub(2),
            Self::Points | Self::Lines | Self::LineLoop | Self::LineStrip => 0,
        }
    }
}

/// Triangles a primitive lists, from its `mode` code (absent: triangles, as the spec defaults it;
/// a code outside the spec: none), the count of its `indices` accessor where it has one (`Some`
/// even when that accessor cannot be found: then `Some(0)`, its count unknown) and otherwise the
/// count of its `POSITION` accessor.
pub fn triangle_count(mode: Option<u64>, indices: Option<u64>, positions: Option<u64>) -> u64 {
    let vertices = indices.or(positions).unwrap_or(0);
    match mode {
        None => Mode::Triangles.triangles(vertices),
        Some(code) => Mode::from_code(code).map_or(0, |mode| mode.triangles(vertices)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_mode_counts_its_triangles() {
        // Points, lines, line loop and line strip list no triangles, whatever their counts.
        for code in 0..=3 {
            assert_eq!(triangle_count(Some(code), Some(12), Some(99)), 0, "mode {code}");
        }
        assert_eq!(triangle_count(Some(4), Some(12), Some(99)), 4, "triangles: indices first");
        assert_eq!(triangle_count(Some(4), Some(13), None), 4, "a partial triangle is not one");
        assert_eq!(triangle_count(Some(5), Some(12), None), 10, "strip");
        assert_eq!(triangle_count(Some(6), None, Some(12)), 10, "fan of positions");
        assert_eq!(triangle_count(None, None, Some(9)), 3, "no mode: triangles");
        assert_eq!(triangle_count(None, Some(0), Some(9)), 0, "indices of unknown count: not the positions");
        assert_eq!(triangle_count(Some(7), Some(12), None), 0, "a mode outside the spec");
        assert_eq!(triangle_count(Some(u64::MAX), Some(12), None), 0);
        // Counts too small for one triangle.
        for code in [4, 5, 6] {
            for n in 0..3 {
                assert_eq!(triangle_count(Some(code), Some(n), None), 0, "mode {code}, {n} vertices");
            }
        }
        assert_eq!(triangle_count(Some(4), None, None), 0, "no indices, no positions");
        assert_eq!(triangle_count(Some(5), Some(u64::MAX), None), u64::MAX - 2);
        assert_eq!(Mode::from_code(6), Some(Mode::TriangleFan));
    }
}
