//! Results of the normals stage checked against geometry we know the answer for.

mod common;

use common::*;
use drafter_core::rng::Rng;
use drafter_core::{Mesh, Topology, Weld};
use drafter_normals::*;
use glam::Vec3;

fn run(mesh: &Mesh, options: &NormalsOptions) -> MeshNormals {
    let topology = Topology::build(mesh, Weld::Exact);
    compute_normals(mesh, &topology, options).0
}

fn assert_finite(normals: &[Vec3]) {
    for (i, n) in normals.iter().enumerate() {
        assert!(n.is_finite(), "normal {i} is {n}");
    }
}

/// Every triangle's three vertex normals equal its face normal (within f32 rounding).
fn assert_flat(mesh: &Mesh, result: &MeshNormals) {
    for (f, tri) in result.layout.triangles.iter().enumerate() {
        let face = result.faces.geometry.normals[f];
        for &v in tri {
            let n = result.normals[v as usize];
            assert!(n.abs_diff_eq(face, 1e-6), "{}: face {f} normal {face} but vertex {v} has {n}", mesh.name);
        }
    }
}

#[test]
fn unwelded_cube_keeps_six_flat_faces() {
    let cube = cube(false);
    let result = run(&cube, &NormalsOptions::default());
    assert_eq!(result.layout.vertex_count(), 24);
    assert_eq!(result.report.welded_vertices, 8);
    assert_eq!(result.report.split_vertices, 16);
    assert_flat(&cube, &result);
    // The six face normals are the six axis directions.
    let mut distinct: Vec<[i32; 3]> =
        result.faces.geometry.normals.iter().map(|n| n.round().as_ivec3().to_array()).collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(distinct.len(), 6);
}

#[test]
fn welded_cube_keeps_six_flat_faces() {
    let cube = cube(true);
    assert_eq!(cube.positions.len(), 8);
    let result = run(&cube, &NormalsOptions::default());
    assert_eq!(result.layout.vertex_count(), 24);
    assert_flat(&cube, &result);
    // Each output vertex copies one of the 8 input vertices at the same position.
    for (v, &source) in result.layout.source_vertex.iter().enumerate() {
        let welded = result.layout.welded_vertex[v] as usize;
        assert_eq!(cube.positions[source as usize], cube.positions[welded]);
    }
}

#[test]
fn fine_sphere_vertex_normals_are_radial() {
    for seam in [false, true] {
        let sphere = uv_sphere(192, 96, seam);
        let result = run(&sphere, &NormalsOptions::default());
        // Smooth everywhere: one output vertex per welded vertex, the seam is welded and smoothed.
        assert_eq!(result.report.split_vertices, 0, "seam {seam}");
        let mut worst = 0.0f32;
        for (v, &source) in result.layout.source_vertex.iter().enumerate() {
            let radial = sphere.positions[source as usize].normalize();
            worst = worst.max(angle_deg(result.normals[v], radial));
        }
        assert!(worst < 1.0, "seam {seam}: worst vertex normal is {worst}° from radial");
    }
}

#[test]
fn input_seams_can_be_kept() {
    let sphere = uv_sphere(32, 16, true);
    let options =
        NormalsOptions { crease: CreaseOptions { keep_input_seams: true, ..Default::default() }, ..Default::default() };
    let result = run(&sphere, &options);
    // Seam columns stay separate: one output vertex per referenced input vertex.
    assert_eq!(result.layout.vertex_count(), sphere.positions.len());
    for (v, &source) in result.layout.source_vertex.iter().enumerate() {
        for &corner in result.layout.corners_of(v) {
            assert_eq!(sphere.triangles[corner as usize / 3][corner as usize % 3], source);
        }
    }
}

