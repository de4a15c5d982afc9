//! ARCHITECTURE.md against the code: the code map names every workspace member and only paths that
//! exist, the renderer's pass order is the order it encodes its passes, and the bake's stage order
//! is `drafter_bake::STAGE_NAMES`. Each test reads the document and the code as they are, so a
//! change to either that makes the document untrue fails here. And the crate graph's arrows, read
//! from every member's Cargo.toml and, past the workspace, from Cargo.lock: stage crates depend on
//! drafter-core only; the CPU scene and the drawings reach no GPU or window crate; the renderer
//! (drafter-render) and the browser build (drafter-web) reach no window crate; only the desktop app
//! (drafter-app) and the CLI may name a window crate.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use drafter_render::renderer::PASS_ORDER;

/// The renderer's crate folder.
const RENDER: &str = "crates/drafter-render";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("cli/ has a parent").to_path_buf()
}

fn read(relative: &str) -> String {
    let path = root().join(relative);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

/// The text of the `## ` section whose heading starts with `heading`, up to the next `## `.
fn section<'a>(doc: &'a str, heading: &str) -> &'a str {
    let start = doc
        .lines()
        .scan(0, |offset, line| {
            let here = *offset;
            *offset += line.len() + 1;
            Some((here, line))
        })
        .find(|(_, line)| line.starts_with("## ") && line[3..].starts_with(heading))
        .map(|(offset, _)| offset)
        .unwrap_or_else(|| panic!("ARCHITECTURE.md has no section \"## {heading}\""));
    let body = &doc[start..];
    let end = body[3..].find("\n## ").map_or(body.len(), |i| i + 4);
    &body[..end]
}

/// The backticked spans of `text`, in order.
fn backticked(text: &str) -> Vec<&str> {
    text.split('`').skip(1).step_by(2).collect()
}

/// The paths of the workspace members, the globs of `[workspace] members` expanded (only a
/// trailing `/*` is supported, which is what the manifest uses; anything else fails the test).
fn workspace_members() -> Vec<String> {
    let manifest = read("Cargo.toml");
    let workspace = &manifest[manifest.find("[workspace]").expect("a [workspace] table")..];
    let members = &workspace[workspace.find("members").expect("workspace members")..];
    let list = &members[members.find('[').expect("members is an array") + 1..];
    let list = &list[..list.find(']').expect("members array closes")];
    let mut paths = Vec::new();
    for entry in list.split('"').skip(1).step_by(2) {
        if let Some(folder) = entry.strip_suffix("/*") {
            assert!(!folder.contains(['*', '?', '[']), "unsupported member glob {entry}");
            let mut found: Vec<String> = std::fs::read_dir(root().join(folder))
                .unwrap_or_else(|e| panic!("member glob {entry}: {e}"))
                .map(|e| e.expect("a directory entry").path())
                .filter(|p| p.join("Cargo.toml").is_file())
                .map(|p| {
                    format!("{folder}/{}", p.file_name().and_then(|n| n.to_str()).expect("a UTF-8 crate folder name"))
                })
                .collect();
            found.sort();
            assert!(!found.is_empty(), "member glob {entry} matches no crate");
            paths.extend(found);
        } else {
            assert!(!entry.contains(['*', '?', '[']), "unsupported member glob {entry}");
            paths.push(entry.to_string());
        }
    }
    assert!(paths.len() >= 5, "too few workspace members parsed: {paths:?}");
    paths
}

/// The first cells of the code map's rows: the paths it describes, without a trailing `/`.
fn code_map_paths(doc: &str) -> Vec<String> {
    let paths: Vec<String> = section(doc, "Code map")
        .lines()
        .filter(|line| line.starts_with("| `"))
        .map(|line| backticked(line)[0].trim_end_matches('/').to_string())
        .collect();
    assert!(paths.len() >= 5, "too few code map rows parsed: {paths:?}");
    paths
}

