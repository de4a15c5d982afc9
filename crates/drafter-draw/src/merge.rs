//! Pieces on the same pixels, merged after every edge's visibility is decided.
//!
//! Different 3D edges can project onto the same pixels: the near and far halves of a circle seen
//! edge-on, the front and back edges of a face seen edge-on, a border drawn by both its parts, two
//! parts' circles of nearly the same radius. Each edge's visibility is decided on its own first
//! ([`crate::visibility`]); only then are the pieces that share pixels merged, so which edge comes
//! first never decides what is drawn.
//!
//! Pieces are taken in the order of what is drawn over what: visible before hidden, then the class
//! the SVG draws last (silhouettes, then boundaries, part borders and non-manifold edges, then
//! creases, then tangent edges), then the longer first. Each is drawn where no piece already drawn
//! covers it, and left out where one does. A piece is covered at a point when a drawn piece
//! running alongside it (within [`ALONGSIDE_SIN`] of parallel) passes within [`SAME_PIXELS_PX`]
//! of that point, the point falling beside it (not beyond its ends): two such strokes print on the
//! same pixels at every width drafter draws (0.6 to 1.6 px). So a piece is left out only where
//! another of the same or a higher standing is drawn within half a pixel of it (a visible line is
//! never lost, a hidden piece never drawn over a visible one), and nothing is moved: what is drawn
//! is always a stretch of a piece's own segment, a piece covered nowhere exactly as it was. The
//! rule is the one [`doubled_visible_length`] measures with, so what that measure still finds is
//! lines more than half a pixel apart or more than about 3° from parallel. A stretch left over that
//! lies wholly within half a pixel of one drawn piece at up to 30° ([`BESIDE_SIN`]: a short piece of
//! a curve crossing a line) is left out too, so merging does not leave crumbs.
//!
//! The drawn stretches are found in a grid of 4-pixel cells over the pieces' box, a list of the
//! stretches themselves a cell, each tagged with its direction so that a piece tests only those
//! nearly parallel to it. The order is the only thing that decides, so the result is the same at
//! any cell size (a test holds the grid to one cell) and on any thread count (it runs on one).

use std::cmp::Reverse;
use std::collections::HashMap;

use drafter_scene::edges::LineClass;
use glam::DVec2;

use crate::{Drawing, Piece};

/// Lines closer than this many pixels, running alongside, are drawn as one (whatever the
/// tolerance: a coarse tolerance drops short pieces, it does not move lines).
pub const SAME_PIXELS_PX: f64 = 0.5;

/// Two pieces run alongside when the sine of the angle between them is at most this (about 3°).
pub const ALONGSIDE_SIN: f64 = 0.05;

/// A short piece lying wholly within [`SAME_PIXELS_PX`] of a drawn one is left out at up to this
/// sine of the angle between them (30°). Steeper, it is a line's own end, the stem of a T where a
/// part's edge meets another's outline, and leaving it out would shorten that line.
pub const BESIDE_SIN: f64 = 0.5;

/// Side of the grid cells drawn stretches are found in, in pixels: small, as a cell's list is
/// walked whole, every direction in it.
const CELL_PX: f64 = 4.0;

/// The most cells a grid takes (24 MB of empty lists); beyond, its cells grow.
const MOST_CELLS: i64 = 1 << 20;

/// Directions are binned by their angle modulo π in bins at least as wide as the widest angle
/// [`ALONGSIDE_SIN`] allows (asin 0.05 = 0.050021 < π / 62), so a piece's candidates lie in its own
/// bin and the two beside it: where many lines cross a cell (a gear's teeth, a bolt circle), those
/// far from parallel are passed over by a bit test.
const DIRECTION_BINS: i64 = 62;

/// Pieces reaching farther than this from the page's corner are drawn as they are (a page 17 m
/// wide at 96 px per inch): they would stretch the grid over more than any page holds.
const FARTHEST_MERGED_PX: f64 = 65_536.0;

