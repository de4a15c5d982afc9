//! `drafter draw -o view.dxf` and `--style`: the DXF of the sample and of a CAD assembly from
//! ../shared/models is read back by two independent readers, and the ISO 128 style puts exact
//! millimetres on the page.
//!
//! - ezdxf (Debian's python3-ezdxf, run by Debian's /usr/bin/python3, whose package it is):
//!   `ezdxf.recover.readfile` and `doc.audit()` find 0 errors and need 0 fixes, the strict
//!   `ezdxf.readfile` loads it too, every layer holds as many polylines as the SVG has strokes of
//!   that visibility, and every vertex is the SVG's point at 25.4/96 mm a pixel with y turned up,
//!   within 0.01 mm.
//! - LibreCAD 2.2 (Debian's librecad), a CAD program with its own DXF reader (libdxfrw):
//!   `librecad dxf2pdf` under Qt's offscreen platform prints it to a one-page PDF, whose ink (poppler's
//!   pdftoppm) has the drawing's proportions.
//!
//! A reader that is missing fails the test (scripts/test installs both); nothing is skipped.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Millimetres per pixel on the page: 96 pixels per inch.
const MM_PER_PX: f64 = 25.4 / 96.0;

/// Debian's interpreter, the one python3-ezdxf installs into (PATH may find another first).
const PYTHON: &str = "/usr/bin/python3";

/// Reads a DXF with ezdxf and prints what the test checks, as JSON.
const EZDXF_READER: &str = r#"
import json, sys
import ezdxf
from ezdxf import recover

path = sys.argv[1]
doc, auditor = recover.readfile(path)
strict = ezdxf.readfile(path)
audit = strict.audit()
msp = doc.modelspace()
layers = {}
entities = []
for e in msp:
    layer = e.dxf.layer
    layers.setdefault(layer, {})
    layers[layer][e.dxftype()] = layers[layer].get(e.dxftype(), 0) + 1
    if e.dxftype() == "LWPOLYLINE":
        entities.append({"layer": layer, "points": [[p[0], p[1]] for p in e.get_points("xy")]})
table = {l.dxf.name: {"lineweight": l.dxf.lineweight, "linetype": l.dxf.linetype} for l in doc.layers}
linetypes = {}
for lt in doc.linetypes:
    pattern = lt.pattern_tags.tags if lt.pattern_tags else None
    linetypes[lt.dxf.name] = [t.value for t in pattern if t.code == 49] if pattern else []
