//! What `drafter inspect` reports of a file (and `drafter.inspect` in Python): format, instances,
//! totals, world bounds, welded topology per unique mesh, input diagnostics, and for a baked file
//! the extension's contents and where its bytes go.

use std::path::Path;

use drafter_core::{Diagnostic, MeshId, Scene, Topology, Weld};
use rayon::prelude::*;
use serde::Serialize;

use crate::job::Error;

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
    pub compression: Option<drafter_format::meshopt::CompressionStats>,
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
fn read_baked(path: &Path, bytes: &[u8]) -> Result<Option<BakedSummary>, Error> {
    let failed = |e: drafter_format::FormatError| Error::Input(format!("{}: {e}", path.display()));
    let Some(baked) = drafter_format::read_if_baked(path, bytes).map_err(failed)? else { return Ok(None) };
    Ok(Some(BakedSummary {
        parts: baked.parts().into_iter().cloned().collect(),
        labelled_primitives: baked.primitive_labels.len(),
        sections: drafter_format::byte_sections(bytes, &drafter_format::external_buffers(path)).map_err(failed)?,
        root: baked.root,
    }))
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

/// Imports `bytes` (read from `path`) within `limits` and reports on them, welded with `weld`; a
/// compressed GLB is described and then read decoded.
pub fn inspect_bytes(path: &Path, bytes: &[u8], limits: &drafter_io::Limits, weld: Weld) -> Result<Report, Error> {
    let imported = drafter_io::import_bytes_within(path, bytes, limits)?;
    let mut report = build_report(&path.display().to_string(), &imported.scene, imported.diagnostics, weld);
    // A compressed GLB: what is encoded, then the baked data from the decoded bytes.
    let json = drafter_format::glb::split(bytes).ok().map(|c| c.json);
    report.compression = json.and_then(drafter_format::meshopt::describe).map(|mut stats| {
        stats.file_bytes_after = bytes.len() as u64;
        stats
    });
    let plain = match report.compression {
        Some(_) => drafter_format::meshopt::decompress_glb(bytes)
            .map_err(|e| Error::Input(format!("{}: {e}", path.display())))?,
        None => None,
    };
    if let (Some(stats), Some(plain)) = (report.compression.as_mut(), &plain) {
        stats.file_bytes_before = plain.len() as u64;
    }
    report.baked = read_baked(path, plain.as_deref().unwrap_or(bytes))?;
    Ok(report)
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
