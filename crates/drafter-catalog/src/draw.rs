//! Drawings of many files, and one file's drawing the same way everywhere: `drafter draw DIR -o
//! OUT --sheet A3` (a catalog), `drafter draw FILE -o x.svg --cache DIR`, and the Python package's
//! `drafter.draw` and `drafter.draw_many` all go through [`draw_file`], over the batch's scheduler
//! ([`crate::batch::run_jobs`]), output confinement and cache.
//!
//! **Options.** A drawing's options are one plain value, [`DrawSpec`] (serde: the CLI fills it from
//! its flags, Python from its keyword arguments as JSON), turned into drafter-draw's options by
//! [`DrawSpec::resolve`], which refuses every mistake by name before any work.
//!
//! **Outputs.** Each input is drawn once and written in every format asked for, as
//! `OUT/<its path relative to what named it>.svg|.pdf|.dxf` (the bake's mirrored path with the
//! format's extension instead of `.glb`).
//!
//! **Cache.** A drawing's key is BLAKE3 over [`DRAW_FORM`], the key of the in-memory bake the
//! drawing would run ([`crate::cache::key_of_file`] with the default configuration: drafter's build,
//! the format version, the input's name, its bytes and every external file it names), the output
//! format and the drawing's options in canonical form ([`Resolved::canonical`]: sorted JSON of the
//! derived serialization, each option as the drawing reads it, so no option can be left out of the
//! key). Entries hold the drawing's bytes and its notes; receipts leave an up-to-date output alone,
//! as for bakes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use drafter_draw::sheet::{self, Angle, Axis, Scale, SheetOptions, SheetSize, ViewKind};
use drafter_draw::{DrawOptions, LineStyle};
use drafter_scene::{LoadError, Model, View};
use serde::{Deserialize, Serialize};

use crate::batch::{CacheUse, Observer, Permit, Record, Scheduling, Status, Summary};
use crate::cache::{Cache, Key, Miss};
use crate::discover::{Discovered, Item};
use crate::job::Error;

/// The version of a drawing key's canonical form: changed whenever the form does.
pub const DRAW_FORM: &str = "drafter-draw-json-1";

/// What a drawing is written as.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    Svg,
    Pdf,
    Dxf,
}

impl Format {
    pub fn extension(self) -> &'static str {
        match self {
            Format::Svg => "svg",
            Format::Pdf => "pdf",
            Format::Dxf => "dxf",
        }
    }

    /// The format a file name asks for, by its extension (any case).
    pub fn of_path(path: &Path) -> Option<Format> {
        let extension = path.extension()?.to_string_lossy().to_ascii_lowercase();
        Self::parse(&extension).ok()
    }

    pub fn parse(text: &str) -> Result<Format, String> {
        match text.trim().to_ascii_lowercase().as_str() {
            "svg" => Ok(Format::Svg),
            "pdf" => Ok(Format::Pdf),
            "dxf" => Ok(Format::Dxf),
            _ => Err(format!("{text}: not a drawing format (svg, pdf or dxf)")),
        }
    }

    /// `svg,pdf,dxf`: each once, in the order given; at least one.
    pub fn parse_list(text: &str) -> Result<Vec<Format>, String> {
        let mut formats = Vec::new();
        for word in text.split(',').filter(|w| !w.trim().is_empty()) {
            let format = Self::parse(word)?;
            if !formats.contains(&format) {
                formats.push(format);
            }
        }
        if formats.is_empty() {
            return Err(format!("{text:?}: no format (svg, pdf or dxf)"));
        }
        Ok(formats)
    }
}

/// Lines hidden by surfaces (drafter-draw's `Hidden`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Hidden {
    #[default]
    None,
    Dashed,
    Solid,
}

/// Tangent edges (drafter-draw's `Smooth`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Smooth {
    None,
    #[default]
    Thin,
    Dashed,
}

/// Pens (drafter-draw's `LineStyle`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Style {
    #[default]
    Iso128,
    Gooch,
}

/// Part fills under one view's lines (drafter-draw's `Fill`; not on a sheet).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Fill {
    #[default]
    None,
    Flat,
    Bands,
}

