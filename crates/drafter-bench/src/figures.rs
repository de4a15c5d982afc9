//! The charts of a [`SweepReport`]: one [`Figure`] per stage, each with a title naming the model,
//! axes in units, a legend, and the default or chosen configuration marked.

use crate::chart::{Figure, Kind, Mark, Panel, Series};
use crate::sweep::{OBB_METHODS, SweepReport};

/// (file stem, figure) for every chart of the report.
pub fn all(report: &SweepReport) -> Vec<(&'static str, Figure)> {
    let mut out = vec![("obb", obb(report)), ("normals", normals(report))];
    if let Some(f) = silhouettes(report) {
        out.push(("silhouettes", f));
    }
    out.push(("segmentation", segmentation(report)));
    if !report.segmentation.contacts.is_empty() {
        out.push(("segmentation_contacts", segmentation_contacts(report)));
    }
    out.push(("bake", bake(report)));
    if let Some(f) = quantization(report) {
        out.push(("quantization", f));
    }
    out
}

/// What each byte of the silhouette normals buys (see `crate::quantization`).
pub fn quantization(report: &SweepReport) -> Option<Figure> {
    let q = report.quantization.as_ref()?;
    let label = |bits: u32| match bits {
        32 => "f32".to_owned(),
        crate::quantization::SHIPPED_BITS => format!("{bits} (shipped)"),
        _ => bits.to_string(),
    };
    let categories: Vec<String> = q.points.iter().map(|p| label(p.bits)).collect();
    let at = |f: &dyn Fn(&crate::quantization::QuantizationPoint) -> f64| -> Vec<(f64, f64)> {
        q.points.iter().enumerate().map(|(i, p)| (i as f64, f(p))).collect()
    };
    let positive = |v: Vec<(f64, f64)>| v.into_iter().filter(|p| p.1 > 0.0).collect::<Vec<_>>();
    let x_label = "bits per component of the stored silhouette normals".to_owned();
    let bytes = Panel {
        title: format!("bytes of {} silhouette normals (two per candidate edge)", thousands(2 * q.candidates)),
        x_label: x_label.clone(),
        y_label: "bytes (MB)".into(),
        categories: categories.clone(),
        series: vec![
            Series::new("as stored (tightly packed)", Kind::Bars, 1, at(&|p| p.raw_bytes as f64 / 1e6)),
            Series::new(
                "through meshoptimizer (--compress)",
                Kind::BigPoints,
                0,
                at(&|p| p.encoded_bytes as f64 / 1e6),
            ),
        ],
        headroom: 0.25,
        y_from_zero: true,
        ..Panel::default()
    };
    let error = Panel {
        title: "angle to the f32 face normal".into(),
        x_label: x_label.clone(),
        y_label: "degrees (log)".into(),
        y_log: true,
        categories: categories.clone(),
        series: vec![
            Series::new("mean", Kind::BigPoints, 0, positive(at(&|p| p.mean_error_deg))),
            Series::new("largest", Kind::BigPoints, 1, positive(at(&|p| p.max_error_deg))),
        ],
        headroom: 0.25,
        ..Panel::default()
    };
    let agreement = Panel {
        title: format!("silhouette decisions that differ from the f32 normals' ({} orthographic views)", q.views),
        x_label,
        y_label: "per million candidate-views (log)".into(),
        y_log: true,
        categories,
        series: vec![Series::new("differing", Kind::BigPoints, 0, positive(at(&|p| p.disagreement_ppm)))],
        headroom: 0.25,
        ..Panel::default()
    };
    Some(Figure {
        title: format!("{}: bytes against accuracy of the silhouette normals", model(report)),
        columns: 1,
        size: (1400, 1500),
        panels: vec![bytes, error, agreement],
    })
}

fn model(report: &SweepReport) -> String {
    format!("{} ({} triangles)", report.model.name, thousands(report.model.triangles))
}

