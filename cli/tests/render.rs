//! `drafter render` and `drafter bench render` end to end: a baked sample and an unbaked mesh render
//! to PNGs of the asked size in every style; bad input exits 2 with one line. Needs a GPU adapter
//! (lavapipe in CI): without one these tests fail, they do not skip.

mod common;

use std::path::Path;

use drafter_render::Image;

fn bake_sample(dir: &Path) -> std::path::PathBuf {
    let baked = dir.join("sample.baked.glb");
    let out = common::run(&["bake", "-q", "-o", baked.to_str().expect("utf-8 path")]);
    assert!(out.status.success(), "bake: {}", String::from_utf8_lossy(&out.stderr));
    baked
}

fn render(args: &[&str]) -> std::process::Output {
    let mut all = vec!["render"];
    all.extend_from_slice(args);
    common::run(&all)
}

fn read_png(path: &Path) -> Image {
    Image::from_png(&std::fs::read(path).expect("PNG written")).expect("valid PNG")
}

#[test]
fn every_style_renders_the_baked_sample() {
    let dir = common::scratch("render_styles");
    let baked = bake_sample(&dir);
    for style in ["gradient", "cel", "gooch", "goochel", "phong", "metal", "hatch"] {
        let png = dir.join(format!("{style}.png"));
        let out = render(&[
            baked.to_str().expect("utf-8"),
            "-o",
            png.to_str().expect("utf-8"),
            "--style",
            style,
            "--size",
            "160x120",
            "--edges",
            "--shadow",
            "soft",
        ]);
        assert!(out.status.success(), "{style}: {}", String::from_utf8_lossy(&out.stderr));
        let image = read_png(&png);
        assert_eq!((image.width, image.height), (160, 120), "{style}");
        let corner = image.pixel(0, 0);
        assert_eq!(corner, [255, 255, 255], "{style}: white background");
        let drawn = image.rgba.chunks_exact(4).filter(|p| p[..3] != corner).count();
        assert!(drawn > 160 * 120 / 5, "{style}: only {drawn} pixels drawn");
    }
}

#[test]
fn unbaked_mesh_renders_with_a_notice() {
    let dir = common::scratch("render_unbaked");
    let model = common::shared_models().join("obj/cgal/pinion.off");
    let png = dir.join("pinion.png");
    let out = render(&[
        model.to_str().expect("utf-8"),
        "-o",
        png.to_str().expect("utf-8"),
        "--size",
        "120x90",
        "--view",
        "-30,40",
        "--ortho",
        "--style",
        "gooch",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("no DRAFTER_illustration data"), "{stderr}");
    assert_eq!((read_png(&png).width, read_png(&png).height), (120, 90));
}

#[test]
fn enhanced_normals_flag_toggles_and_falls_back_with_a_notice() {
    let dir = common::scratch("render_enhanced_normals");
    let baked = bake_sample(&dir);
    let mut images = Vec::new();
    for flag in [None, Some("--enhanced-normals")] {
        let png = dir.join(format!("phong{}.png", flag.unwrap_or("")));
        let mut args = vec![baked.to_str().expect("utf-8"), "-o", png.to_str().expect("utf-8")];
        args.extend(["--style", "phong", "--size", "160x120", "--supersample", "1"]);
        args.extend(flag);
        let out = render(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(!String::from_utf8_lossy(&out.stderr).contains("no enhanced normals"));
        images.push(read_png(&png));
    }
    let changed = images[0].rgba.chunks_exact(4).zip(images[1].rgba.chunks_exact(4)).filter(|(a, b)| a != b).count();
    assert!(changed > 160 * 120 / 100, "the flag changed only {changed} pixels");

    // No enhanced normals in an unbaked file: one notice, and the image of its own normals.
    let model = common::shared_models().join("obj/cgal/pinion.off");
    let (plain, toggled) = (dir.join("pinion.png"), dir.join("pinion-enhanced.png"));
    for (png, flag) in [(&plain, None), (&toggled, Some("--enhanced-normals"))] {
        let mut args = vec![model.to_str().expect("utf-8"), "-o", png.to_str().expect("utf-8"), "--size", "120x90"];
        args.extend(flag);
        let out = render(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let notices = String::from_utf8_lossy(&out.stderr).matches("no enhanced normals").count();
        assert_eq!(notices, usize::from(flag.is_some()));
    }
    assert_eq!(read_png(&plain).rgba, read_png(&toggled).rgba);
}

#[test]
fn bad_input_exits_2_with_one_line() {
    let dir = common::scratch("render_bad");
    let garbage = dir.join("garbage.glb");
    std::fs::write(&garbage, b"glTF\x02\x00\x00\x00garbage").expect("write");
    let baked = bake_sample(&dir);
    let png = dir.join("out.png");
    let (baked, png, garbage) =
        (baked.to_str().expect("utf-8"), png.to_str().expect("utf-8"), garbage.to_str().expect("utf-8"));
    let missing = dir.join("missing.glb");
    let cases: Vec<Vec<&str>> = vec![
        vec![garbage, "-o", png],
        vec![missing.to_str().expect("utf-8"), "-o", png],
        vec![baked, "-o", png, "--size", "0x10"],
        vec![baked, "-o", png, "--cel-steps", "9"],
        vec![baked, "-o", png, "--view", "0,95"],
        vec![baked, "-o", "out.jpg"],
    ];
    for args in cases {
        let out = render(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.starts_with("drafter: error: "), "{args:?}: {stderr}");
    }
    assert!(!Path::new(png).exists(), "no output on failure");
}

#[test]
fn bench_render_prints_ratios_to_phong() {
    let dir = common::scratch("bench_render");
    let baked = bake_sample(&dir);
    let out =
        common::run(&["bench", "render", baked.to_str().expect("utf-8"), "--size", "64x48", "--json", "--warmup", "1"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(report["size"], serde_json::json!([64, 48]));
    assert_eq!(report["frames"], 30);
    assert!(report["device"].as_str().is_some_and(|d| !d.is_empty()));
    let styles = report["styles"].as_object().expect("styles");
    assert_eq!(styles["phong"]["ratio"], 1.0);
    for name in ["gradient", "cel", "gooch", "goochel", "metal", "hatch", "illustration"] {
        let ms = styles[name]["ms"].as_f64().expect(name);
        let ratio = styles[name]["ratio"].as_f64().expect(name);
        assert!(ms > 0.0 && ratio > 0.0, "{name}: {ms} ms, ratio {ratio}");
    }
}