#[test]
fn code_map_lists_every_workspace_member_and_only_paths_that_exist() {
    let doc = read("ARCHITECTURE.md");
    let listed = code_map_paths(&doc);
    let listed_set: BTreeSet<&str> = listed.iter().map(String::as_str).collect();
    let missing: Vec<String> = workspace_members().into_iter().filter(|m| !listed_set.contains(m.as_str())).collect();
    assert!(missing.is_empty(), "workspace members missing from ARCHITECTURE.md's code map: {missing:?}");
    let absent: Vec<&String> = listed.iter().filter(|p| !root().join(p).exists()).collect();
    assert!(absent.is_empty(), "ARCHITECTURE.md's code map lists paths that do not exist: {absent:?}");
    let members: BTreeSet<String> = workspace_members().into_iter().collect();
    let stray: Vec<&String> =
        listed.iter().filter(|p| p.starts_with("crates/") && !members.contains(p.as_str())).collect();
    assert!(stray.is_empty(), "code map rows under crates/ that are not workspace members: {stray:?}");
}

/// The passes as `Renderer::encode_frame` records them: the `.encode(` calls of the renderer's
/// `encode_*` steps that it calls, in its order. `Renderer::submit_frame` (the page's frames) must
/// call the same steps in the same order.
fn encoded_passes() -> Vec<String> {
    let source = read(&format!("{RENDER}/src/renderer.rs"));
    let body_of = |signature: &str| {
        let start = source.find(signature).unwrap_or_else(|| panic!("{signature} in the renderer's renderer.rs"));
        let body = &source[start..];
        body[..body.find("\n    }\n").unwrap_or_else(|| panic!("the end of {signature}"))].to_string()
    };
    // The `self.encode_*(` steps a frame function calls, in order.
    let steps = |body: &str| -> Vec<String> {
        body.match_indices("self.encode_")
            .map(|(i, _)| {
                let name = &body[i + "self.".len()..];
                name[..name.find('(').expect("a call")].to_string()
            })
            .collect()
    };
    let frame = steps(&body_of("pub fn encode_frame("));
    assert!(!frame.is_empty(), "encode_frame calls no encode_* step");
    assert_eq!(steps(&body_of("pub fn submit_frame(")), frame, "submit_frame and encode_frame record different steps");
    let mut passes = Vec::new();
    for step in &frame {
        let body = body_of(&format!("fn {step}("));
        for (i, _) in body.match_indices(".encode(") {
            let before = &body[..i];
            let name_start = before.rfind(|c: char| !(c.is_alphanumeric() || c == '_')).map_or(0, |j| j + 1);
            let receiver = &before[..name_start];
            assert!(receiver.ends_with("self."), "{step} calls encode on something other than a pass field");
            passes.push(before[name_start..].to_string());
        }
    }
    passes
}

#[test]
fn the_renderer_encodes_its_passes_in_pass_order() {
    assert_eq!(encoded_passes(), PASS_ORDER, "Renderer::encode_frame and renderer::PASS_ORDER disagree");
    let mut modules: Vec<String> = std::fs::read_dir(root().join(RENDER).join("src/passes"))
        .expect("the renderer's src/passes")
        .map(|e| e.expect("a directory entry").file_name().into_string().expect("a UTF-8 file name"))
        .filter_map(|name| name.strip_suffix(".rs").map(str::to_string))
        .filter(|name| name != "mod")
        .collect();
    modules.sort();
    let mut order: Vec<String> = PASS_ORDER.iter().map(|s| s.to_string()).collect();
    order.sort();
    assert_eq!(modules, order, "a module under {RENDER}/src/passes/ that PASS_ORDER does not name, or the reverse");
}

