//! Small synthetic scenes for every mode, checked against counts known by construction.

use std::sync::Arc;

use drafter_core::{Instance, InstanceId, Mesh, MeshId, PartId, Scene, SourceFormat};
use drafter_segment::{MeshLabels, Parts, SegmentMode, SegmentOptions, segment};
use glam::{DMat4, DVec3, Vec3};

/// Appends a box from `lo` to `hi` the way CAD exporters write it: every face its own patch of
/// `n`×`n` quads with its own vertices (welding joins them), outward-facing.
fn add_box(mesh: &mut Mesh, lo: Vec3, hi: Vec3, n: u32) {
    for axis in 0..3 {
        for side in [false, true] {
            let (u_axis, v_axis) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = mesh.positions.len() as u32;
            for j in 0..=n {
                for i in 0..=n {
                    let mut p = [0.0f32; 3];
                    p[axis] = if side { hi[axis] } else { lo[axis] };
                    p[u_axis] = lo[u_axis] + (hi[u_axis] - lo[u_axis]) * i as f32 / n as f32;
                    p[v_axis] = lo[v_axis] + (hi[v_axis] - lo[v_axis]) * j as f32 / n as f32;
                    mesh.positions.push(Vec3::from(p));
                }
            }
            for j in 0..n {
                for i in 0..n {
                    let a = base + j * (n + 1) + i;
                    let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
                    // u × v points along +axis: counter-clockwise seen from +axis.
                    if side {
                        mesh.triangles.extend([[a, b, c], [a, c, d]]);
                    } else {
                        mesh.triangles.extend([[a, c, b], [a, d, c]]);
                    }
                }
            }
        }
    }
}

/// Appends a convex polygon (fan) with its own vertices.
fn add_polygon(mesh: &mut Mesh, corners: &[Vec3]) {
    let base = mesh.positions.len() as u32;
    mesh.positions.extend_from_slice(corners);
    for i in 1..corners.len() as u32 - 1 {
        mesh.triangles.push([base, base + i, base + i + 1]);
    }
}

fn scene_of(meshes: Vec<Mesh>, instances: &[(usize, DMat4)]) -> Scene {
    let mut scene = Scene::new(SourceFormat::Stl);
    scene.meshes = meshes;
    for (i, &(mesh, world_from_object)) in instances.iter().enumerate() {
        scene.instances.push(Instance {
            name: format!("i{i}"),
            mesh: MeshId::from(mesh),
            node: None,
            world_from_object,
        });
    }
    scene
}

fn single(mesh: Mesh) -> Scene {
    scene_of(vec![mesh], &[(0, DMat4::IDENTITY)])
}

fn run(scene: &Scene, mode: SegmentMode) -> Parts {
    segment(scene, &SegmentOptions { mode, ..SegmentOptions::default() }).0
}

fn sizes(parts: &Parts) -> Vec<u32> {
    parts.parts.iter().map(|p| p.triangles).collect()
}

/// Part of each triangle of instance 0.
fn labels(parts: &Parts, triangles: usize) -> Vec<u32> {
    (0..triangles as u32).map(|t| parts.part_of(InstanceId(0), t).0).collect()
}

#[test]
fn two_separate_cubes_are_two_components() {
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 1);
    add_box(&mut mesh, Vec3::splat(2.0), Vec3::splat(3.0), 1);
    let scene = single(mesh);
    for mode in [SegmentMode::Components, SegmentMode::Auto] {
        let parts = run(&scene, mode);
        assert_eq!(sizes(&parts), vec![12, 12], "{mode}");
        assert_eq!(labels(&parts, 24), [vec![0; 12], vec![1; 12]].concat());
    }
    assert_eq!(sizes(&run(&scene, SegmentMode::Nodes)), vec![24]);
}

#[test]
fn a_shared_corner_does_not_connect() {
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 1);
    add_box(&mut mesh, Vec3::ONE, Vec3::splat(2.0), 1);
    let scene = single(mesh);
    let topo = drafter_core::Topology::build(&scene.meshes[0], Default::default());
    assert_eq!(topo.component_count, 1, "vertex-connected through the shared corner");
    assert_eq!(sizes(&run(&scene, SegmentMode::Components)), vec![12, 12]);
}

