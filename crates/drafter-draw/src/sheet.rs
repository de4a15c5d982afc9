//! Drawing sheets (`drafter draw FILE --sheet A3 --views front,top,right,iso -o sheet.pdf`): the
//! standard views of a model placed on one ISO 216 sheet by first- or third-angle projection, at
//! one scale of the ISO 5455 series, inside an ISO 5457 border with an ISO 7200-like title block.
//!
//! # How it works
//! - **Which way is front.** The front view looks at the model's front, [`SheetOptions::front`]
//!   (default +z: glTF's assets face +z, so the camera sits on +z and looks along −z), with
//!   [`SheetOptions::up`] up (default +y, glTF's up). `right = up × front`. The other views are
//!   the box around the model seen from its faces: top from `up` (the model's front towards the
//!   bottom of the view), right from `right`, and so on; `iso` from `front + right + up`
//!   (azimuth 45°, elevation arctan(1/√2) = 35.264°), orthographic.
//! - **One scale, exact shared axes.** Every view is the orthographic projection
//!   `sheet = origin + s · (right · p, −up · p)` (millimetres, y down) with one `s` for all
//!   views (the scale times the model's millimetres per unit), computed here in f64, not by the
//!   camera's per-view fit. Views in one column (front, top, bottom) have the same `right` and
//!   the same placed left edge, so a point's x is the same in each, bit for bit; views in one row
//!   (front, left, right, rear) likewise share y.
//! - **Placement.** Third angle (ASME Y14.3): top above the front view, right view to its right;
//!   first angle (ISO 128-30's method E, the default here, as in ISO practice): top below, right
//!   view to the left. Rear goes beyond the side view on the right; `iso` in the free corner
//!   above the right-hand column. Each view's box is its model's projected bounding rectangle
//!   (every vertex, exactly); rows and columns take their largest box, views are centred in
//!   their cell, cells [`GAP_MM`] apart.
//! - **Scale.** The largest of the ISO 5455 series (…, 10:1, 5:1, 2:1, 1:1, 1:2, 1:5, 1:10,
//!   1:20, 1:50, 1:100, …, `{1, 2, 5} · 10^k`) at which the views fit inside the border, either
//!   above the title block or beside it, [`MARGIN_MM`] clear of both; or the one given, refused
//!   when it does not fit ([`SheetError::ScaleDoesNotFit`]).
//! - **The sheet.** Landscape, ISO 5457: the border 20 mm from the left edge (filing margin) and
//!   10 mm from the others, 0.7 mm wide, with centring marks; the title block at the lower right,
//!   [`TITLE_BLOCK_MM`], its fields after ISO 7200 (title, scale, projection method with the ISO
//!   128 truncated-cone symbol, sheet size, date) lettered in a stroke font ([`font`]). The date is
//!   left empty unless given, so a sheet's bytes depend only on its input.
//!
//! - **Section** ([`SheetOptions::section`], [`section`]): a view A–A looking down a cutting
//!   plane's normal at what lies below it, the cut faces of closed bodies hatched.
//!
//! Limits: one sheet, no dimensions, no view labels but the section's; the lettering is capitals
//! only.

use std::fmt;
use std::str::FromStr;

use glam::{DMat4, DVec2, DVec3, DVec4};
use rayon::prelude::*;

use drafter_scene::edges::WorldView;
use drafter_scene::model::Model;

use crate::style::MM_PER_PX;
use crate::{DrawOptions, Drawing, Fill, Hidden, Projection, Stroke};

pub mod font;
pub mod section;
pub mod write;

pub use write::{to_dxf, to_pdf, to_svg};

/// Gap between neighbouring views, millimetres.
pub const GAP_MM: f64 = 12.0;

/// Clear space kept between the views and the border or title block, millimetres.
pub const MARGIN_MM: f64 = 6.0;

/// ISO 5457's border: the filing margin on the left, millimetres…
pub const FILING_MARGIN_MM: f64 = 20.0;

/// …and the margin on the other three sides.
pub const EDGE_MARGIN_MM: f64 = 10.0;

/// The border's line width (ISO 5457: at least 0.7 mm), millimetres.
pub const BORDER_WIDTH_MM: f64 = 0.7;

/// The title block's width and height, millimetres (ISO 7200: at most 180 mm wide).
pub const TITLE_BLOCK_MM: (f64, f64) = (180.0, 34.0);

/// A sheet size of ISO 216's A series, drawn landscape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SheetSize {
    A0,
    A1,
    A2,
    A3,
    A4,
}

impl SheetSize {
    pub const ALL: [SheetSize; 5] = [SheetSize::A0, SheetSize::A1, SheetSize::A2, SheetSize::A3, SheetSize::A4];

    pub fn name(self) -> &'static str {
        match self {
            SheetSize::A0 => "A0",
            SheetSize::A1 => "A1",
            SheetSize::A2 => "A2",
            SheetSize::A3 => "A3",
            SheetSize::A4 => "A4",
        }
    }

    /// Width and height in millimetres, landscape (ISO 216).
    pub fn mm(self) -> (f64, f64) {
        match self {
            SheetSize::A0 => (1189.0, 841.0),
            SheetSize::A1 => (841.0, 594.0),
            SheetSize::A2 => (594.0, 420.0),
            SheetSize::A3 => (420.0, 297.0),
            SheetSize::A4 => (297.0, 210.0),
        }
    }
}

impl FromStr for SheetSize {
    type Err = String;
    fn from_str(s: &str) -> Result<SheetSize, String> {
        SheetSize::ALL
            .into_iter()
            .find(|size| size.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| format!("--sheet {s}: not a sheet size (A0, A1, A2, A3 or A4)"))
    }
}

/// One view of a sheet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ViewKind {
    Front,
    Top,
    Right,
    Left,
    Bottom,
    Rear,
    /// Isometric: from front, right and top alike, orthographic.
    Iso,
    /// The section view A–A ([`SheetOptions::section`]): from above the cutting plane, looking down
    /// its normal at what lies below it; not named in `--views`.
    Section,
}

