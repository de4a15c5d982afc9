//! `drafter draw FILE --sheet SIZE`: a sheet of GearboxAssy (front, top, right and iso, third
//! angle, A3) as PDF (pdfinfo: one A3 landscape page) and SVG (xmllint), its views' shared
//! coordinates agreeing within 0.01 mm as written in the file, the views clear of each other and
//! of the title block inside the border, and the bytes the same run after run and at any thread
//! count; mistakes refused with exit 2 and one line naming the value. The geometry of a sheet
//! against its model is `crates/drafter-draw/tests/sheet.rs`.

mod common;

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// Reads a DXF with ezdxf (Debian's python3-ezdxf, as `cli/tests/dxf.rs` runs it): the recover
/// and strict audits' errors and fixes, polylines per layer, and the extent of the model's lines.
const EZDXF_READER: &str = r#"
import json, sys
import ezdxf
from ezdxf import recover

doc, auditor = recover.readfile(sys.argv[1])
audit = ezdxf.readfile(sys.argv[1]).audit()
counts, xs, ys = {}, [], []
for e in doc.modelspace():
    counts[e.dxf.layer] = counts.get(e.dxf.layer, 0) + 1
    if e.dxf.layer != "FRAME":
        for p in e.get_points("xy"):
            xs.append(p[0])
            ys.append(p[1])
print(json.dumps({
    "problems": [len(auditor.errors), len(auditor.fixes), len(audit.errors), len(audit.fixes)],
    "counts": counts,
    "model_extent": [min(xs), min(ys), max(xs), max(ys)],
}))
"#;

/// A rectangle `[x0, y0, x1, y1]` in millimetres.
type Rect = [f64; 4];

fn extent(points: impl Iterator<Item = (f64, f64)>) -> Rect {
    points.fold([f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY], |r, (x, y)| {
        [r[0].min(x), r[1].min(y), r[2].max(x), r[3].max(y)]
    })
}

/// The coordinate pairs of every `d="M… L…"` in `text`.
fn path_points(text: &str) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for chunk in text.split(" d=\"").skip(1) {
        let d = &chunk[..chunk.find('"').expect("a closed attribute")];
        let numbers: Vec<f64> =
            d.split(['M', 'L', ' ']).filter(|s| !s.is_empty()).map(|s| s.parse().expect("a number")).collect();
        assert_eq!(numbers.len() % 2, 0, "{d}");
        out.extend(numbers.chunks(2).map(|p| (p[0], p[1])));
    }
    out
}

/// One view's group (`id="view-NAME"`): its stated rectangle, the extent of its visible lines,
/// and every point of its lines.
struct View {
    rect: Rect,
    visible: Rect,
    points: Vec<(f64, f64)>,
}

/// The views by name, and the frame's points.
struct Parsed {
    views: BTreeMap<String, View>,
    frame: Vec<(f64, f64)>,
}

