//! Primitives within 16-bit indices: a mesh of more than 65,535 vertices bakes into consecutive
//! primitives of at most 65,535 vertices with UNSIGNED_SHORT indices, for glTF input (the source
//! primitive's JSON copied per chunk) and for synthesized documents, with and without the normal
//! stage's layout; the file reads back to the same triangles, every primitive's Khronos edges
//! decode under the per-primitive rules (hard edges on a chunk seam in each chunk), and the mesh's
//! silhouette candidates are each encoded once, as in the unsplit primitive.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use drafter_core::{Material, MaterialId, Mesh, Scene, SourceFormat, Topology, TriangleGroup, Weld};
use drafter_format::MAX_PRIMITIVE_VERTICES;
use glam::Vec3;
use serde_json::{Value, json};

/// Grid side: 400² = 160,000 vertices in the first primitive (three chunks).
const SIDE: u32 = 400;

/// A bumpy height field of `SIDE`² vertices (row-major quads, two triangles each, with UVs = x, y)
/// followed by a tetrahedron away from it (second primitive, own material).
fn model() -> (Vec<Vec3>, Vec<[u32; 3]>, usize) {
    let mut positions = Vec::new();
    for j in 0..SIDE {
        for i in 0..SIDE {
            let (x, y) = (i as f32 / (SIDE - 1) as f32, j as f32 / (SIDE - 1) as f32);
            let z = 0.05 * (19.0 * x).sin() * (13.0 * y).cos() + 0.03 * (31.0 * x * y).sin();
            positions.push(Vec3::new(x, y, z));
        }
    }
    let mut triangles = Vec::new();
    for j in 0..SIDE - 1 {
        for i in 0..SIDE - 1 {
            let v = j * SIDE + i;
            triangles.push([v, v + 1, v + SIDE]);
            triangles.push([v + 1, v + SIDE + 1, v + SIDE]);
        }
    }
    let grid_triangles = triangles.len();
    let base = positions.len() as u32;
    positions.extend([
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(2.5, 1.0, 0.0),
        Vec3::new(2.5, 0.4, 1.0),
    ]);
    triangles.extend([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]].map(|t| t.map(|v| v + base)));
    (positions, triangles, grid_triangles)
}

/// The model as a .glb: one mesh, two primitives (32-bit indices), the first with `extras`.
fn model_glb() -> Vec<u8> {
    let (positions, triangles, grid) = model();
    let split = SIDE * SIDE;
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut push = |bytes: Vec<u8>, accessor: Value, target: u32| {
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len(), "target": target}));
        bin.extend(bytes);
        let mut accessor = accessor;
        accessor["bufferView"] = (views.len() - 1).into();
        accessors.push(accessor);
        accessors.len() - 1
    };
    let mut primitives = Vec::new();
    for (k, (vertices, tris)) in
        [(&positions[..split as usize], &triangles[..grid]), (&positions[split as usize..], &triangles[grid..])]
            .into_iter()
            .enumerate()
    {
        let first = if k == 0 { 0 } else { split };
        let (lo, hi) =
            vertices.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let position = push(
            vertices.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect(),
            json!({"componentType": 5126, "count": vertices.len(), "type": "VEC3", "min": lo.to_array(), "max": hi.to_array()}),
            34962,
        );
        let uv = push(
            vertices.iter().flat_map(|p| [p.x, p.y]).flat_map(f32::to_le_bytes).collect(),
            json!({"componentType": 5126, "count": vertices.len(), "type": "VEC2"}),
            34962,
        );
        let indices = push(
            tris.iter().flatten().map(|&v| v - first).flat_map(u32::to_le_bytes).collect(),
            json!({"componentType": 5125, "count": 3 * tris.len(), "type": "SCALAR"}),
            34963,
        );
        let mut primitive =
            json!({"attributes": {"POSITION": position, "TEXCOORD_0": uv}, "indices": indices, "material": k});
        if k == 0 {
            primitive["extras"] = json!({"tag": "grid"});
        }
        primitives.push(primitive);
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "grid"}],
        "meshes": [{"name": "grid", "primitives": primitives}],
        "materials": [{"name": "a"}, {"name": "b"}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    drafter_format::glb::write(doc.to_string().as_bytes(), &bin).expect("glb")
}