impl ViewKind {
    pub const ALL: [ViewKind; 7] = [
        ViewKind::Front,
        ViewKind::Top,
        ViewKind::Right,
        ViewKind::Left,
        ViewKind::Bottom,
        ViewKind::Rear,
        ViewKind::Iso,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ViewKind::Front => "front",
            ViewKind::Top => "top",
            ViewKind::Right => "right",
            ViewKind::Left => "left",
            ViewKind::Bottom => "bottom",
            ViewKind::Rear => "rear",
            ViewKind::Iso => "iso",
            ViewKind::Section => "section",
        }
    }

    /// The views of a comma-separated list (`front,top,right,iso`), each once.
    pub fn parse_list(list: &str) -> Result<Vec<ViewKind>, String> {
        let mut views = Vec::new();
        for name in list.split(',').map(str::trim) {
            let view = ViewKind::ALL.into_iter().find(|v| v.name().eq_ignore_ascii_case(name)).ok_or_else(|| {
                format!("--views {list}: no view {name:?} (front, top, right, left, bottom, rear, iso)")
            })?;
            if views.contains(&view) {
                return Err(format!("--views {list}: {name} is named twice"));
            }
            views.push(view);
        }
        Ok(views)
    }

    /// The direction towards the viewer, the view's up and right, from the model's `front`, `up`
    /// and `right` (`up × front`).
    fn frame(self, front: DVec3, up: DVec3, right: DVec3) -> ViewFrame {
        let (towards, screen_up) = match self {
            ViewKind::Front => (front, up),
            ViewKind::Rear => (-front, up),
            ViewKind::Right => (right, up),
            ViewKind::Left => (-right, up),
            ViewKind::Top => (up, -front),
            ViewKind::Bottom => (-up, front),
            ViewKind::Iso => {
                let towards = (front + right + up).normalize();
                (towards, (up - towards * towards.dot(up)).normalize())
            }
            // Set from the plane by `section_frame`.
            ViewKind::Section => (front, up),
        };
        ViewFrame { right: screen_up.cross(towards), up: screen_up, towards }
    }

    /// The view's cell in the layout's grid (row down, column right; front at 0, 0), for the
    /// orthographic views.
    fn cell(self, angle: Angle) -> (i32, i32) {
        let flip = if angle == Angle::Third { 1 } else { -1 };
        match self {
            ViewKind::Front => (0, 0),
            ViewKind::Top => (-flip, 0),
            ViewKind::Bottom => (flip, 0),
            ViewKind::Right => (0, flip),
            ViewKind::Left => (0, -flip),
            ViewKind::Rear => (0, 2),
            ViewKind::Iso => (-1, 1),
            ViewKind::Section => (1, 1),
        }
    }
}

/// A view's axes in world space: `right` and `up` on the sheet, `towards` the viewer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewFrame {
    pub right: DVec3,
    pub up: DVec3,
    pub towards: DVec3,
}

/// The projection method: where the views go around the front view.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Angle {
    /// ISO method E: the view from above goes below the front view, the view from the right to
    /// its left (the default, as ISO practice and most of the world outside North America).
    #[default]
    First,
    /// ISO method A, ASME Y14.3: the view from above goes above, the view from the right to the right.
    Third,
}

impl Angle {
    pub fn name(self) -> &'static str {
        match self {
            Angle::First => "first",
            Angle::Third => "third",
        }
    }
}

/// A world axis, either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    X,
    NegX,
    Y,
    NegY,
    Z,
    NegZ,
}

impl Axis {
    pub fn vector(self) -> DVec3 {
        match self {
            Axis::X => DVec3::X,
            Axis::NegX => DVec3::NEG_X,
            Axis::Y => DVec3::Y,
            Axis::NegY => DVec3::NEG_Y,
            Axis::Z => DVec3::Z,
            Axis::NegZ => DVec3::NEG_Z,
        }
    }
}

impl FromStr for Axis {
    type Err = String;
    fn from_str(s: &str) -> Result<Axis, String> {
        Ok(match s.trim().to_ascii_lowercase().as_str() {
            "x" | "+x" => Axis::X,
            "-x" => Axis::NegX,
            "y" | "+y" => Axis::Y,
            "-y" => Axis::NegY,
            "z" | "+z" => Axis::Z,
            "-z" => Axis::NegZ,
            _ => return Err(format!("{s}: not an axis (x, y, z, -x, -y or -z)")),
        })
    }
}

/// A drawing scale, paper : real (`1:2` draws 2 mm of the model as 1 mm).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scale {
    pub paper: u64,
    pub real: u64,
}

impl Scale {
    /// Paper millimetres per real millimetre.
    pub fn ratio(self) -> f64 {
        self.paper as f64 / self.real as f64
    }

    /// The ISO 5455 series, largest first: `{5, 2, 1} · 10^k` from 5,000,000:1 to 1:10,000,000
    /// (ISO 5455 lists 50:1 to 1:10,000 and extends the series by powers of ten).
    pub fn series() -> Vec<Scale> {
        let mut out = Vec::new();
        for k in (0..=6).rev() {
            for m in [5, 2, 1] {
                out.push(Scale { paper: m * 10u64.pow(k), real: 1 });
            }
        }
        out.pop(); // 1:1 comes once, from the reductions
        for k in 0..=7 {
            for m in [1, 2, 5] {
                out.push(Scale { paper: 1, real: m * 10u64.pow(k) });
            }
        }
        out
    }
}

impl fmt::Display for Scale {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.paper, self.real)
    }
}

impl FromStr for Scale {
    type Err = String;
    fn from_str(s: &str) -> Result<Scale, String> {
        let bad = || format!("--scale {s}: not a scale (paper:real, whole numbers, as 1:2 or 5:1)");
        let (a, b) = s.trim().split_once(':').ok_or_else(bad)?;
        let (paper, real) = (a.trim().parse::<u64>().map_err(|_| bad())?, b.trim().parse::<u64>().map_err(|_| bad())?);
        if paper == 0 || real == 0 || paper > 1 << 40 || real > 1 << 40 {
            return Err(bad());
        }
        Ok(Scale { paper, real })
    }
}

