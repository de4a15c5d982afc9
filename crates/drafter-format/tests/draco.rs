//! `KHR_draco_mesh_compression` decoding, checked against independent data:
//!
//! * the Khronos sample assets' Draco variants in ../shared/models against their uncompressed
//!   siblings: every primitive's triangles, matched with the same winding and positions within the
//!   stream's quantization step, and normals within the octahedral encoding's error;
//! * the fuzzer's Draco seed (fuzz/seeds/draco-cylinder.glb, Google's transcoder) against the
//!   cylinder it was made from (fuzz/seeds/draco-cylinder.py): positions, normals, texture
//!   coordinates and colors;
//! * hostile streams: every truncation and thousands of byte mutations of a real stream end in a
//!   value or an error, never a panic, and a stream whose counts differ from its accessors is
//!   refused before it is decoded.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use drafter_format::draco;
use serde_json::Value;

fn shared_models() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    assert!(dir.join("README.md").is_file(), "the shared models are missing at {}", dir.display());
    dir
}

/// A .gltf with its (external) buffers, in order.
fn load(path: &Path) -> (Vec<u8>, Vec<Vec<u8>>) {
    let json = std::fs::read(path).expect("gltf");
    let doc: Value = serde_json::from_slice(&json).expect("json");
    let buffers = doc["buffers"]
        .as_array()
        .expect("buffers")
        .iter()
        .map(|b| std::fs::read(path.with_file_name(b["uri"].as_str().expect("uri"))).expect("buffer"))
        .collect();
    (json, buffers)
}

/// The components of accessor `a` as f32 (float or unsigned integer types, not normalized).
fn read(doc: &Value, buffers: &[Vec<u8>], a: u64) -> Vec<Vec<f32>> {
    let acc = &doc["accessors"][a as usize];
    let view = &doc["bufferViews"][acc["bufferView"].as_u64().expect("bufferView") as usize];
    let buffer = &buffers[view["buffer"].as_u64().unwrap_or(0) as usize];
    let k = match acc["type"].as_str().expect("type") {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        _ => 4,
    };
    let component = acc["componentType"].as_u64().expect("componentType");
    let size = match component {
        5121 => 1,
        5123 => 2,
        _ => 4,
    };
    let stride = view["byteStride"].as_u64().map_or(size * k, |s| s as usize);
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    let count = acc["count"].as_u64().expect("count") as usize;
    assert!(start + stride * (count - 1) + size * k <= buffer.len(), "accessor {a} fits its buffer");
    (0..count)
        .map(|i| {
            (0..k)
                .map(|c| {
                    let b = &buffer[start + i * stride + c * size..];
                    match component {
                        5121 => f32::from(b[0]),
                        5123 => f32::from(u16::from_le_bytes([b[0], b[1]])),
                        5125 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
                        _ => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    }
                })
                .collect()
        })
        .collect()
}

/// One corner: position and normal.
type Corner = ([f32; 3], [f32; 3]);

fn triangles(doc: &Value, buffers: &[Vec<u8>], prim: &Value) -> Vec<[Corner; 3]> {
    let positions = read(doc, buffers, prim["attributes"]["POSITION"].as_u64().expect("POSITION"));
    let normals = read(doc, buffers, prim["attributes"]["NORMAL"].as_u64().expect("NORMAL"));
    let indices = read(doc, buffers, prim["indices"].as_u64().expect("indices"));
    let corner = |i: &Vec<f32>| {
        let i = i[0] as usize;
        let v = |x: &Vec<f32>| [x[0], x[1], x[2]];
        (v(&positions[i]), v(&normals[i]))
    };
    indices.chunks_exact(3).map(|t| [corner(&t[0]), corner(&t[1]), corner(&t[2])]).collect()
}

fn max_difference(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f32::max)
}