#[test]
fn cubes_sharing_an_edge_are_paired_into_two_solids() {
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 1);
    add_box(&mut mesh, Vec3::new(1.0, 1.0, 0.0), Vec3::new(2.0, 2.0, 1.0), 1);
    let scene = single(mesh);
    let topo = drafter_core::Topology::build(&scene.meshes[0], Default::default());
    assert_eq!(topo.nonmanifold_edge_count(), 1);
    let (parts, diagnostics) = segment(&scene, &SegmentOptions { mode: SegmentMode::Components, ..Default::default() });
    assert_eq!(sizes(&parts), vec![12, 12]);
    assert!(diagnostics.is_empty(), "{diagnostics:?}");
}

#[test]
fn a_face_repeated_in_the_same_orientation_joins_its_solid() {
    // A face written 50 more times, same vertices in the same order: the same surface, not 50
    // one-triangle parts (with many copies, the merge of small parts would be quadratic).
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 1);
    let first = mesh.triangles[0];
    mesh.triangles.extend(std::iter::repeat_n(first, 50));
    let scene = single(mesh);
    for mode in [SegmentMode::Components, SegmentMode::Auto] {
        let (parts, diagnostics) = segment(&scene, &SegmentOptions { mode, ..Default::default() });
        assert_eq!(sizes(&parts), vec![62], "{mode}");
        assert!(diagnostics.is_empty(), "{mode}: {diagnostics:?}");
    }
}

#[test]
fn stacked_cubes_with_coincident_faces_are_two_solids() {
    // As in obj/occt/motor.stl: where two solids touch along a face, both write the same
    // triangles (opposite orientation), so every edge of the contact face is non-manifold.
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 2);
    add_box(&mut mesh, Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 2.0), 2);
    let scene = single(mesh);
    let topo = drafter_core::Topology::build(&scene.meshes[0], Default::default());
    assert!(topo.nonmanifold_edge_count() >= 12);
    let (parts, diagnostics) = segment(&scene, &SegmentOptions { mode: SegmentMode::Components, ..Default::default() });
    assert_eq!(sizes(&parts), vec![48, 48]);
    assert!(diagnostics.is_empty(), "{diagnostics:?}");
    assert_eq!(labels(&parts, 96), [vec![0; 48], vec![1; 48]].concat());
}

#[test]
fn a_double_sided_flap_on_an_edge_merges_into_the_solid() {
    // As on obj/v-hacd/crank.off: two coincident triangles facing apart, glued to an edge of a
    // solid. Pairing makes them a closed piece of zero volume: not a solid, so Auto merges it.
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 20);
    let base = mesh.positions.len() as u32;
    mesh.positions.extend([Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.05, 0.0, 1.0), Vec3::new(0.025, -0.025, 1.025)]);
    mesh.triangles.extend([[base, base + 1, base + 2], [base + 1, base, base + 2]]);
    let scene = single(mesh);
    let (components, diagnostics) =
        segment(&scene, &SegmentOptions { mode: SegmentMode::Components, ..Default::default() });
    assert!(diagnostics.is_empty(), "{diagnostics:?}");
    assert_eq!(sizes(&components), vec![4800, 2]);
    assert_eq!(sizes(&run(&scene, SegmentMode::Auto)), vec![4802]);
}

#[test]
fn inside_out_solids_are_paired_too() {
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 1);
    add_box(&mut mesh, Vec3::new(1.0, 1.0, 0.0), Vec3::new(2.0, 2.0, 1.0), 1);
    for t in &mut mesh.triangles {
        t.swap(1, 2);
    }
    assert_eq!(sizes(&run(&single(mesh), SegmentMode::Components)), vec![12, 12]);
}

#[test]
fn regions_of_a_cube_are_its_six_faces() {
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 3);
    let scene = single(mesh);
    let parts = run(&scene, SegmentMode::Regions);
    assert_eq!(sizes(&parts), vec![18; 6]);
    // Every region is one face of the box: its triangles share an axis-aligned normal.
    for p in 0..parts.len() {
        let normals: Vec<Vec3> = parts
            .triangles_of(PartId::from(p))
            .map(|t| {
                let [a, b, c] = scene.meshes[0].triangles[t as usize].map(|v| scene.meshes[0].positions[v as usize]);
                (b - a).cross(c - a).normalize()
            })
            .collect();
        assert!(normals.iter().all(|n| n.abs_diff_eq(normals[0], 1e-6)));
    }
    // The components are the whole cube.
    assert_eq!(sizes(&run(&scene, SegmentMode::Components)), vec![108]);
}

