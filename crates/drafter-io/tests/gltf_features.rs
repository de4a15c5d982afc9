//! glTF features the importer must honour, each on a tiny file built here: hierarchy with matrix and
//! TRS transforms, instancing (a mesh stored once), mirrored nodes, strips and fans, quantized
//! positions (KHR_mesh_quantization), the default scene, skipped points/lines, GLB and external
//! buffers.

use std::path::Path;

use base64::Engine as _;
use drafter_core::{DiagnosticKind, SourceFormat};
use glam::{DMat4, DVec3, Vec3};
use serde_json::{Value, json};

/// A binary blob plus the buffer views/accessors that describe it, built up piece by piece.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn push(&mut self, bytes: &[u8], accessor: Value) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        let mut a = accessor;
        a["bufferView"] = (self.views.len() - 1).into();
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = p.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        let (lo, hi) = p.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), v| {
            (std::array::from_fn(|i| lo[i].min(v[i])), std::array::from_fn(|i| hi[i].max(v[i])))
        });
        self.push(&bytes, json!({"componentType": 5126, "count": p.len(), "type": "VEC3", "min": lo, "max": hi}))
    }

    fn indices(&mut self, i: &[u16]) -> usize {
        let bytes: Vec<u8> = i.iter().flat_map(|c| c.to_le_bytes()).collect();
        self.push(&bytes, json!({"componentType": 5123, "count": i.len(), "type": "SCALAR"}))
    }

    fn document(self, mut doc: Value) -> Vec<u8> {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        );
        doc["asset"] = json!({"version": "2.0"});
        doc["buffers"] = json!([{"byteLength": self.bin.len(), "uri": uri}]);
        doc["bufferViews"] = Value::Array(self.views);
        doc["accessors"] = Value::Array(self.accessors);
        serde_json::to_vec(&doc).expect("json")
    }
}

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

fn import(bytes: &[u8]) -> drafter_io::Imported {
    drafter_io::import_bytes(Path::new("mem.gltf"), bytes).expect("imports")
}

#[test]
fn hierarchy_instancing_and_mirroring() {
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let idx = b.indices(&[0, 1, 2]);
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let doc = b.document(json!({
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "root", "translation": [10.0, 0.0, 0.0], "children": [1, 2, 3]},
            {"name": "a", "mesh": 0},
            {"name": "b", "mesh": 0, "matrix": [2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,5,1]},
            {"name": "mirror", "mesh": 0, "scale": [-1.0, 1.0, 1.0], "rotation": [0.0, 0.0, half, half]}
        ],
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}]
    }));
    let imported = import(&doc);
    let s = &imported.scene;
    assert_eq!(s.meshes.len(), 1, "a mesh used by three nodes is stored once");
    assert_eq!(s.instances.len(), 3);
    assert_eq!(s.instanced_triangle_count(), 3);
    let names: Vec<&str> = s.instances.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names, ["a", "b", "mirror"]);
    let world = |i: usize, p: [f64; 3]| s.instances[i].world_from_object.transform_point3(DVec3::from(p));
    assert!(world(0, [1.0, 0.0, 0.0]).abs_diff_eq(DVec3::new(11.0, 0.0, 0.0), 1e-12));
    assert!(world(1, [1.0, 0.0, 0.0]).abs_diff_eq(DVec3::new(12.0, 0.0, 5.0), 1e-12));
    assert!(!s.instances[0].flips_winding());
    assert!(s.instances[2].flips_winding(), "negative scale mirrors");
    assert_eq!(s.nodes[1].parent, Some(drafter_core::NodeId(0)));
    assert_eq!(s.roots, vec![drafter_core::NodeId(0)]);
}