#[test]
fn layout_is_a_faithful_remap() {
    for mesh in [cube(false), uv_sphere(16, 8, true), roof(8, 60.0)] {
        let result = run(&mesh, &NormalsOptions::default());
        let layout = &result.layout;
        assert_eq!(layout.triangles.len(), mesh.triangles.len());
        for (tri, input) in layout.triangles.iter().zip(&mesh.triangles) {
            for k in 0..3 {
                let source = layout.source_vertex[tri[k] as usize] as usize;
                assert_eq!(mesh.positions[source], mesh.positions[input[k] as usize], "{}", mesh.name);
            }
        }
        // Every corner belongs to exactly one output vertex.
        let mut seen = vec![false; mesh.triangles.len() * 3];
        for v in 0..layout.vertex_count() {
            for &c in layout.corners_of(v) {
                assert!(!seen[c as usize]);
                seen[c as usize] = true;
                assert_eq!(layout.triangles[c as usize / 3][c as usize % 3], v as u32);
            }
        }
        assert!(seen.iter().all(|&s| s));
    }
}

#[test]
fn crease_splits_only_along_the_crease() {
    let n = 8;
    let sharp = run(&roof(n, 60.0), &NormalsOptions::default());
    // The crease column of n + 1 vertices is doubled; nothing else is split.
    assert_eq!(sharp.report.split_vertices, (n + 1) as usize);
    let smooth = run(&roof(n, 20.0), &NormalsOptions::default());
    assert_eq!(smooth.report.split_vertices, 0);
}

#[test]
fn enhancing_a_flat_plane_changes_nothing() {
    let plane = plane(24);
    for neighborhood in [Neighborhood::Edge, Neighborhood::Vertex] {
        for weighting in [Weighting::Uniform, Weighting::Area, Weighting::ScaleDependent] {
            let options = NormalsOptions {
                enhance: EnhanceOptions { neighborhood, weighting, ..Default::default() },
                ..Default::default()
            };
            let result = run(&plane, &options);
            for n in result.faces.enhanced.iter().chain(&result.enhanced_normals).chain(&result.normals) {
                assert!(n.abs_diff_eq(Vec3::Z, 1e-6), "{neighborhood:?} {weighting:?}: {n}");
            }
            assert_eq!(result.report.split_vertices, 0);
        }
    }
}

#[test]
fn enhanced_normals_are_unit_length() {
    let sphere = bumpy_sphere(64, 32, 0.2);
    for neighborhood in [Neighborhood::Edge, Neighborhood::Vertex] {
        let options = NormalsOptions {
            enhance: EnhanceOptions { neighborhood, strength: 0.7, iterations: 30, ..Default::default() },
            ..Default::default()
        };
        let result = run(&sphere, &options);
        for n in result.faces.enhanced.iter().chain(&result.faces.low_pass).chain(&result.enhanced_normals) {
            assert!((n.length() - 1.0).abs() < 1e-5, "{n} has length {}", n.length());
        }
    }
}

#[test]
fn a_crease_gets_more_contrast() {
    let n = 16;
    let roof = roof(n, 40.0);
    let topology = Topology::build(&roof, Weld::Exact);
    for neighborhood in [Neighborhood::Edge, Neighborhood::Vertex] {
        let faces = enhance_faces(&topology, &EnhanceOptions { neighborhood, ..Default::default() });
        let mut checked = 0;
        for e in 0..topology.edges.len() {
            let &[f, g] = topology.faces_of_edge(e) else { continue };
            let (f, g) = (f as usize, g as usize);
            let before = angle_deg(faces.geometry.normals[f], faces.geometry.normals[g]);
            if before < 1.0 {
                continue;
            }
            let after = angle_deg(faces.enhanced[f], faces.enhanced[g]);
            assert!(after > before + 1.0, "{neighborhood:?}: across the crease {before}° became {after}°");
            checked += 1;
        }
        assert_eq!(checked, n as usize);
    }
}