fn thousands(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

pub fn obb(report: &SweepReport) -> Figure {
    let o = &report.obb;
    let mut series = Vec::new();
    for (k, method) in OBB_METHODS.iter().enumerate() {
        let points = o.per_part.iter().map(|p| (p.ms[k].max(1e-4), p.relative_volume[k])).collect();
        series.push(Series::new(method.name(), Kind::Points, k, points).without_legend());
    }
    for (k, m) in o.methods.iter().enumerate() {
        series.push(Series::new(
            format!("{} (mean {:.3}×, worst {:.3}×)", m.method, m.mean_relative_volume, m.max_relative_volume),
            Kind::BigPoints,
            k,
            vec![(m.mean_ms.max(1e-4), m.mean_relative_volume)],
        ));
    }
    let default = o.methods.iter().find(|m| m.method == "default");
    Figure {
        title: format!("Oriented boxes — {}", model(report)),
        columns: 1,
        size: (1000, 640),
        panels: vec![Panel {
            title: format!(
                "{} of {} parts, one thread: small dots are parts, large dots the mean per method",
                o.measured_parts, o.parts
            ),
            x_label: "time per part (ms, log)".into(),
            y_label: "volume / smallest box found".into(),
            x_log: true,
            y_log: false,
            series,
            marks: default
                .map(|m| Mark { label: "bake default".into(), x: m.mean_ms.max(1e-4), y: m.mean_relative_volume })
                .into_iter()
                .collect(),
            headroom: 0.35,
            ..Panel::default()
        }],
    }
}

pub fn normals(report: &SweepReport) -> Figure {
    let n = &report.normals;
    let it = |f: &dyn Fn(&crate::sweep::NormalsPoint) -> f64| -> Vec<(f64, f64)> {
        n.by_iterations.iter().map(|p| (f64::from(p.iterations), f(p))).collect()
    };
    // The reference itself (0° by definition) is left out of the angle panel.
    let it_no_ref = |f: &dyn Fn(&crate::sweep::NormalsPoint) -> f64| -> Vec<(f64, f64)> {
        n.by_iterations
            .iter()
            .filter(|p| p.iterations != n.converged_iterations)
            .map(|p| (f64::from(p.iterations), f(p)))
            .collect()
    };
    let k = |f: &dyn Fn(&crate::sweep::NormalsPoint) -> f64| -> Vec<(f64, f64)> {
        n.by_strength.iter().map(|p| (f64::from(p.strength), f(p))).collect()
    };
    let default_it = n.by_iterations.iter().find(|p| p.iterations == n.default_iterations);
    let default_k = n.by_strength.iter().find(|p| p.strength == n.default_strength);
    let mark_it = |f: &dyn Fn(&crate::sweep::NormalsPoint) -> f64| -> Vec<Mark> {
        default_it.map(|p| Mark { label: "default".into(), x: f64::from(p.iterations), y: f(p) }).into_iter().collect()
    };
    let mark_k = |f: &dyn Fn(&crate::sweep::NormalsPoint) -> f64| -> Vec<Mark> {
        default_k.map(|p| Mark { label: "default".into(), x: f64::from(p.strength), y: f(p) }).into_iter().collect()
    };
    let panel = |title: &str, x: &str, y: &str, x_log: bool, s: Series, marks: Vec<Mark>| Panel {
        title: title.into(),
        x_label: x.into(),
        y_label: y.into(),
        x_log,
        series: vec![s],
        marks,
        headroom: 0.25,
        y_from_zero: true,
        y_max: y.contains('%').then_some(125.0),
        ..Panel::default()
    };
    let ms = |p: &crate::sweep::NormalsPoint| p.ms;
    let deg = |p: &crate::sweep::NormalsPoint| p.mean_deg_from_converged;
    let frac = |p: &crate::sweep::NormalsPoint| 100.0 * p.crease_contrast_increased;
    let gain = |p: &crate::sweep::NormalsPoint| p.mean_crease_contrast_gain_deg;
    let iters = "iterations (log)";
    let deg_panel = panel(
        &format!("angle to the result at {} iterations", n.converged_iterations),
        iters,
        "mean angle (degrees)",
        true,
        Series::new("enhanced face normals", Kind::Line, 1, it_no_ref(&deg)),
        mark_it(&deg),
    );
    Figure {
        title: format!(
            "Normal enhancement — {}: {} faces, {} crease edges (> 30°) in unique meshes",
            report.model.name,
            thousands(n.faces),
            thousands(n.crease_edges)
        ),
        columns: 3,
        size: (1500, 900),
        panels: vec![
            panel(
                &format!("time vs iterations (k = {})", n.default_strength),
                iters,
                "time (ms)",
                true,
                Series::new("filter, all meshes", Kind::Line, 0, it(&ms)),
                mark_it(&ms),
            ),
            deg_panel,
            panel(
                "crease edges whose contrast grew",
                iters,
                "crease edges (%)",
                true,
                Series::new("enhanced vs original", Kind::Line, 2, it(&frac)),
                mark_it(&frac),
            ),
            panel(
                &format!("time vs strength k ({} iterations)", n.default_iterations),
                "strength k",
                "time (ms)",
                false,
                Series::new("filter, all meshes", Kind::Line, 0, k(&ms)),
                mark_k(&ms),
            ),
            panel(
                "mean contrast change at crease edges",
                "strength k",
                "angle between the faces' normals, change (degrees)",
                false,
                Series::new("enhanced − original", Kind::Line, 3, k(&gain)),
                mark_k(&gain),
            ),
            panel(
                "crease edges whose contrast grew",
                "strength k",
                "crease edges (%)",
                false,
                Series::new("enhanced vs original", Kind::Line, 2, k(&frac)),
                mark_k(&frac),
            ),
        ],
    }
}

pub fn silhouettes(report: &SweepReport) -> Option<Figure> {
    let s = report.silhouettes.as_ref()?;
    let by = |f: &dyn Fn(&crate::sweep::SilhouetteSize) -> f64| -> Vec<(f64, f64)> {
        s.by_size.iter().map(|r| (r.candidates as f64, f(r).max(1e-3))).collect()
    };
    let full = s.by_size.last();
    let mut marks = Vec::new();
    if let Some(r) = full {
        let ortho = if s.chosen_depth.is_some() { r.gauss_overlapping_us } else { r.brute_ortho_us };
        marks.push(Mark { label: "stored (ortho)".into(), x: r.candidates as f64, y: ortho.max(1e-3) });
        let persp = if s.chosen_perspective.starts_with("cone") { r.cone_bvh_us } else { r.brute_perspective_us };
        marks.push(Mark { label: "stored (persp)".into(), x: r.candidates as f64, y: persp.max(1e-3) });
    }
    let size_panel = Panel {
        title: format!(
            "stored for the mesh: {} (orthographic), {} (perspective)",
            short(&s.chosen_orthographic),
            short(&s.chosen_perspective)
        ),
        x_label: "silhouette candidate edges (log)".into(),
        y_label: "time per view (µs, log)".into(),
        x_log: true,
        y_log: true,
        series: vec![
            Series::new("brute force, orthographic", Kind::Line, 0, by(&|r| r.brute_ortho_us)),
            Series::new("brute force, perspective", Kind::Line, 5, by(&|r| r.brute_perspective_us)),
            Series::new("Gauss map, overlapping bins", Kind::Line, 1, by(&|r| r.gauss_overlapping_us)),
            Series::new("Gauss map, strict bins", Kind::Line, 3, by(&|r| r.gauss_strict_us)),
            Series::new("cone BVH, perspective", Kind::Line, 2, by(&|r| r.cone_bvh_us)),
        ],
        marks,
        headroom: 0.6,
        ..Panel::default()
    };
    let depth = |f: &dyn Fn(&crate::sweep::SilhouetteDepth) -> f64| -> Vec<(f64, f64)> {
        s.by_depth.iter().map(|d| (f64::from(d.depth), f(d).max(1e-3))).collect()
    };
    let mut depth_marks = Vec::new();
    if let Some(d) = s.chosen_depth.and_then(|c| s.by_depth.iter().find(|d| d.depth == c)) {
        depth_marks.push(Mark { label: "stored".into(), x: f64::from(d.depth), y: d.overlapping_us.max(1e-3) });
    }
    let depth_panel = Panel {
        title: format!("Gauss map by depth, all {} candidates", thousands(s.candidates)),
        x_label: "hierarchy depth (levels below the icosahedron)".into(),
        y_label: "time per view (µs, log)".into(),
        y_log: true,
        series: vec![
            Series::new(
                "brute force",
                Kind::Line,
                0,
                s.by_depth.iter().map(|d| (f64::from(d.depth), s.brute_ortho_us.max(1e-3))).collect(),
            ),
            Series::new("overlapping bins", Kind::Line, 1, depth(&|d| d.overlapping_us)),
            Series::new("strict bins", Kind::Line, 3, depth(&|d| d.strict_us)),
        ],
        marks: depth_marks,
        headroom: 0.5,
        ..Panel::default()
    };
    Some(Figure {
        title: format!(
            "Silhouettes — {}, mesh {} ({} edges), {} views per point, one thread",
            report.model.name,
            s.mesh,
            thousands(s.edges),
            s.views
        ),
        columns: 2,
        size: (1500, 640),
        panels: vec![size_panel, depth_panel],
    })
}

/// A stored-configuration description without its parenthesised detail.
fn short(choice: &str) -> &str {
    choice.split(" (").next().unwrap_or(choice)
}

pub fn segmentation(report: &SweepReport) -> Figure {
    let g = &report.segmentation;
    let angle = |f: &dyn Fn(&crate::sweep::SegmentPoint) -> f64| -> Vec<(f64, f64)> {
        g.by_region_angle.iter().map(|p| (p.value, f(p))).collect()
    };
    let merge = |f: &dyn Fn(&crate::sweep::SegmentPoint) -> f64| -> Vec<(f64, f64)> {
        g.by_merge_fraction.iter().map(|p| (100.0 * p.value, f(p))).collect()
    };
    let mark =
        |points: &[crate::sweep::SegmentPoint], at: f64, scale: f64, f: &dyn Fn(&crate::sweep::SegmentPoint) -> f64| {
            points
                .iter()
                .find(|p| p.value == at)
                .map(|p| Mark { label: "default".into(), x: scale * p.value, y: f(p) })
                .into_iter()
                .collect::<Vec<_>>()
        };
    let parts = |p: &crate::sweep::SegmentPoint| p.parts as f64;
    let ms = |p: &crate::sweep::SegmentPoint| p.ms;
    let panel = |title: &str, x: &str, y: &str, s: Series, marks: Vec<Mark>| Panel {
        title: title.into(),
        x_label: x.into(),
        y_label: y.into(),
        series: vec![s],
        marks,
        headroom: 0.25,
        y_from_zero: true,
        ..Panel::default()
    };
    let angle_x = "region angle (degrees)";
    let merge_x = "merge threshold (% of the mesh's triangles)";
    Figure {
        title: format!("Segmentation — {}: {} parts with the defaults", model(report), thousands(g.default_parts)),
        columns: 2,
        size: (1300, 900),
        panels: vec![
            panel(
                "parts vs region angle (regions mode)",
                angle_x,
                "parts",
                Series::new("parts", Kind::Line, 0, angle(&parts)),
                mark(&g.by_region_angle, g.default_region_angle_deg, 1.0, &parts),
            ),
            panel(
                "time vs region angle (regions mode)",
                angle_x,
                "time (ms)",
                Series::new("segmentation", Kind::Line, 1, angle(&ms)),
                mark(&g.by_region_angle, g.default_region_angle_deg, 1.0, &ms),
            ),
            panel(
                "parts vs merge threshold (auto mode, each mesh alone)",
                merge_x,
                "parts",
                Series::new("parts", Kind::Line, 0, merge(&parts)),
                mark(&g.by_merge_fraction, g.default_merge_fraction, 100.0, &parts),
            ),
            panel(
                "time vs merge threshold (auto mode, each mesh alone)",
                merge_x,
                "time (ms)",
                Series::new("segmentation", Kind::Line, 1, merge(&ms)),
                mark(&g.by_merge_fraction, g.default_merge_fraction, 100.0, &ms),
            ),
        ],
    }
}

/// `auto` on the generated contact family, fans paired whole only (the earlier rule), in part, and
/// in part with cracks glued (the default): triangles in a matching part, and parts found against the true
/// count.
pub fn segmentation_contacts(report: &SweepReport) -> Figure {
    let c = &report.segmentation.contacts;
    // Numbers on the axis (the names do not fit); the kinds repeat in each variant, in order.
    let categories: Vec<String> = (1..=c.len()).map(|i| i.to_string()).collect();
    let mut kinds: Vec<&str> = Vec::new();
    let mut variants: Vec<&str> = Vec::new();
    for p in c {
        let (kind, variant) = p.name.split_once('/').unwrap_or((&p.name, ""));
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
        if !variants.contains(&variant) {
            variants.push(variant);
        }
    }
    let x_label = format!(
        "generated assembly: {} × ({})",
        variants.join(", "),
        kinds.iter().enumerate().map(|(i, k)| format!("{} {k}", i + 1)).collect::<Vec<_>>().join(", ")
    );
    let at = |offset: f64, f: &dyn Fn(&crate::sweep::ContactPoint) -> f64| -> Vec<(f64, f64)> {
        c.iter().enumerate().map(|(i, p)| (i as f64 + offset, f(p))).collect()
    };
    let passing = |f: &dyn Fn(&crate::sweep::ContactPoint) -> (f64, usize)| {
        c.iter().filter(|p| f(p).0 >= 0.99 && f(p).1 == p.truth_parts).count()
    };
    let (before, between, after) = (passing(&|p| p.whole), passing(&|p| p.partial), passing(&|p| p.stitched));
    let matched = Panel {
        title: "triangles in a part that matches one original part (bar: 99%)".into(),
        x_label: x_label.clone(),
        y_label: "% of triangles".into(),
        categories: categories.clone(),
        series: vec![
            Series::new("fans paired whole only (before)", Kind::BigPoints, 1, at(-0.2, &|p| 100.0 * p.whole.0)),
            Series::new("fans paired in part", Kind::BigPoints, 2, at(0.0, &|p| 100.0 * p.partial.0)),
            Series::new("in part, cracks glued (now)", Kind::BigPoints, 0, at(0.2, &|p| 100.0 * p.stitched.0)),
        ],
        headroom: 0.25,
        y_from_zero: true,
        y_max: Some(100.0),
        ..Panel::default()
    };
    let parts = Panel {
        title: "parts found minus true parts".into(),
        x_label,
        y_label: "extra parts".into(),
        categories,
        series: vec![
            Series::new(
                "fans paired whole only (before)",
                Kind::BigPoints,
                1,
                at(-0.2, &|p| p.whole.1 as f64 - p.truth_parts as f64),
            ),
            Series::new(
                "fans paired in part",
                Kind::BigPoints,
                2,
                at(0.0, &|p| p.partial.1 as f64 - p.truth_parts as f64),
            ),
            Series::new(
                "in part, cracks glued (now)",
                Kind::BigPoints,
                0,
                at(0.2, &|p| p.stitched.1 as f64 - p.truth_parts as f64),
            ),
        ],
        headroom: 0.25,
        y_from_zero: true,
        ..Panel::default()
    };
    Figure {
        title: format!(
            "Segmentation of touching parts (generated, merged into one unwelded mesh): {before} of {} at the bar before, {between} with fans paired in part, {after} now",
            c.len()
        ),
        columns: 1,
        size: (1600, 1100),
        panels: vec![matched, parts],
    }
}

pub fn bake(report: &SweepReport) -> Figure {
    let b = &report.bake;
    let time_panel = Panel {
        title: format!("time per stage (default bake, {:.0} ms in all)", b.total_ms),
        x_label: "stage".into(),
        y_label: "time (ms)".into(),
        categories: b.stages.iter().map(|s| s.0.clone()).collect(),
        series: vec![
            Series::new("time", Kind::Bars, 0, b.stages.iter().enumerate().map(|(i, s)| (i as f64, s.1)).collect())
                .without_legend(),
        ],
        headroom: 0.1,
        ..Panel::default()
    };
    let bytes_panel = Panel {
        title: format!("output bytes per stage ({:.2} MB in all)", b.output_bytes as f64 / 1e6),
        x_label: "what the stage adds to the file".into(),
        y_label: "size (MB)".into(),
        categories: b.bytes.iter().map(|s| s.0.clone()).collect(),
        series: vec![
            Series::new(
                "bytes",
                Kind::Bars,
                2,
                b.bytes.iter().enumerate().map(|(i, s)| (i as f64, s.1 as f64 / 1e6)).collect(),
            )
            .without_legend(),
        ],
        headroom: 0.1,
        ..Panel::default()
    };
    Figure {
        title: format!("Bake — {}", model(report)),
        columns: 2,
        size: (1500, 560),
        panels: vec![time_panel, bytes_panel],
    }
}
