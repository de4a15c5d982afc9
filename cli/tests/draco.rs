//! `drafter bake` of the Draco-compressed Khronos samples in ../shared/models: each bakes
//! to the triangles of its uncompressed sibling (per mesh, every triangle matched with the same
//! winding and positions within the stream's quantization step), the same part structure (per
//! node, the parts' triangle counts), no trace of the extension, and a file the Khronos validator
//! passes with 0 errors and 0 warnings.

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// (JSON, binary chunk) of a baked .glb.
fn baked(path: &Path) -> (Value, Vec<u8>) {
    let bytes = std::fs::read(path).expect("baked file");
    let (json, bin) = drafter_format::split_container(&bytes).expect("container");
    (serde_json::from_slice(json).expect("json"), bin.expect("binary chunk").to_vec())
}

/// Accessor `a` of a baked file: float VEC3 positions or unsigned indices, as f32 rows.
fn read(doc: &Value, bin: &[u8], a: u64) -> Vec<[f32; 3]> {
    let acc = &doc["accessors"][a as usize];
    let view = &doc["bufferViews"][acc["bufferView"].as_u64().expect("view") as usize];
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    let count = acc["count"].as_u64().expect("count") as usize;
    match acc["componentType"].as_u64().expect("componentType") {
        5126 => {
            let stride = view["byteStride"].as_u64().map_or(12, |s| s as usize);
            (0..count)
                .map(|i| {
                    let at = start + i * stride;
                    std::array::from_fn(|k| {
                        f32::from_le_bytes(bin[at + 4 * k..at + 4 * k + 4].try_into().expect("4 bytes"))
                    })
                })
                .collect()
        }
        component => {
            let size = match component {
                5121 => 1,
                5123 => 2,
                _ => 4,
            };
            (0..count)
                .map(|i| {
                    let b = &bin[start + i * size..];
                    let v = match size {
                        1 => u32::from(b[0]),
                        2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    };
                    [v as f32, 0.0, 0.0]
                })
                .collect()
        }
    }
}

type Triangle = [[f32; 3]; 3];

/// Every mesh's triangles (its primitives concatenated), by glTF mesh index.
fn mesh_triangles(doc: &Value, bin: &[u8]) -> Vec<Vec<Triangle>> {
    doc["meshes"]
        .as_array()
        .expect("meshes")
        .iter()
        .map(|mesh| {
            let mut out = Vec::new();
            for prim in mesh["primitives"].as_array().expect("primitives") {
                let positions = read(doc, bin, prim["attributes"]["POSITION"].as_u64().expect("POSITION"));
                let indices = read(doc, bin, prim["indices"].as_u64().expect("indices"));
                out.extend(indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]].map(|i| positions[i[0] as usize])));
            }
            out
        })
        .collect()
}

/// How many of `got` have no twin in `want` (same winding, any first corner, each corner within
/// `tolerance` per axis); each twin is used once, the closest first.
fn unmatched(got: &[Triangle], want: &[Triangle], tolerance: f32) -> usize {
    let cell = 4.0 * tolerance;
    let key = |t: &Triangle| {
        std::array::from_fn::<i64, 3, _>(|k| ((t[0][k] + t[1][k] + t[2][k]) / 3.0 / cell).floor() as i64)
    };
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (i, t) in want.iter().enumerate() {
        grid.entry(key(t)).or_default().push(i);
    }
    let mut used = vec![false; want.len()];
    let mut missing = 0;
    for t in got {
        let k = key(t);
        // The closest unused twin (tiny triangles may lie within the tolerance of each other).
        let error = |i: usize| {
            (0..3)
                .map(|r| {
                    (0..3)
                        .flat_map(|c| (0..3).map(move |a| (c, a)))
                        .map(|(c, a)| (t[c][a] - want[i][(c + r) % 3][a]).abs())
                        .fold(0.0f32, f32::max)
                })
                .fold(f32::INFINITY, f32::min)
        };
        let twin = (0..27)
            .flat_map(|d| grid.get(&[k[0] + d % 3 - 1, k[1] + d / 3 % 3 - 1, k[2] + d / 9 - 1]).into_iter().flatten())
            .copied()
            .filter(|&i| !used[i])
            .map(|i| (i, error(i)))
            .filter(|&(_, e)| e <= tolerance)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i);
        match twin {
            Some(i) => used[i] = true,
            None => missing += 1,
        }
    }
    missing
}

