//! Writing and reading the draft Khronos extension `EXT_mesh_primitive_edge_visibility`
//! (rules restated in ../shared/specs/EXT_mesh_primitive_edge_visibility.md).
//!
//! `visibility` holds 2 bits per triangle edge, edges `v0:v1, v1:v2, v2:v0` of each triangle in glTF
//! order, packed from the least significant bits of each byte; `ceil(6·N/8)` bytes with the unused
//! high bits zero. Values: 0 hidden, 1 silhouette candidate, 2 hard edge, 3 hard edge already
//! encoded as 2.
//!
//! The encoder walks the primitive's own triangles (its original, unwelded indices) and identifies
//! edges through the welded topology, so the two sides of a CAD seam, which use different vertex
//! indices, are one edge: a hard edge is written 2 on the first triangle edge that meets it and 3 on
//! every other; a silhouette candidate is written 1 once and 0 elsewhere, and its two face normals
//! (smaller face index first) go to `silhouetteNormals` in the order the 1s appear.
//! Coplanar and degenerate-neighbour edges are 0, and so are all three edges of a triangle that
//! collapsed in the weld (a repeated welded vertex: the topology gives it no edges); the decoder
//! requires those zeros and otherwise ignores such triangles.
//! The encode-once rules hold per call: encode each primitive with its own triangles. A primitive
//! that the bake split into several (16-bit indices) is encoded chunk by chunk with
//! [`encode_edge_visibility_continuing`]: hard edges again per chunk (a chunk is a primitive of its
//! own, and a primitive's client needs its 2), silhouette candidates once across the chunks, as
//! before the split (the 1 carries both face normals, so a candidate on a chunk seam needs no copy).
//!
//! `silhouetteNormals` is written VEC3 BYTE normalized, the type the merged draft recommends (the
//! earlier oct16 form is neither written nor read), each normal the lattice point whose direction
//! is nearest it (`drafter_core::snorm8_encode_direction`), read back as glTF defines normalized
//! bytes, `max(c / 127, −1)`. The decoder takes the decoded vectors, whatever type a file stored.
//! Our own hierarchies are built on the decoded values, so that they answer exactly for the data
//! every reader has; what 8 bits change against `f32` face normals is measured by
//! `examples/normal_precision.rs`
//! (docs/bench.md#format-02-bytes-and-what-the-silhouette-normals-precision-buys).

use std::collections::HashMap;
use std::sync::atomic::{AtomicU32, Ordering};

use drafter_core::{EDGE_NONE, Topology, snorm8_encode_direction};
use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::{EdgeClass, FeatureEdges};

/// Values of one triangle edge.
pub const HIDDEN: u8 = 0;
pub const SILHOUETTE: u8 = 1;
pub const HARD: u8 = 2;
pub const HARD_REPEATED: u8 = 3;

/// Problems found by [`encode_edge_visibility`] (caller bugs) or [`decode_edge_visibility`] (a
/// file that breaks the draft's rules).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum VisibilityError {
    #[error("triangle {triangle} uses vertex {vertex}, but the topology has {vertices} vertices")]
    VertexOutOfRange { triangle: usize, vertex: u32, vertices: usize },
    #[error("edge {corner} of triangle {triangle} is not an edge of the topology")]
    UnknownEdge { triangle: usize, corner: usize },
    #[error("visibility has {found} bytes, {expected} expected for {triangles} triangles")]
    Length { expected: usize, found: usize, triangles: usize },
    #[error("unused high bits of the last visibility byte are not zero")]
    TrailingBits,
    #[error("triangle {triangle} collapsed in the weld but its edge {corner} is encoded {value}")]
    CollapsedEdge { triangle: usize, corner: usize, value: u8 },
    #[error("edge {a}-{b}: {twos} occurrences encoded 2, {threes} encoded 3, {ones} encoded 1 and {zeros} encoded 0")]
    EncodeOnce { a: u32, b: u32, zeros: u32, ones: u32, twos: u32, threes: u32 },
    #[error("silhouetteNormals has {found} entries, 2 × {ones} expected")]
    NormalCount { expected: usize, found: usize, ones: usize },
    #[error("every visibility value is zero")]
    AllHidden,
}