#[test]
fn default_scene_is_used_and_points_are_skipped() {
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let doc = b.document(json!({
        "scene": 1,
        "scenes": [{"nodes": [0]}, {"nodes": [1]}],
        "nodes": [{"name": "not default", "mesh": 0}, {"name": "default", "mesh": 1}],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": pos}}]},
            {"primitives": [{"attributes": {"POSITION": pos}}, {"attributes": {"POSITION": pos}, "mode": 0}]}
        ]
    }));
    let imported = import(&doc);
    assert_eq!(imported.scene.instances.len(), 1);
    assert_eq!(imported.scene.instances[0].name, "default");
    assert_eq!(imported.scene.instanced_triangle_count(), 1, "non-indexed triangles; points skipped");
    assert!(imported.diagnostics.iter().any(|d| d.kind == DiagnosticKind::SkippedPrimitive));
}

#[test]
fn strips_fans_and_primitive_groups() {
    let mut b = Builder::default();
    let quad = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let pos = b.positions(&quad);
    let strip = b.indices(&[0, 1, 2, 3]);
    let fan = b.indices(&[0, 1, 3, 2]);
    let doc = b.document(json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "materials": [{"name": "m0"}, {"name": "m1", "pbrMetallicRoughness": {"metallicFactor": 0.25}}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": pos}, "indices": strip, "mode": 5, "material": 0},
            {"attributes": {"POSITION": pos}, "indices": fan, "mode": 6, "material": 1}
        ]}]
    }));
    let s = import(&doc).scene;
    let mesh = &s.meshes[0];
    assert_eq!(mesh.triangles.len(), 4);
    assert_eq!(mesh.positions.len(), 8, "primitives are concatenated");
    assert_eq!(mesh.groups.len(), 2);
    assert_eq!(mesh.groups[1].start, 2);
    assert_eq!(s.materials[1].metallic, 0.25);
    // Every triangle of this planar quad must face +z (consistent winding).
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        assert!((b - a).cross(c - a).z > 0.0, "{t:?} faces away");
    }
}

#[test]
fn quantized_positions_decode() {
    let mut b = Builder::default();
    // Normalised i16 positions (KHR_mesh_quantization), scaled back by the node.
    let q: Vec<u8> =
        [[0i16, 0, 0, 0], [32767, 0, 0, 0], [0, 32767, 0, 0]].iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    let pos = b.push(
        &q,
        json!({"componentType": 5122, "normalized": true, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}),
    );
    b.views[pos]["byteStride"] = 8.into();
    let doc = b.document(json!({
        "extensionsUsed": ["KHR_mesh_quantization"],
        "extensionsRequired": ["KHR_mesh_quantization"],
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "scale": [4.0, 4.0, 4.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}]
    }));
    let s = import(&doc).scene;
    assert_eq!(s.meshes[0].positions[1], Vec3::X);
    let w = s.instances[0].world_from_object;
    assert_eq!(w, DMat4::from_scale(DVec3::splat(4.0)));
}

#[test]
fn glb_and_external_buffers_load() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gltf-features");
    std::fs::create_dir_all(&dir).expect("dir");
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let bin = b.bin.clone();
    let mut doc: Value = serde_json::from_slice(&b.document(json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}]
    })))
    .expect("json");
    // External file with a space in its name (percent-encoded URI).
    std::fs::write(dir.join("my data.bin"), &bin).expect("bin");
    doc["buffers"][0]["uri"] = "my%20data.bin".into();
    let path = dir.join("ext.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).expect("json")).expect("gltf");
    let ext = drafter_io::import(&path).expect("external buffer");
    assert_eq!(ext.scene.format, SourceFormat::Gltf);
    assert_eq!(ext.scene.instanced_triangle_count(), 1);

    // The same as GLB: JSON chunk + BIN chunk, buffer without uri.
    doc["buffers"][0].as_object_mut().expect("obj").remove("uri");
    let glb = drafter_format::glb::write(&serde_json::to_vec(&doc).expect("json"), &bin).expect("glb");
    let imported = drafter_io::import_bytes(Path::new("x.glb"), &glb).expect("glb");
    assert_eq!(imported.scene.format, SourceFormat::Glb);
    assert_eq!(imported.scene.meshes[0].positions, TRI.map(Vec3::from).to_vec());
}