/// Where a sheet's views go around the front view.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Projection {
    #[default]
    First,
    Third,
}

/// The length of one model unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Units {
    M,
    Cm,
    Mm,
    In,
}

impl From<Hidden> for drafter_draw::Hidden {
    fn from(h: Hidden) -> Self {
        match h {
            Hidden::None => Self::None,
            Hidden::Dashed => Self::Dashed,
            Hidden::Solid => Self::Solid,
        }
    }
}

impl From<Smooth> for drafter_draw::Smooth {
    fn from(s: Smooth) -> Self {
        match s {
            Smooth::None => Self::None,
            Smooth::Thin => Self::Thin,
            Smooth::Dashed => Self::Dashed,
        }
    }
}

impl From<Style> for LineStyle {
    fn from(s: Style) -> Self {
        match s {
            Style::Iso128 => Self::Iso128,
            Style::Gooch => Self::Gooch,
        }
    }
}

impl From<Fill> for drafter_draw::Fill {
    fn from(f: Fill) -> Self {
        match f {
            Fill::None => Self::None,
            Fill::Flat => Self::Flat,
            Fill::Bands => Self::Bands,
        }
    }
}

impl Units {
    fn mm(self) -> f64 {
        match self {
            Units::M => 1000.0,
            Units::Cm => 10.0,
            Units::Mm => 1.0,
            Units::In => 25.4,
        }
    }
}

/// A drawing's options: one view, or a sheet of views when `sheet` is given. The defaults are
/// `drafter draw`'s.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DrawSpec {
    pub hidden: Hidden,
    pub smooth: Smooth,
    pub style: Style,
    /// Pieces shorter than this many pixels are dropped and end points closer than it joined.
    pub tolerance_px: f64,
    /// One view's size in pixels (not on a sheet).
    pub size: (u32, u32),
    /// One view's azimuth and elevation in degrees (not on a sheet).
    pub view: (f32, f32),
    /// One view in orthographic projection (not on a sheet).
    pub orthographic: bool,
    /// One view's part fills (not on a sheet).
    pub fill: Fill,
    /// A sheet of the standard views instead of one view.
    pub sheet: Option<SheetSpec>,
}

impl Default for DrawSpec {
    fn default() -> Self {
        let defaults = DrawOptions::default();
        DrawSpec {
            hidden: Hidden::None,
            smooth: Smooth::Thin,
            style: Style::Iso128,
            tolerance_px: defaults.tolerance_px,
            size: defaults.size,
            view: (35.0, 25.0),
            orthographic: false,
            fill: Fill::None,
            sheet: None,
        }
    }
}

/// A sheet's options (`drafter draw --sheet ...`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SheetSpec {
    /// A4, A3, A2, A1 or A0.
    pub size: String,
    /// View names (front, top, right, left, bottom, rear, iso); an entry may itself be a
    /// comma-separated list, as the CLI's `--views` is.
    pub views: Vec<String>,
    pub projection: Projection,
    /// PAPER:REAL; `None`: the largest of the ISO 5455 series that fits.
    pub scale: Option<String>,
    /// The model's up axis and the way its front faces: x, y, z, -x, -y or -z.
    pub up: String,
    pub front: String,
    /// `None`: metres for glTF and GLB, millimetres for the other formats.
    pub units: Option<Units>,
    pub date: Option<String>,
    /// `None`: the file's name without its extension (and without `.baked`).
    pub title: Option<String>,
    /// A section view through this plane: `x=10`, or `px,py,pz,nx,ny,nz`.
    pub section: Option<String>,
    /// Parts the section leaves whole, by name pattern.
    pub uncut: Vec<String>,
}

impl Default for SheetSpec {
    fn default() -> Self {
        SheetSpec {
            size: "A3".into(),
            views: vec!["front,top,right,iso".into()],
            projection: Projection::First,
            scale: None,
            up: "y".into(),
            front: "z".into(),
            units: None,
            date: None,
            title: None,
            section: None,
            uncut: Vec::new(),
        }
    }
}

/// What a drawing runs: one view or a sheet.
#[derive(Clone, Debug)]
pub enum Plan {
    View(DrawOptions),
    Sheet(Box<SheetOptions>),
}

