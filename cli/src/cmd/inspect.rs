//! `drafter inspect FILE [--json]`: format, parts, totals, world bounds and welded topology.

use crate::cmd::out;
use std::path::PathBuf;

use anyhow::Result;
use drafter_catalog::inspect::Report;
use drafter_core::{Weld, thousands};

use crate::exit::BadInput;

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum WeldMode {
    Snap,
    Exact,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The file to inspect (glTF, GLB, OBJ, STL, OFF, PLY).
    pub file: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// How positions are welded before topology is counted: `snap` (identical up to float noise,
    /// 1e-9 of the bounding diagonal; the default) or `exact` (bit-identical).
    #[arg(long, value_enum, default_value_t = WeldMode::Snap)]
    pub weld: WeldMode,
    /// Weld positions closer than this fraction of each mesh's bounding diagonal instead.
    #[arg(long, value_name = "FRACTION")]
    pub weld_tolerance: Option<f64>,
    /// Treat any input diagnostic as bad input (exit code 2).
    #[arg(long)]
    pub strict: bool,
    /// Refuse a model that lists more triangles than this (over all meshes, an instanced mesh
    /// once; a glTF's are counted before any is read).
    #[arg(long, value_name = "N", default_value_t = drafter_io::DEFAULT_MAX_TRIANGLES)]
    pub max_triangles: u64,
}

pub fn run(args: Args) -> Result<()> {
    let bytes =
        std::fs::read(&args.file).map_err(|source| drafter_io::ImportError::Io { path: args.file.clone(), source })?;
    let limits = drafter_io::Limits { max_triangles: args.max_triangles };
    let weld = match (args.weld_tolerance, args.weld) {
        (Some(fraction), _) if !(fraction.is_finite() && (0.0..=1.0).contains(&fraction)) => {
            return Err(BadInput(format!(
                "--weld-tolerance must be a fraction of the bounding diagonal in [0, 1], not {fraction}"
            ))
            .into());
        }
        (Some(fraction), _) => Weld::Relative(fraction),
        (None, WeldMode::Snap) => Weld::default(),
        (None, WeldMode::Exact) => Weld::Exact,
    };
    let report = drafter_catalog::inspect::inspect_bytes(&args.file, &bytes, &limits, weld)?;
    if args.json {
        out!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_text(&report)?;
    }
    if args.strict && !report.diagnostics.is_empty() {
        return Err(BadInput(format!(
            "{}: {} kinds of input problems (--strict); first: {}",
            report.file,
            report.diagnostics.len(),
            report.diagnostics[0]
        ))
        .into());
    }
    Ok(())
}

/// Rows of the part and mesh tables printed before "... N more".
const TABLE_ROWS: usize = 40;