/// A unit cube with the edge between its top (+z) and front (-y) faces cut off by a 45° chamfer
/// of width 0.25: 7 planar faces.
fn chamfered_cube() -> Mesh {
    let c = 0.25f32;
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mut mesh = Mesh::default();
    add_polygon(&mut mesh, &[v(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(1.0, 1.0, 0.0), v(1.0, 0.0, 0.0)]); // bottom
    add_polygon(&mut mesh, &[v(0.0, c, 1.0), v(1.0, c, 1.0), v(1.0, 1.0, 1.0), v(0.0, 1.0, 1.0)]); // top
    add_polygon(&mut mesh, &[v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(1.0, 0.0, 1.0 - c), v(0.0, 0.0, 1.0 - c)]); // front
    add_polygon(&mut mesh, &[v(0.0, 0.0, 1.0 - c), v(1.0, 0.0, 1.0 - c), v(1.0, c, 1.0), v(0.0, c, 1.0)]); // chamfer
    add_polygon(&mut mesh, &[v(0.0, 1.0, 0.0), v(0.0, 1.0, 1.0), v(1.0, 1.0, 1.0), v(1.0, 1.0, 0.0)]); // back
    add_polygon(
        &mut mesh,
        &[v(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0 - c), v(0.0, c, 1.0), v(0.0, 1.0, 1.0), v(0.0, 1.0, 0.0)],
    ); // left
    add_polygon(
        &mut mesh,
        &[v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(1.0, 1.0, 1.0), v(1.0, c, 1.0), v(1.0, 0.0, 1.0 - c)],
    ); // right
    mesh
}

#[test]
fn regions_follow_the_crease_angle() {
    let scene = single(chamfered_cube());
    let topo = drafter_core::Topology::build(&scene.meshes[0], Default::default());
    assert_eq!((topo.boundary_edge_count(), topo.nonmanifold_edge_count()), (0, 0), "closed");
    let regions = |angle: f64| {
        let options = SegmentOptions { mode: SegmentMode::Regions, region_angle_deg: angle, ..Default::default() };
        segment(&scene, &options).0.len()
    };
    assert_eq!(regions(30.0), 7);
    // At 50° the 45° chamfer joins both its neighbours: {top, chamfer, front} + 4 faces.
    assert_eq!(regions(50.0), 5);
    assert_eq!(regions(100.0), 1);
}

#[test]
fn a_shallow_bend_is_one_region_at_30_degrees() {
    // Two quads meeting at 20°.
    let a = 20f32.to_radians();
    let mut mesh = Mesh::default();
    let (p0, p1) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
    let (q0, q1) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0));
    let r = Vec3::new(1.0 + a.cos(), 0.0, a.sin());
    let (r0, r1) = (r, r + Vec3::Y);
    add_polygon(&mut mesh, &[p0, q0, q1, p1]);
    add_polygon(&mut mesh, &[q0, r0, r1, q1]);
    let scene = single(mesh);
    let regions = |angle: f64| {
        segment(&scene, &SegmentOptions { mode: SegmentMode::Regions, region_angle_deg: angle, ..Default::default() })
            .0
            .len()
    };
    assert_eq!(regions(30.0), 1);
    assert_eq!(regions(10.0), 2);
}

/// A big box (1200 triangles) with a 2-triangle patch lying on its top face, not welded to it.
fn box_with_sliver() -> Mesh {
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::splat(10.0), 10);
    add_polygon(
        &mut mesh,
        &[Vec3::new(2.0, 2.0, 10.0), Vec3::new(2.5, 2.0, 10.0), Vec3::new(2.5, 2.3, 10.0), Vec3::new(2.0, 2.3, 10.0)],
    );
    mesh
}

#[test]
fn slivers_merge_into_their_neighbour() {
    let scene = single(box_with_sliver());
    assert_eq!(sizes(&run(&scene, SegmentMode::Components)), vec![1200, 2]);
    let (parts, diagnostics) = segment(&scene, &SegmentOptions::default());
    assert_eq!(sizes(&parts), vec![1202]);
    assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
    assert_eq!(diagnostics[0].count, 1);
    // Merging off.
    let off = SegmentOptions { merge_triangle_fraction: 0.0, ..SegmentOptions::default() };
    assert_eq!(sizes(&segment(&scene, &off).0), vec![1200, 2]);
}