/// What a sheet shows and how.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetOptions {
    /// Default [`SheetSize::A3`].
    pub size: SheetSize,
    /// Default front, top, right, iso.
    pub views: Vec<ViewKind>,
    /// Default [`Angle::First`].
    pub angle: Angle,
    /// `None` (the default): the largest of [`Scale::series`] that fits.
    pub scale: Option<Scale>,
    /// The direction the model's front faces, towards the front view's viewer. Default +z (glTF).
    pub front: Axis,
    /// The model's up. Default +y (glTF).
    pub up: Axis,
    /// Millimetres per model unit. Default 1000 (glTF's metres).
    pub mm_per_unit: f64,
    /// The title block's title (the file's name, for the CLI).
    pub title: String,
    /// The title block's date; `None` (the default) leaves the field empty, so the sheet's bytes
    /// depend only on its input.
    pub date: Option<String>,
    /// A section view A–A through this plane (world units), after the other views; `None` (the
    /// default): none.
    pub section: Option<section::Plane>,
    /// Parts the section leaves whole, by name: `*` matches any run of characters, case is
    /// ignored (`shaft*`, `*bolt*`). Default none.
    pub uncut: Vec<String>,
    /// Each view's hidden lines, tolerance and tangent edges; its size, view, projection and fill
    /// are the sheet's own.
    pub draw: DrawOptions,
}

impl Default for SheetOptions {
    fn default() -> Self {
        SheetOptions {
            size: SheetSize::A3,
            views: vec![ViewKind::Front, ViewKind::Top, ViewKind::Right, ViewKind::Iso],
            angle: Angle::First,
            scale: None,
            front: Axis::Z,
            up: Axis::Y,
            mm_per_unit: 1000.0,
            title: String::new(),
            date: None,
            section: None,
            uncut: Vec::new(),
            draw: DrawOptions::default(),
        }
    }
}

/// Why no sheet was drawn (bad input: each names what to change).
#[derive(Clone, Debug, PartialEq)]
pub enum SheetError {
    NoViews,
    /// `--up` and `--front` along one line.
    Axes {
        up: Axis,
        front: Axis,
    },
    /// Millimetres per unit not finite and positive.
    Unit(f64),
    /// The model has no triangles.
    Empty,
    /// The scale asked for does not fit; the largest that does, if any.
    ScaleDoesNotFit {
        scale: Scale,
        size: SheetSize,
        largest: Option<Scale>,
    },
    /// Not even the smallest scale of the series fits (a degenerate model).
    NothingFits {
        size: SheetSize,
    },
}

impl fmt::Display for SheetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SheetError::NoViews => write!(f, "--views: no view to draw"),
            SheetError::Axes { up, front } => {
                write!(f, "--up {up:?} and --front {front:?} must be different axes, not along one line")
            }
            SheetError::Unit(mm) => write!(f, "--units: {mm} mm per unit is not a positive length"),
            SheetError::Empty => write!(f, "the model has no triangles to draw"),
            SheetError::ScaleDoesNotFit { scale, size, largest: Some(largest) } => write!(
                f,
                "--scale {scale}: the views do not fit on {} (the largest standard scale that fits is {largest})",
                size.name()
            ),
            SheetError::ScaleDoesNotFit { scale, size, largest: None } => {
                write!(f, "--scale {scale}: the views do not fit on {}", size.name())
            }
            SheetError::NothingFits { size } => write!(f, "the views fit on {} at no standard scale", size.name()),
        }
    }
}

impl std::error::Error for SheetError {}

/// A rectangle on the sheet, millimetres, y down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub min: DVec2,
    pub max: DVec2,
}

impl Rect {
    pub fn contains(&self, other: &Rect) -> bool {
        self.min.x <= other.min.x && self.min.y <= other.min.y && other.max.x <= self.max.x && other.max.y <= self.max.y
    }

    pub fn overlaps(&self, other: &Rect) -> bool {
        self.min.x < other.max.x && other.min.x < self.max.x && self.min.y < other.max.y && other.min.y < self.max.y
    }

    fn grown(&self, by: f64) -> Rect {
        Rect { min: self.min - DVec2::splat(by), max: self.max + DVec2::splat(by) }
    }
}

/// One view placed on the sheet.
#[derive(Clone, Debug)]
pub struct PlacedView {
    pub kind: ViewKind,
    pub frame: ViewFrame,
    /// The model's projected bounding rectangle (every vertex), where the view's lines lie.
    pub rect: Rect,
    /// Sheet millimetres of the world origin: `sheet = origin + s · (right · p, −up · p)`.
    pub origin: DVec2,
    /// Sheet millimetres per world unit.
    pub mm_per_world: f64,
    /// The view's lines in sheet millimetres (y down); `width` and `height` are the sheet's in
    /// pixels, rounded.
    pub drawing: Drawing,
    /// A section's cut faces: their loops (the first point not repeated), the visible pieces of
    /// their outlines and hatching (what uncut parts in front of the plane leave), sheet
    /// millimetres; empty for the other views.
    pub cut_loops: Vec<Vec<DVec2>>,
    pub cut_outlines: Vec<Vec<DVec2>>,
    pub hatching: Vec<[DVec2; 2]>,
    /// The view's projection onto the sheet's pixels and, for a section, what it cuts away: what
    /// [`crate::visibility_clipped`] takes to redo the view's visibility.
    pub projection: Projection,
    pub clip: Option<section::Clip>,
}

impl PlacedView {
    /// Where a world point lands on the sheet, millimetres.
    pub fn to_sheet(&self, world: DVec3) -> DVec2 {
        self.origin + self.mm_per_world * DVec2::new(self.frame.right.dot(world), -self.frame.up.dot(world))
    }
}

/// A line of the sheet's frame (border, title block, lettering, projection symbol).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameLine {
    /// Millimetres.
    pub width: f64,
    /// Dash pattern in millimetres (on, off, …); empty for a continuous line.
    pub dashes: Vec<f64>,
    pub points: Vec<DVec2>,
}

