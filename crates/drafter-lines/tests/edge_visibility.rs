//! The `EXT_mesh_primitive_edge_visibility` encoder against a decoder that recounts every edge.

// Helpers outside #[test] functions unwrap too: this whole file is test code.
#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use drafter_core::{Topology, Weld};
use drafter_lines::*;

fn round_trip(mesh: &TestMesh) {
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    let encoded = encode_edge_visibility(&mesh.triangles, &topology, &lines).unwrap();
    assert_eq!(encoded.visibility.len(), (6 * mesh.triangles.len()).div_ceil(8));
    assert_eq!(encoded.silhouette_normals.len(), 2 * encoded.silhouette_edges.len());
    assert_eq!(encoded.hard_edges.len(), lines.counts.hard(), "{}", mesh.name);
    assert_eq!(encoded.silhouette_edges.len(), lines.counts.silhouette_candidate);

    let decoded = decode_edge_visibility(
        &mesh.triangles,
        &topology.welded_of_vertex,
        &encoded.visibility,
        &encoded.decoded_normals(),
    )
    .unwrap();
    let mut hard: Vec<[u32; 2]> =
        (0..lines.classes.len()).filter(|&e| lines.classes[e].is_hard()).map(|e| topology.edges[e]).collect();
    hard.sort_unstable();
    assert_eq!(decoded.hard, hard, "{}", mesh.name);
    let pairs: Vec<[u32; 2]> = decoded.silhouettes.iter().map(|s| s.0).collect();
    let expected: Vec<[u32; 2]> = lines.candidates.iter().map(|&e| topology.edges[e as usize]).collect();
    assert_eq!(pairs, expected);
    // Normals survive normalized bytes (within 0.5°, the worst case of per-axis rounding at the worst
    // direction), in the edge's face order.
    for ((_, [d1, d2]), [n1, n2]) in decoded.silhouettes.iter().zip(&lines.candidate_normals) {
        assert!(d1.angle_between(*n1).to_degrees() < 0.5);
        assert!(d2.angle_between(*n2).to_degrees() < 0.5);
    }
    // The encoding order of the 1s is triangle order: the decoder's normals match the encoder's
    // edge list one to one.
    for (k, &e) in encoded.silhouette_edges.iter().enumerate() {
        let c = lines.candidates.binary_search(&e).unwrap();
        assert_eq!(
            encoded.silhouette_normals[2 * k],
            drafter_core::snorm8_encode_direction(lines.candidate_normals[c][0])
        );
        assert_eq!(
            encoded.silhouette_normals[2 * k + 1],
            drafter_core::snorm8_encode_direction(lines.candidate_normals[c][1])
        );
    }
}

/// The bake classifies without the candidates' normals and points: everything else, and the
/// encoding made from it, must be what the full classification gives.
#[test]
fn classification_for_encoding_equals_the_full_one() {
    let meshes = [uv_sphere(64, 40), plate_with_holes(12, 16), random_blob(3), random_lattice_mesh(30, 120, 4)];
    for mesh in &meshes {
        let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
        let full = classify_edges(&topology, None, &LineOptions::default()).unwrap();
        let lean = classify_edges_for_encoding(&topology, FaceLabels::default(), &LineOptions::default()).unwrap();
        assert!(!full.candidates.is_empty() && lean.candidate_normals.is_empty() && lean.candidate_points.is_empty());
        assert!(lean.dihedral_deg.is_empty() && full.dihedral_deg.len() == topology.edges.len());
        let expected = FeatureEdges {
            candidate_normals: Vec::new(),
            candidate_points: Vec::new(),
            dihedral_deg: Vec::new(),
            ..full.clone()
        };
        assert_eq!(lean, expected, "{}", mesh.name);
        assert_eq!(
            encode_edge_visibility(&mesh.triangles, &topology, &lean).unwrap(),
            encode_edge_visibility(&mesh.triangles, &topology, &full).unwrap(),
            "{}",
            mesh.name
        );
    }
}

#[test]
fn sphere_round_trips() {
    round_trip(&uv_sphere(64, 40));
}

#[test]
fn unwelded_cad_plate_round_trips() {
    // Every CAD face is its own patch: the seams are found through the weld, so each crease is
    // encoded 2 on one side and 3 on the other, never 2 twice.
    let plate = plate_with_holes(12, 16);
    round_trip(&plate);
    let topology = Topology::from_triangles(&plate.positions, &plate.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    let encoded = encode_edge_visibility(&plate.triangles, &topology, &lines).unwrap();
    let values: Vec<u8> =
        (0..3 * plate.triangles.len()).map(|s| (encoded.visibility[s / 4] >> (2 * (s % 4))) & 3).collect();
    assert!(values.contains(&HARD_REPEATED) && values.contains(&HARD) && values.contains(&SILHOUETTE));
}

#[test]
fn random_soups_round_trip() {
    for seed in 0..30 {
        let mesh = random_lattice_mesh(20, 60, seed);
        let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
        let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
        let encoded = encode_edge_visibility(&mesh.triangles, &topology, &lines).unwrap();
        if encoded.has_visible_edges() {
            round_trip(&mesh);
        }
    }
}

#[test]
fn per_primitive_encoding_holds_the_rules() {
    // Two "primitives": the halves of a sphere's triangle list, encoded separately.
    let mesh = uv_sphere(32, 20);
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions { crease_angle_deg: 5.0, ..Default::default() }).unwrap();
    let half = mesh.triangles.len() / 2;
    for part in [&mesh.triangles[..half], &mesh.triangles[half..]] {
        let e = encode_edge_visibility(part, &topology, &lines).unwrap();
        decode_edge_visibility(part, &topology.welded_of_vertex, &e.visibility, &e.decoded_normals()).unwrap();
    }
    // Triangles that are not in the topology are a caller bug.
    assert!(matches!(
        encode_edge_visibility(&[[0, 5, 300]], &topology, &lines),
        Err(VisibilityError::UnknownEdge { .. })
    ));
    assert!(matches!(
        encode_edge_visibility(&[[0, 1, 1_000_000]], &topology, &lines),
        Err(VisibilityError::VertexOutOfRange { .. })
    ));
}