/// The extension's payload for one primitive.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EdgeVisibility {
    /// The `visibility` accessor's bytes.
    pub visibility: Vec<u8>,
    /// The `silhouetteNormals` accessor's values: two VEC3 BYTE normalized normals per 1-edge, in
    /// encoding order.
    pub silhouette_normals: Vec<[i8; 3]>,
    /// Topology edge id of each 1-edge, in encoding order (links `silhouette_normals` to the
    /// full-precision normals of our own extension).
    pub silhouette_edges: Vec<u32>,
    /// Topology edge id of each 2-edge, in encoding order.
    pub hard_edges: Vec<u32>,
}

impl EdgeVisibility {
    /// The draft requires at least one non-zero value: write the extension only when this holds.
    pub fn has_visible_edges(&self) -> bool {
        !self.hard_edges.is_empty() || !self.silhouette_edges.is_empty()
    }

    /// `silhouette_normals` as a glTF reader decodes them (`drafter_core::snorm8_decode`).
    pub fn decoded_normals(&self) -> Vec<Vec3> {
        self.silhouette_normals.iter().map(|&c| drafter_core::snorm8_decode(c)).collect()
    }
}

/// Encodes `triangles` (original vertex indices, glTF order, all of them mapped by
/// `topology.welded_of_vertex`) with the classes of `lines` (computed on `topology`).
pub fn encode_edge_visibility(
    triangles: &[[u32; 3]],
    topology: &Topology,
    lines: &FeatureEdges,
) -> Result<EdgeVisibility, VisibilityError> {
    encode_edge_visibility_continuing(triangles, topology, lines, &mut SilhouettesEncoded::default())
}

/// The silhouette candidates that earlier chunks of a split primitive encoded as 1, by topology
/// edge id (see [`encode_edge_visibility_continuing`]). Start each source primitive afresh.
#[derive(Clone, Debug, Default)]
pub struct SilhouettesEncoded {
    written: Vec<bool>,
    /// Each face's normal as written ([`snorm8_encode_direction`]), once its first candidate is
    /// written: a face borders up to three candidates, so rounding per face instead of per
    /// candidate side does about a third of the work.
    face_codes: Vec<[i8; 3]>,
    face_rounded: Vec<bool>,
    /// Candidate index of every topology edge (`u32::MAX`: not a candidate), built by the first
    /// chunk: one table lookup per corner instead of a binary search over up to millions of
    /// candidates, which misses the cache at every step.
    candidate_of_edge: Vec<u32>,
}

/// [`encode_edge_visibility`] for one chunk of a primitive split into consecutive primitives: hard
/// edges follow the encode-once rules within these `triangles` (2 here, even when an earlier chunk
/// has the edge too), while a silhouette candidate that `encoded` records as written by an earlier
/// chunk is 0 here, so that each candidate is encoded 1 exactly once over the chunks, with both
/// face normals, as in the unsplit primitive. Records this chunk's 1s in `encoded`.
pub fn encode_edge_visibility_continuing(
    triangles: &[[u32; 3]],
    topology: &Topology,
    lines: &FeatureEdges,
    encoded: &mut SilhouettesEncoded,
) -> Result<EdgeVisibility, VisibilityError> {
    encode_chunk(triangles, None, topology, lines, encoded)
}

/// [`encode_edge_visibility_continuing`] for triangles that are the faces `first_face..` of the mesh
/// `topology` was built from (a primitive's range of them, as the bake writes it): each corner's
/// edge is read from `topology.face_edges` instead of searched for by its welded vertex pair
/// (a binary search per corner, which misses the cache at every step). Same output.
pub fn encode_faces_continuing(
    triangles: &[[u32; 3]],
    first_face: usize,
    topology: &Topology,
    lines: &FeatureEdges,
    encoded: &mut SilhouettesEncoded,
) -> Result<EdgeVisibility, VisibilityError> {
    // On one thread the passes cost more than the serial walk: they only pay with a second core.
    if rayon::current_num_threads() == 1 {
        return encode_chunk(triangles, Some(first_face), topology, lines, encoded);
    }
    encode_faces_in_blocks(triangles, first_face, topology, lines, encoded, FACE_BLOCK)
}