print(json.dumps({
    "version": doc.dxfversion,
    "recover_errors": len(auditor.errors),
    "recover_fixes": len(auditor.fixes),
    "audit_errors": len(audit.errors),
    "audit_fixes": len(audit.fixes),
    "messages": [str(m) for m in list(auditor.errors) + list(auditor.fixes) + list(audit.errors) + list(audit.fixes)],
    "insunits": doc.header.get("$INSUNITS"),
    "layers": layers,
    "layer_table": table,
    "linetypes": linetypes,
    "entities": entities,
}))
"#;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The strokes of an SVG from `drafter draw`, in order: (visible, points in pixels).
fn svg_strokes(svg: &str) -> Vec<(bool, Vec<(f64, f64)>)> {
    let visible_from = svg.find(r#"<g id="visible""#).expect("a visible group");
    let mut out = Vec::new();
    let mut at = 0;
    while let Some(found) = svg[at..].find("<path") {
        let start = at + found;
        let d = start + svg[start..].find(" d=\"").expect("a path's data") + 4;
        let end = d + svg[d..].find('"').expect("the attribute closes");
        let numbers: Vec<f64> = svg[d..end]
            .split([' ', 'M', 'L'])
            .filter(|t| !t.is_empty())
            .map(|t| t.parse().expect("a coordinate"))
            .collect();
        out.push((start > visible_from, numbers.chunks_exact(2).map(|p| (p[0], p[1])).collect()));
        at = end;
    }
    out
}

/// Runs ezdxf on `dxf`; what it read, as JSON.
fn ezdxf_read(dxf: &Path, dir: &Path) -> serde_json::Value {
    let script = dir.join("read_dxf.py");
    std::fs::write(&script, EZDXF_READER).expect("the reader script is written");
    let run = Command::new(PYTHON)
        .arg(&script)
        .arg(dxf)
        .output()
        .expect("/usr/bin/python3 (apt python3-ezdxf; scripts/test installs it) reads the DXF");
    assert!(
        run.status.success(),
        "ezdxf (apt python3-ezdxf; scripts/test installs it) could not read {}: {}",
        dxf.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).expect("the reader's JSON")
}

/// Prints `dxf` to a PDF with LibreCAD, fitted to an A4 landscape sheet; the PDF's path.
fn librecad_print(dxf: &Path, dir: &Path) -> PathBuf {
    // LibreCAD 2.2 takes `-o` as a flag, not with a file: it writes beside the DXF, named after it.
    let pdf = dxf.with_extension("pdf");
    let runtime = dir.join("runtime");
    std::fs::create_dir_all(&runtime).expect("a runtime folder");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        std::fs::set_permissions(&runtime, std::fs::Permissions::from_mode(0o700)).expect("a private runtime folder");
    }
    let run = Command::new("librecad")
        .args(["dxf2pdf", "--fit", "--paper", "297x210", "--margins", "10,10,10,10"])
        .arg(dxf)
        .env("QT_QPA_PLATFORM", "offscreen")
        .env("XDG_RUNTIME_DIR", &runtime)
        .env("XDG_CONFIG_HOME", dir.join("config"))
        .output()
        .expect("librecad (apt librecad; scripts/test installs it) prints the DXF");
    let out = format!("{}{}", String::from_utf8_lossy(&run.stdout), String::from_utf8_lossy(&run.stderr));
    assert!(
        run.status.success() && out.contains("DONE") && pdf.is_file(),
        "LibreCAD did not print {}: {out}",
        dxf.display()
    );
    pdf
}