#[test]
fn architecture_states_the_renderers_pass_order() {
    let doc = read("ARCHITECTURE.md");
    // The numbered list of "The renderer's passes", each item naming its module's file.
    let passes = format!("`{RENDER}/src/passes/");
    let listed: Vec<&str> = section(&doc, "The renderer's passes")
        .lines()
        .filter(|line| {
            line.split_once(". ").is_some_and(|(n, _)| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
        })
        .map(|line| {
            let file = line.split(passes.as_str()).nth(1).unwrap_or_else(|| panic!("no pass file in {line:?}"));
            &file[..file.find(".rs`").unwrap_or_else(|| panic!("no pass file in {line:?}"))]
        })
        .collect();
    assert_eq!(listed, PASS_ORDER, "the numbered passes of ARCHITECTURE.md's \"The renderer's passes\"");
    // The code map's renderer row names them in the same order.
    let row = section(&doc, "Code map")
        .lines()
        .find(|line| line.starts_with(&format!("| `{RENDER}`")))
        .unwrap_or_else(|| panic!("the code map's {RENDER} row"));
    let named: Vec<&str> = backticked(row).into_iter().filter(|span| PASS_ORDER.contains(span)).collect();
    assert_eq!(named, PASS_ORDER, "the passes as the code map's {RENDER} row names them");
}

#[test]
fn architecture_states_the_bakes_stage_order() {
    let doc = read("ARCHITECTURE.md");
    let stages: Vec<&str> = drafter_bake::STAGE_NAMES.iter().copied().filter(|&name| name != "done").collect();
    assert!(stages.len() >= 5, "STAGE_NAMES: {:?}", drafter_bake::STAGE_NAMES);
    let paragraphs: Vec<String> =
        doc.split("\n\n").map(|p| p.split_whitespace().collect::<Vec<_>>().join(" ")).collect();
    // The summary: the backticked names after its colon.
    let summary = paragraphs
        .iter()
        .find(|p| p.contains("`drafter_bake::STAGE_NAMES`"))
        .expect("a paragraph naming drafter_bake::STAGE_NAMES");
    let after = &summary[summary.find("): ").expect("the list after the colon") + 3..];
    let named: Vec<&str> = backticked(after).into_iter().collect();
    assert_eq!(named, stages, "the stage names ARCHITECTURE.md lists");
    // The detailed order: the word after each arrow, or after "beside" (bounds beside normals).
    let detail = paragraphs
        .iter()
        .find(|p| p.starts_with("Stage order of a bake"))
        .expect("the paragraph \"Stage order of a bake\"");
    let mut named = Vec::new();
    for marker in ["→ ", "beside "] {
        for (i, _) in detail.match_indices(marker) {
            let word: String = detail[i + marker.len()..].chars().take_while(|c| c.is_alphanumeric()).collect();
            if stages.contains(&word.as_str()) {
                named.push((i, word));
            }
        }
    }
    named.sort();
    let named: Vec<String> = named.into_iter().map(|(_, w)| w).collect();
    assert_eq!(named, stages, "the stage order of ARCHITECTURE.md's \"Stage order of a bake\"");
}

/// A workspace member's manifest: its package name and the crates it names, by kind.
#[derive(Debug)]
struct Manifest {
    path: String,
    /// `[dependencies]` and `[build-dependencies]`, target-specific and optional ones included.
    normal: BTreeSet<String>,
    /// `[dev-dependencies]`, target-specific ones included.
    dev: BTreeSet<String>,
}

/// The names of a dependency table.
fn dependency_names(table: Option<&toml::Value>) -> Vec<String> {
    let Some(table) = table.and_then(toml::Value::as_table) else { return Vec::new() };
    table
        .iter()
        // `foo = { package = "bar" }` depends on bar.
        .map(|(key, spec)| spec.get("package").and_then(toml::Value::as_str).unwrap_or(key).to_string())
        .collect()
}

/// Every workspace member's manifest, by package name.
fn manifests() -> BTreeMap<String, Manifest> {
    let mut out = BTreeMap::new();
    for member in workspace_members() {
        let text = read(&format!("{member}/Cargo.toml"));
        let doc: toml::Value = toml::from_str(&text).unwrap_or_else(|e| panic!("{member}/Cargo.toml: {e}"));
        let name = doc
            .get("package")
            .and_then(|p| p.get("name"))
            .and_then(toml::Value::as_str)
            .unwrap_or_else(|| panic!("{member}/Cargo.toml has no package name"))
            .to_string();
        let mut tables = vec![doc.clone()];
        if let Some(targets) = doc.get("target").and_then(toml::Value::as_table) {
            tables.extend(targets.values().cloned());
        }
        let mut normal = BTreeSet::new();
        let mut dev = BTreeSet::new();
        for table in &tables {
            for kind in ["dependencies", "build-dependencies"] {
                normal.extend(dependency_names(table.get(kind)));
            }
            dev.extend(dependency_names(table.get("dev-dependencies")));
        }
        out.insert(name, Manifest { path: member, normal, dev });
    }
    out
}

/// The dependencies of every package Cargo.lock resolves, by name (the versions of one name
/// merged): for the crates outside the workspace, what they bring in on any target with the
/// features the workspace enables.
fn locked_dependencies() -> BTreeMap<String, BTreeSet<String>> {
    let lock: toml::Value = toml::from_str(&read("Cargo.lock")).expect("Cargo.lock parses");
    let packages = lock.get("package").and_then(toml::Value::as_array).expect("Cargo.lock lists packages");
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for package in packages {
        let name = package.get("name").and_then(toml::Value::as_str).expect("a locked package's name");
        let entry = out.entry(name.to_string()).or_default();
        for dep in package.get("dependencies").and_then(toml::Value::as_array).into_iter().flatten() {
            // "name", "name version" or "name version (source)".
            let dep = dep.as_str().expect("a locked dependency is a string");
            entry.insert(dep.split(' ').next().expect("a dependency name").to_string());
        }
    }
    assert!(out.len() >= 50, "too few packages parsed from Cargo.lock: {}", out.len());
    out
}

/// The stage crates: each a function of plain data over drafter-core's scene.
const STAGE_CRATES: [&str; 5] =
    ["drafter-segment", "drafter-bounds", "drafter-normals", "drafter-lines", "drafter-textures"];

/// A GPU crate: wgpu and its parts.
fn is_gpu_crate(name: &str) -> bool {
    name == "wgpu" || name.starts_with("wgpu-")
}

/// A window crate: the event loop and the egui panel of `drafter view` (winit, egui, egui-winit,
/// egui-wgpu, ...).
fn is_window_crate(name: &str) -> bool {
    name == "winit" || name.starts_with("egui")
}

/// Every crate `root` depends on, with the crate that names each first: through workspace crates'
/// normal dependencies (read from their Cargo.toml; `root`'s own dev-dependencies included, as
/// `cargo tree` shows them), and past the workspace through Cargo.lock.
fn reached(
    root: &str,
    manifests: &BTreeMap<String, Manifest>,
    locked: &BTreeMap<String, BTreeSet<String>>,
) -> BTreeMap<String, String> {
    let mut seen: BTreeMap<String, String> = BTreeMap::new();
    let first = &manifests[root];
    let mut stack: Vec<(String, String)> =
        first.normal.iter().chain(&first.dev).map(|d| (d.clone(), root.to_string())).collect();
    while let Some((name, via)) = stack.pop() {
        if seen.contains_key(&name) {
            continue;
        }
        seen.insert(name.clone(), via);
        let next = match manifests.get(&name) {
            Some(m) => &m.normal,
            None => locked.get(&name).unwrap_or_else(|| panic!("{name} is not in Cargo.lock")),
        };
        stack.extend(next.iter().map(|d| (d.clone(), name.clone())));
    }
    seen
}

#[test]
fn stage_crates_depend_on_drafter_core_only() {
    let manifests = manifests();
    for stage in STAGE_CRATES {
        let manifest = manifests.get(stage).unwrap_or_else(|| panic!("stage crate {stage} is not a workspace member"));
        let workspace: Vec<&String> =
            manifest.normal.iter().filter(|d| manifests.contains_key(d.as_str()) && *d != "drafter-core").collect();
        assert!(
            workspace.is_empty(),
            "{} depends on workspace crates {workspace:?}: a stage crate depends on drafter-core only",
            manifest.path
        );
    }
}

/// The glTF owner knows the file and nothing of how it is made: it names no bake stage (the texture
/// mappings it writes are drafter-core's enums), no importer, no view.
#[test]
fn the_format_depends_on_drafter_core_only() {
    let manifests = manifests();
    let format = &manifests["drafter-format"];
    let workspace: Vec<&String> =
        format.normal.iter().filter(|d| manifests.contains_key(d.as_str()) && *d != "drafter-core").collect();
    assert!(workspace.is_empty(), "{} depends on workspace crates {workspace:?}", format.path);
}

/// Fails when `root` reaches a crate `forbidden` says yes to, naming the crate that brings it in.
fn assert_reaches_none(root: &str, forbidden: fn(&str) -> bool, why: &str) {
    let manifests = manifests();
    assert!(manifests.contains_key(root), "{root} is not a workspace member");
    let reached = reached(root, &manifests, &locked_dependencies());
    let found: Vec<String> = reached
        .iter()
        .filter(|(name, _)| forbidden(name))
        .map(|(name, via)| format!("{name} (named by {via})"))
        .collect();
    assert!(found.is_empty(), "{root} depends on {found:?}: {why}");
}

#[test]
fn the_scene_and_the_drawings_reach_no_gpu_or_window_crate() {
    for root in ["drafter-scene", "drafter-draw"] {
        assert_reaches_none(
            root,
            |name| is_gpu_crate(name) || is_window_crate(name),
            "it must build without GPU or window code",
        );
    }
}

#[test]
fn the_renderer_and_the_browser_build_reach_no_window_crate() {
    assert_reaches_none(
        "drafter-render",
        is_window_crate,
        "the renderer builds for the browser; the window and its panel are drafter-app's",
    );
    assert_reaches_none("drafter-web", is_window_crate, "the browser page draws through drafter-render alone");
}

/// The walk the arrows rely on sees through both layers: the CLI names no GPU or window crate
/// itself, yet reaches wgpu through workspace crates, and egui's painter (epaint) only through
/// Cargo.lock.
#[test]
fn the_arrows_are_followed_through_the_workspace_and_cargo_lock() {
    let manifests = manifests();
    let cli = &manifests["drafter-cli"];
    assert!(!cli.normal.iter().any(|d| is_gpu_crate(d)), "{} names a GPU crate itself", cli.path);
    let reached = reached("drafter-cli", &manifests, &locked_dependencies());
    assert!(reached.contains_key("wgpu"), "drafter-cli reaches wgpu through drafter-render and drafter-app");
    let via = reached.get("epaint").expect("drafter-cli reaches epaint through egui");
    assert!(!manifests.contains_key(via), "epaint is named by {via}, a crate outside the workspace");
}

#[test]
fn only_the_app_and_the_cli_name_window_crates() {
    for (name, manifest) in &manifests() {
        if name == "drafter-app" || name == "drafter-cli" {
            continue;
        }
        let named: Vec<&String> = manifest.normal.iter().chain(&manifest.dev).filter(|d| is_window_crate(d)).collect();
        assert!(
            named.is_empty(),
            "{} names {named:?}: only the desktop app (drafter-app) and the CLI may name a window crate",
            manifest.path
        );
    }
}

/// The crates that build on drafter-testkit outside their tests: the benchmarks (`drafter bench`'s
/// generated inputs and contact assemblies), the CLI, which reaches it through drafter-bench alone,
/// and the fuzzer (its generated seeds and the seeded generator).
const TESTKIT_TOOLS: [&str; 3] = ["drafter-bench", "drafter-fuzz", "drafter-cli"];

/// drafter-testkit is a dev-dependency: any crate's tests may use it (a stage crate's included), but
/// no crate reaches it through its normal dependencies, so nothing a bake, a drawing, the viewer, the
/// browser page or Python links carries test fixtures.
#[test]
fn the_testkit_is_a_dev_dependency_only() {
    let manifests = manifests();
    assert!(manifests.contains_key("drafter-testkit"), "drafter-testkit is not a workspace member");
    for (name, manifest) in &manifests {
        if name == "drafter-testkit" || TESTKIT_TOOLS.contains(&name.as_str()) {
            continue;
        }
        let mut seen = BTreeSet::new();
        let mut stack: Vec<(&String, &str)> = manifest.normal.iter().map(|d| (d, name.as_str())).collect();
        while let Some((dep, via)) = stack.pop() {
            if !seen.insert(dep) {
                continue;
            }
            assert!(
                dep != "drafter-testkit",
                "{} reaches drafter-testkit through {via}'s [dependencies]: it belongs in [dev-dependencies]",
                manifest.path
            );
            if let Some(m) = manifests.get(dep.as_str()) {
                stack.extend(m.normal.iter().map(|d| (d, dep.as_str())));
            }
        }
    }
}