/// Triangles per block of [`encode_faces_in_blocks`]: a multiple of 4, so that each block's
/// visibility bits fill whole bytes.
const FACE_BLOCK: usize = 4096;

/// [`encode_chunk`] over the topology's faces `first_face..`, on the thread pool: the serial walk
/// uses one core whatever the pool holds, these passes use every core there is.
///
/// The encode-once rules only ask whether a corner is its edge's first in the chunk, so the
/// serial walk becomes three passes: each triangle's edges, each edge's first corner (an atomic
/// minimum over the corners), then the values and the edges' lists block by block, joined in
/// block order. The output, and which error is reported when there are several (the first the
/// serial walk meets), are [`encode_chunk`]'s: tested against it with blocks of 4 and 8 triangles
/// on meshes with collapsed, non-manifold and boundary faces.
fn encode_faces_in_blocks(
    triangles: &[[u32; 3]],
    first_face: usize,
    topology: &Topology,
    lines: &FeatureEdges,
    encoded: &mut SilhouettesEncoded,
    block: usize,
) -> Result<EdgeVisibility, VisibilityError> {
    // Corner slots are counted in u32 (and a block must fill whole bytes): beyond that, serially.
    if 3 * triangles.len() as u64 >= u64::from(u32::MAX) || block == 0 || !block.is_multiple_of(4) {
        return encode_chunk(triangles, Some(first_face), topology, lines, encoded);
    }
    let unknown = |triangle: usize, corner: usize| VisibilityError::UnknownEdge { triangle, corner };
    let end = first_face.checked_add(triangles.len()).ok_or(unknown(0, 0))?;
    let (face_edges, faces) = match (topology.face_edges.get(first_face..end), topology.faces.get(first_face..end)) {
        (Some(e), Some(f)) => (e, f),
        _ => return Err(unknown(0, 0)),
    };
    prepare(encoded, topology, lines);
    let (candidate_of_edge, written_before) = (&encoded.candidate_of_edge, &encoded.written);

    // Each triangle's edges ([`NO_EDGES`] for a collapsed one), or the error the serial walk
    // meets at it, with its corner slot (the walk checks a triangle's vertices before its edges).
    const NO_EDGES: [u32; 3] = [EDGE_NONE; 3];
    let edges_of = |t: usize| -> Result<[u32; 3], (u32, VisibilityError)> {
        let slot = 3 * t as u32;
        let welded = welded_triangle(&triangles[t], t, &topology.welded_of_vertex).map_err(|e| (slot, e))?;
        if collapsed(&welded) {
            return Ok(NO_EDGES);
        }
        let edges = face_edges[t];
        match (0..3).find(|&k| faces[t] != welded || edges[k] == EDGE_NONE) {
            Some(k) => Err((slot + k as u32, unknown(t, k))),
            None => Ok(edges),
        }
    };
    // Kept as bare edge ids (12 bytes a triangle; a broken triangle has none), and the first
    // error found in a second pass.
    let corners: Vec<[u32; 3]> =
        (0..triangles.len()).into_par_iter().map(|t| edges_of(t).unwrap_or(NO_EDGES)).collect();
    let first_error = (0..triangles.len()).into_par_iter().find_map_first(|t| edges_of(t).err());

    // Each edge's first corner slot in this chunk.
    let first: Vec<AtomicU32> = (0..topology.edges.len()).into_par_iter().map(|_| AtomicU32::new(u32::MAX)).collect();
    corners.par_iter().enumerate().for_each(|(t, edges)| {
        for (k, &e) in edges.iter().enumerate() {
            if e != EDGE_NONE {
                first[e as usize].fetch_min(3 * t as u32 + k as u32, Ordering::Relaxed);
            }
        }
    });

    // The values block by block, with each block's new hard edges and silhouettes in slot order,
    // and the first candidate missing from the candidate list (an error of the serial walk too).
    let mut out = EdgeVisibility { visibility: vec![0; (6 * triangles.len()).div_ceil(8)], ..Default::default() };
    type Block = (Vec<u32>, Vec<u32>, Option<(u32, VisibilityError)>);
    let blocks: Vec<Block> = corners
        .par_chunks(block)
        .zip(out.visibility.par_chunks_mut(3 * block / 4))
        .enumerate()
        .map(|(b, (corners, bytes))| {
            let (mut hard, mut silhouettes) = (Vec::new(), Vec::new());
            for (i, edges) in corners.iter().enumerate() {
                let t = b * block + i;
                for (k, &e) in edges.iter().enumerate() {
                    if e == EDGE_NONE {
                        continue;
                    }
                    let slot = 3 * t as u32 + k as u32;
                    let is_first = first[e as usize].load(Ordering::Relaxed) == slot;
                    let class = lines.classes[e as usize];
                    let value = if class.is_hard() {
                        if is_first {
                            hard.push(e);
                            HARD
                        } else {
                            HARD_REPEATED
                        }
                    } else if class == EdgeClass::SilhouetteCandidate && is_first && !written_before[e as usize] {
                        if candidate_of_edge[e as usize] == u32::MAX {
                            return (hard, silhouettes, Some((slot, unknown(t, k))));
                        }
                        silhouettes.push(e);
                        SILHOUETTE
                    } else {
                        HIDDEN
                    };
                    let local = 3 * i + k;
                    bytes[local / 4] |= value << (2 * (local % 4));
                }
            }
            (hard, silhouettes, None)
        })
        .collect();
    let block_error = blocks.iter().find_map(|(_, _, e)| e.clone());
    if let Some((_, e)) = [first_error, block_error].into_iter().flatten().min_by_key(|(slot, _)| *slot) {
        return Err(e);
    }
    let mut candidates = Vec::new();
    for (hard, silhouettes, _) in blocks {
        out.hard_edges.extend(hard);
        for e in silhouettes {
            encoded.written[e as usize] = true;
            candidates.push(encoded.candidate_of_edge[e as usize] as usize);
            out.silhouette_edges.push(e);
        }
    }
    round_silhouette_normals(&candidates, topology, lines, encoded, &mut out);
    Ok(out)
}

