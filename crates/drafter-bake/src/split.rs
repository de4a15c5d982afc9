//! Primitives within 16-bit indices: the bake splits every triangle group (glTF primitive) that
//! would write more than [`MAX_PRIMITIVE_VERTICES`] vertices into consecutive groups of at most that
//! many, so that each is written with UNSIGNED_SHORT indices (on the Stanford dragon, 437k vertices
//! in one primitive, indices were 10.5 MB of a 51 MB file as UNSIGNED_INT).
//!
//! The split runs after the normal stage, because it counts the vertices the writer will write:
//! the normal stage's layout ([`VertexData`]: output vertices, crease splits included) when there
//! is one, else the group's own vertex range (which the writer passes through whole when it fits).
//! It runs before the lines stage, so that every per-primitive datum (edge visibility, silhouette
//! normals, hard-edge classes, part labels, normals) is produced per chunk.
//!
//! Chunks are greedy in the input's triangle order: a chunk takes triangles until the next one would
//! bring a vertex past the limit. Triangle order is kept, so per-triangle data (labels, corners
//! `3·t + k` of silhouette candidates) needs no remapping; a vertex used on both sides of a chunk
//! seam is written once per chunk. Measured (`examples/split_survey.rs`): the dragon's 8 chunks
//! repeat 21,125 of 444,434 vertices (4.8 %; 1.5 % after a Morton sort of its triangles, 0.4 MB of
//! 46.5 MB less), and CAD exports are ordered coherently (GearboxAssy at a 16,384 limit: 0.3 % in
//! input order, 3.1 % after a Morton sort), so the split does not reorder triangles and the
//! format's "triangle order is kept" holds.
//!
//! Each chunk keeps the source group's material, source primitive and vertex range (the writer
//! renumbers the vertices a chunk uses in order of first use); [`SplitGroups::source`] says which
//! source group a chunk comes from, which the lines stage needs: silhouette candidates are encoded
//! once over the chunks of one source primitive (`drafter_lines::encode_edge_visibility_continuing`).

use drafter_core::{Mesh, Scene, TriangleGroup};
use drafter_format::{MAX_PRIMITIVE_VERTICES, VertexData};
use rayon::prelude::*;
use serde::Serialize;

/// A mesh's groups after the split: each group in order, or the chunks that replace it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SplitGroups {
    pub groups: Vec<TriangleGroup>,
    /// For each group, the index of the mesh group it comes from (non-decreasing).
    pub source: Vec<u32>,
}

/// What the split did, summed over the scene's meshes (in the bake report).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SplitSummary {
    /// Groups (primitives) that needed more vertices than 16-bit indices address.
    pub split_primitives: usize,
    /// The primitives written for them.
    pub chunks: usize,
    /// Vertices those groups write unsplit (distinct vertices used).
    pub vertices: usize,
    /// Vertices written once more because a chunk seam runs through them (the chunks' vertex
    /// counts sum to `vertices + duplicated_vertices`).
    pub duplicated_vertices: usize,
}

impl SplitSummary {
    fn add(&mut self, other: &SplitSummary) {
        self.split_primitives += other.split_primitives;
        self.chunks += other.chunks;
        self.vertices += other.vertices;
        self.duplicated_vertices += other.duplicated_vertices;
    }
}

/// Splits the groups of `mesh` whose written vertices exceed `limit` (≥ 3): with `layout`, the
/// distinct output vertices their triangles use; without, their vertex range. `None` when no group
/// is split into more than one chunk (the mesh is written as it is).
pub fn split_mesh(mesh: &Mesh, layout: Option<&VertexData>, limit: u32) -> (Option<SplitGroups>, SplitSummary) {
    assert!(limit >= 3, "a chunk must hold a triangle");
    let corner = |t: usize, k: usize| layout.map_or(mesh.triangles[t][k], |vd| vd.triangles[t][k]);
    let vertex_space = layout.map_or(mesh.positions.len(), |vd| vd.source_vertex.len());
    let mut summary = SplitSummary::default();
    let mut out = SplitGroups::default();
    let mut split_any = false;
    // Stamps: `chunk_of[v]` the last chunk that took vertex v, `group_of[v]` the last group; ids
    // count up through the mesh, so the arrays are never cleared.
    let (mut chunk_of, mut group_of) = (Vec::new(), Vec::new());
    let (mut chunk_id, mut group_id) = (0u32, 0u32);
    for (g, group) in mesh.groups.iter().enumerate() {
        let written_bound = match layout {
            Some(_) => 3 * u64::from(group.count),
            None => u64::from(group.vertex_count),
        };
        if written_bound <= u64::from(limit) {
            out.groups.push(group.clone());
            out.source.push(g as u32);
            continue;
        }
        if chunk_of.is_empty() {
            chunk_of = vec![0u32; vertex_space];
            group_of = vec![0u32; vertex_space];
        }
        group_id += 1;
        chunk_id += 1;
        let range = group.start as usize..(group.start + group.count) as usize;
        let mut chunks = vec![(group.start, 0u32)];
        let (mut in_chunk, mut written, mut distinct) = (0u32, 0usize, 0usize);
        for t in range {
            let vertices = [corner(t, 0), corner(t, 1), corner(t, 2)];
            let fresh = |stamps: &[u32], id: u32| {
                (0..3).filter(|&k| stamps[vertices[k] as usize] != id && !vertices[..k].contains(&vertices[k])).count()
                    as u32
            };
            if in_chunk + fresh(&chunk_of, chunk_id) > limit {
                chunk_id += 1;
                written += in_chunk as usize;
                in_chunk = 0;
                chunks.push((t as u32, 0));
            }
            in_chunk += fresh(&chunk_of, chunk_id);
            distinct += fresh(&group_of, group_id) as usize;
            for v in vertices {
                chunk_of[v as usize] = chunk_id;
                group_of[v as usize] = group_id;
            }
            chunks.last_mut().expect("one chunk at least").1 += 1;
        }
        written += in_chunk as usize;
        // Counted only when over the limit: a group of fewer written vertices is not split (nor,
        // without a layout, one whose range is over the limit but whose triangles use fewer).
        if distinct > limit as usize || (layout.is_none() && group.vertex_count > limit) {
            summary.split_primitives += 1;
            summary.chunks += chunks.len();
            summary.vertices += distinct;
            summary.duplicated_vertices += written - distinct;
        }
        split_any |= chunks.len() > 1;
        for (start, count) in chunks {
            out.groups.push(TriangleGroup { start, count, ..group.clone() });
            out.source.push(g as u32);
        }
    }
    (split_any.then_some(out), summary)
}