/// A drawn sheet.
#[derive(Clone, Debug)]
pub struct Sheet {
    pub size: SheetSize,
    /// Width and height, millimetres.
    pub mm: (f64, f64),
    pub scale: Scale,
    pub angle: Angle,
    pub hidden: Hidden,
    pub title: String,
    pub date: Option<String>,
    pub views: Vec<PlacedView>,
    /// The border's inner edge.
    pub border: Rect,
    pub title_block: Rect,
    pub frame: Vec<FrameLine>,
    /// With a section: the bodies the plane crosses that are not closed, left uncut.
    pub open_components: usize,
}

/// The layout of the views at scale 1 (world units), before a scale is chosen.
struct Layout {
    /// Per view: its frame, its projected extents `(min, max)` along right and up and towards.
    views: Vec<(ViewKind, ViewFrame, DVec3, DVec3)>,
    /// Per view: row and column index into `rows` and `cols`.
    cells: Vec<(usize, usize)>,
    /// Largest height per row and width per column, world units.
    rows: Vec<f64>,
    cols: Vec<f64>,
}

impl Layout {
    fn new(
        kinds: &[ViewKind],
        angle: Angle,
        front: DVec3,
        up: DVec3,
        points: &[DVec3],
        section: Option<&section::Plane>,
    ) -> Layout {
        let right = up.cross(front);
        let frames: Vec<ViewFrame> = kinds
            .iter()
            .map(|k| match (k, section) {
                (ViewKind::Section, Some(plane)) => section_frame(plane, front, up),
                _ => k.frame(front, up, right),
            })
            .collect();
        let extents: Vec<(DVec3, DVec3)> = kinds
            .par_iter()
            .zip(&frames)
            .map(|(kind, f)| {
                let project = |(lo, hi): (DVec3, DVec3), p: &DVec3| {
                    let q = DVec3::new(f.right.dot(*p), f.up.dot(*p), f.towards.dot(*p));
                    (lo.min(q), hi.max(q))
                };
                let empty = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                match (kind, section) {
                    // What the plane leaves: every triangle cut to its part below the plane.
                    (ViewKind::Section, Some(plane)) => points
                        .chunks_exact(3)
                        .flat_map(|t| section::below(plane, &[t[0], t[1], t[2]]))
                        .fold(empty, |e, p| project(e, &p)),
                    _ => points.iter().fold(empty, project),
                }
            })
            .collect();
        // Grid cells: the orthographic views by the convention, iso above the right-hand column.
        let mut cells: Vec<(i32, i32)> = kinds.iter().map(|k| k.cell(angle)).collect();
        let right_column = kinds
            .iter()
            .zip(&cells)
            .filter(|(k, _)| !matches!(k, ViewKind::Iso | ViewKind::Section))
            .map(|(_, c)| c.1)
            .max()
            .unwrap_or(0)
            .max(1);
        for (k, c) in kinds.iter().zip(cells.iter_mut()) {
            match k {
                ViewKind::Iso => *c = (-1, right_column),
                // The section below the right-hand column.
                ViewKind::Section => *c = (1, right_column),
                _ => {}
            }
        }
        let mut row_ids: Vec<i32> = cells.iter().map(|c| c.0).collect();
        let mut col_ids: Vec<i32> = cells.iter().map(|c| c.1).collect();
        row_ids.sort_unstable();
        row_ids.dedup();
        col_ids.sort_unstable();
        col_ids.dedup();
        let index = |ids: &[i32], id: i32| ids.iter().position(|&i| i == id).unwrap_or(0);
        let cells: Vec<(usize, usize)> = cells.iter().map(|c| (index(&row_ids, c.0), index(&col_ids, c.1))).collect();
        let (mut rows, mut cols) = (vec![0.0f64; row_ids.len()], vec![0.0f64; col_ids.len()]);
        for (&(r, c), (lo, hi)) in cells.iter().zip(&extents) {
            let size = *hi - *lo;
            rows[r] = rows[r].max(size.y);
            cols[c] = cols[c].max(size.x);
        }
        let views = kinds.iter().zip(frames).zip(extents).map(|((k, f), (lo, hi))| (*k, f, lo, hi)).collect();
        Layout { views, cells, rows, cols }
    }

    /// The grid's size on the sheet at `s` millimetres per world unit.
    fn size(&self, s: f64) -> DVec2 {
        let gaps = |n: usize| GAP_MM * n.saturating_sub(1) as f64;
        DVec2::new(
            s * self.cols.iter().sum::<f64>() + gaps(self.cols.len()),
            s * self.rows.iter().sum::<f64>() + gaps(self.rows.len()),
        )
    }

    /// Each view's rectangle with the grid's top left corner at `corner`.
    fn rects(&self, s: f64, corner: DVec2) -> Vec<Rect> {
        let starts = |sizes: &[f64], from: f64| {
            let mut out = Vec::with_capacity(sizes.len());
            let mut at = from;
            for size in sizes {
                out.push(at);
                at += s * size + GAP_MM;
            }
            out
        };
        let (xs, ys) = (starts(&self.cols, corner.x), starts(&self.rows, corner.y));
        self.views
            .iter()
            .zip(&self.cells)
            .map(|((_, _, lo, hi), &(r, c))| {
                let size = DVec2::new(hi.x - lo.x, hi.y - lo.y) * s;
                let min =
                    DVec2::new(xs[c] + 0.5 * (s * self.cols[c] - size.x), ys[r] + 0.5 * (s * self.rows[r] - size.y));
                Rect { min, max: min + size }
            })
            .collect()
    }

