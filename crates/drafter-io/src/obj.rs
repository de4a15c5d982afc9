//! Wavefront OBJ importer, on top of `tobj`.
//!
//! Each `o`/`g` group (tobj also splits a group where its material changes) becomes one [`Mesh`] with
//! one instance at the identity, so an OBJ assembly keeps its parts. Polygons are fan-triangulated by
//! tobj; vertices are re-indexed so that position, normal and texture coordinate share one index
//! (unreferenced vertex records are dropped). A missing or unreadable `.mtl` is a diagnostic, not an
//! error. Material libraries resolve inside the file's folder only.
//!
//! tobj reports *what* failed but not *where*; on error [`locate_error`] re-scans the text with the
//! same rules to name the first offending line.

use std::path::{Component, Path};

use drafter_core::{
    DiagnosticKind, Diagnostics, Instance, Material, MaterialId, Mesh, MeshId, Scene, SourceFormat, TriangleGroup,
};
use glam::{DMat4, Vec2, Vec3};

use crate::error::{ImportError, ParseError};
use crate::raw::drop_nonfinite_faces;

pub(crate) fn import(path: &Path, bytes: &[u8], diagnostics: &mut Diagnostics) -> Result<Scene, ImportError> {
    let folder = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ..Default::default() };
    // tobj reads lines as UTF-8 and fails on any other byte with "read error". CAD tools still
    // write OBJ comments and group names in an 8-bit code page (`g Gehäuse` in Latin-1), so such a
    // file is read as Latin-1, byte for character: names keep their letters, numbers are ASCII.
    let transcoded: String;
    let bytes = match std::str::from_utf8(bytes) {
        Ok(_) => bytes,
        Err(e) => {
            let line = 1 + bytes[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count();
            diagnostics.push(DiagnosticKind::Other, 1, || {
                format!("line {line}: not UTF-8; the file was read as Latin-1 (ISO 8859-1)")
            });
            transcoded = bytes.iter().map(|&b| char::from(b)).collect();
            transcoded.as_bytes()
        }
    };
    let mut reader = std::io::BufReader::new(bytes);
    let (models, materials) =
        tobj::load_obj_buf(&mut reader, &options, |mtl: &Path| load_material_library(&folder, mtl))
            .map_err(|e| locate_error(bytes, &e.to_string()).in_path(path))?;
    let materials = match materials {
        Ok(m) => m,
        Err(e) => {
            diagnostics.push(DiagnosticKind::MissingMaterialLibrary, 1, || {
                format!("material library unusable ({e}); default materials used")
            });
            Vec::new()
        }
    };
    let mut scene = Scene::new(SourceFormat::Obj);
    scene.materials = materials.iter().map(convert_material).collect();
    for model in models {
        let m = &model.mesh;
        let vertex_count = m.positions.len() / 3;
        let mut mesh = Mesh { name: model.name.clone(), ..Mesh::default() };
        mesh.positions = m.positions.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
        mesh.triangles = m.indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        if let Some(bad) = mesh.triangles.iter().flatten().find(|&&v| v as usize >= vertex_count) {
            return Err(ParseError::in_file(format!("group {:?} uses vertex {bad} of {vertex_count}", model.name))
                .in_path(path));
        }
        if m.normals.len() == m.positions.len() {
            mesh.normals = Some(m.normals.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect());
        }
        if m.texcoords.len() / 2 == vertex_count && !m.texcoords.is_empty() {
            mesh.uvs = Some(m.texcoords.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect());
        }
        let material = m.material_id.filter(|&i| i < scene.materials.len()).map(MaterialId::from);
        mesh.groups = vec![TriangleGroup {
            start: 0,
            count: mesh.triangles.len() as u32,
            material,
            vertex_count: vertex_count as u32,
            ..TriangleGroup::default()
        }];
        drop_nonfinite_faces(&mut mesh.positions, &mut mesh.triangles, &mut mesh.groups, diagnostics, &model.name);
        if mesh.normals.as_ref().is_some_and(|n| n.iter().any(|v| !v.is_finite())) {
            diagnostics.push(DiagnosticKind::InvalidNormals, 1, || {
                format!("group {:?}: non-finite normals ignored", model.name)
            });
            mesh.normals = None;
        }
        if mesh.triangles.is_empty() {
            continue;
        }
        let id = MeshId::from(scene.meshes.len());
        let name =
            if model.name.is_empty() || model.name == "unnamed_object" { format!("group {id}") } else { model.name };
        scene.instances.push(Instance { name, mesh: id, node: None, world_from_object: DMat4::IDENTITY });
        scene.meshes.push(mesh);
    }
    if scene.meshes.is_empty() {
        return Err(ParseError::in_file("no triangles with finite positions").in_path(path));
    }
    Ok(scene)
}