/// A [`DrawSpec`] checked and turned into drafter-draw's options for one input.
#[derive(Clone, Debug)]
pub struct Resolved {
    pub plan: Plan,
    pub style: LineStyle,
    /// The options in the form the cache's key hashes: the spec with every value as the drawing
    /// reads it (views by name, the scale as written back, the title and units resolved for the
    /// input, a sheet's view options left at their defaults since a sheet does not read them).
    pub canonical: serde_json::Value,
}

/// Millimetres per unit of `file`'s coordinates when the units are not given: glTF's are metres.
fn default_mm_per_unit(file: &Path) -> f64 {
    let extension = file.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("gltf" | "glb") => 1000.0,
        _ => 1.0,
    }
}

impl DrawSpec {
    /// The options for drawing `input`, every mistake refused by name (bad input) before any work.
    pub fn resolve(&self, input: &Path) -> Result<Resolved, Error> {
        let bad = Error::Input;
        if !(self.tolerance_px.is_finite() && self.tolerance_px >= 0.0) {
            return Err(bad(format!(
                "--tolerance {}: must be a finite number of pixels, 0 or more",
                self.tolerance_px
            )));
        }
        let (hidden, smooth, style) = (self.hidden.into(), self.smooth.into(), LineStyle::from(self.style));
        let mut canonical = self.clone();
        let plan = match &self.sheet {
            None => {
                let (w, h) = self.size;
                if w == 0 || h == 0 || w > 65_536 || h > 65_536 {
                    return Err(bad(format!("--size {w}x{h}: each side must be 1 to 65536 pixels")));
                }
                let view = View { azimuth_deg: self.view.0, elevation_deg: self.view.1 };
                if !view.azimuth_deg.is_finite() {
                    return Err(bad(format!(
                        "--view {},{}: azimuth must be a finite number of degrees",
                        self.view.0, self.view.1
                    )));
                }
                if !(view.elevation_deg > -90.0 && view.elevation_deg < 90.0) {
                    return Err(bad(format!("--view {},{}: elevation must be in (-90, 90)", self.view.0, self.view.1)));
                }
                Plan::View(DrawOptions {
                    size: self.size,
                    view,
                    orthographic: self.orthographic,
                    hidden,
                    tolerance_px: self.tolerance_px,
                    fill: self.fill.into(),
                    smooth,
                    ..DrawOptions::default()
                })
            }
            Some(s) => {
                let size: SheetSize = s.size.parse().map_err(bad)?;
                let views = ViewKind::parse_list(&s.views.join(",")).map_err(bad)?;
                let scale = s.scale.as_deref().map(str::parse::<Scale>).transpose().map_err(bad)?;
                let axis = |flag: &str, text: &str| text.parse::<Axis>().map_err(|e| bad(format!("--{flag} {e}")));
                let (up, front) = (axis("up", &s.up)?, axis("front", &s.front)?);
                if up.vector().cross(front.vector()).length_squared() == 0.0 {
                    return Err(bad(format!("--up {} --front {}: must be two different axes", s.up, s.front)));
                }
                let title = s.title.clone().unwrap_or_else(|| {
                    let name = input.file_stem().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                    name.strip_suffix(".baked").map(str::to_string).unwrap_or(name)
                });
                let mm_per_unit = s.units.map_or_else(|| default_mm_per_unit(input), Units::mm);
                let options = SheetOptions {
                    size,
                    views: views.clone(),
                    angle: match s.projection {
                        Projection::First => Angle::First,
                        Projection::Third => Angle::Third,
                    },
                    scale,
                    front,
                    up,
                    mm_per_unit,
                    title: title.clone(),
                    date: s.date.clone(),
                    section: s.section.as_deref().map(sheet::section::Plane::parse).transpose().map_err(bad)?,
                    uncut: s.uncut.iter().map(|p| p.trim()).filter(|p| !p.is_empty()).map(str::to_string).collect(),
                    draw: DrawOptions { hidden, tolerance_px: self.tolerance_px, smooth, ..DrawOptions::default() },
                };
                // A sheet does not read one view's options: left at their defaults in the key.
                let defaults = DrawSpec::default();
                canonical = DrawSpec { sheet: None, ..self.clone() };
                (canonical.size, canonical.view) = (defaults.size, defaults.view);
                (canonical.orthographic, canonical.fill) = (defaults.orthographic, defaults.fill);
                canonical.sheet = Some(SheetSpec {
                    size: size.name().to_owned(),
                    views: views.iter().map(|v| v.name().to_owned()).collect(),
                    scale: scale.map(|s| s.to_string()),
                    up: s.up.trim().to_ascii_lowercase(),
                    front: s.front.trim().to_ascii_lowercase(),
                    // Resolved into `mm_per_unit` below: the glTF default and an explicit `m` agree.
                    units: None,
                    title: Some(title),
                    uncut: options.uncut.clone(),
                    ..s.clone()
                });
                let mut value = serde_json::to_value(&canonical).unwrap_or(serde_json::Value::Null);
                if let Some(sheet) = value.get_mut("sheet").and_then(|s| s.as_object_mut()) {
                    sheet.insert("mm_per_unit".into(), serde_json::json!(mm_per_unit));
                }
                return Ok(Resolved { plan: Plan::Sheet(Box::new(options)), style, canonical: value });
            }
        };
        canonical.sheet = None;
        let canonical = serde_json::to_value(&canonical).unwrap_or(serde_json::Value::Null);
        Ok(Resolved { plan, style, canonical })
    }
}

