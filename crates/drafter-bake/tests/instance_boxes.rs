//! The boxes of a mesh's instances: each part placed by a rotation, a mirror and a uniform scale
//! takes the orientation found once for its mesh, turned with it (`SharedOrientations` in the
//! bake), and must still be that part's best box: it holds every point of the part and has the
//! volume of the box searched for on the part's own world points. An instance stretched unevenly
//! gets the box searched for on its own points, bit for bit. A symmetric part (a hexagonal nut has
//! six best boxes) gets one of them in every instance, turned with it.

use drafter_bake::{BakeConfig, bake};
use drafter_bounds::{ObbOptions, oriented_box};
use drafter_core::{Instance, Mesh, MeshId, PartId, Scene, SourceFormat};
use drafter_segment::{SegmentOptions, segment};
use glam::{DMat3, DMat4, DQuat, DVec3, Vec3};

/// A closed, lopsided hexahedron (no symmetry, so its best box is unique).
fn lopsided_block() -> Mesh {
    let corners = [
        [0.0, 0.0, 0.0],
        [3.1, 0.2, -0.1],
        [2.9, 1.4, 0.3],
        [-0.2, 1.1, 0.1],
        [0.3, -0.1, 0.7],
        [3.3, 0.1, 0.9],
        [3.0, 1.6, 1.2],
        [0.1, 1.2, 0.8],
    ];
    let positions = corners.iter().map(|&c| Vec3::from_array(c)).collect();
    let triangles = vec![
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    Mesh { name: "block".into(), positions, triangles, ..Default::default() }
}

/// A hexagonal prism, like a nut: six boxes of the same, smallest volume.
fn hexagonal_prism() -> Mesh {
    let mut positions = Vec::new();
    for z in [0.0f32, 0.6] {
        for k in 0..6 {
            let a = std::f32::consts::PI / 3.0 * k as f32;
            positions.push(Vec3::new(a.cos(), a.sin(), z));
        }
    }
    let mut triangles = Vec::new();
    for k in 0..6u32 {
        let n = (k + 1) % 6;
        triangles.extend([[k, n, 6 + n], [k, 6 + n, 6 + k]]);
    }
    for k in 1..5u32 {
        triangles.extend([[0, k + 1, k], [6, 6 + k, 6 + k + 1]]);
    }
    Mesh { name: "nut".into(), positions, triangles, ..Default::default() }
}

fn placements() -> Vec<DMat4> {
    let turn = |axis: DVec3, angle: f64| DQuat::from_axis_angle(axis.normalize(), angle);
    let mut m = vec![
        DMat4::IDENTITY,
        DMat4::from_rotation_translation(turn(DVec3::new(1.0, 2.0, 3.0), 0.7), DVec3::new(10.0, -4.0, 2.0)),
        DMat4::from_scale_rotation_translation(DVec3::splat(2.5), turn(DVec3::Z, 2.1), DVec3::new(-7.0, 0.0, 5e3)),
        // A mirror: the winding flips, the box does not care.
        DMat4::from_scale_rotation_translation(
            DVec3::new(-1.0, 1.0, 1.0),
            turn(DVec3::new(-2.0, 0.5, 1.0), 1.3),
            DVec3::new(0.0, 30.0, 0.0),
        ),
        DMat4::from_scale_rotation_translation(DVec3::splat(1e-3), turn(DVec3::X, -0.4), DVec3::new(1e5, 1e5, 0.0)),
    ];
    // More turns about arbitrary axes (a seeded sequence, no extra crate).
    let mut rng = drafter_core::rng::Rng::new(0x9E37_79B9_7F4A_7C15u64);
    let mut next = || rng.unit_f64();
    for _ in 0..24 {
        let axis = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
        let at = DVec3::new(next(), next(), next()) * 100.0;
        m.push(DMat4::from_rotation_translation(turn(axis, 6.0 * next()), at));
    }
    // Stretched unevenly: not a similarity, boxed on its own.
    m.push(DMat4::from_scale_rotation_translation(DVec3::new(1.0, 3.0, 0.5), turn(DVec3::Y, 0.9), DVec3::ZERO));
    m
}

#[test]
fn instances_share_their_mesh_box_turned_with_them() {
    check(lopsided_block());
    check(hexagonal_prism());
}

fn check(mesh: Mesh) {
    let mut scene = Scene::new(SourceFormat::Obj);
    scene.meshes.push(mesh);
    for (i, m) in placements().into_iter().enumerate() {
        scene.instances.push(Instance { name: format!("part_{i}"), mesh: MeshId(0), node: None, world_from_object: m });
    }
    let baked = bake(&scene, &BakeConfig::default()).expect("bakes");
    let (parts, _) = segment(&scene, &SegmentOptions::default());
    assert_eq!(baked.report.parts.len(), scene.instances.len(), "one part per instance");
    let options = ObbOptions::default();
    let first = &baked.report.parts[0].obb;
    for (p, record) in baked.report.parts.iter().enumerate() {
        let obb = &record.obb;
        let points = drafter_bake::part_points(&scene, &parts, PartId::from(p));
        let searched = oriented_box(&points, &options).expect("box");
        let size = searched.half_extents.max_element();
        let (center, axes) = (DVec3::from(obb.center), obb.axes.map(DVec3::from));
        for q in &points {
            let d = *q - center;
            for (axis, half) in axes.iter().zip(obb.half_extents) {
                assert!(axis.dot(d).abs() <= half + 1e-9 * (size + q.abs().max_element()), "part {p}");
            }
        }
        let m = scene.instances[p].world_from_object;
        if p == scene.instances.len() - 1 {
            // The uneven stretch: the search on its own points, as before sharing.
            assert_eq!(obb.axes, searched.axes.map(|a| a.to_array()), "part {p}");
            assert_eq!(obb.half_extents, searched.half_extents.to_array(), "part {p}");
            continue;
        }
        let name = &scene.meshes[0].name;
        // The world points themselves are rounded to the ulp of their coordinates (1e5 away, a
        // part 1e-3 across: 1e-8 of its size).
        let rounding = 64.0 * f64::EPSILON * center.abs().max_element() / size;
        let change = (obb.volume / searched.volume - 1.0).abs();
        assert!(change < 1e-9 + rounding, "{name} {p}: {} against {}", obb.volume, searched.volume);
        // Turned with the instance: the first instance's axes carried by this one's transform.
        let carry = DMat3::from_mat4(m) * DMat3::from_mat4(scene.instances[0].world_from_object).inverse();
        for (k, (axis, first)) in axes.iter().zip(first.axes).enumerate() {
            let expected = (carry * DVec3::from(first)).normalize();
            assert!(expected.dot(*axis).abs() > 1.0 - 1e-12, "{name} {p} axis {k}: {expected} against {axis}");
        }
    }
}
