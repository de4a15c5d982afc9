//! The hierarchies a baked file stores answer exactly as brute force over what a reader decodes
//! from the file (format 0.2: the candidates are the Khronos 1-edges, their normals the decoded
//! `silhouetteNormals`, their points the written positions), bit for bit, over 10,000 views per
//! model: half orthographic, a quarter eyes outside the bounding box, a quarter inside.
//!
//! The path is the viewer's: bake in memory, `drafter_format::read`, the mesh's positions through
//! drafter-io's import of the baked bytes, `SilhouetteIndex::from_arrays` (which renumbers into
//! the Gauss map's storage order), then queries mapped back to corners and compared as sets.

use drafter_core::rng::Rng;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use drafter_lines::{BruteForce, EdgeSet, HierarchyChoice, SilhouetteArrays, SilhouetteIndex, View};
use glam::Vec3;

const VIEWS: usize = 10_000;

fn model(rel: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    assert!(root.join("README.md").is_file(), "the shared model corpus is missing at {}", root.display());
    root.join(rel)
}

fn check(path: &Path, compress: drafter_bake::Compression) -> usize {
    let imported = drafter_io::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let config = drafter_bake::BakeConfig { output: drafter_bake::OutputOptions { compress }, ..Default::default() };
    let baked = drafter_bake::bake(&imported.scene, &config).expect("bakes");
    let bytes = baked.written.main;
    if compress == drafter_bake::Compression::None {
        // The writer's sections, taken from its document, are what a reader finds in the file.
        let read = drafter_format::byte_sections(&bytes, &|_| None).expect("sections read");
        assert_eq!(baked.report.sections, read, "{}", path.display());
    }
    let file = drafter_format::read(&bytes, &|_| None).expect("reads");
    let scene = drafter_io::import_bytes(Path::new("baked.glb"), &bytes).expect("imports").scene;
    let mut hierarchies = 0;
    for (m, s) in &file.mesh_silhouettes {
        let mesh = &scene.meshes[*m as usize];
        let position =
            |corner: u32| mesh.positions[mesh.triangles[(corner / 3) as usize][(corner % 3) as usize] as usize];
        let points: Vec<f32> = s.candidate_corners.iter().flat_map(|&c| position(c).to_array()).collect();
        let choice = HierarchyChoice::GaussMap { max_depth: 0, nodes: 0, predicted_speedup: 0.0 };
        let arrays = SilhouetteArrays {
            candidate_edges: s.candidate_corners.clone(),
            candidate_normals: s.candidate_normals.clone(),
            candidate_points: points.clone(),
            gauss_map: s.gauss_map.clone(),
            cone_bvh: s.cone_bvh.clone(),
            orthographic: choice,
            perspective: HierarchyChoice::ConeBvh { leaf_size: 0, nodes: 0, predicted_speedup: 0.0 },
        };
        if arrays.gauss_map.is_none() && arrays.cone_bvh.is_none() {
            continue;
        }
        hierarchies += 1;
        let index = SilhouetteIndex::from_arrays(&arrays)
            .unwrap_or_else(|e| panic!("{}: mesh {m}: stored hierarchies do not load: {e}", path.display()));
        // The reference: brute force over the decoded candidates in file order.
        let normals: Vec<[Vec3; 2]> = s
            .candidate_normals
            .chunks_exact(6)
            .map(|c| [Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5])])
            .collect();
        let points: Vec<Vec3> = points.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
        let brute = BruteForce::new(&normals, &points);
        let (lo, hi) = points.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let (center, half) = ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-6));
        let mut rng = Rng::new(0x9E37_79B9_7F4A_7C15 ^ u64::from(*m));
        let (mut a, mut b) = (EdgeSet::new(normals.len()), EdgeSet::new(normals.len()));
        for v in 0..VIEWS {
            let view = match v % 4 {
                0 | 1 => View::Orthographic { direction: rng.direction_f32() },
                2 => View::Perspective { eye: center + rng.direction_f32() * half * (1.05 + 4.0 * rng.unit_f32()) },
                _ => View::Perspective {
                    eye: lo + (hi - lo) * Vec3::new(rng.unit_f32(), rng.unit_f32(), rng.unit_f32()),
                },
            };
            a.reset(normals.len());
            b.reset(normals.len());
            brute.query_serial(view, &mut a);
            index.query_serial(view, &mut b);
            let expected: BTreeSet<u32> = a.iter().map(|c| s.candidate_corners[c as usize]).collect();
            let got: BTreeSet<u32> = b.iter().map(|c| index.candidate_edges()[c as usize]).collect();
            assert_eq!(got, expected, "{}: mesh {m}, view {v} ({view:?})", path.display());
        }
    }
    hierarchies
}

#[test]
fn stored_hierarchies_answer_as_brute_force_over_the_decoded_file() {
    let mut total = 0;
    for rel in [
        "obj/common-3d-test-models/fandisk.obj",
        "obj/common-3d-test-models/stanford-bunny.obj",
        "obj/v-hacd/crank.off",
        // Every normal cell fits one cone-BVH leaf: no dual-space split, no `splits` accessor.
        "obj/cgal/larger_sphere.off",
    ] {
        let n = check(&model(rel), drafter_bake::Compression::None);
        assert!(n > 0, "{rel}: no stored hierarchy to check");
        total += n;
    }
    assert!(total >= 4);
}

