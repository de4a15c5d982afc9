//! The lines pass draws exactly the silhouettes drafter-lines' brute force selects ("the
//! lines pass draws exactly the edges the brute-force test selects for that camera"), and picking
//! reads the part under a pixel.
//!
//! The reference is computed here, independently of the viewer's query path: the baked file is
//! read again with drafter-format, each candidate's point is taken from the imported mesh, the
//! camera of the rendered frame is taken into each instance's object space with this file's own
//! f64 arithmetic, and [`drafter_lines::BruteForce`] tests every candidate serially. The viewer's
//! side is what the renderer uploaded in that frame ([`drafter_render::Renderer::last_silhouettes`]),
//! which went through the stored hierarchies when the file has them.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use drafter_lines::{BruteForce, EdgeSet, View as LinesView};
use drafter_render::edges::{DrawnSilhouette, Hierarchies};
use drafter_render::{Camera, Model, RenderOptions, Renderer, Style, View};
use glam::{DMat4, Vec3};

/// A baked file in memory: the viewer's model, the file's extension data and its imported scene.
struct Baked {
    bytes: Vec<u8>,
    model: Model,
    file: drafter_format::BakedFile,
    scene: drafter_core::Scene,
}

fn bake(path: &Path) -> Baked {
    let imported = drafter_io::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let baked = drafter_bake::bake(&imported.scene, &drafter_bake::BakeConfig::default())
        .unwrap_or_else(|e| panic!("{}: bake failed: {e}", path.display()));
    let bytes = baked.written.main;
    let name = Path::new("baked.glb");
    let model = Model::load_bytes(name, &bytes).expect("baked file loads");
    let file = drafter_format::read(&bytes, &|_| None).expect("baked file reads");
    let scene = drafter_io::import_bytes(name, &bytes).expect("baked file imports").scene;
    Baked { bytes, model, file, scene }
}

/// Brute force over the file's candidates of every instance, in its object space.
fn reference(b: &Baked, camera: &Camera, transform_eye: bool) -> BTreeSet<DrawnSilhouette> {
    let origin = b.model.origin;
    let mut out = BTreeSet::new();
    for (instance, (&mesh, world_from_object)) in
        b.model.instance_mesh.iter().zip(&b.model.instance_world_from_object).enumerate()
    {
        let Some((_, s)) = b.file.mesh_silhouettes.iter().find(|(m, _)| *m == mesh) else { continue };
        let m = &b.scene.meshes[mesh as usize];
        let normals: Vec<[Vec3; 2]> = s
            .candidate_normals
            .chunks_exact(6)
            .map(|c| [Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5])])
            .collect();
        let points: Vec<Vec3> = s
            .candidate_corners
            .iter()
            .map(|&c| m.positions[m.triangles[(c / 3) as usize][(c % 3) as usize] as usize])
            .collect();
        let brute = BruteForce::new(&normals, &points);
        let object_from_world: DMat4 = if transform_eye { world_from_object.inverse() } else { DMat4::IDENTITY };
        let view = if camera.orthographic {
            let d = camera.view_from_render.inverse().transform_vector3(Vec3::NEG_Z).as_dvec3();
            LinesView::Orthographic { direction: object_from_world.transform_vector3(d).as_vec3() }
        } else {
            let eye = camera.position_in_render.as_dvec3() + origin;
            LinesView::Perspective { eye: object_from_world.transform_point3(eye).as_vec3() }
        };
        let mut set = EdgeSet::new(normals.len());
        brute.query_serial(view, &mut set);
        out.extend(set.iter().map(|c| DrawnSilhouette {
            instance: instance as u32,
            mesh,
            corner: s.candidate_corners[c as usize],
        }));
    }
    out
}

fn cameras() -> Vec<RenderOptions> {
    let base = RenderOptions { size: (160, 120), lines: true, style: Style::Gooch, ..RenderOptions::default() };
    let mut v = Vec::new();
    for (az, el) in [(35.0, 25.0), (-120.0, 10.0), (200.0, -40.0), (80.0, 70.0)] {
        for orthographic in [false, true] {
            v.push(RenderOptions { view: View { azimuth_deg: az, elevation_deg: el }, orthographic, ..base.clone() });
        }
    }
    // A wide lens, close up: the eye near the model.
    v.push(RenderOptions { zoom: 3.0, fov_y_deg: 120.0, ..base });
    v
}

