//! `drafter inspect FILE [--json]`: format, parts, totals, world bounds and welded topology.

use crate::cmd::out;
use std::path::PathBuf;

use anyhow::Result;
use drafter_core::{Diagnostic, MeshId, Scene, Topology, Weld, thousands};
use rayon::prelude::*;
use serde::Serialize;

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

/// The report, also the `--json` schema. Topology is computed per unique mesh after welding and
/// summed; boundary and non-manifold edges follow the incidence convention of
/// [`Topology::incidence_edge_counts`], edges and components the welded topology.
#[derive(Debug, Serialize)]
pub struct Report {
    pub file: String,
    pub format: &'static str,
    /// Triangles drawn in the world (every instance counted).
    pub triangles: usize,
    /// Vertices over all instances.
    pub vertices: usize,
    /// Unique meshes used by the scene.
    pub meshes: usize,
    /// Mesh instances (parts as the file gives them).
    pub instances: usize,
    pub unique_triangles: usize,
    pub bounds: Bounds,
    pub topology: TopologyStats,
    pub parts: Vec<PartRow>,
    pub mesh_topology: Vec<MeshRow>,
    pub diagnostics: Vec<Diagnostic>,
    /// The `DRAFTER_illustration` data of a baked file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baked: Option<BakedSummary>,
    /// `EXT_meshopt_compression`: views encoded and their bytes (`file_bytes_before`: the file
    /// decoded); absent for a plain file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compression: Option<drafter_core::meshopt::CompressionStats>,
}

/// What a baked file carries: the root extension and every part, by id.
#[derive(Debug, Serialize)]
pub struct BakedSummary {
    pub root: drafter_format::RootExtension,
    pub parts: Vec<drafter_format::PartRecord>,
    /// Primitives with per-triangle part labels.
    pub labelled_primitives: usize,
    /// The file's bytes by what they hold.
    pub sections: drafter_format::ByteSections,
}

/// Reads the extension if the file is a baked glTF; `None` for anything else.
fn read_baked(path: &std::path::Path, bytes: &[u8]) -> Result<Option<BakedSummary>> {
    let (json, _) = match drafter_format::split_container(bytes) {
        Ok(parts) => parts,
        Err(_) => return Ok(None),
    };
    if !json.windows(drafter_format::EXTENSION.len()).any(|w| w == drafter_format::EXTENSION.as_bytes()) {
        return Ok(None);
    }
    // drafter-format resolves the buffer URI, confined to the file's folder as the importer does.
    let external = drafter_format::external_buffers(path);
    match drafter_format::read(bytes, &external) {
        Ok(baked) => Ok(Some(BakedSummary {
            parts: baked.parts().into_iter().cloned().collect(),
            labelled_primitives: baked.primitive_labels.len(),
            sections: drafter_format::byte_sections(bytes, &external)
                .map_err(|e| BadInput(format!("{}: {e}", path.display())))?,
            root: baked.root,
        })),
        Err(drafter_format::FormatError::NotBaked(_)) => Ok(None),
        Err(e) => Err(BadInput(format!("{}: {e}", path.display())).into()),
    }
}

#[derive(Debug, Serialize)]
pub struct Bounds {
    pub min: [f64; 3],
    pub max: [f64; 3],
    pub size: [f64; 3],
}

#[derive(Debug, Default, Serialize, Clone, Copy)]
pub struct TopologyStats {
    pub welded_vertices: usize,
    pub edges: usize,
    pub boundary_edges: usize,
    pub nonmanifold_edges: usize,
    pub components: usize,
    pub degenerate_triangles: usize,
}

impl std::ops::AddAssign for TopologyStats {
    fn add_assign(&mut self, o: Self) {
        self.welded_vertices += o.welded_vertices;
        self.edges += o.edges;
        self.boundary_edges += o.boundary_edges;
        self.nonmanifold_edges += o.nonmanifold_edges;
        self.components += o.components;
        self.degenerate_triangles += o.degenerate_triangles;
    }
}

#[derive(Debug, Serialize)]
pub struct PartRow {
    pub name: String,
    pub mesh: MeshId,
    pub vertices: usize,
    pub triangles: usize,
    pub mirrored: bool,
}

