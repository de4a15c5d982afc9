//! drafter-draw: vector line drawings with exact hidden lines (`drafter draw`), as SVG or PDF.
//!
//! It reads drafter-scene's CPU model (the same [`Model`], camera fit and baked edges the wgpu
//! viewer draws) and links no GPU code.
//!
//! # What is drawn
//! The lines the raster lines pass draws ([`drafter_scene::edges`]): every hard edge of the file (crease,
//! boundary, part border, non-manifold, and tangent edges as [`DrawOptions::smooth`] says) and this
//! view's silhouettes among the file's candidates,
//! decided from face normals computed in f64 from the positions (the stored normals are rounded),
//! under the camera `drafter render --lines` uses ([`Camera::fit`] on
//! [`Model::frame_points`], the same `--view`, `--ortho`, `--size` and field of view).
//!
//! # Visibility, in object space
//! Each edge is split where it passes behind a surface. Under a perspective or parallel projection
//! an edge stays a straight segment on the screen and a triangle a triangle; along the projected
//! edge (parameter `u`), and across a projected triangle, the *closeness* `c` — `1/w` in
//! perspective (w the view depth), minus the normalised depth in parallel projection — is an
//! affine function of the screen position. So the part of an edge that one triangle hides is
//! exact and closed-form: the interval of `u` where the projected point lies inside the projected
//! triangle (three half-planes, each linear in `u`) and the triangle is closer than the edge (one
//! more linear inequality). The hidden part of an edge is the union of these intervals over the
//! triangles a BVH of projected boxes (obvhs, `x`, `y` and `c`; a triangle wholly behind the edge
//! is never visited) returns; its visible part is the rest. Change points are therefore found to
//! rounding, not by sampling; a triangle hides a point only when it is closer by more than a
//! relative `1e-6` of the closeness, so the faces meeting at an edge never hide it, nor a surface
//! touching it within the rounding of the file's `f32` positions. Pieces shorter
//! than [`DrawOptions::tolerance_px`] are dropped.
//!
//! # Visibility first, then what shares pixels
//! Every edge is decided on its own (an edge listed twice in 3D once). Only then are pieces of
//! different edges that overlap on one screen line merged ([`merge`]): the near and far halves of
//! a circle seen edge-on, the front and back edges of a face seen edge-on. A visible piece wins
//! over a hidden one, so which edge comes first never turns a visible line hidden, and a line is
//! drawn once. Pieces sharing end points are then chained into polylines.
//!
//! Limits: edges are the file's edges, so a curved CAD surface's outline is its tessellation's;
//! lines are not clipped against each other's widths (a line passing just behind another's
//! surface edge is split at the edge itself).

use std::collections::HashMap;
use std::time::{Duration, Instant};

use drafter_core::{EDGE_NONE, Topology, Weld};
use glam::{DMat4, DVec2, DVec3, DVec4, Vec3};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use rayon::prelude::*;

use drafter_scene::camera::Camera;
use drafter_scene::edges::LineClass;
use drafter_scene::model::Model;
use drafter_scene::style::{DEFAULT_FOV_Y_DEG, View};

pub mod dxf;
pub mod fills;
pub mod merge;
pub mod sheet;
pub mod style;

pub use crate::dxf::to_dxf;
pub use crate::fills::{Fill, PartFill};
pub use crate::merge::doubled_visible_length;
pub use crate::style::{LineStyle, MM_PER_PX, Pen};

/// What a drawing shows of the lines hidden by surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hidden {
    /// Not drawn (and not computed).
    None,
    /// Drawn dashed, in a group of their own.
    Dashed,
    /// Drawn as thin solid lines, in a group of their own.
    Solid,
}

/// What a drawing shows of tangent edges (the borders between the input's faces that meet below
/// the crease angle: a fillet meeting a plane), after FreeCAD TechDraw's "smooth lines". Wherever
/// a tangent edge is this view's outline (its two faces turn opposite ways to the viewer) it is
/// drawn as a silhouette, whatever this says. Where a tangent edge is hidden it is not drawn at
/// all (hidden smooth lines are left out in ISO 128 practice, by TechDraw's default and by
/// OpenCascade's exporter).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Smooth {
    /// Left out.
    None,
    /// Thin solid lines of their own class, `tangent` (the default: CAD viewers show tangent
    /// edges, and without them a fillet's outline stops in mid-air).
    #[default]
    Thin,
    /// Thin dashed lines of their own class ([`pen_of`]).
    Dashed,
}

/// One view's drawing options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawOptions {
    /// Width and height in pixels (the SVG's user units).
    pub size: (u32, u32),
    pub view: View,
    pub orthographic: bool,
    pub fov_y_deg: f32,
    pub hidden: Hidden,
    /// Pieces shorter than this (pixels) are dropped and end points closer than it joined.
    pub tolerance_px: f64,
    /// Part fills under the lines ([`crate::fills`]).
    pub fill: Fill,
    /// Tangent edges ([`Smooth`]); default [`Smooth::Thin`].
    pub smooth: Smooth,
}

impl Default for DrawOptions {
    fn default() -> Self {
        DrawOptions {
            size: (800, 600),
            view: View::default(),
            orthographic: false,
            fov_y_deg: DEFAULT_FOV_Y_DEG,
            hidden: Hidden::None,
            tolerance_px: 0.05,
            fill: Fill::None,
            smooth: Smooth::Thin,
        }
    }
}

/// A chained polyline of one class, visible or hidden, in pixels (y down).
#[derive(Clone, Debug, PartialEq)]
pub struct Stroke {
    pub class: LineClass,
    pub visible: bool,
    /// The part the line's first piece belongs to (`None` where the model has no such part).
    pub part: Option<u32>,
    pub points: Vec<DVec2>,
}

/// What [`draw`] did, for reports and benchmarks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DrawStats {
    /// Triangles of every instance.
    pub triangles: usize,
    /// Of which hide something in this view: the rest are back faces of closed bodies (their
    /// front faces hide all they would) or have no area on the screen.
    pub occluders: usize,
    /// Edges considered: hard edges of every instance plus this view's silhouettes.
    pub edges: usize,
    /// Of which silhouettes.
    pub silhouettes: usize,
    /// Edges listed twice in 3D (same class, same end points), decided once.
    pub duplicates: usize,
    /// Pieces drawn as part of another on the same screen line (see [`merge`]).
    pub merged: usize,
    /// Triangle-edge pairs tested exactly (after the BVH).
    pub pairs_tested: u64,
    /// Visible and hidden length in pixels.
    pub visible_px: f64,
    pub hidden_px: f64,
    pub elapsed: Duration,
}

/// A view's line drawing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Drawing {
    pub width: u32,
    pub height: u32,
    /// Part fills, farthest part first ([`crate::fills`]); empty without `--fill`.
    pub fills: Vec<PartFill>,
    pub strokes: Vec<Stroke>,
    /// How the tangent strokes are drawn (what [`DrawOptions::smooth`] said).
    pub smooth: Smooth,
    pub stats: DrawStats,
}

/// A projected point: pixels and closeness (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Projected {
    x: f64,
    y: f64,
    c: f64,
}

/// The camera's projection in f64 (its f32 matrix, evaluated without further rounding).
#[derive(Clone, Copy, Debug)]
pub struct Projection {
    clip_from_render: DMat4,
    /// Where the camera looks from, as the raster lines pass queries silhouettes.
    view: drafter_scene::edges::WorldView,
    origin: DVec3,
    orthographic: bool,
    width: f64,
    height: f64,
}