/// Renders every camera and compares what the lines pass drew with brute force. Returns the
/// total silhouettes and how many cameras a wrong (untransformed) eye would have failed.
fn check(b: &Baked, renderer: &mut Renderer, label: &str) -> (usize, usize) {
    let mut total = 0;
    let mut wrong_would_fail = 0;
    for options in cameras() {
        renderer.render(&options).unwrap_or_else(|e| panic!("{label}: {e}"));
        let camera = renderer.last_frame().expect("a frame").camera;
        let frame = renderer.last_silhouettes().expect("lines were drawn");
        let drawn: BTreeSet<DrawnSilhouette> = frame.drawn.iter().copied().collect();
        assert_eq!(drawn.len(), frame.drawn.len(), "{label}: an edge uploaded twice");
        assert_eq!(frame.segments.len(), frame.drawn.len());
        let expected = reference(b, &camera, true);
        let missing: Vec<_> = expected.difference(&drawn).take(5).collect();
        let extra: Vec<_> = drawn.difference(&expected).take(5).collect();
        assert!(
            missing.is_empty() && extra.is_empty(),
            "{label} {:?} ortho {}: {} drawn, {} by brute force; missing {missing:?}, extra {extra:?}",
            options.view,
            options.orthographic,
            drawn.len(),
            expected.len()
        );
        assert!(!drawn.is_empty(), "{label}: no silhouettes at all");
        // Every uploaded segment joins the two vertices of its corner, in object space.
        for (segment, d) in frame.segments.iter().zip(&frame.drawn) {
            let m = &b.scene.meshes[d.mesh as usize];
            let t = m.triangles[(d.corner / 3) as usize];
            let k = (d.corner % 3) as usize;
            assert_eq!(segment.a_in_object, m.positions[t[k] as usize].to_array());
            assert_eq!(segment.b_in_object, m.positions[t[(k + 1) % 3] as usize].to_array());
            assert_eq!(segment.instance, d.instance);
        }
        total += drawn.len();
        wrong_would_fail += usize::from(reference(b, &camera, false) != drawn);
    }
    (total, wrong_would_fail)
}

#[test]
fn drawn_silhouettes_equal_brute_force_on_the_sample_assembly() {
    let b = bake(&common::repo_path("samples/assembly.glb"));
    assert!(!b.model.lines.is_empty(), "the sample has baked edges");
    assert!(b.model.instance_mesh.len() > 1, "several instances");
    let mut renderer = common::renderer();
    renderer.set_model(&b.model).expect("upload");
    let (total, wrong) = check(&b, &mut renderer, "assembly");
    assert!(total > 100, "only {total} silhouettes over all cameras");
    // The comparison can fail: ignoring the instance transforms changes the answer.
    assert!(wrong > 0, "the instances' transforms never mattered: the test would not notice a wrong eye");
}

#[test]
fn drawn_silhouettes_equal_brute_force_through_the_hierarchies() {
    // A noisy scan: enough candidates that the bake stores a Gauss map and a cone BVH.
    let b = bake(&common::corpus_path("obj/common-3d-test-models/stanford-bunny.obj"));
    let (_, s) = &b.file.mesh_silhouettes[0];
    assert!(s.gauss_map.is_some() && s.cone_bvh.is_some(), "the bunny's hierarchies are stored");
    assert!(b.model.notices.iter().all(|n| !n.contains("validate")), "{:?}", b.model.notices);
    let index = &b.model.lines.meshes[0].silhouettes.as_ref().expect("candidates").index;
    assert!(index.gauss_map().is_some() && index.cone_bvh().is_some(), "the viewer queries the stored hierarchies");
    let mut renderer = common::renderer();
    renderer.set_model(&b.model).expect("upload");
    let (total, _) = check(&b, &mut renderer, "bunny");
    assert!(total > 1000, "only {total} silhouettes");
}

