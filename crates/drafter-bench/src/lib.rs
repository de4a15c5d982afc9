//! Speed against accuracy for every bake stage: parameter sweeps of each stage on a
//! user's model ([`sweep`]), their charts ([`chart`], [`figures`]), and the synthetic scenes of
//! `drafter bench parts` ([`spheres`]). The generated inputs where methods are known to fail, which
//! the stability suite (`tests/stability.rs`) and the scaling benchmark (`examples/scaling.rs`)
//! run, and the contact assemblies of the segmentation sweep are drafter-testkit's.
//!
//! The CLI's `drafter bench FILE --out DIR` runs [`sweep::run`], writes [`figures::all`] as SVG and
//! the [`sweep::SweepReport`] as JSON. Nothing here prints; progress goes through
//! [`sweep::Progress`].

pub mod chart;
pub mod figures;
pub mod quantization;
pub mod spheres;
pub mod sweep;

use std::path::Path;

/// Writes `bench.json` and every chart of `report` as SVG (and PNG when `png`) into `dir`, which
/// must exist. Returns the file names written, in order.
pub fn write_outputs(report: &sweep::SweepReport, dir: &Path, png: bool) -> Result<Vec<String>, OutputError> {
    let mut written = Vec::new();
    let mut put = |name: String, bytes: &[u8]| -> Result<(), OutputError> {
        let path = dir.join(&name);
        std::fs::write(&path, bytes).map_err(|e| OutputError::Write(format!("{}: {e}", path.display())))?;
        written.push(name);
        Ok(())
    };
    let json = serde_json::to_string_pretty(report).map_err(|e| OutputError::Chart(e.to_string()))?;
    put("bench.json".into(), json.as_bytes())?;
    for (stem, figure) in figures::all(report) {
        let svg = chart::to_svg(&figure).map_err(|e| OutputError::Chart(format!("{stem}: {e}")))?;
        put(format!("{stem}.svg"), svg.as_bytes())?;
        if png {
            let bytes = chart::to_png(&figure).map_err(|e| OutputError::Chart(format!("{stem}: {e}")))?;
            put(format!("{stem}.png"), &bytes)?;
        }
    }
    Ok(written)
}

/// Why the outputs could not be written.
#[derive(Debug)]
pub enum OutputError {
    /// A file could not be written (the path and the reason).
    Write(String),
    /// A chart could not be drawn (a bug).
    Chart(String),
}

impl std::fmt::Display for OutputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OutputError::Write(m) => write!(f, "cannot write {m}"),
            OutputError::Chart(m) => write!(f, "cannot draw chart {m}"),
        }
    }
}

impl std::error::Error for OutputError {}