/// Reads the model to draw from `bytes` (read from `path`). A file without `DRAFTER_illustration`
/// data has no baked edges: it is baked in memory first through [`crate::job::bake_bytes`] with the
/// default settings, so it draws the lines its bake would; the `bool` says so. A file that loads
/// but cannot be drawn is bad input.
pub fn load(path: &Path, bytes: Vec<u8>, limits: &drafter_io::Limits) -> Result<(Model, bool), Error> {
    let bad = |e: LoadError| match e {
        LoadError::Import(e) => Error::Import(e),
        other => Error::Input(other.to_string()),
    };
    if is_baked(path, &bytes) {
        return Ok((Model::load_bytes_for_drawing(path, &bytes, limits).map_err(bad)?, false));
    }
    // The drawing reads the bake's edges, not its lookup textures.
    let mut config = drafter_bake::BakeConfig::default();
    config.textures.enabled = false;
    let baked = crate::job::bake_bytes(path, bytes, &config, limits, &mut |_| {})?;
    // The default container is one self-contained .glb, named as `drafter bake` would name it.
    let name = path.with_extension("baked.glb");
    Ok((Model::load_bytes_for_drawing(&name, &baked.written.main, limits).map_err(bad)?, true))
}

/// Whether `bytes` carry `DRAFTER_illustration` data (a compressed GLB decoded first, as the model
/// loader does). A file whose data does not read counts as baked: loading it reports why.
fn is_baked(path: &Path, bytes: &[u8]) -> bool {
    let plain = drafter_format::meshopt::decompress_glb(bytes).ok().flatten();
    !matches!(drafter_format::read_if_baked(path, plain.as_deref().unwrap_or(bytes)), Ok(None))
}

/// One input's drawing, in each format asked for.
#[derive(Clone, Debug)]
pub struct Drawn {
    /// The bytes of each format, in the order asked for.
    pub files: Vec<Vec<u8>>,
    /// What a single `drafter draw` notes on stderr: a file baked in memory, the model's notices,
    /// bodies a section left uncut.
    pub notes: Vec<String>,
}