impl Projection {
    /// The projection `drafter render` uses for `options` on `model`.
    pub fn new(model: &Model, options: &DrawOptions) -> Projection {
        let (w, h) = options.size;
        let aspect = w as f32 / h.max(1) as f32;
        let camera = Camera::fit(&model.frame_points, options.view, aspect, options.orthographic, options.fov_y_deg);
        Projection {
            clip_from_render: camera.clip_from_render().as_dmat4(),
            view: drafter_scene::camera::world_view(&camera, model.origin),
            origin: model.origin,
            orthographic: options.orthographic,
            width: f64::from(w),
            height: f64::from(h),
        }
    }

    /// Where the camera looks from, as the silhouette query takes it.
    pub fn view(&self) -> drafter_scene::edges::WorldView {
        self.view
    }

    /// Pixels (x right, y down) of a world point; `None` behind the eye.
    pub fn to_screen(&self, world: DVec3) -> Option<DVec2> {
        self.project(world).map(|p| DVec2::new(p.x, p.y))
    }

    /// The view's width and height in pixels.
    pub(crate) fn size(&self) -> (f64, f64) {
        (self.width, self.height)
    }

    /// Pixels (x right, y down) and closeness of a world point; `None` behind the eye.
    pub(crate) fn screen_and_closeness(&self, world: DVec3) -> Option<(DVec2, f64)> {
        self.project(world).map(|p| (DVec2::new(p.x, p.y), p.c))
    }

    /// Pixels (x right, y down) and closeness of a world point; `None` behind the eye.
    fn project(&self, world: DVec3) -> Option<Projected> {
        let clip: DVec4 = self.clip_from_render * (world - self.origin).extend(1.0);
        if clip.w.is_nan() || clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        let c = if self.orthographic { -ndc.z } else { 1.0 / clip.w };
        Some(Projected { x: (ndc.x + 1.0) * 0.5 * self.width, y: (1.0 - ndc.y) * 0.5 * self.height, c })
    }
}

/// A world-space edge to draw.
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: DVec3,
    b: DVec3,
    class: LineClass,
    part: Option<u32>,
}

/// Every triangle of every instance in world space, with its part.
struct Triangles {
    corners: Vec<[DVec3; 3]>,
    /// Per triangle, its part (a section's uncut parts keep their triangles, [`sheet::section`]).
    parts: Vec<Option<u32>>,
    /// Per triangle of a closed body, the sign (+1 or −1) that turns the normal of its world
    /// corners' winding, `(b − a) × (c − a)`, outward; 0 for a triangle of an open surface or one
    /// that must hide from either side ([`world_triangles_facing`]).
    outward: Vec<i8>,
}

fn world_triangles(model: &Model) -> Triangles {
    world_triangles_facing(model, &[], None)
}

/// [`world_triangles`], with the outward sign of the triangles of closed bodies from `faces` (one
/// per batch, in order; none known where it is shorter). An instance whose box holds `eye` (a
/// perspective view from inside it) keeps 0: its far side faces the eye.
fn world_triangles_facing(model: &Model, faces: &[MeshFaces], eye: Option<DVec3>) -> Triangles {
    let count: usize = model.batches.iter().map(|b| b.indices.len() / 3 * b.instances.len()).sum();
    let (mut corners, mut parts, mut outward) =
        (Vec::with_capacity(count), Vec::with_capacity(count), Vec::with_capacity(count));
    for (b, batch) in model.batches.iter().enumerate() {
        let sides = faces.get(b).map(|f| f.outward.as_slice()).unwrap_or(&[]);
        for instance in batch.instances.clone() {
            let Some(world) = model.instance_world_from_object.get(instance as usize) else { continue };
            let points: Vec<DVec3> = batch
                .vertices
                .iter()
                .map(|v| world.transform_point3(Vec3::from_array(v.position_in_object).as_dvec3()))
                .collect();
            // A mirroring instance turns every winding the other way.
            let mirror: i8 = if world.determinant() < 0.0 { -1 } else { 1 };
            let inside = eye.is_some_and(|eye| {
                let (lo, hi) =
                    points.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
                let pad = (hi - lo).max_element() * 1e-6;
                eye.cmpge(lo - pad).all() && eye.cmple(hi + pad).all()
            });
            for (k, t) in batch.indices.chunks_exact(3).enumerate() {
                let p = |k: usize| points.get(t[k] as usize).copied();
                if let (Some(a), Some(b), Some(c)) = (p(0), p(1), p(2)) {
                    corners.push([a, b, c]);
                    parts.push(part_of(model, Some(batch), instance, k));
                    let side = if inside { 0 } else { sides.get(k).copied().unwrap_or(0) };
                    outward.push(side * mirror);
                }
            }
        }
    }
    Triangles { corners, parts, outward }
}

/// The welded connectivity of a batch's mesh ([`Topology`], welded exactly: the hard edges' and
/// candidates' end points are the file's `f32`s), the normal of each of its faces, and which of
/// them bound closed bodies.
struct MeshFaces {
    topology: Topology,
    /// Per triangle, its normal (f64, unnormalised) from the file's positions.
    normals: Vec<DVec3>,
    /// Per triangle, the sign that turns its normal outward where its component is a closed body
    /// ([`sheet::section::closed_components`]), else 0.
    outward: Vec<i8>,
}

impl MeshFaces {
    /// The faces of `batch` (the mesh's triangles in its order).
    fn of_batch(batch: &drafter_scene::model::Batch) -> MeshFaces {
        let positions: Vec<Vec3> = batch.vertices.iter().map(|v| Vec3::from_array(v.position_in_object)).collect();
        let triangles: Vec<[u32; 3]> = batch.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        if triangles.iter().flatten().any(|&v| v as usize >= positions.len()) {
            return MeshFaces { topology: Topology::default(), normals: Vec::new(), outward: Vec::new() };
        }
        let normals = triangles
            .iter()
            .map(|t| {
                let p = t.map(|v| positions[v as usize].as_dvec3());
                (p[1] - p[0]).cross(p[2] - p[0])
            })
            .collect();
        let topology = Topology::from_triangles(&positions, &triangles, Weld::Exact);
        let welded: Vec<DVec3> = topology.welded_positions.iter().map(|p| p.as_dvec3()).collect();
        let sides = sheet::section::closed_components(&topology, &welded);
        let outward = topology.face_component.iter().map(|&c| sides.get(c as usize).copied().unwrap_or(0)).collect();
        MeshFaces { topology, normals, outward }
    }

    /// The normals of the two faces at the edge of corner `3·t + k` (v_k → v_(k+1) of triangle t),
    /// when exactly two faces meet there, in triangle order.
    fn pair(&self, corner: u32) -> Option<[DVec3; 2]> {
        let edge = *self.topology.face_edges.get(corner as usize / 3)?.get(corner as usize % 3)?;
        if edge == EDGE_NONE {
            return None;
        }
        match *self.topology.faces_of_edge(edge as usize) {
            [f, g] => Some([*self.normals.get(f as usize)?, *self.normals.get(g as usize)?]),
            _ => None,
        }
    }
}

/// The batch that draws `instance` (looked up once per instance, not per edge).
fn batch_of(model: &Model, instance: u32) -> Option<&drafter_scene::model::Batch> {
    model.batches.iter().find(|b| b.instances.contains(&instance))
}