/// The same mesh as a scene without a glTF document (as OBJ input is).
fn synthesized_scene() -> Scene {
    let (positions, triangles, grid) = model();
    let uvs = Some(positions.iter().map(|p| glam::Vec2::new(p.x, p.y)).collect());
    let groups = vec![
        TriangleGroup {
            start: 0,
            count: grid as u32,
            material: Some(MaterialId(0)),
            vertex_count: SIDE * SIDE,
            ..Default::default()
        },
        TriangleGroup {
            start: grid as u32,
            count: 4,
            material: Some(MaterialId(1)),
            first_vertex: SIDE * SIDE,
            vertex_count: 4,
            ..Default::default()
        },
    ];
    let mesh = Mesh { name: "grid".into(), positions, triangles, uvs, groups, ..Default::default() };
    let mut scene = Scene::single_mesh(SourceFormat::Obj, mesh, "grid");
    scene.materials = ["a", "b"].map(|name| Material { name: name.into(), ..Default::default() }).to_vec();
    scene
}

/// A triangle by its corner positions, rotated to start at the smallest (winding kept).
fn by_position(positions: &[Vec3], t: [u32; 3]) -> [[u32; 3]; 3] {
    let c = t.map(|v| positions[v as usize].to_array().map(f32::to_bits));
    let k = (0..3).min_by_key(|&k| c[k]).expect("three corners");
    [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
}

fn config(normals: bool) -> drafter_bake::BakeConfig {
    let mut config = drafter_bake::BakeConfig::default();
    config.normals.enabled = normals;
    // Low enough that the bumps make hard edges and silhouette candidates all over the grid.
    config.lines.crease_angle_deg = 1.5;
    config.segment.mode = drafter_segment::SegmentMode::Components;
    config
}

/// Checks a baked file of [`model`]; returns its primitive count.
fn check(bytes: &[u8], report: &drafter_bake::BakeReport, normals: bool, from_gltf: bool) -> usize {
    let (json, bin) = drafter_format::split_container(bytes).expect("container");
    let doc: Value = serde_json::from_slice(json).expect("json");
    let bin = bin.expect("bin");
    let primitives = doc["meshes"][0]["primitives"].as_array().expect("primitives").clone();
    // Three chunks of the grid, then the tetrahedron.
    assert_eq!(primitives.len(), 4, "{primitives:?}");
    for (p, prim) in primitives.iter().enumerate() {
        let indices = prim["indices"].as_u64().expect("indices") as usize;
        // The tetrahedron fits: written as before (its source's UNSIGNED_INT, or the smallest type).
        if p < 3 {
            assert_eq!(doc["accessors"][indices]["componentType"], 5123, "primitive {p}: UNSIGNED_SHORT");
        }
        let values = drafter_format::read_scalars(&doc, indices, bin).expect("indices read");
        let position = prim["attributes"]["POSITION"].as_u64().expect("POSITION") as usize;
        let count = doc["accessors"][position]["count"].as_u64().expect("count");
        assert!(count <= u64::from(MAX_PRIMITIVE_VERTICES), "primitive {p}: {count} vertices");
        assert!(values.iter().all(|&i| i < 65_535 && u64::from(i) < count), "primitive {p}: index range");
        assert_eq!(prim.get("mode"), None);
        assert_eq!(prim["material"], if p < 3 { 0 } else { 1 }, "the source primitive's material");
        if from_gltf {
            assert_eq!(prim.get("extras").cloned(), (p < 3).then(|| json!({"tag": "grid"})));
        }
        assert_eq!(prim["attributes"].get("_ENHANCED_NORMAL").is_some(), normals);
    }
    let split = report.split.expect("a split");
    assert_eq!((split.split_primitives, split.chunks), (1, 3));

    // The same triangles, by position, with their UVs.
    let (positions, triangles, _) = model();
    let scene = drafter_io::import_bytes(Path::new("baked.glb"), bytes).expect("imports").scene;
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.triangles.len(), triangles.len());
    let mut expected: Vec<_> = triangles.iter().map(|&t| by_position(&positions, t)).collect();
    let mut got: Vec<_> = mesh.triangles.iter().map(|&t| by_position(&mesh.positions, t)).collect();
    // Triangle order is kept.
    assert_eq!(got, expected);
    expected.sort_unstable();
    got.sort_unstable();
    assert_eq!(got, expected);
    let uvs = mesh.uvs.as_ref().expect("uvs");
    assert!(mesh.positions.iter().zip(uvs).all(|(p, t)| p.x == t.x && p.y == t.y));
    assert_eq!(
        mesh.groups.iter().map(|g| g.count as usize).sum::<usize>(),
        triangles.len(),
        "the primitives hold every triangle once"
    );

    // The Khronos edges, primitive by primitive.
    let file = drafter_format::read(bytes, &|_| None).expect("reads");
    let topology = Topology::build(mesh, Weld::default());
    let edges_of = |g: &TriangleGroup| -> BTreeSet<[u32; 2]> {
        mesh.triangles[g.start as usize..(g.start + g.count) as usize]
            .iter()
            .map(|t| t.map(|v| topology.welded_of_vertex[v as usize]))
            .flat_map(|w| (0..3).map(move |k| [w[k].min(w[(k + 1) % 3]), w[k].max(w[(k + 1) % 3])]))
            .filter(|[a, b]| a != b)
            .collect()
    };
    let mut hard_total = 0;
    let mut hard = BTreeSet::new();
    let mut silhouettes: BTreeMap<[u32; 2], usize> = BTreeMap::new();
    let mut primitives_of_edge: BTreeMap<[u32; 2], usize> = BTreeMap::new();
    assert_eq!(file.primitive_edges.len(), 4);
    for (_, p, e) in &file.primitive_edges {
        let group = mesh.groups.iter().find(|g| g.primitive == Some(*p)).expect("group of the primitive");
        let triangles = &mesh.triangles[group.start as usize..(group.start + group.count) as usize];
        let decoded = drafter_lines::decode_edge_visibility(
            triangles,
            &topology.welded_of_vertex,
            &e.visibility,
            &e.silhouette_normals.decoded_all(),
        )
        .unwrap_or_else(|err| panic!("primitive {p}: {err}"));
        assert_eq!(e.hard_edge_classes.len(), decoded.hard.len());
        hard_total += decoded.hard.len();
        hard.extend(decoded.hard.iter().copied());
        for (pair, _) in &decoded.silhouettes {
            *silhouettes.entry(*pair).or_default() += 1;
        }
        for pair in edges_of(group) {
            *primitives_of_edge.entry(pair).or_default() += 1;
        }
    }
    // Hard edges on a seam are encoded in each chunk; there are some.
    assert!(hard_total > hard.len(), "no hard edge on a chunk seam");
    // Silhouette candidates: each encoded once in the mesh, seam ones included, and as many as the
    // line stage classified (the unsplit primitive's count: nothing is shared with the tetrahedron).
    assert!(silhouettes.values().all(|&n| n == 1), "a candidate encoded twice");
    let seam_candidates = silhouettes.keys().filter(|pair| primitives_of_edge[*pair] > 1).count();
    assert!(seam_candidates > 0, "no silhouette candidate on a chunk seam");
    let lines = report.lines.as_ref().expect("lines");
    assert_eq!(silhouettes.len(), lines.edges.silhouette_candidate);
    assert_eq!(lines.silhouette_candidates, lines.edges.silhouette_candidate);
    let (_, stored) = &file.mesh_silhouettes[0];
    assert_eq!(stored.candidate_corners.len(), silhouettes.len());

    // Labels (two parts) and normals per primitive.
    assert_eq!(file.primitive_labels.len(), 4);
    for (_, p, labels) in &file.primitive_labels {
        let group = mesh.groups.iter().find(|g| g.primitive == Some(*p)).expect("group");
        assert_eq!(labels.len(), group.count as usize);
        assert!(labels.iter().all(|&l| l == u32::from(*p == 3)), "primitive {p}: labels");
    }
    let sets = drafter_format::read_normal_sets(bytes, &|_| None).expect("normal sets");
    assert_eq!(sets.len(), if normals { 4 } else { 0 });
    for set in &sets {
        let group = mesh.groups.iter().find(|g| g.primitive == Some(set.primitive)).expect("group");
        assert_eq!(set.normals.len(), group.vertex_count as usize);
    }
    primitives.len()
}