/// Draws `bytes`, read from `path`, as `resolved` says, in each of `formats`.
pub fn draw_bytes(
    path: &Path,
    bytes: Vec<u8>,
    resolved: &Resolved,
    formats: &[Format],
    limits: &drafter_io::Limits,
) -> Result<Drawn, Error> {
    let (model, baked_here) = load(path, bytes, limits)?;
    let style = resolved.style;
    let mut notes = Vec::new();
    if baked_here {
        notes.push(format!("{} has no baked lines: baked in memory with the default settings", path.display()));
    }
    notes.extend(model.notices.iter().cloned());
    let files = match &resolved.plan {
        Plan::View(options) => {
            let drawing = drafter_draw::draw(&model, options);
            let hidden = options.hidden;
            formats
                .iter()
                .map(|format| match format {
                    Format::Svg => drafter_draw::to_svg(&drawing, hidden, style).into_bytes(),
                    Format::Pdf => drafter_draw::to_pdf(&drawing, hidden, style),
                    Format::Dxf => drafter_draw::to_dxf(&drawing, hidden, style),
                })
                .collect()
        }
        Plan::Sheet(options) => {
            let sheet =
                sheet::draw_sheet(&model, options).map_err(|e| Error::Input(format!("{}: {e}", path.display())))?;
            if sheet.open_components > 0 {
                notes.push(format!(
                    "{} bodies the section plane crosses are not closed surfaces: left uncut",
                    sheet.open_components
                ));
            }
            formats
                .iter()
                .map(|format| match format {
                    Format::Svg => sheet::to_svg(&sheet, style).into_bytes(),
                    Format::Pdf => sheet::to_pdf(&sheet, style),
                    Format::Dxf => sheet::to_dxf(&sheet, style),
                })
                .collect()
        }
    };
    Ok(Drawn { files, notes })
}

/// The key of drawing the input whose in-memory bake has the key `bake`, as `canonical` says, in
/// `format`.
pub fn draw_key(bake: &Key, canonical: &serde_json::Value, format: Format) -> Key {
    let mut h = blake3::Hasher::new();
    h.update(b"drafter-draw-key\0");
    h.update(&bake.0);
    let text = format!("{DRAW_FORM}\0{}\0{canonical}", format.extension());
    h.update(&(text.len() as u64).to_le_bytes());
    h.update(text.as_bytes());
    Key(*h.finalize().as_bytes())
}

/// Whether `a` and `b` name the same existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    a.canonicalize().ok().zip(b.canonicalize().ok()).is_some_and(|(a, b)| a == b)
}

/// Draws `input` into each of `outputs` (a format and its path), through `cache` when given: when
/// every format has an intact entry, the stored bytes are written without loading the model or
/// waiting for admission; otherwise `admit` is asked for the estimated peak (a file without baked
/// lines is baked in memory first), and `None` from it skips the file. All outputs are staged
/// before any is renamed into place, and an output that is the input itself is refused. The record
/// says what happened; nothing is partial.
pub fn draw_file<'b>(
    input: &Path,
    outputs: &[(Format, PathBuf)],
    resolved: &Resolved,
    limits: &drafter_io::Limits,
    cache: Option<&Cache>,
    admit: &dyn Fn(u64) -> Option<Permit<'b>>,
) -> Record {
    let started = Instant::now();
    let first = outputs.first().map(|(_, p)| p.clone()).unwrap_or_default();
    let mut record = Record::new(input, &first);
    if outputs.len() > 1 {
        record.outputs = outputs.iter().map(|(_, p)| p.display().to_string()).collect();
    }
    if let Err(e) = draw_file_inner(input, outputs, resolved, limits, cache, admit, &mut record) {
        record.fail(&e);
    }
    record.ms = started.elapsed().as_secs_f64() * 1e3;
    record
}

