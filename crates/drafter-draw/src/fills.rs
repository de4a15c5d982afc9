//! Part fills of a line drawing (`drafter draw --fill flat|bands`): each part's
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
//! * **Painter's order is the approximation.** The painted units are *patches*: connected pieces
//!   of one part's triangles that face the same way and share vertices (a baked mesh splits its
//!   vertices at creases, so a patch is a smooth piece of surface: a CAD face, a cylinder's side).
//!   Who is in front of whom is counted at pixel centres (the two nearest patches of every pixel,
//!   closeness interpolated exactly over the front-facing triangles) and the patches are painted
//!   in topological order of that relation, farthest first among those free; a cycle is broken at
//!   the farthest remaining patch. A patch seen both in front of another and behind it (a shaft
//!   sticking out of a gear's face) is then cut into 16-pixel screen tiles, with the one it
//!   conflicts with, and the order counted again. Runs of one part's patches become one group.
//!   drafter-render's `tests/drawing.rs` (`the_fills_match_the_renderers_parts`) holds the
//!   pixels painted with another part than the renderer shows to a small share.
//! * Pieces of one surface painted apart would show hairline seams under anti-aliasing, so each
//!   region is also stroked with its own grey, half a pixel wide (the SVG and the PDF).

use std::collections::HashMap;

use drafter_core::gradient::{GradientParams, IntensityTransfer, TransferCurve};
use glam::{DVec2, DVec3, DVec4, Vec3};

use crate::Projection;
use drafter_scene::model::Model;

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

/// A part's fill, in painter's order within [`crate::Drawing::fills`].
#[derive(Clone, Debug, PartialEq)]
pub struct PartFill {
    /// The part (`None`: triangles of no part).
    pub part: Option<u32>,
    /// Area-weighted mean closeness of its front-facing triangles (the order's key).
    pub closeness: f64,
    pub regions: Vec<Region>,
}

/// The longest side, in cells, of the grid the painter's order is counted on.
const ORDER_GRID: f64 = 2048.0;

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

    /// Adds `other`'s edges (their shared edges cancel).
    fn merge(&mut self, other: Outline) {
        for (edge, count) in other.edges {
            *self.edges.entry(edge).or_default() += count;
        }
        self.points.extend(other.points);
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

/// One painted unit: a connected patch of one part's triangles that face the same way, joined
/// across shared vertices (a baked mesh splits its vertices at creases, so a patch is a smooth
/// piece of surface, a CAD face or a part of one).
struct Patch {
    part: Option<u32>,
    /// Area-weighted mean closeness of its front-facing triangles.
    mean: f64,
    /// Per band (one for `flat`).
    outlines: Vec<Outline>,
}

/// A front-facing triangle for the order: its patch, screen corners and their closeness.
type Front = (usize, [DVec2; 3], [f64; 3]);

/// Patches in front of each other both ways are cut into square screen tiles this many pixels
/// wide, and ordered again.
const SPLIT_TILE: f64 = 16.0;

/// Union-find over a mesh instance's triangles.
fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// A triangle as drawn: its part, whether it faces the eye, its screen and world corners.
#[derive(Clone, Copy)]
struct Drawn {
    part: Option<u32>,
    front: bool,
    screen: [DVec2; 3],
    /// The corners' closeness (module docs of `drawing`), for the order.
    closeness: [f64; 3],
    corners: [DVec3; 3],
}

/// Every triangle of `batch` drawn by `instance` (`None`: behind the eye, or of no screen area).
fn drawn_triangles(
    model: &Model,
    batch: &drafter_scene::model::Batch,
    instance: u32,
    projection: &Projection,
) -> Vec<Option<Drawn>> {
    let Some(world) = model.instance_world_from_object.get(instance as usize) else { return Vec::new() };
    let mirrored = world.determinant() < 0.0;
    let points: Vec<DVec3> = batch
        .vertices
        .iter()
        .map(|v| world.transform_point3(Vec3::from_array(v.position_in_object).as_dvec3()))
        .collect();
    batch
        .indices
        .chunks_exact(3)
        .enumerate()
        .map(|(t, tri)| {
            let corners = [0, 1, 2].map(|k| points.get(tri[k] as usize).copied());
            let [Some(a), Some(b), Some(c)] = corners else { return None };
            let projected = [
                projection.screen_and_closeness(a)?,
                projection.screen_and_closeness(b)?,
                projection.screen_and_closeness(c)?,
            ];
            let (screen, closeness) = (projected.map(|p| p.0), projected.map(|p| p.1));
            // Twice the signed area with y up: positive is counter-clockwise on the screen.
            let area_up = -(screen[1] - screen[0]).perp_dot(screen[2] - screen[0]);
            if area_up == 0.0 {
                return None;
            }
            let front = (area_up > 0.0) != mirrored;
            let part = crate::part_of(model, Some(batch), instance, t);
            Some(Drawn { part, front, screen, closeness, corners: [a, b, c] })
        })
        .collect()
}

/// The patch (a root triangle) of each triangle: triangles of one part and one facing that share
/// an edge (its two vertex indices) are joined; triangles `split` marks only within one screen
/// tile of [`SPLIT_TILE`] pixels (by their centroids).
fn patch_roots(indices: &[u32], drawn: &[Option<Drawn>], split: &dyn Fn(usize) -> bool) -> Vec<u32> {
    let tile = |d: &Drawn| {
        let c = (d.screen[0] + d.screen[1] + d.screen[2]) / 3.0;
        ((c.x / SPLIT_TILE).floor() as i64, (c.y / SPLIT_TILE).floor() as i64)
    };
    let mut parent: Vec<u32> = (0..drawn.len() as u32).collect();
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let Some(d) = drawn[t] else { continue };
        for k in 0..3 {
            let (i, j) = (tri[k], tri[(k + 1) % 3]);
            let edge = (i.min(j), i.max(j));
            let Some(&other) = edges.get(&edge) else {
                edges.insert(edge, t as u32);
                continue;
            };
            let joins = drawn[other as usize].is_some_and(|o| {
                o.part == d.part && o.front == d.front && (!(split(t) || split(other as usize)) || tile(&o) == tile(&d))
            });
            if joins {
                let (ra, rb) = (find(&mut parent, t as u32), find(&mut parent, other));
                parent[ra.max(rb) as usize] = ra.min(rb);
            }
        }
    }
    (0..drawn.len() as u32).map(|t| find(&mut parent, t)).collect()
}