    /// The views' rectangles at `s`, placed inside `border` clear of `title_block`, or `None`
    /// where they do not fit: centred above the title block if they fit there, else centred in
    /// the border if that keeps them clear of it.
    fn place(&self, s: f64, border: &Rect, title_block: &Rect) -> Option<Vec<Rect>> {
        let size = self.size(s);
        let inside = border.grown(-MARGIN_MM);
        let above = Rect { min: inside.min, max: DVec2::new(inside.max.x, title_block.min.y - MARGIN_MM) };
        for area in [above, inside] {
            let room = area.max - area.min;
            if size.x > room.x || size.y > room.y {
                continue;
            }
            let rects = self.rects(s, area.min + 0.5 * (room - size));
            let keep_out = title_block.grown(MARGIN_MM);
            if rects.iter().all(|r| inside.contains(r) && !r.overlaps(&keep_out)) {
                return Some(rects);
            }
        }
        None
    }
}

/// Draws the sheet `options` describe of `model`.
pub fn draw_sheet(model: &Model, options: &SheetOptions) -> Result<Sheet, SheetError> {
    if options.views.is_empty() {
        return Err(SheetError::NoViews);
    }
    let (front, up) = (options.front.vector(), options.up.vector());
    if front.cross(up) == DVec3::ZERO {
        return Err(SheetError::Axes { up: options.up, front: options.front });
    }
    if !(options.mm_per_unit.is_finite() && options.mm_per_unit > 0.0) {
        return Err(SheetError::Unit(options.mm_per_unit));
    }
    let points: Vec<DVec3> = crate::world_triangles(model).corners.into_iter().flatten().collect();
    if points.is_empty() {
        return Err(SheetError::Empty);
    }
    let (w, h) = options.size.mm();
    let border = Rect {
        min: DVec2::new(FILING_MARGIN_MM, EDGE_MARGIN_MM),
        max: DVec2::new(w - EDGE_MARGIN_MM, h - EDGE_MARGIN_MM),
    };
    let title_block = Rect { min: border.max - DVec2::new(TITLE_BLOCK_MM.0, TITLE_BLOCK_MM.1), max: border.max };
    let mut kinds = options.views.clone();
    kinds.retain(|k| *k != ViewKind::Section);
    if options.section.is_some() {
        kinds.push(ViewKind::Section);
    }
    // Parts drawn whole in the section view, by name.
    let mut uncut: Vec<u32> = model
        .parts
        .iter()
        .filter(|p| options.uncut.iter().any(|pattern| matches_pattern(pattern, &p.name)))
        .map(|p| p.id)
        .collect();
    uncut.sort_unstable();
    uncut.dedup();
    let cut = options.section.as_ref().map(|plane| {
        let mut cut = section::cut(model, plane);
        cut.faces.retain(|f| f.part.is_none_or(|p| uncut.binary_search(&p).is_err()));
        cut
    });
    let layout = Layout::new(&kinds, options.angle, front, up, &points, options.section.as_ref());
    let fit = |scale: Scale| layout.place(scale.ratio() * options.mm_per_unit, &border, &title_block);
    let (scale, rects) = match options.scale {
        Some(scale) => match fit(scale) {
            Some(rects) => (scale, rects),
            None => {
                let largest = Scale::series().into_iter().find(|&s| fit(s).is_some());
                return Err(SheetError::ScaleDoesNotFit { scale, size: options.size, largest });
            }
        },
        None => Scale::series()
            .into_iter()
            .find_map(|s| fit(s).map(|rects| (s, rects)))
            .ok_or(SheetError::NothingFits { size: options.size })?,
    };
    let s = scale.ratio() * options.mm_per_unit;
    let sheet_px = DVec2::new(w, h) / MM_PER_PX;
    let view_options = DrawOptions {
        size: (sheet_px.x.round() as u32, sheet_px.y.round() as u32),
        orthographic: true,
        fill: Fill::None,
        ..options.draw
    };
    let faces = crate::ModelFaces::of(model);
    let views: Vec<PlacedView> = layout
        .views
        .par_iter()
        .zip(&rects)
        .map(|(&(kind, frame, lo, hi), rect)| {
            // sheet = origin + s · (right · p, −up · p): the rectangle's left edge is the lowest
            // `right`, its top edge the highest `up`.
            let origin = DVec2::new(rect.min.x - s * lo.x, rect.min.y + s * hi.y);
            let projection = view_projection(model, frame, origin, s, (lo.z, hi.z), (w, h));
            let to_sheet = |p: DVec3| origin + s * DVec2::new(frame.right.dot(p), -frame.up.dot(p));
            let (mut cut_outlines, mut hatching, mut cut_loops, mut clip) = (Vec::new(), Vec::new(), Vec::new(), None);
            if let (ViewKind::Section, Some(plane), Some(cut)) = (kind, &options.section, &cut) {
                let plane_closeness =
                    projection.screen_and_closeness(plane.normal * plane.offset).map_or(0.0, |(_, c)| c);
                // The uncut parts in front of the plane hide the cut faces' lines behind them.
                let front = uncut_in_front(model, plane, &uncut, &projection);
                let visible = |a: DVec2, b: DVec2| visible_pieces(front.as_ref(), plane_closeness, a, b);
                let mut loops_px = Vec::new();
                for (k, face) in cut.faces.iter().enumerate() {
                    let loops: Vec<Vec<DVec2>> =
                        face.loops.iter().map(|l| l.iter().map(|p| to_sheet(*p)).collect()).collect();
                    // ISO 128-50: 45° thin lines; neighbouring parts told apart by direction and spacing.
                    let part = face.part.map_or(k, |p| p as usize);
                    let angle = if part % 2 == 0 { 45.0 } else { 135.0 };
                    let spacing = [2.0, 3.0, 2.5][(part / 2) % 3];
                    for [a, b] in section::hatch(&loops, angle, spacing) {
                        hatching.extend(visible(a, b));
                    }
                    for ring in &loops {
                        loops_px.push(ring.iter().map(|p| *p / MM_PER_PX).collect());
                        for (i, a) in ring.iter().enumerate() {
                            cut_outlines
                                .extend(visible(*a, ring[(i + 1) % ring.len()]).into_iter().map(|[a, b]| vec![a, b]));
                        }
                    }
                    cut_loops.extend(loops);
                }
                clip = Some(section::Clip { plane: *plane, cut: loops_px, uncut: uncut.clone(), plane_closeness });
            }
            let mut drawing = crate::draw_with_faces(model, &faces, &view_options, projection, clip.as_ref());
            for stroke in &mut drawing.strokes {
                for p in &mut stroke.points {
                    *p *= MM_PER_PX;
                }
            }
            PlacedView {
                kind,
                cut_loops,
                frame,
                rect: *rect,
                origin,
                mm_per_world: s,
                drawing,
                cut_outlines,
                hatching,
                projection,
                clip,
            }
        })
        .collect();
    let mut sheet = Sheet {
        size: options.size,
        mm: (w, h),
        scale,
        angle: options.angle,
        hidden: options.draw.hidden,
        title: options.title.clone(),
        date: options.date.clone(),
        views,
        border,
        title_block,
        frame: Vec::new(),
        open_components: cut.map_or(0, |c| c.open_components),
    };
    sheet.frame = frame_lines(&sheet);
    Ok(sheet)
}