/// The largest position quantization step over the Draco streams of `gltf` (read by the decoder).
fn largest_position_step(gltf: &Path) -> f32 {
    let doc: Value = serde_json::from_slice(&std::fs::read(gltf).expect("gltf")).expect("json");
    let bin = std::fs::read(gltf.with_extension("bin")).expect("bin");
    let mut step = 0.0f32;
    for mesh in doc["meshes"].as_array().expect("meshes") {
        for prim in mesh["primitives"].as_array().expect("primitives") {
            let ext = &prim["extensions"][drafter_format::draco::EXTENSION];
            let view = &doc["bufferViews"][ext["bufferView"].as_u64().expect("view") as usize];
            let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
            let stream = &bin[start..start + view["byteLength"].as_u64().expect("length") as usize];
            let id = ext["attributes"]["POSITION"].as_u64().expect("POSITION id");
            let q = drafter_format::draco::quantization(stream).expect("stream").into_iter().find(|q| q.id == id);
            step = step.max(q.expect("quantized positions").step);
        }
    }
    assert!(step > 0.0);
    step
}

/// Per node with parts: its parts' triangle counts, sorted.
fn part_structure(path: &Path) -> Vec<(u32, Vec<u32>)> {
    let bytes = std::fs::read(path).expect("baked");
    let file = drafter_format::read(&bytes, &drafter_format::external_buffers(path)).expect("reads back");
    file.nodes
        .iter()
        .map(|(node, ext)| {
            let mut counts: Vec<u32> = ext.parts.iter().map(|p| p.triangles).collect();
            counts.sort_unstable();
            (*node, counts)
        })
        .collect()
}

fn khronos_validate(files: &[PathBuf]) {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    assert!(
        repo.join("tools/validate-gltf/node_modules/gltf-validator").is_dir(),
        "the Khronos validator is not installed: run `npm ci --prefix tools/validate-gltf` (CI does)"
    );
    let out = Command::new("node")
        .arg(repo.join("tools/validate-gltf/validate.mjs"))
        .args(files)
        .output()
        .expect("node runs (is Node.js installed?)");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "validator failed:\n{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(stdout.matches(" 0 errors, 0 warnings").count(), files.len(), "{stdout}");
}

#[test]
fn draco_samples_bake_like_their_uncompressed_siblings_and_validate() {
    let dir = common::scratch("draco");
    let models = common::shared_models().join("gltf");
    let mut outputs = Vec::new();
    for (model, triangles, parts) in [("GearboxAssy", 409_264, 95), ("Buggy", 278_672, 190)] {
        let draco_input = models.join(model).join("draco").join(format!("{model}.gltf"));
        let plain_input = models.join(model).join(format!("{model}.gltf"));
        let (draco_out, plain_out) = (dir.join(format!("{model}-draco.glb")), dir.join(format!("{model}.glb")));
        common::bake(&draco_input, &draco_out, &[]);
        common::bake(&plain_input, &plain_out, &[]);

        let (draco_doc, draco_bin) = baked(&draco_out);
        let (plain_doc, plain_bin) = baked(&plain_out);
        let text = draco_doc.to_string();
        assert!(!text.contains(drafter_format::draco::EXTENSION), "{model}: the baked file still names the extension");
        let (got, want) = (mesh_triangles(&draco_doc, &draco_bin), mesh_triangles(&plain_doc, &plain_bin));
        assert_eq!(got.len(), want.len(), "{model}: meshes");
        assert_eq!(got.iter().map(Vec::len).sum::<usize>(), triangles, "{model}: triangles");
        let step = largest_position_step(&draco_input);
        for (m, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g.len(), w.len(), "{model} mesh {m}: triangles");
            assert_eq!(unmatched(g, w, step), 0, "{model} mesh {m}: triangles without a twin within {step}");
        }

        let (draco_parts, plain_parts) = (part_structure(&draco_out), part_structure(&plain_out));
        assert_eq!(draco_parts, plain_parts, "{model}: parts per node");
        let part_count: usize = draco_parts.iter().map(|(_, p)| p.len()).sum();
        assert!(part_count >= parts, "{model}: {part_count} parts for {parts} mesh nodes");
        outputs.push(draco_out);
    }
    khronos_validate(&outputs);
}
