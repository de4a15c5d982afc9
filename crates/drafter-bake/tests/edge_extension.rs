//! `EXT_mesh_primitive_edge_visibility` is written only on primitives with something to draw: the
//! draft requires a non-zero value in the bitfield, and CesiumJS stops rendering (a TypeError) on a
//! primitive whose bitfield is all zeros. A primitive whose every edge is smooth or
//! coplanar gets no extension; every written one holds a non-zero byte.

use drafter_core::{Mesh, Scene, SourceFormat, TriangleGroup};
use glam::Vec3;
use serde_json::Value;

/// Every primitive of a baked file that carries the extension, with its visibility bytes.
fn visibility_bytes(bytes: &[u8]) -> Vec<(usize, Option<Vec<u32>>)> {
    let (json, bin) = drafter_format::split_container(bytes).expect("container");
    let doc: Value = serde_json::from_slice(json).expect("json");
    let bin = bin.expect("bin");
    let mut out = Vec::new();
    for mesh in doc["meshes"].as_array().expect("meshes") {
        for (p, prim) in mesh["primitives"].as_array().expect("primitives").iter().enumerate() {
            let ext = &prim["extensions"]["EXT_mesh_primitive_edge_visibility"];
            let values = ext["visibility"]
                .as_u64()
                .map(|a| drafter_format::read_scalars(&doc, a as usize, bin).expect("visibility read"));
            out.push((p, values));
        }
    }
    out
}

/// A flat 4 × 4 grid whose two central triangles are a primitive of their own: all their edges are
/// coplanar with their neighbours, so they hold no hard edge and no silhouette candidate.
fn grid_with_a_flat_primitive() -> Scene {
    let side = 5u32;
    let mut positions: Vec<Vec3> =
        (0..side * side).map(|i| Vec3::new((i % side) as f32, (i / side) as f32, 0.0)).collect();
    let quad = |x: u32, y: u32| {
        let v = y * side + x;
        [[v, v + 1, v + side + 1], [v, v + side + 1, v + side]]
    };
    // The centre square (1, 1) .. (2, 2) with corners of its own (welded back to the grid's).
    let base = positions.len() as u32;
    positions.extend([
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(2.0, 1.0, 0.0),
        Vec3::new(2.0, 2.0, 0.0),
        Vec3::new(1.0, 2.0, 0.0),
    ]);
    let mut triangles = vec![[base, base + 1, base + 2], [base, base + 2, base + 3]];
    for y in 0..side - 1 {
        for x in 0..side - 1 {
            if (x, y) != (1, 1) {
                triangles.extend(quad(x, y));
            }
        }
    }
    let groups = vec![
        TriangleGroup { start: 0, count: 2, first_vertex: base, vertex_count: 4, ..Default::default() },
        TriangleGroup {
            start: 2,
            count: triangles.len() as u32 - 2,
            first_vertex: 0,
            vertex_count: side * side,
            ..Default::default()
        },
    ];
    let mesh = Mesh { name: "grid".into(), positions, triangles, groups, ..Default::default() };
    Scene::single_mesh(SourceFormat::Obj, mesh, "grid")
}

#[test]
fn a_primitive_without_edges_gets_no_extension() {
    let mut config = drafter_bake::BakeConfig::default();
    config.segment.mode = drafter_segment::SegmentMode::Components;
    let baked = drafter_bake::bake(&grid_with_a_flat_primitive(), &config).expect("bake");
    let primitives = visibility_bytes(&baked.written.main);
    assert_eq!(primitives.len(), 2);
    assert_eq!(primitives[0].1, None, "the flat centre has nothing to draw");
    let outer = primitives[1].1.as_ref().expect("the grid's border is hard edges");
    assert!(outer.iter().any(|&b| b != 0));
}

#[test]
fn no_written_primitive_has_an_all_zero_bitfield() {
    let sample = include_bytes!("../../../samples/assembly.glb");
    let imported = drafter_io::import_bytes(std::path::Path::new("assembly.glb"), sample).expect("sample");
    for compress in [drafter_bake::Compression::None, drafter_bake::Compression::Meshopt] {
        let config =
            drafter_bake::BakeConfig { output: drafter_bake::OutputOptions { compress }, ..Default::default() };
        let baked = drafter_bake::bake(&imported.scene, &config).expect("bake");
        let plain = drafter_format::meshopt::decompress_glb(&baked.written.main).expect("decode");
        let bytes = plain.as_deref().unwrap_or(&baked.written.main);
        let written: Vec<_> = visibility_bytes(bytes).into_iter().filter_map(|(p, v)| v.map(|v| (p, v))).collect();
        assert!(!written.is_empty());
        for (p, values) in written {
            assert!(values.iter().any(|&b| b != 0), "primitive {p}: an all-zero visibility bitfield");
        }
    }
}
