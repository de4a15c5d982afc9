//! `drafter web FILE.glb -o DIR [--page PAGE_DIR]`: a folder for any static host: the browser page
//! (`index.html`, `drafter-viewer.js`, the WebAssembly module `drafter_web_bg.wasm` and its loader
//! `drafter_web.js`) and the model beside them; `DIR/index.html` served over HTTP shows the model
//! with the viewer's own renderer ([docs/web.md](../../../docs/web.md)).
//!
//! The page is built by `scripts/web` into `target/web/page/`, where a `drafter` built in the same
//! checkout (`target/release/drafter`, `target/debug/drafter`) finds it: `../web/page` from its own
//! folder. `--page` or `DRAFTER_WEB_PAGE` names another folder. Without the page files the command
//! fails with one line and exit code 5 ([`crate::exit::MISSING_PAGE`]).
//!
//! The model is checked first as the page will load it (the viewer's reader, the page's default
//! triangle limit), so a file the page would refuse is refused here (exit code 2); an unbaked
//! file is written with a note, as the page shows it with one. The files are
//! staged beside their targets and renamed into place together.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::exit::{BadInput, MissingPage};

/// The files of a built page, all needed.
pub const PAGE_FILES: [&str; 4] = ["index.html", "drafter-viewer.js", "drafter_web.js", "drafter_web_bg.wasm"];

/// The most triangles the page loads by default (its `max-triangles` attribute changes it), which
/// `drafter web` holds the model to before writing the folder: a tab's memory, not the renderer, is
/// the limit. The page's script cannot import it and states it as `DEFAULT_MAX_TRIANGLES`; a test
/// below holds the two equal.
pub const PAGE_MAX_TRIANGLES: u64 = 5_000_000;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The baked model to show (.glb).
    pub file: PathBuf,
    /// The folder to write (created if missing; files of the same names are replaced).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The built page's folder (default: `../web/page` from this executable's folder, where
    /// scripts/web puts it).
    #[arg(long, env = "DRAFTER_WEB_PAGE", value_name = "DIR")]
    pub page: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The folder of the built page: `page`, or `../web/page` beside the running executable.
pub fn page_folder(page: Option<&Path>) -> Result<PathBuf, MissingPage> {
    let folder = match page {
        Some(p) => p.to_path_buf(),
        None => std::env::current_exe()
            .ok()
            .and_then(|exe| Some(exe.parent()?.join("../web/page")))
            .ok_or_else(|| MissingPage("cannot locate this executable to find the web page".into()))?,
    };
    if let Some(missing) = PAGE_FILES.iter().find(|f| !folder.join(f).is_file()) {
        return Err(MissingPage(format!(
            "the browser page is not built ({} has no {missing}): run scripts/web, or name its folder with \
             --page or DRAFTER_WEB_PAGE",
            folder.display()
        )));
    }
    Ok(folder)
}

/// The model's name in the folder: its file name where that is safe in a URL, else `model.glb`.
fn model_name(file: &Path) -> String {
    let name = file.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let plain = name.chars().all(|c| c.is_ascii_alphanumeric() || "._-".contains(c));
    if plain && name.to_ascii_lowercase().ends_with(".glb") && !name.starts_with('.') {
        name
    } else {
        "model.glb".into()
    }
}

