//! The baked edges of a model, ready for the lines pass, and the per-frame silhouette query.
//!
//! # What a baked file gives
//! Per glTF primitive, `EXT_mesh_primitive_edge_visibility` marks every triangle edge with 2 bits
//! (0 hidden, 1 silhouette candidate, 2 hard edge, 3 hard edge already written) and our
//! `hardEdgeClasses` gives each hard edge its class (crease, boundary, part border, non-manifold,
//! tangent).
//! Per mesh, `DRAFTER_illustration.silhouettes` lists every candidate as a triangle corner `3·t + k`
//! with its two face normals in full precision, plus the hierarchies drafter-lines chose to store:
//! a Gauss-map arc hierarchy for orthographic views and a normal-cone BVH for eye points (Gooch et
//! al. 1999, §5.1; ../shared/papers/001_*). [`ModelLines::from_scene`] turns both into object-space
//! segments; the hierarchies are loaded with drafter-lines' own `SilhouetteIndex::from_arrays`
//! (which validates every bound), so their layout stays drafter-lines' business.
//!
//! # The query, per frame
//! A silhouette edge is one whose two faces point to opposite sides of the eye: with `a = n1·w`,
//! `b = n2·w` (`w` the view direction, or `e − v` from the edge's point `v` to the eye `e`) of
//! strictly opposite signs. The test is invariant under the instance transform — `n` maps by the
//! inverse transpose and `w` by the matrix, so `n_world·w_world = n_object·w_object`, and a mirror
//! flips both normals, which keeps "opposite" — so each instance queries its mesh's index with the
//! eye (or direction) taken into object space in f64 ([`instance_view`]), and gets exactly the set
//! drafter-lines' brute force selects there. Instances whose object-space direction is bit-identical
//! (translated copies under an orthographic camera) share one query.
//!
//! Limits: a mesh whose stored hierarchy does not validate against the file's candidates is
//! queried by brute force (and [`ModelLines::notices`] says so); candidate points are the file's
//! positions of each corner's first vertex, which the bake uses too.

use std::ops::Range;
use std::time::Duration;

use web_time::Instant;

use drafter_core::Scene;
use drafter_format::{BakedFile, HardEdgeClass, MeshSilhouettes};
use drafter_lines::{BruteForceReason, EdgeSet, HierarchyChoice, SilhouetteArrays, SilhouetteIndex, View as LinesView};
use glam::{DMat4, DVec3, Vec3};

use crate::layout::LineSegmentGpu;

/// Class of a drawn line. Codes 1–4 are the file's `hardEdgeClasses`; the file's tangent code (5)
/// is [`LineClass::Tangent`] (6) here, since 5 was the silhouette's first. What the lines pass
/// uploads is [`LineClass::gpu_kind`] (`lines.wgsl`: `CLASS_*`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum LineClass {
    Crease = HardEdgeClass::Crease as u32,
    Boundary = HardEdgeClass::Boundary as u32,
    PartBorder = HardEdgeClass::PartBorder as u32,
    NonManifold = HardEdgeClass::NonManifold as u32,
    /// A silhouette of the current view.
    Silhouette = 5,
    /// A tangent edge: a border between two faces of the input meeting below the crease angle
    /// (`hardEdgeClasses` code 5).
    Tangent = 6,
}

impl LineClass {
    /// The class of a `hardEdgeClasses` code; unknown codes are drawn as boundaries (black).
    pub fn from_hard_code(code: u8) -> LineClass {
        match code {
            1 => LineClass::Crease,
            3 => LineClass::PartBorder,
            4 => LineClass::NonManifold,
            c if c == HardEdgeClass::Tangent as u8 => LineClass::Tangent,
            _ => LineClass::Boundary,
        }
    }

    /// The `kind` the raster lines pass draws by (`lines.wgsl`): a tangent edge as a crease (a
    /// light inner line; the shader makes it a contour where the depth jumps across it).
    pub fn gpu_kind(self) -> u32 {
        match self {
            LineClass::Tangent => LineClass::Crease as u32,
            other => other as u32,
        }
    }
}