#[test]
fn deferred_hierarchies_draw_the_same_silhouettes_before_and_after_they_are_built() {
    // The browser's load: brute force answers the first frames, the stored hierarchies come later.
    let mut b = bake(&common::corpus_path("obj/common-3d-test-models/stanford-bunny.obj"));
    b.model = Model::load_bytes_with(Path::new("baked.glb"), &b.bytes, &Default::default(), Hierarchies::Deferred)
        .expect("loads deferred");
    let lines = b.model.lines.meshes[0].silhouettes.as_ref().expect("candidates");
    assert!(lines.pending.is_some() && lines.index.gauss_map().is_none() && lines.index.cone_bvh().is_none());
    let mut renderer = common::renderer();
    renderer.set_model(&b.model).expect("upload");
    assert!(renderer.hierarchies_pending());
    let (before, _) = check(&b, &mut renderer, "bunny, brute force");
    assert!(renderer.complete_hierarchies().is_empty(), "the stored hierarchies validate");
    assert!(!renderer.hierarchies_pending());
    let (after, _) = check(&b, &mut renderer, "bunny, hierarchies built");
    assert_eq!(before, after);
    assert!(after > 1000, "only {after} silhouettes");
}

#[test]
fn hard_edges_match_the_bake() {
    // Every hard edge of the file is uploaded once per instance, and nothing else.
    let b = bake(&common::repo_path("samples/assembly.glb"));
    let per_mesh: usize = b
        .file
        .primitive_edges
        .iter()
        .map(|(m, _, e)| {
            let instances = b.model.instance_mesh.iter().filter(|&&x| x == *m).count();
            e.hard_edges().count() * instances
        })
        .sum();
    let mut renderer = common::renderer();
    renderer.set_model(&b.model).expect("upload");
    assert!(per_mesh > 0);
    assert_eq!(renderer.hard_edge_count() as usize, per_mesh);
    // The classes are the file's, edge for edge (the sample's parts are closed meshes of their
    // own: creases only).
    let mut from_file = std::collections::BTreeMap::new();
    for (m, _, e) in &b.file.primitive_edges {
        let instances = b.model.instance_mesh.iter().filter(|&&x| x == *m).count();
        for (_, class) in e.hard_edges() {
            *from_file.entry(u32::from(class)).or_insert(0usize) += instances;
        }
    }
    let mut drawn = std::collections::BTreeMap::new();
    for s in b.model.lines.hard_segments() {
        *drawn.entry(s.class).or_insert(0usize) += 1;
    }
    assert_eq!(drawn, from_file);
    assert!(drawn.contains_key(&1), "{drawn:?}");
}

#[test]
fn lines_change_the_image_and_picking_reads_parts() {
    let b = bake(&common::repo_path("samples/assembly.glb"));
    let mut renderer = common::renderer();
    renderer.set_model(&b.model).expect("upload");
    let base = RenderOptions { size: (200, 150), style: Style::Gooch, ..RenderOptions::default() };
    let plain = renderer.render(&base).expect("render");
    let lined = renderer.render(&RenderOptions { lines: true, ..base.clone() }).expect("render");
    let black =
        |img: &drafter_render::Image| img.rgba.chunks_exact(4).filter(|p| p[0] < 40 && p[1] < 40 && p[2] < 40).count();
    assert!(black(&lined) > black(&plain) + 300, "lines added {} dark pixels", black(&lined) - black(&plain));
    // Picking: the centre of the frame is on a part, the corner is background.
    let (w, h) = (base.size.0, base.size.1);
    let mut hits = BTreeSet::new();
    for (x, y) in [(w / 2, h / 2), (w / 2 - 20, h / 2 + 10), (w / 2 + 25, h / 2 - 5)] {
        if let Some(id) = renderer.pick(x, y).expect("pick") {
            assert!((id as usize) < b.model.parts.len());
            hits.insert(id);
        }
    }
    assert!(!hits.is_empty(), "nothing picked near the centre");
    assert_eq!(renderer.pick(0, 0).expect("pick"), None);
    assert_eq!(renderer.pick(w * 10, 0).expect("pick"), None);
}