fn parse(svg: &str) -> Parsed {
    let (body, frame) = svg.split_once(r#"<g id="frame">"#).expect("a frame group");
    let mut views = BTreeMap::new();
    for chunk in body.split(r#"<g id="view-"#).skip(1) {
        let name = chunk[..chunk.find('"').expect("an id")].to_string();
        let rect_text = chunk.split("data-rect=\"").nth(1).expect("a data-rect");
        let r: Vec<f64> = rect_text[..rect_text.find('"').expect("a closed attribute")]
            .split(' ')
            .map(|v| v.parse().expect("a number"))
            .collect();
        let visible = chunk.split(r#"<g class="visible""#).nth(1).expect("visible lines");
        let view = View {
            rect: [r[0], r[1], r[2], r[3]],
            visible: extent(path_points(visible).into_iter()),
            points: path_points(chunk),
        };
        views.insert(name, view);
    }
    Parsed { views, frame: path_points(frame) }
}

fn overlaps(a: &Rect, b: &Rect) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

fn sheet(input: &Path, output: &Path, threads: &str) -> std::process::Output {
    common::drafter()
        .env("RAYON_NUM_THREADS", threads)
        .args(["draw", &input.display().to_string(), "-o", &output.display().to_string()])
        .args(["--sheet", "A3", "--views", "front,top,right,iso", "--projection", "third", "--hidden", "dashed"])
        .args(["--json"])
        .output()
        .expect("drafter runs")
}

#[test]
fn a_gearbox_sheet_is_valid_aligned_and_reproducible() {
    let dir = common::scratch("sheet");
    let baked = dir.join("GearboxAssy.glb");
    let source = common::shared_models().join("gltf/GearboxAssy/GearboxAssy.gltf");
    assert!(source.is_file(), "{} is missing", source.display());
    let bake = common::bake(&source, &baked, &[]);
    assert!(bake.status.success(), "{}", String::from_utf8_lossy(&bake.stderr));

    let (svg, pdf) = (dir.join("gearbox.svg"), dir.join("gearbox.pdf"));
    for out in [&svg, &pdf] {
        let run = sheet(&baked, out, "2");
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let figures: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        assert_eq!(figures["sheet"], "A3");
        assert_eq!(figures["views"].as_array().unwrap().len(), 4, "{figures}");
    }

    // The PDF: one A3 landscape page (420 × 297 mm in points).
    let info = Command::new("pdfinfo").arg(&pdf).output().expect("pdfinfo (apt poppler-utils) reads the PDF");
    assert!(info.status.success(), "pdfinfo: {}", String::from_utf8_lossy(&info.stderr));
    let info = String::from_utf8_lossy(&info.stdout);
    let field = |name: &str| {
        info.lines().find_map(|l| l.strip_prefix(name)?.strip_prefix(':')).map(str::trim).unwrap_or_default()
    };
    assert_eq!(field("Pages"), "1", "{info}");
    assert_eq!(field("Page size"), "1190.55 x 841.89 pts (A3)", "{info}");
    assert_eq!(field("Title"), "GearboxAssy", "{info}");

    // The SVG: valid, on an A3 page in millimetres.
    let lint = Command::new("xmllint").arg("--noout").arg(&svg).output().expect("xmllint checks the SVG");
    assert!(lint.status.success(), "xmllint: {}", String::from_utf8_lossy(&lint.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains(r#"width="420mm" height="297mm" viewBox="0 0 420 297""#));
    let parsed = parse(&text);
    assert_eq!(parsed.views.keys().collect::<Vec<_>>(), ["front", "iso", "right", "top"]);
    let (front, top, right) = (&parsed.views["front"], &parsed.views["top"], &parsed.views["right"]);
    // Shared coordinates as written: the front view's visible lines span the top view's x and
    // the right view's y, within 0.01 mm; each view's lines span its box (the projected box of
    // every vertex) within 0.01 mm.
    let close = |a: f64, b: f64| (a - b).abs() < 0.01;
    let (f, t, r) = (front.visible, top.visible, right.visible);
    assert!(close(f[0], t[0]) && close(f[2], t[2]), "x: front {f:?} top {t:?}");
    assert!(close(f[1], r[1]) && close(f[3], r[3]), "y: front {f:?} right {r:?}");
    for (name, view) in &parsed.views {
        let (rect, lines) = (view.rect, view.visible);
        assert!((0..4).all(|k| close(rect[k], lines[k])), "{name}: lines {lines:?} against its box {rect:?}");
    }
    // Third angle: top above the front view, right view to its right.
    assert!(top.rect[3] < front.rect[1] && right.rect[0] > front.rect[2]);
    // Inside the border (20 mm filing margin, 10 mm elsewhere), clear of each other and of the
    // title block (180 × 34 mm at the border's lower right); the frame on the page.
    let border: Rect = [20.0, 10.0, 410.0, 287.0];
    let title_block: Rect = [230.0, 253.0, 410.0, 287.0];
    let names: Vec<&String> = parsed.views.keys().collect();
    for (i, name) in names.iter().enumerate() {
        let View { rect, points, .. } = &parsed.views[*name];
        for &(x, y) in points {
            assert!(x >= rect[0] - 0.001 && y >= rect[1] - 0.001 && x <= rect[2] + 0.001 && y <= rect[3] + 0.001);
        }
        assert!(rect[0] > border[0] && rect[1] > border[1] && rect[2] < border[2] && rect[3] < border[3], "{name}");
        assert!(!overlaps(rect, &title_block), "{name} overlaps the title block");
        for other in &names[i + 1..] {
            assert!(!overlaps(rect, &parsed.views[*other].rect), "{name} overlaps {other}");
        }
    }
    assert!(parsed.frame.iter().all(|&(x, y)| (0.0..=420.0).contains(&x) && (0.0..=297.0).contains(&y)));

    // The DXF: ezdxf reads it with no error and nothing to fix; as many polylines on VISIBLE and
    // HIDDEN as the SVG's views have paths, the frame on FRAME; the model's lines span the views'
    // boxes, in millimetres with y up.
    let dxf = dir.join("gearbox.dxf");
    let run = sheet(&baked, &dxf, "2");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let script = dir.join("read_dxf.py");
    std::fs::write(&script, EZDXF_READER).expect("the reader script is written");
    let read = Command::new("/usr/bin/python3")
        .arg(&script)
        .arg(&dxf)
        .output()
        .expect("/usr/bin/python3 (apt python3-ezdxf; scripts/test installs it) reads the DXF");
    assert!(read.status.success(), "ezdxf: {}", String::from_utf8_lossy(&read.stderr));
    let read: serde_json::Value = serde_json::from_slice(&read.stdout).expect("the reader's JSON");
    assert_eq!(read["problems"], serde_json::json!([0, 0, 0, 0]), "{read}");
    let paths_of = |group: &str| text.matches(group).count();
    let model_paths = text.split(r#"<g id="frame">"#).next().unwrap_or_default().matches("<path").count();
    let counts = &read["counts"];
    assert_eq!(
        counts["VISIBLE"].as_u64().unwrap_or(0)
            + counts["HIDDEN"].as_u64().unwrap_or(0)
            + counts["TANGENT"].as_u64().unwrap_or(0),
        model_paths as u64,
        "{read}"
    );
    assert_eq!(counts["FRAME"].as_u64(), Some(paths_of("<path") as u64 - model_paths as u64), "{read}");
    let union =
        parsed.views.values().fold([f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY], |r, v| {
            [r[0].min(v.rect[0]), r[1].min(v.rect[1]), r[2].max(v.rect[2]), r[3].max(v.rect[3])]
        });
    let model: Vec<f64> =
        read["model_extent"].as_array().expect("an extent").iter().filter_map(|v| v.as_f64()).collect();
    let flipped = [union[0], 297.0 - union[3], union[2], 297.0 - union[1]];
    assert!((0..4).all(|k| close(model[k], flipped[k])), "DXF {model:?} against the SVG's views {flipped:?}");

    // The same bytes again, on one thread.
    for (threads, out) in [("1", dir.join("one.svg")), ("1", dir.join("one.pdf"))] {
        let run = sheet(&baked, &out, threads);
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let reference = if out.extension().unwrap() == "svg" { &svg } else { &pdf };
        assert!(std::fs::read(&out).unwrap() == std::fs::read(reference).unwrap(), "{} differs", out.display());
    }
}

#[test]
fn sheet_mistakes_end_with_exit_2_and_one_line_naming_the_value() {
    let dir = common::scratch("sheet-mistakes");
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/gear.glb");
    let out = dir.join("never.svg");
    for (extra, named) in [
        (&["--sheet", "A9"][..], "A9"),
        (&["--sheet", "A3", "--views", "front,frnt"], "frnt"),
        (&["--sheet", "A3", "--scale", "500:1"], "500:1"),
        (&["--sheet", "A3", "--scale", "1:0"], "1:0"),
        (&["--sheet", "A3", "--up", "w"], "w"),
        (&["--sheet", "A3", "--section", "w=1"], "w=1"),
        (&["--sheet", "A3", "--section", "0,0,0,0,0,0"], "0,0,0,0,0,0"),
        (&["--sheet", "A3", "--up", "z", "--front", "-z"], "-z"),
    ] {
        let run = common::drafter()
            .args(["draw", sample.to_str().unwrap(), "-o", out.to_str().unwrap()])
            .args(extra)
            .output()
            .expect("drafter runs");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{extra:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{extra:?}: {stderr}");
        assert!(stderr.contains(named), "{extra:?}: {stderr}");
        assert!(!out.exists(), "{extra:?} wrote a file");
    }
    // The scale refused names the largest that fits, which is then accepted.
    let run = common::drafter()
        .args(["draw", sample.to_str().unwrap(), "-o", out.to_str().unwrap(), "--sheet", "A4", "--scale", "500:1"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    let largest = stderr.trim_end().rsplit(' ').next().unwrap().trim_end_matches(')');
    let run = common::drafter()
        .args(["draw", sample.to_str().unwrap(), "-o", out.to_str().unwrap(), "--sheet", "A4", "--scale", largest])
        .output()
        .unwrap();
    assert!(run.status.success(), "{largest}: {}", String::from_utf8_lossy(&run.stderr));
}

#[test]
fn a_section_sheet_of_the_sample_is_valid_svg_and_dxf() {
    let dir = common::scratch("sheet-section");
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb");
    let (svg, dxf) = (dir.join("section.svg"), dir.join("section.dxf"));
    for out in [&svg, &dxf] {
        let run = common::drafter()
            .args(["draw", &sample.display().to_string(), "-o", &out.display().to_string()])
            .args(["--sheet", "A3", "--section", "0.01,0.02,0,0.25,0.4,1", "--uncut", "shaft*,*bolt*"])
            .args(["--hidden", "dashed"])
            .output()
            .expect("drafter runs");
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    }
    let lint = Command::new("xmllint").arg("--noout").arg(&svg).output().expect("xmllint checks the SVG");
    assert!(lint.status.success(), "xmllint: {}", String::from_utf8_lossy(&lint.stderr));
    let text = std::fs::read_to_string(&svg).expect("the SVG");
    let section = text.split(r#"<g id="view-section""#).nth(1).expect("a section view");
    assert!(section.contains(r#"<g class="hatching""#) && section.contains(r#"<g class="cut""#));
    let script = dir.join("read_dxf.py");
    std::fs::write(&script, EZDXF_READER).expect("the reader script is written");
    let read = Command::new("/usr/bin/python3").arg(&script).arg(&dxf).output().expect("ezdxf reads the DXF");
    assert!(read.status.success(), "ezdxf: {}", String::from_utf8_lossy(&read.stderr));
    let read: serde_json::Value = serde_json::from_slice(&read.stdout).expect("the reader's JSON");
    assert_eq!(read["problems"], serde_json::json!([0, 0, 0, 0]), "{read}");
    let hatching = section.split(r#"<g class="hatching""#).nth(1).unwrap_or_default();
    let hatch_lines = hatching[..hatching.find("</g>").unwrap_or(0)].matches("<path").count() as u64;
    assert!(hatch_lines > 0);
    assert_eq!(read["counts"]["HATCH"].as_u64(), Some(hatch_lines), "{read}");
}
