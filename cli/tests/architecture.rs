//! ARCHITECTURE.md against the code: the code map names every workspace member and only paths that
//! exist, the viewer's pass order is the order the renderer encodes its passes, and the bake's
//! stage order is `drafter_bake::STAGE_NAMES`. Each test reads the document and the code as they
//! are, so a change to either that makes the document untrue fails here. And the crate graph's
//! arrows, read from every member's Cargo.toml: stage crates depend on drafter-core only, the CPU
//! scene and the drawings reach no GPU or window crate, and only the viewer and the CLI name a
//! window crate.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use drafter_viewer::renderer::PASS_ORDER;

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

/// The names of the passes `Renderer::encode_frame` encodes (`self.NAME.encode(`), in source order.
fn encoded_passes() -> Vec<String> {
    let source = read("viewer/src/renderer.rs");
    let start = source.find("pub fn encode_frame(").expect("Renderer::encode_frame in viewer/src/renderer.rs");
    let body = &source[start..];
    let body = &body[..body.find("\n    }\n").expect("the end of encode_frame")];
    let mut passes = Vec::new();
    for (i, _) in body.match_indices(".encode(") {
        let before = &body[..i];
        let name_start = before.rfind(|c: char| !(c.is_alphanumeric() || c == '_')).map_or(0, |j| j + 1);
        let receiver = &before[..name_start];
        assert!(receiver.ends_with("self."), "encode_frame calls encode on something other than a pass field");
        passes.push(before[name_start..].to_string());
    }
    passes
}

#[test]
fn the_renderer_encodes_its_passes_in_pass_order() {
    assert_eq!(encoded_passes(), PASS_ORDER, "Renderer::encode_frame and renderer::PASS_ORDER disagree");
    let mut modules: Vec<String> = std::fs::read_dir(root().join("viewer/src/passes"))
        .expect("viewer/src/passes")
        .map(|e| e.expect("a directory entry").file_name().into_string().expect("a UTF-8 file name"))
        .filter_map(|name| name.strip_suffix(".rs").map(str::to_string))
        .filter(|name| name != "mod")
        .collect();
    modules.sort();
    let mut order: Vec<String> = PASS_ORDER.iter().map(|s| s.to_string()).collect();
    order.sort();
    assert_eq!(modules, order, "a module under viewer/src/passes/ that PASS_ORDER does not name, or the reverse");
}

#[test]
fn architecture_states_the_renderers_pass_order() {
    let doc = read("ARCHITECTURE.md");
    // The numbered list of "The viewer's passes", each item naming its module's file.
    let listed: Vec<&str> = section(&doc, "The viewer's passes")
        .lines()
        .filter(|line| {
            line.split_once(". ").is_some_and(|(n, _)| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
        })
        .map(|line| {
            let file = line.split("`viewer/src/passes/").nth(1).unwrap_or_else(|| panic!("no pass file in {line:?}"));
            &file[..file.find(".rs`").unwrap_or_else(|| panic!("no pass file in {line:?}"))]
        })
        .collect();
    assert_eq!(listed, PASS_ORDER, "the numbered passes of ARCHITECTURE.md's \"The viewer's passes\"");
    // The code map's viewer row names them in the same order.
    let row = section(&doc, "Code map")
        .lines()
        .find(|line| line.starts_with("| `viewer/`"))
        .expect("the code map's viewer/ row");
    let named: Vec<&str> = backticked(row).into_iter().filter(|span| PASS_ORDER.contains(span)).collect();
    assert_eq!(named, PASS_ORDER, "the passes as the code map's viewer/ row names them");
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
    /// `[dependencies]` and `[build-dependencies]`, target-specific ones included: name → optional.
    normal: BTreeMap<String, bool>,
    /// `[dev-dependencies]`, target-specific ones included.
    dev: BTreeSet<String>,
    /// `[features]`: feature → what it enables.
    features: BTreeMap<String, Vec<String>>,
}

/// The names of a dependency table, each with whether it is optional.
fn dependency_names(table: Option<&toml::Value>) -> Vec<(String, bool)> {
    let Some(table) = table.and_then(toml::Value::as_table) else { return Vec::new() };
    table
        .iter()
        .map(|(key, spec)| {
            // `foo = { package = "bar" }` depends on bar.
            let name = spec.get("package").and_then(toml::Value::as_str).unwrap_or(key).to_string();
            let optional = spec.get("optional").and_then(toml::Value::as_bool).unwrap_or(false);
            (name, optional)
        })
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
        let mut normal = BTreeMap::new();
        let mut dev = BTreeSet::new();
        for table in &tables {
            for kind in ["dependencies", "build-dependencies"] {
                for (dep, optional) in dependency_names(table.get(kind)) {
                    normal.insert(dep, optional);
                }
            }
            dev.extend(dependency_names(table.get("dev-dependencies")).into_iter().map(|(d, _)| d));
        }
        let features = doc
            .get("features")
            .and_then(toml::Value::as_table)
            .map(|f| {
                f.iter()
                    .map(|(k, v)| {
                        let list =
                            v.as_array().map(|a| a.iter().filter_map(|x| x.as_str().map(str::to_string)).collect());
                        (k.clone(), list.unwrap_or_default())
                    })
                    .collect()
            })
            .unwrap_or_default();
        out.insert(name, Manifest { path: member, normal, dev, features });
    }
    out
}