fn draw_file_inner<'b>(
    input: &Path,
    outputs: &[(Format, PathBuf)],
    resolved: &Resolved,
    limits: &drafter_io::Limits,
    cache: Option<&Cache>,
    admit: &dyn Fn(u64) -> Option<Permit<'b>>,
    record: &mut Record,
) -> Result<(), Error> {
    if outputs.is_empty() {
        return Err(Error::Input(format!("{}: no output format", input.display())));
    }
    if let Some((_, output)) = outputs.iter().find(|(_, o)| same_file(o, input)) {
        return Err(Error::Input(format!("{}: is the input; not replaced", output.display())));
    }
    record.bytes_in = crate::batch::input_size(input);
    let paths: Vec<&Path> = outputs.iter().map(|(_, p)| p.as_path()).collect();
    // With a cache, the keys first, from the input's hash alone.
    let keys: Option<(&Cache, Vec<Key>)> = match cache {
        Some(c) => {
            record.cache = CacheUse::Uncacheable;
            let bake = crate::cache::key_of_file(input, &drafter_bake::BakeConfig::default())
                .map_err(|source| drafter_io::ImportError::Io { path: input.to_path_buf(), source })?;
            bake.map(|bake| (c, outputs.iter().map(|(f, _)| draw_key(&bake, &resolved.canonical, *f)).collect()))
        }
        None => None,
    };
    if let Some((cache, keys)) = &keys {
        if paths.iter().zip(keys).all(|(path, key)| cache.receipt_matches(&[path], key)) {
            for key in keys {
                cache.touch(key);
            }
            record.bytes_out = paths.iter().map(|p| std::fs::metadata(p).map_or(0, |m| m.len())).sum();
            record.status = Status::Cached;
            record.cache = CacheUse::Hit;
            record.up_to_date = true;
            return Ok(());
        }
        let mut stored = Vec::with_capacity(keys.len());
        record.cache = CacheUse::Hit;
        for key in keys {
            match cache.get(key) {
                Ok(payloads) => stored.push(payloads),
                Err(Miss::Absent) => {
                    if record.cache == CacheUse::Hit {
                        record.cache = CacheUse::Miss;
                    }
                }
                Err(Miss::Corrupt(_)) => record.cache = CacheUse::Rebuilt,
            }
        }
        if record.cache == CacheUse::Hit {
            let files: Vec<&[u8]> = stored.iter().map(|p| p[0].as_slice()).collect();
            write_all(&paths, &files)?;
            for (path, key) in paths.iter().zip(keys) {
                cache.write_receipt(&[path], key);
            }
            record.bytes_out = files.iter().map(|f| f.len() as u64).sum();
            record.status = Status::Cached;
            let notes: Vec<String> = stored[0].get(1).and_then(|n| serde_json::from_slice(n).ok()).unwrap_or_default();
            let path = input.display().to_string();
            record.notes = notes.iter().map(|n| n.replace(INPUT_PLACEHOLDER, &path)).collect();
            return Ok(());
        }
        if record.cache == CacheUse::Miss
            && let Ok(reason) = cache.get(&crate::cache::failure_key(&keys[0], limits))
        {
            record.cache = CacheUse::Hit;
            let reason = reason.first().map(|r| String::from_utf8_lossy(r).into_owned()).unwrap_or_default();
            return Err(Error::Input(reason.replace(INPUT_PLACEHOLDER, &input.display().to_string())));
        }
    }
    let bytes = crate::job::read_input(input)?;
    // A file without baked lines is baked first: the bake's peak is the one to admit.
    let estimate = crate::estimate::peak_bytes(input, &bytes);
    let Some(permit) = admit(estimate) else {
        record.status = Status::Skipped;
        return Ok(());
    };
    record.estimated_peak_bytes = estimate;
    record.over_budget = permit.over_budget();
    let formats: Vec<Format> = outputs.iter().map(|(f, _)| *f).collect();
    let drawn = match draw_bytes(input, bytes, resolved, &formats, limits) {
        Ok(drawn) => drawn,
        Err(e) => {
            // As a bake's refusal: stored with the input's path as a placeholder, so that a rerun
            // (on any machine sharing the cache) replays it without reading the model again.
            if let Some((cache, keys)) = &keys
                && e.is_content_fault()
            {
                let reason = e.to_string().replace(&input.display().to_string(), INPUT_PLACEHOLDER);
                let failure = crate::cache::failure_key(&keys[0], limits);
                let _ = cache.put(&failure, &[reason.as_bytes()], &crate::batch::guard);
            }
            return Err(e);
        }
    };
    drop(permit);
    let files: Vec<&[u8]> = drawn.files.iter().map(Vec::as_slice).collect();
    write_all(&paths, &files)?;
    record.bytes_out = files.iter().map(|f| f.len() as u64).sum();
    record.status = Status::Drawn;
    record.notes = drawn.notes;
    if let Some((cache, keys)) = &keys {
        // The input's path as a placeholder, as in a stored refusal: each machine's own path.
        let path = input.display().to_string();
        let notes: Vec<String> = record.notes.iter().map(|n| n.replace(&path, INPUT_PLACEHOLDER)).collect();
        let notes = serde_json::to_vec(&notes).unwrap_or_default();
        for ((path, key), file) in paths.iter().zip(keys).zip(&files) {
            if let Err(e) = cache.put(key, &[file, &notes], &crate::batch::guard) {
                record.warning = Some(format!("{}: cannot store in the cache: {e}", cache.root().display()));
            }
            cache.write_receipt(&[path], key);
        }
    }
    Ok(())
}