/// Whether `name` matches `pattern`: `*` any run of characters, case ignored.
fn matches_pattern(pattern: &str, name: &str) -> bool {
    let (pattern, name) = (pattern.to_lowercase(), name.to_lowercase());
    let pieces: Vec<&str> = pattern.split('*').collect();
    if pieces.len() == 1 {
        return pattern == name;
    }
    let (first, last) = (pieces[0], pieces[pieces.len() - 1]);
    if name.len() < first.len() + last.len() || !name.starts_with(first) || !name.ends_with(last) {
        return false;
    }
    let mut rest = &name[first.len()..name.len() - last.len()];
    for piece in &pieces[1..pieces.len() - 1] {
        match rest.find(piece) {
            Some(at) => rest = &rest[at + piece.len()..],
            None => return false,
        }
    }
    true
}

/// The occluders the uncut parts put in front of a section's plane (their triangles' parts above
/// it), or `None` when there are none.
fn uncut_in_front(
    model: &Model,
    plane: &section::Plane,
    uncut: &[u32],
    projection: &Projection,
) -> Option<crate::Occluders> {
    if uncut.is_empty() {
        return None;
    }
    let above = section::Plane { normal: -plane.normal, offset: -plane.offset };
    let all = crate::world_triangles(model);
    let mut corners = Vec::new();
    for (t, part) in all.corners.iter().zip(&all.parts) {
        if part.is_some_and(|p| uncut.binary_search(&p).is_ok()) {
            let polygon = section::below(&above, t);
            for i in 1..polygon.len().saturating_sub(1) {
                corners.push([polygon[0], polygon[i], polygon[i + 1]]);
            }
        }
    }
    let (parts, outward) = (vec![None; corners.len()], vec![0; corners.len()]);
    Some(crate::Occluders::new(&crate::Triangles { corners, parts, outward }, projection))
}

/// The pieces of the sheet segment `a → b` (millimetres, on the section's plane, of closeness `c`)
/// that `occluders` leave visible.
fn visible_pieces(occluders: Option<&crate::Occluders>, c: f64, a: DVec2, b: DVec2) -> Vec<[DVec2; 2]> {
    let hidden = occluders.map_or_else(Vec::new, |o| {
        let at = |p: DVec2| crate::Projected { x: p.x / MM_PER_PX, y: p.y / MM_PER_PX, c };
        o.hidden(at(a), at(b), &mut 0)
    });
    let mut pieces = Vec::new();
    let mut from = 0.0;
    for (lo, hi) in hidden.into_iter().chain([(1.0, 1.0)]) {
        if lo > from {
            pieces.push([a + (b - a) * from, a + (b - a) * lo]);
        }
        from = f64::max(from, hi);
    }
    pieces
}

/// The section view's axes: looking down the plane's normal from above it, the model's up (or,
/// across a horizontal plane, its back) up on the sheet.
fn section_frame(plane: &section::Plane, front: DVec3, up: DVec3) -> ViewFrame {
    let towards = plane.normal;
    let upright = up - towards * towards.dot(up);
    let screen_up = if upright.length() > 1e-6 {
        upright.normalize()
    } else {
        (-front - towards * towards.dot(-front)).normalize()
    };
    ViewFrame { right: screen_up.cross(towards), up: screen_up, towards }
}

/// The projection of one view onto the whole sheet in its pixels ([`MM_PER_PX`] mm each):
/// `sheet = origin + s · (right · p, −up · p)` millimetres, closeness rising towards the viewer
/// from −1 at the model's farthest point to −0.5 at its nearest (kept away from 0, as the
/// camera's orthographic depth is, so the relative closeness margin stays meaningful).
fn view_projection(
    model: &Model,
    frame: ViewFrame,
    origin: DVec2,
    s: f64,
    (near_lo, near_hi): (f64, f64),
    (w, h): (f64, f64),
) -> Projection {
    let depth = (near_hi - near_lo).max(1e-12);
    // Render space is world − model.origin: fold the origin into each row's constant.
    let o = model.origin;
    let row_x = (frame.right * (2.0 * s / w)).extend((2.0 / w) * (origin.x + s * frame.right.dot(o)) - 1.0);
    let row_y = (frame.up * (2.0 * s / h)).extend(1.0 - (2.0 / h) * (origin.y - s * frame.up.dot(o)));
    let row_z = (frame.towards * (-0.5 / depth)).extend(1.0 - 0.5 * (frame.towards.dot(o) - near_lo) / depth);
    let clip_from_render = DMat4::from_cols(row_x, row_y, row_z, DVec4::W).transpose();
    Projection {
        clip_from_render,
        view: WorldView::Orthographic { direction: frame.towards },
        origin: o,
        orthographic: true,
        width: w / MM_PER_PX,
        height: h / MM_PER_PX,
    }
}

/// A continuous frame line.
fn line(width: f64, points: Vec<DVec2>) -> FrameLine {
    FrameLine { width, dashes: Vec::new(), points }
}