/// Which piece is drawn where pieces overlap: higher wins.
fn rank(p: &Piece) -> u32 {
    let class = match p.class {
        LineClass::Tangent => 0,
        LineClass::Crease => 1,
        LineClass::NonManifold => 2,
        LineClass::PartBorder => 3,
        LineClass::Boundary => 4,
        LineClass::Silhouette => 5,
    };
    class + if p.visible { 8 } else { 0 }
}

/// The grid cells a segment from `a` to `b` passes within `pad` of (a superset: the boxes of
/// pieces of it at most a cell long), each once per run of neighbouring boxes.
fn cells(a: DVec2, b: DVec2, pad: f64, cell: f64, mut visit: impl FnMut((i64, i64))) {
    let steps = ((a.distance(b) / cell).ceil() as usize).clamp(1, 1 << 16);
    // The previous box's cells (empty at first): its cells are not visited again.
    let mut last = (0i64, -1i64, 0i64, -1i64);
    for k in 0..steps {
        let (p, q) = (a.lerp(b, k as f64 / steps as f64), a.lerp(b, (k + 1) as f64 / steps as f64));
        let (lo, hi) = (p.min(q) - DVec2::splat(pad), p.max(q) + DVec2::splat(pad));
        let here = (
            (lo.x / cell).floor() as i64,
            (hi.x / cell).floor() as i64,
            (lo.y / cell).floor() as i64,
            (hi.y / cell).floor() as i64,
        );
        for x in here.0..=here.1 {
            for y in here.2..=here.3 {
                if !(last.0..=last.1).contains(&x) || !(last.2..=last.3).contains(&y) {
                    visit((x, y));
                }
            }
        }
        last = here;
    }
}

/// The drawn stretches in square cells over the box the pieces span: a list a cell, with no table
/// to hash, each list holding the stretches themselves (not their numbers) in one run of memory,
/// as walking the lists is most of the merge's time.
struct Grid {
    origin: DVec2,
    cell: f64,
    nx: i64,
    ny: i64,
    /// Each cell's drawn stretches, with their numbers and direction bins.
    lists: Vec<Vec<(Drawn, u32, u8)>>,
}

impl Grid {
    /// Cells of at least `cell` pixels over the box from `lo` to `hi`, larger where more than
    /// [`MOST_CELLS`] would be needed.
    fn new(lo: DVec2, hi: DVec2, cell: f64) -> Grid {
        let size = (hi - lo).max(DVec2::ZERO);
        let sides = |cell: f64| ((size.x / cell).floor() as i64 + 1, (size.y / cell).floor() as i64 + 1);
        let mut cell = cell;
        while sides(cell).0 * sides(cell).1 > MOST_CELLS {
            cell *= 1.5;
        }
        let (nx, ny) = sides(cell);
        Grid { origin: lo, cell, nx, ny, lists: std::iter::repeat_with(Vec::new).take((nx * ny) as usize).collect() }
    }

    /// The cells the segment from `a` to `b` passes within `pad` of, as [`cells`] finds them, those
    /// outside the box left out (no point looked up lies there).
    fn cells(&self, a: DVec2, b: DVec2, pad: f64, mut visit: impl FnMut(usize)) {
        let (a, b, pad) = ((a - self.origin) / self.cell, (b - self.origin) / self.cell, pad / self.cell);
        let steps = (a.distance(b).ceil() as usize).clamp(1, 1 << 20);
        let mut last = (0i64, -1i64, 0i64, -1i64);
        for k in 0..steps {
            let (p, q) = (a.lerp(b, k as f64 / steps as f64), a.lerp(b, (k + 1) as f64 / steps as f64));
            let (lo, hi) = (p.min(q) - pad, p.max(q) + pad);
            let here = (
                (lo.x.floor() as i64).max(0),
                (hi.x.floor() as i64).min(self.nx - 1),
                (lo.y.floor() as i64).max(0),
                (hi.y.floor() as i64).min(self.ny - 1),
            );
            for y in here.2..=here.3 {
                for x in here.0..=here.1 {
                    if !(last.0..=last.1).contains(&x) || !(last.2..=last.3).contains(&y) {
                        visit((y * self.nx + x) as usize);
                    }
                }
            }
            last = here;
        }
    }

