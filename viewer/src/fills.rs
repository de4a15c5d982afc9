//! Part fills of a line drawing (`drafter draw --fill flat|bands`, issue 45): each part's
//! projected area as vector regions, painted part by part under the lines.
//!
//! # What is exact and what is not
//! * **A part's region is exact.** It is the union of the part's projected triangles (all of them
//!   for `flat`, the front-facing ones for `bands`), each oriented counter-clockwise on the screen,
//!   written as closed paths filled with the nonzero rule. Edges that two of those triangles share
//!   in opposite directions cancel (their contributions to every winding number do), so the paths
//!   are the region's outline, not a triangle soup, and fill exactly the points the triangles cover.
//! * **Bands are exact in the projector.** Lux et al. 2013 shade a part by ω(γ(p), q, f, p′) of the
//!   projector value p, an affine function of the position (`PartGpu::projector_row`); the band
//!   index ⌊γ(p)^p′ q⌋ changes at levels of p, found here to machine precision by bisection on
//!   the same γ table the renderer samples. A level of an affine function is a straight line across
//!   a triangle in space and on the screen, so each band piece of a triangle is an exact polygon:
//!   cut points are computed on the triangle's own edges, from the edge's two end points in a fixed
//!   order, so that neighbours compute the same bits and their shared pieces cancel. A band is
//!   filled with the shade at its middle p: the fade inside a band (f < 1) is drawn flat.
//! * **Painter's order is the approximation.** Parts are painted farthest first, by the mean
//!   closeness of their front-facing triangles weighted by screen area. Where two parts overlap
//!   each other in both orders (interlocking parts), the one painted later covers the other
//!   everywhere; within a part, `bands` paints front faces only, so a concave part whose front faces
//!   overlap on the screen shows whichever band comes later. `drafter bench draw --fill` and
//!   `viewer/tests/drawing.rs` measure the pixels this gets wrong against the renderer's part ids.

use std::collections::HashMap;

use drafter_core::gradient::{GradientParams, IntensityTransfer, TransferCurve};
use glam::{DVec2, DVec3, DVec4, Vec3};

use crate::drawing::Projection;
use crate::model::Model;

/// Which fills a drawing has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Fill {
    /// Lines only.
    #[default]
    None,
    /// Each part's projected area in one light grey.
    Flat,
    /// Each part's gradient bands (Lux et al. 2013) as grey regions.
    Bands,
}

/// One filled region: closed loops in pixels (y down), filled with the nonzero rule.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// The band's index (0 = lowest p) for `bands`; 0 for `flat`.
    pub band: u32,
    /// Grey in [0, 1].
    pub grey: f64,
    pub loops: Vec<Vec<DVec2>>,
}

/// A part's fill, in painter's order within [`crate::drawing::Drawing::fills`].
#[derive(Clone, Debug, PartialEq)]
pub struct PartFill {
    /// The part (`None`: triangles of no part).
    pub part: Option<u32>,
    /// Area-weighted mean closeness of its front-facing triangles (the order's key).
    pub closeness: f64,
    pub regions: Vec<Region>,
}

/// The grey of a flat fill.
pub const FLAT_GREY: f64 = 0.93;

/// Bits of a screen point: shared corners and cut points of neighbouring triangles compare equal.
type Key = [u64; 2];

fn key(p: DVec2) -> Key {
    [p.x.to_bits(), p.y.to_bits()]
}

/// A part's directed screen edges, per band.
#[derive(Default)]
struct Outline {
    /// (from, to) → count, stored with from < to (a reversed edge counts −1).
    edges: HashMap<(Key, Key), i64>,
    points: HashMap<Key, DVec2>,
}

impl Outline {
    fn add_polygon(&mut self, polygon: &[DVec2]) {
        for (i, &a) in polygon.iter().enumerate() {
            let b = polygon[(i + 1) % polygon.len()];
            let (ka, kb) = (key(a), key(b));
            if ka == kb {
                continue;
            }
            self.points.insert(ka, a);
            self.points.insert(kb, b);
            if ka < kb {
                *self.edges.entry((ka, kb)).or_default() += 1;
            } else {
                *self.edges.entry((kb, ka)).or_default() -= 1;
            }
        }
    }

