//! Line drawings: the hidden parts of every edge against brute force. Each sampled point of an edge
//! is ray-cast from the eye (or along the view direction) against every triangle of the scene in
//! world space (Möller–Trumbore in f64, an independent formulation: no projection, no BVH, no
//! interval clipping); the drawing must say the same thing wherever the point lies farther than the
//! tolerance from one of its change points. On the sample assembly, fandisk and RodAssembly (29
//! instances), in perspective and orthographic views.

mod common;

use drafter_draw::brute::{blocked, world_triangles};
use drafter_draw::{self as drawing, DrawOptions, Hidden, LineStyle};
use drafter_scene::edges::{LineClass, WorldView};
use drafter_scene::{Model, View};
use glam::DVec2;

/// Samples `per_edge` points on every `stride`-th edge and counts disagreements with brute force
/// beyond `tolerance_px` of a change point. Returns (samples compared, disagreements, hidden
/// samples).
fn check(model: &Model, options: &DrawOptions, stride: usize, per_edge: usize) -> (usize, usize, usize) {
    let triangles = world_triangles(model);
    let vis = drawing::visibility(model, options);
    let viewer = vis.projection.view();
    let diagonal = model.bounds.max.distance(model.bounds.min).max(1e-9);
    let (mut compared, mut wrong, mut hidden_count) = (0, 0, 0);
    let mut first_wrong = None;
    for edge in vis.edges.iter().step_by(stride) {
        let [a2, b2] = edge.screen;
        let length = a2.distance(b2);
        if length < 1.0 {
            continue;
        }
        for k in 0..per_edge {
            // A point of the 3D edge, and where it falls on the projected one.
            let s = (k as f64 + 0.5) / per_edge as f64;
            let point = edge.a + (edge.b - edge.a) * s;
            let screen: DVec2 = vis.projection.to_screen(point).expect("in front of the eye");
            let u = (screen - a2).dot(b2 - a2) / (length * length);
            let near_change = edge.hidden.iter().any(|&(lo, hi)| {
                ((u - lo).abs() * length) < options.tolerance_px || ((u - hi).abs() * length) < options.tolerance_px
            });
            if near_change || u * length < options.tolerance_px || (1.0 - u) * length < options.tolerance_px {
                continue;
            }
            let drawn_hidden = edge.hidden.iter().any(|&(lo, hi)| u > lo && u < hi);
            let towards = match viewer {
                WorldView::Perspective { eye } => eye,
                // The direction the camera looks along (`renderer::world_view`): the viewer is
                // behind it.
                WorldView::Orthographic { direction } => point - direction.normalize() * (10.0 * diagonal),
            };
            let brute_hidden = blocked(point, towards, &triangles);
            compared += 1;
            hidden_count += usize::from(brute_hidden);
            if brute_hidden != drawn_hidden {
                wrong += 1;
                first_wrong.get_or_insert((edge.class, u, length, brute_hidden, edge.hidden.clone()));
            }
        }
    }
    if let Some(w) = first_wrong {
        eprintln!("first disagreement: {w:?}");
    }
    (compared, wrong, hidden_count)
}

fn options(view: (f32, f32), orthographic: bool) -> DrawOptions {
    DrawOptions {
        size: (800, 600),
        view: View { azimuth_deg: view.0, elevation_deg: view.1 },
        orthographic,
        hidden: Hidden::Dashed,
        ..DrawOptions::default()
    }
}

fn check_model(name: &str, model: &Model, stride: usize) {
    for (view, orthographic) in [((35.0, 25.0), false), ((-120.0, 40.0), true), ((200.0, -20.0), false)] {
        let (compared, wrong, hidden) = check(model, &options(view, orthographic), stride, 7);
        eprintln!("{name} view {view:?} ortho {orthographic}: {compared} samples, {hidden} hidden, {wrong} wrong");
        assert!(compared > 500, "{name}: enough samples ({compared})");
        assert!(hidden > compared / 20, "{name}: the view hides something ({hidden} of {compared})");
        assert_eq!(wrong, 0, "{name} {view:?} ortho {orthographic}: {wrong} of {compared} samples misclassified");
    }
}

#[test]
fn hidden_lines_match_brute_force_on_the_sample() {
    check_model("sample", &common::sample(), 4);
}