    /// The cell of point `p` of the box.
    fn cell_of(&self, p: DVec2) -> usize {
        let c = (p - self.origin) / self.cell;
        let (x, y) = ((c.x.floor() as i64).clamp(0, self.nx - 1), (c.y.floor() as i64).clamp(0, self.ny - 1));
        (y * self.nx + x) as usize
    }
}

/// A stretch of a piece that is drawn.
#[derive(Clone, Copy)]
struct Drawn {
    a: DVec2,
    /// Unit direction.
    u: DVec2,
    length: f64,
}

/// The direction bin of unit direction `u` ([`DIRECTION_BINS`]).
fn direction_bin(u: DVec2) -> i64 {
    let mut angle = u.y.atan2(u.x);
    if angle < 0.0 {
        angle += std::f64::consts::PI;
    }
    ((angle / std::f64::consts::PI * DIRECTION_BINS as f64).floor() as i64).rem_euclid(DIRECTION_BINS)
}

/// Where along the segment from `a` in unit direction `u` (parameters 0 to `length`) `drawn`
/// covers it: it runs alongside, within `eps` of the point, the point falling beside it.
fn covered(a: DVec2, u: DVec2, length: f64, drawn: &Drawn, eps: f64) -> Option<(f64, f64)> {
    let w = drawn.u;
    if u.perp_dot(w).abs() > ALONGSIDE_SIN {
        return None;
    }
    let (n, d) = (w.perp(), a - drawn.a);
    let (mut lo, mut hi) = (0.0f64, length);
    // Both conditions are linear in the parameter: f0 + t·slope within [min, max].
    for (f0, slope, min, max) in [(d.dot(n), u.dot(n), -eps, eps), (d.dot(w), u.dot(w), 0.0, drawn.length)] {
        if slope == 0.0 {
            if f0 < min || f0 > max {
                return None;
            }
        } else {
            let (t0, t1) = ((min - f0) / slope, (max - f0) / slope);
            lo = lo.max(t0.min(t1));
            hi = hi.min(t0.max(t1));
        }
    }
    (hi > lo).then_some((lo, hi))
}

/// Whether the segment from `a` in unit direction `u` to `b` lies wholly beside `drawn` (its ends
/// within `eps` of it and neither beyond its ends) at up to [`BESIDE_SIN`] from parallel: a short
/// piece crossing a line at a few degrees prints on its pixels.
fn beside(a: DVec2, b: DVec2, u: DVec2, drawn: &Drawn, eps: f64) -> bool {
    u.perp_dot(drawn.u).abs() <= BESIDE_SIN
        && [a, b].iter().all(|&p| {
            let d = p - drawn.a;
            let t = d.dot(drawn.u);
            (0.0..=drawn.length).contains(&t) && d.perp_dot(drawn.u).abs() <= eps
        })
}

/// Merges the pieces that share pixels (see the module docs); returns the pieces to draw, each
/// piece's drawn stretches in the order of the pieces and along each, and how many pieces were
/// left out entirely.
pub(crate) fn merge(pieces: &[Piece], tolerance: f64) -> (Vec<Piece>, usize) {
    merge_in_cells(pieces, tolerance, CELL_PX)
}

