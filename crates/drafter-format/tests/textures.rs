//! Embedded textures: appended after the input's own images/samplers/textures, referenced by glTF
//! texture index from the root record, kept by compaction, read back byte for byte; a record that
//! does not reference every image exactly once is refused.

use std::path::Path;

use drafter_format::{
    BakeOutput, BoxRecord, CelTableRecord, CelTexture, Container, EmbeddedTextures, FormatError, GradientRecord,
    GradientTexture, HatchingTexture, InputInfo, PartRecord, ProjectorRecord, RootExtension, SamplerDesc, TextureImage,
    TextureRef, TexturesRecord,
};
use serde_json::Value;

/// One triangle with a base-colour texture of its own (image 0 in a buffer view), plus an accessor
/// nothing uses, so that compaction renumbers buffer views.
const SOURCE: &str = r#"{
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"name": "tri", "mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}],
  "textures": [{"source": 0, "sampler": 0}],
  "samplers": [{"magFilter": 9728}],
  "images": [{"bufferView": 3, "mimeType": "image/png"}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
    {"bufferView": 2, "componentType": 5126, "count": 1, "type": "SCALAR"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36},
    {"buffer": 0, "byteOffset": 36, "byteLength": 6},
    {"buffer": 0, "byteOffset": 56, "byteLength": 4},
    {"buffer": 0, "byteOffset": 44, "byteLength": 12}
  ],
  "buffers": [{"byteLength": 60, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAACJUE5HDQoaCmZha2UAAOBA"}]
}"#;

const INPUT_IMAGE: &[u8] = b"\x89PNG\r\n\x1a\nfake";

fn part() -> PartRecord {
    PartRecord {
        id: 0,
        name: "tri".into(),
        triangles: 1,
        obb: BoxRecord {
            center: [0.5, 0.5, 0.0],
            axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            half_extents: [0.5, 0.5, 0.0],
            volume: 0.0,
            method: drafter_format::ObbMethod::Aabb,
        },
        projector: ProjectorRecord {
            anchor: [0.5, 0.5, 0.0],
            direction: [1.0, 0.0, 0.0],
            scale: 1.0,
            matrix: [0.0; 16],
        },
        gradient: GradientRecord { q: 10.0, f: 0.5, p: 1.0, transfer: drafter_format::TransferCurve::Identity },
        style: None,
        flat: None,
    }
}

fn image(name: &str, bytes: &[u8], mipmaps: bool) -> TextureImage {
    TextureImage {
        name: name.into(),
        png: bytes.to_vec(),
        sampler: SamplerDesc { repeat_u: mipmaps, repeat_v: mipmaps, linear: true, mipmaps },
    }
}

fn textures() -> EmbeddedTextures {
    EmbeddedTextures {
        // Indices are positions in `images`, deliberately not in image order.
        record: TexturesRecord {
            gradient: Some(GradientTexture { index: 2, curves: vec![drafter_format::TransferCurve::Identity] }),
            cel: Some(CelTexture {
                index: 0,
                tables: vec![CelTableRecord {
                    steps: 3,
                    specular: true,
                    min_level: 0.3,
                    specular_threshold: 0.95,
                    diffuse_max: 0.8,
                }],
            }),
            hatching: Some(HatchingTexture {
                levels: vec![TextureRef { index: 1 }, TextureRef { index: 3 }],
                contrast: 4.0,
            }),
            ..TexturesRecord::default()
        },
        images: vec![
            image("cel_atlas", b"cel bytes", false),
            image("hatching", b"hatching level 0", true),
            image("gamma_atlas", b"gamma!", false),
            image("hatching_mip1", b"hatching level 1..", true),
        ],
    }
}

fn write(textures: Option<EmbeddedTextures>) -> Result<Vec<u8>, FormatError> {
    let scene = drafter_io::import_bytes(Path::new("tri.gltf"), SOURCE.as_bytes()).expect("imports").scene;
    let root = RootExtension {
        version: drafter_format::FORMAT_VERSION.into(),
        generator: "test".into(),
        input: InputInfo { name: "tri.gltf".into(), format: "gltf".into(), sha256: "0".repeat(64) },
        settings: Value::Null,
        scene_center: [0.5, 0.5, 0.0],
        part_count: 1,
        normals: None,
        textures: None,
    };
    let out = BakeOutput {
        scene: &scene,
        root,
        instance_parts: vec![vec![part()]],
        mesh_labels: vec![None],
        vertex_data: vec![None],
        primitive_edges: vec![vec![]],
        mesh_silhouettes: vec![None],
        textures,
        quantized_normals: false,
    };
    Ok(drafter_format::write(&out, &Container::Glb)?.main)
}

fn json_of(glb: &[u8]) -> Value {
    serde_json::from_slice(drafter_format::split_container(glb).expect("container").0).expect("json")
}

#[test]
fn textures_are_appended_referenced_and_read_back() {
    let glb = write(Some(textures())).expect("writes");
    let doc = json_of(&glb);
    // The input's texture, sampler and image stay first and unchanged.
    assert_eq!(doc["textures"][0]["source"], 0);
    assert_eq!(doc["samplers"][0]["magFilter"], 9728);
    assert_eq!(doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"], 0);
    // Ours follow: 4 images, 4 textures, 2 distinct samplers.
    assert_eq!(doc["images"].as_array().expect("images").len(), 5);
    assert_eq!(doc["textures"].as_array().expect("textures").len(), 5);
    assert_eq!(doc["samplers"].as_array().expect("samplers").len(), 3);
    assert_eq!(
        doc["samplers"][1],
        serde_json::json!({"magFilter": 9729, "minFilter": 9729, "wrapS": 33071, "wrapT": 33071})
    );
    assert_eq!(
        doc["samplers"][2],
        serde_json::json!({"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497})
    );
    let record = &doc["extensions"][drafter_format::EXTENSION]["textures"];
    assert_eq!(record["gradient"]["index"], 3);
    assert_eq!(record["cel"]["index"], 1);
    assert_eq!(record["hatching"]["levels"], serde_json::json!([{"index": 2}, {"index": 4}]));
    assert_eq!(doc["textures"][3]["name"], "gamma_atlas");
    assert_eq!(doc["textures"][3]["sampler"], 1);
    assert_eq!(doc["textures"][2]["sampler"], 2);

    // The reader gives the indices and the bytes back, in record order.
    let baked = drafter_format::read(&glb, &|_| None).expect("reads");
    let read_record = baked.root.textures.expect("textures record");
    assert_eq!(read_record.indices(), [3, 1, 2, 4]);
    let pngs = drafter_format::read_textures(&glb, &|_| None).expect("reads textures");
    let got: Vec<(u32, &str, &[u8])> = pngs.iter().map(|p| (p.texture, p.name.as_str(), p.png.as_slice())).collect();
    assert_eq!(
        got,
        [
            (3, "gamma_atlas", &b"gamma!"[..]),
            (1, "cel_atlas", &b"cel bytes"[..]),
            (2, "hatching", &b"hatching level 0"[..]),
            (4, "hatching_mip1", &b"hatching level 1.."[..]),
        ]
    );

    // Compaction dropped the unused accessor and its view, yet every image's bytes survived:
    // the input's own image too.
    assert_eq!(doc["accessors"].as_array().expect("accessors").len(), 2);
    let bin = drafter_format::split_container(&glb).expect("container").1.expect("bin");
    let view = &doc["bufferViews"][doc["images"][0]["bufferView"].as_u64().expect("view") as usize];
    let start = view["byteOffset"].as_u64().expect("offset") as usize;
    assert_eq!(&bin[start..start + view["byteLength"].as_u64().expect("length") as usize], INPUT_IMAGE);
}

#[test]
fn bin_grows_by_the_padded_image_bytes() {
    let without = write(None).expect("writes");
    let with = write(Some(textures())).expect("writes");
    let bin = |glb: &[u8]| drafter_format::split_container(glb).expect("container").1.map_or(0, <[u8]>::len);
    let padded: usize = textures().images.iter().map(|i| i.png.len().next_multiple_of(4)).sum();
    assert_eq!(bin(&with) - bin(&without), padded);
    assert!(drafter_format::read_textures(&without, &|_| None).expect("reads").is_empty());
    assert_eq!(drafter_format::read(&without, &|_| None).expect("reads").root.textures, None);
}

#[test]
fn every_image_must_be_referenced_exactly_once() {
    let mut unused = textures();
    unused.images.push(image("orphan", b"x", false));
    assert!(matches!(write(Some(unused)), Err(FormatError::Inconsistent(m)) if m.contains("image 4")));
    let mut twice = textures();
    twice.record.cel.as_mut().expect("cel").index = 2;
    assert!(matches!(write(Some(twice)), Err(FormatError::Inconsistent(_))));
    let mut missing = textures();
    missing.record.gradient.as_mut().expect("gradient").index = 9;
    assert!(matches!(write(Some(missing)), Err(FormatError::Inconsistent(m)) if m.contains("missing image 9")));
}