pub fn run(args: Args) -> Result<()> {
    let page = page_folder(args.page.as_deref())?;
    if args.file.extension().is_none_or(|e| !e.eq_ignore_ascii_case("glb")) {
        return Err(BadInput(format!(
            "{}: the page loads one binary glTF (.glb); bake the model to .glb first",
            args.file.display()
        ))
        .into());
    }
    let model = crate::cmd::render::load(&args.file, PAGE_MAX_TRIANGLES)?;
    if !model.baked && !args.quiet {
        eprintln!(
            "note: {} is not baked (no DRAFTER_illustration data): the page draws each object as one part, with no \
             baked lines or gradients, and says so; bake it first (drafter bake {} -o OUT.glb)",
            args.file.display(),
            args.file.display()
        );
    }
    let bytes = std::fs::read(&args.file).map_err(|e| BadInput(format!("{}: {e}", args.file.display())))?;
    let name = model_name(&args.file);

    let index = std::fs::read_to_string(page.join("index.html")).context("reading the page's index.html")?;
    let marker = "<html lang=\"en\">";
    if !index.contains(marker) {
        anyhow::bail!("{}: not the page scripts/web builds (no `{marker}`)", page.join("index.html").display());
    }
    let index = index.replacen(marker, &format!("<html lang=\"en\" data-model=\"{name}\">"), 1);

    std::fs::create_dir_all(&args.output)
        .map_err(|e| crate::exit::IoFailure(format!("{}: cannot create: {e}", args.output.display())))?;
    let mut staged = vec![drafter_catalog::output::Staged::new(&args.output.join("index.html"), index.as_bytes())?];
    for file in &PAGE_FILES[1..] {
        let contents =
            std::fs::read(page.join(file)).with_context(|| format!("reading {}", page.join(file).display()))?;
        staged.push(drafter_catalog::output::Staged::new(&args.output.join(file), &contents)?);
    }
    staged.push(drafter_catalog::output::Staged::new(&args.output.join(&name), &bytes)?);
    drafter_catalog::output::commit(staged)?;

    if !args.quiet {
        let total: u64 = PAGE_FILES
            .iter()
            .chain([&name.as_str()])
            .filter_map(|f| std::fs::metadata(args.output.join(f)).ok())
            .map(|m| m.len())
            .sum();
        eprintln!(
            "wrote {}: index.html, the viewer module and {name} ({} triangles, {} parts), {:.1} MB; serve the folder \
             over HTTP (e.g. python3 -m http.server -d {}) and open index.html",
            args.output.display(),
            model.triangle_count(),
            model.parts.len(),
            total as f64 / 1e6,
            args.output.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_names_are_kept_when_safe_in_a_url() {
        assert_eq!(model_name(Path::new("out/gear-box_2.baked.glb")), "gear-box_2.baked.glb");
        assert_eq!(model_name(Path::new("out/a b.glb")), "model.glb");
        assert_eq!(model_name(Path::new("out/x\"y.glb")), "model.glb");
        assert_eq!(model_name(Path::new(".hidden.glb")), "model.glb");
    }

    /// The value of the page script's top-level `const NAME = VALUE;`.
    fn page_constant(name: &str) -> &'static str {
        let script = include_str!("../../../web/page/drafter-viewer.js");
        let start = format!("\nconst {name} = ");
        let at = script.find(&start).unwrap_or_else(|| panic!("drafter-viewer.js has no top-level const {name}"));
        let value = &script[at + start.len()..];
        value[..value.find(";\n").unwrap_or_else(|| panic!("const {name} ends with ;"))].trim()
    }

    /// The strings of a one-line JS array of quoted strings.
    fn page_strings(name: &str) -> Vec<&'static str> {
        let value = page_constant(name);
        let items =
            value.strip_prefix('[').and_then(|v| v.strip_suffix(']')).unwrap_or_else(|| panic!("{name}: {value}"));
        items
            .split(',')
            .map(|item| {
                let item = item.trim();
                item.strip_prefix('\'').and_then(|i| i.strip_suffix('\'')).unwrap_or_else(|| panic!("{name}: {item}"))
            })
            .collect()
    }

    /// The page's script states what it cannot import from the Rust side; each value must be the
    /// Rust one, so that a change on either side fails here rather than in a browser.
    #[test]
    fn the_page_script_states_the_rust_values() {
        let limit: u64 = page_constant("DEFAULT_MAX_TRIANGLES").replace('_', "").parse().expect("a number");
        assert_eq!(limit, PAGE_MAX_TRIANGLES, "the page's DEFAULT_MAX_TRIANGLES");
        // The styles in the viewer's order, as the toolbar lists them and the keys 1-7 number them.
        let styles: Vec<&str> = drafter_render::Style::ALL.iter().map(|s| s.name()).collect();
        assert_eq!(page_strings("STYLES"), styles, "the page's STYLES");
        let shadows: Vec<&str> = drafter_render::ShadowMode::ALL.iter().map(|s| s.name()).collect();
        assert_eq!(page_strings("SHADOWS"), shadows, "the page's SHADOWS");
        // The files a drop loads: any format the importers read (the page imports with drafter-io).
        let mut dropped = page_strings("MODEL_EXTENSIONS");
        dropped.sort_unstable();
        let mut read: Vec<&str> = drafter_io::EXTENSIONS.iter().map(|(x, _)| *x).collect();
        read.sort_unstable();
        assert_eq!(dropped, read, "the page's MODEL_EXTENSIONS");
    }

    #[test]
    fn a_missing_page_is_named() {
        let err = page_folder(Some(Path::new("/nonexistent-drafter-page"))).unwrap_err();
        assert!(err.0.contains("scripts/web"), "{}", err.0);
    }
}