#[test]
fn degenerate_faces_get_no_vote_and_no_nan() {
    // A strip of two triangles plus a collinear sliver on their shared edge and a collapsed face.
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.3), Vec3::new(0.5, 0.5, 0.0)];
    let clean = vec![[0, 1, 2], [1, 3, 2]];
    let mut dirty = clean.clone();
    dirty.push([1, 4, 2]); // zero area: 4 lies on edge 1–2
    dirty.push([0, 0, 3]); // collapsed
    let clean_mesh = mesh("clean", positions.clone(), clean);
    let dirty_mesh = mesh("dirty", positions, dirty);
    let options = NormalsOptions::default();
    let (a, _) = compute_normals(&clean_mesh, &Topology::build(&clean_mesh, Weld::Exact), &options);
    let (b, diagnostics) = compute_normals(&dirty_mesh, &Topology::build(&dirty_mesh, Weld::Exact), &options);
    assert_eq!(b.report.degenerate_faces, 2);
    assert!(!diagnostics.is_empty());
    for faces in [&b.faces.low_pass, &b.faces.enhanced, &b.normals, &b.enhanced_normals] {
        assert_finite(faces);
    }
    // The degenerate faces changed nothing for the others.
    assert_eq!(a.faces.enhanced[..2], b.faces.enhanced[..2]);
    assert_eq!(a.faces.low_pass[..2], b.faces.low_pass[..2]);
    // The sliver takes its neighbours' average; the collapsed face has no neighbour with a normal.
    assert!((b.faces.enhanced[2].length() - 1.0).abs() < 1e-6);
    assert_eq!(b.faces.enhanced[3], Vec3::ZERO);
    for n in &b.normals {
        assert!((n.length() - 1.0).abs() < 1e-6);
    }
}

#[test]
fn isolated_triangle_keeps_its_normal() {
    let tri = mesh("tri", vec![Vec3::ZERO, Vec3::X, Vec3::new(0.3, 0.2, 1.0)], vec![[0, 1, 2]]);
    for weighting in [Weighting::Uniform, Weighting::Area, Weighting::ScaleDependent] {
        let options =
            NormalsOptions { enhance: EnhanceOptions { weighting, ..Default::default() }, ..Default::default() };
        let result = run(&tri, &options);
        let n = result.faces.geometry.normals[0];
        assert!(result.faces.low_pass[0].abs_diff_eq(n, 1e-6));
        assert!(result.faces.enhanced[0].abs_diff_eq(n, 1e-6));
        for v in 0..3 {
            assert!(result.normals[v].abs_diff_eq(n, 1e-6));
            assert!(result.enhanced_normals[v].abs_diff_eq(n, 1e-6));
        }
    }
}

#[test]
fn nonmanifold_and_boundary_edges_are_handled() {
    // Three coplanar-ish fins on edge 0–1, each a boundary elsewhere.
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.5, -1.0, 0.1), Vec3::new(0.5, 0.0, 1.0)];
    let fins = mesh("fins", positions, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
    let result = run(&fins, &NormalsOptions::default());
    assert_eq!(result.report.nonmanifold_edges, 1);
    // A non-manifold edge is sharp: each fin keeps its own vertices.
    assert_eq!(result.layout.vertex_count(), 9);
    assert_flat(&fins, &result);
    // The non-manifold edge bounds the filter and the other edges are boundaries: no fin has a
    // neighbour, so none is enhanced (averaging the three would depend on rounding).
    for (f, (e, n)) in result.faces.enhanced.iter().zip(&result.faces.geometry.normals).enumerate() {
        assert!(e.abs_diff_eq(*n, 1e-6), "fin {f}: {e} vs {n}");
    }
    for n in result.faces.enhanced.iter().chain(&result.enhanced_normals) {
        assert!((n.length() - 1.0).abs() < 1e-6);
    }
}

#[test]
fn area_weighting_matches_a_hand_computed_step() {
    // Two triangles of areas 0.5 and 1.0 sharing an edge; one iteration of the area average.
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 2.0, 1.0)];
    let m = mesh("pair", positions, vec![[0, 1, 2], [1, 3, 2]]);
    let topology = Topology::build(&m, Weld::Exact);
    let geometry = FaceGeometry::compute(&topology);
    let adjacency = FaceAdjacency::build(&topology, &geometry, Neighborhood::Edge, Weighting::Area);
    let low = low_pass(&adjacency, &geometry.normals, 1);
    let (n0, n1) = (geometry.normals[0], geometry.normals[1]);
    let (a0, a1) = (geometry.areas[0], geometry.areas[1]);
    let expected = (n0 * a0 + n1 * a1).normalize();
    assert!(low[0].abs_diff_eq(expected, 1e-6) && low[1].abs_diff_eq(expected, 1e-6));
    let k = 0.5;
    let enhanced = enhance(&geometry.normals, &low, k);
    assert!(enhanced[0].abs_diff_eq((n0 + k * (n0 - expected)).normalize(), 1e-6));
}

