//! Drawing sheets (`drafter_draw::sheet`): the views share their axes exactly (the model's
//! bounding-box corners land on one x in the front and top views and one y in the front and side
//! views; the drawn lines span exactly the views' rectangles), sit where the projection method
//! puts them, keep clear of each other, the border and the title block, at the largest standard
//! scale that fits; a scale that does not fit is refused, naming the one that does.

mod common;

use drafter_draw::sheet::{self, Angle, Axis, Rect, Scale, Sheet, SheetError, SheetOptions, SheetSize, ViewKind};
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
