//! The gradient style on the GPU against drafter-bounds' CPU definition: a flat quad seen head-on
//! through an orthographic camera, every pixel's grey value compared with `ω(γ(p))` at that pixel's
//! world position (`drafter_core::gradient::omega`) — once through the unbaked fallback (default q, f, p) and once through baked
//! parameters (q, f, p, transfer and a tilted projector from drafter-bounds' `Projector::matrix`).

mod common;

use drafter_bounds::Projector;
use drafter_core::gradient::{TransferCurve, omega};
use drafter_core::{Instance, Mesh, MeshId, Node, NodeId, Scene, SourceFormat, TriangleGroup};
use drafter_format::{BakedFile, BoxRecord, GradientRecord, NodeExtension, PartRecord, ProjectorRecord, RootExtension};
use drafter_render::{Model, RenderOptions, Style, View};
use glam::{DMat4, DVec3, Vec3, Vec4Swizzles};

const SIZE: (u32, u32) = (240, 120);

/// A 2 × 1 quad in the plane z = 0 (world x ∈ [1, 3], y ∈ [-1, 0]), facing +z.
fn quad() -> Scene {
    let mut scene = Scene::new(SourceFormat::Gltf);
    scene.meshes.push(Mesh {
        name: "quad".into(),
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        normals: Some(vec![Vec3::Z; 4]),
        uvs: None,
        groups: vec![TriangleGroup {
            start: 0,
            count: 2,
            primitive: Some(0),
            first_vertex: 0,
            vertex_count: 4,
            material: None,
        }],
    });
    let world_from_object = DMat4::from_translation(DVec3::new(1.0, -1.0, 0.0));
    scene.nodes.push(Node {
        name: "quad".into(),
        parent: None,
        children: vec![],
        parent_from_local: world_from_object,
        mesh: Some(MeshId(0)),
    });
    scene.roots.push(NodeId(0));
    scene.instances.push(Instance { name: "quad".into(), mesh: MeshId(0), node: Some(NodeId(0)), world_from_object });
    scene
}

fn baked(projector: &Projector, q: u32, f: f64, p: f64, transfer: TransferCurve) -> BakedFile {
    let part = PartRecord {
        id: 0,
        name: "quad".into(),
        triangles: 2,
        obb: BoxRecord {
            center: [2.0, -0.5, 0.0],
            axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            half_extents: [1.0, 0.5, 0.0],
            volume: 0.0,
            method: drafter_format::ObbMethod::Aabb,
        },
        projector: ProjectorRecord {
            anchor: projector.anchor.to_array(),
            direction: projector.direction.to_array(),
            scale: projector.scale,
            matrix: projector.matrix().to_cols_array(),
        },
        gradient: GradientRecord { q: f64::from(q), f, p, transfer },
        style: Some(drafter_format::PartStyle::Gradient),
        flat: None,
    };
    BakedFile {
        // From JSON, as a reader would see it: fields added to the extension later keep their defaults.
        root: serde_json::from_value::<RootExtension>(serde_json::json!({
            "version": drafter_format::FORMAT_VERSION,
            "generator": "test",
            "input": { "name": "quad", "format": "gltf", "sha256": "" },
            "sceneCenter": [2.0, -0.5, 0.0],
            "partCount": 1
        }))
        .expect("root extension"),
        nodes: vec![(0, NodeExtension { parts: vec![part] })],
        primitive_labels: vec![],
        primitive_edges: vec![],
        mesh_silhouettes: vec![],
    }
}

/// Renders `model` head-on and checks every pixel of the middle rows against `expected(world)`.
fn check(name: &str, model: &Model, expected: impl Fn(DVec3) -> f64) {
    let mut renderer = common::renderer();
    renderer.set_model(model).expect("upload");
    let options = RenderOptions {
        size: SIZE,
        style: Style::Phong, // the part's hint (or the override below) picks the gradient
        use_part_styles: model.baked,
        view: View { azimuth_deg: 0.0, elevation_deg: 0.0 },
        orthographic: true,
        ..RenderOptions::default()
    };
    let options = if model.baked { options } else { RenderOptions { style: Style::Gradient, ..options } };
    let image = renderer.render(&options).expect("render");
    let camera = renderer.last_frame().expect("frame").camera;
    let render_from_clip = camera.clip_from_render().inverse();
    let world_at = |x: f64, y: f64| {
        let ndc = Vec3::new((x / SIZE.0 as f64 * 2.0 - 1.0) as f32, (1.0 - y / SIZE.1 as f64 * 2.0) as f32, 0.5);
        let r = render_from_clip * ndc.extend(1.0);
        (r.xyz() / r.w).as_dvec3() + model.origin
    };
    // The default material (0.8 grey) tints the gradient by mix(1, 0.8, 0.3) = 0.94; ω maps to
    // [0.18, 1] of it (gbuffer.wgsl, shade_gradient).
    let grey = |w: f64| 0.94 * (0.18 + 0.82 * w) * 255.0;
    let (mut checked, mut worst) = (0usize, 0.0f64);
    for y in (SIZE.1 * 3 / 8)..(SIZE.1 * 5 / 8) {
        for x in 0..SIZE.0 {
            let centre = world_at(f64::from(x) + 0.5, f64::from(y) + 0.5);
            if !(1.0..=3.0).contains(&centre.x) {
                continue;
            }
            // Skip pixels that straddle a band edge (ω jumps there).
            let (left, right) =
                (world_at(f64::from(x), f64::from(y) + 0.5), world_at(f64::from(x) + 1.0, f64::from(y) + 0.5));
            let (lo, hi) = (grey(expected(left)), grey(expected(right)));
            if (lo - hi).abs() > 4.0 {
                continue;
            }
            let want = grey(expected(centre));
            let got = f64::from(image.pixel(x, y)[0]);
            worst = worst.max((got - want).abs());
            assert!((got - want).abs() <= 2.0, "{name}: pixel ({x}, {y}) at x = {:.4}: {got} vs {want:.1}", centre.x);
            checked += 1;
        }
    }
    assert!(checked > (SIZE.0 * SIZE.1 / 8) as usize, "{name}: only {checked} pixels checked");
    eprintln!("{name}: {checked} pixels within {worst:.2} levels of ω");
}

#[test]
fn unbaked_fallback_matches_omega() {
    let model = Model::from_scene(&quad(), None).expect("model");
    assert!(!model.baked);
    // Fallback projector: along the longest side (+x, the part is at the scene centre), scale 2.
    check("fallback", &model, |w| omega((w.x - 1.0) / 2.0, 10, 0.5, 1.0));
}

#[test]
fn baked_parameters_match_omega() {
    let projector = Projector { anchor: DVec3::new(2.0, -0.5, 0.0), direction: DVec3::new(0.8, 0.6, 0.0), scale: 1.6 };
    for (q, f, p, curve, name) in [
        (4, 0.3, 1.4, TransferCurve::Smoothstep, "smoothstep"),
        (7, 1.0, 0.6, TransferCurve::Invert, "invert"),
        (255, 0.0, 1.0, TransferCurve::EaseIn, "ease_in"),
    ] {
        let file = baked(&projector, q, f, p, curve);
        let model = Model::from_scene(&quad(), Some(&file)).expect("model");
        // Only the line saying where the lookups come from (this file has no textures).
        assert_eq!(model.notices, ["textures: procedural (file has none)"]);
        check(name, &model, |w| omega(curve.eval(projector.coordinate(w)), q, f, p));
    }
}