/// The faces of every batch of `model`, in order.
fn faces_of_batches(model: &Model) -> Vec<MeshFaces> {
    model.batches.par_iter().map(MeshFaces::of_batch).collect()
}

/// The part of mesh triangle `t` drawn by `instance` through `batch`.
pub(crate) fn part_of(
    model: &Model,
    batch: Option<&drafter_scene::model::Batch>,
    instance: u32,
    t: usize,
) -> Option<u32> {
    let batch = batch?;
    let v = *batch.indices.get(3 * t)? as usize;
    let label = batch.vertices.get(v)?.label;
    let gpu = model.instances.get(instance as usize)?;
    if label >= gpu.label_count {
        return None;
    }
    model.label_to_part.get((gpu.label_base + label) as usize).copied()
}

/// The edges of `model` for a view from `projection`: hard edges of every instance and the
/// view's silhouettes, in world space.
fn view_edges(model: &Model, projection: &Projection, smooth: Smooth, batches: &[MeshFaces]) -> (Vec<Edge>, usize) {
    let mut edges = Vec::new();
    let empty = MeshFaces { topology: Topology::default(), normals: Vec::new(), outward: Vec::new() };
    let faces_of: Vec<&MeshFaces> = model
        .lines
        .meshes
        .iter()
        .map(|mesh| {
            let batch = model.batches.iter().position(|b| b.instances.contains(&mesh.instances.start));
            batch.and_then(|b| batches.get(b)).unwrap_or(&empty)
        })
        .collect();
    for (mesh, faces) in model.lines.meshes.iter().zip(&faces_of) {
        for instance in mesh.instances.clone() {
            let Some(world) = model.instance_world_from_object.get(instance as usize) else { continue };
            let batch = batch_of(model, instance);
            let object_from_world =
                model.lines.object_from_world.get(instance as usize).copied().unwrap_or(DMat4::IDENTITY);
            for (k, &([a, b], class)) in mesh.hard.iter().enumerate() {
                let corner = mesh.hard_corners.get(k).copied();
                let part = corner.and_then(|c| part_of(model, batch, instance, (c / 3) as usize));
                // A crease or tangent edge whose faces turn opposite ways to the viewer lies on the
                // contour: drawn as a silhouette, as the raster lines pass draws a crease across
                // which the depth jumps (Gooch et al. 1999 draw every silhouette black and heavy).
                // A tangent edge is never a candidate, so this is its only way to be an outline.
                let class = match (class, corner.and_then(|c| faces.pair(c))) {
                    (LineClass::Crease | LineClass::Tangent, Some(normals)) => {
                        let middle = (a.as_dvec3() + b.as_dvec3()) * 0.5;
                        let towards = match projection.view {
                            drafter_scene::edges::WorldView::Perspective { eye } => {
                                object_from_world.transform_point3(eye) - middle
                            }
                            drafter_scene::edges::WorldView::Orthographic { direction } => {
                                object_from_world.transform_vector3(direction)
                            }
                        };
                        // Faces turned opposite ways, or one face exactly edge-on beside one that
                        // is not: a face seen edge-on is seen as a line, and both its borders lie
                        // on the contour (a slot's wall seen edge-on, tangent to its round end).
                        // Edge-on within the rounding of the camera's f32 matrix (the view
                        // direction comes out of it about 1e-7 off an axis).
                        let towards = towards.normalize_or_zero();
                        let (s0, s1) = (normals[0].dot(towards), normals[1].dot(towards));
                        let lengths = (normals[0].length(), normals[1].length());
                        let (e0, e1) = (s0.abs() <= EDGE_ON * lengths.0, s1.abs() <= EDGE_ON * lengths.1);
                        if (s0 * s1 < 0.0 && !e0 && !e1) || e0 != e1 { LineClass::Silhouette } else { class }
                    }
                    (class, _) => class,
                };
                if class == LineClass::Tangent && smooth == Smooth::None {
                    continue;
                }
                edges.push(Edge {
                    a: world.transform_point3(a.as_dvec3()),
                    b: world.transform_point3(b.as_dvec3()),
                    class,
                    part,
                });
            }
        }
    }
    // Silhouettes exactly, from the faces' normals computed in f64 from the positions: the file's
    // stored normals (and the hierarchies built on them) are rounded, and a face within a few
    // hundredths of a degree of edge-on can come out facing the other way, which moves a
    // cylinder's outline one column back (found against OpenCascade, docs/drawing.md). A drawing
    // is made once, so every candidate is tested. A face exactly edge-on counts as facing away, so
    // one of its two edges is the outline.
    let mut silhouettes = 0;
    for (mesh, faces) in model.lines.meshes.iter().zip(&faces_of) {
        let Some(candidates) = &mesh.silhouettes else { continue };
        let normals: Vec<Option<[DVec3; 2]>> = candidates.corners.iter().map(|&c| faces.pair(c)).collect();
        for instance in mesh.instances.clone() {
            let Some(world) = model.instance_world_from_object.get(instance as usize) else { continue };
            let batch = batch_of(model, instance);
            let object_from_world =
                model.lines.object_from_world.get(instance as usize).copied().unwrap_or(DMat4::IDENTITY);
            for (k, (&[a, b], n)) in candidates.segments.iter().zip(&normals).enumerate() {
                let Some([n1, n2]) = n else { continue };
                let towards = match projection.view {
                    drafter_scene::edges::WorldView::Perspective { eye } => {
                        object_from_world.transform_point3(eye) - a.as_dvec3()
                    }
                    drafter_scene::edges::WorldView::Orthographic { direction } => {
                        object_from_world.transform_vector3(direction)
                    }
                };
                if (n1.dot(towards) > 0.0) == (n2.dot(towards) > 0.0) {
                    continue;
                }
                silhouettes += 1;
                let corner = candidates.corners.get(k).copied().unwrap_or(0);
                edges.push(Edge {
                    a: world.transform_point3(a.as_dvec3()),
                    b: world.transform_point3(b.as_dvec3()),
                    class: LineClass::Silhouette,
                    part: part_of(model, batch, instance, (corner / 3) as usize),
                });
            }
        }
    }
    (edges, silhouettes)
}

/// A face whose unit normal is within this of perpendicular to the view is seen edge-on (for a
/// crease or tangent edge on the contour, [`view_edges`]).
const EDGE_ON: f64 = 1e-6;

/// Closeness tolerance: a triangle hides a point when closer by more than this share of the
/// point's closeness. 1e-7 let a part's face touching another's silhouette within a few `f32`
/// roundings (1.9e-7 of the distance to the eye, the sample assembly's axis views in perspective)
/// hide it; brute force, which ignores hits within 1e-6 of the point, saw it visible.
const CLOSER_BY: f64 = 1e-6;