/// A closed rectangle as a polyline.
fn rectangle(r: &Rect) -> Vec<DVec2> {
    vec![r.min, DVec2::new(r.max.x, r.min.y), r.max, DVec2::new(r.min.x, r.max.y), r.min]
}

/// Lettering `height` high (ISO 3098: the stroke a tenth of it) with its baseline from `at`.
fn text(out: &mut Vec<FrameLine>, text: &str, at: DVec2, height: f64) {
    out.extend(font::letter(text, at, height).into_iter().map(|points| line(height / 10.0, points)));
}

/// The border, centring marks, title block and its fields.
fn frame_lines(sheet: &Sheet) -> Vec<FrameLine> {
    let (w, h) = sheet.mm;
    let b = &sheet.border;
    let mut out = vec![line(BORDER_WIDTH_MM, rectangle(b))];
    // The section view's name above it (ISO 128-40 letters it A–A), and its cutting plane where
    // another view sees it edge-on.
    for view in sheet.views.iter().filter(|v| v.kind == ViewKind::Section) {
        text(&mut out, "SECTION A-A", DVec2::new(view.rect.min.x, view.rect.min.y - 2.0), 3.5);
    }
    out.extend(cutting_plane_marks(sheet));
    // ISO 5457 centring marks: from the border 5 mm outwards, at the middle of each side.
    for (from, to) in [
        (DVec2::new(w / 2.0, b.min.y), DVec2::new(w / 2.0, b.min.y - 5.0)),
        (DVec2::new(w / 2.0, b.max.y), DVec2::new(w / 2.0, b.max.y + 5.0)),
        (DVec2::new(b.min.x, h / 2.0), DVec2::new(b.min.x - 5.0, h / 2.0)),
        (DVec2::new(b.max.x, h / 2.0), DVec2::new(b.max.x + 5.0, h / 2.0)),
    ] {
        out.push(line(BORDER_WIDTH_MM, vec![from, to]));
    }
    // The title block: its outline as wide as the border; a title row over four fields.
    let t = &sheet.title_block;
    out.push(line(BORDER_WIDTH_MM, rectangle(t)));
    let split = t.min.y + 16.0;
    out.push(line(0.35, vec![DVec2::new(t.min.x, split), DVec2::new(t.max.x, split)]));
    let widths = [40.0, 55.0, 30.0, 55.0];
    let mut x = t.min.x;
    let label_at = |x: f64, y: f64| DVec2::new(x + 1.5, y + 1.5 + 2.5);
    let (label, value) = (2.5, 5.0);
    let room = t.max.x - t.min.x - 3.0;
    let title = if sheet.title.is_empty() { "-".to_string() } else { sheet.title.clone() };
    let title_height = (room / font::width(&title, 1.0)).min(7.0);
    text(&mut out, "TITLE", label_at(t.min.x, t.min.y), label);
    text(&mut out, &title, DVec2::new(t.min.x + 1.5, split - 2.5), title_height);
    let date = sheet.date.clone().unwrap_or_default();
    let fields: [(&str, String); 4] = [
        ("SCALE", sheet.scale.to_string()),
        ("PROJECTION", String::new()),
        ("SIZE", sheet.size.name().to_string()),
        ("DATE", date),
    ];
    for (k, (name, content)) in fields.iter().enumerate() {
        if k > 0 {
            out.push(line(0.35, vec![DVec2::new(x, split), DVec2::new(x, t.max.y)]));
        }
        text(&mut out, name, label_at(x, split), label);
        let fits = ((widths[k] - 3.0) / font::width(content, 1.0)).min(value);
        text(&mut out, content, DVec2::new(x + 1.5, t.max.y - 3.0), fits);
        if *name == "PROJECTION" {
            let symbol_left = DVec2::new(x + 2.0, t.max.y - 3.0 - 3.5);
            out.extend(projection_symbol(sheet.angle, symbol_left, 3.5));
            let words = match sheet.angle {
                Angle::First => "FIRST ANGLE",
                Angle::Third => "THIRD ANGLE",
            };
            text(&mut out, words, DVec2::new(x + 2.0 + 22.0, t.max.y - 3.0 - 3.5 + 1.25), label);
        }
        x += widths[k];
    }
    out
}