/// The material libraries an OBJ's text names (`mtllib` lines, tobj's rule: the rest of the line
/// after the first space, trimmed), in order: the files besides the OBJ that its import reads, for
/// the cache's key. Names that lead out of the folder are listed too (the import refuses them).
pub fn material_libraries(bytes: &[u8]) -> Vec<std::path::PathBuf> {
    // Only the lines holding the word are decoded: a batch's cache keys every OBJ it is given.
    let mut libraries = Vec::new();
    if memchr::memmem::find(bytes, b"mtllib").is_none() {
        return libraries;
    }
    let utf8 = std::str::from_utf8(bytes).is_ok();
    let mut searched = 0;
    while let Some(found) = memchr::memmem::find(&bytes[searched..], b"mtllib").map(|at| searched + at) {
        let start = memchr::memrchr(b'\n', &bytes[..found]).map_or(0, |at| at + 1);
        let end = memchr::memchr(b'\n', &bytes[found..]).map_or(bytes.len(), |at| found + at);
        searched = end;
        let line = &bytes[start..end];
        // As the import reads the file: UTF-8, else Latin-1 byte for character.
        let line: String = if utf8 {
            String::from_utf8_lossy(line).into_owned()
        } else {
            line.iter().map(|&b| char::from(b)).collect()
        };
        let line = line.strip_suffix('\r').unwrap_or(&line);
        if line.split_whitespace().next() == Some("mtllib") {
            libraries.push(std::path::PathBuf::from(line.split_once(' ').unwrap_or_default().1.trim()));
        }
    }
    libraries
}

/// Opens a material library named by the OBJ in `folder`: only a relative path that stays inside
/// the folder.
pub fn open_material_library(folder: &Path, mtl: &Path) -> Option<std::fs::File> {
    let inside = mtl.components().all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    if !inside {
        return None;
    }
    std::fs::File::open(folder.join(mtl)).ok()
}

fn load_material_library(folder: &Path, mtl: &Path) -> tobj::MTLLoadResult {
    let file = open_material_library(folder, mtl).ok_or(tobj::LoadError::OpenFileFailed)?;
    tobj::load_mtl_buf(&mut std::io::BufReader::new(file))
}

/// MTL has no PBR factors except the common `Pm`/`Pr` extension; without them the material is a
/// dielectric whose roughness follows the Phong exponent (Ns 0 → 1, Ns 1000 → ~0.04).
fn convert_material(m: &tobj::Material) -> Material {
    let [r, g, b] = m.diffuse.unwrap_or([0.8, 0.8, 0.8]);
    let alpha = m.dissolve.unwrap_or(1.0);
    let param = |key: &str| m.unknown_param.get(key).and_then(|v| v.trim().parse::<f32>().ok());
    let roughness = param("Pr").unwrap_or_else(|| {
        let ns = m.shininess.unwrap_or(0.0).max(0.0);
        (2.0 / (ns + 2.0)).sqrt()
    });
    Material {
        name: m.name.clone(),
        base_color: [r, g, b, alpha],
        metallic: param("Pm").unwrap_or(0.0).clamp(0.0, 1.0),
        roughness: roughness.clamp(0.0, 1.0),
    }
}