/// Readies `encoded` for a chunk of `topology` classified as `lines`: the candidate of every edge
/// (built by the first chunk) and room for every edge's written flag.
fn prepare(encoded: &mut SilhouettesEncoded, topology: &Topology, lines: &FeatureEdges) {
    if encoded.candidate_of_edge.len() != topology.edges.len() {
        encoded.candidate_of_edge = vec![u32::MAX; topology.edges.len()];
        for (c, &e) in lines.candidates.iter().enumerate() {
            if let Some(slot) = encoded.candidate_of_edge.get_mut(e as usize) {
                *slot = c as u32;
            }
        }
    }
    encoded.written.resize(topology.edges.len(), false);
}

fn encode_chunk(
    triangles: &[[u32; 3]],
    first_face: Option<usize>,
    topology: &Topology,
    lines: &FeatureEdges,
    encoded: &mut SilhouettesEncoded,
) -> Result<EdgeVisibility, VisibilityError> {
    // The faces' own edge ids, where the caller says the triangles are the topology's faces.
    let face_edges = match first_face {
        Some(first) => Some(
            first
                .checked_add(triangles.len())
                .and_then(|end| topology.face_edges.get(first..end))
                .ok_or(VisibilityError::UnknownEdge { triangle: 0, corner: 0 })?,
        ),
        None => None,
    };
    let lookup = if face_edges.is_some() { None } else { Some(EdgeLookup::new(topology)) };
    let mut out = EdgeVisibility { visibility: vec![0; (6 * triangles.len()).div_ceil(8)], ..Default::default() };
    let mut written = vec![false; topology.edges.len()];
    prepare(encoded, topology, lines);
    let candidate_of_edge = &encoded.candidate_of_edge;
    let silhouette_written = &mut encoded.written;
    // Candidates in encoding order; their normals are rounded afterwards, on the thread pool.
    let mut candidates = Vec::new();
    for (t, tri) in triangles.iter().enumerate() {
        let welded = welded_triangle(tri, t, &topology.welded_of_vertex)?;
        if collapsed(&welded) {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (welded[k], welded[(k + 1) % 3]);
            let e = match (face_edges, &lookup) {
                // A triangle that is not the topology's face breaks the caller's promise: reported
                // as an unknown edge, never read as another face's edge.
                (Some(edges), _) => (topology.faces[first_face.unwrap_or(0) + t] == welded && edges[t][k] != EDGE_NONE)
                    .then_some(edges[t][k] as usize),
                (None, Some(lookup)) => lookup.find(a, b),
                (None, None) => None,
            }
            .ok_or(VisibilityError::UnknownEdge { triangle: t, corner: k })?;
            let class = lines.classes[e];
            let value = if class.is_hard() {
                if written[e] {
                    HARD_REPEATED
                } else {
                    out.hard_edges.push(e as u32);
                    HARD
                }
            } else if class == EdgeClass::SilhouetteCandidate && !std::mem::replace(&mut silhouette_written[e], true) {
                let c = candidate_of_edge[e];
                if c == u32::MAX {
                    return Err(VisibilityError::UnknownEdge { triangle: t, corner: k });
                }
                candidates.push(c as usize);
                out.silhouette_edges.push(e as u32);
                SILHOUETTE
            } else {
                HIDDEN
            };
            written[e] = true;
            let slot = 3 * t + k;
            out.visibility[slot / 4] |= value << (2 * (slot % 4));
        }
    }
    round_silhouette_normals(&candidates, topology, lines, encoded, &mut out);
    Ok(out)
}