#[test]
fn a_sliver_joins_the_largest_of_the_parts_it_touches() {
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::splat(10.0), 4); // 192 triangles
    add_box(&mut mesh, Vec3::new(10.0, 0.0, 0.0), Vec3::new(20.0, 10.0, 10.0), 10); // 1200 triangles
    // A vertical strip standing across the joint of the two top faces (touches both, welds to none).
    add_polygon(
        &mut mesh,
        &[Vec3::new(9.5, 5.0, 10.0), Vec3::new(10.5, 5.0, 10.0), Vec3::new(10.5, 5.0, 10.3), Vec3::new(9.5, 5.0, 10.3)],
    );
    let scene = single(mesh);
    assert_eq!(sizes(&run(&scene, SegmentMode::Components)), vec![192, 1200, 2]);
    // The boxes touch along x = 10 with different tessellations (no shared edge): two
    // components. The strip touches both and goes to the bigger.
    assert_eq!(sizes(&run(&scene, SegmentMode::Auto)), vec![192, 1202]);
}

#[test]
fn what_does_not_merge() {
    let mut mesh = box_with_sliver();
    // A far-away open patch touches nothing: it stays.
    add_polygon(&mut mesh, &[Vec3::splat(30.0), Vec3::new(30.5, 30.0, 30.0), Vec3::new(30.0, 30.5, 30.0)]);
    // A small closed box standing on the big one is a solid: it stays.
    add_box(&mut mesh, Vec3::new(6.0, 6.0, 10.0), Vec3::new(6.5, 6.5, 10.5), 1);
    let scene = single(mesh);
    let (parts, diagnostics) = segment(&scene, &SegmentOptions::default());
    assert_eq!(sizes(&parts), vec![1202, 1, 12]);
    assert!(diagnostics[0].first_example.contains("1 small ones touch nothing and 0 touch only"), "{diagnostics:?}");
}

#[test]
fn an_instanced_mesh_gives_parts_per_instance() {
    let mut mesh = Mesh::default();
    for i in 0..3 {
        add_box(&mut mesh, Vec3::new(3.0 * i as f32, 0.0, 0.0), Vec3::new(3.0 * i as f32 + 1.0, 1.0, 1.0), 1);
    }
    let mut other = Mesh::default();
    add_box(&mut other, Vec3::ZERO, Vec3::ONE, 2);
    // 20 instances of the 3-box mesh, with the 1-box mesh in the middle of the list.
    let mut instances: Vec<(usize, DMat4)> =
        (0..20).map(|i| (0, DMat4::from_translation(DVec3::new(0.0, 2.0 * i as f64, 0.0)))).collect();
    instances.insert(7, (1, DMat4::IDENTITY));
    let scene = scene_of(vec![mesh, other], &instances);

    let parts = run(&scene, SegmentMode::Components);
    assert_eq!(parts.len(), 61);
    assert_eq!(parts.instances.len(), 21);
    let mut next = 0;
    for (i, ip) in parts.instances.iter().enumerate() {
        assert_eq!(ip.first_part, PartId(next), "parts are numbered by instance, then label");
        next += ip.part_count;
        for label in 0..ip.part_count {
            let part = parts.part(PartId(ip.first_part.0 + label));
            assert_eq!((part.instance, part.label), (InstanceId::from(i), label));
        }
    }
    // One label table, shared by the 20 instances of mesh 0.
    let tables: Vec<_> = parts
        .instances
        .iter()
        .filter_map(|ip| match &ip.labels {
            MeshLabels::PerTriangle(t) => Some(t.clone()),
            MeshLabels::Whole => None,
        })
        .collect();
    assert_eq!(tables.len(), 20);
    assert!(tables.iter().all(|t| Arc::ptr_eq(t, &tables[0])));
    assert_eq!(parts.instances[7].labels, MeshLabels::Whole);
    assert_eq!(parts.part(PartId(21)).name, "i7");
    assert_eq!(parts.part(PartId(22)).name, "i8#0");
    // part_of and triangles_of agree.
    for p in 0..parts.len() {
        let part = PartId::from(p);
        let triangles: Vec<u32> = parts.triangles_of(part).collect();
        assert_eq!(triangles.len() as u32, parts.part(part).triangles);
        assert!(triangles.iter().all(|&t| parts.part_of(parts.part(part).instance, t) == part));
    }

    // Auto keeps the file's parts: one per instance.
    let auto = run(&scene, SegmentMode::Auto);
    assert_eq!(auto.len(), 21);
    assert!(auto.instances.iter().all(|ip| ip.labels == MeshLabels::Whole));
    assert_eq!(run(&scene, SegmentMode::Nodes), auto);
}