    /// The edges left after cancellation, walked into closed loops (deterministic: keys sorted).
    fn loops(self) -> Vec<Vec<DVec2>> {
        let mut next: HashMap<Key, Vec<Key>> = HashMap::new();
        let mut sorted: Vec<((Key, Key), i64)> = self.edges.into_iter().filter(|(_, n)| *n != 0).collect();
        sorted.sort_unstable();
        for ((a, b), n) in sorted {
            let (from, to) = if n > 0 { (a, b) } else { (b, a) };
            for _ in 0..n.unsigned_abs() {
                next.entry(from).or_default().push(to);
            }
        }
        let mut starts: Vec<Key> = next.keys().copied().collect();
        starts.sort_unstable();
        for list in next.values_mut() {
            list.reverse(); // popped in sorted order
        }
        let mut loops = Vec::new();
        for start in starts {
            while next.get(&start).is_some_and(|l| !l.is_empty()) {
                let mut points = vec![self.points[&start]];
                let mut at = start;
                while let Some(to) = next.get_mut(&at).and_then(Vec::pop) {
                    if to == start {
                        break;
                    }
                    points.push(self.points[&to]);
                    at = to;
                }
                if points.len() >= 3 {
                    loops.push(points);
                }
            }
        }
        loops
    }
}

/// The levels of the projector value p where a part's band changes, ascending, and each band's
/// grey (one more than the levels).
fn band_levels(params: &GradientParams, transfer: &IntensityTransfer) -> (Vec<f64>, Vec<f64>) {
    let q = params.q.max(1);
    let band = |p: f64| -> u32 {
        let i = f64::from(transfer.sample(p as f32)).clamp(0.0, 1.0);
        let t = if i <= 0.0 { 0.0 } else { i.powf(f64::from(params.p.max(0.01))) * f64::from(q) };
        (t.floor() as u32).min(q)
    };
    const SAMPLES: usize = 2048;
    let mut levels = Vec::new();
    let mut previous = band(0.0);
    for k in 1..=SAMPLES {
        let x = k as f64 / SAMPLES as f64;
        let here = band(x);
        if here != previous {
            let (mut lo, mut hi) = ((k - 1) as f64 / SAMPLES as f64, x);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if band(mid) == previous {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            levels.push(hi);
            previous = here;
        }
    }
    let mut bounds = vec![0.0];
    bounds.extend(levels.iter().copied());
    bounds.push(1.0);
    let greys = bounds
        .windows(2)
        .map(|w| 0.18 + 0.82 * f64::from(params.shade((0.5 * (w[0] + w[1])) as f32, transfer)))
        .collect();
    (levels, greys)
}

/// The piece of a triangle between projector levels `lo` and `hi` (`None`: unbounded), walked
/// along its edges: corners inside the band and the band's cut points on each edge, each cut
/// computed from the edge's end points in key order so that a neighbour gets the same bits.
fn band_piece(
    corners: &[(DVec3, f64); 3],
    lo: Option<f64>,
    hi: Option<f64>,
    project: &impl Fn(DVec3) -> Option<DVec2>,
) -> Option<Vec<DVec2>> {
    let inside = |p: f64| lo.is_none_or(|l| p >= l) && hi.is_none_or(|h| p < h);
    let mut out = Vec::new();
    for i in 0..3 {
        let (u, pu) = corners[i];
        let (v, pv) = corners[(i + 1) % 3];
        if inside(pu) {
            out.push(project(u)?);
        }
        // Levels crossed going from u to v, in that order.
        let mut cuts: Vec<f64> = [lo, hi].into_iter().flatten().filter(|&l| (pu < l) != (pv < l)).collect();
        if pv < pu {
            cuts.reverse();
        }
        for level in cuts {
            // The same point from either side: the end points ordered by their screen keys.
            let (a, pa, b, pb) = if key(project(u)?) <= key(project(v)?) { (u, pu, v, pv) } else { (v, pv, u, pu) };
            let t = (level - pa) / (pb - pa);
            out.push(project(a + (b - a) * t)?);
        }
    }
    (out.len() >= 3).then_some(out)
}

/// The fills of `model` under `projection` (module docs), in painter's order.
pub fn fills(model: &Model, projection: &Projection, mode: Fill) -> Vec<PartFill> {
    if mode == Fill::None {
        return Vec::new();
    }
    struct Acc {
        closeness: f64,
        area: f64,
        outlines: Vec<Outline>,
        greys: Vec<f64>,
        levels: Vec<f64>,
    }
    let mut parts: HashMap<Option<u32>, Acc> = HashMap::new();
    // Front-facing triangles on the screen with their corners' closeness, for the order.
    let mut fronts: Vec<(Option<u32>, [DVec2; 3], [f64; 3])> = Vec::new();
    let project = |w: DVec3| projection.to_screen(w);
    for batch in &model.batches {
        for instance in batch.instances.clone() {
            let Some(world) = model.instance_world_from_object.get(instance as usize) else { continue };
            let mirrored = world.determinant() < 0.0;
            let points: Vec<DVec3> = batch
                .vertices
                .iter()
                .map(|v| world.transform_point3(Vec3::from_array(v.position_in_object).as_dvec3()))
                .collect();
            for (t, tri) in batch.indices.chunks_exact(3).enumerate() {
                let Some(corners) = tri.iter().map(|&i| points.get(i as usize).copied()).collect::<Option<Vec<_>>>()
                else {
                    continue;
                };
                let Some(screen) = corners.iter().map(|&c| projection.to_screen(c)).collect::<Option<Vec<_>>>() else {
                    continue;
                };
                // Twice the signed area with y up: positive is counter-clockwise on the screen.
                let (e1, e2) = (screen[1] - screen[0], screen[2] - screen[0]);
                let area_up = -(e1.x * e2.y - e1.y * e2.x);
                if area_up == 0.0 {
                    continue;
                }
                let front = (area_up > 0.0) != mirrored;
                let part = crate::drawing::part_of(model, Some(batch), instance, t);
                let acc = parts.entry(part).or_insert_with(|| {
                    let (levels, greys) = match mode {
                        Fill::Bands => part_gradient(model, part),
                        _ => (Vec::new(), vec![FLAT_GREY]),
                    };
                    Acc {
                        closeness: 0.0,
                        area: 0.0,
                        outlines: (0..greys.len()).map(|_| Outline::default()).collect(),
                        greys,
                        levels,
                    }
                });
                let weight = area_up.abs();
                if front {
                    let c = projection.closeness_of(&corners).unwrap_or(0.0);
                    acc.closeness += weight * c;
                    acc.area += weight;
                    let cs: Option<Vec<f64>> = corners.iter().map(|&k| projection.closeness_of(&[k])).collect();
                    if let Some(cs) = cs {
                        fronts.push((part, [screen[0], screen[1], screen[2]], [cs[0], cs[1], cs[2]]));
                    }
                }
                // Counter-clockwise on the screen (y up), so windings add.
                let order: [usize; 3] = if area_up > 0.0 { [0, 1, 2] } else { [0, 2, 1] };
                match mode {
                    Fill::Flat => {
                        let polygon: Vec<DVec2> = order.iter().map(|&k| screen[k]).collect();
                        acc.outlines[0].add_polygon(&polygon);
                    }
                    Fill::Bands if front => {
                        let row = model.parts.get(part.unwrap_or(u32::MAX) as usize).map(|p| p.gpu.projector_row);
                        let row = row.map_or(DVec4::ZERO, |r| DVec4::from_array(r.map(f64::from)));
                        let p_at = |w: DVec3| row.truncate().dot(w - model.origin) + row.w;
                        let tri3 = order.map(|k| (corners[k], p_at(corners[k])));
                        let n = acc.greys.len();
                        for band in 0..n {
                            let lo = (band > 0).then(|| acc.levels[band - 1]);
                            let hi = (band + 1 < n).then(|| acc.levels[band]);
                            if let Some(piece) = band_piece(&tri3, lo, hi, &project) {
                                acc.outlines[band].add_polygon(&piece);
                            }
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    let mut out: Vec<PartFill> = parts
        .into_iter()
        .map(|(part, acc)| {
            let closeness = if acc.area > 0.0 { acc.closeness / acc.area } else { f64::NEG_INFINITY };
            let regions = acc
                .outlines
                .into_iter()
                .zip(acc.greys)
                .enumerate()
                .map(|(band, (outline, grey))| Region { band: band as u32, grey, loops: outline.loops() })
                .filter(|r| !r.loops.is_empty())
                .collect();
            PartFill { part, closeness, regions }
        })
        .collect();
    out.sort_by(|a, b| a.closeness.total_cmp(&b.closeness).then(a.part.cmp(&b.part)));
    let (w, h) = projection.size();
    painter_order(&mut out, &fronts, (w as usize, h as usize));
    out
}

/// Orders `fills` so that, wherever two parts overlap, the one in front is painted later, as far
/// as a cycle allows. Who is in front of whom is counted at pixel centres: the two nearest parts of
/// every pixel from the front-facing triangles (closeness interpolated exactly: it is affine on the
/// screen). Parts are then taken in topological order; in a cycle, the part with the least weight
/// of "in front of a remaining part" goes first. Ties keep the mean-closeness order given.
fn painter_order(fills: &mut Vec<PartFill>, fronts: &[(Option<u32>, [DVec2; 3], [f64; 3])], (w, h): (usize, usize)) {
    let index: HashMap<Option<u32>, usize> = fills.iter().enumerate().map(|(i, f)| (f.part, i)).collect();
    let n = fills.len();
    // Per pixel: nearest (closeness, fill index), and the nearest of another part.
    let mut first = vec![(f64::NEG_INFINITY, usize::MAX); w * h];
    let mut second = vec![(f64::NEG_INFINITY, usize::MAX); w * h];
    for (part, s, c) in fronts {
        let Some(&f) = index.get(part) else { continue };
        let area = (s[1] - s[0]).perp_dot(s[2] - s[0]);
        if area == 0.0 {
            continue;
        }
        let x0 = (s.iter().map(|p| p.x).fold(f64::INFINITY, f64::min) - 0.5).ceil().max(0.0) as usize;
        let x1 = ((s.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max) - 0.5).floor().max(-1.0) + 1.0) as usize;
        let y0 = (s.iter().map(|p| p.y).fold(f64::INFINITY, f64::min) - 0.5).ceil().max(0.0) as usize;
        let y1 = ((s.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max) - 0.5).floor().max(-1.0) + 1.0) as usize;
        for y in y0..y1.min(h) {
            for x in x0..x1.min(w) {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let b0 = (s[2] - s[1]).perp_dot(p - s[1]) / area;
                let b1 = (s[0] - s[2]).perp_dot(p - s[2]) / area;
                let b2 = 1.0 - b0 - b1;
                if b0 < 0.0 || b1 < 0.0 || b2 < 0.0 {
                    continue;
                }
                let depth = b0 * c[0] + b1 * c[1] + b2 * c[2];
                let at = y * w + x;
                if first[at].1 == f {
                    first[at].0 = first[at].0.max(depth);
                } else if depth > first[at].0 {
                    second[at] = first[at];
                    first[at] = (depth, f);
                } else if second[at].1 == f || depth > second[at].0 {
                    second[at] = (second[at].0.max(depth), f);
                }
            }
        }
    }
    // in_front[a][b]: pixels where a is nearest and b next.
    let mut in_front: HashMap<(usize, usize), u64> = HashMap::new();
    for (a, b) in first.iter().zip(&second) {
        if a.1 != usize::MAX && b.1 != usize::MAX {
            *in_front.entry((a.1, b.1)).or_default() += 1;
        }
    }
    // b must come before a when a is in front of b more often than the reverse.
    let mut before: Vec<Vec<(usize, u64)>> = vec![Vec::new(); n]; // for a: the parts that precede it
    for (&(a, b), &count) in &in_front {
        let reverse = in_front.get(&(b, a)).copied().unwrap_or(0);
        if count > reverse || (count == reverse && a > b) {
            before[a].push((b, count - reverse));
        }
    }
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(n);
    while order.len() < n {
        // The first unplaced part (in the given order) with nothing unplaced before it; in a
        // cycle, the one whose unplaced predecessors weigh least.
        let pending = |i: usize| before[i].iter().filter(|(b, _)| !placed[*b]).map(|(_, c)| c).sum::<u64>();
        let next = (0..n).filter(|&i| !placed[i]).min_by_key(|&i| (pending(i), i)).unwrap_or(0);
        placed[next] = true;
        order.push(next);
    }
    let mut taken: Vec<Option<PartFill>> = std::mem::take(fills).into_iter().map(Some).collect();
    fills.extend(order.into_iter().filter_map(|i| taken[i].take()));
}

/// A part's band levels and greys (the file's gradient, or the defaults for a part without one).
fn part_gradient(model: &Model, part: Option<u32>) -> (Vec<f64>, Vec<f64>) {
    let record = part.and_then(|p| model.parts.get(p as usize)).and_then(|p| p.record.as_ref());
    let (params, curve) = match record {
        Some(r) => (
            GradientParams {
                q: r.gradient.q.round().clamp(1.0, 255.0) as u32,
                f: r.gradient.f as f32,
                p: r.gradient.p as f32,
            },
            r.gradient.transfer,
        ),
        None => (GradientParams::default(), TransferCurve::default()),
    };
    band_levels(&params, &IntensityTransfer::from_curve(curve))
}