/// [`merge`] with grid cells of `cell` pixels (the tests compare it against one cell).
fn merge_in_cells(pieces: &[Piece], tolerance: f64, cell: f64) -> (Vec<Piece>, usize) {
    let eps = SAME_PIXELS_PX;
    let lengths: Vec<f64> = pieces.iter().map(|p| p.a.distance(p.b)).collect();
    let mut order: Vec<u32> = (0..pieces.len() as u32).collect();
    // Lengths are not negative, so their bits sort as they do.
    order.sort_unstable_by_key(|&i| (Reverse(rank(&pieces[i as usize])), Reverse(lengths[i as usize].to_bits()), i));
    // Pieces far off the page (an edge running towards the eye) are drawn as they are: they
    // would stretch the grid over more than any page holds.
    let merged = |i: usize| {
        let p = &pieces[i];
        lengths[i] > 0.0 && [p.a, p.b].iter().all(|e| e.abs().max_element() <= FARTHEST_MERGED_PX)
    };
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for (i, p) in pieces.iter().enumerate() {
        if merged(i) {
            (lo, hi) = (lo.min(p.a.min(p.b)), hi.max(p.a.max(p.b)));
        }
    }
    let mut grid = Grid::new(lo, hi, cell);
    // The last piece each drawn stretch (by number) was tested against, so a stretch met in
    // several cells is tested once.
    let mut tested: Vec<u32> = Vec::new();
    // Each piece's drawn stretches (parameters along it), found in `order`, and where in `kept`
    // they start.
    let mut kept: Vec<(f64, f64)> = Vec::with_capacity(pieces.len());
    let mut kept_of: Vec<(u32, u32)> = vec![(0, 0); pieces.len()];
    let mut cover: Vec<(f64, f64)> = Vec::new();
    // The cells a drawn stretch goes into (found before the grid is changed).
    let mut cells: Vec<usize> = Vec::new();
    for &i in &order {
        let (p, length) = (&pieces[i as usize], lengths[i as usize]);
        let start = kept.len() as u32;
        if !merged(i as usize) {
            kept.push((0.0, length));
            kept_of[i as usize] = (start, 1);
            continue;
        }
        let u = (p.b - p.a) / length;
        let bin = direction_bin(u);
        let near_bins = [bin - 1, bin, bin + 1].iter().fold(0u64, |m, b| m | 1 << b.rem_euclid(DIRECTION_BINS));
        cover.clear();
        grid.cells(p.a, p.b, 0.0, |c| {
            for &(d, id, b) in &grid.lists[c] {
                if near_bins >> b & 1 == 0 || tested[id as usize] == i {
                    continue;
                }
                tested[id as usize] = i;
                cover.extend(covered(p.a, u, length, &d, eps));
            }
        });
        // What no drawn stretch covers, stretches shorter than the tolerance left out.
        cover.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        let mut from = 0.0f64;
        let mut keep = |s: f64, e: f64| {
            if e - s > 0.0 && e - s >= tolerance {
                kept.push((s, e));
            }
        };
        for &(lo, hi) in &cover {
            if lo > from {
                keep(from, lo);
            }
            from = from.max(hi);
        }
        keep(from, length);
        // A stretch left that lies wholly beside one drawn stretch at a wider angle is on its pixels
        // too. Only one shorter than 2 eps / ALONGSIDE_SIN can (a longer one within the angle would
        // have been covered), and its middle lies in a cell the drawn stretch was entered in.
        let mut k = start as usize;
        while k < kept.len() {
            let (s, e) = kept[k];
            let (a, b) = (p.a + u * s, p.a + u * e);
            let on_drawn = e - s <= 2.0 * eps / ALONGSIDE_SIN
                && grid.lists[grid.cell_of((a + b) * 0.5)].iter().any(|(d, _, _)| beside(a, b, u, d, eps));
            if on_drawn {
                kept.remove(k);
            } else {
                k += 1;
            }
        }
        kept_of[i as usize] = (start, kept.len() as u32 - start);
        for &(s, e) in &kept[start as usize..] {
            let id = tested.len() as u32;
            let (a, b) = (p.a + u * s, p.a + u * e);
            let d = Drawn { a, u, length: e - s };
            tested.push(u32::MAX);
            grid.cells(a, b, eps, |c| cells.push(c));
            for c in cells.drain(..) {
                grid.lists[c].push((d, id, bin as u8));
            }
        }
    }
    let mut out = Vec::with_capacity(kept.len());
    let mut dropped = 0;
    for (p, (&(start, count), &length)) in pieces.iter().zip(kept_of.iter().zip(&lengths)) {
        dropped += usize::from(count == 0);
        for &(s, e) in &kept[start as usize..(start + count) as usize] {
            // A piece's own end points where the stretch ends there.
            let at = |t: f64| {
                if t <= 0.0 {
                    p.a
                } else if t >= length {
                    p.b
                } else {
                    p.a + (p.b - p.a) * (t / length)
                }
            };
            out.push(Piece { a: at(s), b: at(e), ..*p });
        }
    }
    (out, dropped)
}

