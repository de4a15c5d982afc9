//! Pieces on the same pixels, merged after every edge's visibility is decided.
//!
//! Different 3D edges can project onto the same screen line: the near and far halves of a circle
//! seen edge-on, the front and back edges of a face seen edge-on, a border drawn by both its parts.
//! Each edge's visibility is decided on its own first ([`crate::visibility`]); only then are the
//! pieces that overlap on one screen line merged, so which edge comes first never decides what is
//! drawn. Where pieces overlap, one is drawn: a visible piece over a hidden one, and among pieces of
//! the same visibility the class the SVG draws last (silhouettes, then boundaries, part borders and
//! non-manifold edges, then creases); ties go to the longer piece.
//!
//! A piece is on a line when both its ends lie within [`SAME_PIXELS_PX`] of the line's longest
//! piece, extended, running along it, and near one of its pieces: two lines a quarter pixel apart print as one at every width drafter draws (0.6 to
//! 1.6 px), as the outline of a gear seen from above and the crease of its chamfer a sixth of a
//! pixel inside do. Nothing is moved: where pieces overlap, the one drawn keeps its own line and
//! the others are left out there. A piece alone on its line is kept exactly as it is.

use std::collections::HashMap;

use drafter_scene::edges::LineClass;
use glam::DVec2;

use crate::{Drawing, Piece};

/// Side of the grid cells candidate pairs are found in, in pixels.
const CELL_PX: f64 = 16.0;

/// Lines closer than this many pixels are drawn as one (whatever the tolerance: a coarse tolerance
/// drops short pieces, it does not move lines).
pub const SAME_PIXELS_PX: f64 = 0.25;

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
/// pieces of it at most a cell long).
fn cells(a: DVec2, b: DVec2, pad: f64, cell: f64, mut visit: impl FnMut((i64, i64))) {
    let steps = ((a.distance(b) / cell).ceil() as usize).clamp(1, 1 << 16);
    let mut last: Vec<(i64, i64)> = Vec::new();
    for k in 0..steps {
        let (p, q) = (a.lerp(b, k as f64 / steps as f64), a.lerp(b, (k + 1) as f64 / steps as f64));
        let (lo, hi) = (p.min(q) - DVec2::splat(pad), p.max(q) + DVec2::splat(pad));
        let mut here = Vec::with_capacity(4);
        for x in (lo.x / cell).floor() as i64..=(hi.x / cell).floor() as i64 {
            for y in (lo.y / cell).floor() as i64..=(hi.y / cell).floor() as i64 {
                if !last.contains(&(x, y)) {
                    visit((x, y));
                }
                here.push((x, y));
            }
        }
        last = here;
    }
}

/// A screen line: the longest piece on it, and the stretch its pieces cover.
struct Line {
    origin: DVec2,
    /// Unit direction of the longest piece.
    u: DVec2,
    /// The stretch the pieces cover, as parameters along `u` from `origin`.
    extent: (f64, f64),
    /// Indices of its pieces, the longest first.
    pieces: Vec<usize>,
}

impl Line {
    /// The stretch of `p` along the line, when both its ends lie within `eps` of it.
    fn span(&self, p: &Piece, eps: f64) -> Option<(f64, f64)> {
        let n = self.u.perp();
        if (p.a - self.origin).dot(n).abs() > eps || (p.b - self.origin).dot(n).abs() > eps {
            return None;
        }
        let (t0, t1) = ((p.a - self.origin).dot(self.u), (p.b - self.origin).dot(self.u));
        Some((t0.min(t1), t0.max(t1)))
    }
}