#[test]
fn gltf_primitives_over_65535_vertices_split_into_16_bit_chunks() {
    let glb = model_glb();
    let scene = drafter_io::import_bytes(Path::new("grid.glb"), &glb).expect("imports").scene;
    for normals in [true, false] {
        let baked = drafter_bake::bake(&scene, &config(normals)).expect("bakes");
        assert!(baked.written.notes.is_empty(), "{:?}", baked.written.notes);
        check(&baked.written.main, &baked.report, normals, true);
        if normals {
            // Deterministic at any thread count.
            let at = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
                pool.install(|| drafter_bake::bake(&scene, &config(true)).expect("bakes").written.main)
            };
            assert!(at(1) == baked.written.main && at(2) == baked.written.main);
            // Chunks of a layout count its output vertices: 160,000 plus the seam copies.
            let split = baked.report.split.expect("split");
            assert_eq!(split.vertices, (SIDE * SIDE) as usize);
            assert!(split.duplicated_vertices > 0 && split.duplicated_vertices < 3 * SIDE as usize);
        }
    }
}

#[test]
fn synthesized_primitives_over_65535_vertices_split_into_16_bit_chunks() {
    let scene = synthesized_scene();
    for normals in [true, false] {
        let baked = drafter_bake::bake(&scene, &config(normals)).expect("bakes");
        assert!(baked.written.notes.is_empty(), "{:?}", baked.written.notes);
        check(&baked.written.main, &baked.report, normals, false);
    }
}