/// The interval of `u` in [0, 1] over which the projected triangle `t` hides the projected
/// segment `a → b`, if any (see the module docs).
fn hidden_interval(a: Projected, b: Projected, t: &[Projected; 3]) -> Option<(f64, f64)> {
    let area = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x);
    if area == 0.0 || !area.is_finite() {
        return None;
    }
    let sign = area.signum();
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    // Inside: each edge's half-plane, linear in u.
    for k in 0..3 {
        let (p, q) = (t[k], t[(k + 1) % 3]);
        let side = |x: f64, y: f64| sign * ((q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x));
        let (s0, s1) = (side(a.x, a.y), side(b.x, b.y));
        if !clip_positive(s0, s1, &mut lo, &mut hi) {
            return None;
        }
    }
    // Closer: the triangle's closeness at the segment's points, by barycentric coordinates
    // (affine in the screen position, so in u), against the segment's own.
    let closeness_at = |x: f64, y: f64| {
        let w1 = ((x - t[0].x) * (t[2].y - t[0].y) - (y - t[0].y) * (t[2].x - t[0].x)) / area;
        let w2 = ((t[1].x - t[0].x) * (y - t[0].y) - (t[1].y - t[0].y) * (x - t[0].x)) / area;
        t[0].c + w1 * (t[1].c - t[0].c) + w2 * (t[2].c - t[0].c)
    };
    let margin = |c: f64| CLOSER_BY * c.abs().max(f64::MIN_POSITIVE);
    let d0 = closeness_at(a.x, a.y) - a.c - margin(a.c);
    let d1 = closeness_at(b.x, b.y) - b.c - margin(b.c);
    if !clip_positive(d0, d1, &mut lo, &mut hi) || hi <= lo {
        return None;
    }
    Some((lo, hi))
}

/// Narrows `[lo, hi]` to where `f(u) = f0 + u (f1 − f0) > 0`; false when nothing is left.
fn clip_positive(f0: f64, f1: f64, lo: &mut f64, hi: &mut f64) -> bool {
    if !(f0.is_finite() && f1.is_finite()) {
        return false;
    }
    if f0 <= 0.0 && f1 <= 0.0 {
        return false;
    }
    if f0 > 0.0 && f1 > 0.0 {
        return true;
    }
    let root = f0 / (f0 - f1);
    if f0 > 0.0 {
        *hi = hi.min(root);
    } else {
        *lo = lo.max(root);
    }
    *hi > *lo
}

/// Intervals of an edge's parameter this close are one: two triangles sharing a side hide the
/// stretches on either side of where the edge crosses it, and the two ends computed from each
/// triangle's own corners can miss each other by a rounding.
const SAME_U: f64 = 1e-9;

/// The union of `intervals` (sorted in place), merged ([`SAME_U`]).
fn union(intervals: &mut [(f64, f64)]) -> Vec<(f64, f64)> {
    intervals.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Vec<(f64, f64)> = Vec::new();
    for &(lo, hi) in intervals.iter() {
        match out.last_mut() {
            Some(last) if lo <= last.1 + SAME_U => last.1 = last.1.max(hi),
            _ => out.push((lo, hi)),
        }
    }
    out
}

/// The occlusion structure: projected triangles and a BVH over their boxes.
struct Occluders {
    projected: Vec<[Projected; 3]>,
    /// Per triangle, its screen box ([`padded_box`]), tested before the triangle itself.
    boxes: Vec<Aabb>,
    bvh: obvhs::bvh2::Bvh2,
}

impl Occluders {
    fn new(triangles: &Triangles, projection: &Projection) -> Occluders {
        let projected: Vec<[Projected; 3]> = triangles
            .corners
            .par_iter()
            .zip(&triangles.outward)
            .filter_map(|(t, &outward)| {
                let p = [projection.project(t[0])?, projection.project(t[1])?, projection.project(t[2])?];
                // A triangle of no area on the screen hides nothing ([`hidden_interval`]), nor does
                // a closed body's back face (its front faces hide all it would).
                let area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
                (area != 0.0 && area.is_finite() && f64::from(outward) * area * FRONT >= 0.0).then_some(p)
            })
            .collect();
        // The BVH holds runs of GROUP triangles in the mesh's order (a tessellation lists
        // neighbours together), not single triangles: a quarter of the boxes to build over.
        let boxes: Vec<Aabb> = projected.par_iter().map(padded_box).collect();
        let runs: Vec<Aabb> = boxes
            .par_chunks(GROUP)
            .map(|run| run.iter().copied().reduce(|a, b| a.union(&b)).unwrap_or_default())
            .collect();
        let params = BvhBuildParams { max_prims_per_leaf: 2, ..BvhBuildParams::very_fast_build() };
        let bvh = build_bvh2(&runs, params, &mut Duration::default());
        Occluders { projected, boxes, bvh }
    }

    /// The hidden intervals of the projected segment `a → b`.
    fn hidden(&self, a: Projected, b: Projected, tested: &mut u64) -> Vec<(f64, f64)> {
        // A long edge is queried in screen pieces of at most QUERY_PIECE_PX, each with its own
        // box: a diagonal across the frame would otherwise visit every triangle of the frame.
        // Closeness is affine along the edge, so a piece's ends interpolate exactly and its
        // intervals map back to the edge's parameter.
        let length = (b.x - a.x).hypot(b.y - a.y);
        let pieces = ((length / QUERY_PIECE_PX).ceil() as usize).clamp(1, 4096);
        let at = |u: f64| Projected { x: a.x + (b.x - a.x) * u, y: a.y + (b.y - a.y) * u, c: a.c + (b.c - a.c) * u };
        let mut intervals = Vec::new();
        for k in 0..pieces {
            let (u0, u1) = (k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64);
            let (pa, pb) = (if k == 0 { a } else { at(u0) }, if k + 1 == pieces { b } else { at(u1) });
            let lo = glam::Vec3A::new(pa.x.min(pb.x) as f32, pa.y.min(pb.y) as f32, pa.c.min(pb.c) as f32);
            let hi = glam::Vec3A::new(pa.x.max(pb.x) as f32, pa.y.max(pb.y) as f32, f32::MAX);
            let query = Aabb { min: lo - pad(lo), max: hi + pad(hi) };
            // How far from the piece's start the intervals found so far hide it without a gap,
            // and those beyond: once the whole piece is hidden, no other triangle can change it.
            let (mut reach, mut beyond) = (0.0f64, Vec::<(f64, f64)>::new());
            let total = self.projected.len() as u32;
            let mut visit = |first: usize, count: usize| {
                let runs = &self.bvh.primitive_indices[first..first + count];
                for p in runs.iter().flat_map(|&run| GROUP as u32 * run..(GROUP as u32 * (run + 1)).min(total)) {
                    *tested += 1;
                    // The test a BVH leaf of single triangles makes, for the triangles of a run.
                    if !self.boxes[p as usize].intersect_aabb(&query) {
                        continue;
                    }
                    let Some((lo, hi)) = hidden_interval(pa, pb, &self.projected[p as usize]) else { continue };
                    intervals.push((u0 + lo * (u1 - u0), u0 + hi * (u1 - u0)));
                    if lo > reach {
                        beyond.push((lo, hi));
                        continue;
                    }
                    reach = reach.max(hi);
                    while let Some(k) = beyond.iter().position(|&(lo, _)| lo <= reach) {
                        reach = reach.max(beyond.swap_remove(k).1);
                    }
                    if reach >= 1.0 {
                        return false;
                    }
                }
                true
            };
            self.traverse_nearest_first(&query, &mut visit);
        }
        union(&mut intervals)
    }
}

/// The sign of the screen area (x right, y down) of a triangle whose winding's normal points
/// towards the eye: the projection keeps orientation (w > 0 at every kept corner) and the screen's
/// y runs down, so a counter-clockwise front face turns clockwise.
const FRONT: f64 = -1.0;

