//! The seeds each target's cases start from: the repository's `samples/*.glb` (as .glb, and as
//! .gltf with the buffer embedded as a data URI), the small files of `../shared/models` (every file
//! up to a size limit, .gltf buffers embedded the same way), small meshes generated here in every
//! text and binary flavour (drafter-testkit's shapes written as OBJ, STL, OFF and PLY), and for the
//! baked-file target the bakes of the samples and of two generated meshes, made in-process at start.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context as _;
use base64::Engine as _;
use drafter_testkit::generate::{self, TriMesh};

use crate::Target;

/// One starting input.
#[derive(Clone, Debug)]
pub struct Seed {
    /// Where it came from (a repository-relative path or `generated:<shape>`).
    pub name: String,
    pub bytes: Vec<u8>,
}

/// Seeds by target; every target has at least one.
#[derive(Clone, Debug, Default)]
pub struct Corpus {
    pub seeds: BTreeMap<Target, Vec<Seed>>,
}

impl Corpus {
    pub fn of(&self, target: Target) -> &[Seed] {
        self.seeds.get(&target).map_or(&[], Vec::as_slice)
    }

    fn add(&mut self, target: Target, name: impl Into<String>, bytes: Vec<u8>) {
        self.seeds.entry(target).or_default().push(Seed { name: name.into(), bytes });
    }
}