/// A POSITION accessor without a bufferView, all zeros but for `count_sparse` substituted elements:
/// the sparse indices 0.. and the values `TRI`.
fn sparse_only_positions(count: u64) -> Vec<u8> {
    let mut b = Builder::default();
    let indices = b.indices(&[0, 1, 2]);
    let values = b.positions(&TRI);
    let (index_view, value_view) =
        (b.accessors[indices]["bufferView"].clone(), b.accessors[values]["bufferView"].clone());
    b.accessors.push(json!({
        "componentType": 5126, "count": count, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0],
        "sparse": {"count": 3, "indices": {"bufferView": index_view, "componentType": 5123}, "values": {"bufferView": value_view}}
    }));
    let pos = b.accessors.len() - 1;
    b.document(json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}]
    }))
}

#[test]
fn sparse_accessor_without_buffer_view() {
    // Three elements, all substituted: a triangle.
    let s = import(&sparse_only_positions(3)).scene;
    assert_eq!(s.meshes[0].positions, TRI.map(Vec3::from).to_vec());
    // The count alone cannot size an allocation: 50 million VEC3s (600 MB) from a file of a few
    // hundred bytes is refused before anything is allocated, naming the accessor.
    let err = drafter_io::import_bytes(Path::new("mem.gltf"), &sparse_only_positions(50_000_000))
        .expect_err("a count beyond the file's buffers is refused");
    let message = err.to_string();
    assert!(message.contains("/accessors/2") && message.contains("50000000 elements"), "{message}");
}

/// Tightly packed accessors take a fast path of their own; strided ones (interleaved data) the
/// general one. Both must give the same scene, the same error at the same element, and no panic
/// for an empty accessor whose offset lies past its view.
#[test]
fn packed_and_strided_accessors_decode_alike() {
    let quad = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.5]];
    let corners: [u32; 6] = [0, 1, 2, 2, 1, 3];
    let document = |b: Builder, pos: usize, idx: usize| {
        b.document(json!({
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}]
        }))
    };
    let packed = |corners: &[u32]| {
        let mut b = Builder::default();
        let pos = b.positions(&quad);
        let bytes: Vec<u8> = corners.iter().flat_map(|c| c.to_le_bytes()).collect();
        let idx = b.push(&bytes, json!({"componentType": 5125, "count": corners.len(), "type": "SCALAR"}));
        document(b, pos, idx)
    };
    let strided = |corners: &[u32]| {
        let mut b = Builder::default();
        // Positions with a padding float after each (stride 16), indices as u16 with padding (stride 4).
        let bytes: Vec<u8> = quad.iter().flat_map(|p| [p[0], p[1], p[2], 9.0]).flat_map(f32::to_le_bytes).collect();
        let pos = b
            .push(&bytes, json!({"componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0.5]}));
        b.views[pos]["byteStride"] = 16.into();
        let bytes: Vec<u8> = corners.iter().flat_map(|&c| [c as u16, 0xffff]).flat_map(u16::to_le_bytes).collect();
        let idx = b.push(&bytes, json!({"componentType": 5123, "count": corners.len(), "type": "SCALAR"}));
        b.views[idx]["byteStride"] = 4.into();
        document(b, pos, idx)
    };
    let (a, b) = (import(&packed(&corners)).scene, import(&strided(&corners)).scene);
    assert_eq!(a.meshes[0].positions, b.meshes[0].positions);
    assert_eq!(a.meshes[0].triangles, b.meshes[0].triangles);
    assert_eq!(a.meshes[0].triangles, [[0, 1, 2], [2, 1, 3]]);
    assert_eq!(a.meshes[0].positions[3], Vec3::new(1.0, 1.0, 0.5));

    let bad = [0, 1, 2, 2, 7, 3];
    for doc in [packed(&bad), strided(&bad)] {
        let Err(error) = drafter_io::import_bytes(Path::new("mem.gltf"), &doc) else { panic!("index 7 is accepted") };
        let error = error.to_string();
        assert!(error.contains("index 7 at element 4"), "{error}");
    }

    let mut b = Builder::default();
    let pos = b.positions(&quad);
    let idx = b.push(&[0u8; 4], json!({"componentType": 5125, "count": 0, "type": "SCALAR", "byteOffset": 4096}));
    let empty = document(b, pos, idx);
    // Either a scene without triangles or an error; never a panic.
    if let Ok(imported) = drafter_io::import_bytes(Path::new("mem.gltf"), &empty) {
        assert!(imported.scene.meshes.iter().all(|m| m.triangles.is_empty()));
    }
}

/// The triangle limit counts what the primitives list (lists, strips, fans, unindexed, the same
/// accessors listed again) before reading any: at the count the import builds it passes, one
/// below it the import is refused at the primitive where the count passes the limit.
#[test]
fn the_triangle_limit_counts_what_the_primitives_list() {
    let mut b = Builder::default();
    let quad = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let pos = b.positions(&quad);
    let list = b.indices(&[0, 1, 2, 1, 3, 2, 0]);
    let strip = b.indices(&[0, 1, 2, 3]);
    let fan = b.indices(&[0, 1, 3, 2]);
    let mut primitives = Vec::new();
    for _ in 0..5 {
        primitives.push(json!({"attributes": {"POSITION": pos}, "indices": list}));
        primitives.push(json!({"attributes": {"POSITION": pos}, "indices": strip, "mode": 5}));
        primitives.push(json!({"attributes": {"POSITION": pos}, "indices": fan, "mode": 6}));
        primitives.push(json!({"attributes": {"POSITION": pos}}));
        primitives.push(json!({"attributes": {"POSITION": pos}, "indices": list, "mode": 1}));
    }
    let doc = b.document(json!({
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"mesh": 1}],
        "meshes": [{"primitives": primitives}, {"primitives": [{"attributes": {"POSITION": pos}, "indices": strip, "mode": 5}]}]
    }));
    let path = Path::new("mem.gltf");
    let built = drafter_io::import_bytes(path, &doc).expect("imports").scene;
    let total: usize = built.meshes.iter().map(|m| m.triangles.len()).sum();
    assert_eq!(total, 5 * (2 + 2 + 2 + 1) + 2, "lines are skipped, a 7-index list drops its last index");
    let at_limit = drafter_io::Limits { max_triangles: total as u64 };
    drafter_io::import_bytes_within(path, &doc, &at_limit).expect("a file at the limit imports");
    let below = drafter_io::Limits { max_triangles: total as u64 - 1 };
    let e =
        drafter_io::import_bytes_within(path, &doc, &below).expect_err("one below the limit is refused").to_string();
    assert!(e.contains("mem.gltf: /meshes/1/primitives/0: the meshes list 37 triangles up to here"), "{e}");
    let e = drafter_io::import_bytes_within(path, &doc, &drafter_io::Limits { max_triangles: 6 })
        .expect_err("refused early")
        .to_string();
    assert!(e.contains("/meshes/0/primitives/3: the meshes list 7 triangles"), "{e}");
}

