//! The measurement behind the uneven-tessellation decision (crate docs, "Uneven tessellation").
//!
//! For each CAD model: how uneven its tessellation is ([`TessellationStats`]), what refining it to
//! edges ≤ 4× the median edge would cost (§4.1's remedy), and how far each weighting on the *unrefined*
//! mesh lands from the result of refine-then-filter (area weighting on the refined mesh, the paper's
//! recipe): the area-weighted mean angle between a face's enhanced normal and the mean enhanced normal
//! of its children. Smaller means the weighting stands in for refinement without adding triangles.
//!
//! ```text
//! cargo run --release -p drafter-normals --example tessellation_survey [-- MODEL...]
//! ```
//! Without arguments it surveys the CAD models of ../shared/models.

use std::path::{Path, PathBuf};

use drafter_core::{Mesh, Topology, Weld};
use drafter_normals::*;
use glam::Vec3;

const DEFAULT_MODELS: &[&str] = &[
    "obj/common-3d-test-models/fandisk.obj",
    "obj/common-3d-test-models/rocker-arm.obj",
    "obj/cad-denoising-set/block.obj",
    "obj/cad-denoising-set/joint.obj",
    "obj/cad-denoising-set/partLp.obj",
    "obj/cgal/anchor_dense.off",
    "obj/cgal/couplingdown.off",
    "obj/cgal/dragknob.off",
    "obj/cgal/pinion.off",
    "obj/cgal/rotor.off",
    "obj/cgal/spool.off",
    "obj/v-hacd/casting.off",
    "obj/occt/TR12J_OCC.stl",
    "obj/occt/sh1.stl",
    "obj/occt/video_part.stl",
    "obj/trimesh/featuretype.STL",
    "obj/trimesh/ADIS16480.STL",
    "obj/trimesh/idler_riser.STL",
    "obj/trimesh/plate_holes.STL",
    "obj/trimesh/angle_block.STL",
    "gltf/2CylinderEngine/2CylinderEngine.gltf",
    "gltf/ReciprocatingSaw/ReciprocatingSaw.gltf",
    "gltf/RodAssembly/rod.glb",
    "gltf/CycloidalDrive/cycloidal.glb",
];

#[derive(Default)]
struct Totals {
    faces: f64,
    stats: [f64; 6],
    refine_added: f64,
    deviation: [f64; 3],
    deviation_area: f64,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    let models: Vec<PathBuf> = if args.is_empty() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
        DEFAULT_MODELS.iter().map(|m| root.join(m)).collect()
    } else {
        args
    };
    let weightings = [Weighting::Uniform, Weighting::Area, Weighting::ScaleDependent];
    println!(
        "{:<24} {:>8} {:>7} {:>7} {:>7} {:>8} {:>8} {:>6} | {:>7} | deviation from refine-then-filter (deg): uniform area scale-dep",
        "model", "faces", "maxE/md", "asp50", "asp99", "nbrA99", "A99/A1", "long%", "refine+"
    );
    let mut all = Totals::default();
    for path in &models {
        let imported = drafter_io::import(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut totals = Totals::default();
        for mesh in &imported.scene.meshes {
            if mesh.triangles.len() < 16 {
                continue;
            }
            survey_mesh(mesh, &weightings, &mut totals);
        }
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        print_row(&name, &totals);
        all.faces += totals.faces;
        all.refine_added += totals.refine_added;
        all.deviation_area += totals.deviation_area;
        for i in 0..6 {
            all.stats[i] += totals.stats[i];
        }
        for i in 0..3 {
            all.deviation[i] += totals.deviation[i];
        }
    }
    print_row("ALL (face-weighted)", &all);
    Ok(())
}

fn print_row(name: &str, t: &Totals) {
    let s = |i: usize| t.stats[i] / t.faces.max(1.0);
    let d = |i: usize| t.deviation[i] / t.deviation_area.max(f64::MIN_POSITIVE);
    println!(
        "{:<24} {:>8} {:>7.1} {:>7.1} {:>7.1} {:>8.1} {:>8.0} {:>5.0}% | {:>6.0}% | {:>7.2} {:>5.2} {:>5.2}",
        name,
        t.faces,
        s(0),
        s(1),
        s(2),
        s(3),
        s(4),
        100.0 * s(5),
        100.0 * t.refine_added / t.faces.max(1.0),
        d(0),
        d(1),
        d(2),
    );
}

fn survey_mesh(mesh: &Mesh, weightings: &[Weighting; 3], totals: &mut Totals) {
    let topology = Topology::build(mesh, Weld::Exact);
    let stats = TessellationStats::measure(&topology);
    let faces = mesh.triangles.len() as f64;
    totals.faces += faces;
    for (i, value) in [
        stats.max_edge_over_median,
        stats.aspect_p50,
        stats.aspect_p99.min(1e4),
        stats.neighbor_area_ratio_p99.min(1e6),
        stats.area_p99_over_p1.min(1e6),
        stats.long_face_area_share,
    ]
    .into_iter()
    .enumerate()
    {
        totals.stats[i] += value as f64 * faces;
    }

    // Refine to edges ≤ 4× median, with a generous budget, as the reference.
    let refined = refine(mesh, &RefineOptions { max_added_ratio: 50.0, max_passes: 16, ..Default::default() });
    totals.refine_added += refined.report.triangles_added as f64;
    let refined_topology = Topology::build(&refined.mesh, Weld::Exact);
    let options = EnhanceOptions::default();
    let reference = enhance_faces(&refined_topology, &EnhanceOptions { weighting: Weighting::Area, ..options });
    // Mean enhanced normal of each input face's children, area-weighted.
    let mut child_mean = vec![Vec3::ZERO; mesh.triangles.len()];
    for (child, &parent) in refined.parent_face.iter().enumerate() {
        child_mean[parent as usize] += reference.enhanced[child] * reference.geometry.areas[child];
    }
    for (i, &weighting) in weightings.iter().enumerate() {
        let ours = enhance_faces(&topology, &EnhanceOptions { weighting, ..options });
        let mut weighted = 0.0f64;
        let mut area = 0.0f64;
        for (f, children) in child_mean.iter().enumerate() {
            let a = ours.geometry.areas[f] as f64;
            let (Some(mine), Some(theirs)) = (ours.enhanced[f].try_normalize(), children.try_normalize()) else {
                continue;
            };
            weighted += a * mine.angle_between(theirs).to_degrees() as f64;
            area += a;
        }
        // Scale the per-mesh mean by its face count so that the file totals are face-weighted.
        if area > 0.0 {
            totals.deviation[i] += weighted / area * faces;
        }
        if i == 0 {
            totals.deviation_area += faces;
        }
    }
}
