//! `drafter render FILE -o out.png [--style S] [--size WxH] [--view AZ,EL] [--edges] [--lines]
//! [--shadow hard|penumbra|soft|none] [--ortho] [--supersample N] ...`: renders a baked file (or any
//! model) headless with the viewer's passes and writes a PNG. Works without a GPU on lavapipe.

use std::path::PathBuf;

use anyhow::Result;
use drafter_render::{Enhancements, LoadError, Model, RenderOptions, Renderer, ShadowMode, Style, View};

use crate::exit::BadInput;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The model to render: a baked .glb/.gltf, or any glTF, OBJ, STL, OFF, PLY.
    pub file: PathBuf,
    /// The PNG to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Shading style of the scene; parts with a baked style hint keep theirs (see --uniform-style).
    #[arg(long, value_enum, default_value_t = Style::Gradient)]
    pub style: Style,
    /// Ignore the parts' baked style hints: every part in --style.
    #[arg(long)]
    pub uniform_style: bool,
    /// Image size in pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "800x600", value_parser = parse_size)]
    pub size: (u32, u32),
    /// View direction: azimuth about +y from +z towards +x, and elevation, in degrees.
    #[arg(long, value_name = "AZ,EL", default_value = "35,25", value_parser = parse_view, allow_hyphen_values = true)]
    pub view: (f32, f32),
    /// Image-space edges: outlines (part borders, silhouettes, heavier outer line), creases and
    /// the depth unsharp mask.
    #[arg(long)]
    pub edges: bool,
    /// Lines from the baked edges: creases, boundaries, part borders and this view's silhouettes
    /// (from the baked hierarchies), drawn as wide screen-space lines.
    #[arg(long)]
    pub lines: bool,
    /// Drop shadow on the ground plane.
    #[arg(long, value_enum, default_value_t = ShadowMode::None)]
    pub shadow: ShadowMode,
    /// Orthographic projection instead of perspective.
    #[arg(long)]
    pub ortho: bool,
    /// Supersampling factor (1–4): drawn at N times the size and filtered down.
    #[arg(long, default_value_t = 2)]
    pub supersample: u32,
    /// Steps of cel and Goochel shading (2–4).
    #[arg(long, default_value_t = drafter_render::style::DEFAULT_CEL_STEPS)]
    pub cel_steps: u32,
    /// Gooch's splash-back term on cool-to-warm shading.
    #[arg(long)]
    pub splash_back: bool,
    /// Highlight the part with this id.
    #[arg(long, value_name = "ID")]
    pub select: Option<u32>,
    /// Shade with the baked enhanced normals (Cignoni et al. 2005, `_ENHANCED_NORMAL`) instead of
    /// the crease-aware ones; a file baked without them renders as usual, with a notice.
    #[arg(long)]
    pub enhanced_normals: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
    /// Refuse a model that lists more triangles than this (over all meshes, an instanced mesh
    /// once; a glTF's are counted before any is read).
    #[arg(long, value_name = "N", default_value_t = drafter_io::DEFAULT_MAX_TRIANGLES)]
    pub max_triangles: u64,
}

pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("{s:?} is not WIDTHxHEIGHT"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("{s:?}: {e}"));
    Ok((parse(w)?, parse(h)?))
}

pub(crate) fn parse_view(s: &str) -> Result<(f32, f32), String> {
    let (az, el) = s.split_once(',').ok_or_else(|| format!("{s:?} is not AZ,EL"))?;
    let parse = |v: &str| v.trim().parse::<f32>().map_err(|e| format!("{s:?}: {e}"));
    Ok((parse(az)?, parse(el)?))
}

impl Args {
    /// The viewer's options for these arguments.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            size: self.size,
            supersample: self.supersample,
            style: self.style,
            use_part_styles: !self.uniform_style,
            view: View { azimuth_deg: self.view.0, elevation_deg: self.view.1 },
            orthographic: self.ortho,
            enhancements: if self.edges { Enhancements::ALL } else { Enhancements::default() },
            lines: self.lines,
            shadow: self.shadow,
            cel_steps: self.cel_steps,
            splash_back: self.splash_back,
            selected_part: self.select,
            enhanced_normals: self.enhanced_normals,
            ..RenderOptions::default()
        }
    }
}

/// Loads a model for rendering, mapping the viewer's load errors onto the CLI's exit codes.
pub fn load(path: &std::path::Path, max_triangles: u64) -> Result<Model> {
    Model::load_within(path, &drafter_io::Limits { max_triangles }).map_err(|e| match e {
        LoadError::Import(e) => anyhow::Error::from(e),
        other => anyhow::Error::from(BadInput(other.to_string())),
    })
}

pub fn run(args: Args) -> Result<()> {
    let options = args.options();
    options.validate().map_err(BadInput)?;
    if args.output.extension().is_none_or(|e| !e.eq_ignore_ascii_case("png")) {
        return Err(BadInput(format!("{}: output must end in .png", args.output.display())).into());
    }
    let model = load(&args.file, args.max_triangles)?;
    let mut renderer = Renderer::new()?;
    renderer.set_model(&model)?;
    let image = renderer.render(&options)?;
    let png = image.to_png()?;
    std::fs::write(&args.output, png).map_err(|e| BadInput(format!("{}: cannot write: {e}", args.output.display())))?;
    if !args.quiet {
        eprintln!(
            "rendered {} → {}: {}x{}, style {}, {} triangles, {} parts, on {}",
            args.file.display(),
            args.output.display(),
            image.width,
            image.height,
            options.style,
            model.triangle_count(),
            model.parts.len(),
            renderer.gpu().description()
        );
        for notice in &model.notices {
            eprintln!("  note: {notice}");
        }
        if args.enhanced_normals && !model.has_enhanced_normals() {
            eprintln!("  note: no enhanced normals in the file (bake it with normals): drawn with its own normals");
        }
        if args.lines
            && let Some(notice) = drafter_render::passes::lines::notice(&model.lines)
        {
            eprintln!("  note: {notice}");
        }
    }
    Ok(())
}
