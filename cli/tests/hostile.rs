//! Hostile inputs: each must exit 2 with one line on stderr that names the file and the problem,
//! without a panic, with peak memory (the child's max RSS, from wait4) under 100 MB.
#![allow(unsafe_code)] // wait4 is the only way to read one child's peak RSS.

mod common;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Stdio;

use base64::Engine as _;

const PEAK_LIMIT_KB: i64 = 100 * 1024;

struct Outcome {
    code: i32,
    stderr: String,
    stdout: String,
    peak_kb: i64,
}

#[allow(clippy::zombie_processes)] // reaped by wait4 below, which std cannot see
fn inspect(file: &Path, extra: &[&str]) -> Outcome {
    let mut child = common::drafter()
        .arg("inspect")
        .args(extra)
        .arg(file)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn drafter");
    let mut stdout = String::new();
    let mut stderr = String::new();
    let mut out_pipe = child.stdout.take().expect("stdout");
    let mut err_pipe = child.stderr.take().expect("stderr");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        out_pipe.read_to_string(&mut s).expect("read stdout");
        s
    });
    err_pipe.read_to_string(&mut stderr).expect("read stderr");
    stdout.push_str(&reader.join().expect("stdout thread"));
    let mut status = 0;
    // SAFETY: plain FFI call on our own child's pid with valid out-pointers.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = child.id() as libc::pid_t;
    let waited = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(waited, pid, "wait4 failed");
    let code = if libc::WIFEXITED(status) { libc::WEXITSTATUS(status) } else { -libc::WTERMSIG(status) };
    Outcome { code, stderr, stdout, peak_kb: usage.ru_maxrss }
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write input");
    p
}

/// Runs `drafter inspect` on `file` and checks the contract for bad input; `needle` must appear in
/// the message.
#[track_caller]
fn assert_rejected(file: &Path, needle: &str) {
    let o = inspect(file, &[]);
    let name = file.file_name().expect("name").to_string_lossy().into_owned();
    assert_eq!(o.code, 2, "{name}: exit {} (stderr: {})", o.code, o.stderr);
    let lines: Vec<&str> = o.stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{name}: stderr must be one line: {:?}", o.stderr);
    assert!(lines[0].contains(&name), "{name}: message does not name the file: {}", lines[0]);
    assert!(lines[0].to_lowercase().contains(&needle.to_lowercase()), "{name}: message lacks {needle:?}: {}", lines[0]);
    assert!(o.peak_kb < PEAK_LIMIT_KB, "{name}: peak RSS {} KB", o.peak_kb);
    assert!(o.stdout.is_empty(), "{name}: wrote to stdout on failure");
}