/// Adds a drawn triangle's outline to its patch (whole for `flat`, cut into the part's bands for
/// `bands`).
fn add_to_patch(patch: &mut Patch, d: &Drawn, model: &Model, projection: &Projection, gradient: &(Vec<f64>, Vec<f64>)) {
    let area_up = -(d.screen[1] - d.screen[0]).perp_dot(d.screen[2] - d.screen[0]);
    // Counter-clockwise on the screen (y up), so windings add.
    let order: [usize; 3] = if area_up > 0.0 { [0, 1, 2] } else { [0, 2, 1] };
    let (levels, greys) = gradient;
    if greys.len() == 1 && levels.is_empty() && patch.outlines.len() == 1 {
        patch.outlines[0].add_polygon(&order.map(|k| d.screen[k]));
        return;
    }
    let row = model.parts.get(d.part.unwrap_or(u32::MAX) as usize).map(|p| p.gpu.projector_row);
    let row = row.map_or(DVec4::ZERO, |r| DVec4::from_array(r.map(f64::from)));
    let p_at = |w: DVec3| row.truncate().dot(w - model.origin) + row.w;
    let tri3 = order.map(|k| (d.corners[k], p_at(d.corners[k])));
    let n = greys.len();
    for band in 0..n {
        let lo = (band > 0).then(|| levels[band - 1]);
        let hi = (band + 1 < n).then(|| levels[band]);
        if let Some(piece) = band_piece(&tri3, lo, hi, &|w| projection.to_screen(w)) {
            patch.outlines[band].add_polygon(&piece);
        }
    }
}

/// One mesh instance's triangles as drawn, and the patch of each (`usize::MAX`: none).
struct Instance<'a> {
    batch: &'a drafter_scene::model::Batch,
    drawn: Vec<Option<Drawn>>,
    patch: Vec<usize>,
}