/// Merges the pieces that overlap on one screen line (see the module docs); returns the pieces to
/// draw, in the order of their first piece, and how many pieces were merged into others.
///
/// Pieces are taken longest first; each joins the lines, among those of the pieces already taken
/// near it, that it lies on (they become one), or starts a line of its own. Every piece is tested against the line's own direction (its longest piece's), never
/// against another member, so a line cannot drift along the short pieces of a curve.
pub(crate) fn merge(pieces: &[Piece], tolerance: f64) -> (Vec<Piece>, usize) {
    let eps = SAME_PIXELS_PX;
    let length = |i: usize| pieces[i].a.distance(pieces[i].b);
    let mut order: Vec<usize> = (0..pieces.len()).collect();
    order.sort_by(|&x, &y| length(y).total_cmp(&length(x)).then(x.cmp(&y)));
    let mut lines: Vec<Line> = Vec::new();
    // Lines found to be one (a piece lay on both) point to the first of them.
    let mut same: Vec<usize> = Vec::new();
    fn root(same: &mut [usize], mut l: usize) -> usize {
        while same[l] != l {
            same[l] = same[same[l]];
            l = same[l];
        }
        l
    }
    let mut line_of = vec![0usize; pieces.len()];
    // Grid cell → the lines with a piece passing near it.
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for &i in &order {
        let p = &pieces[i];
        let mut near: Vec<usize> = Vec::new();
        cells(p.a, p.b, eps, CELL_PX, |c| {
            if let Some(list) = grid.get(&c) {
                near.extend(list.iter().copied());
            }
        });
        for l in &mut near {
            *l = root(&mut same, *l);
        }
        near.sort_unstable();
        near.dedup();
        // Along a line, not across it (a piece shorter than the distance can lie within it at any
        // angle).
        let on: Vec<(usize, f64, f64)> = near
            .into_iter()
            .filter_map(|l| {
                let (lo, hi) = lines[l].span(p, eps)?;
                (hi - lo >= 0.5 * length(i)).then_some((l, lo, hi))
            })
            .collect();
        let l = match on.first() {
            Some(&(l, lo, hi)) => {
                let line = &mut lines[l];
                line.extent = (line.extent.0.min(lo), line.extent.1.max(hi));
                // Lines the piece also lies on become this one where all of each lies on it
                // (not two lines crossing at a short piece).
                for &(other, _, _) in &on[1..] {
                    let o = &lines[other];
                    let ends = [o.origin + o.u * o.extent.0, o.origin + o.u * o.extent.1];
                    let n = lines[l].u.perp();
                    if ends.iter().all(|&e| (e - lines[l].origin).dot(n).abs() <= eps) {
                        same[other] = l;
                    }
                }
                l
            }
            None => {
                let d = p.b - p.a;
                let u = if d.length() > 0.0 { d / d.length() } else { DVec2::X };
                lines.push(Line { origin: p.a, u, extent: (0.0, d.length()), pieces: Vec::new() });
                same.push(lines.len() - 1);
                lines.len() - 1
            }
        };
        line_of[i] = l;
        cells(p.a, p.b, eps, CELL_PX, |c| {
            let list = grid.entry(c).or_default();
            if list.last() != Some(&l) {
                list.push(l);
            }
        });
    }
    // Each line's pieces, the longest first.
    for &i in &order {
        let l = root(&mut same, line_of[i]);
        line_of[i] = l;
        lines[l].pieces.push(i);
    }
    // Each line is drawn where its first piece, in input order, was.
    let mut first_of = vec![usize::MAX; lines.len()];
    for i in (0..pieces.len()).rev() {
        first_of[line_of[i]] = i;
    }
    let mut out = Vec::with_capacity(pieces.len());
    let mut merged = 0;
    for (i, piece) in pieces.iter().enumerate() {
        let line = &lines[line_of[i]];
        if first_of[line_of[i]] != i {
            continue;
        }
        if line.pieces.len() == 1 {
            out.push(*piece);
            continue;
        }
        let painted = paint(pieces, line, tolerance);
        merged += line.pieces.len().saturating_sub(painted.len());
        out.extend(painted);
    }
    (out, merged)
}

/// The pieces a line's overlapping pieces are drawn as: along the line, each stretch shows its
/// highest-ranked piece; a piece's neighbouring stretches are joined; end points come from the
/// piece's own line (exactly its own end points where it ends).
fn paint(pieces: &[Piece], line: &Line, tolerance: f64) -> Vec<Piece> {
    let cluster = &line.pieces;
    let (origin, u) = (line.origin, line.u);
    // Each member's stretch of the line, and how a parameter maps back onto its own segment.
    let spans: Vec<(f64, f64)> = cluster
        .iter()
        .map(|&m| {
            let (t0, t1) = ((pieces[m].a - origin).dot(u), (pieces[m].b - origin).dot(u));
            (t0.min(t1), t0.max(t1))
        })
        .collect();
    let point = |k: usize, t: f64| {
        let p = &pieces[cluster[k]];
        let (t0, t1) = ((p.a - origin).dot(u), (p.b - origin).dot(u));
        if t == t0 {
            p.a
        } else if t == t1 {
            p.b
        } else {
            p.a + (p.b - p.a) * ((t - t0) / (t1 - t0))
        }
    };
    let mut breaks: Vec<f64> = spans.iter().flat_map(|&(lo, hi)| [lo, hi]).collect();
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    // Runs: (first member, start, last member, end).
    let mut runs: Vec<(usize, f64, usize, f64)> = Vec::new();
    for w in breaks.windows(2) {
        let (s, e) = (w[0], w[1]);
        let winner = (0..cluster.len())
            .filter(|&k| spans[k].0 <= s && spans[k].1 >= e)
            .max_by(|&x, &y| rank(&pieces[cluster[x]]).cmp(&rank(&pieces[cluster[y]])).then(y.cmp(&x)));
        let Some(k) = winner else { continue };
        match runs.last_mut() {
            // One piece's stretches only: joining two pieces' would draw a segment across from
            // one's line to the other's.
            Some(run) if run.3 == s && run.2 == k => {
                run.2 = k;
                run.3 = e;
            }
            _ => runs.push((k, s, k, e)),
        }
    }
    runs.into_iter()
        .filter(|&(_, s, _, e)| e - s >= tolerance)
        .map(|(first, s, last, e)| {
            let p = &pieces[cluster[first]];
            Piece { a: point(first, s), b: point(last, e), class: p.class, visible: p.visible, part: p.part }
        })
        .collect()
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
}