/// [`split_mesh`] at [`MAX_PRIMITIVE_VERTICES`] for every mesh of `scene` (`layouts` in mesh order),
/// in parallel; the result is in mesh order and independent of the thread count.
pub fn split_scene(scene: &Scene, layouts: &[Option<VertexData>]) -> (Vec<Option<SplitGroups>>, SplitSummary) {
    let results: Vec<(Option<SplitGroups>, SplitSummary)> = scene
        .meshes
        .par_iter()
        .zip(layouts.par_iter())
        .map(|(mesh, layout)| split_mesh(mesh, layout.as_ref(), MAX_PRIMITIVE_VERTICES))
        .collect();
    let mut summary = SplitSummary::default();
    let splits = results
        .into_iter()
        .map(|(split, s)| {
            summary.add(&s);
            split
        })
        .collect();
    (splits, summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A strip of `n` quads (2n triangles over 2n + 2 vertices), in order along the strip.
    fn strip(n: u32) -> Mesh {
        let positions = (0..=n).flat_map(|i| [Vec3::new(i as f32, 0.0, 0.0), Vec3::new(i as f32, 1.0, 0.0)]).collect();
        let triangles =
            (0..n).flat_map(|i| [[2 * i, 2 * i + 2, 2 * i + 1], [2 * i + 1, 2 * i + 2, 2 * i + 3]]).collect();
        let groups = vec![TriangleGroup {
            start: 0,
            count: 2 * n,
            primitive: Some(0),
            vertex_count: 2 * n + 2,
            ..Default::default()
        }];
        Mesh { positions, triangles, groups, ..Default::default() }
    }

    #[test]
    fn chunks_hold_at_most_the_limit_and_cover_the_group_in_order() {
        let mesh = strip(100);
        let (split, summary) = split_mesh(&mesh, None, 10);
        let split = split.expect("split");
        assert_eq!(split.groups.first().map(|g| g.start), Some(0));
        let mut next = 0;
        for g in &split.groups {
            assert_eq!(g.start, next, "consecutive");
            next += g.count;
            let mut used: Vec<u32> =
                mesh.triangles[g.start as usize..next as usize].iter().flatten().copied().collect();
            used.sort_unstable();
            used.dedup();
            assert!(used.len() <= 10);
            assert_eq!((g.primitive, g.first_vertex, g.vertex_count), (Some(0), 0, 202));
        }
        assert_eq!(next, 200);
        assert!(split.source.iter().all(|&s| s == 0));
        // 10 vertices = 4 quads = 8 triangles per chunk; each seam repeats the 2 vertices of an edge.
        assert_eq!(split.groups.len(), 25);
        assert_eq!(summary, SplitSummary { split_primitives: 1, chunks: 25, vertices: 202, duplicated_vertices: 48 });
    }

    #[test]
    fn groups_that_fit_are_kept_and_a_layout_counts_output_vertices() {
        let mut mesh = strip(4);
        assert_eq!(split_mesh(&mesh, None, 10), (None, SplitSummary::default()));
        // The same 10 vertices, every triangle on vertices of its own in the layout (30 outputs).
        let layout = VertexData {
            source_vertex: (0..24).map(|i| mesh.triangles[i / 3][i % 3]).collect(),
            triangles: (0..8).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
            normals: vec![[0.0, 0.0, 1.0]; 24],
            enhanced: vec![[0.0, 0.0, 1.0]; 24],
        };
        let (split, summary) = split_mesh(&mesh, Some(&layout), 10);
        let split = split.expect("split by output vertices");
        assert_eq!(split.groups.iter().map(|g| g.count).collect::<Vec<_>>(), [3, 3, 2]);
        assert_eq!(summary.duplicated_vertices, 0);
        // A second group after a split one keeps its place and its source index.
        mesh.triangles.push([0, 1, 2]);
        mesh.groups.push(TriangleGroup {
            start: 8,
            count: 1,
            primitive: Some(1),
            vertex_count: 3,
            ..Default::default()
        });
        let mut layout = layout;
        layout.triangles.push([0, 1, 2]);
        let (split, _) = split_mesh(&mesh, Some(&layout), 10);
        let split = split.expect("split");
        assert_eq!(split.source, [0, 0, 0, 1]);
        assert_eq!(split.groups[3].start, 8);
    }
}