/// Checks that the accessors' `min`/`max` are their data's, as the validator does.
fn check_bounds(doc: &Value, buffers: &[Vec<u8>], a: u64) {
    let acc = &doc["accessors"][a as usize];
    let values = read(doc, buffers, a);
    for (key, pick) in [("min", f32::min as fn(f32, f32) -> f32), ("max", f32::max)] {
        let declared: Vec<f32> =
            acc[key].as_array().expect("bounds").iter().map(|v| v.as_f64().expect("number") as f32).collect();
        let actual: Vec<f32> =
            (0..declared.len()).map(|c| values.iter().map(|v| v[c]).reduce(pick).expect("values")).collect();
        assert_eq!(declared, actual, "accessor {a} {key}");
    }
}

fn compare_with_sibling(model: &str) -> (usize, usize, f32) {
    let models = shared_models().join("gltf").join(model);
    let (json, buffers) = load(&models.join("draco").join(format!("{model}.gltf")));
    let (plain_json, plain_buffers) = load(&models.join(format!("{model}.gltf")));
    let plain: Value = serde_json::from_slice(&plain_json).expect("plain json");
    let source: Value = serde_json::from_slice(&json).expect("draco json");
    let decoded = draco::decompress(&json, &buffers).expect("decodes").expect("uses Draco");
    let doc: Value = serde_json::from_str(&decoded.json).expect("decoded json");
    assert!(!decoded.json.contains(draco::EXTENSION), "{model}: the extension is gone");
    let mut all = buffers.clone();
    all.push(decoded.buffer.clone());
    assert_eq!(doc["buffers"].as_array().expect("buffers").len(), all.len());

    let (mut primitives, mut triangle_count, mut worst_normal) = (0, 0, 0.0f32);
    let meshes = doc["meshes"].as_array().expect("meshes");
    assert_eq!(meshes.len(), plain["meshes"].as_array().expect("meshes").len(), "{model}: meshes");
    for (m, mesh) in meshes.iter().enumerate() {
        for (p, prim) in mesh["primitives"].as_array().expect("primitives").iter().enumerate() {
            let place = format!("{model} mesh {m} primitive {p}");
            // The stream's position step, from the decoder's own header.
            let ext = &source["meshes"][m]["primitives"][p]["extensions"][draco::EXTENSION];
            let view = &source["bufferViews"][ext["bufferView"].as_u64().expect("view") as usize];
            let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
            let stream = &buffers[0][offset..offset + view["byteLength"].as_u64().expect("length") as usize];
            let position_id = ext["attributes"]["POSITION"].as_u64().expect("id");
            let step = draco::quantization(stream)
                .expect("quantization")
                .into_iter()
                .find(|q| q.id == position_id)
                .expect("quantized positions")
                .step;
            for a in [&prim["attributes"]["POSITION"], &prim["indices"]] {
                check_bounds(&doc, &all, a.as_u64().expect("accessor"));
            }

            let got = triangles(&doc, &all, prim);
            let want = triangles(&plain, &plain_buffers, &plain["meshes"][m]["primitives"][p]);
            assert_eq!(got.len(), want.len(), "{place}: triangles");
            // Each decoded triangle is a plain one (same winding, any first corner), matched once.
            let cell = 4.0 * step;
            let key = |t: &[Corner; 3]| {
                let c: [f32; 3] = std::array::from_fn(|k| (t[0].0[k] + t[1].0[k] + t[2].0[k]) / 3.0);
                c.map(|x| (x / cell).floor() as i64)
            };
            let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
            for (i, t) in want.iter().enumerate() {
                grid.entry(key(t)).or_default().push(i);
            }
            let mut used = vec![false; want.len()];
            for t in &got {
                let k = key(t);
                let mut best: Option<(usize, usize, f32)> = None;
                for d in 0..27 {
                    let near = [k[0] + d % 3 - 1, k[1] + d / 3 % 3 - 1, k[2] + d / 9 - 1];
                    for &i in grid.get(&near).into_iter().flatten() {
                        if used[i] {
                            continue;
                        }
                        for r in 0..3 {
                            let e = (0..3).map(|c| max_difference(t[c].0, want[i][(c + r) % 3].0)).fold(0.0, f32::max);
                            if best.is_none_or(|b| e < b.2) {
                                best = Some((i, r, e));
                            }
                        }
                    }
                }
                let Some((i, r, e)) = best else { panic!("{place}: a decoded triangle has no plain twin") };
                assert!(e <= step, "{place}: corner off by {e}, step {step}");
                used[i] = true;
                for c in 0..3 {
                    worst_normal = worst_normal.max(max_difference(t[c].1, want[i][(c + r) % 3].1));
                }
            }
            primitives += 1;
            triangle_count += got.len();
        }
    }
    (primitives, triangle_count, worst_normal)
}

