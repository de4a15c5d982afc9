//! Line drawings (`drafter_viewer::drawing`, issue 45): the hidden parts of every edge against brute
//! force. Each sampled point of an edge is ray-cast from the eye (or along the view direction)
//! against every triangle of the scene in world space (Möller–Trumbore in f64, an independent
//! formulation: no projection, no BVH, no interval clipping); the drawing must say the same thing
//! wherever the point lies farther than the tolerance from one of its change points. On the sample
//! assembly, fandisk and RodAssembly (29 instances), in perspective and orthographic views.

mod common;

use drafter_viewer::Model;
use drafter_viewer::View;
use drafter_viewer::drawing::brute::{blocked, world_triangles};
use drafter_viewer::drawing::{self, DrawOptions, Hidden};
use drafter_viewer::edges::{LineClass, WorldView};
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
    let svg = drawing::to_svg(&drawing, options.hidden);
    for needle in
        [r#"<g id="visible""#, r#"<g id="hidden""#, r#"class="silhouette""#, r#"class="crease""#, "stroke-dasharray"]
    {
        assert!(svg.contains(needle), "{needle}");
    }
    assert!(svg.contains(r#"class="part-"#), "paths name their parts");
    assert_eq!(svg, drawing::to_svg(&drawing::draw(&model, &options), options.hidden), "deterministic");
    let none = drawing::to_svg(&drawing::draw(&model, &DrawOptions { hidden: Hidden::None, ..options }), Hidden::None);
    assert!(!none.contains(r#"<g id="hidden""#));
}

/// The drawing's visible black lines (silhouettes, boundaries, part borders) against the raster
/// lines pass of `drafter render --lines` in the Gooch style (black lines over cool-to-warm shading,
/// creases white): at the same view and size, every black pixel of the raster lies within 2 px of
/// the drawing's black lines, and nearly every pixel of those lines within 2 px of the raster's black.
#[test]
fn the_drawing_matches_the_raster_lines_pass() {
    let model = common::sample();
    let size = (800u32, 600u32);
    let options = DrawOptions { size, hidden: Hidden::None, ..DrawOptions::default() };
    let drawing = drawing::draw(&model, &options);
    let mut renderer = common::renderer();
    renderer.set_model(&model).expect("upload");
    let render = drafter_viewer::RenderOptions {
        size,
        style: drafter_viewer::Style::Gooch,
        use_part_styles: false,
        lines: true,
        view: options.view,
        ..drafter_viewer::RenderOptions::default()
    };
    let image = renderer.render(&render).expect("frame");
    let (w, h) = (size.0 as usize, size.1 as usize);
    let raster_black: Vec<bool> = image.rgba.chunks_exact(4).map(|p| p[0].max(p[1]).max(p[2]) < 48).collect();
    // The drawing's black classes, rasterised by sampling each segment every quarter pixel.
    let drawn = rasterise(&drawing, (w, h), |class| class != LineClass::Crease);
    let near = |mask: &[bool], x: usize, y: usize| {
        let r = 2isize;
        (-r..=r).any(|dy| {
            (-r..=r).any(|dx| {
                let (xx, yy) = (x as isize + dx, y as isize + dy);
                xx >= 0 && yy >= 0 && (xx as usize) < w && (yy as usize) < h && mask[yy as usize * w + xx as usize]
            })
        })
    };
    let share = |from: &[bool], to: &[bool]| {
        let (mut n, mut hit) = (0usize, 0usize);
        for y in 0..h {
            for x in 0..w {
                if from[y * w + x] {
                    n += 1;
                    hit += usize::from(near(to, x, y));
                }
            }
        }
        (hit as f64 / n.max(1) as f64, n)
    };
    for class in [LineClass::Silhouette, LineClass::Boundary, LineClass::PartBorder] {
        let (s, n) = share(&rasterise(&drawing, (w, h), |c| c == class), &raster_black);
        eprintln!("{class:?}: {n} pixels, {:.2}% near the raster's black", 100.0 * s);
    }
    let (drawing_in_raster, drawn_pixels) = share(&drawn, &raster_black);
    let (raster_in_drawing, raster_pixels) = share(&raster_black, &drawn);
    eprintln!(
        "drawing pixels {drawn_pixels}: {:.2}% near the raster's black; raster black pixels {raster_pixels}: {:.2}% near the drawing",
        100.0 * drawing_in_raster,
        100.0 * raster_in_drawing
    );
    assert!(drawn_pixels > 2000 && raster_pixels > 2000);
    // The raster pass turns a crease into an outline where the depth jumps across it by more than
    // a relative threshold (`passes::lines::CONTOUR_DEPTH_JUMP`), an image-space test; the drawing
    // where its faces turn opposite ways, exactly. Folds whose far side lies close behind (gear
    // flanks) are outlines only in the drawing: 90.4% of its black pixels meet the raster's black.
    assert!(drawing_in_raster >= 0.88, "{drawing_in_raster}");
    assert!(raster_in_drawing >= 0.97, "{raster_in_drawing}");
}

/// The pixels the visible strokes of the classes `keep` accepts pass through (each segment sampled
/// every quarter pixel).
fn rasterise(drawing: &drawing::Drawing, (w, h): (usize, usize), keep: impl Fn(LineClass) -> bool) -> Vec<bool> {
    let mut mask = vec![false; w * h];
    for stroke in drawing.strokes.iter().filter(|s| s.visible && keep(s.class)) {
        for pair in stroke.points.windows(2) {
            let steps = (pair[0].distance(pair[1]) * 4.0).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let p = pair[0] + (pair[1] - pair[0]) * (k as f64 / steps as f64);
                let (x, y) = (p.x.floor() as isize, p.y.floor() as isize);
                if x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h {
                    mask[y as usize * w + x as usize] = true;
                }
            }
        }
    }
    mask
}

/// A 126-sided cylinder seen so that two of its faces are exactly edge-on (found against
/// OpenCascade's hidden-line removal, docs/drawing.md): the outline is still drawn, on both sides,
/// and from a view a hair away the same.
#[test]
fn a_cylinder_with_faces_edge_on_keeps_its_outline() {
    let dir = std::env::temp_dir().join(format!("drafter-drawing-cylinder-{}", std::process::id()));
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
    std::fs::remove_dir_all(&dir).ok();
}

/// The parts' fills rasterised in painter's order (scanlines through pixel centres, nonzero
/// winding), as the part id of each pixel.
fn rasterise_fills(drawing: &drawing::Drawing, (w, h): (usize, usize)) -> Vec<Option<u32>> {
    let mut ids = vec![None; w * h];
    for fill in &drawing.fills {
        // Per row: (x of the crossing, +1 or −1) of every edge of every region of the part.
        let mut rows: Vec<Vec<(f64, i32)>> = vec![Vec::new(); h];
        for ring in fill.regions.iter().flat_map(|r| &r.loops) {
            for (i, &a) in ring.iter().enumerate() {
                let b = ring[(i + 1) % ring.len()];
                if a.y == b.y {
                    continue;
                }
                let (lo, hi, dir) = if a.y < b.y { (a, b, 1) } else { (b, a, -1) };
                let first = (lo.y - 0.5).ceil().max(0.0) as usize;
                let mut y = first;
                while y < h && (y as f64 + 0.5) < hi.y {
                    let yc = y as f64 + 0.5;
                    rows[y].push((lo.x + (hi.x - lo.x) * (yc - lo.y) / (hi.y - lo.y), dir));
                    y += 1;
                }
            }
        }
        for (y, row) in rows.iter_mut().enumerate() {
            row.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut winding = 0;
            for k in 0..row.len() {
                winding += row[k].1;
                if winding != 0 && k + 1 < row.len() {
                    let from = (row[k].0 - 0.5).ceil().max(0.0) as usize;
                    let to = ((row[k + 1].0 - 0.5).ceil().max(0.0) as usize).min(w);
                    for x in from..to {
                        ids[y * w + x] = fill.part;
                    }
                }
            }
        }
    }
    ids
}

/// `--fill flat` and `--fill bands` against the renderer's part ids at the same view: the regions
/// are exact, painter's order of surface patches is the approximation (fills.rs); the share of pixels
/// it paints with another part than the renderer shows is printed and bounded.
#[test]
fn the_fills_match_the_renderers_parts() {
    for (name, model) in
        [("sample", common::sample()), ("RodAssembly", common::baked(&common::corpus_path("gltf/RodAssembly/rod.glb")))]
    {
        let size = (800u32, 600u32);
        let mut renderer = common::renderer();
        renderer.set_model(&model).expect("upload");
        let render = drafter_viewer::RenderOptions {
            size,
            supersample: 1,
            view: DrawOptions::default().view,
            ..drafter_viewer::RenderOptions::default()
        };
        renderer.render(&render).expect("frame");
        let parts = renderer.part_map().expect("part ids").expect("a frame");
        for fill in [drawing::Fill::Flat, drawing::Fill::Bands] {
            let options = DrawOptions { size, fill, ..DrawOptions::default() };
            let drawing = drawing::draw(&model, &options);
            let ids = rasterise_fills(&drawing, (size.0 as usize, size.1 as usize));
            let covered = ids.iter().zip(&parts.ids).filter(|(a, b)| a.is_some() || b.is_some()).count();
            let wrong = ids.iter().zip(&parts.ids).filter(|(a, b)| a != b).count();
            let share = wrong as f64 / covered.max(1) as f64;
            let loops: usize = drawing.fills.iter().flat_map(|f| &f.regions).map(|r| r.loops.len()).sum();
            let svg = drawing::to_svg(&drawing, Hidden::None);
            eprintln!(
                "{name} {fill:?}: {} parts, {loops} loops, {} SVG bytes; {wrong} of {covered} covered pixels ({:.3}%) differ from the renderer's part",
                drawing.fills.len(),
                svg.len(),
                100.0 * share
            );
            assert!(covered > 20_000, "{name}: the view shows the model");
            // Measured 2026-11-29: sample 0.025%, RodAssembly 0.070% (patches both in front of and
            // behind another cut into 16-px tiles); without the cut 2.26% and 0.072%, by whole
            // parts 7.29% and 17.69%. A regression guard.
            let bound = 0.003;
            assert!(share <= bound, "{name} {fill:?}: {:.3}% of pixels disagree", 100.0 * share);
            assert!(svg.contains(r#"<g id="fills""#) && svg.contains("class=\"fill part-"));
        }
    }
}