impl Occluders {
    /// Visits the leaves of the BVH whose boxes meet `query`, the nearer child of each node first
    /// (by the closeness its box reaches), until `visit` says stop: a triangle near the eye that
    /// hides a whole piece is then met early. obvhs's own traversal visits children in a fixed
    /// order, so this is written here.
    fn traverse_nearest_first(&self, query: &Aabb, visit: &mut impl FnMut(usize, usize) -> bool) {
        let nodes = &self.bvh.nodes;
        let Some(root) = nodes.first() else { return };
        if !root.aabb().intersect_aabb(query) {
            return;
        }
        if root.is_leaf() {
            visit(root.first_index as usize, root.prim_count as usize);
            return;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(root.first_index);
        while let Some(first) = stack.pop() {
            let (a, b) = (&nodes[first as usize], &nodes[first as usize + 1]);
            // Nearer (larger closeness) first: pushed last.
            let (near, far) = if a.aabb().max.z >= b.aabb().max.z { (a, b) } else { (b, a) };
            let mut deferred = None;
            for (k, node) in [near, far].into_iter().enumerate() {
                if !node.aabb().intersect_aabb(query) {
                    continue;
                }
                if node.is_leaf() {
                    if !visit(node.first_index as usize, node.prim_count as usize) {
                        return;
                    }
                } else if k == 0 {
                    deferred = Some(node.first_index);
                } else {
                    stack.push(node.first_index);
                }
            }
            if let Some(first) = deferred {
                stack.push(first);
            }
        }
    }
}

/// Triangles per BVH primitive ([`Occluders::new`]).
const GROUP: usize = 4;

/// The longest stretch of an edge one BVH query covers, in pixels.
const QUERY_PIECE_PX: f64 = 24.0;

/// Twice an `f32` rounding of `v` and a little: boxes in `f32` that still contain the `f64`
/// values they bound.
fn pad(v: glam::Vec3A) -> glam::Vec3A {
    v.abs() * 4.0 * f32::EPSILON + glam::Vec3A::splat(1e-6)
}

fn padded_box(t: &[Projected; 3]) -> Aabb {
    let lo = glam::Vec3A::new(
        t[0].x.min(t[1].x).min(t[2].x) as f32,
        t[0].y.min(t[1].y).min(t[2].y) as f32,
        t[0].c.min(t[1].c).min(t[2].c) as f32,
    );
    let hi = glam::Vec3A::new(
        t[0].x.max(t[1].x).max(t[2].x) as f32,
        t[0].y.max(t[1].y).max(t[2].y) as f32,
        t[0].c.max(t[1].c).max(t[2].c) as f32,
    );
    Aabb { min: lo - pad(lo), max: hi + pad(hi) }
}

/// A piece of an edge on the screen.
#[derive(Clone, Copy, Debug)]
struct Piece {
    a: DVec2,
    b: DVec2,
    class: LineClass,
    visible: bool,
    part: Option<u32>,
}

/// One edge of the view with the parts of it that surfaces hide.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeVisibility {
    /// World-space end points.
    pub a: DVec3,
    pub b: DVec3,
    pub class: LineClass,
    pub part: Option<u32>,
    /// The end points on the screen (pixels, y down).
    pub screen: [DVec2; 2],
    /// Hidden intervals of the screen parameter `u` (0 at `screen[0]`, 1 at `screen[1]`),
    /// sorted and disjoint.
    pub hidden: Vec<(f64, f64)>,
}

/// Every edge of a view (one listed twice in 3D: once) and what hides it, each decided on its own.
#[derive(Clone, Debug)]
pub struct Visibility {
    pub projection: Projection,
    pub edges: Vec<EdgeVisibility>,
    pub stats: DrawStats,
}

/// The edges of `model` in the view `options` describe, each with its hidden intervals.
pub fn visibility(model: &Model, options: &DrawOptions) -> Visibility {
    visibility_in(model, options, Projection::new(model, options))
}

/// [`visibility`] under a given projection (a drawing sheet's views, [`sheet`]) instead of the
/// camera `options` fit; `options.view`, `orthographic` and `size` are then not read.
pub fn visibility_in(model: &Model, options: &DrawOptions, projection: Projection) -> Visibility {
    visibility_clipped(model, options, projection, None)
}

/// [`visibility_in`] of what a section leaves ([`sheet::section::Clip`]): edges and occluders cut
/// at its plane, and the cut faces hiding what lies behind them.
pub fn visibility_clipped(
    model: &Model,
    options: &DrawOptions,
    projection: Projection,
    clip: Option<&sheet::section::Clip>,
) -> Visibility {
    visibility_from(model, &ModelFaces::of(model), options, projection, clip, true)
}

/// [`visibility_in`] with every triangle an occluder, the back faces of closed bodies too: what
/// leaving them out must not change (the tests compare the two).
#[doc(hidden)]
pub fn visibility_every_face(model: &Model, options: &DrawOptions, projection: Projection) -> Visibility {
    visibility_from(model, &ModelFaces::of(model), options, projection, None, false)
}

/// What the views of one model share: the welded faces of every batch and, once an orthographic
/// view asks for them, the world triangles with their closed bodies' outward signs (a parallel
/// view has no eye inside a body). Computed once for the views of a sheet.
pub(crate) struct ModelFaces {
    batches: Vec<MeshFaces>,
    orthographic: std::sync::OnceLock<Triangles>,
}

impl ModelFaces {
    pub(crate) fn of(model: &Model) -> ModelFaces {
        ModelFaces { batches: faces_of_batches(model), orthographic: std::sync::OnceLock::new() }
    }
}

fn visibility_from(
    model: &Model,
    faces: &ModelFaces,
    options: &DrawOptions,
    projection: Projection,
    clip: Option<&sheet::section::Clip>,
    front_faces_only: bool,
) -> Visibility {
    let start = Instant::now();
    // Back faces of closed bodies hide nothing their front faces do not (a line of sight into a
    // body enters it through a front face first), so they are left out of the occluders; not
    // with a section, whose cut opens the bodies.
    let eye = match projection.view {
        drafter_scene::edges::WorldView::Perspective { eye } => Some(eye),
        drafter_scene::edges::WorldView::Orthographic { .. } => None,
    };
    let (mut edges, silhouettes) = view_edges(model, &projection, options.smooth, &faces.batches);
    let owned;
    let triangles: &Triangles = match (clip, front_faces_only, eye) {
        // Every orthographic view of a sheet takes the same world triangles.
        (None, true, None) => faces.orthographic.get_or_init(|| world_triangles_facing(model, &faces.batches, None)),
        (None, true, Some(eye)) => {
            owned = world_triangles_facing(model, &faces.batches, Some(eye));
            &owned
        }
        (Some(clip), _, _) => {
            let mut cut = world_triangles(model);
            clip.keep_below(&mut cut, &mut edges);
            owned = cut;
            &owned
        }
        (None, false, _) => {
            owned = world_triangles(model);
            &owned
        }
    };
    let occluders = Occluders::new(triangles, &projection);
    let mut stats = DrawStats {
        triangles: triangles.corners.len(),
        occluders: occluders.projected.len(),
        edges: edges.len(),
        silhouettes,
        ..Default::default()
    };
    // An edge listed twice in 3D (the same class between the same world points: a border of two
    // parts, coincident instances) is decided once: its copies hide and are hidden alike. Edges
    // that only meet on the screen are each decided on their own; where their pieces overlap,
    // `merge` picks what is drawn after visibility is known.
    let mut seen = std::collections::HashSet::new();
    let mut unique = Vec::new();
    for edge in &edges {
        let (Some(a), Some(b)) = (projection.project(edge.a), projection.project(edge.b)) else { continue };
        let (ka, kb) = (edge.a.to_array().map(f64::to_bits), edge.b.to_array().map(f64::to_bits));
        let ordered = if ka <= kb { (ka, kb) } else { (kb, ka) };
        if !seen.insert((ordered, edge.class as u32)) {
            stats.duplicates += 1;
            continue;
        }
        unique.push((edge, a, b));
    }
    // Edges are independent: on the thread pool, in order (the result does not depend on the
    // thread count).
    let answers: Vec<(Vec<(f64, f64)>, u64)> = unique
        .par_iter()
        .map(|(_, a, b)| {
            let mut tested = 0;
            let hidden = occluders.hidden(*a, *b, &mut tested);
            (if let Some(clip) = clip { clip.hide(*a, *b, hidden) } else { hidden }, tested)
        })
        .collect();
    let mut out = Vec::with_capacity(unique.len());
    for ((edge, a, b), (hidden, tested)) in unique.into_iter().zip(answers) {
        stats.pairs_tested += tested;
        out.push(EdgeVisibility {
            a: edge.a,
            b: edge.b,
            class: edge.class,
            part: edge.part,
            screen: [DVec2::new(a.x, a.y), DVec2::new(b.x, b.y)],
            hidden,
        });
    }
    stats.elapsed = start.elapsed();
    Visibility { projection, edges: out, stats }
}

