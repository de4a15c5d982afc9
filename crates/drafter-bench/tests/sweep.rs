//! The sweeps on the sample assembly: every stage measured, the numbers consistent with each other
//! and with what the stages guarantee, and every chart drawn.

use std::path::PathBuf;

use drafter_bench::sweep::{self, Silent, SweepOptions};

fn sample() -> drafter_core::Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples/assembly.glb");
    drafter_io::import(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).scene
}

#[test]
fn sweeps_of_the_sample_assembly_are_consistent() {
    let scene = sample();
    let options = SweepOptions { views: 24, ..SweepOptions::default() };
    let report = sweep::run(&scene, "assembly.glb", &options, &mut Silent);
    assert_eq!(report.model.triangles, scene.instanced_triangle_count());

    // Boxes: the best box is 1.0 by definition; optimal is the smallest (up to rounding) and every
    // method is at least as large as it.
    let o = &report.obb;
    assert!(o.measured_parts > 0 && o.measured_parts == o.per_part.len());
    for part in &o.per_part {
        let best = part.relative_volume.iter().copied().fold(f64::INFINITY, f64::min);
        assert!((best - 1.0).abs() < 1e-12, "part {}: best {best}", part.part);
        let optimal = part.relative_volume[sweep::OBB_METHODS.len() - 1];
        assert!(optimal <= 1.0 + 1e-9, "part {}: optimal {optimal}× the best", part.part);
    }
    let names: Vec<&str> = o.methods.iter().map(|m| m.method.as_str()).collect();
    assert_eq!(names, ["aabb", "pca", "hull", "default", "optimal"]);

    // Normals: the converged run is its own reference; fractions are fractions; k = 0 changes
    // nothing, so no crease gets sharper.
    let n = &report.normals;
    assert!(n.faces > 0 && n.crease_edges > 0, "the sample has creases");
    let last = n.by_iterations.last().expect("iterations");
    assert_eq!(last.iterations, sweep::CONVERGED_ITERATIONS);
    assert!(last.mean_deg_from_converged < 1e-9);
    let first = &n.by_iterations[0];
    assert!(first.mean_deg_from_converged > last.mean_deg_from_converged);
    for p in n.by_iterations.iter().chain(&n.by_strength) {
        assert!((0.0..=1.0).contains(&p.crease_contrast_increased) && p.ms >= 0.0);
    }
    let k0 = &n.by_strength[0];
    assert_eq!(k0.strength, 0.0);
    assert!(k0.crease_contrast_increased < 0.01 && k0.mean_crease_contrast_gain_deg.abs() < 1e-3, "{k0:?}");
    let k_default = n.by_strength.iter().find(|p| p.strength == n.default_strength).expect("default k");
    assert!(k_default.mean_crease_contrast_gain_deg > 0.0, "enhancement sharpens creases on average");

    // Silhouettes: every hierarchy answered exactly as brute force; sizes grow with the stride.
    let s = report.silhouettes.as_ref().expect("the sample has silhouette candidates");
    assert_eq!(s.mismatches, 0);
    assert_eq!(s.by_size.last().map(|r| r.candidates), Some(s.candidates));
    assert!(s.by_size.windows(2).all(|w| w[0].candidates < w[1].candidates));

    // Segmentation: more angle, fewer (or as many) regions; no merging keeps the most parts.
    let g = &report.segmentation;
    assert!(g.by_region_angle.windows(2).all(|w| w[0].parts >= w[1].parts), "{:?}", g.by_region_angle);
    assert!(g.by_merge_fraction.windows(2).all(|w| w[0].parts >= w[1].parts), "{:?}", g.by_merge_fraction);

    // Bake: the per-stage bytes add up to the file.
    let b = &report.bake;
    assert_eq!(b.bytes.iter().map(|x| x.1).sum::<i64>(), b.output_bytes as i64);
    assert!(b.stages.iter().any(|s| s.0 == "lines"));

    // Charts: one per stage, each with its title and axis units.
    let figures = drafter_bench::figures::all(&report);
    let stems: Vec<&str> = figures.iter().map(|f| f.0).collect();
    assert_eq!(
        stems,
        ["obb", "normals", "silhouettes", "segmentation", "segmentation_contacts", "bake", "quantization"]
    );

    // Quantization: every width measured; f32 loses nothing, fewer bits lose more.
    let q = report.quantization.as_ref().expect("the sample has silhouette candidates");
    assert_eq!(q.points.iter().map(|p| p.bits).collect::<Vec<_>>(), drafter_bench::quantization::QUANTIZATION_BITS);
    let last = q.points.last().expect("f32");
    assert_eq!((last.mean_error_deg, last.disagreement_ppm), (0.0, 0.0));
    assert!(q.points.windows(2).all(|w| w[1].mean_error_deg < w[0].mean_error_deg), "{:?}", q.points);
    for (stem, figure) in &figures {
        let svg = drafter_bench::chart::to_svg(figure).expect("draws");
        if *stem == "segmentation_contacts" {
            // The generated family of touching parts, the same for every model.
            assert!(svg.contains("% of triangles") && svg.contains("extra parts"), "{stem}: axes");
            continue;
        }
        assert!(svg.contains("assembly.glb"), "{stem}: title names the model");
        assert!(svg.contains("(ms") || svg.contains("(µs") || svg.contains("(MB)"), "{stem}: units");
    }
}