/// `--compress` bakes the same triangles in the codecs' preferred order (vertex cache, first use,
/// each triangle starting at the corner the index codec keeps) with `NORMAL` rounded to 2^-10: the
/// compressed file holds the input's triangles (as position triples, up to order and rotation),
/// the same parts, and the same numbers of silhouette, hard and hidden edges as a plain bake; its
/// hierarchies answer as brute force over what a reader decodes from it. (That the codecs decode
/// every view back exactly is checked view by view as the file is written.)
#[test]
fn compressed_files_decode_to_the_plain_data_and_stay_exact() {
    let path = model("obj/common-3d-test-models/fandisk.obj");
    let imported = drafter_io::import(&path).expect("imports");
    let bake = |compress| {
        let config =
            drafter_bake::BakeConfig { output: drafter_bake::OutputOptions { compress }, ..Default::default() };
        drafter_bake::bake(&imported.scene, &config).expect("bakes")
    };
    let (plain, packed) = (bake(drafter_bake::Compression::None), bake(drafter_bake::Compression::Meshopt));
    let stats = packed.report.compression.clone().expect("compression stats");
    assert!(stats.encoded_views > 0 && stats.encoded_bytes_after < stats.encoded_bytes_before, "{stats:?}");
    assert!(packed.written.main.len() < plain.written.main.len());
    assert_eq!(stats.file_bytes_after, packed.written.main.len() as u64);

    let read = |bytes: &[u8]| drafter_format::read(bytes, &|_| None).expect("reads");
    let (a, b) = (read(&packed.written.main), read(&plain.written.main));
    let parts = |f: &drafter_format::BakedFile| -> Vec<(String, u32)> {
        f.parts().iter().map(|p| (p.name.clone(), p.triangles)).collect()
    };
    assert_eq!(parts(&a), parts(&b));
    // Edge values 0..=3 counted over every written triangle edge.
    let values = |f: &drafter_format::BakedFile| {
        let mut count = [0usize; 4];
        for (_, _, e) in &f.primitive_edges {
            for byte in &e.visibility {
                for k in 0..4 {
                    count[usize::from(byte >> (2 * k) & 3)] += 1;
                }
            }
        }
        count
    };
    let (va, vb) = (values(&a), values(&b));
    assert_eq!(va[1..], vb[1..], "silhouette, hard and repeated hard edges");

    let scene = |bytes: &[u8]| drafter_io::import_bytes(Path::new("baked.glb"), bytes).expect("imports").scene;
    let (sa, sb) = (scene(&packed.written.main), scene(&plain.written.main));
    // The same triangles as the input (position triples, up to order and rotation).
    let triangles = |scene: &drafter_core::Scene| {
        let mut out: Vec<[[u32; 3]; 3]> = Vec::new();
        for mesh in &scene.meshes {
            out.extend(mesh.triangles.iter().map(|t| {
                let p = t.map(|v| mesh.positions[v as usize].to_array().map(f32::to_bits));
                let first = (0..3).min_by_key(|&k| p[k]).unwrap_or(0);
                [p[first], p[(first + 1) % 3], p[(first + 2) % 3]]
            }));
        }
        out.sort_unstable();
        out
    };
    let input = triangles(&imported.scene);
    assert!(input == triangles(&sa) && input == triangles(&sb), "the baked triangles are the input's");
    // NORMAL is normalized bytes in the compressed file (KHR_mesh_quantization, required), each
    // a unit vector within the validator's tolerance, near the plain file's.
    let plain_glb =
        drafter_format::meshopt::decompress_glb(&packed.written.main).expect("decodes").expect("compressed");
    let json: serde_json::Value =
        serde_json::from_slice(drafter_format::glb::split(&plain_glb).expect("a GLB").json).expect("JSON");
    let required: Vec<&str> =
        json["extensionsRequired"].as_array().expect("required list").iter().filter_map(|v| v.as_str()).collect();
    assert!(required.contains(&"KHR_mesh_quantization"), "{required:?}");
    let normals = |s: &drafter_core::Scene| -> Vec<glam::Vec3> {
        s.meshes.iter().flat_map(|m| m.normals.clone().unwrap_or_default()).collect()
    };
    let (na, nb) = (normals(&sa), normals(&sb));
    assert!(!na.is_empty());
    for n in &na {
        assert!(n.to_array().iter().all(|c| ((c * 127.0).round() - c * 127.0).abs() < 1e-3), "{n}");
        assert!((n.length() - 1.0).abs() <= drafter_core::VALIDATOR_UNIT_TOLERANCE, "{n}");
    }
    // The two files' vertices differ in order; the mean of the normals is near either way.
    let mean = |v: &[glam::Vec3]| v.iter().copied().sum::<glam::Vec3>() / v.len() as f32;
    assert!(mean(&na).distance(mean(&nb)) < 0.02, "{} vs {}", mean(&na), mean(&nb));
    assert!(check(&path, drafter_bake::Compression::Meshopt) > 0);
}

/// The byte sections in the bake's report come from the writer's own document; they must be what
/// `drafter inspect` reads from the files, for both containers and a glTF source whose nodes
/// carry the part records.
#[test]
fn reported_sections_are_read_back_from_both_containers() {
    let imported = drafter_io::import(&model("gltf/2CylinderEngine/2CylinderEngine.gltf")).expect("imports");
    for container in [drafter_format::Container::Glb, drafter_format::Container::Gltf { bin_uri: "out.bin".into() }] {
        let config = drafter_bake::BakeConfig { container: container.clone(), ..Default::default() };
        let baked = drafter_bake::bake(&imported.scene, &config).expect("bakes");
        let bin = baked.written.bin.clone();
        let read = drafter_format::byte_sections(&baked.written.main, &|uri| {
            assert_eq!(uri, "out.bin");
            bin.clone()
        })
        .expect("sections read");
        assert_eq!(baked.report.sections, read, "{container:?}");
        assert!(read.json > 0 && read.geometry > 0 && read.total > read.json, "{read:?}");
    }
}