#[test]
fn scale_dependent_equals_area_on_a_uniform_grid() {
    // An axis-aligned grid with all cells cut the same way: every neighbour pair is equally far apart.
    let mut grid = plane(6);
    for (i, t) in grid.triangles.iter_mut().enumerate() {
        let (cell, second) = (i / 2, i % 2 == 1);
        let (x, y) = ((cell % 6) as u32, (cell / 6) as u32);
        let id = |x: u32, y: u32| y * 7 + x;
        *t = if second {
            [id(x, y), id(x + 1, y + 1), id(x, y + 1)]
        } else {
            [id(x, y), id(x + 1, y), id(x + 1, y + 1)]
        };
    }
    let topology = Topology::build(&grid, Weld::Exact);
    let geometry = FaceGeometry::compute(&topology);
    let area = FaceAdjacency::build(&topology, &geometry, Neighborhood::Edge, Weighting::Area);
    let scaled = FaceAdjacency::build(&topology, &geometry, Neighborhood::Edge, Weighting::ScaleDependent);
    assert_eq!(area.entry_count(), scaled.entry_count());
    for f in 0..area.face_count() {
        assert_eq!(area.row(f), scaled.row(f));
    }
}

#[test]
fn scale_dependent_weights_damp_far_neighbours() {
    // One large triangle next to a small one: the small face is pulled less by the large one than with
    // plain area weights, so the large face no longer dominates it.
    let positions = vec![Vec3::ZERO, Vec3::new(0.0, 0.1, 0.0), Vec3::new(-0.1, 0.05, 0.02), Vec3::new(10.0, 0.05, 0.0)];
    let m = mesh("pair", positions, vec![[0, 1, 2], [1, 0, 3]]);
    let topology = Topology::build(&m, Weld::Exact);
    let geometry = FaceGeometry::compute(&topology);
    let area = FaceAdjacency::build(&topology, &geometry, Neighborhood::Edge, Weighting::Area);
    let scaled = FaceAdjacency::build(&topology, &geometry, Neighborhood::Edge, Weighting::ScaleDependent);
    // Only one distance, so the median equals it and nothing is damped...
    assert_eq!(area.row(0), scaled.row(0));
    // ...but with a row of small faces the large neighbour's pull drops.
    let sphere = uv_sphere(12, 6, false);
    let mut positions = sphere.positions.clone();
    let mut triangles = sphere.triangles.clone();
    let far = positions.len() as u32;
    positions.push(Vec3::new(30.0, 0.0, 1.0));
    // Face 0 becomes a large face reaching far out; `near` is the small face across its edge a–b.
    let [a, b, _] = triangles[0];
    triangles[0] = [a, b, far];
    let near = triangles.iter().position(|t| t.contains(&a) && t.contains(&b) && *t != [a, b, far]).expect("a–b");
    let m = mesh("sphere+sliver", positions, triangles);
    let topology = Topology::build(&m, Weld::Exact);
    let geometry = FaceGeometry::compute(&topology);
    let area = FaceAdjacency::build(&topology, &geometry, Neighborhood::Edge, Weighting::Area);
    let scaled = FaceAdjacency::build(&topology, &geometry, Neighborhood::Edge, Weighting::ScaleDependent);
    let big = 0u32;
    let (row_area, row_scaled) = (area.row(near), scaled.row(near));
    assert_eq!(row_area.len(), row_scaled.len());
    let k = row_area.iter().position(|&(g, _)| g == big).expect("`near` borders the large face");
    assert_eq!(row_scaled[k].0, big);
    assert!(row_scaled[k].1 < 0.01 * row_area[k].1, "{:?} vs {:?}", row_scaled[k], row_area[k]);
}