#[derive(Debug, Serialize)]
pub struct MeshRow {
    pub mesh: MeshId,
    pub name: String,
    pub vertices: usize,
    pub triangles: usize,
    pub instances: usize,
    #[serde(flatten)]
    pub topology: TopologyStats,
}

pub fn run(args: Args) -> Result<()> {
    let bytes =
        std::fs::read(&args.file).map_err(|source| drafter_io::ImportError::Io { path: args.file.clone(), source })?;
    let limits = drafter_io::Limits { max_triangles: args.max_triangles };
    let imported = drafter_io::import_bytes_within(&args.file, &bytes, &limits)?;
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
    let mut report = build_report(&args.file.display().to_string(), &imported.scene, imported.diagnostics, weld);
    // A compressed GLB: what is encoded, then the baked data from the decoded bytes.
    let json = drafter_core::glb::split(&bytes).ok().map(|c| c.json);
    report.compression = json.and_then(drafter_core::meshopt::describe).map(|mut stats| {
        stats.file_bytes_after = bytes.len() as u64;
        stats
    });
    let plain = match report.compression {
        Some(_) => drafter_core::meshopt::decompress_glb(&bytes)
            .map_err(|e| BadInput(format!("{}: {e}", args.file.display())))?,
        None => None,
    };
    if let (Some(stats), Some(plain)) = (report.compression.as_mut(), &plain) {
        stats.file_bytes_before = plain.len() as u64;
    }
    report.baked = read_baked(&args.file, plain.as_deref().unwrap_or(&bytes))?;
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

pub fn build_report(file: &str, scene: &Scene, diagnostics: Vec<Diagnostic>, weld: Weld) -> Report {
    let mut uses = vec![0usize; scene.meshes.len()];
    for inst in &scene.instances {
        uses[inst.mesh.index()] += 1;
    }
    let used: Vec<usize> = (0..scene.meshes.len()).filter(|&m| uses[m] > 0).collect();
    let mesh_topology: Vec<MeshRow> = used
        .par_iter()
        .map(|&m| {
            let mesh = &scene.meshes[m];
            let topo = Topology::build(mesh, weld);
            // Incidence convention (collapsed faces count), as trimesh and MeshLab report.
            let (boundary_edges, nonmanifold_edges) = topo.incidence_edge_counts();
            MeshRow {
                mesh: MeshId::from(m),
                name: mesh.name.clone(),
                vertices: mesh.vertex_count(),
                triangles: mesh.triangle_count(),
                instances: uses[m],
                topology: TopologyStats {
                    welded_vertices: topo.referenced_vertex_count(),
                    edges: topo.edge_count(),
                    boundary_edges,
                    nonmanifold_edges,
                    components: topo.component_count,
                    degenerate_triangles: topo.degenerate_triangle_count(),
                },
            }
        })
        .collect();
    let mut topology = TopologyStats::default();
    for row in &mesh_topology {
        topology += row.topology;
    }
    let b = scene.world_bounds();
    let (min, max) = if b.is_empty() { ([0.0; 3], [0.0; 3]) } else { (b.min.to_array(), b.max.to_array()) };
    Report {
        file: file.to_owned(),
        format: scene.format.name(),
        triangles: scene.instanced_triangle_count(),
        vertices: scene.instanced_vertex_count(),
        meshes: used.len(),
        instances: scene.instances.len(),
        unique_triangles: used.iter().map(|&m| scene.meshes[m].triangle_count()).sum(),
        bounds: Bounds { min, max, size: [max[0] - min[0], max[1] - min[1], max[2] - min[2]] },
        topology,
        parts: scene
            .instances
            .iter()
            .map(|i| PartRow {
                name: i.name.clone(),
                mesh: i.mesh,
                vertices: scene.mesh(i.mesh).vertex_count(),
                triangles: scene.mesh(i.mesh).triangle_count(),
                mirrored: i.flips_winding(),
            })
            .collect(),
        mesh_topology,
        diagnostics,
        baked: None,
        compression: None,
    }
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