/// Draws `model` as `options` say.
pub fn draw(model: &Model, options: &DrawOptions) -> Drawing {
    draw_in(model, options, Projection::new(model, options))
}

/// [`draw`] under a given projection (a drawing sheet's views, [`sheet`]) instead of the camera
/// `options` fit; `options.view` and `orthographic` are then not read.
pub fn draw_in(model: &Model, options: &DrawOptions, projection: Projection) -> Drawing {
    draw_clipped(model, options, projection, None)
}

/// [`draw_in`] of what a section leaves ([`visibility_clipped`]).
pub fn draw_clipped(
    model: &Model,
    options: &DrawOptions,
    projection: Projection,
    clip: Option<&sheet::section::Clip>,
) -> Drawing {
    draw_with_faces(model, &ModelFaces::of(model), options, projection, clip)
}

/// [`draw_clipped`] with the model's faces computed once for several views ([`sheet`]).
pub(crate) fn draw_with_faces(
    model: &Model,
    faces: &ModelFaces,
    options: &DrawOptions,
    projection: Projection,
    clip: Option<&sheet::section::Clip>,
) -> Drawing {
    let start = Instant::now();
    let Visibility { edges, mut stats, projection } = visibility_from(model, faces, options, projection, clip, true);
    let fills = crate::fills::fills(model, &projection, options.fill);
    let tolerance = options.tolerance_px.max(0.0);
    let mut pieces = Vec::new();
    for edge in &edges {
        let [pa, pb] = edge.screen;
        let length = pa.distance(pb);
        if length < tolerance {
            continue;
        }
        let at = |u: f64| pa + (pb - pa) * u;
        let mut push = |lo: f64, hi: f64, visible: bool| {
            if (hi - lo) * length >= tolerance {
                pieces.push(Piece { a: at(lo), b: at(hi), class: edge.class, visible, part: edge.part });
            }
        };
        // Hidden tangent edges are not drawn, whatever `smooth` says: ISO 128 drafting and
        // TechDraw's default leave hidden smooth lines out, and so does OpenCascade's exporter.
        let hidden_drawn = options.hidden != Hidden::None && edge.class != LineClass::Tangent;
        let mut from = 0.0;
        for &(lo, hi) in &edge.hidden {
            push(from, lo, true);
            if hidden_drawn {
                push(lo, hi, false);
            }
            from = hi;
        }
        push(from, 1.0, true);
    }
    // Visibility first, then what shares pixels: a visible piece over a hidden one.
    let (pieces, merged) = merge::merge(&pieces, tolerance);
    stats.merged = merged;
    for p in &pieces {
        let length = p.a.distance(p.b);
        if p.visible {
            stats.visible_px += length;
        } else {
            stats.hidden_px += length;
        }
    }
    let strokes = chain(&pieces, tolerance);
    stats.elapsed = start.elapsed();
    Drawing { width: options.size.0, height: options.size.1, fills, strokes, smooth: options.smooth, stats }
}

/// Joins pieces of one class and visibility that meet end to end (within `tolerance`) into
/// polylines, deterministically (pieces in order, each chain walked forward then backward).
fn chain(pieces: &[Piece], tolerance: f64) -> Vec<Stroke> {
    let quantum = tolerance.max(1e-9);
    let cell = |p: DVec2| ((p.x / quantum).round() as i64, (p.y / quantum).round() as i64);
    // End point cell → pieces touching it, per class and visibility.
    let mut ends: HashMap<(u32, bool, (i64, i64)), Vec<usize>> = HashMap::new();
    for (i, p) in pieces.iter().enumerate() {
        for end in [p.a, p.b] {
            ends.entry((p.class as u32, p.visible, cell(end))).or_default().push(i);
        }
    }
    let mut used = vec![false; pieces.len()];
    let mut strokes = Vec::new();
    for start in 0..pieces.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let first = pieces[start];
        let mut points = std::collections::VecDeque::from([first.a, first.b]);
        // Forward from b, then backward from a.
        for forward in [true, false] {
            loop {
                let tip =
                    if forward { *points.back().unwrap_or(&first.b) } else { *points.front().unwrap_or(&first.a) };
                let next = ends
                    .get(&(first.class as u32, first.visible, cell(tip)))
                    .and_then(|list| list.iter().copied().find(|&j| !used[j]));
                let Some(j) = next else { break };
                used[j] = true;
                let p = pieces[j];
                let other = if cell(p.a) == cell(tip) { p.b } else { p.a };
                if forward {
                    points.push_back(other);
                } else {
                    points.push_front(other);
                }
            }
        }
        strokes.push(Stroke { class: first.class, visible: first.visible, part: first.part, points: points.into() });
    }
    strokes
}

/// The order the writers draw the classes in, within the hidden lines and then the visible ones:
/// silhouettes last, on top ([`to_svg`], [`to_pdf`], [`dxf::to_dxf`]).
pub const CLASS_ORDER: [LineClass; 6] = [
    LineClass::Tangent,
    LineClass::Crease,
    LineClass::Boundary,
    LineClass::PartBorder,
    LineClass::NonManifold,
    LineClass::Silhouette,
];

/// The pen of a stroke of `class` in `drawing`: `style`'s ([`LineStyle::pen`]), with visible
/// tangent edges dashed where the drawing was made with [`Smooth::Dashed`]: dashes of 6 and gaps
/// of 3 line widths, half the dash of ISO 128's dashed line (12 and 3) that hidden lines use, so
/// the two read apart.
pub fn pen_of(drawing: &Drawing, style: LineStyle, class: LineClass, visible: bool, hidden: Hidden) -> Pen {
    let mut pen = style.pen(class, visible, hidden);
    if visible && class == LineClass::Tangent && drawing.smooth == Smooth::Dashed {
        let times = |k: f64| match pen.width {
            style::Length::Mm(w) => style::Length::Mm(k * w),
            style::Length::Px(w) => style::Length::Px(k * w),
        };
        pen.dash = Some([times(6.0), times(3.0)]);
    }
    pen
}