/// Numbers the patches of every instance (`split`: which triangles to cut into tiles, per
/// instance), and returns each patch's part and mean closeness, and the front-facing triangles
/// by patch for the order.
fn number_patches(
    instances: &mut [Instance],
    mode: Fill,
    split: &dyn Fn(usize, usize) -> bool,
) -> (Vec<Option<u32>>, Vec<f64>, Vec<Front>) {
    let (mut parts, mut sums, mut fronts) = (Vec::new(), Vec::<(f64, f64)>::new(), Vec::new());
    for (k, instance) in instances.iter_mut().enumerate() {
        let roots = patch_roots(&instance.batch.indices, &instance.drawn, &|t| split(k, t));
        let mut patch_of_root: HashMap<u32, usize> = HashMap::new();
        instance.patch = vec![usize::MAX; instance.drawn.len()];
        for (t, (d, &root)) in instance.drawn.iter().zip(&roots).enumerate() {
            let Some(d) = d else { continue };
            if mode == Fill::Bands && !d.front {
                continue;
            }
            let p = *patch_of_root.entry(root).or_insert_with(|| {
                parts.push(d.part);
                sums.push((0.0, 0.0));
                parts.len() - 1
            });
            instance.patch[t] = p;
            if d.front {
                let area = (d.screen[1] - d.screen[0]).perp_dot(d.screen[2] - d.screen[0]).abs();
                let cs = d.closeness;
                sums[p].0 += area * (cs[0] + cs[1] + cs[2]) / 3.0;
                sums[p].1 += area;
                fronts.push((p, d.screen, cs));
            }
        }
    }
    let means = sums.iter().map(|&(c, a)| if a > 0.0 { c / a } else { f64::NEG_INFINITY }).collect();
    (parts, means, fronts)
}

/// The fills of `model` under `projection` (module docs), in painter's order.
pub fn fills(model: &Model, projection: &Projection, mode: Fill) -> Vec<PartFill> {
    if mode == Fill::None {
        return Vec::new();
    }
    let mut instances: Vec<Instance> = Vec::new();
    for batch in &model.batches {
        for instance in batch.instances.clone() {
            let drawn = drawn_triangles(model, batch, instance, projection);
            instances.push(Instance { batch, drawn, patch: Vec::new() });
        }
    }
    // The count needs pixels, not the output's resolution: at most ORDER_GRID on the longer side
    // (a 65536-pixel drawing must not allocate a buffer per output pixel).
    let (w, h) = projection.size();
    let scale = (ORDER_GRID / w.max(h).max(1.0)).min(1.0);
    let grid = ((w * scale).ceil().max(1.0) as usize, (h * scale).ceil().max(1.0) as usize);
    let order_of = |means: &[f64], mut fronts: Vec<Front>| {
        if scale < 1.0 {
            for (_, screen, _) in &mut fronts {
                *screen = screen.map(|p| p * scale);
            }
        }
        painter_order(means, &fronts, grid)
    };
    let (mut parts, mut means, fronts) = number_patches(&mut instances, mode, &|_, _| false);
    let (mut order, conflicted) = order_of(&means, fronts);
    // Patches in front of each other both ways are cut into screen tiles and ordered again.
    if conflicted.iter().any(|&c| c) {
        let marks: Vec<Vec<bool>> =
            instances.iter().map(|i| i.patch.iter().map(|&p| p != usize::MAX && conflicted[p]).collect()).collect();
        let fronts;
        (parts, means, fronts) = number_patches(&mut instances, mode, &|k, t| marks[k][t]);
        order = order_of(&means, fronts).0;
    }
    // The outlines of the patches, then the runs of one part.
    let mut gradients: HashMap<Option<u32>, (Vec<f64>, Vec<f64>)> = HashMap::new();
    for &part in &parts {
        gradients.entry(part).or_insert_with(|| match mode {
            Fill::Bands => part_gradient(model, part),
            _ => (Vec::new(), vec![FLAT_GREY]),
        });
    }
    let mut patches: Vec<Patch> = parts
        .iter()
        .zip(&means)
        .map(|(&part, &mean)| Patch {
            part,
            mean,
            outlines: (0..gradients[&part].1.len()).map(|_| Outline::default()).collect(),
        })
        .collect();
    for instance in &instances {
        for (d, &p) in instance.drawn.iter().zip(&instance.patch) {
            if let (Some(d), true) = (d, p != usize::MAX) {
                add_to_patch(&mut patches[p], d, model, projection, &gradients[&d.part]);
            }
        }
    }
    group_runs(order, patches, &gradients)
}

/// The patches in `order`, consecutive patches of one part painted as one group (their shared
/// edges cancel), as the drawing's part fills.
fn group_runs(
    order: Vec<usize>,
    patches: Vec<Patch>,
    gradients: &HashMap<Option<u32>, (Vec<f64>, Vec<f64>)>,
) -> Vec<PartFill> {
    let finish = |run: Patch, out: &mut Vec<PartFill>| {
        let greys = &gradients[&run.part].1;
        let regions: Vec<Region> = run
            .outlines
            .into_iter()
            .zip(greys)
            .enumerate()
            .map(|(band, (outline, &grey))| Region { band: band as u32, grey, loops: outline.loops() })
            .filter(|r| !r.loops.is_empty())
            .collect();
        if !regions.is_empty() {
            out.push(PartFill { part: run.part, closeness: run.mean, regions });
        }
    };
    let mut out = Vec::new();
    let mut taken: Vec<Option<Patch>> = patches.into_iter().map(Some).collect();
    let mut run: Option<Patch> = None;
    for i in order {
        let Some(patch) = taken[i].take() else { continue };
        match &mut run {
            Some(current) if current.part == patch.part => {
                for (mine, theirs) in current.outlines.iter_mut().zip(patch.outlines) {
                    mine.merge(theirs);
                }
            }
            _ => {
                if let Some(done) = run.replace(patch) {
                    finish(done, &mut out);
                }
            }
        }
    }
    if let Some(done) = run {
        finish(done, &mut out);
    }
    out
}