/// One mesh's candidates: the loaded index and the object-space segment of each candidate.
#[derive(Clone, Debug)]
pub struct MeshSilhouetteLines {
    pub index: SilhouetteIndex,
    /// The corner `3·t + k` of each candidate, in the index's candidate order.
    pub corners: Vec<u32>,
    /// Object-space endpoints of each candidate, in the index's candidate order.
    pub segments: Vec<[Vec3; 2]>,
    /// The file's hierarchies, not built yet: brute force answers until
    /// [`ModelLines::complete_hierarchies`] builds them (see [`Hierarchies::Deferred`]).
    pub pending: Option<Box<MeshSilhouettes>>,
}

/// When a loaded file's silhouette hierarchies are built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Hierarchies {
    /// At load: every query after it is answered by the stored hierarchies.
    #[default]
    AtLoad,
    /// Later, by [`ModelLines::complete_hierarchies`]; until then each mesh's candidates are
    /// answered by brute force (the same sets). Checking a stored hierarchy means assigning its
    /// candidates down the stored tree again, most of a large file's load in the browser, where
    /// one query by brute force takes only milliseconds, so the page shows its first frame first
    /// and builds them after it.
    Deferred,
    /// Never: brute force answers every query. For a few views (a drawing, a sheet) one pass over
    /// the candidates costs less than checking the stored hierarchies.
    Never,
}

/// The edges of one mesh and the instances that draw it.
#[derive(Clone, Debug)]
pub struct MeshLines {
    /// Scene mesh index.
    pub mesh: u32,
    /// Range of [`crate::Model::instances`] drawing this mesh.
    pub instances: Range<u32>,
    /// Hard edges: object-space endpoints and class.
    pub hard: Vec<([Vec3; 2], LineClass)>,
    /// The corner `3·t + k` each hard edge was read from (edge v_k → v_(k+1) of mesh triangle t):
    /// for drawings, its triangle's part and, through the mesh's topology, its two faces.
    pub hard_corners: Vec<u32>,
    pub silhouettes: Option<MeshSilhouetteLines>,
}

/// Every mesh's edges, with what the per-frame query needs about the instances.
#[derive(Clone, Debug, Default)]
pub struct ModelLines {
    pub meshes: Vec<MeshLines>,
    /// Per model instance, the inverse of its `world_from_object` (f64).
    pub object_from_world: Vec<DMat4>,
    /// What could not be used as stored (one line each).
    pub notices: Vec<String>,
}

/// Where the camera is, in world space, for the silhouette query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WorldView {
    /// Central projection from this world point.
    Perspective { eye: DVec3 },
    /// Parallel projection along this world direction (either sign: the test is symmetric).
    Orthographic { direction: DVec3 },
}

/// A silhouette the lines pass draws: which instance, and which candidate of its mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct DrawnSilhouette {
    /// Index into [`crate::Model::instances`].
    pub instance: u32,
    /// Scene mesh index.
    pub mesh: u32,
    /// The candidate's corner `3·t + k` (edge v_k → v_(k+1) of mesh triangle t).
    pub corner: u32,
}

/// One frame's silhouettes.
#[derive(Clone, Debug, Default)]
pub struct SilhouetteFrame {
    /// What the lines pass uploads, one per drawn silhouette.
    pub segments: Vec<LineSegmentGpu>,
    /// The same edges by identity, in upload order.
    pub drawn: Vec<DrawnSilhouette>,
    /// Queries run (instances sharing an object-space direction share one).
    pub queries: usize,
    /// Wall time of the queries and of building the segment list.
    pub elapsed: Duration,
}

/// The view in an instance's object space (see the module docs), rounded to f32 once.
pub fn instance_view(view: WorldView, object_from_world: &DMat4) -> LinesView {
    match view {
        WorldView::Perspective { eye } => {
            LinesView::Perspective { eye: object_from_world.transform_point3(eye).as_vec3() }
        }
        WorldView::Orthographic { direction } => {
            LinesView::Orthographic { direction: object_from_world.transform_vector3(direction).as_vec3() }
        }
    }
}

impl ModelLines {
    /// The edges of `scene` (the import of the baked file) from `baked`. `instance_meshes[i]` and
    /// `world_from_object[i]` describe model instance `i`; instances of a mesh are contiguous.
    pub fn from_scene(scene: &Scene, baked: &BakedFile, instance_meshes: &[u32], world_from_object: &[DMat4]) -> Self {
        Self::from_scene_with(scene, baked, instance_meshes, world_from_object, Hierarchies::AtLoad)
    }

