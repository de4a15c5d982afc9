//! `drafter draw`: a valid SVG (xmllint; Chromium draws it where `drafter render --lines` draws its
//! lines) and PDF (pdfinfo) of the baked sample with its hidden lines in a group of
//! their own; a model that is not baked (OBJ, STL, plain glTF) is baked in memory and draws the
//! lines its bake draws; bad input and bad options end with exit 2, one line, and no output file. The exactness of the hidden lines is
//! `crates/drafter-draw/tests/visibility.rs` (brute force).

mod common;

#[path = "../../crates/drafter-draw/tests/fixtures/block.rs"]
mod block;

use std::process::Command;

#[test]
fn the_sample_draws_as_a_valid_svg_with_hidden_lines() {
    let dir = common::scratch("draw");
    let baked = dir.join("sample.glb");
    assert!(
        common::bake(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb").as_path(),
            &baked,
            &[]
        )
        .status
        .success()
    );
    let svg = dir.join("sample.svg");
    let run =
        common::run(&["draw", baked.to_str().unwrap(), "-o", svg.to_str().unwrap(), "--hidden", "dashed", "--json"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let figures: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert!(figures["strokes"].as_u64().unwrap() > 100 && figures["hidden_px"].as_f64().unwrap() > 0.0, "{figures}");
    let lint = Command::new("xmllint")
        .arg("--noout")
        .arg(&svg)
        .output()
        .expect("xmllint (apt libxml2-utils; scripts/test installs it) checks the SVG");
    assert!(lint.status.success(), "xmllint: {}", String::from_utf8_lossy(&lint.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains(r#"<g id="hidden""#) && text.contains(r#"<g id="visible""#));
    assert_eq!(text.matches("<path").count() as u64, figures["strokes"].as_u64().unwrap());

    // With the gradient bands under the lines: still valid, the fills first, a group per part.
    let banded = dir.join("sample-bands.svg");
    let run = common::run(&["draw", baked.to_str().unwrap(), "-o", banded.to_str().unwrap(), "--fill", "bands"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let lint = Command::new("xmllint").arg("--noout").arg(&banded).output().expect("xmllint");
    assert!(lint.status.success(), "xmllint: {}", String::from_utf8_lossy(&lint.stderr));
    let text = std::fs::read_to_string(&banded).unwrap();
    let (fills, visible) = (text.find(r#"<g id="fills""#).unwrap(), text.find(r#"<g id="visible""#).unwrap());
    assert!(fills < visible, "fills are painted under the lines");
    assert!(text.matches(r#"<g class="fill part-"#).count() >= 10 && text.contains(r#"class="band-1""#));

    // The largest size allowed: fills never allocate per output pixel (their order is counted on a
    // grid of at most 2048 cells a side).
    let huge = dir.join("huge.svg");
    let run = common::run(&[
        "draw",
        baked.to_str().unwrap(),
        "-o",
        huge.to_str().unwrap(),
        "--fill",
        "flat",
        "--size",
        "65536x65536",
    ]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(std::fs::read_to_string(&huge).unwrap().contains(r#"<g id="fills""#));
}

/// The same drawing as a PDF: one page of 600 × 450 pt for 800 × 600 px, which poppler reads.
#[test]
fn the_sample_draws_as_a_pdf() {
    let dir = common::scratch("draw-pdf");
    let pdf = dir.join("sample.pdf");
    let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb");
    let run = common::run(&["draw", sample.to_str().unwrap(), "-o", pdf.to_str().unwrap(), "--hidden", "dashed"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let info = Command::new("pdfinfo")
        .arg(&pdf)
        .output()
        .expect("pdfinfo (apt poppler-utils; scripts/test installs it) checks the PDF");
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(info.status.success(), "pdfinfo: {}", String::from_utf8_lossy(&info.stderr));
    assert!(text.contains("Pages:           1") && text.contains("600 x 450 pts"), "{text}");
}

/// The `d` attributes of an SVG's paths, in order: its strokes and fills.
fn path_data(svg: &str) -> Vec<&str> {
    svg.split(" d=\"").skip(1).map(|rest| &rest[..rest.find('"').expect("attribute closes")]).collect()
}

#[test]
fn an_unbaked_model_is_baked_in_memory_and_draws_the_lines_of_its_bake() {
    let dir = common::scratch("draw-plain");
    let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples");
    let obj = common::shared_models().join("obj/common-3d-test-models/fandisk.obj");
    for (input, args) in [
        (obj.as_path(), &["--hidden", "dashed"][..]),
        (sample.join("gear.glb").as_path(), &["--view", "0,89.99999", "--ortho", "--hidden", "dashed"][..]),
    ] {
        let name = input.file_stem().unwrap().to_string_lossy().into_owned();
        let baked = dir.join(format!("{name}.baked.glb"));
        common::bake(input, &baked, &[]);
        let (plain_svg, baked_svg) = (dir.join(format!("{name}.svg")), dir.join(format!("{name}.baked.svg")));
        let plain =
            common::run(&[&["draw", input.to_str().unwrap(), "-o", plain_svg.to_str().unwrap()][..], args].concat());
        assert!(plain.status.success(), "{name}: {}", String::from_utf8_lossy(&plain.stderr));
        assert!(String::from_utf8_lossy(&plain.stderr).contains("baked in memory"), "{name}: says so");
        let run =
            common::run(&[&["draw", baked.to_str().unwrap(), "-o", baked_svg.to_str().unwrap()][..], args].concat());
        assert!(run.status.success(), "{name}: {}", String::from_utf8_lossy(&run.stderr));
        // A drawing shades nothing with lookup textures: it neither bakes nor decodes them, nor notes them.
        for out in [&plain, &run] {
            assert!(
                !String::from_utf8_lossy(&out.stderr).contains("textures"),
                "{name}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        let (a, b) = (std::fs::read_to_string(&plain_svg).unwrap(), std::fs::read_to_string(&baked_svg).unwrap());
        let strokes = path_data(&a);
        assert!(strokes.len() > 20, "{name}: lines drawn ({})", strokes.len());
        assert_eq!(strokes, path_data(&b), "{name}: the same strokes as its bake's");
        assert!(a.contains(r#"class="crease""#), "{name}: creases known");
    }
    // One triangle of STL: its boundary, and fills from both sides (`flat` fills a sheet whichever
    // face the eye sees, `bands` its front face only).
    let stl = dir.join("tetra.stl");
    std::fs::write(
        &stl,
        "solid t\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n",
    )
    .unwrap();
    let svg = dir.join("t.svg");
    for (view, fill) in [("35,25", "none"), ("35,25", "flat"), ("215,-25", "flat"), ("35,25", "bands")] {
        let run =
            common::run(&["draw", stl.to_str().unwrap(), "-o", svg.to_str().unwrap(), "--fill", fill, "--view", view]);
        assert!(run.status.success(), "{view} {fill}: {}", String::from_utf8_lossy(&run.stderr));
        let lint = Command::new("xmllint").arg("--noout").arg(&svg).output().expect("xmllint");
        assert!(lint.status.success());
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains(r#"class="boundary""#), "{view} {fill}: the triangle's edges: {text}");
        assert!(text.contains(r#"<g id="fills""#) || fill == "bands" || fill == "none", "{view} {fill}: {text}");
    }
}

#[test]
fn bad_input_and_bad_options_end_with_exit_2_and_no_file() {
    let dir = common::scratch("draw-bad");
    let garbage = dir.join("garbage.glb");
    std::fs::write(&garbage, b"glTF\x02\x00\x00\x00garbage").unwrap();
    let svg = dir.join("out.svg");
    let s = svg.to_str().unwrap();
    let g = garbage.to_str().unwrap();
    let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb");
    let sample = sample.to_str().unwrap();
    for args in [
        vec!["draw", g, "-o", s],
        vec!["draw", sample, "-o", s, "--size", "0x600"],
        vec!["draw", sample, "-o", s, "--tolerance=-1"],
        vec!["draw", sample, "-o", s, "--tolerance", "-1"],
        vec!["draw", sample, "-o", s, "--tolerance", "NaN"],
        vec!["draw", sample, "-o", s, "--view", "0,90"],
        vec!["draw", sample, "-o", dir.join("out.png").to_str().unwrap()],
    ] {
        let run = common::run(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: one line: {stderr}");
        assert!(!svg.exists(), "{args:?}: no output");
    }
    // What each refusal blames: a negative tolerance parses and is refused by name, an infinite
    // azimuth is the azimuth's fault, a missing folder is found before the model is even read.
    for (args, words) in [
        (vec!["draw", sample, "-o", s, "--tolerance", "-1"], "--tolerance -1"),
        (vec!["draw", sample, "-o", s, "--view", "inf,0"], "azimuth"),
        (vec!["draw", g, "-o", dir.join("missing/out.svg").to_str().unwrap(), "--view", "inf,0"], "azimuth"),
        (vec!["draw", g, "-o", dir.join("missing/out.svg").to_str().unwrap()], "no folder"),
    ] {
        let run = common::run(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(words), "{args:?}: {stderr}");
    }
}

/// `drafter bench draw`: the finest tolerance is its own reference (100 % both ways), a coarser one
/// still holds nearly all of the reference's length, fewer strokes make smaller SVGs, and brute
/// force is timed beside the drawing.
#[test]
fn bench_draw_charts_tolerance_against_agreement() {
    let dir = common::scratch("bench-draw");
    let baked = dir.join("sample.glb");
    let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb");
    assert!(common::bake(&sample, &baked, &[]).status.success());
    let run = common::run(&[
        "bench",
        "draw",
        baked.to_str().unwrap(),
        "--views",
        "2",
        "--tolerances",
        "1,0",
        "--brute-samples",
        "100",
        "--json",
    ]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let report: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let rows = report["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4, "2 views × 2 tolerances");
    for view in 0..2 {
        let row = |t: f64| rows.iter().find(|r| r["view"] == view && r["tolerance_px"].as_f64() == Some(t)).unwrap();
        let (fine, coarse) = (row(0.0), row(1.0));
        for key in ["visible_reference_covered", "visible_covered_by_reference", "hidden_covered_by_reference"] {
            assert_eq!(fine[key].as_f64(), Some(1.0), "{key}: {fine}");
        }
        assert!(coarse["visible_reference_covered"].as_f64().unwrap() > 0.9, "{coarse}");
        assert!(coarse["visible_covered_by_reference"].as_f64().unwrap() > 0.99, "{coarse}");
        assert!(coarse["strokes"].as_u64() <= fine["strokes"].as_u64(), "{coarse} {fine}");
        assert!(coarse["svg_bytes"].as_u64() <= fine["svg_bytes"].as_u64());
    }
    let brute = report["brute"].as_array().unwrap();
    assert_eq!(brute.len(), 2);
    assert!(brute.iter().all(|b| b["samples"].as_u64() == Some(100) && b["ns_per_sample"].as_f64().unwrap() > 0.0));
}

/// Pixels of `mask` with a pixel of `other` within 2 px, as a share of `mask`'s pixels.
fn near_share(mask: &[bool], other: &[bool], (w, h): (usize, usize)) -> (f64, usize) {
    let (mut near, mut total) = (0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            if !mask[y * w + x] {
                continue;
            }
            total += 1;
            let found = (y.saturating_sub(2)..(y + 3).min(h))
                .any(|yy| (x.saturating_sub(2)..(x + 3).min(w)).any(|xx| other[yy * w + xx]));
            near += usize::from(found);
        }
    }
    (near as f64 / total.max(1) as f64, total)
}

/// The SVG opens in Chromium, and Chromium's rendering of it matches `drafter render --lines` of
/// the same view: its black lines against the raster pass's black silhouettes and borders (the
/// measure of `crates/drafter-render/tests/drawing.rs`, here on a browser's rasterisation of the
/// file itself).
#[test]
fn chromium_draws_the_svg_where_drafter_render_draws_its_lines() {
    let dir = common::scratch("draw-chromium");
    let baked = dir.join("sample.glb");
    let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb");
    assert!(common::bake(&sample, &baked, &[]).status.success());
    let (svg, shot, render) = (dir.join("view.svg"), dir.join("chromium.png"), dir.join("render.png"));
    let view = ["--size", "800x600", "--view", "35,25"];
    // Gooch's weights, as the raster pass draws them (ISO 128's one 0.5 mm width is 1.89 px).
    let drawn = common::run(
        &[&["draw", baked.to_str().unwrap(), "-o", svg.to_str().unwrap(), "--style", "gooch"][..], &view].concat(),
    );
    assert!(drawn.status.success(), "{}", String::from_utf8_lossy(&drawn.stderr));
    // The raster pass draws creases white: hide the drawing's with a stylesheet, as a user would.
    let text = std::fs::read_to_string(&svg).unwrap();
    let open = text.find("<desc>").expect("the SVG's first element");
    std::fs::write(&svg, format!("{}<style>.crease {{ display: none }}</style>\n{}", &text[..open], &text[open..]))
        .unwrap();
    let chromium = Command::new("/usr/bin/chromium")
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--window-size=800,600"])
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", svg.display()))
        .output()
        .expect("Chromium (scripts/test installs it) opens the SVG");
    assert!(shot.is_file(), "Chromium wrote no screenshot: {}", String::from_utf8_lossy(&chromium.stderr));
    let rendered = common::run(
        &[
            &["render", baked.to_str().unwrap(), "-o", render.to_str().unwrap(), "--lines", "--style", "gooch"][..],
            &view,
        ]
        .concat(),
    );
    assert!(rendered.status.success(), "{}", String::from_utf8_lossy(&rendered.stderr));
    let read = |p: &std::path::Path| drafter_render::Image::from_png(&std::fs::read(p).unwrap()).unwrap();
    let (page, raster) = (read(&shot), read(&render));
    assert_eq!((page.width, page.height, raster.width, raster.height), (800, 600, 800, 600));
    let dark = |img: &drafter_render::Image, level: u8| -> Vec<bool> {
        img.rgba.chunks_exact(4).map(|p| p[0].max(p[1]).max(p[2]) < level).collect()
    };
    // Chromium's anti-aliased strokes (half-dark or darker); the raster's black lines.
    let (page_dark, raster_black) = (dark(&page, 128), dark(&raster, 48));
    let (raster_in_page, raster_pixels) = near_share(&raster_black, &page_dark, (800, 600));
    let (page_in_raster, page_pixels) = near_share(&page_dark, &raster_black, (800, 600));
    eprintln!(
        "raster black {raster_pixels} px: {:.2}% near Chromium's; Chromium's dark {page_pixels} px: {:.2}% near the raster's",
        100.0 * raster_in_page,
        100.0 * page_in_raster
    );
    assert!(page_pixels > 2000 && raster_pixels > 2000, "both show lines");
    // Measured 2026-11-29: 100.00% and 90.25%; the rest are folds that are outlines by the exact
    // facing test and not by the raster's depth-jump threshold (docs/drawing.md).
    assert!(raster_in_page >= 0.97, "{raster_in_page}");
    assert!(page_in_raster >= 0.88, "{page_in_raster}");
}

/// The class groups of an SVG's visible or hidden group: (class, the group's attributes, its paths).
fn class_groups(svg: &str, id: &str) -> Vec<(String, String, usize)> {
    let Some(start) = svg.find(&format!(r#"<g id="{id}""#)) else { return Vec::new() };
    let body = &svg[start..];
    let end = body.find("\n</g>\n<g id=").or_else(|| body.find("\n</g>\n</svg>")).unwrap_or(body.len());
    let mut groups = Vec::new();
    for chunk in body[..end].split(r#"<g class=""#).skip(1) {
        let (class, rest) = chunk.split_once('"').expect("class attribute");
        let attributes = rest[..rest.find('>').expect("group tag")].to_owned();
        groups.push((class.to_owned(), attributes, chunk.matches("<path").count()));
    }
    groups
}

/// `--smooth`: a block with a rounded edge, exported one glTF primitive per CAD face, has two
/// tangent edges (plane to fillet); they are the `tangent` class drawn thin by default, dashed with
/// `--smooth dashed`, left out with `--smooth none`, and every other line is the same in all three.
/// A mistyped value is refused by name, with the accepted ones (exit 2, no file).
#[test]
fn smooth_draws_the_tangent_edges_thin_dashed_or_not_at_all() {
    let dir = common::scratch("draw-smooth");
    let gltf = block::write_gltf(&dir);
    let draw = |smooth: &str| {
        let svg = dir.join(format!("{smooth}.svg"));
        let run = common::run(&[
            "draw",
            gltf.to_str().unwrap(),
            "-o",
            svg.to_str().unwrap(),
            "--view",
            "30,35",
            "--smooth",
            smooth,
        ]);
        assert!(run.status.success(), "--smooth {smooth}: {}", String::from_utf8_lossy(&run.stderr));
        std::fs::read_to_string(&svg).unwrap()
    };
    let (thin, dashed, none) = (draw("thin"), draw("dashed"), draw("none"));
    let default = {
        let svg = dir.join("default.svg");
        let run = common::run(&["draw", gltf.to_str().unwrap(), "-o", svg.to_str().unwrap(), "--view", "30,35"]);
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        std::fs::read_to_string(&svg).unwrap()
    };
    assert_eq!(default, thin, "thin is the default");
    let tangent = |svg: &str| class_groups(svg, "visible").into_iter().find(|(class, ..)| class == "tangent");
    let (_, thin_attributes, thin_paths) = tangent(&thin).expect("--smooth thin draws a tangent group");
    let (_, dashed_attributes, dashed_paths) = tangent(&dashed).expect("--smooth dashed draws a tangent group");
    assert_eq!(thin_paths, 2, "the two borders of the fillet: {thin}");
    assert_eq!(dashed_paths, 2);
    assert!(!thin_attributes.contains("dasharray"), "thin is solid: {thin_attributes}");
    assert!(dashed_attributes.contains("stroke-dasharray"), "dashed: {dashed_attributes}");
    assert!(tangent(&none).is_none() && !none.contains(r#"class="tangent""#), "--smooth none: {none}");
    // Every other class is drawn alike.
    let others = |svg: &str| {
        class_groups(svg, "visible").into_iter().filter(|(class, ..)| class != "tangent").collect::<Vec<_>>()
    };
    assert!(!others(&thin).is_empty());
    assert_eq!(others(&thin), others(&dashed));
    assert_eq!(others(&thin), others(&none));

    let wrong = dir.join("wrong.svg");
    let run = common::run(&["draw", gltf.to_str().unwrap(), "-o", wrong.to_str().unwrap(), "--smooth", "dotted"]);
    assert_eq!(run.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("dotted") && stderr.contains("thin") && stderr.contains("dashed"), "{stderr}");
    assert!(!wrong.exists());
}