#[test]
fn hidden_lines_match_brute_force_on_fandisk() {
    check_model("fandisk", &common::baked(&common::corpus_path("obj/common-3d-test-models/fandisk.obj")), 2);
}

#[test]
fn hidden_lines_match_brute_force_on_a_cad_assembly() {
    check_model("RodAssembly", &common::baked(&common::corpus_path("gltf/RodAssembly/rod.glb")), 40);
}

/// The drawing is made of chained polylines, grouped by visibility and class, and deterministic.
#[test]
fn the_svg_groups_classes_and_chains_pieces() {
    let model = common::sample();
    let options = options((35.0, 25.0), false);
    let drawing = drawing::draw(&model, &options);
    let pieces: usize = drawing.strokes.iter().map(|s| s.points.len() - 1).sum();
    assert!(drawing.strokes.len() * 3 < pieces * 2, "chained: {} strokes for {pieces} pieces", drawing.strokes.len());
    let again = drawing::draw(&model, &options);
    for style in [LineStyle::Iso128, LineStyle::Gooch] {
        let svg = drawing::to_svg(&drawing, options.hidden, style);
        for needle in [
            r#"<g id="visible""#,
            r#"<g id="hidden""#,
            r#"class="silhouette""#,
            r#"class="crease""#,
            "stroke-dasharray",
        ] {
            assert!(svg.contains(needle), "{style:?}: {needle}");
        }
        assert!(svg.contains(r#"class="part-"#), "paths name their parts");
        assert_eq!(svg, drawing::to_svg(&again, options.hidden, style), "deterministic");
        assert_eq!(drawing::to_dxf(&drawing, options.hidden, style), drawing::to_dxf(&again, options.hidden, style));
    }
    let none = drawing::to_svg(
        &drawing::draw(&model, &DrawOptions { hidden: Hidden::None, ..options }),
        Hidden::None,
        LineStyle::default(),
    );
    assert!(!none.contains(r#"<g id="hidden""#));
}

/// A 126-sided cylinder seen so that two of its faces are exactly edge-on (found against
/// OpenCascade's hidden-line removal, docs/drawing.md): the outline is still drawn, on both sides,
/// and from a view a hair away the same.
#[test]
fn a_cylinder_with_faces_edge_on_keeps_its_outline() {
    let model = cylinder("outline");
    for azimuth in [0.0, 0.001] {
        let options = DrawOptions {
            view: View { azimuth_deg: azimuth, elevation_deg: 30.0 },
            orthographic: true,
            ..DrawOptions::default()
        };
        let drawing = drawing::draw(&model, &options);
        let outline: f64 = drawing
            .strokes
            .iter()
            .filter(|s| s.visible && s.class == LineClass::Silhouette)
            .flat_map(|s| s.points.windows(2).map(|p| p[0].distance(p[1])))
            .sum();
        assert!(drawing.stats.silhouettes >= 2, "azimuth {azimuth}: {} silhouettes", drawing.stats.silhouettes);
        // Two sides of the cylinder's height, each several hundred pixels long on an 800 x 600 view.
        assert!(outline > 600.0, "azimuth {azimuth}: {outline:.0} px of visible outline");
    }
}

/// A 126-sided cylinder of radius 1 and height 3 along +y, with capped ends, its columns half a
/// step off the axes (two faces' normals exactly along x), baked.
fn cylinder(name: &str) -> Model {
    let dir = std::env::temp_dir().join(format!("drafter-drawing-cylinder-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    let n = 126;
    let mut obj = String::new();
    for k in 0..n {
        // Columns half a step off the axes: the faces' normals fall on them, two exactly along x.
        let angle = std::f64::consts::TAU * (k as f64 + 0.5) / n as f64;
        let (x, z) = (angle.cos(), angle.sin());
        obj += &format!("v {x} 0 {z}\nv {x} 3 {z}\n");
    }
    obj += "v 0 0 0\nv 0 3 0\n";
    for k in 0..n {
        let (a, b) = (2 * k + 1, 2 * ((k + 1) % n) + 1);
        obj += &format!("f {a} {b} {}\nf {a} {} {}\n", b + 1, b + 1, a + 1);
        obj += &format!("f {} {b} {a}\nf {} {} {}\n", 2 * n + 1, 2 * n + 2, a + 1, b + 1);
    }
    let path = dir.join("cylinder.obj");
    std::fs::write(&path, obj).expect("write");
    let model = common::baked(&path);
    std::fs::remove_dir_all(&dir).ok();
    model
}

/// The steepest elevation the camera accepts (in f32, below 90).
const STEEPEST: f32 = 89.99999;

/// Points on every edge that brute force finds visible (away from the edge's ends and its change
/// points, by the tolerance) must lie on a visible stroke of the drawing (within half a pixel):
/// a visible line drawn hidden, or lost, is counted. Returns (visible samples, not drawn visible,
/// samples the edge's own intervals disagree on with brute force).
fn visible_drawn_visible(model: &Model, options: &DrawOptions, per_edge: usize) -> (usize, usize, usize) {
    let triangles = world_triangles(model);
    let vis = drawing::visibility(model, options);
    let drawn = drawing::draw(model, options);
    let diagonal = model.bounds.max.distance(model.bounds.min).max(1e-9);
    // The visible strokes' segments in 8-px cells.
    let cell = 8.0;
    let mut grid: std::collections::HashMap<(i64, i64), Vec<(DVec2, DVec2)>> = std::collections::HashMap::new();
    for stroke in drawn.strokes.iter().filter(|s| s.visible) {
        for w in stroke.points.windows(2) {
            let (lo, hi) = (w[0].min(w[1]) - DVec2::splat(1.0), w[0].max(w[1]) + DVec2::splat(1.0));
            for x in (lo.x / cell).floor() as i64..=(hi.x / cell).floor() as i64 {
                for y in (lo.y / cell).floor() as i64..=(hi.y / cell).floor() as i64 {
                    grid.entry((x, y)).or_default().push((w[0], w[1]));
                }
            }
        }
    }
    let on_visible = |p: DVec2| {
        grid.get(&((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)).is_some_and(|list| {
            list.iter().any(|&(a, b)| {
                let t = ((p - a).dot(b - a) / (b - a).length_squared().max(1e-300)).clamp(0.0, 1.0);
                p.distance(a + (b - a) * t) <= 0.5
            })
        })
    };
    let (mut visible, mut lost, mut disagree) = (0, 0, 0);
    let mut first_lost = None;
    for edge in &vis.edges {
        let [a2, b2] = edge.screen;
        let length = a2.distance(b2);
        if length < 1.0 {
            continue;
        }
        for k in 0..per_edge {
            let s = (k as f64 + 0.5) / per_edge as f64;
            let point = edge.a + (edge.b - edge.a) * s;
            let screen: DVec2 = vis.projection.to_screen(point).expect("in front of the eye");
            let u = (screen - a2).dot(b2 - a2) / (length * length);
            let near_change = edge.hidden.iter().any(|&(lo, hi)| {
                ((u - lo).abs() * length) < options.tolerance_px || ((u - hi).abs() * length) < options.tolerance_px
            });
            if near_change || u * length < 1.0 || (1.0 - u) * length < 1.0 {
                continue;
            }
            let towards = match vis.projection.view() {
                WorldView::Perspective { eye } => eye,
                WorldView::Orthographic { direction } => point - direction.normalize() * (10.0 * diagonal),
            };
            if blocked(point, towards, &triangles) {
                continue;
            }
            visible += 1;
            disagree += usize::from(edge.hidden.iter().any(|&(lo, hi)| u > lo && u < hi));
            if !on_visible(screen) {
                lost += 1;
                first_lost.get_or_insert((edge.class, screen, edge.hidden.clone()));
            }
        }
    }
    if let Some(l) = first_lost {
        eprintln!("first visible point not drawn visible: {l:?}");
    }
    (visible, lost, disagree)
}

/// Exact axis views, where different edges project onto the same pixels (the near and far halves
/// of an edge-on circle, the top and bottom outlines of a gear seen from above): every point brute
/// force finds visible is drawn visible, and the visible length drawn twice stays under 2%, in
/// perspective too (where the two edges of a face seen edge-on converge towards the eye's height).
#[test]
fn axis_views_draw_every_visible_line_visible_and_once() {
    let all = [((0.0, 0.0), true), ((0.0, 0.0), false), ((0.0, STEEPEST), true), ((90.0, STEEPEST), false)];
    let models = [
        ("cylinder", cylinder("axis"), &all[..]),
        ("gear", common::baked(&common::repo_path("samples/gear.glb")), &all[..]),
        ("sample", common::sample(), &all[..]),
    ];
    for (name, model, views) in &models {
        for &(view, orthographic) in *views {
            let options = options(view, orthographic);
            let (visible, lost, disagree) = visible_drawn_visible(model, &options, 5);
            let drawing = drawing::draw(model, &options);
            let (doubled, length) = drawing::doubled_visible_length(&drawing, 0.5);
            eprintln!(
                "{name} view {view:?} ortho {orthographic}: {visible} visible samples, {lost} not drawn visible, {disagree} \
                 against the edge's intervals; doubled {:.2}% of {length:.0} px",
                100.0 * doubled / length.max(1e-9)
            );
            assert!(visible > 200, "{name} {view:?}: enough samples ({visible})");
            assert_eq!(lost, 0, "{name} {view:?} ortho {orthographic}: visible points not drawn visible");
            assert_eq!(disagree, 0, "{name} {view:?} ortho {orthographic}: intervals against brute force");
            assert!(
                doubled <= 0.02 * length,
                "{name} {view:?} ortho {orthographic}: doubled {doubled:.0} of {length:.0} px"
            );
        }
    }
}

/// The hidden intervals of `edge`, in pixels along it.
fn hidden_px(edge: &drawing::EdgeVisibility) -> Vec<(f64, f64)> {
    let length = edge.screen[0].distance(edge.screen[1]);
    edge.hidden.iter().map(|&(lo, hi)| (lo * length, hi * length)).collect()
}

/// The length covered by exactly one of two sorted, disjoint interval lists.
fn symmetric_difference(x: &[(f64, f64)], y: &[(f64, f64)]) -> f64 {
    let mut cuts: Vec<f64> = x.iter().chain(y).flat_map(|&(lo, hi)| [lo, hi]).collect();
    cuts.sort_by(f64::total_cmp);
    let inside = |list: &[(f64, f64)], t: f64| list.iter().any(|&(lo, hi)| lo <= t && t <= hi);
    cuts.windows(2)
        .filter(|w| {
            let middle = 0.5 * (w[0] + w[1]);
            inside(x, middle) != inside(y, middle)
        })
        .map(|w| w[1] - w[0])
        .sum()
}

#[test]
fn leaving_out_the_back_faces_of_closed_bodies_hides_the_same() {
    let models = [
        ("sample", common::sample()),
        ("RodAssembly", common::baked(&common::corpus_path("gltf/RodAssembly/rod.glb"))),
        ("fandisk", common::baked(&common::corpus_path("obj/common-3d-test-models/fandisk.obj"))),
    ];
    for (name, model) in &models {
        for (view, orthographic) in
            [((35.0, 25.0), false), ((0.0, 0.0), true), ((0.0, 89.99999), true), ((200.0, -20.0), false)]
        {
            let options = options(view, orthographic);
            let projection = drawing::Projection::new(model, &options);
            let fast = drawing::visibility_in(model, &options, projection);
            let every = drawing::visibility_every_face(model, &options, projection);
            assert_eq!(fast.edges.len(), every.edges.len());
            let (mut differ, mut hidden) = (0, 0.0);
            for (a, b) in fast.edges.iter().zip(&every.edges) {
                let (x, y) = (hidden_px(a), hidden_px(b));
                hidden += x.iter().map(|(lo, hi)| hi - lo).sum::<f64>();
                // Equal up to roundings: the intervals may split differently where two front
                // faces meet instead of one back face spanning the seam, and an interval of no
                // length may come or go.
                let same = symmetric_difference(&x, &y) < 1e-6;
                if !same && differ < 6 {
                    eprintln!("  {:?} {:?} fast {x:?} every {y:?}", a.class, a.screen);
                }
                differ += usize::from(!same);
            }
            eprintln!(
                "{name} {view:?} ortho {orthographic}: {} of {} triangles hide, {hidden:.0} px hidden, {differ} edges differ",
                fast.stats.occluders, fast.stats.triangles
            );
            assert_eq!(differ, 0, "{name} {view:?}: edges whose hidden parts changed");
            assert!(hidden > 100.0, "{name} {view:?}: the view hides something");
            if *name == "sample" {
                // Its parts are closed bodies: about half their faces turn away.
                assert!(fast.stats.occluders * 10 < every.stats.occluders * 7, "{name}: back faces left out");
            }
        }
    }
}