/// The cutting plane of the section view, in every orthographic view that sees it edge-on (ISO
/// 128-44): a narrow chain line across the view, 2 mm past its box, wide for 5 mm at each end,
/// with an arrow at each end pointing the way the section looks (down the plane's normal, its tip
/// on the line) and the letter A at the arrow's tail.
fn cutting_plane_marks(sheet: &Sheet) -> Vec<FrameLine> {
    let mut out = Vec::new();
    let Some(plane) = sheet.views.iter().find_map(|v| v.clip.as_ref().map(|c| c.plane)) else { return out };
    for view in sheet.views.iter().filter(|v| !matches!(v.kind, ViewKind::Iso | ViewKind::Section)) {
        let f = &view.frame;
        if plane.normal.dot(f.towards).abs() > 1e-9 {
            continue;
        }
        // The trace a x + b y = d in the view's axes, then on the sheet (y down).
        let (a, b) = (plane.normal.dot(f.right), plane.normal.dot(f.up));
        let foot = DVec2::new(a, b) * (plane.offset / (a * a + b * b));
        let start = view.origin + view.mm_per_world * DVec2::new(foot.x, -foot.y);
        let along = DVec2::new(-b, -a).normalize();
        let looking = DVec2::new(-a, b).normalize();
        // Clip the line to the view's box grown by 2 mm (slabs).
        let r = view.rect.grown(2.0);
        let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
        for (p, d, lo, hi) in [(start.x, along.x, r.min.x, r.max.x), (start.y, along.y, r.min.y, r.max.y)] {
            if d.abs() < 1e-12 {
                if p < lo || p > hi {
                    t0 = f64::INFINITY;
                }
                continue;
            }
            let (u, v) = ((lo - p) / d, (hi - p) / d);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
        if t0 >= t1 {
            continue;
        }
        let (e0, e1) = (start + along * t0, start + along * t1);
        out.push(FrameLine { width: 0.25, dashes: vec![6.0, 1.0, 0.5, 1.0], points: vec![e0, e1] });
        for (end, inward) in [(e0, along), (e1, -along)] {
            out.push(line(BORDER_WIDTH_MM, vec![end, end + inward * 5.0]));
            let tail = end - looking * 8.0;
            let side = looking.perp() * 0.9;
            out.push(line(0.35, vec![tail, end]));
            out.push(line(0.35, vec![end - looking * 2.5 + side, end, end - looking * 2.5 - side]));
            let letter = tail - looking * 2.5;
            text(&mut out, "A", letter + DVec2::new(-1.05, 1.75), 3.5);
        }
    }
    out
}

/// The ISO 128-30 (ISO 5456-2) projection symbol: a truncated cone, axis level, small end on the
/// left, drawn as its front view (a trapezoid) beside its view from the left (two circles); the
/// circles to the right of the trapezoid for the first-angle method, to its left for third
/// angle. `h` is the lettering height it goes with: the large diameter 2h, the small h, the cone
/// 2h long, the views h apart; outlines h/10 wide, centre lines narrow chain lines. `left` is
/// the middle of the symbol's left side.
fn projection_symbol(angle: Angle, left: DVec2, h: f64) -> Vec<FrameLine> {
    let (big, small, long, gap) = (h, h / 2.0, 2.0 * h, h);
    let outline = h / 10.0;
    let (cone_x, circle_x) = match angle {
        Angle::First => (left.x, left.x + long + gap + big),
        Angle::Third => (left.x + 2.0 * big + gap, left.x + big),
    };
    let y = left.y;
    let mut out = vec![line(
        outline,
        vec![
            DVec2::new(cone_x, y - small),
            DVec2::new(cone_x + long, y - big),
            DVec2::new(cone_x + long, y + big),
            DVec2::new(cone_x, y + small),
            DVec2::new(cone_x, y - small),
        ],
    )];
    for r in [big, small] {
        let points = (0..=72)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k % 72) / 72.0;
                DVec2::new(circle_x + r * a.cos(), y - r * a.sin())
            })
            .collect();
        out.push(line(outline, points));
    }
    // Centre lines (ISO 128 type 04.1, narrow chain), 1 mm past the outlines.
    let chain = vec![3.0, 0.75, 0.1, 0.75];
    let (x0, x1) = (left.x - 1.0, left.x + long + gap + 2.0 * big + 1.0);
    out.push(FrameLine { width: 0.18, dashes: chain.clone(), points: vec![DVec2::new(x0, y), DVec2::new(x1, y)] });
    out.push(FrameLine {
        width: 0.18,
        dashes: chain,
        points: vec![DVec2::new(circle_x, y - big - 1.0), DVec2::new(circle_x, y + big + 1.0)],
    });
    out
}

/// The strokes of every view, for tests and reports: (view, stroke) in sheet millimetres.
pub fn strokes(sheet: &Sheet) -> impl Iterator<Item = (ViewKind, &Stroke)> {
    sheet.views.iter().flat_map(|v| v.drawing.strokes.iter().map(move |s| (v.kind, s)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_series_runs_down_by_1_2_5() {
        let series = Scale::series();
        let names: Vec<String> = series.iter().map(Scale::to_string).collect();
        let at = names.iter().position(|n| n == "10:1").expect("10:1");
        assert_eq!(names[at..at + 9], ["10:1", "5:1", "2:1", "1:1", "1:2", "1:5", "1:10", "1:20", "1:50"]);
        assert!(series.windows(2).all(|w| w[0].ratio() > w[1].ratio()));
        assert_eq!("1:2".parse::<Scale>(), Ok(Scale { paper: 1, real: 2 }));
        assert!("1:0".parse::<Scale>().is_err() && "2".parse::<Scale>().is_err() && "a:b".parse::<Scale>().is_err());
    }

    #[test]
    fn views_parse_by_name_and_name_a_mistake() {
        assert_eq!(ViewKind::parse_list("front,top").unwrap(), [ViewKind::Front, ViewKind::Top]);
        let e = ViewKind::parse_list("front,frnt").unwrap_err();
        assert!(e.contains("\"frnt\"") && !e.contains('\n'), "{e}");
        assert!(ViewKind::parse_list("front,front").is_err());
        assert!("a9".parse::<SheetSize>().unwrap_err().contains("A9") || "A9".parse::<SheetSize>().is_err());
        assert_eq!("a3".parse::<SheetSize>(), Ok(SheetSize::A3));
    }

    #[test]
    fn view_frames_are_right_handed_and_share_their_axes() {
        let (front, up) = (DVec3::Z, DVec3::Y);
        let right = up.cross(front);
        assert_eq!(right, DVec3::X);
        for kind in ViewKind::ALL {
            let f = kind.frame(front, up, right);
            assert!((f.right.cross(f.up) - f.towards).length() < 1e-12, "{kind:?}");
        }
        let (fr, top, side) = (
            ViewKind::Front.frame(front, up, right),
            ViewKind::Top.frame(front, up, right),
            ViewKind::Right.frame(front, up, right),
        );
        assert_eq!(fr.right, top.right, "front and top share x");
        assert_eq!(fr.up, side.up, "front and right share y");
        // Top: the model's front at the bottom of the view; right: the front on the left.
        assert_eq!(top.up, -front);
        assert_eq!(side.right, -front);
        let iso = ViewKind::Iso.frame(front, up, right);
        assert!((iso.towards.y.asin().to_degrees() - 35.264).abs() < 1e-3);
    }

    #[test]
    fn third_angle_puts_top_above_and_right_to_the_right() {
        assert_eq!(ViewKind::Top.cell(Angle::Third), (-1, 0));
        assert_eq!(ViewKind::Right.cell(Angle::Third), (0, 1));
        assert_eq!(ViewKind::Top.cell(Angle::First), (1, 0));
        assert_eq!(ViewKind::Right.cell(Angle::First), (0, -1));
    }
}