fn print_text(r: &Report) -> anyhow::Result<()> {
    out!("{} ({})", r.file, r.format);
    out!(
        "  {} instances of {} meshes: {} triangles in the world ({} unique), {} vertices",
        r.instances,
        r.meshes,
        r.triangles,
        r.unique_triangles,
        r.vertices
    );
    let f = |v: [f64; 3]| format!("({:.6}, {:.6}, {:.6})", v[0], v[1], v[2]);
    out!("  world bounds {} .. {}  size {}", f(r.bounds.min), f(r.bounds.max), f(r.bounds.size));
    if let Some(c) = &r.compression {
        out!("  compressed with {c}");
    }
    let t = &r.topology;
    out!(
        "  topology (welded, per unique mesh, summed): {} welded vertices, {} edges, {} boundary, {} non-manifold, {} components, {} degenerate triangles",
        t.welded_vertices,
        t.edges,
        t.boundary_edges,
        t.nonmanifold_edges,
        t.components,
        t.degenerate_triangles
    );
    out!("\n  {:<40} {:>6} {:>10} {:>10}", "part", "mesh", "vertices", "triangles");
    for p in r.parts.iter().take(TABLE_ROWS) {
        let mirrored = if p.mirrored { " (mirrored)" } else { "" };
        out!("  {:<40} {:>6} {:>10} {:>10}{mirrored}", truncate(&p.name, 40), p.mesh.0, p.vertices, p.triangles);
    }
    if r.parts.len() > TABLE_ROWS {
        out!("  ... {} more parts (--json lists all)", r.parts.len() - TABLE_ROWS);
    }
    out!(
        "\n  {:<6} {:<28} {:>5} {:>9} {:>9} {:>8} {:>8} {:>6} {:>5} {:>5}",
        "mesh",
        "name",
        "uses",
        "triangles",
        "welded v",
        "edges",
        "boundary",
        "nonman",
        "comp",
        "degen"
    );
    for m in r.mesh_topology.iter().take(TABLE_ROWS) {
        let t = &m.topology;
        out!(
            "  {:<6} {:<28} {:>5} {:>9} {:>9} {:>8} {:>8} {:>6} {:>5} {:>5}",
            m.mesh.0,
            truncate(&m.name, 28),
            m.instances,
            m.triangles,
            t.welded_vertices,
            t.edges,
            t.boundary_edges,
            t.nonmanifold_edges,
            t.components,
            t.degenerate_triangles
        );
    }
    if r.mesh_topology.len() > TABLE_ROWS {
        out!("  ... {} more meshes (--json lists all)", r.mesh_topology.len() - TABLE_ROWS);
    }
    if let Some(b) = &r.baked {
        let input = &b.root.input;
        out!(
            "\n  baked by {} (extension {} v{}) from {} ({}, sha256 {}…): {} parts, {} labelled primitives",
            b.root.generator,
            drafter_format::EXTENSION,
            b.root.version,
            input.name,
            input.format,
            input.sha256.get(..12).unwrap_or(&input.sha256),
            b.root.part_count,
            b.labelled_primitives
        );
        out!(
            "  {:>4} {:<28} {:>9} {:>8} {:>12} {:>24} {:>10} {:>14} {:>6}",
            "id",
            "part",
            "triangles",
            "obb",
            "volume",
            "projector direction",
            "scale",
            "gradient q/f/p",
            "style"
        );
        for p in b.parts.iter().take(TABLE_ROWS) {
            let d = p.projector.direction;
            out!(
                "  {:>4} {:<28} {:>9} {:>8} {:>12.4e} {:>24} {:>10.4} {:>14} {:>6}",
                p.id,
                truncate(&p.name, 28),
                p.triangles,
                p.obb.method,
                p.obb.volume,
                format!("({:.3}, {:.3}, {:.3})", d[0], d[1], d[2]),
                p.projector.scale,
                format!("{}/{}/{}", p.gradient.q, p.gradient.f, p.gradient.p),
                p.style.map_or("-", drafter_format::PartStyle::name).to_owned()
                    + &p.flat.map(|g| format!(", flat {g}")).unwrap_or_default()
            );
        }
        if b.parts.len() > TABLE_ROWS {
            out!("  ... {} more parts (--json lists all)", b.parts.len() - TABLE_ROWS);
        }
        if let Some(t) = &b.root.textures {
            let mut kinds = Vec::new();
            kinds.extend(t.gradient.as_ref().map(|g| format!("gradient #{} ({} curves)", g.index, g.curves.len())));
            kinds.extend(t.cel.as_ref().map(|c| format!("cel #{}", c.index)));
            kinds.extend(t.cool_to_warm.iter().map(|c| format!("cool-to-warm #{}", c.index)));
            kinds.extend(t.hatching.as_ref().map(|h| format!("hatching ({} levels)", h.levels.len())));
            kinds.extend(t.metal.as_ref().map(|m| format!("metal ({} metal parts)", m.parts.len())));
            out!("  textures: {}", kinds.join(", "));
        }
        let s = &b.sections;
        let row = |name: &str, bytes: u64| {
            format!("{name} {} ({:.1}%)", thousands(bytes as usize), 100.0 * bytes as f64 / s.total.max(1) as f64)
        };
        out!(
            "  bytes: {} in all: {}",
            thousands(s.total as usize),
            [
                row("geometry", s.geometry),
                row("normals", s.normals),
                row("Khronos edges", s.khronos_edges),
                row("hierarchies", s.hierarchies),
                row("labels", s.labels),
                row("textures", s.textures),
                row("JSON", s.json),
                row("other", s.other),
            ]
            .join(", ")
        );
    }
    if !r.diagnostics.is_empty() {
        out!("\n  input problems recovered from:");
        for d in drafter_core::summarize(&r.diagnostics) {
            out!("    {d}");
        }
    }
    Ok(())
}

fn truncate(s: &str, n: usize) -> String {
    if s.chars().count() <= n { s.to_owned() } else { s.chars().take(n - 1).chain(['…']).collect() }
}
