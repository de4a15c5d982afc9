//! Drawing sheets (`drafter_draw::sheet`): the views share their axes exactly (the model's
//! bounding-box corners land on one x in the front and top views and one y in the front and side
//! views; the drawn lines span exactly the views' rectangles), sit where the projection method
//! puts them, keep clear of each other, the border and the title block, at the largest standard
//! scale that fits; a scale that does not fit is refused, naming the one that does.

mod common;

use drafter_draw::sheet::{
    self, Angle, Axis, Rect, Scale, Sheet, SheetError, SheetOptions, SheetSize, ViewKind, section,
};
use drafter_draw::{DrawOptions, Hidden};
use glam::{DVec2, DVec3};

/// The bounding box of every triangle corner of `model`, in world space.
fn world_box(model: &drafter_scene::Model) -> (DVec3, DVec3) {
    drafter_draw::brute::world_triangles(model)
        .iter()
        .flatten()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

fn corners((lo, hi): (DVec3, DVec3)) -> Vec<DVec3> {
    (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect()
}

/// The extent of a view's visible lines on the sheet.
fn visible_extent(sheet: &Sheet, kind: ViewKind) -> Rect {
    let view = sheet.views.iter().find(|v| v.kind == kind).expect("view drawn");
    let points = view.drawing.strokes.iter().filter(|s| s.visible).flat_map(|s| s.points.iter());
    let (min, max) = points.fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    Rect { min, max }
}

fn check(sheet: &Sheet, model_box: (DVec3, DVec3)) {
    let view = |kind| sheet.views.iter().find(|v| v.kind == kind).expect("view drawn");
    let (front, top, right) = (view(ViewKind::Front), view(ViewKind::Top), view(ViewKind::Right));
    // Shared axes, exactly: every corner of the model's box has one x in front and top, one y in
    // front and right.
    for corner in corners(model_box) {
        let (f, t, r) = (front.to_sheet(corner), top.to_sheet(corner), right.to_sheet(corner));
        assert_eq!(f.x, t.x, "front and top share x at {corner}");
        assert_eq!(f.y, r.y, "front and right share y at {corner}");
    }
    // The drawn lines span each view's rectangle (the projected box of every vertex): the front
    // view's x-extent is the top view's, its y-extent the right view's, within 0.01 mm.
    for v in &sheet.views {
        let e = visible_extent(sheet, v.kind);
        let d = (e.min - v.rect.min).abs().max((e.max - v.rect.max).abs());
        assert!(d.max_element() < 0.01, "{:?}: lines {e:?} against the view's box {:?}", v.kind, v.rect);
        // Every stroke, hidden ones too, inside its rectangle.
        for s in &v.drawing.strokes {
            for p in &s.points {
                assert!(
                    p.x >= v.rect.min.x - 1e-6
                        && p.x <= v.rect.max.x + 1e-6
                        && p.y >= v.rect.min.y - 1e-6
                        && p.y <= v.rect.max.y + 1e-6,
                    "{:?}: {p} outside {:?}",
                    v.kind,
                    v.rect
                );
            }
        }
    }
    let (ef, et, er) = (
        visible_extent(sheet, ViewKind::Front),
        visible_extent(sheet, ViewKind::Top),
        visible_extent(sheet, ViewKind::Right),
    );
    assert!((ef.min.x - et.min.x).abs() < 0.01 && (ef.max.x - et.max.x).abs() < 0.01, "{ef:?} {et:?}");
    assert!((ef.min.y - er.min.y).abs() < 0.01 && (ef.max.y - er.max.y).abs() < 0.01, "{ef:?} {er:?}");
    // Placement by the projection method.
    match sheet.angle {
        Angle::Third => {
            assert!(top.rect.max.y < front.rect.min.y, "third angle: top above front");
            assert!(right.rect.min.x > front.rect.max.x, "third angle: right to the right");
        }
        Angle::First => {
            assert!(top.rect.min.y > front.rect.max.y, "first angle: top below front");
            assert!(right.rect.max.x < front.rect.min.x, "first angle: right to the left");
        }
    }
    // Clear of each other, inside the border, clear of the title block.
    for (i, a) in sheet.views.iter().enumerate() {
        assert!(sheet.border.contains(&a.rect), "{:?} inside the border", a.kind);
        assert!(!a.rect.overlaps(&sheet.title_block), "{:?} clear of the title block", a.kind);
        for b in &sheet.views[i + 1..] {
            assert!(!a.rect.overlaps(&b.rect), "{:?} and {:?} overlap", a.kind, b.kind);
        }
    }
    // The frame on the page; the lettering and symbol inside the title block.
    let page = Rect { min: DVec2::ZERO, max: DVec2::new(sheet.mm.0, sheet.mm.1) };
    for line in &sheet.frame {
        for p in &line.points {
            assert!(p.x >= page.min.x && p.y >= page.min.y && p.x <= page.max.x && p.y <= page.max.y, "{p}");
        }
    }
    let lettering = sheet.frame.iter().filter(|l| l.width < 0.7);
    for line in lettering {
        for p in &line.points {
            let t = &sheet.title_block;
            assert!(p.x >= t.min.x && p.y >= t.min.y && p.x <= t.max.x && p.y <= t.max.y, "{p} outside {t:?}");
        }
    }
}

#[test]
fn the_sample_sheet_shares_its_axes_exactly_in_both_projections() {
    let model = common::sample();
    let model_box = world_box(&model);
    for angle in [Angle::Third, Angle::First] {
        let options = SheetOptions {
            size: SheetSize::A4,
            angle,
            title: "assembly".into(),
            draw: DrawOptions { hidden: Hidden::Dashed, ..DrawOptions::default() },
            ..SheetOptions::default()
        };
        let sheet = sheet::draw_sheet(&model, &options).expect("sheet");
        check(&sheet, model_box);
        // The largest standard scale that fits: the next larger does not.
        let series = Scale::series();
        let at = series.iter().position(|&s| s == sheet.scale).unwrap();
        let larger = SheetOptions { scale: Some(series[at - 1]), ..options.clone() };
        match sheet::draw_sheet(&model, &larger) {
            Err(SheetError::ScaleDoesNotFit { largest, .. }) => assert_eq!(largest, Some(sheet.scale)),
            other => panic!("{:?} fits: {:?}", series[at - 1], other.map(|s| s.scale)),
        }
        // A smaller scale fits and keeps the axes shared.
        let smaller = SheetOptions { scale: Some(series[at + 1]), ..options };
        check(&sheet::draw_sheet(&model, &smaller).expect("smaller scale"), model_box);
    }
}

#[test]
fn up_and_front_turn_the_views() {
    let model = common::sample();
    let options = SheetOptions {
        size: SheetSize::A3,
        views: vec![ViewKind::Front, ViewKind::Top, ViewKind::Right, ViewKind::Rear, ViewKind::Left, ViewKind::Bottom],
        up: Axis::Z,
        front: Axis::NegY,
        ..SheetOptions::default()
    };
    let sheet = sheet::draw_sheet(&model, &options).expect("sheet");
    let view = |kind| sheet.views.iter().find(|v| v.kind == kind).unwrap();
    assert_eq!(view(ViewKind::Front).frame.towards, DVec3::NEG_Y);
    assert_eq!(view(ViewKind::Front).frame.up, DVec3::Z);
    assert_eq!(view(ViewKind::Top).frame.towards, DVec3::Z);
    assert_eq!(view(ViewKind::Right).frame.towards, DVec3::X, "right = up × front");
    // Six views, first angle: bottom above, left to the right, rear beyond it.
    let (f, b, l, r) = (view(ViewKind::Front), view(ViewKind::Bottom), view(ViewKind::Left), view(ViewKind::Rear));
    assert!(b.rect.max.y < f.rect.min.y && l.rect.min.x > f.rect.max.x && r.rect.min.x > l.rect.max.x);
    for (i, a) in sheet.views.iter().enumerate() {
        for c in &sheet.views[i + 1..] {
            assert!(!a.rect.overlaps(&c.rect), "{:?} and {:?} overlap", a.kind, c.kind);
        }
    }
    let parallel = SheetOptions { up: Axis::Z, front: Axis::NegZ, ..SheetOptions::default() };
    assert!(matches!(sheet::draw_sheet(&model, &parallel), Err(SheetError::Axes { .. })));
}

/// The volume of the closed bodies below `h` above `plane` (signed distance), by the divergence
/// theorem over their triangles alone: with `F = min(s − h, 0) n`, `div F` is 1 below and 0 above,
/// and the flux of `F` through a triangle clipped to `s < h` is exact from its fan (the integrand is
/// linear). Independent of the cut: no crossing points, no loops, no cap.
fn volume_below(model: &drafter_scene::Model, plane: &section::Plane, h: f64) -> f64 {
    let mut volume = 0.0;
    for batch in &model.batches {
        let positions: Vec<glam::Vec3> =
            batch.vertices.iter().map(|v| glam::Vec3::from_array(v.position_in_object)).collect();
        let triangles: Vec<[u32; 3]> = batch.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        let topology = drafter_core::Topology::from_triangles(&positions, &triangles, drafter_core::Weld::Exact);
        let object: Vec<DVec3> = topology.welded_positions.iter().map(|p| p.as_dvec3()).collect();
        let sides = section::closed_components(&topology, &object);
        for instance in batch.instances.clone() {
            let world = model.instance_world_from_object[instance as usize];
            let mirror = if world.determinant() < 0.0 { -1.0 } else { 1.0 };
            for (f, face) in topology.faces.iter().enumerate() {
                let side = f64::from(sides[topology.face_component[f] as usize]);
                if side == 0.0 {
                    continue;
                }
                let corners = face.map(|v| world.transform_point3(object[v as usize]));
                // Sutherland–Hodgman against s < h.
                let s = |p: DVec3| plane.distance(p) - h;
                let mut polygon = Vec::new();
                for k in 0..3 {
                    let (a, b) = (corners[k], corners[(k + 1) % 3]);
                    if s(a) < 0.0 {
                        polygon.push(a);
                    }
                    if (s(a) < 0.0) != (s(b) < 0.0) {
                        polygon.push(a + (b - a) * (s(a) / (s(a) - s(b))));
                    }
                }
                for i in 1..polygon.len().saturating_sub(1) {
                    let (q0, q1, q2) = (polygon[0], polygon[i], polygon[i + 1]);
                    let flux = plane.normal.dot((q1 - q0).cross(q2 - q0)) * 0.5;
                    volume += side * mirror * flux * (s(q0) + s(q1) + s(q2)) / 3.0;
                }
            }
        }
    }
    volume
}

/// Checks the cut of `model` by planes across each axis: the cut faces' area against the
/// derivative of [`volume_below`] within 0.1%, and 45° hatching inside them.
fn check_sections(model: &drafter_scene::Model, name: &str) {
    let (lo, hi) = world_box(model);
    let size = (hi - lo).max_element();
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        // Off the middle by an odd fraction, so that no vertex lies within the difference step.
        let offset = axis.dot((lo + hi) * 0.5) + 0.0123457 * size;
        let plane = section::Plane { normal: axis, offset };
        let cut = section::cut(model, &plane);
        let area: f64 = cut.faces.iter().map(|f| f.area(&plane)).sum();
        let step = 1e-5 * size;
        let reference = (volume_below(model, &plane, step) - volume_below(model, &plane, -step)) / (2.0 * step);
        println!(
            "{name} {axis}: {} cut faces ({} loops), {} open components; area {area:.6e} against {reference:.6e}",
            cut.faces.len(),
            cut.faces.iter().map(|f| f.loops.len()).sum::<usize>(),
            cut.open_components
        );
        assert!(!cut.faces.is_empty(), "{name}: the plane cuts a closed body");
        assert!((area - reference).abs() <= 1e-3 * reference.abs(), "{name} {axis}: {area} against {reference}");
        // Every body's material has positive area; every loop is closed (at least a triangle).
        for face in &cut.faces {
            assert!(face.area(&plane) > 0.0 && face.loops.iter().all(|l| l.len() >= 3), "{name}: {face:?}");
        }
        // Hatching in the plane's own 2D frame: every line's middle inside its face.
        let u = axis.any_orthonormal_vector();
        let v = axis.cross(u);
        let mut lines = 0;
        for (k, face) in cut.faces.iter().enumerate() {
            let loops: Vec<Vec<DVec2>> =
                face.loops.iter().map(|l| l.iter().map(|p| DVec2::new(p.dot(u), p.dot(v))).collect()).collect();
            for [a, b] in section::hatch(&loops, if k % 2 == 0 { 45.0 } else { 135.0 }, size / 200.0) {
                assert!(section::inside(&loops, (a + b) * 0.5), "{name}: a hatch line outside its face");
                lines += 1;
            }
        }
        assert!(lines > 0, "{name}: hatched");
    }
}

#[test]
fn section_cuts_have_the_area_of_the_bodies_plane_cut() {
    check_sections(&common::sample(), "sample");
    check_sections(&common::baked(&common::corpus_path("gltf/GearboxAssy/GearboxAssy.gltf")), "GearboxAssy");
}

#[test]
fn a_section_view_hatches_its_cut_and_hides_exactly_what_brute_force_hides() {
    let sample = common::sample();
    let all_views = SheetOptions::default().views;
    check_section_view(&sample, &all_views, &[], usize::MAX);
    // The shafts left whole (ISO 128-50 does not section shafts): drawn uncut, in front of the
    // plane too, hiding the cut faces behind them.
    check_section_view(&sample, &all_views, &["SHAFT*"], usize::MAX);
    // GearboxAssy (646,064 triangles): brute force on the edges of a sample of about 800 points.
    let gearbox = common::baked(&common::corpus_path("gltf/GearboxAssy/GearboxAssy.gltf"));
    check_section_view(&gearbox, &[ViewKind::Front], &[], 800);
}

/// A sheet of `model` with `views` and an oblique section leaving `uncut` whole, checked as the
/// test says; brute force on about `max_points` points of the section view's edges.
fn check_section_view(model: &drafter_scene::Model, views: &[ViewKind], uncut: &[&str], max_points: usize) {
    let (lo, hi) = world_box(model);
    let size = (hi - lo).max_element();
    // An oblique plane: in a view along an axis, edges lie exactly behind others and rays graze
    // faces, where "hidden" depends on a boundary convention (docs/drawing.md, axis views).
    let normal = DVec3::new(0.25, 0.4, 1.0).normalize();
    let plane = section::Plane { normal, offset: normal.dot((lo + hi) * 0.5) + 0.0123457 * size };
    let options = SheetOptions {
        size: SheetSize::A3,
        angle: Angle::Third,
        section: Some(plane),
        views: views.to_vec(),
        uncut: uncut.iter().map(|s| s.to_string()).collect(),
        draw: DrawOptions { hidden: Hidden::Dashed, ..DrawOptions::default() },
        ..SheetOptions::default()
    };
    let sheet = sheet::draw_sheet(model, &options).expect("sheet");
    let view = sheet.views.iter().find(|v| v.kind == ViewKind::Section).expect("a section view");
    assert_eq!(sheet.views.len(), views.len() + 1);
    for (i, a) in sheet.views.iter().enumerate() {
        assert!(sheet.border.contains(&a.rect) && !a.rect.overlaps(&sheet.title_block), "{:?}", a.kind);
        for b in &sheet.views[i + 1..] {
            assert!(!a.rect.overlaps(&b.rect), "{:?} and {:?} overlap", a.kind, b.kind);
        }
    }
    // The uncut parts, by name.
    let uncut_parts: Vec<u32> = model
        .parts
        .iter()
        .filter(|p| uncut.iter().any(|u| p.name.to_uppercase().starts_with(u.trim_end_matches('*'))))
        .map(|p| p.id)
        .collect();
    assert_eq!(uncut_parts.is_empty(), uncut.is_empty(), "{uncut:?} names parts");
    let is_uncut = |part: Option<u32>| part.is_some_and(|p| uncut_parts.contains(&p));
    // The cut on the sheet: the cut parts' area times the scale squared; hatching inside it.
    let mut cut = section::cut(model, &plane);
    cut.faces.retain(|f| !is_uncut(f.part));
    let area: f64 = cut.faces.iter().map(|f| f.area(&plane)).sum();
    let on_sheet: f64 = view
        .cut_loops
        .iter()
        .map(|ring| {
            // y runs down on the sheet: clockwise there is counter-clockwise seen from above.
            -0.5 * (0..ring.len()).map(|k| ring[k].perp_dot(ring[(k + 1) % ring.len()])).sum::<f64>()
        })
        .sum();
    let s2 = view.mm_per_world * view.mm_per_world;
    assert!((on_sheet - area * s2).abs() <= 1e-6 * area * s2, "{on_sheet} mm² against {}", area * s2);
    assert!(!view.hatching.is_empty());
    for [a, b] in &view.hatching {
        assert!(section::inside(&view.cut_loops, (*a + *b) * 0.5), "a hatch line outside the cut");
    }
    for s in view.drawing.strokes.iter().flat_map(|s| &s.points) {
        assert!(s.x >= view.rect.min.x - 1e-6 && s.x <= view.rect.max.x + 1e-6, "{s}");
        assert!(s.y >= view.rect.min.y - 1e-6 && s.y <= view.rect.max.y + 1e-6, "{s}");
    }

    // Brute force: what lies below the plane as triangles, the uncut parts' whole, and the cut
    // faces in the plane. A point of an edge is hidden when a ray from it up the normal meets one
    // of those triangles, or it lies below the plane and its foot on the plane lies inside a cut
    // face (even-odd in the plane).
    let parts = drafter_draw::brute::world_triangle_parts(model);
    let occluders: Vec<[DVec3; 3]> = drafter_draw::brute::world_triangles(model)
        .iter()
        .zip(&parts)
        .flat_map(|(t, &part)| {
            if is_uncut(part) {
                return vec![*t];
            }
            let polygon = section::below(&plane, t);
            (1..polygon.len().saturating_sub(1)).map(|i| [polygon[0], polygon[i], polygon[i + 1]]).collect()
        })
        .collect();
    let u = plane.normal.any_orthonormal_vector();
    let v = plane.normal.cross(u);
    let faces_2d: Vec<Vec<DVec2>> = cut
        .faces
        .iter()
        .flat_map(|f| f.loops.iter().map(|l| l.iter().map(|p| DVec2::new(p.dot(u), p.dot(v))).collect()))
        .collect();
    let visibility = drafter_draw::visibility_clipped(model, &options.draw, view.projection, view.clip.as_ref());
    let (mut compared, mut hidden_points, mut above, mut disagreements) = (0, 0, 0, 0);
    let stride = (visibility.edges.len() * 4 / max_points.max(1)).max(1);
    for edge in visibility.edges.iter().step_by(stride) {
        let length = edge.screen[0].distance(edge.screen[1]);
        if length < 1.0 {
            continue;
        }
        for k in 1..5 {
            let t = f64::from(k) / 5.0;
            // Away from the drawing's change points by more than the tolerance.
            let margin = 0.1 / length;
            if edge.hidden.iter().any(|&(a, b)| (t - a).abs() < margin || (t - b).abs() < margin) {
                continue;
            }
            let p = edge.a + (edge.b - edge.a) * t;
            let s = plane.distance(p);
            if s.abs() < 1e-6 * size {
                continue;
            }
            let drawn_hidden = edge.hidden.iter().any(|&(a, b)| a < t && t < b);
            let foot = p - plane.normal * s;
            let brute = (s < 0.0 && section::inside(&faces_2d, DVec2::new(foot.dot(u), foot.dot(v))))
                || drafter_draw::brute::blocked(p, p + plane.normal * (2.0 * size), &occluders);
            compared += 1;
            hidden_points += usize::from(brute);
            above += usize::from(s > 0.0);
            disagreements += usize::from(brute != drawn_hidden);
        }
    }
    // What is drawn of the cut faces' hatching and outlines is not behind an uncut part: their
    // middles, lifted back onto the plane, see the viewer.
    let f = view.frame;
    let lift = |m: DVec2| {
        let (x, y) = ((m.x - view.origin.x) / view.mm_per_world, -(m.y - view.origin.y) / view.mm_per_world);
        f.right * x + f.up * y + plane.normal * plane.offset
    };
    let mut lines_checked = 0;
    for [a, b] in view.hatching.iter().copied().chain(view.cut_outlines.iter().map(|l| [l[0], l[1]])) {
        if a.distance(b) < 0.1 {
            continue;
        }
        let m = lift((a + b) * 0.5);
        assert!(
            !drafter_draw::brute::blocked(m, m + plane.normal * (2.0 * size), &occluders),
            "a drawn piece of the cut behind an uncut part at {m}"
        );
        lines_checked += 1;
    }
    assert!(lines_checked > 100, "{lines_checked}");
    println!(
        "section view, uncut {uncut:?}: {compared} points compared ({above} in front of the plane), {hidden_points} hidden, {disagreements} disagreements"
    );
    assert!(compared > max_points.min(1000) / 5 && hidden_points > compared / 10, "{compared} {hidden_points}");
    assert_eq!(above > 0, !uncut.is_empty(), "only uncut parts reach in front of the plane");
    assert_eq!(disagreements, 0);
}

#[test]
fn a_section_across_an_axis_is_marked_where_views_see_its_plane_edge_on() {
    let model = common::sample();
    let (lo, hi) = world_box(&model);
    let plane = section::Plane { normal: DVec3::X, offset: (lo.x + hi.x) * 0.5 };
    let options = SheetOptions { size: SheetSize::A3, section: Some(plane), ..SheetOptions::default() };
    let sheet = sheet::draw_sheet(&model, &options).expect("sheet");
    // x = c is edge-on in the front and top views (right = +x), not in the right view.
    let chains: Vec<_> = sheet.frame.iter().filter(|l| l.dashes.len() == 4 && l.width == 0.25).collect();
    assert_eq!(chains.len(), 2, "one chain line in each of front and top");
    for chain in chains {
        let x = chain.points[0].x;
        assert!((chain.points[1].x - x).abs() < 1e-9, "vertical: the trace of x = c");
        let front = sheet.views.iter().find(|v| v.kind == ViewKind::Front).unwrap();
        assert!((front.to_sheet(DVec3::new(plane.offset, 0.0, 0.0)).x - x).abs() < 1e-9, "at x = c");
    }
}