/// The other formats are checked after their parse: they hold every triangle they list.
#[test]
fn the_triangle_limit_holds_for_text_formats() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
    let path = Path::new("two.obj");
    drafter_io::import_bytes_within(path, obj, &drafter_io::Limits { max_triangles: 2 }).expect("at the limit");
    let e = drafter_io::import_bytes_within(path, obj, &drafter_io::Limits { max_triangles: 1 })
        .expect_err("over the limit")
        .to_string();
    assert_eq!(e, "two.obj: file: 2 triangles, more than the limit of 1 (--max-triangles)");
}

/// A valid one-triangle document with `extra` merged into its root (images, cameras, ...).
fn triangle_with(extra: Value) -> Vec<u8> {
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let mut doc = json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}]
    });
    for (k, v) in extra.as_object().expect("object") {
        doc[k] = v.clone();
    }
    b.document(doc)
}

/// A 1×1 PNG as a data URI (the importer does not decode images; any bytes would do).
const PNG_URI: &str = "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8DwHwAFBQIAX8jx0gAAAABJRU5ErkJggg==";

/// Whether `f` panics (the panic hook is quiet meanwhile).
fn panics(f: impl FnOnce()) -> bool {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let panicked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).is_err();
    std::panic::set_hook(hook);
    panicked
}