#[test]
fn sample_assets_decode_to_their_uncompressed_siblings() {
    for (model, primitives, triangles) in [("GearboxAssy", 42, 409_264), ("Buggy", 148, 278_672)] {
        let (p, t, normal) = compare_with_sibling(model);
        assert_eq!((p, t), (primitives, triangles), "{model}");
        // The sample normals are 8-bit octahedral; a component's error stays far below 0.02.
        assert!(normal < 0.02, "{model}: a normal differs by {normal}");
    }
}

fn seed() -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/draco-cylinder.glb")).expect("seed")
}

/// The seed GLB as (JSON, buffers).
fn seed_parts() -> (Vec<u8>, Vec<Vec<u8>>) {
    let bytes = seed();
    let chunks = drafter_format::glb::split(&bytes).expect("glb");
    (chunks.json.to_vec(), vec![chunks.bin.expect("bin").to_vec()])
}

#[test]
fn the_seed_decodes_to_the_cylinder_it_was_made_from() {
    let (json, buffers) = seed_parts();
    let decoded = draco::decompress(&json, &buffers).expect("decodes").expect("uses Draco");
    assert_eq!((decoded.primitives, decoded.triangles), (1, 48));
    let doc: Value = serde_json::from_str(&decoded.json).expect("json");
    assert!(doc.get("extensionsRequired").is_none() && doc.get("extensionsUsed").is_none());
    let mut all = buffers.clone();
    all.push(decoded.buffer);
    let prim = &doc["meshes"][0]["primitives"][0];
    let attribute = |name: &str| read(&doc, &all, prim["attributes"][name].as_u64().expect(name));
    let (positions, normals, uvs, colors) =
        (attribute("POSITION"), attribute("NORMAL"), attribute("TEXCOORD_0"), attribute("COLOR_0"));
    assert_eq!(positions.len(), 52);
    // Quantization steps: positions 11 bits over 2 units, texture coordinates 10 bits over 1, colors
    // 8 bits over 1; normals 8-bit octahedral.
    let (p_step, t_step, c_step) = (2.0 / 2047.0, 1.0 / 1023.0, 1.0 / 255.0);
    for i in 0..positions.len() {
        let (p, n, t, c) = (&positions[i], &normals[i], &uvs[i], &colors[i]);
        let radius = p[0].hypot(p[1]);
        let on_cap = p[2].abs() <= p_step || (p[2] - 2.0).abs() <= p_step;
        assert!((radius - 1.0).abs() <= 2.0 * p_step || (on_cap && radius <= 2.0 * p_step), "point {i}: {p:?}");
        let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((length - 1.0).abs() < 1e-3, "normal {i}: {n:?}");
        // The generator's rules: side normals are radial, cap normals axial; colors are (u, v, ½, 1).
        let expected = if n[2].abs() > 0.5 { [0.0, 0.0, n[2].signum()] } else { [p[0], p[1], 0.0] };
        assert!(max_difference([n[0], n[1], n[2]], expected) < 0.03, "normal {i}: {n:?} for {p:?}");
        assert!((0.0..=1.0 + t_step).contains(&t[0]) && (0.0..=1.0 + t_step).contains(&t[1]), "uv {i}: {t:?}");
        for (k, want) in [(0, t[0]), (1, t[1]), (2, 0.5), (3, 1.0)] {
            assert!((c[k] - want).abs() <= c_step + t_step, "color {i}: {c:?} for uv {t:?}");
        }
    }
    let indices = read(&doc, &all, prim["indices"].as_u64().expect("indices"));
    assert_eq!(indices.len(), 144);
    assert!(indices.iter().all(|i| (i[0] as usize) < positions.len()));
    for a in ["POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0"] {
        check_bounds(&doc, &all, prim["attributes"][a].as_u64().expect(a));
    }
}

