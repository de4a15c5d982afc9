//! `drafter bench silhouettes FILE [--views N|icosa] [--perspective] [--json]`: brute force
//! against the silhouette hierarchies, per view, in the same process.
//!
//! A baked file is measured as a reader loads it: each mesh's stored candidates (the Khronos edges
//! encoded 1, with their decoded normals) and stored hierarchies, through the viewer's loader
//! (`drafter_scene::edges::load_silhouettes`); `build_ms` is then the load time. `--rebuild`, or
//! any other file, gives every unique mesh what the bake would store for it: its welded topology
//! (default weld), its edge classes at the default crease angle (part borders are not separated
//! here: the bench measures the mesh's own edges) and the [`SilhouetteIndex`] with default
//! options, which keeps a hierarchy only where its cost model predicts a gain. A view is given in
//! world space and taken into each instance's object space (`object_from_world` of the point or
//! direction; the signs of the predicate survive any invertible transform, mirrors included), so a
//! view costs the sum over instances. Brute force is [`BruteForce::query_serial`]; the hierarchy
//! side is [`SilhouetteIndex::query_serial`], which is brute force itself where no hierarchy is
//! stored. Both run on one thread.
//!
//! Views: `--views N` random uniform directions (orthographic) or random eyes outside the scene's
//! bounding box, 1.05 to 5 half-diagonals from its centre (`--perspective`); `--views icosa` the
//! 20 fixed directions of [`drafter_lines::measure::icosa_directions`] (orthographic only).
//! Timing is [`Warmth::Warm`] (the headline: an interactive loop's consecutive frames) and
//! [`Warmth::Cold`]; see [`drafter_lines::measure`].

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;

use anyhow::{Result, bail};
use drafter_core::rng::Rng;
use drafter_core::{Scene, Topology, Weld};
use drafter_lines::measure::{Warmth, icosa_directions, time_per_view};
use drafter_lines::{
    BruteForce, EdgeSet, HierarchyChoice, LineOptions, SilhouetteIndex, SilhouetteOptions, View, classify_edges,
};
use glam::{DMat4, DVec3, Vec3};
use rayon::prelude::*;
use serde::Serialize;

use crate::exit::BadInput;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The model (glTF, GLB, OBJ, STL, OFF, PLY; baked or not).
    pub file: PathBuf,
    /// Number of random views, or `icosa` for the 20 fixed orthographic directions.
    #[arg(long, default_value = "1000", value_parser = parse_views)]
    pub views: Views,
    /// Random eyes outside the bounding box instead of orthographic directions.
    #[arg(long)]
    pub perspective: bool,
    /// Seed of the random views.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Build the hierarchies from the geometry even when the file stores them.
    #[arg(long)]
    pub rebuild: bool,
}

#[derive(Debug, Clone, Copy)]
pub enum Views {
    Random(usize),
    Icosa,
}

fn parse_views(s: &str) -> Result<Views, String> {
    if s == "icosa" {
        return Ok(Views::Icosa);
    }
    match s.parse::<usize>() {
        Ok(n) if n > 0 => Ok(Views::Random(n)),
        _ => Err(format!("{s:?} is neither a positive number of views nor `icosa`")),
    }
}

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct Report {
    pub file: String,
    pub mode: &'static str,
    /// Welded edges over every instance.
    pub edges: usize,
    /// Silhouette candidates over every instance.
    pub candidates: usize,
    pub views: usize,
    /// Warm timing (the headline): mean over views of the fastest of three runs in a row.
    pub brute_ns_per_view: f64,
    pub hierarchy_ns_per_view: f64,
    pub speedup: f64,
    /// Brute force throughput on one thread, candidates per second.
    pub brute_candidates_per_s: f64,
    /// Cold timing: the two methods alternate.
    pub cold: ColdTiming,
    /// Views whose silhouette sets differ between brute force and the hierarchy.
    pub mismatches: usize,
    /// Silhouette edges per view (every instance), in view order.
    pub counts: Vec<usize>,
    /// `stored` (the file's candidates and hierarchies, as loaded) or `built` (from the geometry).
    pub hierarchies: &'static str,
    pub meshes: Vec<MeshRow>,
}