/// Gathers the corpus. `repo` is the repository root (its `samples/`, and `../shared/models`
/// beside it when present); files above `max_bytes` are left out. Fails when the samples are
/// missing: a fuzzer without its seeds would test nothing.
pub fn corpus(repo: &Path, max_bytes: usize) -> anyhow::Result<Corpus> {
    let mut corpus = Corpus::default();
    generated(&mut corpus);

    let samples = repo.join("samples");
    let mut sample_files: Vec<_> = std::fs::read_dir(&samples)
        .with_context(|| format!("{}: the samples are the fuzzer's seeds", samples.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    sample_files.sort();
    anyhow::ensure!(!sample_files.is_empty(), "{}: no .glb samples", samples.display());
    for path in &sample_files {
        let bytes = std::fs::read(path).with_context(|| path.display().to_string())?;
        let name = format!("samples/{}", path.file_name().unwrap_or_default().to_string_lossy());
        if let Some(gltf) = glb_to_gltf(&bytes) {
            corpus.add(Target::Gltf, format!("{name} (as .gltf)"), gltf);
        }
        if bytes.len() <= max_bytes {
            corpus.add(Target::Glb, name.clone(), bytes);
        }
    }

    // Committed seeds of what nothing in the workspace writes: a Draco-compressed glTF
    // (KHR_draco_mesh_compression; fuzz/seeds/draco-cylinder.py says how it was made),
    // mutated as a GLB and as a .gltf with a data URI.
    let committed = repo.join("fuzz/seeds");
    let mut committed_files: Vec<_> = std::fs::read_dir(&committed)
        .with_context(|| format!("{}: the committed seeds", committed.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    committed_files.sort();
    anyhow::ensure!(
        committed_files.iter().any(|p| p.file_name().is_some_and(|n| n == "draco-cylinder.glb")),
        "{}: the Draco seed draco-cylinder.glb is missing",
        committed.display()
    );
    for path in &committed_files {
        let bytes = std::fs::read(path).with_context(|| path.display().to_string())?;
        let name = format!("fuzz/seeds/{}", path.file_name().unwrap_or_default().to_string_lossy());
        if let Some(gltf) = glb_to_gltf(&bytes) {
            corpus.add(Target::Gltf, format!("{name} (as .gltf)"), gltf);
        }
        corpus.add(Target::Glb, name, bytes);
    }

    let shared = repo.join("../shared/models");
    let mut files = Vec::new();
    walk(&shared, &mut files);
    files.sort();
    for path in files {
        let Ok(meta) = std::fs::metadata(&path) else { continue };
        if meta.len() as usize > max_bytes {
            continue;
        }
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        let Ok(bytes) = std::fs::read(&path) else { continue };
        let name = path.strip_prefix(repo).unwrap_or(&path).display().to_string();
        match ext.as_str() {
            "glb" => corpus.add(Target::Glb, name, bytes),
            "gltf" => {
                if let Some(embedded) = embed_buffers(&path, &bytes, max_bytes) {
                    corpus.add(Target::Gltf, name, embedded);
                }
            }
            "obj" => corpus.add(Target::Obj, name, bytes),
            "off" => corpus.add(Target::Off, name, bytes),
            "ply" => corpus.add(Target::Ply, name, bytes),
            "stl" if is_binary_stl(&bytes) => corpus.add(Target::StlBinary, name, bytes),
            "stl" => corpus.add(Target::StlAscii, name, bytes),
            _ => {}
        }
    }

    features(&mut corpus);
    baked(&mut corpus)?;
    for target in Target::ALL {
        anyhow::ensure!(!corpus.of(target).is_empty(), "no seeds for {}", target.name());
    }
    Ok(corpus)
}

fn walk(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            walk(&path, out);
        } else {
            out.push(path);
        }
    }
}

fn is_binary_stl(bytes: &[u8]) -> bool {
    bytes.len() >= 84 && {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        count.checked_mul(50).and_then(|n| n.checked_add(84)) == Some(bytes.len())
    }
}

fn data_uri(bin: &[u8]) -> String {
    format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(bin))
}

/// A .glb as a .gltf whose buffer 0 is a data URI.
fn glb_to_gltf(bytes: &[u8]) -> Option<Vec<u8>> {
    let chunks = drafter_format::glb::split(bytes).ok()?;
    let mut doc: serde_json::Value = serde_json::from_slice(chunks.json).ok()?;
    let buffer = doc.get_mut("buffers")?.get_mut(0)?.as_object_mut()?;
    buffer.insert("uri".into(), data_uri(chunks.bin.unwrap_or_default()).into());
    serde_json::to_vec_pretty(&doc).ok()
}

/// A .gltf with its external buffers read and embedded as data URIs; `None` when one is missing or
/// the result exceeds `max_bytes`.
fn embed_buffers(path: &Path, bytes: &[u8], max_bytes: usize) -> Option<Vec<u8>> {
    let mut doc: serde_json::Value = serde_json::from_slice(bytes).ok()?;
    let dir = path.parent()?;
    for buffer in doc.get_mut("buffers")?.as_array_mut()? {
        let uri = buffer.get("uri")?.as_str()?;
        if uri.starts_with("data:") {
            continue;
        }
        let bin = std::fs::read(dir.join(uri)).ok()?;
        buffer.as_object_mut()?.insert("uri".into(), data_uri(&bin).into());
    }
    let out = serde_json::to_vec(&doc).ok()?;
    (out.len() <= max_bytes).then_some(out)
}

/// Small meshes in every flavour of every text and binary format.
fn generated(corpus: &mut Corpus) {
    let shapes: [(&str, TriMesh); 5] = [
        ("cube", generate::cube()),
        ("cylinder", generate::cylinder(12, 2.0)),
        ("open-box", generate::open_box()),
        ("nonmanifold-fan", generate::nonmanifold_fan(4)),
        ("single-triangle", generate::single_triangle()),
    ];
    for (name, mesh) in &shapes {
        let name = format!("generated:{name}");
        corpus.add(Target::Obj, &name, obj(mesh));
        corpus.add(Target::StlAscii, &name, stl_ascii(mesh));
        corpus.add(Target::StlBinary, &name, stl_binary(mesh));
        corpus.add(Target::Off, &name, off(mesh));
        corpus.add(Target::Ply, format!("{name} (ascii)"), ply(mesh, false));
        corpus.add(Target::Ply, format!("{name} (binary)"), ply(mesh, true));
    }
    // OBJ with what OBJ files carry besides faces: normals, uvs, groups, a quad, a negative index.
    corpus.add(
        Target::Obj,
        "generated:obj-features",
        b"# features\nmtllib none.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n\
vn 0 0 1\ng a\nusemtl red\ns 1\nf 1/1/1 2/2/1 3/3/1\ng b\nf -4 -2 -1\nf 1 2 3 4\nl 1 2\n"
            .to_vec(),
    );
}

fn obj(mesh: &TriMesh) -> Vec<u8> {
    let mut s = String::from("o mesh\n");
    for p in &mesh.positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s.into_bytes()
}

fn stl_ascii(mesh: &TriMesh) -> Vec<u8> {
    let mut s = String::from("solid mesh\n");
    for t in &mesh.triangles {
        s.push_str("facet normal 0 0 0\nouter loop\n");
        for &v in t {
            let p = mesh.positions[v as usize];
            let _ = writeln!(s, "vertex {} {} {}", p.x, p.y, p.z);
        }
        s.push_str("endloop\nendfacet\n");
    }
    s.push_str("endsolid mesh\n");
    s.into_bytes()
}

fn stl_binary(mesh: &TriMesh) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out.extend_from_slice(&(mesh.triangles.len() as u32).to_le_bytes());
    for t in &mesh.triangles {
        out.extend_from_slice(&[0u8; 12]);
        for &v in t {
            for c in mesh.positions[v as usize].to_array() {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}

fn off(mesh: &TriMesh) -> Vec<u8> {
    let mut s = format!("OFF\n{} {} 0\n", mesh.positions.len(), mesh.triangles.len());
    for p in &mesh.positions {
        let _ = writeln!(s, "{} {} {}", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
    }
    s.into_bytes()
}

fn ply(mesh: &TriMesh, binary: bool) -> Vec<u8> {
    let format = if binary { "binary_little_endian" } else { "ascii" };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment generated\nelement vertex {}\nproperty float x\nproperty float y\n\
property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .into_bytes();
    for p in &mesh.positions {
        if binary {
            for c in p.to_array() {
                out.extend_from_slice(&c.to_le_bytes());
            }
        } else {
            out.extend_from_slice(format!("{} {} {}\n", p.x, p.y, p.z).as_bytes());
        }
    }
    for t in &mesh.triangles {
        if binary {
            out.push(3);
            for v in t {
                out.extend_from_slice(&(*v as i32).to_le_bytes());
            }
        } else {
            out.extend_from_slice(format!("3 {} {} {}\n", t[0], t[1], t[2]).as_bytes());
        }
    }
    out
}

/// The baked-file seeds: every .glb seed and two generated meshes, baked with the default config.
fn baked(corpus: &mut Corpus) -> anyhow::Result<()> {
    let mut inputs: Vec<(String, drafter_core::Scene)> = vec![
        ("generated:cylinder".into(), generate::cylinder(12, 2.0).to_scene("cylinder")),
        ("generated:open-box".into(), generate::open_box().to_scene("open-box")),
    ];
    for seed in corpus.of(Target::Glb).iter().filter(|s| s.name.starts_with("samples/")) {
        let imported = drafter_io::import_bytes(Path::new("seed.glb"), &seed.bytes)
            .with_context(|| format!("{}: a seed must import", seed.name))?;
        inputs.push((seed.name.clone(), imported.scene));
    }
    for (name, scene) in inputs {
        let baked = drafter_bake::bake(&scene, &drafter_bake::BakeConfig::default())
            .with_context(|| format!("{name}: a seed must bake"))?;
        // A baked sample is a glTF input as well, and one with what the samples lack: images
        // (the PNG lookups, in buffer views), textures and samplers, extensions.
        if name.starts_with("samples/") {
            if let Some(gltf) = glb_to_gltf(&baked.written.main) {
                corpus.add(Target::Gltf, format!("{name} (baked, as .gltf)"), gltf);
            }
            corpus.add(Target::Glb, format!("{name} (baked)"), baked.written.main.clone());
        }
        corpus.add(Target::Baked, format!("{name} (baked)"), baked.written.main);
    }
    Ok(())
}

/// A 1×1 PNG (the importer does not decode images; a real one keeps the seed a valid glTF).
const PNG: &[u8] = &[
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00, 0x00,
    0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00, 0x00, 0x1f, 0x15, 0xc4, 0x89, 0x00, 0x00, 0x00, 0x0d, 0x49,
    0x44, 0x41, 0x54, 0x78, 0xda, 0x63, 0xfc, 0xcf, 0xc0, 0xf0, 0x1f, 0x00, 0x05, 0x05, 0x02, 0x00, 0x5f, 0xc8, 0xf1,
    0xd2, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82,
];

/// A small glTF with every part of the format the gltf crate models and the samples do not have:
/// images by URI and by buffer view, textures, a sampler, a textured material with a
/// KHR_texture_transform, both camera types, a skin with its joint attributes, an animation, a
/// sparse accessor and strided data; as .gltf (data URIs) and as .glb.
fn features(corpus: &mut Corpus) {
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<serde_json::Value> = Vec::new();
    let mut view = |bin: &mut Vec<u8>, bytes: &[u8], stride: Option<usize>| -> usize {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let mut v = serde_json::json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()});
        if let Some(stride) = stride {
            v["byteStride"] = stride.into();
        }
        bin.extend_from_slice(bytes);
        views.push(v);
        views.len() - 1
    };
    let floats = |values: &[f32]| values.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>();
    // Positions and normals interleaved (stride 24).
    let quad = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let interleaved: Vec<f32> = quad.iter().flat_map(|p| [p[0], p[1], p[2], 0.0, 0.0, 1.0]).collect();
    let vertices = view(&mut bin, &floats(&interleaved), Some(24));
    let uvs = view(&mut bin, &floats(&[0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0]), None);
    let indices = view(&mut bin, &[0u16, 1, 2, 0, 2, 3].map(u16::to_le_bytes).concat(), None);
    let joints = view(&mut bin, &[0u8; 16], None);
    let weights = view(&mut bin, &floats(&[1.0, 0.0, 0.0, 0.0].repeat(4)), None);
    let identity = floats(&[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    let inverse_bind = view(&mut bin, &identity, None);
    let times = view(&mut bin, &floats(&[0.0, 1.0]), None);
    let translations = view(&mut bin, &floats(&[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]), None);
    let sparse_indices = view(&mut bin, &2u16.to_le_bytes(), None);
    let sparse_values = view(&mut bin, &floats(&[1.0, 1.0, 0.5]), None);
    let image = view(&mut bin, PNG, None);
    let doc = serde_json::json!({
        "asset": {"version": "2.0", "generator": "drafter-fuzz features seed"},
        "extensionsUsed": ["KHR_texture_transform"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "root", "children": [1, 2, 3, 4]},
            {"name": "skinned", "mesh": 0, "skin": 0},
            {"name": "eye", "camera": 0, "translation": [0.5, 0.5, 3.0]},
            {"name": "top", "camera": 1, "rotation": [-0.70710677, 0.0, 0.0, 0.70710677], "translation": [0.5, 3.0, 0.0]},
            {"name": "joint", "translation": [0.0, 0.0, 0.0]}
        ],
        "meshes": [{"name": "quad", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "JOINTS_0": 4, "WEIGHTS_0": 5},
             "indices": 3, "material": 0},
            {"attributes": {"POSITION": 9}, "mode": 4}
        ]}],
        "accessors": [
            {"bufferView": vertices, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": vertices, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": uvs, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": indices, "componentType": 5123, "count": 6, "type": "SCALAR"},
            {"bufferView": joints, "componentType": 5121, "count": 4, "type": "VEC4"},
            {"bufferView": weights, "componentType": 5126, "count": 4, "type": "VEC4"},
            {"bufferView": inverse_bind, "componentType": 5126, "count": 1, "type": "MAT4"},
            {"bufferView": times, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
            {"bufferView": translations, "componentType": 5126, "count": 2, "type": "VEC3"},
            {"bufferView": vertices, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0.5],
             "sparse": {"count": 1, "indices": {"bufferView": sparse_indices, "componentType": 5123},
                        "values": {"bufferView": sparse_values}}}
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
        "images": [
            {"name": "by uri", "uri": format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(PNG))},
            {"name": "by view", "bufferView": image, "mimeType": "image/png"}
        ],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 33648, "wrapT": 10497}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1}],
        "materials": [{
            "name": "textured",
            "pbrMetallicRoughness": {
                "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [2, 2]}}},
                "metallicRoughnessTexture": {"index": 1},
                "metallicFactor": 0.5
            },
            "normalTexture": {"index": 1, "scale": 0.5},
            "occlusionTexture": {"index": 0, "strength": 0.5},
            "emissiveTexture": {"index": 1},
            "emissiveFactor": [0.1, 0.1, 0.1],
            "alphaMode": "MASK",
            "alphaCutoff": 0.3,
            "doubleSided": true
        }],
        "cameras": [
            {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "zfar": 100, "aspectRatio": 1.5}},
            {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.01, "zfar": 10}}
        ],
        "skins": [{"joints": [4], "inverseBindMatrices": 6, "skeleton": 4}],
        "animations": [{
            "channels": [{"sampler": 0, "target": {"node": 4, "path": "translation"}}],
            "samplers": [{"input": 7, "output": 8, "interpolation": "LINEAR"}]
        }]
    });
    let json = serde_json::to_vec(&doc).unwrap_or_default();
    if let Ok(glb) = drafter_format::glb::write(&json, &bin) {
        if let Some(gltf) = glb_to_gltf(&glb) {
            corpus.add(Target::Gltf, "generated:features (as .gltf)", gltf);
        }
        corpus.add(Target::Glb, "generated:features", glb);
    }
}