/// The strokes in the order the writers draw them: hidden ones first (when `hidden` draws them),
/// each visibility by [`CLASS_ORDER`], each class in the drawing's order. One SVG path, one PDF
/// subpath, one DXF polyline per stroke, in this order.
pub fn strokes_in_order(drawing: &Drawing, hidden: Hidden) -> impl Iterator<Item = &Stroke> {
    [false, true].into_iter().filter(move |&visible| visible || hidden != Hidden::None).flat_map(move |visible| {
        CLASS_ORDER
            .into_iter()
            .flat_map(move |class| drawing.strokes.iter().filter(move |st| st.visible == visible && st.class == class))
    })
}

/// The class names of the SVG groups and paths.
pub fn class_name(class: LineClass) -> &'static str {
    match class {
        LineClass::Silhouette => "silhouette",
        LineClass::Crease => "crease",
        LineClass::Boundary => "boundary",
        LineClass::PartBorder => "part-border",
        LineClass::NonManifold => "non-manifold",
        LineClass::Tangent => "tangent",
    }
}

/// The drawing as SVG: a group per visibility, a group per class inside, one path per stroke
/// carrying its part (`class="part-N"`); coordinates at a hundredth of a pixel (or the tolerance,
/// if finer), in a viewBox of the drawing's pixels on a page of [`MM_PER_PX`] millimetres a pixel
/// (96 per inch), so the `style`'s widths and dashes in millimetres are exact on paper
/// ([`style`]). Restyle with CSS on the ids and classes.
pub fn to_svg(drawing: &Drawing, hidden: Hidden, style: LineStyle) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let (w, h) = (drawing.width, drawing.height);
    let (page_w, page_h) = (style::short(f64::from(w) * MM_PER_PX), style::short(f64::from(h) * MM_PER_PX));
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{page_w}mm" height="{page_h}mm" viewBox="0 0 {w} {h}" fill="none" stroke-linecap="round" stroke-linejoin="round">"#
    );
    let _ = writeln!(
        s,
        "<desc>drafter draw: {} strokes, style {}; 1 px = 25.4/96 mm (96 px per inch), 1:1</desc>",
        drawing.strokes.len(),
        style.name()
    );
    if !drawing.fills.is_empty() {
        // Farthest part first (painter's order); the nonzero rule fills each region's loops.
        let _ = writeln!(s, r#"<g id="fills" stroke-width="0.5">"#);
        for fill in &drawing.fills {
            let part = fill.part.map(|p| format!(" part-{p}")).unwrap_or_default();
            let _ = writeln!(s, r#"<g class="fill{part}">"#);
            for region in &fill.regions {
                let g = (region.grey.clamp(0.0, 1.0) * 255.0).round() as u8;
                // Stroked with its own grey, half a pixel wide: pieces of one surface painted apart
                // leave no hairline seam under anti-aliasing (the region grows by a quarter pixel).
                let _ = write!(
                    s,
                    r##"<path class="band-{}" fill="#{g:02x}{g:02x}{g:02x}" stroke="#{g:02x}{g:02x}{g:02x}" d=""##,
                    region.band
                );
                for (k, ring) in region.loops.iter().enumerate() {
                    for (i, p) in ring.iter().enumerate() {
                        let sep = match (k, i) {
                            (0, 0) => "M",
                            (_, 0) => " M",
                            _ => " L",
                        };
                        let _ = write!(s, "{sep}{} {}", coordinate(p.x), coordinate(p.y));
                    }
                    let _ = write!(s, "Z");
                }
                let _ = writeln!(s, r#""/>"#);
            }
            let _ = writeln!(s, "</g>");
        }
        let _ = writeln!(s, "</g>");
    }
    for visible in [false, true] {
        if !visible && hidden == Hidden::None {
            continue;
        }
        // The visibility's group carries the colour and dashes of its creases' pen; a class whose
        // pen differs says so on its own group.
        let id = if visible { "visible" } else { "hidden" };
        let group = style.pen(LineClass::Crease, visible, hidden);
        let _ = writeln!(s, r#"<g id="{id}" stroke="{}"{}>"#, group.svg_colour(), svg_dashes(group.dash));
        for class in CLASS_ORDER {
            let strokes: Vec<&Stroke> =
                drawing.strokes.iter().filter(|st| st.visible == visible && st.class == class).collect();
            if strokes.is_empty() {
                continue;
            }
            let pen = pen_of(drawing, style, class, visible, hidden);
            let mut extra = String::new();
            if pen.grey != group.grey {
                let _ = write!(extra, r#" stroke="{}""#, pen.svg_colour());
            }
            if pen.dash != group.dash {
                extra += &pen.dash.map_or_else(|| r#" stroke-dasharray="none""#.to_string(), |d| svg_dashes(Some(d)));
            }
            let _ = writeln!(s, r#"<g class="{}" stroke-width="{}"{extra}>"#, class_name(class), pen.width.svg());
            for stroke in strokes {
                let part = stroke.part.map(|p| format!(r#" class="part-{p}""#)).unwrap_or_default();
                let _ = write!(s, r#"<path{part} d=""#);
                for (i, p) in stroke.points.iter().enumerate() {
                    let _ = write!(s, "{}{} {}", if i == 0 { "M" } else { " L" }, coordinate(p.x), coordinate(p.y));
                }
                let _ = writeln!(s, r#""/>"#);
            }
            let _ = writeln!(s, "</g>");
        }
        let _ = writeln!(s, "</g>");
    }
    let _ = writeln!(s, "</svg>");
    s
}

/// ` stroke-dasharray="…"` for a dashed pen, nothing for a continuous one.
fn svg_dashes(dash: Option<[style::Length; 2]>) -> String {
    dash.map(|[on, off]| format!(r#" stroke-dasharray="{} {}""#, on.svg(), off.svg())).unwrap_or_default()
}

/// The drawing as a one-page PDF (pdf-writer), the same strokes, widths, greys and dashes as
/// [`to_svg`] on the same page: a pixel drawn as 0.75 pt (96 per inch), widths and dashes in
/// millimetres at 72/25.4 pt each, y turned up as PDF wants it. Hidden lines first, then each
/// visible class, silhouettes last, as in the SVG.
pub fn to_pdf(drawing: &Drawing, hidden: Hidden, style: LineStyle) -> Vec<u8> {
    use pdf_writer::Content;
    const POINTS_PER_PIXEL: f32 = 0.75;
    let (w, h) = (drawing.width as f32 * POINTS_PER_PIXEL, drawing.height as f32 * POINTS_PER_PIXEL);
    let mut content = Content::new();
    // Fills as in the SVG: each region filled and stroked with its grey, half a pixel wide.
    content.set_line_width(0.5 * POINTS_PER_PIXEL);
    content.set_line_join(pdf_writer::types::LineJoinStyle::RoundJoin);
    for region in drawing.fills.iter().flat_map(|f| &f.regions) {
        content.set_fill_gray(region.grey as f32);
        content.set_stroke_gray(region.grey as f32);
        for ring in &region.loops {
            for (i, q) in ring.iter().enumerate() {
                let (x, y) = (q.x as f32 * POINTS_PER_PIXEL, h - q.y as f32 * POINTS_PER_PIXEL);
                if i == 0 {
                    content.move_to(x, y);
                } else {
                    content.line_to(x, y);
                }
            }
            content.close_path();
        }
        content.fill_nonzero_and_stroke();
    }
    content.set_line_cap(pdf_writer::types::LineCapStyle::RoundCap);
    content.set_line_join(pdf_writer::types::LineJoinStyle::RoundJoin);
    for visible in [false, true] {
        if !visible && hidden == Hidden::None {
            continue;
        }
        for class in CLASS_ORDER {
            let pen = pen_of(drawing, style, class, visible, hidden);
            let points = |length: style::Length| length.px() as f32 * POINTS_PER_PIXEL;
            content.set_stroke_gray(pen.grey as f32);
            match pen.dash {
                Some([on, off]) => content.set_dash_pattern([points(on), points(off)], 0.0),
                None => content.set_dash_pattern([], 0.0),
            };
            content.set_line_width(points(pen.width));
            let mut any = false;
            for stroke in drawing.strokes.iter().filter(|st| st.visible == visible && st.class == class) {
                for (i, q) in stroke.points.iter().enumerate() {
                    let (x, y) = (q.x as f32 * POINTS_PER_PIXEL, h - q.y as f32 * POINTS_PER_PIXEL);
                    if i == 0 {
                        content.move_to(x, y);
                    } else {
                        content.line_to(x, y);
                    }
                }
                any = true;
            }
            if any {
                content.stroke();
            }
        }
    }
    one_page_pdf((w, h), None, content)
}

/// A PDF of one page `size` points large drawn by `content`, with `title` in the document's
/// information: the frame of [`to_pdf`] and of a sheet's PDF ([`sheet`]).
pub(crate) fn one_page_pdf(size: (f32, f32), title: Option<&str>, content: pdf_writer::Content) -> Vec<u8> {
    use pdf_writer::{Finish, Pdf, Rect, Ref, TextStr};
    let (catalog, tree, page, content_id, info) = (Ref::new(1), Ref::new(2), Ref::new(3), Ref::new(4), Ref::new(5));
    let mut pdf = Pdf::new();
    pdf.catalog(catalog).pages(tree);
    pdf.pages(tree).kids([page]).count(1);
    let mut p = pdf.page(page);
    p.media_box(Rect::new(0.0, 0.0, size.0, size.1)).parent(tree).contents(content_id);
    p.resources();
    p.finish();
    if let Some(title) = title {
        pdf.document_info(info).title(TextStr(title));
    }
    pdf.stream(content_id, &content.finish());
    pdf.finish()
}

/// A coordinate at a hundredth of a pixel, without trailing zeros.
fn coordinate(v: f64) -> String {
    let text = format!("{:.2}", v);
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" { "0".to_string() } else { text.to_string() }
}

/// Brute force, the reference the drawing is checked and timed against (`tests/visibility.rs`,
/// `drafter bench draw`): a point is hidden when any triangle of the scene crosses the segment from
/// it to the eye, tested triangle by triangle in world space (Möller–Trumbore in f64). Independent
/// of the drawing's method: no projection, no BVH, no interval clipping.
pub mod brute {
    use glam::{DVec3, Vec3};

    use drafter_scene::model::Model;

    /// Every triangle of `model` in world space.
    pub fn world_triangles(model: &Model) -> Vec<[DVec3; 3]> {
        let mut out = Vec::new();
        for batch in &model.batches {
            for instance in batch.instances.clone() {
                let world = model.instance_world_from_object[instance as usize];
                for t in batch.indices.chunks_exact(3) {
                    let p = |k: usize| {
                        world.transform_point3(Vec3::from(batch.vertices[t[k] as usize].position_in_object).as_dvec3())
                    };
                    out.push([p(0), p(1), p(2)]);
                }
            }
        }
        out
    }

    /// The part of each triangle of [`world_triangles`], in its order.
    pub fn world_triangle_parts(model: &Model) -> Vec<Option<u32>> {
        let mut out = Vec::new();
        for batch in &model.batches {
            for instance in batch.instances.clone() {
                let triangles = batch.indices.len() / 3;
                out.extend((0..triangles).map(|t| crate::part_of(model, Some(batch), instance, t)));
            }
        }
        out
    }

    /// Whether a triangle crosses the open segment from `p` to `q` (parameter in (10⁻⁶, 1)).
    pub fn blocked(p: DVec3, q: DVec3, triangles: &[[DVec3; 3]]) -> bool {
        let d = q - p;
        triangles.iter().any(|t| {
            let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
            let h = d.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-300 {
                return false;
            }
            let s = p - t[0];
            let u = s.dot(h) / det;
            if !(0.0..=1.0).contains(&u) {
                return false;
            }
            let qv = s.cross(e1);
            let v = d.dot(qv) / det;
            if v < 0.0 || u + v > 1.0 {
                return false;
            }
            let t_hit = e2.dot(qv) / det;
            t_hit > 1e-6 && t_hit < 1.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64, c: f64) -> Projected {
        Projected { x, y, c }
    }

    #[test]
    fn a_triangle_in_front_hides_the_middle_of_a_segment_exactly() {
        // Segment along y = 5 from x = 0 to 10 at closeness 1; triangle covering x in [2, 6] at
        // y = 5, closeness 2 (closer).
        let t = [p(2.0, 0.0, 2.0), p(6.0, 5.0 * 2.0, 2.0), p(2.0, 10.0, 2.0)];
        let (lo, hi) = hidden_interval(p(0.0, 5.0, 1.0), p(10.0, 5.0, 1.0), &t).expect("hidden");
        assert!((lo - 0.2).abs() < 1e-12 && (hi - 0.4).abs() < 1e-12, "{lo} {hi}");
        // The same triangle behind hides nothing.
        let behind = t.map(|q| p(q.x, q.y, 0.5));
        assert_eq!(hidden_interval(p(0.0, 5.0, 1.0), p(10.0, 5.0, 1.0), &behind), None);
        // A triangle piercing the segment's depth hides from where it comes in front: closeness
        // rising along x from 0 (at x = 2) to 2 (at x = 6) crosses 1 at x = 4.
        let tri = [p(2.0, -10.0, 0.0), p(6.0, 5.0, 2.0), p(2.0, 20.0, 0.0)];
        let (lo, hi) = hidden_interval(p(0.0, 5.0, 1.0), p(10.0, 5.0, 1.0), &tri).expect("hidden");
        assert!((lo - 0.4).abs() < 1e-6 && (hi - 0.6).abs() < 1e-12, "{lo} {hi}");
    }

    #[test]
    fn a_face_meeting_the_edge_never_hides_it() {
        // The edge is a side of the triangle, at the same closeness.
        let t = [p(0.0, 0.0, 1.0), p(10.0, 0.0, 1.0), p(5.0, 8.0, 1.0)];
        assert_eq!(hidden_interval(p(0.0, 0.0, 1.0), p(10.0, 0.0, 1.0), &t), None);
    }

    #[test]
    fn intervals_merge_and_pieces_chain() {
        let mut v = vec![(0.5, 0.7), (0.1, 0.2), (0.15, 0.3), (0.7, 0.8)];
        assert_eq!(union(&mut v), vec![(0.1, 0.3), (0.5, 0.8)]);
        let piece = |a: (f64, f64), b: (f64, f64)| Piece {
            a: DVec2::new(a.0, a.1),
            b: DVec2::new(b.0, b.1),
            class: LineClass::Crease,
            visible: true,
            part: None,
        };
        let strokes =
            chain(&[piece((1.0, 0.0), (2.0, 0.0)), piece((0.0, 0.0), (1.0, 0.0)), piece((2.0, 0.0), (2.0, 1.0))], 0.05);
        assert_eq!(strokes.len(), 1);
        assert_eq!(strokes[0].points.len(), 4);
    }
}
