//! How a part's oriented bounding box was oriented: the methods drafter-bounds implements, named
//! here because the name is also a field of the baked file (`obb.method`, drafter-format) and of the
//! bake's configuration; one enum for all of them, so no reader parses the name again.

use serde::{Deserialize, Serialize};

use crate::ParamError;

/// How to orient a box.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum ObbMethod {
    /// World axis-aligned box.
    Aabb,
    /// Covariance of all points.
    Pca,
    /// Area-weighted covariance of the convex-hull surface (Gottschalk 2000).
    Hull,
    /// Largest hull faces with exact rectangles, plus short refinement: fast and tight.
    #[default]
    Default,
    /// Minimum volume: all hull faces, antipodal edge pairs and edge triples, plus refinement.
    Optimal,
}

impl ObbMethod {
    /// Every method, cheapest first.
    pub const ALL: [ObbMethod; 5] =
        [ObbMethod::Aabb, ObbMethod::Pca, ObbMethod::Hull, ObbMethod::Default, ObbMethod::Optimal];

    /// The name used in configuration files, reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ObbMethod::Aabb => "aabb",
            ObbMethod::Pca => "pca",
            ObbMethod::Hull => "hull",
            ObbMethod::Default => "default",
            ObbMethod::Optimal => "optimal",
        }
    }
}

impl std::str::FromStr for ObbMethod {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ObbMethod::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| ParamError {
            name: "obb method",
            value: s.to_owned(),
            expected: "one of aabb, pca, hull, default, optimal",
        })
    }
}

impl std::fmt::Display for ObbMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