/// Stands for the input's path in a refusal stored in the cache (a character no path holds).
const INPUT_PLACEHOLDER: &str = "\u{0}input\u{0}";

/// Writes every file staged first, then renamed into place: a failure leaves all of them as they
/// were. Each file is staged (written and synced) on a thread of its own: a sync waits on the disk,
/// not the processor, and a catalog written from the cache is bound by its syncs.
fn write_all(paths: &[&Path], files: &[&[u8]]) -> Result<(), Error> {
    let staged: Vec<Result<crate::output::Staged, Error>> = std::thread::scope(|scope| {
        let writes: Vec<_> = paths
            .iter()
            .zip(files)
            .map(|(path, bytes)| scope.spawn(move || crate::output::Staged::new(path, bytes)))
            .collect();
        writes.into_iter().map(|w| w.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))).collect()
    });
    crate::output::commit(staged.into_iter().collect::<Result<Vec<_>, _>>()?)
}

/// Options of a catalog of drawings.
#[derive(Debug)]
pub struct Options {
    pub spec: DrawSpec,
    /// The formats each input is written in, each as `OUT/<relative path>.<format>`.
    pub formats: Vec<Format>,
    pub limits: drafter_io::Limits,
    pub cache: Option<Cache>,
    pub scheduling: Scheduling,
}

/// Where `item`'s drawing in `format` goes, relative to the output folder: its mirrored path with
/// the format's extension.
pub fn relative_output(item: &Item, format: Format) -> PathBuf {
    item.relative_output.with_extension(format.extension())
}