#[test]
fn collapsed_triangles_join_a_neighbour() {
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 1);
    // (0, 0, 1): two welded vertices the same; it has no edge.
    mesh.triangles.push([0, 0, 1]);
    mesh.triangles.push([1, 1, 1]);
    let scene = single(mesh);
    for mode in [SegmentMode::Components, SegmentMode::Regions] {
        let parts = run(&scene, mode);
        let whole = parts.part_of(InstanceId(0), 0);
        assert_eq!(parts.part_of(InstanceId(0), 12), whole, "{mode}");
        assert_eq!(parts.part_of(InstanceId(0), 13), parts.part_of(InstanceId(0), 1), "{mode}");
    }
}

#[test]
fn empty_scenes_and_meshes() {
    let empty = Scene::new(SourceFormat::Obj);
    for mode in SegmentMode::ALL {
        let (parts, diagnostics) = segment(&empty, &SegmentOptions { mode, ..Default::default() });
        assert!(parts.is_empty() && diagnostics.is_empty());
    }
    let scene = single(Mesh::default());
    for mode in SegmentMode::ALL {
        let parts = run(&scene, mode);
        assert_eq!(sizes(&parts), vec![0], "{mode}");
        assert_eq!(parts.triangles_of(PartId(0)).count(), 0);
    }
}

#[test]
fn same_parts_at_any_thread_count() {
    let mut mesh = box_with_sliver();
    for i in 0..40 {
        let x = 12.0 + (i % 8) as f32 * 1.5;
        let y = (i / 8) as f32 * 1.5;
        add_box(&mut mesh, Vec3::new(x, y, 0.0), Vec3::new(x + 1.0, y + 1.0, 1.0 + i as f32 * 0.1), 1 + i % 3);
        add_polygon(&mut mesh, &[Vec3::new(x, y, 1.0), Vec3::new(x + 0.2, y, 1.0), Vec3::new(x, y + 0.2, 1.0)]);
    }
    let scene = single(mesh);
    for mode in SegmentMode::ALL {
        let options = SegmentOptions { mode, merge_triangle_fraction: 0.02, ..Default::default() };
        let run_with = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
            pool.install(|| segment(&scene, &options))
        };
        let one = run_with(1);
        assert_eq!(one, run_with(4), "{mode}");
        assert_eq!(one, run_with(3), "{mode}");
    }
}

#[test]
fn modes_parse_and_print() {
    for mode in SegmentMode::ALL {
        assert_eq!(mode.name().parse::<SegmentMode>(), Ok(mode));
        assert_eq!(mode.to_string(), mode.name());
    }
    assert!("blobs".parse::<SegmentMode>().is_err());
    assert_eq!(SegmentMode::default(), SegmentMode::Auto);
}

/// A box whose faces are patches of `n[face]`×`n[face]` quads (faces in the order of `add_box`:
/// -x, +x, -y, +y, -z, +z), each with its own vertices; faces with different `n` meet at a crack
/// (T-junctions: they share the corners but no edge). `lift` moves the +z face up.
fn cracked_box(n: [u32; 6], lift: f32) -> Mesh {
    let mut mesh = Mesh::default();
    let mut face = Mesh::default();
    for (k, &nk) in n.iter().enumerate() {
        face.positions.clear();
        face.triangles.clear();
        add_box(&mut face, Vec3::ZERO, Vec3::ONE, nk);
        // add_box writes six faces of 2·nk² triangles and (nk + 1)² vertices each, in order.
        let (v, t) = (((nk + 1) * (nk + 1)) as usize, (2 * nk * nk) as usize);
        let base = mesh.positions.len() as u32;
        let offset = (k * v) as u32;
        let up = if k == 5 { Vec3::Z * lift } else { Vec3::ZERO };
        mesh.positions.extend(face.positions[k * v..(k + 1) * v].iter().map(|&p| p + up));
        mesh.triangles.extend(face.triangles[k * t..(k + 1) * t].iter().map(|tri| tri.map(|i| i - offset + base)));
    }
    mesh
}

