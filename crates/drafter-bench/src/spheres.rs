//! Synthetic scenes for `drafter bench parts` and `drafter bench render`'s edit timing: the same UV
//! spheres on a square grid, grouped into any number of parts, so that only the grouping changes
//! with the part count.

use drafter_core::{Instance, Mesh, MeshId, Node, NodeId, Scene, SourceFormat, TriangleGroup};
use drafter_format::{BakedFile, NodeExtension, PartRecord, RootExtension};
use glam::{DMat4, Vec3};

/// Appends a UV sphere of about `triangles` triangles at `center` to `mesh`.
fn add_sphere(mesh: &mut Mesh, center: Vec3, radius: f32, triangles: usize) {
    let side = ((triangles as f64 / 2.0).sqrt().round() as u32).max(3);
    let (rows, cols) = (side, side);
    let base = mesh.positions.len() as u32;
    let normals = mesh.normals.get_or_insert_with(Vec::new);
    for r in 0..=rows {
        let theta = std::f32::consts::PI * r as f32 / rows as f32;
        for c in 0..=cols {
            let phi = std::f32::consts::TAU * c as f32 / cols as f32;
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            mesh.positions.push(center + n * radius);
            normals.push(n);
        }
    }
    for r in 0..rows {
        for c in 0..cols {
            let a = base + r * (cols + 1) + c;
            let b = a + cols + 1;
            mesh.triangles.push([a, b, a + 1]);
            mesh.triangles.push([a + 1, b, b + 1]);
        }
    }
}

/// Closes `mesh` with one triangle group (one glTF primitive) over all of it.
fn close(mut mesh: Mesh) -> Mesh {
    mesh.groups.push(TriangleGroup {
        start: 0,
        count: mesh.triangles.len() as u32,
        primitive: Some(0),
        first_vertex: 0,
        vertex_count: mesh.positions.len() as u32,
        material: None,
    });
    mesh
}

fn record(id: u32, center: Vec3, radius: f32, triangles: usize) -> Result<PartRecord, serde_json::Error> {
    let c = center.as_dvec3();
    let s = f64::from(radius) * 2.0;
    // Projector along +x over the sphere: p = 1/2 + (x − c.x)/s.
    let matrix = [
        1.0 / s,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0 / s,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0 / s,
        0.0,
        0.5 - c.x / s,
        0.5 - c.y / s,
        0.5 - c.z / s,
        1.0,
    ];
    serde_json::from_value(serde_json::json!({
        "id": id,
        "name": format!("sphere_{id}"),
        "triangles": triangles,
        "obb": { "center": c.to_array(), "axes": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                 "halfExtents": [radius, radius, radius], "volume": s * s * s, "method": "aabb" },
        "projector": { "anchor": c.to_array(), "direction": [1, 0, 0], "scale": s, "matrix": matrix },
        "gradient": { "q": 10, "f": 0.5, "p": 1.0, "transfer": "identity" }
    }))
}

/// The spheres of every scene: the same triangles whatever the part count.
pub const SPHERES: usize = 1000;

/// [`SPHERES`] spheres with `triangles` in all, grouped into `parts` parts of consecutive
/// spheres: one mesh with a label per part (`labelled`), or one mesh and one instance per part
/// (unbaked: each instance is a part). Only the grouping changes with `parts`. The part records of a
/// labelled scene come with it, as a baked file's; an unlabelled scene has none.
pub fn scene(parts: usize, triangles: usize, labelled: bool) -> Result<(Scene, Option<BakedFile>), serde_json::Error> {
    let side = (SPHERES as f64).sqrt().ceil() as usize;
    let spacing = 2.0 / side as f32;
    let radius = spacing * 0.45;
    let per = triangles / SPHERES;
    let centers: Vec<Vec3> = (0..SPHERES)
        .map(|i| Vec3::new((i % side) as f32 * spacing - 1.0, 0.0, (i / side) as f32 * spacing - 1.0))
        .collect();
    let parts = parts.clamp(1, SPHERES);
    let members: Vec<Vec<usize>> =
        (0..parts).map(|p| (0..SPHERES).filter(|i| i * parts / SPHERES == p).collect()).collect();
    // Each part's centre (mean of its spheres) and the radius of a ball around it holding them.
    let bounds: Vec<(Vec3, f32)> = members
        .iter()
        .map(|m| {
            let c = m.iter().map(|&i| centers[i]).sum::<Vec3>() / m.len().max(1) as f32;
            let r = m.iter().map(|&i| (centers[i] - c).length()).fold(0.0f32, f32::max) + radius;
            (c, r)
        })
        .collect();
    let mut scene = Scene::new(SourceFormat::Gltf);
    if labelled {
        let mut mesh = Mesh { name: "spheres".into(), ..Mesh::default() };
        let mut labels = Vec::new();
        let mut records = Vec::new();
        for (p, m) in members.iter().enumerate() {
            let first = mesh.triangles.len();
            for &i in m {
                add_sphere(&mut mesh, centers[i], radius, per);
            }
            let count = mesh.triangles.len() - first;
            labels.extend(std::iter::repeat_n(p as u32, count));
            records.push(record(p as u32, bounds[p].0, bounds[p].1, count)?);
        }
        scene.meshes.push(close(mesh));
        scene.nodes.push(Node {
            name: "spheres".into(),
            parent: None,
            children: Vec::new(),
            parent_from_local: DMat4::IDENTITY,
            mesh: Some(MeshId(0)),
        });
        scene.roots.push(NodeId(0));
        scene.instances.push(Instance {
            name: "spheres".into(),
            mesh: MeshId(0),
            node: Some(NodeId(0)),
            world_from_object: DMat4::IDENTITY,
        });
        let root: RootExtension = serde_json::from_value(serde_json::json!({
            "version": drafter_format::FORMAT_VERSION,
            "generator": drafter_format::GENERATOR,
            "input": { "name": "spheres", "format": "gltf", "sha256": "" },
            "sceneCenter": [0.0, 0.0, 0.0],
            "partCount": parts
        }))?;
        let baked = BakedFile {
            root,
            nodes: vec![(0, NodeExtension { parts: records })],
            primitive_labels: vec![(0, 0, labels)],
            primitive_edges: Vec::new(),
            mesh_silhouettes: Vec::new(),
        };
        Ok((scene, Some(baked)))
    } else {
        for (p, m) in members.iter().enumerate() {
            let (c, _) = bounds[p];
            let mut mesh = Mesh { name: format!("part_{p}"), ..Mesh::default() };
            for &i in m {
                add_sphere(&mut mesh, centers[i] - c, radius, per);
            }
            scene.meshes.push(close(mesh));
            scene.instances.push(Instance {
                name: format!("part_{p}"),
                mesh: MeshId(p as u32),
                node: None,
                world_from_object: DMat4::from_translation(c.as_dvec3()),
            });
        }
        Ok((scene, None))
    }
}