fn binary_stl(claimed: u32, facets: usize, first_vertex: [f32; 3]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b[..5].copy_from_slice(b"solid");
    b.extend_from_slice(&claimed.to_le_bytes());
    for _ in 0..facets {
        b.extend_from_slice(&[0u8; 12]);
        for v in [first_vertex, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for c in v {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

#[test]
fn the_valid_baselines_import() {
    let dir = common::scratch("hostile-baseline");
    for (name, bytes) in [
        ("ok.gltf", common::gltf_triangle(|_| {})),
        ("ok.stl", binary_stl(2, 2, [0.0; 3])),
        ("ok.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec()),
    ] {
        let o = inspect(&write(&dir, name, &bytes), &[]);
        assert_eq!(o.code, 0, "{name}: {}", o.stderr);
    }
}

/// A weld tolerance that is not a fraction in [0, 1] is refused, not read as "weld nothing" (NaN,
/// infinity) or "weld everything" (negative).
#[test]
fn nonsense_weld_tolerances_are_refused() {
    let dir = common::scratch("hostile-weld");
    let file = write(&dir, "ok.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    for value in ["-1", "nan", "inf", "2"] {
        let o = inspect(&file, &[&format!("--weld-tolerance={value}")]);
        assert_eq!(o.code, 2, "{value}: {}", o.stderr);
        assert!(o.stderr.lines().count() == 1 && o.stderr.contains("--weld-tolerance"), "{value}: {}", o.stderr);
    }
    assert_eq!(inspect(&file, &["--weld-tolerance=1e-6"]).code, 0);
}

#[test]
fn empty_files() {
    let dir = common::scratch("hostile-empty");
    for name in ["empty.gltf", "empty.glb", "empty.obj", "empty.stl", "empty.off", "empty.ply", "empty"] {
        assert_rejected(&write(&dir, name, b""), "empty");
    }
}

#[test]
fn unknown_format_lists_the_supported_ones() {
    let dir = common::scratch("hostile-unknown");
    assert_rejected(&write(&dir, "model.xyz", b"\x00\x01garbage"), "supported: glTF");
}

#[test]
fn truncated_files() {
    let dir = common::scratch("hostile-truncated");
    let gltf = common::gltf_triangle(|_| {});
    assert_rejected(&write(&dir, "cut.gltf", &gltf[..gltf.len() / 2]), "line");
    // A GLB whose header claims more bytes than the file has: a valid container (drafter-core's
    // writer) with its total length field overwritten.
    let mut glb = drafter_format::glb::write(b"{}", &[0u8; 8]).expect("glb");
    glb[8..12].copy_from_slice(&1_000_000u32.to_le_bytes());
    assert_rejected(&write(&dir, "cut.glb", &glb), "GLB");
    assert_rejected(&write(&dir, "cut.off", b"OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n"), "line");
    assert_rejected(&write(&dir, "cut.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n"), "line");
    assert_rejected(
        &write(&dir, "cut.stl", b"solid cut\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"),
        "line",
    );
}

#[test]
fn headers_claiming_more_than_the_file_holds() {
    let dir = common::scratch("hostile-claims");
    // Binary STL: header says 4 billion triangles, 2 present. Must not allocate 200 GB.
    let mut stl = binary_stl(u32::MAX, 2, [0.0; 3]);
    stl[..5].copy_from_slice(b"\x00\x00\x00\x00\x00");
    assert_rejected(&write(&dir, "liar.stl", &stl), "triangles");
    assert_rejected(&write(&dir, "liar.off", b"OFF\n4000000000 4000000000 0\n0 0 0\n"), "line");
    assert_rejected(
        &write(&dir, "liar.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00\x00\x00"),
        "byte",
    );
    assert_rejected(
        &write(&dir, "liar.gltf", &common::gltf_triangle(|j| j["accessors"][0]["count"] = 1_000_000_000.into())),
        "/accessors/0",
    );
    assert_rejected(
        &write(&dir, "liar-buffer.gltf", &common::gltf_triangle(|j| j["buffers"][0]["byteLength"] = 1_000_000.into())),
        "/buffers/0",
    );
    assert_rejected(
        &write(
            &dir,
            "liar-view.gltf",
            &common::gltf_triangle(|j| j["bufferViews"][0]["byteOffset"] = 4_000_000_000u64.into()),
        ),
        "/bufferViews/0",
    );
}

/// One 10,000-triangle strip listed in 2,001 primitives: 20,010,000 triangles from a 288 KB file,
/// over the default limit of 20 million. Refused from the accessors' counts, before any triangle
/// is built (a 4.7 MB file listing 200 million built 2.8 GB before the process aborted under a
/// 4 GB limit); `bake` writes nothing. Raising the limit is what the message says to do.
#[test]
fn geometry_listed_again_and_again_is_refused_before_it_is_built() {
    let dir = common::scratch("hostile-listed-again");
    // The one-triangle file, its indices a strip of 10,002 (cycling over its three vertices).
    let strip: Vec<u8> = (0..10_002u16).flat_map(|i| (i % 3).to_le_bytes()).collect();
    let doc = common::gltf_triangle(|j| {
        let mut bin = base64::engine::general_purpose::STANDARD
            .decode(j["buffers"][0]["uri"].as_str().expect("uri").split_once(',').expect("data URI").1)
            .expect("base64");
        bin.truncate(36);
        bin.extend_from_slice(&strip);
        let uri = base64::engine::general_purpose::STANDARD.encode(&bin);
        j["buffers"][0] =
            serde_json::json!({"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{uri}")});
        j["bufferViews"][1]["byteLength"] = strip.len().into();
        j["accessors"][1]["count"] = 10_002.into();
        let primitive = serde_json::json!({"attributes": {"POSITION": 0}, "indices": 1, "mode": 5});
        j["meshes"][0]["primitives"] = serde_json::Value::Array(vec![primitive; 2001]);
    });
    let file = write(&dir, "listed-again.gltf", &doc);
    assert_rejected(
        &file,
        "/meshes/0/primitives/2000: the meshes list 20,010,000 triangles up to here, more than the limit of 20,000,000 (--max-triangles",
    );
    let out = dir.join("listed-again.baked.glb");
    let o = common::run(&["bake", &file.to_string_lossy(), "-o", &out.to_string_lossy()]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.exists(), "no output for a refused input");
    // A lower limit refuses earlier; `inspect` takes the flag too.
    let o = inspect(&file, &["--max-triangles", "25000"]);
    assert_eq!(o.code, 2);
    assert!(o.stderr.contains("/meshes/0/primitives/2: the meshes list 30,000 triangles"), "{}", o.stderr);
}

#[test]
fn out_of_range_indices() {
    let dir = common::scratch("hostile-indices");
    let mut bad_index = common::gltf_triangle(|_| {});
    // Rewrite the index buffer (inside the data URI) so it points at vertex 7.
    let text = String::from_utf8(bad_index.clone()).expect("utf8");
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let uri = json["buffers"][0]["uri"].as_str().expect("uri");
    let mut bin =
        base64::engine::general_purpose::STANDARD.decode(&uri[uri.find(',').expect("comma") + 1..]).expect("b64");
    bin[38..40].copy_from_slice(&7u16.to_le_bytes());
    bad_index = common::gltf_triangle(|j| {
        j["buffers"][0]["uri"] =
            format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin))
                .into()
    });
    assert_rejected(&write(&dir, "index.gltf", &bad_index), "out of range");
    assert_rejected(&write(&dir, "index.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), "line 4");
    assert_rejected(&write(&dir, "index.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"), "line");
    assert_rejected(&write(&dir, "index.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), "line");
    assert_rejected(
        &write(&dir, "node.gltf", &common::gltf_triangle(|j| j["nodes"][0]["mesh"] = 5.into())),
        "/nodes/0/mesh",
    );
    // gltf-json 1.4 indexes a POSITION accessor unchecked while validating: it must be refused
    // before that (it was a panic in the dependency and exit 1).
    let position = common::gltf_triangle(|j| j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 5.into());
    assert_rejected(&write(&dir, "position.gltf", &position), "/meshes/0/primitives/0/attributes/POSITION");
    let huge = common::gltf_triangle(|j| j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = u32::MAX.into());
    assert_rejected(&write(&dir, "position-huge.gltf", &huge), "does not exist");
}

#[test]
fn non_finite_positions_drop_faces_or_fail_when_nothing_is_left() {
    let dir = common::scratch("hostile-nan");
    // Every facet uses a NaN vertex: nothing drawable is left.
    assert_rejected(&write(&dir, "allnan.stl", &binary_stl(3, 3, [f32::NAN, 0.0, 0.0])), "finite");
    // Some faces use one: they are dropped with a diagnostic; --strict turns that into bad input.
    let file = write(&dir, "somenan.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv inf 0 0\nf 1 2 3\nf 1 2 4\n");
    let o = inspect(&file, &["--json"]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    let json: serde_json::Value = serde_json::from_str(&o.stdout).expect("json");
    assert_eq!(json["triangles"], 1);
    let kinds: Vec<&str> =
        json["diagnostics"].as_array().expect("list").iter().filter_map(|d| d["kind"].as_str()).collect();
    assert!(kinds.contains(&"dropped_face"), "{kinds:?}");
    let strict = inspect(&file, &["--strict"]);
    assert_eq!(strict.code, 2);
}

#[test]
fn uris_outside_the_folder_are_refused() {
    let dir = common::scratch("hostile-uri");
    std::fs::write(dir.join("../outside.bin"), vec![0u8; 64]).expect("write");
    for (name, uri) in [
        ("dotdot.gltf", "../outside.bin"),
        ("absolute.gltf", "/etc/hostname"),
        ("scheme.gltf", "http://example.invalid/x.bin"),
        ("file.gltf", "file:///etc/hostname"),
    ] {
        let bytes = common::gltf_triangle(|j| j["buffers"][0]["uri"] = uri.into());
        assert_rejected(&write(&dir, name, &bytes), "/buffers/0");
    }
    // The folder itself is not a file, and the message says so.
    let bytes = common::gltf_triangle(|j| j["buffers"][0]["uri"] = ".".into());
    assert_rejected(&write(&dir, "dot.gltf", &bytes), "names a folder");
}

#[test]
fn required_extensions_we_cannot_decode_are_named() {
    let dir = common::scratch("hostile-ext");
    let bytes = common::gltf_triangle(|j| {
        j["extensionsUsed"] = serde_json::json!(["EXT_meshopt_compression"]);
        j["extensionsRequired"] = serde_json::json!(["EXT_meshopt_compression"]);
    });
    assert_rejected(&write(&dir, "meshopt.gltf", &bytes), "EXT_meshopt_compression");
}

#[test]
fn malformed_json_names_the_line() {
    let dir = common::scratch("hostile-json");
    assert_rejected(
        &write(&dir, "bad.gltf", b"{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [,]\n}\n"),
        "line 3",
    );
    assert_rejected(
        &write(&dir, "wrongtype.gltf", &common::gltf_triangle(|j| j["accessors"][0]["type"] = "VEC9".into())),
        "/accessors/0",
    );
    // An image `{}` made the gltf crate panic (gltf-1.4.1 src/image.rs:128), exit 1.
    let empty_image = common::gltf_triangle(|j| j["images"] = serde_json::json!([{"uri": "x.png"}, {}]));
    assert_rejected(&write(&dir, "image.gltf", &empty_image), "/images/1: an image needs a uri or a bufferView");
}

/// Inputs `inspect` accepts never end a bake with "internal error" (exit 1): a node whose mesh has
/// only line primitives bakes (its part is the node's origin); JSON the writer cannot carry over (a
/// number beyond f64 in `extras`, nesting deeper than serde_json's limit) is refused as bad input.
#[test]
fn accepted_inputs_bake_or_are_refused_as_input() {
    let dir = common::scratch("hostile-accepted");
    let bake = |name: &str, bytes: Vec<u8>| {
        let input = write(&dir, name, &bytes);
        let out = common::drafter()
            .arg("bake")
            .arg(&input)
            .arg("-o")
            .arg(dir.join(format!("{name}.glb")))
            .arg("--quiet")
            .output()
            .expect("runs");
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let lines_node = common::gltf_triangle(|j| {
        j["meshes"].as_array_mut().expect("meshes").push(serde_json::json!({
            "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 1}]
        }));
        j["nodes"].as_array_mut().expect("nodes").push(serde_json::json!({"mesh": 1}));
        j["scenes"][0]["nodes"] = serde_json::json!([0, 1]);
    });
    let (code, stderr) = bake("lines.gltf", lines_node);
    assert_eq!(code, Some(0), "{stderr}");

    let huge_number = String::from_utf8(common::gltf_triangle(|j| j["extras"] = serde_json::json!({"n": 1.0})))
        .expect("utf-8")
        .replace("\"n\": 1.0", "\"n\": 1e309");
    let mut deep = serde_json::json!(0);
    for _ in 0..200 {
        deep = serde_json::json!({ "a": deep });
    }
    for (name, bytes) in [
        ("number.gltf", huge_number.into_bytes()),
        ("deep.gltf", common::gltf_triangle(|j| j["extras"] = deep.clone())),
    ] {
        let (code, stderr) = bake(name, bytes);
        assert_eq!(code, Some(2), "{name}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{name}: {stderr}");
        assert!(stderr.contains(name), "{name}: {stderr}");
    }
}