/// The stage crates: each a function of plain data over drafter-core's scene.
const STAGE_CRATES: [&str; 5] =
    ["drafter-segment", "drafter-bounds", "drafter-normals", "drafter-lines", "drafter-textures"];

/// The GPU crates, and the window side of the viewer (the event loop and the egui panel).
const GPU_CRATES: [&str; 1] = ["wgpu"];
const WINDOW_CRATES: [&str; 4] = ["winit", "egui", "egui-winit", "egui-wgpu"];

/// Every crate `root` depends on through workspace crates' normal dependencies (its own
/// dev-dependencies included: `cargo tree` shows them too), with the workspace crate that names
/// each first.
fn reached(root: &str, manifests: &BTreeMap<String, Manifest>) -> BTreeMap<String, String> {
    let mut seen: BTreeMap<String, String> = BTreeMap::new();
    let first = &manifests[root];
    let mut stack: Vec<(String, String)> =
        first.normal.keys().chain(&first.dev).map(|d| (d.clone(), root.to_string())).collect();
    while let Some((name, via)) = stack.pop() {
        if seen.contains_key(&name) {
            continue;
        }
        seen.insert(name.clone(), via);
        if let Some(m) = manifests.get(&name) {
            stack.extend(m.normal.keys().map(|d| (d.clone(), name.clone())));
        }
    }
    seen
}

#[test]
fn stage_crates_depend_on_drafter_core_only() {
    let manifests = manifests();
    for stage in STAGE_CRATES {
        let manifest = manifests.get(stage).unwrap_or_else(|| panic!("stage crate {stage} is not a workspace member"));
        let workspace: Vec<&String> =
            manifest.normal.keys().filter(|d| manifests.contains_key(d.as_str()) && *d != "drafter-core").collect();
        assert!(
            workspace.is_empty(),
            "{} depends on workspace crates {workspace:?}: a stage crate depends on drafter-core only",
            manifest.path
        );
    }
}

#[test]
fn the_scene_and_the_drawings_reach_no_gpu_or_window_crate() {
    let manifests = manifests();
    for root in ["drafter-scene", "drafter-draw"] {
        assert!(manifests.contains_key(root), "{root} is not a workspace member");
        let reached = reached(root, &manifests);
        for forbidden in GPU_CRATES.iter().chain(&WINDOW_CRATES) {
            if let Some(via) = reached.get(*forbidden) {
                panic!("{root} depends on {forbidden} (named by {via}): it must build without GPU or window code");
            }
        }
    }
}

#[test]
fn only_the_viewer_and_the_cli_name_window_crates() {
    let manifests = manifests();
    for (name, manifest) in &manifests {
        for window in WINDOW_CRATES {
            let Some(&optional) = manifest.normal.get(window) else { continue };
            match name.as_str() {
                "drafter-cli" => {}
                // The viewer's window side is behind its `native` feature, which the browser build
                // leaves out.
                "drafter-viewer" => {
                    let native = manifest.features.get("native").cloned().unwrap_or_default();
                    assert!(
                        optional && native.contains(&format!("dep:{window}")),
                        "viewer/Cargo.toml: {window} must be optional and enabled by the `native` feature only"
                    );
                }
                _ => panic!("{} depends on {window}: only the viewer's window side and the CLI may", manifest.path),
            }
        }
        assert!(
            !manifest
                .dev
                .iter()
                .any(|d| WINDOW_CRATES.contains(&d.as_str()) && name != "drafter-viewer" && name != "drafter-cli"),
            "{} names a window crate",
            manifest.path
        );
    }
}
