//! Line drawings (drafter-draw) against the renderer: the visible black lines against the raster
//! lines pass, and the part fills against the renderer's part ids, at the same view and size. The
//! drawing's own tests (brute-force visibility, SVG) are in `crates/drafter-draw/tests/`.

mod common;

use drafter_draw::{self as drawing, DrawOptions, Hidden};
use drafter_render::edges::LineClass;

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
    let render = drafter_render::RenderOptions {
        size,
        style: drafter_render::Style::Gooch,
        use_part_styles: false,
        lines: true,
        view: options.view,
        ..drafter_render::RenderOptions::default()
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
        let render = drafter_render::RenderOptions {
            size,
            supersample: 1,
            view: DrawOptions::default().view,
            ..drafter_render::RenderOptions::default()
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
            let svg = drawing::to_svg(&drawing, Hidden::None, drawing::LineStyle::default());
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