/// Writes `out.silhouette_normals` for `candidates` (in encoding order): each side's face normal
/// rounded once per face over the chunks (`encoded`).
fn round_silhouette_normals(
    candidates: &[usize],
    topology: &Topology,
    lines: &FeatureEdges,
    encoded: &mut SilhouettesEncoded,
    out: &mut EdgeVisibility,
) {
    // The faces of this chunk's candidates not rounded by an earlier chunk, in first-use order.
    let faces = lines.face_normals.len();
    encoded.face_codes.resize(faces, [0; 3]);
    encoded.face_rounded.resize(faces, false);
    // Each candidate's two faces are read once (a cache miss apiece on a large mesh), for both
    // the faces to round and the normals' order.
    let sides: Vec<[u32; 2]> = candidates
        .par_iter()
        .with_min_len(1024)
        .map(|&c| {
            let faces = topology.faces_of_edge(lines.candidates[c] as usize);
            [faces[0], faces[1]]
        })
        .collect();
    let mut todo = Vec::new();
    for &f in sides.iter().flatten() {
        if !std::mem::replace(&mut encoded.face_rounded[f as usize], true) {
            todo.push(f);
        }
    }
    // The normal of a candidate's side is its face's normal in f32 (`classify_edges`), so rounding
    // the face gives the same bytes as rounding the side.
    let normal = |f: u32| lines.face_normals[f as usize].map_or(Vec3::ZERO, |n| n.as_vec3());
    let rounded: Vec<[i8; 3]> = todo.par_iter().map(|&f| snorm8_encode_direction(normal(f))).collect();
    for (&f, code) in todo.iter().zip(rounded) {
        encoded.face_codes[f as usize] = code;
    }
    let codes = &encoded.face_codes;
    let mut normals = vec![[0i8; 3]; 2 * sides.len()];
    normals.par_chunks_mut(2).zip(sides.par_iter()).with_min_len(1024).for_each(|(pair, &[f, g])| {
        pair.copy_from_slice(&[codes[f as usize], codes[g as usize]]);
    });
    out.silhouette_normals = normals;
    debug_assert!(
        lines.candidate_normals.is_empty()
            || candidates.iter().zip(out.silhouette_normals.chunks(2)).take(4096).all(|(&c, pair)| lines
                .candidate_normals[c]
                .iter()
                .zip(pair)
                .all(|(&n, &code)| snorm8_encode_direction(n) == code)),
        "a candidate's normals are its faces' normals"
    );
}