#[test]
fn a_face_cracked_off_its_solid_is_glued_back() {
    // The top is a 2×2 patch on 1×1 sides: its edges' midpoints lie on the sides' edges.
    let scene = single(cracked_box([1, 1, 1, 1, 1, 2], 0.0));
    assert_eq!(sizes(&run(&scene, SegmentMode::Components)), vec![10, 8]);
    let (parts, diagnostics) = segment(&scene, &SegmentOptions::default());
    assert_eq!(sizes(&parts), vec![18]);
    let glued = diagnostics.iter().find(|d| d.kind == drafter_core::DiagnosticKind::GluedCrack);
    assert_eq!(glued.map(|d| d.count), Some(1), "{diagnostics:?}");
    // Off, or with the face lifted beyond the tolerance, the crack stays a cut.
    let off = SegmentOptions { stitch_fraction: 0.0, ..SegmentOptions::default() };
    assert_eq!(sizes(&segment(&scene, &off).0), vec![10, 8]);
    let lifted = single(cracked_box([1, 1, 1, 1, 1, 2], 1e-4));
    assert_eq!(sizes(&segment(&lifted, &SegmentOptions::default()).0), vec![10, 8]);
}

#[test]
fn every_face_cracked_apart_is_glued_into_one_part() {
    // Six patches, no two with the same tessellation along a shared edge: six open pieces.
    let scene = single(cracked_box([1, 2, 3, 4, 5, 6], 0.0));
    assert_eq!(run(&scene, SegmentMode::Components).len(), 6);
    assert_eq!(run(&scene, SegmentMode::Auto).len(), 1);
}

#[test]
fn open_pieces_that_only_touch_are_not_glued() {
    // Two squares side by side along half an edge: neither is sealed by the other.
    let mut mesh = Mesh::default();
    add_polygon(&mut mesh, &[Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]);
    add_polygon(
        &mut mesh,
        &[Vec3::new(1.0, 0.5, 0.0), Vec3::new(2.0, 0.5, 0.0), Vec3::new(2.0, 1.5, 0.0), Vec3::new(1.0, 1.5, 0.0)],
    );
    assert_eq!(run(&single(mesh), SegmentMode::Auto).len(), 2);
    // A sheet lying on a closed cube's face: the cube has no free edge to seal it.
    let mut mesh = Mesh::default();
    add_box(&mut mesh, Vec3::ZERO, Vec3::ONE, 1);
    add_polygon(
        &mut mesh,
        &[
            Vec3::new(0.25, 0.25, 1.0),
            Vec3::new(0.75, 0.25, 1.0),
            Vec3::new(0.75, 0.75, 1.0),
            Vec3::new(0.25, 0.75, 1.0),
        ],
    );
    assert_eq!(sizes(&run(&single(mesh), SegmentMode::Auto)), vec![12, 2]);
}

#[test]
fn thousands_of_open_slivers_through_one_point_are_not_searched_pairwise() {
    // 20,000 separate triangles that share only their apex: 40,000 free edges through one point.
    // Crowded cells are skipped, so this is linear; nothing seals anything.
    let mut mesh = Mesh::default();
    for i in 0..20_000u32 {
        let a = i as f32 * 0.000_314;
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([
            Vec3::ZERO,
            Vec3::new(a.cos(), a.sin(), 0.1),
            Vec3::new((a + 0.0002).cos(), (a + 0.0002).sin(), 0.1),
        ]);
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    let (parts, diagnostics) = segment(&single(mesh), &SegmentOptions::default());
    assert!(!parts.is_empty());
    assert!(diagnostics.iter().all(|d| d.kind != drafter_core::DiagnosticKind::GluedCrack), "{diagnostics:?}");
}

#[test]
fn one_long_free_edge_among_tiny_ones_does_not_blow_up_the_grid() {
    // Found by the fuzz campaign: 300 separate triangles a nanometre wide near the origin and one
    // large triangle. The grid cell follows the tiny edges; the large triangle's edges must still
    // touch a bounded number of cells, or the grid would ask for gigabytes.
    let mut mesh = Mesh::default();
    for i in 0..300u32 {
        let o = Vec3::new(i as f32 * 3e-9, 0.0, 0.0);
        add_polygon(&mut mesh, &[o, o + Vec3::new(1e-9, 0.0, 0.0), o + Vec3::new(0.0, 1e-9, 0.0)]);
    }
    add_polygon(&mut mesh, &[Vec3::ZERO, Vec3::ONE, Vec3::new(1.0, 0.0, 0.0)]);
    let (parts, _) = segment(&single(mesh), &SegmentOptions::default());
    assert!(!parts.is_empty());
}