#[test]
fn refinement_splits_only_long_edges_within_budget() {
    // A fine strip next to one huge triangle.
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..=20u32 {
        positions.push(Vec3::new(i as f32 * 0.05, 0.0, 0.0));
        positions.push(Vec3::new(i as f32 * 0.05, 0.05, 0.0));
    }
    for i in 0..20u32 {
        let (a, b, c, d) = (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
        triangles.push([a, b, c]);
        triangles.push([a, c, d]);
    }
    // The CAD way: a fan of slivers from one far vertex to every vertex of the strip's edge.
    let apex = positions.len() as u32;
    positions.push(Vec3::new(0.5, -1.0, 0.0));
    for i in 0..20u32 {
        triangles.push([2 * i + 2, 2 * i, apex]);
    }
    let m = mesh("strip+fan", positions, triangles);
    let area_before: f64 = m.triangles.iter().map(|t| triangle_area(t.map(|v| m.positions[v as usize]))).sum();

    let refined = refine(&m, &RefineOptions { max_added_ratio: 10.0, ..Default::default() });
    let report = refined.report;
    assert!(report.triangles_added > 0 && report.long_edges_left == 0, "{report:?}");
    assert_eq!(refined.mesh.triangles.len(), m.triangles.len() + report.triangles_added);
    let area_after: f64 =
        refined.mesh.triangles.iter().map(|t| triangle_area(t.map(|v| refined.mesh.positions[v as usize]))).sum();
    assert!((area_after - area_before).abs() < 1e-5 * area_before);
    // Conforming: a T-junction would add boundary edges inside the mesh, so the boundary length is kept.
    let topology = Topology::build(&refined.mesh, Weld::Exact);
    assert_eq!(topology.nonmanifold_edge_count(), 0);
    let before = boundary_length(&Topology::build(&m, Weld::Exact));
    assert!((boundary_length(&topology) - before).abs() < 1e-5 * before);
    // Parents: the strip's triangles are untouched, children cover the big one.
    assert!(refined.parent_face.windows(2).all(|w| w[0] <= w[1]));
    assert_eq!(&refined.parent_face[..40], &(0..40).collect::<Vec<u32>>()[..]);

    // A tight budget stops early and says so.
    let capped = refine(&m, &RefineOptions { max_added_ratio: 0.05, ..Default::default() });
    assert!(capped.report.budget_exhausted);
    assert!(capped.report.triangles_added <= (0.05 * m.triangles.len() as f64) as usize);
}

fn boundary_length(topology: &Topology) -> f64 {
    (0..topology.edges.len())
        .filter(|&e| topology.edge_valence(e) == 1)
        .map(|e| {
            let [a, b] = topology.edges[e];
            topology.welded_positions[a as usize].as_dvec3().distance(topology.welded_positions[b as usize].as_dvec3())
        })
        .sum()
}

fn triangle_area(p: [Vec3; 3]) -> f64 {
    let [a, b, c] = p.map(|v| v.as_dvec3());
    0.5 * (b - a).cross(c - a).length()
}

#[test]
fn tessellation_stats_see_unevenness() {
    let uniform = TessellationStats::measure(&Topology::build(&plane(16), Weld::Exact));
    assert!(uniform.neighbor_area_ratio_p99 < 1.01 && uniform.long_face_area_share == 0.0, "{uniform:?}");
    let mut uneven = plane(16);
    let apex = uneven.positions.len() as u32;
    uneven.positions.push(Vec3::new(0.5, -5.0, 0.0));
    for x in 0..16u32 {
        uneven.triangles.push([x + 1, x, apex]);
    }
    let stats = TessellationStats::measure(&Topology::build(&uneven, Weld::Exact));
    assert!(stats.max_edge_over_median > 50.0 && stats.long_face_area_share > 0.5, "{stats:?}");
}

#[test]
fn output_is_identical_at_any_thread_count() {
    let sphere = bumpy_sphere(160, 80, 0.3);
    let run_with = |threads: usize, options: NormalsOptions| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
        pool.install(|| run(&sphere, &options))
    };
    for neighborhood in [Neighborhood::Edge, Neighborhood::Vertex] {
        let options = NormalsOptions {
            enhance: EnhanceOptions { neighborhood, ..Default::default() },
            crease: CreaseOptions { crease_angle_deg: 10.0, ..Default::default() },
        };
        let one = run_with(1, options);
        assert!(one.report.split_vertices > 0, "the test should exercise splitting");
        for threads in [2, 3] {
            let many = run_with(threads, options);
            let bits = |v: &[Vec3]| v.iter().flat_map(|n| n.to_array().map(f32::to_bits)).collect::<Vec<u32>>();
            assert_eq!(bits(&one.faces.low_pass), bits(&many.faces.low_pass));
            assert_eq!(bits(&one.faces.enhanced), bits(&many.faces.enhanced));
            assert_eq!(bits(&one.normals), bits(&many.normals));
            assert_eq!(bits(&one.enhanced_normals), bits(&many.enhanced_normals));
            assert_eq!(one.layout, many.layout);
        }
    }
}