/// A triangle with a repeated welded vertex: the topology gives it no edges, it is encoded 0.
fn collapsed(w: &[u32; 3]) -> bool {
    w[0] == w[1] || w[1] == w[2] || w[2] == w[0]
}

fn welded_triangle(tri: &[u32; 3], t: usize, welded_of_vertex: &[u32]) -> Result<[u32; 3], VisibilityError> {
    let mut w = [0u32; 3];
    for k in 0..3 {
        w[k] = *welded_of_vertex.get(tri[k] as usize).ok_or(VisibilityError::VertexOutOfRange {
            triangle: t,
            vertex: tri[k],
            vertices: welded_of_vertex.len(),
        })?;
    }
    Ok(w)
}

/// Edge id by welded vertex pair: edges are sorted by `(a, b)`, so a CSR offset per `a` and a
/// binary search per bucket.
struct EdgeLookup<'a> {
    edges: &'a [[u32; 2]],
    first: Vec<u32>,
}

impl<'a> EdgeLookup<'a> {
    fn new(topology: &'a Topology) -> Self {
        let n = topology.welded_positions.len();
        let mut first = vec![0u32; n + 2];
        for &[a, _] in &topology.edges {
            if (a as usize) < n {
                first[a as usize + 1] += 1;
            }
        }
        for v in 0..=n {
            first[v + 1] += first[v];
        }
        Self { edges: &topology.edges, first }
    }

    fn find(&self, u: u32, w: u32) -> Option<usize> {
        let (a, b) = (u.min(w), u.max(w));
        let lo = *self.first.get(a as usize)? as usize;
        let hi = *self.first.get(a as usize + 1)? as usize;
        self.edges[lo..hi].binary_search_by_key(&b, |e| e[1]).ok().map(|k| lo + k)
    }
}

/// What a file's `visibility` and `silhouetteNormals` say, per welded edge.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DecodedEdgeVisibility {
    /// Welded vertex pairs `[a, b]`, `a < b`, of the hard edges, sorted.
    pub hard: Vec<[u32; 2]>,
    /// Silhouette edges with their two decoded normals, sorted by pair.
    pub silhouettes: Vec<([u32; 2], [Vec3; 2])>,
}