/// The bounding box of a PDF page's ink (pdftoppm at 72 dpi, grey levels below 128), in pixels:
/// (width, height, dark pixels).
fn ink(pdf: &Path) -> (usize, usize, usize) {
    let stem = pdf.with_extension("");
    let run = Command::new("pdftoppm")
        .args(["-r", "72", "-gray", "-singlefile"])
        .arg(pdf)
        .arg(&stem)
        .output()
        .expect("pdftoppm (apt poppler-utils; scripts/test installs it) rasterises the PDF");
    assert!(run.status.success(), "pdftoppm: {}", String::from_utf8_lossy(&run.stderr));
    let pgm = std::fs::read(stem.with_extension("pgm")).expect("pdftoppm wrote the page");
    // Binary PGM: "P5\n<w> <h>\n<max>\n" then one byte a pixel.
    let mut fields = Vec::new();
    let mut at = 0;
    while fields.len() < 4 {
        while pgm[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while !pgm[at].is_ascii_whitespace() {
            at += 1;
        }
        fields.push(String::from_utf8_lossy(&pgm[start..at]).into_owned());
    }
    let size = |k: usize| fields[k].parse::<usize>().expect("a PGM size");
    let (w, h) = (size(1), size(2));
    let pixels = &pgm[at + 1..];
    assert_eq!(pixels.len(), w * h);
    let (mut x0, mut y0, mut x1, mut y1, mut dark) = (usize::MAX, usize::MAX, 0, 0, 0);
    for (i, &p) in pixels.iter().enumerate() {
        if p < 128 {
            let (x, y) = (i % w, i / w);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            dark += 1;
        }
    }
    assert!(dark > 0, "{}: no ink", pdf.display());
    (x1 - x0 + 1, y1 - y0 + 1, dark)
}

#[test]
fn dxf_of_the_sample_and_a_cad_assembly_reads_back_in_ezdxf_and_librecad() {
    let dir = common::scratch("draw-dxf");
    let sample = dir.join("sample.glb");
    common::bake(&repo().join("samples/assembly.glb"), &sample, &[]);
    let rod = common::shared_models().join("gltf/RodAssembly/rod.glb");
    for (name, input, args) in [
        ("sample", sample.as_path(), &["--hidden", "dashed"][..]),
        (
            "sample-gooch",
            sample.as_path(),
            &["--hidden", "dashed", "--style", "gooch", "--view", "0,89.99999", "--ortho"][..],
        ),
        ("rod", rod.as_path(), &["--hidden", "dashed", "--view", "0,0", "--ortho", "--size", "1000x700"][..]),
    ] {
        let (svg, dxf) = (dir.join(format!("{name}.svg")), dir.join(format!("{name}.dxf")));
        for out in [&svg, &dxf] {
            let run =
                common::run(&[&["draw", input.to_str().unwrap(), "-o", out.to_str().unwrap()][..], args].concat());
            assert!(run.status.success(), "{name}: {}", String::from_utf8_lossy(&run.stderr));
        }
        let strokes = svg_strokes(&std::fs::read_to_string(&svg).unwrap());
        let height = if name == "rod" { 700.0 } else { 600.0 };
        let read = ezdxf_read(&dxf, &dir);
        eprintln!(
            "{name}: {} strokes; ezdxf read {} (layers {}), recover {} errors {} fixes, audit {} errors {} fixes",
            strokes.len(),
            read["version"],
            read["layers"],
            read["recover_errors"],
            read["recover_fixes"],
            read["audit_errors"],
            read["audit_fixes"]
        );
        assert_eq!(read["version"], "AC1015", "{name}: DXF R2000");
        for key in ["recover_errors", "recover_fixes", "audit_errors", "audit_fixes"] {
            assert_eq!(read[key], 0, "{name}: {key}: {}", read["messages"]);
        }
        assert_eq!(read["insunits"], 4, "{name}: millimetres");
        // One polyline per SVG stroke, on the layer of its visibility, nothing else.
        let count = |visible: bool| strokes.iter().filter(|s| s.0 == visible).count();
        let on = |layer: &str| read["layers"][layer]["LWPOLYLINE"].as_u64().unwrap_or(0) as usize;
        let tangent = on("TANGENT");
        assert_eq!(on("VISIBLE") + tangent, count(true), "{name}: visible polylines");
        assert_eq!(on("HIDDEN"), count(false), "{name}: hidden polylines");
        assert!(
            count(true) > 50 && count(false) > 10,
            "{name}: lines drawn: {} visible, {} hidden",
            count(true),
            count(false)
        );
        let kinds: usize = read["layers"]
            .as_object()
            .unwrap()
            .values()
            .flat_map(|l| l.as_object().unwrap().values())
            .map(|n| n.as_u64().unwrap() as usize)
            .sum();
        assert_eq!(kinds, strokes.len(), "{name}: no other entities: {}", read["layers"]);
        // Every vertex where the SVG puts it, in millimetres with y up.
        let entities = read["entities"].as_array().unwrap();
        assert_eq!(entities.len(), strokes.len());
        let mut worst = 0.0f64;
        for ((visible, points), entity) in strokes.iter().zip(entities) {
            let layer = entity["layer"].as_str().unwrap();
            assert_eq!(*visible, layer != "HIDDEN", "{name}: the same order as the SVG");
            let vertices = entity["points"].as_array().unwrap();
            assert_eq!(vertices.len(), points.len(), "{name}: the same vertices as the SVG path");
            for (&(x, y), v) in points.iter().zip(vertices) {
                let (vx, vy) = (v[0].as_f64().unwrap(), v[1].as_f64().unwrap());
                worst = worst.max((vx - x * MM_PER_PX).abs()).max((vy - (height - y) * MM_PER_PX).abs());
            }
        }
        eprintln!("{name}: the farthest DXF vertex {worst:.5} mm from its SVG point");
        assert!(worst <= 0.01, "{name}: a vertex {worst} mm from the SVG's point");
        // The layers' pens: ISO 128 by default, exact in DXF's lineweights.
        let table = &read["layer_table"];
        if name.ends_with("gooch") {
            assert_eq!(
                (table["VISIBLE"]["lineweight"].as_i64(), table["HIDDEN"]["lineweight"].as_i64()),
                (Some(40), Some(15))
            );
        } else {
            assert_eq!(
                (table["VISIBLE"]["lineweight"].as_i64(), table["HIDDEN"]["lineweight"].as_i64()),
                (Some(50), Some(25))
            );
            assert_eq!(table["HIDDEN"]["linetype"], "HIDDEN");
            let pattern: Vec<f64> =
                read["linetypes"]["HIDDEN"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            assert_eq!(pattern, [3.0, -0.75], "{name}: ISO 128-20 dashes, 12 d and 3 d at d = 0.25 mm");
        }
        // Deterministic bytes.
        let again = dir.join(format!("{name}-again.dxf"));
        let run = common::run(&[&["draw", input.to_str().unwrap(), "-o", again.to_str().unwrap()][..], args].concat());
        assert!(run.status.success());
        assert_eq!(std::fs::read(&dxf).unwrap(), std::fs::read(&again).unwrap(), "{name}: the same bytes");

        // LibreCAD prints it; its ink has the proportions of the drawing's extents.
        let pdf = librecad_print(&dxf, &dir);
        let (w, h, dark) = ink(&pdf);
        let all: Vec<(f64, f64)> = strokes.iter().flat_map(|s| s.1.iter().copied()).collect();
        let span = |f: fn(&(f64, f64)) -> f64| {
            let values = all.iter().map(f);
            values.clone().fold(f64::MIN, f64::max) - values.fold(f64::MAX, f64::min)
        };
        let (drawing_ratio, ink_ratio) = (span(|p| p.0) / span(|p| p.1), w as f64 / h as f64);
        eprintln!(
            "{name}: LibreCAD's ink {w} x {h} pt ({dark} dark pixels), ratio {ink_ratio:.3} against the drawing's {drawing_ratio:.3}"
        );
        assert!(dark > 1000, "{name}: LibreCAD drew the lines");
        assert!((ink_ratio / drawing_ratio - 1.0).abs() < 0.05, "{name}: {ink_ratio} against {drawing_ratio}");
    }
}

/// `--style iso128` (the default): a page in millimetres at 96 px per inch, one visible width of
/// 0.5 mm, hidden lines 0.25 mm dashed 12 d on and 3 d off; xmllint accepts it; the PDF has the
/// same page in points. `--style gooch` keeps the three pixel weights.
#[test]
fn iso128_puts_exact_millimetres_on_the_page() {
    let dir = common::scratch("draw-iso128");
    let sample = repo().join("samples/assembly.glb");
    let baked = dir.join("sample.glb");
    common::bake(&sample, &baked, &[]);
    let svg = dir.join("iso.svg");
    let run = common::run(&["draw", baked.to_str().unwrap(), "-o", svg.to_str().unwrap(), "--hidden", "dashed"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let lint = Command::new("xmllint").arg("--noout").arg(&svg).output().expect("xmllint");
    assert!(lint.status.success(), "xmllint: {}", String::from_utf8_lossy(&lint.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains(r#"width="211.666667mm" height="158.75mm" viewBox="0 0 800 600""#),
        "800 x 600 px at 96 per inch"
    );
    let widths: std::collections::BTreeSet<&str> =
        text.split("stroke-width=\"").skip(1).map(|rest| &rest[..rest.find('"').unwrap()]).collect();
    let visible = &text[text.find(r#"<g id="visible""#).unwrap()..];
    let hidden = &text[text.find(r#"<g id="hidden""#).unwrap()..text.find(r#"<g id="visible""#).unwrap()];
    let width_set = |part: &str| -> std::collections::BTreeSet<String> {
        part.split("<g class=\"")
            .skip(1)
            .filter(|g| !g.starts_with("tangent"))
            .map(|g| {
                let rest = &g[g.find("stroke-width=\"").unwrap() + 14..];
                rest[..rest.find('"').unwrap()].to_string()
            })
            .collect()
    };
    assert_eq!(width_set(visible), ["0.5mm".to_string()].into(), "one visible width: {widths:?}");
    assert_eq!(width_set(hidden), ["0.25mm".to_string()].into(), "narrow hidden lines");
    assert!(
        hidden.starts_with(r##"<g id="hidden" stroke="#000" stroke-dasharray="3mm 0.75mm">"##),
        "{}",
        &hidden[..80]
    );
    // The proportions: dash 12 d, gap 3 d, d the hidden width.
    let (d, dash, gap) = (0.25, 3.0, 0.75);
    assert_eq!((dash / d, gap / d), (12.0, 3.0));

    // Gooch: its weights (the sample shows outlines and creases) and the grey "4 3" dashes, in
    // pixels, as before.
    let gooch = dir.join("gooch.svg");
    let run = common::run(&[
        "draw",
        baked.to_str().unwrap(),
        "-o",
        gooch.to_str().unwrap(),
        "--hidden",
        "dashed",
        "--style",
        "gooch",
    ]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let text = std::fs::read_to_string(&gooch).unwrap();
    let visible = &text[text.find(r#"<g id="visible""#).unwrap()..];
    for needle in [r#"<g class="silhouette" stroke-width="1.6">"#, r#"<g class="crease" stroke-width="0.9">"#] {
        assert!(visible.contains(needle), "{needle}");
    }
    assert!(text.contains(r##"<g id="hidden" stroke="#666" stroke-dasharray="4 3">"##));

    // The PDF: the same page in points (800 px = 600 pt).
    let pdf = dir.join("iso.pdf");
    let run = common::run(&["draw", baked.to_str().unwrap(), "-o", pdf.to_str().unwrap(), "--hidden", "dashed"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let info = Command::new("pdfinfo").arg(&pdf).output().expect("pdfinfo");
    assert!(String::from_utf8_lossy(&info.stdout).contains("600 x 450 pts"));
    // Its line widths and dashes (the content stream is not compressed): 0.5 and 0.25 mm, dashes
    // of 3 and 0.75 mm, at 72/25.4 pt a millimetre (the fills' 0.375 pt outline left aside).
    let bytes = std::fs::read(&pdf).unwrap();
    let content = String::from_utf8_lossy(&bytes);
    let pt = |mm: f64| mm * 72.0 / 25.4;
    let mut widths: Vec<f64> = content
        .lines()
        .filter_map(|l| l.strip_suffix(" w"))
        .map(|v| v.parse::<f64>().expect("a width"))
        .filter(|&w| w != 0.375)
        .collect();
    widths.dedup();
    widths.sort_by(f64::total_cmp);
    widths.dedup();
    assert_eq!(widths.len(), 2, "{widths:?}");
    assert!((widths[0] - pt(0.25)).abs() < 1e-5 && (widths[1] - pt(0.5)).abs() < 1e-5, "{widths:?}");
    let dashes: Vec<&str> =
        content.lines().filter(|l| l.ends_with(" d") && l.starts_with("[") && !l.starts_with("[]")).collect();
    assert!(!dashes.is_empty());
    for dash in dashes {
        let numbers: Vec<f64> = dash[1..dash.find(']').unwrap()].split(' ').map(|v| v.parse().unwrap()).collect();
        assert!((numbers[0] - pt(3.0)).abs() < 1e-5 && (numbers[1] - pt(0.75)).abs() < 1e-5, "{dash}");
    }
}