/// Visible length drawn twice: the length of the drawing's visible strokes that lies within
/// `within_px` of another visible stroke segment running alongside (within about 3° of parallel,
/// the point falling inside that segment, neighbouring segments of one stroke not counted),
/// measured at points every quarter pixel. Returns (doubled, visible) in pixels.
pub fn doubled_visible_length(drawing: &Drawing, within_px: f64) -> (f64, f64) {
    const STEP: f64 = 0.25;
    let segments: Vec<(usize, usize, DVec2, DVec2)> = drawing
        .strokes
        .iter()
        .enumerate()
        .filter(|(_, s)| s.visible)
        .flat_map(|(i, s)| s.points.windows(2).enumerate().map(move |(k, w)| (i, k, w[0], w[1])))
        .filter(|&(_, _, a, b)| a.distance(b) > 0.0)
        .collect();
    let cell = 4.0f64.max(2.0 * within_px);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (n, &(_, _, a, b)) in segments.iter().enumerate() {
        cells(a, b, within_px, cell, |c| grid.entry(c).or_default().push(n));
    }
    let (mut doubled, mut visible) = (0.0, 0.0);
    for &(stroke, k, a, b) in &segments {
        let length = a.distance(b);
        let u = (b - a) / length;
        visible += length;
        let samples = (length / STEP).ceil().max(1.0) as usize;
        for s in 0..samples {
            let p = a.lerp(b, (s as f64 + 0.5) / samples as f64);
            let key = ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
            let on_other = grid.get(&key).is_some_and(|list| {
                list.iter().any(|&m| {
                    let (other, j, c, d) = segments[m];
                    if other == stroke && j.abs_diff(k) <= 1 {
                        return false;
                    }
                    let v = d - c;
                    let l = v.length();
                    let w = v / l;
                    let t = (p - c).dot(w);
                    u.perp_dot(w).abs() <= 0.05 && t > 0.0 && t < l && (p - c).perp_dot(w).abs() <= within_px
                })
            });
            if on_other {
                doubled += length / samples as f64;
            }
        }
    }
    (doubled, visible)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(a: (f64, f64), b: (f64, f64), class: LineClass, visible: bool) -> Piece {
        Piece { a: DVec2::new(a.0, a.1), b: DVec2::new(b.0, b.1), class, visible, part: None }
    }

    /// What a merge drew, comparable (`Piece` is not).
    fn drawn(merged: &(Vec<Piece>, usize)) -> (Vec<(DVec2, DVec2, LineClass, bool)>, usize) {
        (merged.0.iter().map(|p| (p.a, p.b, p.class, p.visible)).collect(), merged.1)
    }

    #[test]
    fn a_visible_piece_wins_over_a_hidden_one_on_the_same_pixels() {
        // The far half of an edge-on circle came first and hidden; the near half, visible, covers
        // its middle.
        let pieces = [
            piece((0.0, 5.0), (10.0, 5.0), LineClass::Crease, false),
            piece((2.0, 5.0), (8.0, 5.0), LineClass::Crease, true),
            piece((0.0, 9.0), (3.0, 9.0), LineClass::Crease, false),
        ];
        let (out, merged) = merge(&pieces, 0.05);
        let visible: Vec<&Piece> = out.iter().filter(|p| p.visible).collect();
        assert_eq!(visible.len(), 1);
        assert_eq!((visible[0].a, visible[0].b), (DVec2::new(2.0, 5.0), DVec2::new(8.0, 5.0)));
        let hidden: f64 = out.iter().filter(|p| !p.visible && p.a.y == 5.0).map(|p| p.a.distance(p.b)).sum();
        assert!((hidden - 4.0).abs() < 1e-12, "{hidden}");
        // The piece on another line is kept as it was.
        assert!(out.iter().any(|p| p.a == DVec2::new(0.0, 9.0) && p.b == DVec2::new(3.0, 9.0)));
        assert_eq!(out.len(), 4);
        assert_eq!(merged, 0, "one hidden piece cut in two: nothing dropped");
    }

    #[test]
    fn doubled_visible_pieces_are_drawn_once_and_the_heavier_class_wins() {
        let pieces = [
            piece((0.0, 0.0), (10.0, 0.0), LineClass::Crease, true),
            piece((10.0, 0.0), (0.0, 1e-9), LineClass::Silhouette, true),
            piece((5.0, 0.0), (15.0, 0.0), LineClass::Crease, true),
        ];
        let (out, merged) = merge(&pieces, 0.05);
        assert_eq!(merged, 1);
        let total: f64 = out.iter().map(|p| p.a.distance(p.b)).sum();
        assert!((total - 15.0).abs() < 1e-6, "{total}");
        assert!(out.iter().any(|p| p.class == LineClass::Silhouette && (p.a.distance(p.b) - 10.0).abs() < 1e-6));
    }

    #[test]
    fn lines_under_half_a_pixel_apart_are_drawn_once_and_farther_ones_twice() {
        // A shaft's outline and its bore's 0.4 px apart (one line on paper), and two outlines
        // 0.6 px apart (two).
        let pieces = [
            piece((0.0, 0.0), (20.0, 0.0), LineClass::Silhouette, true),
            piece((5.0, 0.4), (30.0, 0.4), LineClass::Crease, true),
            piece((0.0, 10.0), (20.0, 10.0), LineClass::Silhouette, true),
            piece((0.0, 10.6), (20.0, 10.6), LineClass::Crease, true),
        ];
        let (out, merged) = merge(&pieces, 0.05);
        assert_eq!(merged, 0);
        assert_eq!(out.len(), 4, "{out:?}");
        assert_eq!((out[0].a, out[0].b), (pieces[0].a, pieces[0].b));
        // The crease is left out where the silhouette runs beside it, and keeps its own line.
        assert_eq!((out[1].a, out[1].b), (DVec2::new(20.0, 0.4), DVec2::new(30.0, 0.4)));
        assert_eq!(drawn(&(out[2..].to_vec(), 0)), drawn(&(pieces[2..].to_vec(), 0)));
        let drawing = |pieces: &[Piece]| Drawing {
            width: 40,
            height: 20,
            strokes: pieces
                .iter()
                .map(|p| crate::Stroke { class: p.class, visible: p.visible, part: None, points: vec![p.a, p.b] })
                .collect(),
            ..Drawing::default()
        };
        assert_eq!(doubled_visible_length(&drawing(&out), 0.5).0, 0.0);
        assert!((doubled_visible_length(&drawing(&pieces), 0.5).0 - 30.0).abs() < 0.5);
    }

    #[test]
    fn a_line_crossing_at_a_small_angle_is_left_out_only_beside_the_other() {
        // 0.02 rad apart, crossing at x = 50: within half a pixel from x = 25 to 75.
        let slope = 0.02f64.tan();
        let pieces = [
            piece((0.0, 0.0), (100.0, 0.0), LineClass::Silhouette, true),
            piece((0.0, -50.0 * slope), (100.0, 50.0 * slope), LineClass::Crease, true),
        ];
        let (out, _) = merge(&pieces, 0.05);
        let creases: Vec<&Piece> = out.iter().filter(|p| p.class == LineClass::Crease).collect();
        assert_eq!(creases.len(), 2, "{out:?}");
        for (p, x) in creases.iter().zip([25.0, 75.0]) {
            let end = if p.a == pieces[1].a || p.a == pieces[1].b { p.b } else { p.a };
            assert!((end.x - x).abs() < 0.01 && (end.y.abs() - 0.5).abs() < 1e-9, "{end}");
        }
    }

    /// Random pieces bunched along a few lines: near-parallel, crossing, overlapping, hidden and
    /// visible, of every class that ranks differently, with stubs across them.
    fn bunched_pieces(seed: u64, count: usize) -> Vec<Piece> {
        let mut rng = drafter_core::rng::Rng::new(seed);
        let classes = [LineClass::Crease, LineClass::Silhouette, LineClass::Boundary, LineClass::Tangent];
        let lines: Vec<(DVec2, f64)> = (0..6)
            .map(|_| (DVec2::new(rng.unit_f64(), rng.unit_f64()) * 60.0, rng.unit_f64() * std::f64::consts::PI))
            .collect();
        (0..count)
            .map(|k| {
                let (origin, angle) = lines[rng.below(lines.len() as u64) as usize];
                let stub = k % 7 == 0;
                let angle = if stub { rng.unit_f64() * 6.3 } else { angle + 0.08 * rng.signed_f64() };
                let u = DVec2::new(angle.cos(), angle.sin());
                let length = 0.05 + if stub { 1.5 } else { 30.0 } * rng.unit_f64();
                let a = origin + u.perp() * 0.8 * rng.signed_f64() + u * 30.0 * rng.signed_f64();
                let class = classes[rng.below(classes.len() as u64) as usize];
                Piece { a, b: a + u * length, class, visible: rng.below(3) > 0, part: None }
            })
            .collect()
    }

    #[test]
    fn the_grid_finds_what_testing_every_pair_finds() {
        for seed in 1..=20 {
            let pieces = bunched_pieces(seed, 400);
            let merged = drawn(&merge_in_cells(&pieces, 0.05, CELL_PX));
            assert_eq!(merged, drawn(&merge_in_cells(&pieces, 0.05, 1e9)), "seed {seed}: one cell");
            assert_eq!(merged, drawn(&merge_in_cells(&pieces, 0.05, 1.0)), "seed {seed}: 1-px cells");
        }
    }

    /// The distance from `p` to the segment of `q`, and whether `p` falls beside it.
    fn distance_beside(p: DVec2, q: &Piece) -> Option<f64> {
        let (d, l) = (q.b - q.a, q.a.distance(q.b));
        let t = (p - q.a).dot(d) / l;
        (0.0..=l).contains(&t).then(|| ((p - q.a).perp_dot(d) / l).abs())
    }

    #[test]
    fn nothing_is_lost_moved_or_drawn_over_a_visible_line() {
        for seed in 1..=20 {
            let pieces = bunched_pieces(seed, 400);
            let (out, _) = merge(&pieces, 0.05);
            let length = |pieces: &[Piece]| pieces.iter().map(|p| p.a.distance(p.b)).sum::<f64>();
            assert!(length(&out) < 0.8 * length(&pieces), "seed {seed}: bunched enough to merge");
            for p in &out {
                // Each drawn piece lies on an input piece of its class and visibility.
                assert!(
                    pieces.iter().any(|q| q.class == p.class
                        && q.visible == p.visible
                        && [p.a, p.b].iter().all(|&e| {
                            let t = ((e - q.a).dot(q.b - q.a) / q.a.distance_squared(q.b)).clamp(0.0, 1.0);
                            e.distance(q.a.lerp(q.b, t)) < 1e-9
                        })),
                    "seed {seed}: {p:?} moved"
                );
            }
            for q in &pieces {
                for k in 0..=20 {
                    let point = q.a.lerp(q.b, k as f64 / 20.0);
                    // Every point of a piece is drawn within half a pixel, by a visible piece where
                    // it is visible.
                    let near = out.iter().filter(|p| p.visible || !q.visible).map(|p| {
                        let t = ((point - p.a).dot(p.b - p.a) / p.a.distance_squared(p.b)).clamp(0.0, 1.0);
                        point.distance(p.a.lerp(p.b, t))
                    });
                    // A stretch shorter than the tolerance may be dropped at the end of a cover.
                    assert!(
                        near.fold(f64::INFINITY, f64::min) <= SAME_PIXELS_PX + 0.05 + 1e-9,
                        "seed {seed}: {point} of {q:?} lost"
                    );
                }
            }
            for h in out.iter().filter(|p| !p.visible) {
                for k in 1..20 {
                    let point = h.a.lerp(h.b, k as f64 / 20.0);
                    let under = out.iter().filter(|p| p.visible).any(|v| {
                        let (u, w) = ((h.b - h.a).normalize(), (v.b - v.a).normalize());
                        u.perp_dot(w).abs() <= ALONGSIDE_SIN
                            && distance_beside(point, v).is_some_and(|d| d < SAME_PIXELS_PX - 1e-9)
                    });
                    assert!(!under, "seed {seed}: hidden {h:?} drawn over a visible piece at {point}");
                }
            }
        }
    }
}