/// The real CAD part the paper's kind of figure shows: fandisk has sharp creases and smooth patches.
#[test]
fn fandisk_splits_along_its_creases() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/models/obj/common-3d-test-models/fandisk.obj");
    let imported = drafter_io::import(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mesh = &imported.scene.meshes[0];
    let topology = Topology::build(mesh, Weld::Exact);
    let (result, _) = compute_normals(mesh, &topology, &NormalsOptions::default());
    assert_eq!(result.report.degenerate_faces, 0);
    assert!(
        result.report.split_vertices > 100 && result.report.split_vertices < mesh.positions.len() / 4,
        "{:?}",
        result.report
    );
    for n in result.normals.iter().chain(&result.enhanced_normals) {
        assert!((n.length() - 1.0).abs() < 1e-5);
    }
}

#[test]
fn refinement_survives_t_junctions() {
    // A strip whose bottom edge is also the long edge of one big triangle: the big triangle's midpoints
    // land on strip vertices (a T-junction, common in STL exports).
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..=16u32 {
        positions.push(Vec3::new(i as f32 / 16.0, 0.0, 0.0));
        positions.push(Vec3::new(i as f32 / 16.0, 1.0 / 16.0, 0.0));
    }
    for i in 0..16u32 {
        let (a, b, c, d) = (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
        triangles.push([a, b, c]);
        triangles.push([a, c, d]);
    }
    let apex = positions.len() as u32;
    positions.push(Vec3::new(0.5, -1.0, 0.0));
    triangles.push([32, 0, apex]);
    let m = mesh("t-junction", positions, triangles);
    let refined = refine(&m, &RefineOptions { max_added_ratio: 20.0, ..Default::default() });
    assert_eq!(refined.report.long_edges_left, 0, "{:?}", refined.report);
    // Every child faces the way its parent does.
    let parent_normals = FaceGeometry::compute(&Topology::build(&m, Weld::Exact)).normals;
    let child_topology = Topology::build(&refined.mesh, Weld::Exact);
    let child_normals = FaceGeometry::compute(&child_topology).normals;
    assert_eq!(child_topology.nonmanifold_edge_count(), 0);
    for (child, &parent) in refined.parent_face.iter().enumerate() {
        assert!(angle_deg(child_normals[child], parent_normals[parent as usize]) < 0.01);
    }
}

#[test]
fn a_far_nonmanifold_fin_changes_nothing_else() {
    // A non-manifold fin far away (its edge bounds the filter); the sphere's faces must not notice.
    let sphere = bumpy_sphere(24, 12, 0.3);
    let mut positions = sphere.positions.clone();
    let base = positions.len() as u32;
    positions.extend([
        Vec3::splat(10.0),
        Vec3::new(11.0, 10.0, 10.0),
        Vec3::new(10.0, 11.0, 10.0),
        Vec3::new(10.0, 10.0, 11.0),
        Vec3::new(10.5, 9.0, 10.0),
    ]);
    let mut triangles = sphere.triangles.clone();
    triangles.extend([[base, base + 1, base + 2], [base + 1, base, base + 3], [base, base + 1, base + 4]]);
    let with_fin = mesh("sphere+fin", positions, triangles);
    // Uniform weights: the fin's areas do not change the sphere's weights (area weights are normalised
    // by the mean area).
    let options = EnhanceOptions { weighting: Weighting::Uniform, ..Default::default() };
    let a = enhance_faces(&Topology::build(&sphere, Weld::Exact), &options);
    let b = enhance_faces(&Topology::build(&with_fin, Weld::Exact), &options);
    assert_eq!(a.enhanced[..], b.enhanced[..sphere.triangles.len()]);
}

/// The iteration against a plain f64 re-implementation from the public rows, for every layout:
/// packed rows with and without dampings, and CSR rows.
#[test]
fn low_pass_matches_a_reference_jacobi() {
    let sphere = bumpy_sphere(24, 12, 0.3);
    let mut positions = sphere.positions.clone();
    let mut triangles = sphere.triangles.clone();
    let far = positions.len() as u32;
    positions.push(Vec3::new(6.0, 0.0, 0.5));
    // Face 0 becomes a long face reaching far out (a manifold edge still joins it to the sphere).
    let [a, b, _] = triangles[0];
    triangles[0] = [a, b, far];
    let uneven = mesh("sphere+far", positions, triangles);
    let topology = Topology::build(&uneven, Weld::Exact);
    let geometry = FaceGeometry::compute(&topology);
    for (neighborhood, weighting) in [
        (Neighborhood::Edge, Weighting::ScaleDependent),
        (Neighborhood::Edge, Weighting::Uniform),
        (Neighborhood::Vertex, Weighting::Area),
        (Neighborhood::Vertex, Weighting::ScaleDependent),
    ] {
        let adjacency = FaceAdjacency::build(&topology, &geometry, neighborhood, weighting);
        if weighting == Weighting::ScaleDependent {
            let damped = (0..adjacency.face_count())
                .any(|f| adjacency.row(f).iter().any(|&(g, w)| w < 0.999 * adjacency.self_weight(g as usize)));
            assert!(damped, "{neighborhood:?}: the far face should be damped");
        }
        let iterations = 7;
        let ours = low_pass(&adjacency, &geometry.normals, iterations);
        let mut reference: Vec<glam::DVec3> = geometry.normals.iter().map(|n| n.as_dvec3()).collect();
        for _ in 0..iterations {
            reference = (0..reference.len())
                .map(|f| {
                    let mut sum = reference[f] * adjacency.self_weight(f) as f64;
                    for (g, w) in adjacency.row(f) {
                        sum += reference[g as usize] * w as f64;
                    }
                    sum.normalize_or_zero()
                })
                .collect();
        }
        for (f, (o, r)) in ours.iter().zip(&reference).enumerate() {
            assert!(o.as_dvec3().abs_diff_eq(*r, 1e-5), "{neighborhood:?} {weighting:?} face {f}: {o} vs {r}");
        }
    }
}

/// A random height field with holes, fins on random edges (non-manifold), a separate fan touching
/// one grid vertex (a bowtie vertex), split and shuffled input vertices and shuffled faces; no
/// degenerate face.
fn random_relief(seed: u64) -> Mesh {
    let mut rng = Rng::new(seed);
    let side = 3 + rng.below(10) as u32;
    let height = rng.unit_f32() * 1.5;
    let mut positions: Vec<Vec3> = (0..side * side)
        .map(|i| Vec3::new((i % side) as f32, (i / side) as f32, (rng.unit_f32() - 0.5) * height))
        .collect();
    let mut triangles = Vec::new();
    for y in 0..side - 1 {
        for x in 0..side - 1 {
            let v = y * side + x;
            for t in [[v, v + 1, v + side + 1], [v, v + side + 1, v + side]] {
                if rng.below(10) != 0 {
                    triangles.push(t);
                }
            }
        }
    }
    // Fins: a third face on a random grid edge.
    for _ in 0..rng.below(4) {
        let Some(&[a, b, _]) = triangles.get(rng.below(triangles.len().max(1) as u64) as usize) else { break };
        let apex = (positions[a as usize] + positions[b as usize]) * 0.5 + Vec3::new(0.1, -0.2, 0.7 + rng.unit_f32());
        positions.push(apex);
        triangles.push([a, b, positions.len() as u32 - 1]);
    }
    // A bowtie: a closed fan of its own around a copy of a grid vertex's position (welded to it).
    let centre = positions[rng.below(u64::from(side * side)) as usize];
    let first = positions.len() as u32;
    positions.push(centre);
    let ring = 3 + rng.below(4) as u32;
    for k in 0..ring {
        let angle = k as f32 / ring as f32 * std::f32::consts::TAU;
        positions.push(centre + Vec3::new(0.3 * angle.cos(), 0.3 * angle.sin(), 0.5 + 0.2 * rng.unit_f32()));
    }
    for k in 0..ring {
        triangles.push([first, first + 1 + k, first + 1 + (k + 1) % ring]);
    }
    // Split some input vertices (the copies weld back) and shuffle the faces.
    for t in triangles.iter_mut() {
        for v in t.iter_mut() {
            if rng.below(4) == 0 {
                positions.push(positions[*v as usize]);
                *v = positions.len() as u32 - 1;
            }
        }
    }
    for i in (1..triangles.len()).rev() {
        triangles.swap(i, rng.below(i as u64 + 1) as usize);
    }
    mesh(&format!("relief {seed}"), positions, triangles)
}

/// The layout's grouping rule, written out directly for meshes without degenerate faces: around each
/// welded vertex, faces joined through edges at the vertex with exactly two faces whose normals are
/// within the crease angle; groups in order of their first face, corners ascending, the source the
/// lowest input vertex of the group.
fn reference_groups(mesh: &Mesh, topology: &Topology, normals: &[Vec3], crease_deg: f32) -> Vec<(u32, u32, Vec<u32>)> {
    let cos_crease = (crease_deg as f64).to_radians().cos() as f32;
    let mut groups = Vec::new();
    for v in 0..topology.welded_positions.len() {
        let faces = topology.faces_of_vertex(v);
        let mut label: Vec<usize> = (0..faces.len()).collect();
        // Relabel to the smallest label until nothing changes: connected components, independently
        // of the library's union-find.
        loop {
            let mut changed = false;
            for (e, &[a, b]) in topology.edges.iter().enumerate() {
                if a as usize != v && b as usize != v {
                    continue;
                }
                let [f, g] = match topology.faces_of_edge(e) {
                    &[f, g] => [f, g],
                    _ => continue,
                };
                if normals[f as usize].dot(normals[g as usize]) < cos_crease {
                    continue;
                }
                let i = faces.binary_search(&f).expect("a face of an edge at v is a face of v");
                let j = faces.binary_search(&g).expect("a face of an edge at v is a face of v");
                let low = label[i].min(label[j]);
                if label[i] != low || label[j] != low {
                    (label[i], label[j]) = (low, low);
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        let mut roots: Vec<usize> = label.clone();
        roots.sort_unstable();
        roots.dedup();
        for root in roots {
            let mut corners = Vec::new();
            let mut source = u32::MAX;
            for (i, &f) in faces.iter().enumerate() {
                if label[i] != root {
                    continue;
                }
                let k = topology.faces[f as usize].iter().position(|&w| w as usize == v).expect("a face of v holds v");
                corners.push(f * 3 + k as u32);
                source = source.min(mesh.triangles[f as usize][k]);
            }
            groups.push((v as u32, source, corners));
        }
    }
    groups
}

#[test]
fn layout_matches_the_grouping_rule_on_random_reliefs() {
    let mut splits = 0;
    for seed in 0..300u64 {
        let relief = random_relief(seed);
        let crease = [0.0, 10.0, 30.0, 60.0, 120.0, 180.0][seed as usize % 6];
        let options = NormalsOptions {
            crease: CreaseOptions { crease_angle_deg: crease, ..Default::default() },
            ..Default::default()
        };
        let topology = Topology::build(&relief, Weld::Exact);
        let result = compute_normals(&relief, &topology, &options).0;
        assert_eq!(result.report.degenerate_faces, 0, "{}", relief.name);
        let expected = reference_groups(&relief, &topology, &result.faces.geometry.normals, crease);
        let layout = &result.layout;
        assert_eq!(layout.vertex_count(), expected.len(), "{}, crease {crease}", relief.name);
        for (v, (welded, source, corners)) in expected.iter().enumerate() {
            assert_eq!(layout.welded_vertex[v], *welded, "{} vertex {v}", relief.name);
            assert_eq!(layout.source_vertex[v], *source, "{} vertex {v}", relief.name);
            assert_eq!(layout.corners_of(v), corners.as_slice(), "{} vertex {v}", relief.name);
            for &c in corners {
                assert_eq!(layout.triangles[c as usize / 3][c as usize % 3], v as u32);
            }
        }
        splits += result.report.split_vertices;
    }
    // The sample holds both kinds of vertex: one smooth fan, and several groups.
    assert!(splits > 1000, "only {splits} split vertices over the sample");
}