    /// [`Self::from_scene`], building the stored hierarchies when `hierarchies` says.
    pub fn from_scene_with(
        scene: &Scene,
        baked: &BakedFile,
        instance_meshes: &[u32],
        world_from_object: &[DMat4],
        hierarchies: Hierarchies,
    ) -> Self {
        let mut notices = Vec::new();
        let mut meshes = Vec::new();
        let mut bad_slots = 0usize;
        for (m, mesh) in scene.meshes.iter().enumerate() {
            let first = instance_meshes.iter().position(|&x| x as usize == m);
            let Some(first) = first else { continue };
            let count = instance_meshes[first..].iter().take_while(|&&x| x as usize == m).count();
            let instances = first as u32..(first + count) as u32;
            let position = |t: usize, k: usize| -> Option<Vec3> {
                let tri = mesh.triangles.get(t)?;
                mesh.positions.get(tri[k % 3] as usize).copied()
            };
            let mut hard = Vec::new();
            let mut hard_corners = Vec::new();
            for (_, p, edges) in baked.primitive_edges.iter().filter(|(mm, _, _)| *mm as usize == m) {
                let Some(group) = mesh.groups.iter().find(|g| g.primitive == Some(*p)) else {
                    bad_slots += 1;
                    continue;
                };
                for (slot, class) in edges.hard_edges() {
                    let (t, k) = ((slot / 3) as usize, (slot % 3) as usize);
                    if t >= group.count as usize {
                        bad_slots += 1;
                        continue;
                    }
                    let t = group.start as usize + t;
                    match (position(t, k), position(t, k + 1)) {
                        (Some(a), Some(b)) => {
                            hard.push(([a, b], LineClass::from_hard_code(class)));
                            hard_corners.push((3 * t + k) as u32);
                        }
                        _ => bad_slots += 1,
                    }
                }
            }
            let silhouettes =
                baked.mesh_silhouettes.iter().find(|(mm, _)| *mm as usize == m).and_then(|(_, s)| match hierarchies {
                    Hierarchies::AtLoad => load_silhouettes(m, s, &position, &mut notices),
                    Hierarchies::Deferred => load_silhouettes_deferred(m, s, &position, &mut notices, true),
                    Hierarchies::Never => load_silhouettes_deferred(m, s, &position, &mut notices, false),
                });
            if hard.is_empty() && silhouettes.is_none() {
                continue;
            }
            meshes.push(MeshLines { mesh: m as u32, instances, hard, hard_corners, silhouettes });
        }
        if bad_slots > 0 {
            notices.push(format!("{bad_slots} baked edges do not match the file's triangles: not drawn"));
        }
        let object_from_world = world_from_object
            .iter()
            .map(|w| if w.determinant().abs() > 1e-300 { w.inverse() } else { DMat4::IDENTITY })
            .collect();
        ModelLines { meshes, object_from_world, notices }
    }

    /// Whether the file had any edges to draw.
    pub fn is_empty(&self) -> bool {
        self.meshes.is_empty()
    }

    /// Hard edges of every instance, in render space coordinates of their instance (object-space
    /// endpoints plus the instance index the shader transforms them with).
    pub fn hard_segments(&self) -> Vec<LineSegmentGpu> {
        let mut out = Vec::new();
        for mesh in &self.meshes {
            for instance in mesh.instances.clone() {
                out.extend(mesh.hard.iter().map(|&([a, b], class)| LineSegmentGpu::new(a, b, instance, class)));
            }
        }
        out
    }

    /// Whether some mesh's stored hierarchies wait for [`Self::complete_hierarchies`].
    pub fn hierarchies_pending(&self) -> bool {
        self.meshes.iter().any(|m| m.silhouettes.as_ref().is_some_and(|s| s.pending.is_some()))
    }

    /// Builds the stored hierarchies that a [`Hierarchies::Deferred`] load left for later, as
    /// [`load_silhouettes`] does at load (one that does not validate is dropped with a notice, and
    /// brute force keeps answering). Returns the new notices (also added to [`Self::notices`]).
    pub fn complete_hierarchies(&mut self) -> Vec<String> {
        self.complete_hierarchies_of(usize::MAX).0
    }