/// The order to paint the patches in (indices; `means`: each one's mean closeness), so that
/// wherever two overlap the one in front comes later, as far as a cycle allows, and which patches
/// are in front of another in some pixels and behind it in others (`fills` cuts those into tiles). Who is in front of whom is counted at pixel centres: the two
/// nearest patches of every pixel, from the front-facing triangles (closeness interpolated
/// exactly: it is affine on the screen). Patches are then taken in topological order of "is behind
/// more often than in front of", the farthest first among those free (by area-weighted mean
/// closeness); when a cycle leaves none free, the farthest remaining patch goes next.
fn painter_order(means: &[f64], fronts: &[Front], (w, h): (usize, usize)) -> (Vec<usize>, Vec<bool>) {
    let n = means.len();
    // Farthest first; ties by index.
    let mut by_depth: Vec<usize> = (0..n).collect();
    by_depth.sort_by(|&a, &b| means[a].total_cmp(&means[b]).then(a.cmp(&b)));
    let mut rank = vec![0usize; n];
    for (r, &i) in by_depth.iter().enumerate() {
        rank[i] = r;
    }
    // Per pixel: the nearest (closeness, patch), and the nearest of another patch.
    let mut first = vec![(f64::NEG_INFINITY, usize::MAX); w * h];
    let mut second = vec![(f64::NEG_INFINITY, usize::MAX); w * h];
    for &(f, s, c) in fronts {
        let area = (s[1] - s[0]).perp_dot(s[2] - s[0]);
        if area == 0.0 {
            continue;
        }
        let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
        let x0 = (lo.x - 0.5).ceil().max(0.0) as usize;
        let y0 = (lo.y - 0.5).ceil().max(0.0) as usize;
        let x1 = ((hi.x - 0.5).floor() + 1.0).clamp(0.0, w as f64) as usize;
        let y1 = ((hi.y - 0.5).floor() + 1.0).clamp(0.0, h as f64) as usize;
        for y in y0..y1 {
            for x in x0..x1 {
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
    // in_front[(a, b)]: pixels where a is nearest and b next.
    let mut in_front: HashMap<(usize, usize), u64> = HashMap::new();
    for (a, b) in first.iter().zip(&second) {
        if a.1 != usize::MAX && b.1 != usize::MAX {
            *in_front.entry((a.1, b.1)).or_default() += 1;
        }
    }
    // Patches seen in front of each other both ways.
    let mut conflicted = vec![false; n];
    for &(a, b) in in_front.keys() {
        if in_front.contains_key(&(b, a)) {
            conflicted[a] = true;
            conflicted[b] = true;
        }
    }
    // b before a where a is in front of b more often than the reverse.
    let mut after: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut blocking = vec![0usize; n];
    let mut pairs: Vec<(&(usize, usize), &u64)> = in_front.iter().collect();
    pairs.sort_unstable();
    for (&(a, b), &count) in pairs {
        let reverse = in_front.get(&(b, a)).copied().unwrap_or(0);
        if count > reverse || (count == reverse && a > b) {
            after[b].push(a);
            blocking[a] += 1;
        }
    }
    let mut free: std::collections::BinaryHeap<std::cmp::Reverse<usize>> =
        (0..n).filter(|&i| blocking[i] == 0).map(|i| std::cmp::Reverse(rank[i])).collect();
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut cursor = 0; // into by_depth: the farthest patch not yet placed
    while order.len() < n {
        let next = match free.pop() {
            Some(std::cmp::Reverse(r)) => by_depth[r],
            None => {
                while placed[by_depth[cursor]] {
                    cursor += 1;
                }
                by_depth[cursor]
            }
        };
        if placed[next] {
            continue;
        }
        placed[next] = true;
        order.push(next);
        for &a in &after[next] {
            blocking[a] = blocking[a].saturating_sub(1);
            if blocking[a] == 0 && !placed[a] {
                free.push(std::cmp::Reverse(rank[a]));
            }
        }
    }
    (order, conflicted)
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
