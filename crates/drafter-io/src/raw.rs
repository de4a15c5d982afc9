//! The common output of the single-mesh readers (STL, OFF, PLY) before it becomes a [`Scene`].

use drafter_core::{DiagnosticKind, Diagnostics, Mesh, Scene, SourceFormat, TriangleGroup};
use glam::Vec3;

use crate::error::ParseError;

/// One mesh as read from a file: positions and triangles exactly as stored (polygons already
/// fan-triangulated), not yet checked for NaN.
///
/// Invariant (enforced by each reader, which reports the place of the offence): every index is
/// `< positions.len()`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawMesh {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex normals if the file has them (PLY nx/ny/nz), one per position.
    pub normals: Option<Vec<[f32; 3]>>,
}

/// Turns a reader's output into a one-instance scene: drops faces using non-finite positions (with a
/// diagnostic) and fails if nothing drawable is left.
pub(crate) fn single_mesh_scene(
    raw: RawMesh,
    format: SourceFormat,
    name: &str,
    diagnostics: &mut Diagnostics,
) -> Result<Scene, ParseError> {
    let mut mesh = Mesh { name: name.to_owned(), ..Mesh::default() };
    mesh.positions = raw.positions.iter().map(|&p| Vec3::from(p)).collect();
    let total = raw.triangles.len();
    mesh.triangles = raw.triangles;
    let vertex_count = mesh.positions.len() as u32;
    mesh.groups = vec![TriangleGroup { start: 0, count: total as u32, vertex_count, ..TriangleGroup::default() }];
    drop_nonfinite_faces(&mut mesh.positions, &mut mesh.triangles, &mut mesh.groups, diagnostics, name);
    if let Some(normals) = raw.normals {
        if normals.len() == mesh.positions.len() && normals.iter().all(|n| n.iter().all(|c| c.is_finite())) {
            mesh.normals = Some(normals.into_iter().map(Vec3::from).collect());
        } else {
            diagnostics.push(DiagnosticKind::InvalidNormals, 1, || "vertex normals are not finite; ignored".into());
        }
    }
    if mesh.triangles.is_empty() {
        return Err(ParseError::in_file(if total == 0 {
            "no triangles".to_owned()
        } else {
            "no triangle with finite vertex positions".to_owned()
        }));
    }
    Ok(Scene::single_mesh(format, mesh, name))
}

/// Drops triangles that use a non-finite position (NaN or infinite), keeping `groups` consistent,
/// and zeroes those positions so the array stays dense and finite. Reports both with diagnostics.
pub(crate) fn drop_nonfinite_faces(
    positions: &mut [Vec3],
    triangles: &mut Vec<[u32; 3]>,
    groups: &mut [TriangleGroup],
    diagnostics: &mut Diagnostics,
    context: &str,
) {
    let finite: Vec<bool> = positions.iter().map(|p| p.is_finite()).collect();
    let Some(first) = finite.iter().position(|&f| !f) else { return };
    let bad_vertices = finite.iter().filter(|&&f| !f).count();
    diagnostics.push(DiagnosticKind::NonFinitePosition, bad_vertices, || {
        format!("{context}: vertex {first} is NaN or infinite")
    });
    for (p, &ok) in positions.iter_mut().zip(&finite) {
        if !ok {
            *p = Vec3::ZERO;
        }
    }
    let keep = |t: &[u32; 3]| t.iter().all(|&v| finite[v as usize]);
    let mut kept = Vec::with_capacity(triangles.len());
    if groups.is_empty() {
        kept.extend(triangles.iter().copied().filter(keep));
    }
    for group in groups.iter_mut() {
        let range = group.start as usize..(group.start + group.count) as usize;
        let start = kept.len() as u32;
        kept.extend(triangles[range].iter().copied().filter(keep));
        group.start = start;
        group.count = kept.len() as u32 - start;
    }
    let dropped = triangles.len() - kept.len();
    *triangles = kept;
    diagnostics
        .push(DiagnosticKind::DroppedFace, dropped, || format!("{context}: {dropped} faces used non-finite vertices"));
}