    /// [`Self::complete_hierarchies`] for at most `meshes` meshes (the page builds one at a time
    /// between input events). Returns the notices and how many meshes still wait.
    pub fn complete_hierarchies_of(&mut self, meshes: usize) -> (Vec<String>, usize) {
        let mut notices = Vec::new();
        let mut built = 0;
        for mesh in &mut self.meshes {
            if built == meshes {
                break;
            }
            let Some(lines) = mesh.silhouettes.as_mut() else { continue };
            let Some(stored) = lines.pending.take() else { continue };
            built += 1;
            // The brute-force index keeps the file's candidate order: each corner's segment is
            // at the corner's place in the file.
            let by_corner: std::collections::HashMap<u32, [Vec3; 2]> =
                lines.corners.iter().copied().zip(lines.segments.iter().copied()).collect();
            let position = |t: usize, k: usize| -> Option<Vec3> {
                let corner = (3 * t + k % 3) as u32;
                // Corner k's start point is the segment of corner k, or the end of corner k − 1.
                by_corner.get(&corner).map(|s| s[0]).or_else(|| {
                    let previous = (3 * t + (k + 2) % 3) as u32;
                    by_corner.get(&previous).map(|s| s[1])
                })
            };
            match load_silhouettes(mesh.mesh as usize, &stored, &position, &mut notices) {
                Some(full) => *lines = full,
                None => {
                    // The candidates loaded once; keep answering them by brute force.
                }
            }
        }
        self.notices.extend(notices.iter().cloned());
        let left = self.meshes.iter().filter(|m| m.silhouettes.as_ref().is_some_and(|s| s.pending.is_some())).count();
        (notices, left)
    }

    /// Candidates of every mesh (for reports).
    pub fn candidate_count(&self) -> usize {
        self.meshes.iter().filter_map(|m| m.silhouettes.as_ref()).map(|s| s.index.len()).sum()
    }

    /// The silhouettes of `view`: every instance of every mesh with candidates, queried in its
    /// object space by the mesh's index (hierarchy or brute force, identical answers).
    pub fn silhouettes(&self, view: WorldView) -> SilhouetteFrame {
        let start = Instant::now();
        let mut frame = SilhouetteFrame::default();
        let mut set = EdgeSet::new(0);
        for mesh in &self.meshes {
            let Some(s) = &mesh.silhouettes else { continue };
            let mut last: Option<LinesView> = None;
            for instance in mesh.instances.clone() {
                let object_from_world = self.object_from_world.get(instance as usize).unwrap_or(&DMat4::IDENTITY);
                let local = instance_view(view, object_from_world);
                // Translated copies see the same direction: reuse the answer.
                let same = matches!((last, local), (Some(LinesView::Orthographic { direction: d0 }), LinesView::Orthographic { direction: d1 }) if d0.to_array().map(f32::to_bits) == d1.to_array().map(f32::to_bits));
                if !same {
                    set.reset(s.index.len());
                    s.index.query(local, &mut set);
                    frame.queries += 1;
                }
                last = Some(local);
                for c in set.iter() {
                    let [a, b] = s.segments[c as usize];
                    frame.segments.push(LineSegmentGpu::new(a, b, instance, LineClass::Silhouette));
                    frame.drawn.push(DrawnSilhouette { instance, mesh: mesh.mesh, corner: s.corners[c as usize] });
                }
            }
        }
        frame.elapsed = start.elapsed();
        frame
    }
}

/// [`load_silhouettes`] without the hierarchies: the candidates by brute force, in the file's
/// order, and (`keep`) the stored hierarchies kept for [`ModelLines::complete_hierarchies`].
fn load_silhouettes_deferred(
    m: usize,
    s: &MeshSilhouettes,
    position: &dyn Fn(usize, usize) -> Option<Vec3>,
    notices: &mut Vec<String>,
    keep: bool,
) -> Option<MeshSilhouetteLines> {
    if s.gauss_map.is_none() && s.cone_bvh.is_none() {
        return load_silhouettes(m, s, position, notices);
    }
    // The candidates alone (the stored hierarchies are not copied for them).
    let candidates = MeshSilhouettes {
        candidate_corners: s.candidate_corners.clone(),
        candidate_normals: s.candidate_normals.clone(),
        orthographic: drafter_format::OrthographicHierarchy::BruteForce,
        perspective: drafter_format::PerspectiveHierarchy::BruteForce,
        gauss_map: None,
        cone_bvh: None,
    };
    let mut lines = load_silhouettes(m, &candidates, position, notices)?;
    if keep {
        lines.pending = Some(Box::new(s.clone()));
    }
    Some(lines)
}