#[test]
fn hostile_streams_end_in_an_error_never_a_panic() {
    let (json, buffers) = seed_parts();
    let doc: Value = serde_json::from_slice(&json).expect("json");
    let view = &doc["bufferViews"][0];
    let (start, length) =
        (view["byteOffset"].as_u64().unwrap_or(0) as usize, view["byteLength"].as_u64().expect("len") as usize);
    // Every truncation of the stream (the view's length shortened).
    for cut in 0..length {
        let mut shorter = doc.clone();
        shorter["bufferViews"][0]["byteLength"] = cut.into();
        let text = serde_json::to_vec(&shorter).expect("json");
        let _ = draco::decompress(&text, &buffers);
    }
    // Byte mutations of the stream, deterministic.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let (mut decoded, mut refused) = (0, 0);
    for _ in 0..3000 {
        let mut bin = buffers[0].clone();
        for _ in 0..1 + next() % 4 {
            let at = start + (next() as usize) % length;
            bin[at] = match next() % 3 {
                0 => bin[at] ^ (1 << (next() % 8)),
                1 => next() as u8,
                _ => [0, 0xff, 0x7f, 0x80][(next() % 4) as usize],
            };
        }
        match draco::decompress(&json, &[bin]) {
            Ok(_) => decoded += 1,
            Err(_) => refused += 1,
        }
    }
    assert!(decoded > 0 && refused > 0, "{decoded} decoded, {refused} refused");
}

#[test]
fn counts_other_than_the_accessors_are_refused_before_decoding() {
    let (json, buffers) = seed_parts();
    let mut doc: Value = serde_json::from_slice(&json).expect("json");
    doc["accessors"][0]["count"] = 3_000_000_000u64.into();
    let error = draco::decompress(&serde_json::to_vec(&doc).expect("json"), &buffers).expect_err("refused");
    assert!(error.message.contains("declares 48 faces"), "{error}");
    assert_eq!(error.place, format!("/meshes/0/primitives/0/extensions/{}", draco::EXTENSION));

    // A view outside its buffer, and an attribute id the stream does not have.
    let mut doc: Value = serde_json::from_slice(&json).expect("json");
    doc["bufferViews"][0]["byteOffset"] = u64::MAX.into();
    assert!(draco::decompress(&serde_json::to_vec(&doc).expect("json"), &buffers).is_err());
    let mut doc: Value = serde_json::from_slice(&json).expect("json");
    doc["meshes"][0]["primitives"][0]["extensions"][draco::EXTENSION]["attributes"]["POSITION"] = 9.into();
    let error = draco::decompress(&serde_json::to_vec(&doc).expect("json"), &buffers).expect_err("refused");
    assert!(error.message.contains("no attribute 9"), "{error}");
    // No extension: nothing to do.
    assert_eq!(draco::decompress(br#"{"asset":{"version":"2.0"}}"#, &[]), Ok(None));
}

#[test]
fn preflight_reads_the_counts_without_decoding() {
    let (json, buffers) = seed_parts();
    let doc: Value = serde_json::from_slice(&json).expect("json");
    let view = &doc["bufferViews"][0];
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let stream = &buffers[0][start..start + view["byteLength"].as_u64().expect("len") as usize];
    let counts = draco::preflight(stream).expect("counts");
    assert_eq!(counts.faces, 48);
    assert!(counts.vertices <= 52, "{counts:?}");
    assert!(draco::preflight(b"DRACO").is_err());
    assert!(
        draco::preflight(b"DRACO\x02\x02\x01\x01\x00\x00\x00\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\x7f").is_err()
    );
}