/// Decodes one primitive's payload and checks the draft's rules by recounting every edge
/// independently of [`Topology`]: edges are identified by welded vertex pairs (`welded_of_vertex`;
/// pass the identity to identify them by index as a plain client would); `silhouette_normals` are
/// the decoded vectors (`drafter_core::snorm8_decode` for the BYTE normals we write).
pub fn decode_edge_visibility(
    triangles: &[[u32; 3]],
    welded_of_vertex: &[u32],
    visibility: &[u8],
    silhouette_normals: &[Vec3],
) -> Result<DecodedEdgeVisibility, VisibilityError> {
    let slots = 3 * triangles.len();
    let expected = (2 * slots).div_ceil(8);
    if visibility.len() != expected {
        return Err(VisibilityError::Length { expected, found: visibility.len(), triangles: triangles.len() });
    }
    if !slots.is_multiple_of(4) && visibility.last().is_some_and(|&last| last >> (2 * (slots % 4)) != 0) {
        return Err(VisibilityError::TrailingBits);
    }
    // Per pair: how often each value occurs, and the normals of its 1.
    type Tally = ([u32; 4], Option<[Vec3; 2]>);
    let mut edges: HashMap<[u32; 2], Tally> = HashMap::new();
    let mut ones = 0usize;
    let mut any = false;
    for (t, tri) in triangles.iter().enumerate() {
        let w = welded_triangle(tri, t, welded_of_vertex)?;
        for k in 0..3 {
            let slot = 3 * t + k;
            let value = (visibility[slot / 4] >> (2 * (slot % 4))) & 3;
            any |= value != 0;
            if collapsed(&w) {
                if value != 0 {
                    return Err(VisibilityError::CollapsedEdge { triangle: t, corner: k, value });
                }
                continue;
            }
            let (a, b) = (w[k], w[(k + 1) % 3]);
            let entry = edges.entry([a.min(b), a.max(b)]).or_default();
            entry.0[value as usize] += 1;
            if value == SILHOUETTE {
                if let (Some(&x), Some(&y)) = (silhouette_normals.get(2 * ones), silhouette_normals.get(2 * ones + 1)) {
                    entry.1 = Some([x, y]);
                }
                ones += 1;
            }
        }
    }
    if silhouette_normals.len() != 2 * ones {
        return Err(VisibilityError::NormalCount { expected: 2 * ones, found: silhouette_normals.len(), ones });
    }
    if !any {
        return Err(VisibilityError::AllHidden);
    }
    let mut out = DecodedEdgeVisibility::default();
    for (&[a, b], &([zeros, ones, twos, threes], normals)) in &edges {
        let hard = twos + threes > 0;
        let broken = if hard { twos != 1 || zeros != 0 || ones != 0 } else { ones > 1 };
        if broken {
            return Err(VisibilityError::EncodeOnce { a, b, zeros, ones, twos, threes });
        }
        if hard {
            out.hard.push([a, b]);
        } else if let (1, Some(n)) = (ones, normals) {
            out.silhouettes.push(([a, b], n));
        }
    }
    out.hard.sort_unstable();
    out.silhouettes.sort_unstable_by_key(|s| s.0);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bumpy `n`×`n` grid, with what a CAD tessellation brings: a seam of unwelded duplicate
    /// vertices, collapsed triangles (a repeated vertex, and two vertices at one position), a fin
    /// on a third face of an edge, and a doubled face.
    fn rough_grid(n: u32, seed: u64) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut rng = drafter_core::rng::Rng::new(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        let mut r = move || rng.unit_f32();
        let mut positions: Vec<Vec3> =
            (0..n * n).map(|i| Vec3::new((i % n) as f32, (i / n) as f32, if r() < 0.3 { r() } else { 0.0 })).collect();
        let at = |x: u32, y: u32| y * n + x;
        let mut triangles = Vec::new();
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                let (a, b, c, d) = (at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1));
                // Right of the seam column, the triangles use copies of the seam's vertices.
                let mut seam = |v: u32| {
                    if x == n / 2 && v % n == n / 2 {
                        positions.push(positions[v as usize]);
                        positions.len() as u32 - 1
                    } else {
                        v
                    }
                };
                let (a, d) = (seam(a), seam(d));
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
                if r() < 0.02 {
                    triangles.push([a, a, b]);
                }
                if r() < 0.02 {
                    triangles.push([a, b, d]);
                    triangles.push([b, a, d]);
                }
            }
        }
        // A fin over the first quad's diagonal, and a triangle collapsed by the weld.
        positions.push(Vec3::new(0.5, 0.5, 2.0));
        triangles.push([at(0, 0), at(1, 1), positions.len() as u32 - 1]);
        positions.push(positions[at(2, 2) as usize]);
        triangles.push([at(2, 2), positions.len() as u32 - 1, at(3, 2)]);
        (positions, triangles)
    }

    /// The block encoder against the serial walk, chunk by chunk over one state: the same
    /// output, and the same error where the input breaks the caller's promises in several places.
    #[test]
    fn face_blocks_encode_as_the_serial_walk() {
        use crate::{LineOptions, classify_edges};
        use drafter_core::Weld;
        for (case, (n, block)) in
            [(9, 4), (23, 8), (40, 4), (64, FACE_BLOCK), (150, 8), (150, 4096 - 4)].into_iter().enumerate()
        {
            let (positions, triangles) = rough_grid(n, case as u64);
            let topology = Topology::from_triangles(&positions, &triangles, Weld::Exact);
            let options = LineOptions { crease_angle_deg: 20.0, ..Default::default() };
            let lines = classify_edges(&topology, None, &options).unwrap();
            assert!(lines.counts.hard() > 0 && lines.counts.silhouette_candidate > 0, "case {case}");
            let len = triangles.len();
            let cuts = [0, len / 5, len / 2, len / 2 + 1, len];
            let (mut serial, mut blocks) = (SilhouettesEncoded::default(), SilhouettesEncoded::default());
            for w in cuts.windows(2) {
                let chunk = &triangles[w[0]..w[1]];
                let expected = encode_chunk(chunk, Some(w[0]), &topology, &lines, &mut serial).unwrap();
                let got = encode_faces_in_blocks(chunk, w[0], &topology, &lines, &mut blocks, block).unwrap();
                assert_eq!(got, expected, "case {case}: chunk at {}", w[0]);
                assert_eq!(blocks.written, serial.written, "case {case}");
            }
            // Broken promises: shifted faces, a vertex out of range, and a candidate the lines do
            // not list, alone and together (the first the walk meets is reported).
            let mut missing = lines.clone();
            missing.candidates.remove(missing.candidates.len() / 2);
            let mut bad_vertex = triangles.clone();
            bad_vertex[2 * len / 3][1] = positions.len() as u32 + 7;
            let mut early_bad_vertex = triangles.clone();
            early_bad_vertex[3][2] = u32::MAX;
            for (what, tris, first, lines) in [
                ("shifted", &triangles[1..], 0, &lines),
                ("beyond", &triangles[..], 1, &lines),
                ("vertex", &bad_vertex[..], 0, &lines),
                ("early vertex", &early_bad_vertex[..], 0, &missing),
                ("missing", &triangles[..], 0, &missing),
                ("missing and vertex", &bad_vertex[..], 0, &missing),
            ] {
                let expected = encode_chunk(tris, Some(first), &topology, lines, &mut SilhouettesEncoded::default());
                let got =
                    encode_faces_in_blocks(tris, first, &topology, lines, &mut SilhouettesEncoded::default(), block);
                assert!(expected.is_err(), "case {case}, {what}");
                assert_eq!(got, expected, "case {case}, {what}");
            }
        }
    }

    #[test]
    fn decoder_rejects_broken_rules() {
        // Two triangles sharing edge 0-2 (slots 2 of t0, 0 of t1).
        let tris = [[0u32, 1, 2], [0, 2, 3]];
        let ident = [0u32, 1, 2, 3];
        let pack = |v: [u8; 6]| -> Vec<u8> {
            let mut b = vec![0u8; 2];
            for (s, x) in v.iter().enumerate() {
                b[s / 4] |= x << (2 * (s % 4));
            }
            b
        };
        // Shared edge written 2 twice.
        let err = decode_edge_visibility(&tris, &ident, &pack([0, 0, 2, 2, 0, 0]), &[]).unwrap_err();
        assert!(matches!(err, VisibilityError::EncodeOnce { a: 0, b: 2, twos: 2, .. }));
        // 3 without 2.
        assert!(decode_edge_visibility(&tris, &ident, &pack([0, 0, 3, 3, 0, 0]), &[]).is_err());
        // Silhouette twice.
        assert!(
            decode_edge_visibility(&tris, &ident, &pack([0, 0, 1, 1, 0, 0]), &[Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE])
                .is_err()
        );
        // Missing normals.
        assert!(matches!(
            decode_edge_visibility(&tris, &ident, &pack([0, 0, 1, 0, 0, 0]), &[]),
            Err(VisibilityError::NormalCount { .. })
        ));
        assert_eq!(decode_edge_visibility(&tris, &ident, &pack([0; 6]), &[]), Err(VisibilityError::AllHidden));
        assert!(matches!(decode_edge_visibility(&tris, &ident, &[0], &[]), Err(VisibilityError::Length { .. })));
        let mut bytes = pack([2, 2, 2, 3, 2, 2]);
        bytes[1] |= 0b1000_0000;
        assert_eq!(decode_edge_visibility(&tris, &ident, &bytes, &[]), Err(VisibilityError::TrailingBits));
        // A valid one.
        let ok = decode_edge_visibility(&tris, &ident, &pack([2, 2, 1, 0, 2, 2]), &[Vec3::Z, Vec3::X]).unwrap();
        assert_eq!(ok.hard.len(), 4);
        assert_eq!(ok.silhouettes.len(), 1);
        assert_eq!(ok.silhouettes[0].0, [0, 2]);
    }
}