/// The index of one mesh's stored candidates and hierarchies, as every reader of the file loads it
/// (`position(t, k)`: the position of corner k of mesh triangle t); `None` (with a notice) when the
/// candidates do not match the mesh. A stored hierarchy that does not validate is dropped, with a
/// notice, and brute force answers its views.
pub fn load_silhouettes(
    m: usize,
    s: &MeshSilhouettes,
    position: &dyn Fn(usize, usize) -> Option<Vec3>,
    notices: &mut Vec<String>,
) -> Option<MeshSilhouetteLines> {
    // The object-space segment of a corner `3·t + k` (edge v_k → v_(k+1) of mesh triangle t).
    let segment = |corner: u32| {
        let (t, k) = ((corner / 3) as usize, (corner % 3) as usize);
        Some([position(t, k)?, position(t, k + 1)?])
    };
    let mut points = Vec::with_capacity(3 * s.candidate_corners.len());
    for &corner in &s.candidate_corners {
        match segment(corner) {
            Some([a, _]) => points.extend(a.to_array()),
            None => {
                notices
                    .push(format!("mesh {m}: silhouette candidate corner {corner} is not a triangle edge: none drawn"));
                return None;
            }
        }
    }
    // What answers each kind of view, as the file records it (node counts and predicted speedups
    // are not stored; a mesh the bake gave no hierarchy reads as brute force by choice).
    let none = HierarchyChoice::BruteForce(BruteForceReason::Disabled);
    let orthographic = match (s.orthographic, &s.gauss_map) {
        (drafter_format::OrthographicHierarchy::GaussMap, Some(g)) => {
            HierarchyChoice::GaussMap { max_depth: g.max_depth.min(255) as u8, nodes: 0, predicted_speedup: 0.0 }
        }
        _ => none,
    };
    let perspective = match (s.perspective, &s.cone_bvh) {
        (drafter_format::PerspectiveHierarchy::ConeBvh, Some(_)) => {
            HierarchyChoice::ConeBvh { leaf_size: 0, nodes: 0, predicted_speedup: 0.0 }
        }
        _ => none,
    };
    let arrays = |gauss: bool, bvh: bool| SilhouetteArrays {
        candidate_edges: s.candidate_corners.clone(),
        candidate_normals: s.candidate_normals.clone(),
        candidate_points: points.clone(),
        gauss_map: s.gauss_map.clone().filter(|_| gauss),
        cone_bvh: s.cone_bvh.clone().filter(|_| bvh),
        orthographic: if gauss { orthographic } else { none },
        perspective: if bvh { perspective } else { none },
    };
    let index = match SilhouetteIndex::from_arrays(&arrays(true, true)) {
        Ok(index) => index,
        Err(e) => {
            // Keep what validates; brute force answers the rest (same sets, slower).
            let fallback = [(true, false), (false, true), (false, false)]
                .into_iter()
                .find_map(|(g, b)| SilhouetteIndex::from_arrays(&arrays(g, b)).ok().map(|i| (i, g, b)));
            match fallback {
                Some((index, g, b)) => {
                    let dropped = match (g, b) {
                        (true, false) => "cone BVH",
                        (false, true) => "Gauss map",
                        _ => "hierarchies",
                    };
                    notices.push(format!("mesh {m}: stored {dropped} does not validate ({e}): brute force instead"));
                    index
                }
                None => {
                    notices.push(format!("mesh {m}: silhouette candidates do not load ({e}): none drawn"));
                    return None;
                }
            }
        }
    };
    // The index answers in its own candidate order (the Gauss map's storage order): segments and
    // corners follow it.
    let corners = index.candidate_edges().to_vec();
    let segments: Option<Vec<[Vec3; 2]>> = corners.iter().map(|&c| segment(c)).collect();
    match segments {
        Some(segments) if segments.len() == index.len() => {
            Some(MeshSilhouetteLines { index, corners, segments, pending: None })
        }
        _ => {
            notices.push(format!("mesh {m}: silhouette index and candidates disagree: none drawn"));
            None
        }
    }
}
