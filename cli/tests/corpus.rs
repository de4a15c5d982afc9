//! `drafter inspect --json` over every model of ../shared/models, checked against the counts in its
//! README (computed independently with trimesh): triangles (instanced for glTF, facets for STL),
//! and for single-mesh files the welded boundary / non-manifold edge and component counts. The
//! Draco-compressed samples are read like the rest.

mod common;

use serde_json::Value;

#[derive(Debug)]
struct Row {
    path: String,
    triangles: u64,
    boundary: Option<u64>,
    nonmanifold: Option<u64>,
    components: Option<u64>,
    /// Draco-compressed (KHR_draco_mesh_compression): decoded on import, so checked as
    /// any other row; `readme_parser_reads_known_rows` holds the parser to finding them.
    needs_draco: bool,
}

fn number(s: &str) -> Option<u64> {
    let digits: String = s.chars().take_while(|c| c.is_ascii_digit() || *c == ',').filter(|c| *c != ',').collect();
    digits.parse().ok()
}

/// The number right before `label` in `text`, e.g. `"223 boundary edges"` → 223.
fn number_before(text: &str, label: &str) -> Option<u64> {
    text.match_indices(label).find_map(|(at, _)| {
        let before = text[..at].trim_end();
        let start = before.rfind(|c: char| !(c.is_ascii_digit() || c == ',')).map_or(0, |i| i + 1);
        number(&before[start..])
    })
}

fn readme_rows() -> Vec<Row> {
    let readme = std::fs::read_to_string(common::shared_models().join("README.md")).expect("README");
    let mut rows = Vec::new();
    for line in readme.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | path | format | meshes/parts | vertices | triangles | origin | license | notes |
        if cells.len() < 9 || !(cells[1].starts_with("gltf/") || cells[1].starts_with("obj/")) {
            continue;
        }
        let triangles_cell = cells[5];
        let triangles = match triangles_cell.find('(') {
            Some(i) if triangles_cell.contains("instanced") => number(&triangles_cell[i + 1..]),
            _ => number(triangles_cell),
        }
        .expect("triangle count");
        let parts = cells[3];
        let single = parts.starts_with("1 mesh,") || cells[1].starts_with("obj/") && !cells[1].ends_with(".glb");
        let (boundary, nonmanifold, components) = if single {
            (
                Some(number_before(parts, "boundary edge").unwrap_or(0)),
                Some(number_before(parts, "non-manifold edge").unwrap_or(0)),
                number_before(parts, "component"),
            )
        } else {
            (None, None, None)
        };
        rows.push(Row {
            path: cells[1].to_owned(),
            triangles,
            boundary,
            nonmanifold,
            components,
            needs_draco: cells[8].contains("KHR_draco_mesh_compression"),
        });
    }
    rows
}

#[test]
fn inspect_matches_the_corpus_readme() {
    let models = common::shared_models();
    let rows = readme_rows();
    assert!(rows.len() >= 40, "parsed only {} rows from the README table", rows.len());
    let mut failures = Vec::new();
    for row in &rows {
        let file = models.join(&row.path);
        let out = common::run(&["inspect", "--json", file.to_str().expect("utf-8 path")]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        if !out.status.success() {
            failures.push(format!("{}: exit {:?}: {stderr}", row.path, out.status.code()));
            continue;
        }
        let json: Value = serde_json::from_slice(&out.stdout).expect("json");
        let got = json["triangles"].as_u64().expect("triangles");
        if got != row.triangles {
            failures.push(format!("{}: {got} triangles, README says {}", row.path, row.triangles));
        }
        let topo = &json["topology"];
        for (name, expected) in
            [("boundary_edges", row.boundary), ("nonmanifold_edges", row.nonmanifold), ("components", row.components)]
        {
            if let Some(expected) = expected {
                let got = topo[name].as_u64().expect(name);
                if got != expected {
                    failures.push(format!("{}: {name} = {got}, README says {expected}", row.path));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{} mismatches:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn readme_parser_reads_known_rows() {
    let rows = readme_rows();
    assert_eq!(rows.iter().filter(|r| r.needs_draco).count(), 2, "the two Draco samples");
    let buggy = rows.iter().find(|r| r.path == "gltf/Buggy/draco/Buggy.gltf").expect("Draco Buggy row");
    assert_eq!((buggy.triangles, buggy.needs_draco), (474_329, true));
    let bunny = rows.iter().find(|r| r.path.ends_with("stanford-bunny.obj")).expect("bunny row");
    assert_eq!((bunny.triangles, bunny.boundary, bunny.nonmanifold), (69_451, Some(223), Some(0)));
    let motor = rows.iter().find(|r| r.path.ends_with("motor.stl")).expect("motor row");
    assert_eq!((motor.boundary, motor.nonmanifold, motor.components), (Some(4), Some(172), Some(12)));
    let engine = rows.iter().find(|r| r.path.ends_with("2CylinderEngine.gltf")).expect("engine row");
    assert_eq!((engine.triangles, engine.boundary), (121_496, None));
}