/// Finds the first line that breaks the rule tobj complained about (`message` is tobj's text).
fn locate_error(bytes: &[u8], message: &str) -> ParseError {
    let text = String::from_utf8_lossy(bytes);
    let (mut positions, mut texcoords, mut normals) = (0i64, 0i64, 0i64);
    for (number, line) in text.lines().enumerate() {
        let line_no = number + 1;
        let mut tokens = line.split_whitespace();
        let Some(keyword) = tokens.next() else { continue };
        let rest: Vec<&str> = tokens.collect();
        let floats_ok = |min: usize| rest.len() >= min && rest.iter().take(min).all(|t| t.parse::<f32>().is_ok());
        match keyword {
            "v" => {
                if !floats_ok(3) {
                    return ParseError::at_line(line_no, format!("{message}: a vertex needs 3 numbers"));
                }
                // `x y z`, `x y z w`, or `x y z r g b` (a colour per vertex): tobj takes no other count.
                if ![3, 4, 6].contains(&rest.len()) {
                    return ParseError::at_line(
                        line_no,
                        format!("{message}: a vertex has 3, 4 or 6 numbers, not {}", rest.len()),
                    );
                }
                positions += 1;
            }
            "vt" => {
                if !floats_ok(1) {
                    return ParseError::at_line(line_no, format!("{message}: bad texture coordinate"));
                }
                texcoords += 1;
            }
            "vn" => {
                if !floats_ok(3) {
                    return ParseError::at_line(line_no, format!("{message}: a normal needs 3 numbers"));
                }
                normals += 1;
            }
            "f" => {
                if rest.len() < 3 {
                    return ParseError::at_line(line_no, format!("{message}: a face needs at least 3 vertices"));
                }
                for corner in &rest {
                    for (slot, (field, count)) in corner.split('/').zip([positions, texcoords, normals]).enumerate() {
                        if field.is_empty() && slot > 0 {
                            continue;
                        }
                        let Ok(i) = field.parse::<i64>() else {
                            return ParseError::at_line(line_no, format!("{message}: {corner:?} is not a face index"));
                        };
                        let resolved = if i < 0 { count + i } else { i - 1 };
                        if i == 0 || resolved < 0 || resolved >= count {
                            let kind = if slot == 0 {
                                "vertex"
                            } else if slot == 1 {
                                "texture coordinate"
                            } else {
                                "normal"
                            };
                            return ParseError::at_line(
                                line_no,
                                format!("{message}: {kind} index {i} is out of range ({count} defined so far)"),
                            );
                        }
                    }
                }
            }
            _ => {}
        }
    }
    ParseError::in_file(message.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn import_text(text: &str) -> Result<Scene, ImportError> {
        import(Path::new("test.obj"), text.as_bytes(), &mut Diagnostics::new())
    }

    #[test]
    fn latin1_text_is_read_with_a_note() {
        let mut d = Diagnostics::new();
        let bytes = b"# Erstellt f\xfcr\nv 0 0 0\nv 1 0 0\nv 0 1 0\ng Geh\xe4use\nf 1 2 3\n";
        let scene = import(Path::new("l.obj"), bytes, &mut d).unwrap();
        assert_eq!(scene.instances[0].name, "Geh\u{e4}use");
        assert_eq!(scene.meshes[0].triangles.len(), 1);
        let notes = d.into_vec();
        assert!(notes.iter().any(|n| n.first_example.starts_with("line 1: not UTF-8")), "{notes:?}");
    }

    #[test]
    fn a_vertex_with_five_numbers_is_named_by_line() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0 1 1\nf 1 2 3\n";
        let e = import_text(text).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("3, 4 or 6 numbers, not 5"), "{e}");
    }

    #[test]
    fn groups_become_instances() {
        let scene = import_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\no a\nf 1 2 3\no b\nf 2 4 3\n").unwrap();
        assert_eq!(scene.meshes.len(), 2);
        assert_eq!(scene.instances.iter().map(|i| i.name.as_str()).collect::<Vec<_>>(), ["a", "b"]);
    }

    #[test]
    fn quads_are_triangulated_and_missing_mtl_is_a_diagnostic() {
        let mut d = Diagnostics::new();
        let text = "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
        let scene = import(Path::new("q.obj"), text.as_bytes(), &mut d).unwrap();
        assert_eq!(scene.meshes[0].triangles.len(), 2);
        assert_eq!(d.count(DiagnosticKind::MissingMaterialLibrary), 1);
    }

    #[test]
    fn out_of_range_index_names_the_line() {
        let err = import_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n").unwrap_err().to_string();
        assert!(err.contains("line 5"), "{err}");
    }

    #[test]
    fn bad_number_names_the_line() {
        let err = import_text("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n").unwrap_err().to_string();
        assert!(err.contains("line 2"), "{err}");
    }

    #[test]
    fn nan_vertices_drop_their_faces() {
        let mut d = Diagnostics::new();
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nf 1 2 3\nf 1 2 4\n";
        let scene = import(Path::new("n.obj"), text.as_bytes(), &mut d).unwrap();
        assert_eq!(scene.meshes[0].triangles.len(), 1);
        assert_eq!(d.count(DiagnosticKind::DroppedFace), 1);
    }
}