#[derive(Debug, Serialize)]
pub struct ColdTiming {
    pub brute_ns_per_view: f64,
    pub hierarchy_ns_per_view: f64,
    pub speedup: f64,
}

#[derive(Debug, Serialize)]
pub struct MeshRow {
    pub mesh: usize,
    pub instances: usize,
    pub edges: usize,
    pub candidates: usize,
    /// What answers this mode's queries, and why.
    pub choice: HierarchyChoice,
    /// Build time, or load time for stored hierarchies.
    pub build_ms: f64,
}

struct Prepared {
    mesh: usize,
    index: SilhouetteIndex,
    /// `object_from_world` of each instance.
    instances: Vec<DMat4>,
    edges: usize,
    build_ms: f64,
}

pub fn run(args: Args) -> Result<()> {
    let path = &args.file;
    let bytes = std::fs::read(path).map_err(|source| drafter_io::ImportError::Io { path: path.clone(), source })?;
    let scene = drafter_io::import_bytes(path, &bytes)?.scene;
    if args.perspective && matches!(args.views, Views::Icosa) {
        bail!(BadInput("--views icosa gives orthographic directions; leave out --perspective".into()));
    }
    let stored = if args.rebuild { None } else { stored(&scene, &bytes) };
    let hierarchies = if stored.is_some() { "stored" } else { "built" };
    let prepared = stored.unwrap_or_else(|| prepare(&scene));
    if prepared.iter().all(|p| p.index.is_empty()) {
        bail!(BadInput(format!("{}: no silhouette candidates (no closed, curved surface to outline)", path.display())));
    }
    let views = make_views(&scene, &args);
    let report = measure(&args, &prepared, &views, hierarchies);
    let text = if args.json { serde_json::to_string_pretty(&report)? + "\n" } else { table(&report) };
    // A reader that stops early (`| head`) is not an error.
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

/// `object_from_world` of every mesh's instances (those with an invertible transform).
fn mesh_instances(scene: &Scene) -> Vec<Vec<DMat4>> {
    let mut instances: Vec<Vec<DMat4>> = vec![Vec::new(); scene.meshes.len()];
    for inst in &scene.instances {
        let m = inst.world_from_object;
        if m.determinant().abs() > 0.0 && m.is_finite() {
            instances[inst.mesh.index()].push(m.inverse());
        }
    }
    instances
}

/// The stored candidates and hierarchies of a baked file, as the viewer loads them; `None` when
/// the file stores none (not baked, or baked without lines). A stored hierarchy that does not
/// validate is reported on stderr and answered by brute force, as in the viewer.
fn stored(scene: &Scene, bytes: &[u8]) -> Option<Vec<Prepared>> {
    let baked = drafter_format::read(bytes, &|_| None).ok()?;
    if baked.mesh_silhouettes.is_empty() {
        return None;
    }
    let instances = mesh_instances(scene);
    let mut notices = Vec::new();
    let mut prepared = Vec::new();
    for (m, s) in &baked.mesh_silhouettes {
        let m = *m as usize;
        let (Some(mesh), Some(inst)) = (scene.meshes.get(m), instances.get(m)) else { continue };
        if inst.is_empty() {
            continue;
        }
        let position = |t: usize, k: usize| -> Option<Vec3> {
            let tri = mesh.triangles.get(t)?;
            mesh.positions.get(tri[k % 3] as usize).copied()
        };
        let start = std::time::Instant::now();
        let Some(lines) = drafter_scene::edges::load_silhouettes(m, s, &position, &mut notices) else { continue };
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        prepared.push(Prepared {
            mesh: m,
            index: lines.index,
            instances: inst.clone(),
            edges: Topology::build(mesh, Weld::default()).edges.len(),
            build_ms,
        });
    }
    for n in notices {
        eprintln!("note: {n}");
    }
    (!prepared.is_empty()).then_some(prepared)
}

/// Topology, edge classes and index of every mesh an instance uses, in parallel.
fn prepare(scene: &Scene) -> Vec<Prepared> {
    let instances = mesh_instances(scene);
    scene
        .meshes
        .par_iter()
        .enumerate()
        .filter(|(m, mesh)| !instances[*m].is_empty() && !mesh.triangles.is_empty())
        .map(|(m, mesh)| {
            let start = std::time::Instant::now();
            let topology = Topology::build(mesh, Weld::default());
            let index = match classify_edges(&topology, None, &LineOptions::default()) {
                Ok(lines) => SilhouetteIndex::build(&lines, &SilhouetteOptions::default()),
                Err(_) => {
                    SilhouetteIndex::from_candidates(Vec::new(), Vec::new(), Vec::new(), &SilhouetteOptions::default())
                }
            };
            Prepared {
                mesh: m,
                index,
                instances: instances[m].clone(),
                edges: topology.edges.len(),
                build_ms: start.elapsed().as_secs_f64() * 1e3,
            }
        })
        .collect()
}

fn make_views(scene: &Scene, args: &Args) -> Vec<View> {
    let mut rng = Rng::new(args.seed);
    match args.views {
        Views::Icosa => icosa_directions().into_iter().map(|direction| View::Orthographic { direction }).collect(),
        Views::Random(n) if !args.perspective => {
            (0..n).map(|_| View::Orthographic { direction: rng.direction_f32() }).collect()
        }
        Views::Random(n) => {
            let (lo, hi) = world_bounds(scene);
            (0..n).map(|_| View::Perspective { eye: drafter_lines::measure::eye_outside(&mut rng, lo, hi) }).collect()
        }
    }
}

fn world_bounds(scene: &Scene) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for inst in &scene.instances {
        for p in &scene.meshes[inst.mesh.index()].positions {
            let w = inst.world_from_object.transform_point3(p.as_dvec3());
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    (lo.as_vec3(), hi.as_vec3())
}

/// A world-space view in an instance's object space.
fn local(view: View, object_from_world: &DMat4) -> View {
    match view {
        View::Orthographic { direction } => {
            View::Orthographic { direction: object_from_world.transform_vector3(direction.as_dvec3()).as_vec3() }
        }
        View::Perspective { eye } => {
            View::Perspective { eye: object_from_world.transform_point3(eye.as_dvec3()).as_vec3() }
        }
    }
}

fn measure(args: &Args, prepared: &[Prepared], views: &[View], hierarchies: &'static str) -> Report {
    // Every (mesh, instance) pair with its view per world view, computed once.
    let pairs: Vec<(usize, &DMat4)> =
        prepared.iter().enumerate().flat_map(|(k, p)| p.instances.iter().map(move |m| (k, m))).collect();
    let local_views: Vec<Vec<View>> =
        views.iter().map(|&v| pairs.iter().map(|&(_, m)| local(v, m)).collect()).collect();
    let brute = |k: usize| -> &BruteForce { prepared[k].index.brute_force() };

    let mut a = EdgeSet::default();
    let mut b = EdgeSet::default();
    let mut counts = Vec::with_capacity(views.len());
    let mut mismatches = 0;
    for lv in &local_views {
        let (mut count, mut differs) = (0, false);
        for (&(k, _), &v) in pairs.iter().zip(lv) {
            brute(k).query_serial(v, &mut a);
            prepared[k].index.query_serial(v, &mut b);
            count += a.count();
            differs |= a != b;
        }
        counts.push(count);
        mismatches += usize::from(differs);
    }

    let mut run = |method: usize, view: usize| {
        for (&(k, _), &v) in pairs.iter().zip(&local_views[view]) {
            if method == 0 {
                brute(k).query_serial(v, &mut a);
            } else {
                prepared[k].index.query_serial(v, &mut b);
            }
        }
    };
    let warm = time_per_view(views.len(), 2, Warmth::Warm, &mut run);
    let cold = time_per_view(views.len(), 2, Warmth::Cold, &mut run);

    let candidates: usize = prepared.iter().map(|p| p.index.len() * p.instances.len()).sum();
    let perspective = matches!(views.first(), Some(View::Perspective { .. }));
    Report {
        file: args.file.display().to_string(),
        mode: if perspective { "perspective" } else { "orthographic" },
        edges: prepared.iter().map(|p| p.edges * p.instances.len()).sum(),
        candidates,
        views: views.len(),
        brute_ns_per_view: warm[0],
        hierarchy_ns_per_view: warm[1],
        speedup: warm[0] / warm[1].max(1e-9),
        brute_candidates_per_s: candidates as f64 / warm[0].max(1e-9) * 1e9,
        cold: ColdTiming {
            brute_ns_per_view: cold[0],
            hierarchy_ns_per_view: cold[1],
            speedup: cold[0] / cold[1].max(1e-9),
        },
        mismatches,
        counts,
        hierarchies,
        meshes: prepared
            .iter()
            .map(|p| MeshRow {
                mesh: p.mesh,
                instances: p.instances.len(),
                edges: p.edges,
                candidates: p.index.len(),
                choice: if perspective { p.index.perspective_choice() } else { p.index.orthographic_choice() },
                build_ms: p.build_ms,
            })
            .collect(),
    }
}

fn table(r: &Report) -> String {
    let mut out = String::new();
    let mean = r.counts.iter().sum::<usize>() as f64 / r.counts.len().max(1) as f64;
    let _ = writeln!(out, "{} — {} views, {}, {} hierarchies", r.file, r.views, r.mode, r.hierarchies);
    let _ = writeln!(
        out,
        "  {} edges, {} candidates; mean {:.1} silhouettes per view; {} mismatching views",
        r.edges, r.candidates, mean, r.mismatches
    );
    let _ = writeln!(
        out,
        "  brute force   {:>12.0} ns/view  ({:.0} M candidates/s on one thread)",
        r.brute_ns_per_view,
        r.brute_candidates_per_s / 1e6
    );
    let _ =
        writeln!(out, "  hierarchy     {:>12.0} ns/view  speedup {:.2}× (warm)", r.hierarchy_ns_per_view, r.speedup);
    let _ = writeln!(
        out,
        "  cold          {:>12.0} / {:.0} ns/view  speedup {:.2}×",
        r.cold.brute_ns_per_view, r.cold.hierarchy_ns_per_view, r.cold.speedup
    );
    for m in &r.meshes {
        let _ = writeln!(
            out,
            "  mesh {:>4}: {:>3} instance(s), {:>9} candidates, {} in {:.0} ms, {}",
            m.mesh,
            m.instances,
            m.candidates,
            if r.hierarchies == "stored" { "loaded" } else { "built" },
            m.build_ms,
            describe(&m.choice)
        );
    }
    out
}

/// A hierarchy choice in words: what answers the views, its size, and the speedup the cost model
/// predicted where the index was built here (a file does not store it).
fn describe(choice: &HierarchyChoice) -> String {
    let predicted = |p: f32| if p > 0.0 { format!(", predicted speedup {p:.1}×") } else { String::new() };
    match *choice {
        HierarchyChoice::GaussMap { max_depth, nodes, predicted_speedup } => {
            format!("Gauss map of {nodes} nodes, built to level {max_depth}{}", predicted(predicted_speedup))
        }
        HierarchyChoice::ConeBvh { leaf_size, nodes, predicted_speedup } => {
            format!("cone BVH of {nodes} nodes, leaves of up to {leaf_size}{}", predicted(predicted_speedup))
        }
        HierarchyChoice::BruteForce(reason) => format!("brute force ({reason:?})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_parse() {
        assert!(matches!(parse_views("icosa"), Ok(Views::Icosa)));
        assert!(matches!(parse_views("25"), Ok(Views::Random(25))));
        assert!(parse_views("0").is_err());
        assert!(parse_views("many").is_err());
    }

    #[test]
    fn mirrored_instances_keep_silhouettes() {
        // A direction taken into a mirrored instance's space selects the same edges as the
        // mirrored geometry seen in the world: n·(M⁻¹ u) = (M⁻ᵀ n)·u.
        let m = DMat4::from_scale(DVec3::new(-1.0, 2.0, 0.5)).inverse();
        let n = DVec3::new(0.3, -0.4, 0.866);
        let u = DVec3::new(0.6, 0.0, 0.8);
        let View::Orthographic { direction } = local(View::Orthographic { direction: u.as_vec3() }, &m) else {
            unreachable!()
        };
        let world_normal = m.transpose().transform_vector3(n);
        assert!((n.dot(direction.as_dvec3()) - world_normal.dot(u)).abs() < 1e-6);
    }
}