/// Draws what [`crate::discover::discover_all`] found into `out_dir`, `scheduling.workers` files
/// at a time under the memory budget, one record per input (each folder that could not be listed
/// one more failed record). Every output is named below `out_dir` through
/// [`crate::output::confined`].
pub fn run(
    found: &Discovered,
    out_dir: &Path,
    options: &Options,
    stop: &(dyn Fn() -> bool + Sync),
    observer: &dyn Observer,
) -> Summary {
    let draw: &crate::batch::Job<'_> = &|item, admit| {
        let mut outputs = Vec::with_capacity(options.formats.len());
        for &format in &options.formats {
            let relative = relative_output(item, format);
            match crate::output::confined(out_dir, &relative) {
                Ok(path) => outputs.push((format, path)),
                Err(e) => {
                    let mut record = Record::new(&item.input, &out_dir.join(&relative));
                    record.fail(&e);
                    return record;
                }
            }
        }
        match options.spec.resolve(&item.input) {
            Ok(resolved) => draw_file(&item.input, &outputs, &resolved, &options.limits, options.cache.as_ref(), admit),
            Err(e) => {
                let mut record = Record::new(&item.input, &outputs[0].1);
                record.fail(&e);
                record
            }
        }
    };
    let mut summary = crate::batch::run_jobs(&found.items, out_dir, &options.scheduling, stop, observer, draw);
    crate::batch::add_unreadable(&mut summary, found, out_dir);
    summary.drawn = Some(summary.files.iter().filter(|r| r.status == Status::Drawn).count());
    summary.config = serde_json::json!({
        "draw": serde_json::to_value(&options.spec).unwrap_or(serde_json::Value::Null),
        "formats": options.formats,
        "form": DRAW_FORM,
    });
    summary
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_canonical_form_follows_every_option_a_drawing_reads_and_no_other() {
        let input = Path::new("gear.glb");
        let base = DrawSpec::default().resolve(input).unwrap().canonical;
        let changed = |f: &dyn Fn(&mut DrawSpec)| {
            let mut spec = DrawSpec::default();
            f(&mut spec);
            spec.resolve(input).unwrap().canonical
        };
        for edit in [
            &(|s: &mut DrawSpec| s.hidden = Hidden::Dashed) as &dyn Fn(&mut DrawSpec),
            &|s| s.smooth = Smooth::None,
            &|s| s.style = Style::Gooch,
            &|s| s.tolerance_px = 0.1,
            &|s| s.size = (801, 600),
            &|s| s.view = (35.0, 26.0),
            &|s| s.orthographic = true,
            &|s| s.fill = Fill::Bands,
            &|s| s.sheet = Some(SheetSpec::default()),
        ] {
            assert_ne!(changed(edit), base);
        }
        let sheet = |f: &dyn Fn(&mut SheetSpec)| {
            changed(&|s: &mut DrawSpec| {
                let mut sheet = SheetSpec::default();
                f(&mut sheet);
                s.sheet = Some(sheet);
            })
        };
        let a3 = sheet(&|_| {});
        for edit in [
            &(|s: &mut SheetSpec| s.size = "A4".into()) as &dyn Fn(&mut SheetSpec),
            &|s| s.views = vec!["front".into()],
            &|s| s.projection = Projection::Third,
            &|s| s.scale = Some("1:2".into()),
            &|s| (s.up, s.front) = ("z".into(), "-y".into()),
            &|s| s.front = "x".into(),
            &|s| s.units = Some(Units::Mm),
            &|s| s.date = Some("2026-12-06".into()),
            &|s| s.title = Some("Gear".into()),
            &|s| s.section = Some("x=0".into()),
            &|s| s.uncut = vec!["shaft*".into()],
        ] {
            assert_ne!(sheet(edit), a3);
        }
        // Spelled differently, read the same: the same form.
        assert_eq!(sheet(&|s| s.views = vec!["front, top".into(), "right,iso".into()]), a3);
        assert_eq!(sheet(&|s| s.size = "a3".into()), a3);
        assert_eq!(sheet(&|s| s.units = Some(Units::M)), a3, "glTF's default unit");
        assert_eq!(sheet(&|s| s.title = Some("gear".into())), a3, "the file's name is the default title");
        // A sheet does not read one view's options.
        let with_view = changed(&|s| {
            s.sheet = Some(SheetSpec::default());
            s.view = (10.0, 10.0);
            s.fill = Fill::Flat;
        });
        assert_eq!(with_view, a3);
        // Floats in shortest round-trip form; keys sorted: the text is reproducible.
        let text = a3.to_string();
        assert_eq!(serde_json::from_str::<serde_json::Value>(&text).unwrap().to_string(), text);
        assert!(text.contains("\"mm_per_unit\":1000.0"), "{text}");
    }

    #[test]
    fn mistakes_are_refused_by_name() {
        let input = Path::new("m.obj");
        let sheet = |f: &dyn Fn(&mut SheetSpec)| {
            let mut sheet = SheetSpec::default();
            f(&mut sheet);
            DrawSpec { sheet: Some(sheet), ..DrawSpec::default() }.resolve(input).unwrap_err().to_string()
        };
        assert!(sheet(&|s| s.size = "A9".into()).contains("A9"));
        assert!(sheet(&|s| s.views = vec!["frnt".into()]).contains("frnt"));
        assert!(sheet(&|s| s.up = "w".into()).contains("w"));
        assert!(sheet(&|s| (s.up, s.front) = ("z".into(), "-z".into())).contains("-z"));
        assert!(sheet(&|s| s.section = Some("w=1".into())).contains("w=1"));
        let view = DrawSpec { view: (0.0, 90.0), ..DrawSpec::default() };
        assert!(view.resolve(input).unwrap_err().to_string().contains("elevation"));
        assert_eq!(Format::parse_list("svg, pdf,svg").unwrap(), [Format::Svg, Format::Pdf]);
        assert!(Format::parse_list("png").unwrap_err().contains("png"));
        let json = r#"{"sheet": {"size": "A3", "viws": []}}"#;
        assert!(serde_json::from_str::<DrawSpec>(json).unwrap_err().to_string().contains("viws"));
    }
}