/// What gltf-json's validation lets through but the gltf crate unwraps is refused before
/// the crate is asked, with one line naming the file and the JSON pointer (the CLI's exit 2). Each
/// document passes the crate's own validation, and the crate's accessor panics on it, which is why
/// the importer must check first.
#[test]
fn what_the_gltf_crate_unwraps_is_refused_by_its_place() {
    let cases: [(&str, Value, &str); 4] = [
        // gltf-1.4.1 src/image.rs:128, found by a black-box campaign of the release CLI.
        ("image {}", json!({"images": [{"uri": PNG_URI}, {}]}), "/images/1: an image needs a uri or a bufferView"),
        // src/image.rs:125.
        (
            "image in a view without mimeType",
            json!({"images": [{"bufferView": 0}]}),
            "/images/0: an image in a bufferView needs a mimeType",
        ),
        // src/camera.rs:86 (and :82 for an orthographic type).
        (
            "perspective camera without perspective",
            json!({"cameras": [{"type": "perspective", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.1}}]}),
            "/cameras/0: a camera of type perspective needs the member perspective",
        ),
        (
            "orthographic camera without orthographic",
            json!({"cameras": [{"type": "orthographic", "perspective": {"yfov": 1, "znear": 0.1}}]}),
            "/cameras/0: a camera of type orthographic needs the member orthographic",
        ),
    ];
    for (what, extra, expected) in cases {
        let bytes = triangle_with(extra);
        let crate_view = gltf::Gltf::from_slice(&bytes).expect("the gltf crate's validation accepts it");
        assert!(
            panics(|| {
                crate_view.images().for_each(|i| {
                    let _ = i.source();
                });
                crate_view.cameras().for_each(|c| {
                    let _ = c.projection();
                });
            }),
            "{what}: the gltf crate no longer panics; the guard may go"
        );
        let err = drafter_io::import_bytes(Path::new("mem.gltf"), &bytes).expect_err(what).to_string();
        assert_eq!(err, format!("mem.gltf: {expected}"), "{what}");
        // As a GLB, the same words.
        let mut doc: Value = serde_json::from_slice(&bytes).expect("json");
        let bin = base64::engine::general_purpose::STANDARD
            .decode(doc["buffers"][0]["uri"].as_str().expect("uri").split_once(',').expect("data uri").1)
            .expect("base64");
        doc["buffers"][0].as_object_mut().expect("buffer").remove("uri");
        let glb = drafter_format::glb::write(&serde_json::to_vec(&doc).expect("json"), &bin).expect("glb");
        let err = drafter_io::import_bytes(Path::new("mem.glb"), &glb).expect_err(what).to_string();
        assert_eq!(err, format!("mem.glb: {expected}"), "{what} (GLB)");
    }
    // The valid neighbours of those: images by URI and by view, both camera types.
    let ok = triangle_with(json!({
        "images": [{"uri": PNG_URI}, {"bufferView": 0, "mimeType": "image/png"}],
        "cameras": [
            {"type": "perspective", "perspective": {"yfov": 1, "znear": 0.1}},
            {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.1}}
        ]
    }));
    assert_eq!(import(&ok).scene.instanced_triangle_count(), 1);
}

/// A GLB whose JSON chunk is itself a GLB header claiming 4 bytes: `gltf::Gltf::from_slice` would
/// read it as a GLB and subtract the header's 12 bytes from 4 (gltf-1.4.1 src/binary.rs:252, a
/// panic with overflow checks, as in the CI's debug builds). The importer parses the chunk as JSON.
#[test]
fn a_json_chunk_that_is_a_glb_header_is_refused_as_json() {
    let inner = b"glTF\x02\x00\x00\x00\x04\x00\x00\x00";
    if cfg!(debug_assertions) {
        assert!(panics(|| drop(gltf::Gltf::from_slice(inner))), "the gltf crate no longer panics here");
    }
    let glb = drafter_format::glb::write(inner, &[]).expect("glb");
    let err = drafter_io::import_bytes(Path::new("nested.glb"), &glb).expect_err("refused").to_string();
    assert!(err.starts_with("nested.glb: line 1: invalid glTF JSON"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
}