#[test]
fn chunks_of_a_split_primitive_encode_hard_edges_each_and_silhouettes_once() {
    // A primitive split into consecutive chunks (the bake's 16-bit index split): every chunk holds
    // the rules on its own (a hard edge on a seam is 2 in each chunk that has it), and each
    // silhouette candidate is 1 exactly once over the chunks, in the first chunk that meets it.
    let mesh = uv_sphere(32, 20);
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions { crease_angle_deg: 10.0, ..Default::default() }).unwrap();
    assert!(lines.counts.hard() > 0 && lines.counts.silhouette_candidate > 0);
    let whole = encode_edge_visibility(&mesh.triangles, &topology, &lines).unwrap();
    let n = mesh.triangles.len();
    let chunks = [&mesh.triangles[..n / 3], &mesh.triangles[n / 3..2 * n / 3], &mesh.triangles[2 * n / 3..]];
    let mut encoded = SilhouettesEncoded::default();
    let mut silhouettes = Vec::new();
    let (mut hard_repeats, mut candidate_meets) = (0, 0);
    for chunk in chunks {
        let e = encode_edge_visibility_continuing(chunk, &topology, &lines, &mut encoded).unwrap();
        let decoded =
            decode_edge_visibility(chunk, &topology.welded_of_vertex, &e.visibility, &e.decoded_normals()).unwrap();
        // The edges of this chunk's own triangles, by class.
        let mut edges: Vec<usize> = chunk
            .iter()
            .flat_map(|t| (0..3).map(move |k| [t[k], t[(k + 1) % 3]]))
            .map(|[a, b]| [topology.welded_of_vertex[a as usize], topology.welded_of_vertex[b as usize]])
            .filter_map(|[a, b]| topology.edges.binary_search(&[a.min(b), a.max(b)]).ok())
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let hard: Vec<[u32; 2]> =
            edges.iter().filter(|&&e| lines.classes[e].is_hard()).map(|&e| topology.edges[e]).collect();
        assert_eq!(decoded.hard, hard, "exactly the hard edges of the chunk's triangles");
        hard_repeats += hard.len();
        candidate_meets += edges.iter().filter(|&&e| lines.classes[e] == EdgeClass::SilhouetteCandidate).count();
        silhouettes.extend(decoded.silhouettes.iter().map(|s| s.0));
        assert_eq!(e.silhouette_edges.len(), decoded.silhouettes.len());
    }
    // Seams exist for both kinds: hard edges are counted again per chunk, candidates are not.
    assert!(hard_repeats > lines.counts.hard() && candidate_meets > lines.counts.silhouette_candidate);
    silhouettes.sort_unstable();
    let expected: Vec<[u32; 2]> = lines.candidates.iter().map(|&e| topology.edges[e as usize]).collect();
    assert_eq!(silhouettes, expected, "every candidate exactly once over the chunks");
    assert_eq!(whole.silhouette_edges.len(), expected.len());
    // A fresh state per call is the one-primitive encoder.
    let again =
        encode_edge_visibility_continuing(&mesh.triangles, &topology, &lines, &mut SilhouettesEncoded::default())
            .unwrap();
    assert_eq!(again, whole);
}

#[test]
fn encoding_faces_by_their_edge_ids_equals_the_searching_encoder() {
    // The bake's encoder reads each corner's edge from `Topology::face_edges`; the general one finds
    // it by its welded vertex pair. Same bytes, chunk by chunk, on meshes with degenerate, collapsed,
    // non-manifold and boundary faces (the random lattices have all of them).
    let mut meshes = vec![uv_sphere(32, 20), plate_with_holes(4, 12)];
    meshes.extend((0..6).map(|seed| random_lattice_mesh(300, 1500, seed)));
    for mesh in &meshes {
        let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
        let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
        let n = mesh.triangles.len();
        let cuts = [0, n / 3, 2 * n / 3, n];
        let (mut searching, mut by_id) = (SilhouettesEncoded::default(), SilhouettesEncoded::default());
        for w in cuts.windows(2) {
            let chunk = &mesh.triangles[w[0]..w[1]];
            let expected = encode_edge_visibility_continuing(chunk, &topology, &lines, &mut searching).unwrap();
            let got = encode_faces_continuing(chunk, w[0], &topology, &lines, &mut by_id).unwrap();
            assert_eq!(got, expected, "{}: chunk at {}", mesh.name, w[0]);
        }
        // Triangles that are not the faces named are refused, never read as other faces' edges.
        let shifted =
            encode_faces_continuing(&mesh.triangles[1..], 0, &topology, &lines, &mut SilhouettesEncoded::default());
        assert!(matches!(shifted, Err(VisibilityError::UnknownEdge { .. })), "{}", mesh.name);
        let beyond = encode_faces_continuing(&mesh.triangles, 1, &topology, &lines, &mut SilhouettesEncoded::default());
        assert!(matches!(beyond, Err(VisibilityError::UnknownEdge { .. })), "{}", mesh.name);
    }
}
