//! The illustrator's edits in `drafter view` (Lux et al. 2013, §4): a selection with a reference
//! part, the four projector manipulators (anchor, scale, direction, projector line) and their
//! propagation over a multi-selection, gradient and style changes, undo and redo, and the two ways
//! out: the baked file rewritten in place (`drafter_format::replace_part_records`) and a TOML
//! overrides file that `drafter bake --config` applies to the source model.
//!
//! Plain functions over plain data. The window (`window.rs`) turns mouse and keys into these calls
//! and uploads the part table after each change; nothing is re-baked (§4: "in real time, without
//! re-processing the scene").
//!
//! Conventions: screen positions are pixels with y down, as winit reports the cursor; every world
//! quantity is f64, as in the file.

use drafter_bounds::Projector;
use drafter_core::gradient::{MAX_POWER, MAX_QUANTIZATION, MIN_POWER};
use drafter_format::{BoxRecord, GradientRecord, PartRecord, PartStyle, ProjectorRecord, TransferCurve};
use glam::{DMat4, DQuat, DVec2, DVec3, DVec4, Mat4};

/// Cursor movement under which a scale or direction drag is not yet defined (too close to the
/// anchor to give a ratio or an angle), pixels.
pub const MIN_HANDLE_PX: f64 = 2.0;

/// Radius around the anchor's dot (pixels) where a scale drag grabs the anchor itself: the end of
/// the projector then follows the cursor's distance from the anchor.
pub const ANCHOR_GRAB_PX: f64 = 8.0;

/// A direction within this angle of its box's reference normal (degrees) runs along the line of
/// sight: moving the anchor across the reference plane changes nothing, and a turn about the normal
/// barely moves it, so the direction tool tilts it instead ([`manipulate`]).
pub const FACING_DEG: f64 = 20.0;

/// Degrees the direction tool turns (or tilts) a direction per pixel of drag (100 px: 50°).
pub const TURN_DEGREES_PER_PIXEL: f64 = 0.5;

/// Step of `f` per key press.
pub const F_STEP: f32 = 0.05;

/// Factor of `p` per key press.
pub const P_FACTOR: f32 = 1.25;

/// The flat greys `g` cycles through after "shaded" (black, three greys, white).
pub const FLAT_GREYS: [f32; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// What an illustrator edits in a part: the projector (anchor, direction, scale; Lux et al. 2013
/// §3.2), the gradient ω(i, q, f, p) with its transfer γ (§3.3), the style hint and a flat grey.
/// `q`, `f` and `p` have the types `drafter bake --config` reads, so an exported edit re-bakes to
/// the same record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartParams {
    pub anchor: DVec3,
    /// Unit vector.
    pub direction: DVec3,
    /// > 0.
    pub scale: f64,
    pub q: u32,
    pub f: f32,
    pub p: f32,
    pub transfer: TransferCurve,
    pub style: Option<PartStyle>,
    pub flat: Option<f32>,
}

impl PartParams {
    /// The parameters of a baked record.
    pub fn from_record(record: &PartRecord) -> Self {
        let g = &record.gradient;
        Self {
            anchor: DVec3::from(record.projector.anchor),
            direction: DVec3::from(record.projector.direction),
            scale: record.projector.scale,
            q: g.q.round().clamp(1.0, 255.0) as u32,
            f: g.f as f32,
            p: g.p as f32,
            transfer: g.transfer,
            style: record.style,
            flat: record.flat.map(|v| v as f32),
        }
    }

    /// `record` with these parameters: the projector matrix is recomputed as the bake computes it
    /// (`drafter_bounds::Projector::matrix`); box, name and counts stay.
    pub fn to_record(&self, record: &PartRecord) -> PartRecord {
        let projector = Projector { anchor: self.anchor, direction: self.direction, scale: self.scale };
        PartRecord {
            projector: ProjectorRecord {
                anchor: self.anchor.to_array(),
                direction: self.direction.to_array(),
                scale: self.scale,
                matrix: projector.matrix().to_cols_array(),
            },
            gradient: GradientRecord {
                q: f64::from(self.q),
                f: f64::from(self.f),
                p: f64::from(self.p),
                transfer: self.transfer,
            },
            style: self.style,
            flat: self.flat.map(f64::from),
            ..record.clone()
        }
    }
}

/// A part's oriented box, as the manipulators need it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartBox {
    pub center: DVec3,
    /// Orthonormal.
    pub axes: [DVec3; 3],
    pub half_extents: DVec3,
}

impl PartBox {
    pub fn from_record(obb: &BoxRecord) -> Self {
        Self {
            center: DVec3::from(obb.center),
            axes: obb.axes.map(DVec3::from),
            half_extents: DVec3::from(obb.half_extents),
        }
    }

    /// The normal of the box's reference plane seen from `toward_viewer`: the box axis most
    /// aligned with the line of sight, signed to face the viewer. Anchors move in planes parallel
    /// to that face (Lux et al. 2013, §4.1), and directions turn about it.
    pub fn reference_normal(&self, toward_viewer: DVec3) -> DVec3 {
        let axis = self
            .axes
            .iter()
            .copied()
            .max_by(|a, b| a.dot(toward_viewer).abs().total_cmp(&b.dot(toward_viewer).abs()))
            .unwrap_or(DVec3::Z);
        if axis.dot(toward_viewer) < 0.0 { -axis } else { axis }
    }

    /// Whether `direction` runs within [`FACING_DEG`] of this box's reference normal as seen from
    /// `toward_viewer`: then an anchor move across the reference plane changes nothing visible.
    pub fn faces(&self, direction: DVec3, toward_viewer: DVec3) -> bool {
        direction.dot(self.reference_normal(toward_viewer)).abs() >= FACING_DEG.to_radians().cos()
    }

    /// The box's diagonal length.
    pub fn diagonal(&self) -> f64 {
        2.0 * self.half_extents.length()
    }
}

/// The camera of the frame on screen, in world coordinates: world points to pixels and pixels to
/// rays. Built from the renderer's camera (render space, f32) and the model's render origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenView {
    clip_from_world: DMat4,
    world_from_clip: DMat4,
    size: DVec2,
}

impl ScreenView {
    /// `clip_from_render` with depth in [0, 1] (wgpu), `origin` the world position of the render
    /// origin, `size` the window's pixels.
    pub fn new(clip_from_render: Mat4, origin: DVec3, size: (u32, u32)) -> Self {
        Self::from_world(clip_from_render.as_dmat4() * DMat4::from_translation(-origin), size)
    }

    /// From a world-to-clip matrix directly.
    pub fn from_world(clip_from_world: DMat4, size: (u32, u32)) -> Self {
        Self {
            clip_from_world,
            world_from_clip: clip_from_world.inverse(),
            size: DVec2::new(f64::from(size.0.max(1)), f64::from(size.1.max(1))),
        }
    }

    /// The pixel a world point lands on; `None` behind the camera.
    pub fn project(&self, world: DVec3) -> Option<DVec2> {
        let clip = self.clip_from_world * world.extend(1.0);
        if clip.w <= 1e-12 * clip.truncate().length().max(1.0) {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some(DVec2::new((ndc.x + 1.0) * 0.5 * self.size.x, (1.0 - ndc.y) * 0.5 * self.size.y))
    }

    /// The ray through a pixel: a point on the near plane and the unit direction away from the
    /// viewer.
    pub fn ray(&self, pixel: DVec2) -> (DVec3, DVec3) {
        let x = 2.0 * pixel.x / self.size.x - 1.0;
        let y = 1.0 - 2.0 * pixel.y / self.size.y;
        let unproject = |z: f64| {
            let p = self.world_from_clip * DVec4::new(x, y, z, 1.0);
            p.truncate() / p.w
        };
        let (near, far) = (unproject(0.0), unproject(1.0));
        (near, (far - near).normalize_or(DVec3::NEG_Z))
    }

    /// Unit vector from `world` towards the viewer (along the ray through its pixel).
    pub fn toward_viewer(&self, world: DVec3) -> DVec3 {
        match self.project(world) {
            Some(pixel) => -self.ray(pixel).1,
            None => -self.ray(self.size * 0.5).1,
        }
    }

    /// Where the ray through `pixel` meets the plane through `point` with normal `normal`; `None`
    /// when the ray runs (nearly) parallel to it.
    pub fn on_plane(&self, pixel: DVec2, point: DVec3, normal: DVec3) -> Option<DVec3> {
        let (origin, direction) = self.ray(pixel);
        let along = direction.dot(normal);
        if along.abs() < 1e-9 {
            return None;
        }
        let t = (point - origin).dot(normal) / along;
        Some(origin + direction * t)
    }
}

/// The selected parts and the reference part among them (Lux et al. 2013 §4: a multi-selection
/// edits every part the way the reference is edited; the reference is drawn lighter).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Selection {
    /// In the order they were selected.
    pub parts: Vec<u32>,
    pub reference: Option<u32>,
}

impl Selection {
    pub fn contains(&self, id: u32) -> bool {
        self.parts.contains(&id)
    }

    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// A plain click: on a part outside the selection, selects it alone; on a selected part, makes
    /// it the reference (a single click changes the reference); on the background, clears.
    pub fn click(&mut self, hit: Option<u32>) {
        match hit {
            None => *self = Selection::default(),
            Some(id) if self.contains(id) => self.reference = Some(id),
            Some(id) => *self = Selection { parts: vec![id], reference: Some(id) },
        }
    }

    /// A shift-click: adds the part, or removes it (the reference passes to the first part left).
    pub fn toggle(&mut self, id: u32) {
        if let Some(at) = self.parts.iter().position(|&p| p == id) {
            self.parts.remove(at);
            if self.reference == Some(id) {
                self.reference = self.parts.first().copied();
            }
        } else {
            self.parts.push(id);
            self.reference.get_or_insert(id);
        }
    }

    /// A box or lasso selection: `inside` replaces the selection, or joins it when `add`.
    pub fn lasso(&mut self, inside: &[u32], add: bool) {
        if !add {
            *self = Selection::default();
        }
        for &id in inside {
            if !self.contains(id) {
                self.parts.push(id);
            }
        }
        if self.reference.is_none_or(|r| !self.contains(r)) {
            self.reference = self.parts.first().copied();
        }
    }
}

/// Whether `point` is inside the closed polygon `path` (even-odd rule; the last point joins the
/// first).
pub fn inside_polygon(point: DVec2, path: &[DVec2]) -> bool {
    let mut inside = false;
    for (k, &a) in path.iter().enumerate() {
        let b = path[(k + 1) % path.len()];
        if (a.y > point.y) != (b.y > point.y) {
            let x = a.x + (point.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if point.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The parts whose box centre projects inside the lasso `path` (Lux et al. 2013 §4), in id order.
pub fn parts_in_lasso(path: &[DVec2], view: &ScreenView, boxes: &[(u32, PartBox)]) -> Vec<u32> {
    if path.len() < 3 {
        return Vec::new();
    }
    boxes
        .iter()
        .filter(|(_, b)| view.project(b.center).is_some_and(|c| inside_polygon(c, path)))
        .map(|&(id, _)| id)
        .collect()
}

/// The four direct manipulations of a projector (Lux et al. 2013 §4.1, Fig. 7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Drag the gradient across the part: the anchor moves parallel to the box's reference plane
    /// and stays under the cursor's offset; a click centres it under the cursor.
    Anchor,
    /// Drag away from or towards the anchor: the scale grows or shrinks by the ratio of the
    /// cursor's distances from the anchor on screen.
    Scale,
    /// Drag left or right: the direction turns about the reference plane's normal,
    /// [`TURN_DEGREES_PER_PIXEL`] of horizontal drag, clockwise on screen to the right, wherever the
    /// drag starts. A direction facing the viewer ([`PartBox::faces`]) tilts towards the drag
    /// instead, at the same rate.
    Direction,
    /// Draw a line: the anchor at its start, the direction along it, the scale its length (all in
    /// the reference plane through the anchor).
    Line,
}

impl Tool {
    pub const ALL: [Tool; 4] = [Tool::Anchor, Tool::Scale, Tool::Direction, Tool::Line];

    pub fn name(self) -> &'static str {
        match self {
            Tool::Anchor => "anchor",
            Tool::Scale => "scale",
            Tool::Direction => "direction",
            Tool::Line => "projector line",
        }
    }
}

/// One selected part as a manipulation sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    pub id: u32,
    pub params: PartParams,
    pub obb: PartBox,
}

/// The result of dragging `tool` from `start` to `now` over `targets` (their parameters when the
/// drag began), `targets[reference]` being the reference part; the new parameters in the same
/// order. The reference follows the cursor; the others follow it as Lux et al. (2013, §4)
/// propagate a multi-selection: the same anchor offset, the same scale, the same rotation angle
/// about each part's own reference normal; a projector line gives every part the same direction
/// and scale and moves its anchor by the reference's offset. `None` while the gesture is not
/// defined (the cursor on the anchor, a ray parallel to the plane, the anchor behind the camera).
pub fn manipulate(
    tool: Tool,
    targets: &[Target],
    reference: usize,
    view: &ScreenView,
    start: DVec2,
    now: DVec2,
) -> Option<Vec<PartParams>> {
    let r = targets.get(reference)?;
    let anchor = r.params.anchor;
    let normal = r.obb.reference_normal(view.toward_viewer(anchor));
    let anchor_px = view.project(anchor)?;
    let mut out: Vec<PartParams> = targets.iter().map(|t| t.params).collect();
    match tool {
        Tool::Anchor => {
            let moved = view.on_plane(anchor_px + (now - start), anchor, normal)?;
            let offset = moved - anchor;
            for p in &mut out {
                p.anchor += offset;
            }
            // The reference exactly where the ray put it (no rounding through the offset).
            out[reference].anchor = moved;
        }
        Tool::Scale => {
            let (from, to) = ((start - anchor_px).length(), (now - anchor_px).length());
            let floor = 1e-6 * r.obb.diagonal().max(f64::MIN_POSITIVE);
            let scale = if from < ANCHOR_GRAB_PX {
                // Grabbed on the anchor's dot: the projector's end follows the cursor's distance
                // from the anchor (in the reference plane where the end is not seen apart from it).
                let end = view.project(anchor + r.params.direction * r.params.scale);
                match end.map(|e| (e - anchor_px).length()) {
                    Some(handle) if handle >= ANCHOR_GRAB_PX => r.params.scale * to / handle,
                    _ => (view.on_plane(now, anchor, normal)? - anchor).length(),
                }
            } else if to < MIN_HANDLE_PX {
                return None;
            } else {
                r.params.scale * to / from
            };
            if !scale.is_finite() {
                return None;
            }
            let scale = scale.max(floor);
            for p in &mut out {
                p.scale = scale;
            }
        }
        Tool::Direction if r.obb.faces(r.params.direction, view.toward_viewer(anchor)) => {
            // Along the line of sight a turn about the normal barely moves the direction: tilt it
            // towards the drag instead, by an angle in proportion to the drag's length; every
            // selected part turns by the same rotation.
            let drag = now - start;
            if drag.length() < 1e-9 {
                return Some(out);
            }
            let towards = view.on_plane(anchor_px + drag, anchor, normal)? - anchor;
            let axis = normal.cross(towards);
            if axis.length() <= 1e-12 * towards.length() {
                return None;
            }
            let turn = DQuat::from_axis_angle(axis.normalize(), (drag.length() * TURN_DEGREES_PER_PIXEL).to_radians());
            for p in &mut out {
                p.direction = (turn * p.direction).normalize();
            }
        }
        Tool::Direction => {
            // A dial: the rate does not depend on where the drag starts. (The angle the cursor
            // turned about the anchor gave a drag that starts far from it, or moves away from it,
            // a few degrees for 100 px.) Counter-clockwise on screen is positive about a normal
            // that faces the viewer: a drag to the left.
            let angle = (-(now.x - start.x) * TURN_DEGREES_PER_PIXEL).to_radians();
            for (p, t) in out.iter_mut().zip(targets) {
                let n = t.obb.reference_normal(view.toward_viewer(t.params.anchor));
                p.direction = (DQuat::from_axis_angle(n, angle) * t.params.direction).normalize();
            }
        }
        Tool::Line => {
            let from = view.on_plane(start, anchor, normal)?;
            let to = view.on_plane(now, anchor, normal)?;
            let length = (to - from).length();
            if length.is_nan() || length <= 1e-9 * r.obb.diagonal().max(f64::MIN_POSITIVE) {
                return None;
            }
            let direction = (to - from).normalize();
            let offset = from - anchor;
            for p in &mut out {
                p.anchor += offset;
                p.direction = direction;
                p.scale = length;
            }
            out[reference].anchor = from;
        }
    }
    Some(out)
}

/// A keyboard edit of the gradient, style or tone of every selected part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Adjust {
    /// q by this many steps (clamped to 1..=[`MAX_QUANTIZATION`]).
    Q(i32),
    /// f by this many [`F_STEP`]s (clamped to [0, 1], kept on the step grid).
    F(i32),
    /// p times [`P_FACTOR`] to this power (clamped to [[`MIN_POWER`], [`MAX_POWER`]]).
    P(i32),
    /// The next transfer curve γ.
    NextTransfer,
    /// The next style hint (the scene's style after the last).
    NextStyle,
    /// Shaded, then each of [`FLAT_GREYS`], then shaded again.
    NextFlat,
    /// q set (the panel's slider; clamped as [`Adjust::Q`]).
    SetQ(u32),
    /// f set (clamped to [0, 1]).
    SetF(f32),
    /// p set (clamped as [`Adjust::P`]).
    SetP(f32),
    SetTransfer(TransferCurve),
    /// The style hint set, `None`: the scene's style.
    SetStyle(Option<PartStyle>),
    /// The flat grey set (clamped to [0, 1]), `None`: shaded.
    SetFlat(Option<f32>),
}

impl Adjust {
    /// `params` after this edit.
    pub fn apply(self, params: &PartParams) -> PartParams {
        let mut p = *params;
        match self {
            Adjust::Q(k) => p.q = (i64::from(p.q) + i64::from(k)).clamp(1, i64::from(MAX_QUANTIZATION)) as u32,
            Adjust::F(k) => {
                let steps = (p.f / F_STEP).round() as i32 + k;
                p.f = (steps as f32 * F_STEP).clamp(0.0, 1.0);
            }
            Adjust::P(k) => p.p = (p.p * P_FACTOR.powi(k)).clamp(MIN_POWER, MAX_POWER),
            Adjust::NextTransfer => {
                let all = TransferCurve::ALL;
                let at = all.iter().position(|&c| c == p.transfer).unwrap_or(0);
                p.transfer = all[(at + 1) % all.len()];
            }
            Adjust::NextStyle => {
                let all = PartStyle::ALL;
                p.style = match p.style {
                    None => Some(all[0]),
                    Some(s) => all.iter().position(|&x| x == s).and_then(|at| all.get(at + 1)).copied(),
                };
            }
            Adjust::NextFlat => {
                p.flat = match p.flat {
                    None => Some(FLAT_GREYS[0]),
                    Some(g) => FLAT_GREYS.iter().position(|&x| x == g).and_then(|at| FLAT_GREYS.get(at + 1)).copied(),
                };
            }
            Adjust::SetQ(q) => p.q = q.clamp(1, MAX_QUANTIZATION),
            Adjust::SetF(f) if f.is_finite() => p.f = f.clamp(0.0, 1.0),
            Adjust::SetP(power) if power.is_finite() => p.p = power.clamp(MIN_POWER, MAX_POWER),
            Adjust::SetTransfer(curve) => p.transfer = curve,
            Adjust::SetStyle(style) => p.style = style,
            Adjust::SetFlat(flat) => p.flat = flat.filter(|g| g.is_finite()).map(|g| g.clamp(0.0, 1.0)),
            Adjust::SetF(_) | Adjust::SetP(_) => {}
        }
        p
    }
}

/// One undoable step: every part it changed, before and after.
#[derive(Clone, Debug, PartialEq)]
pub struct Change {
    pub parts: Vec<(u32, PartParams, PartParams)>,
}

/// The state of an editing session over one baked file: the parts' records as they are now, the
/// selection, the gesture in progress and the undo history.
#[derive(Clone, Debug)]
pub struct Editor {
    /// Indexed by part id; `None` for parts without a baked record (not editable).
    records: Vec<Option<PartRecord>>,
    /// The records as the file on disk holds them (loaded, or last saved).
    saved: Vec<Option<PartRecord>>,
    /// The records when the session began (what an export compares against).
    first: Vec<Option<PartRecord>>,
    pub selection: Selection,
    gesture: Option<Gesture>,
    /// The selection as a panel widget found it when it was grabbed ([`Self::adjust_live`]).
    live: Option<Vec<Target>>,
    undo: Vec<Change>,
    redo: Vec<Change>,
}

#[derive(Clone, Debug)]
struct Gesture {
    tool: Tool,
    start: DVec2,
    targets: Vec<Target>,
    reference: usize,
}

impl Editor {
    /// A session over `records`, indexed by part id.
    pub fn new(records: Vec<Option<PartRecord>>) -> Self {
        Self {
            saved: records.clone(),
            first: records.clone(),
            records,
            selection: Selection::default(),
            gesture: None,
            live: None,
            undo: Vec::new(),
            redo: Vec::new(),
        }
    }

    /// Part `id`'s record as edited so far.
    pub fn record(&self, id: u32) -> Option<&PartRecord> {
        self.records.get(id as usize).and_then(Option::as_ref)
    }

    /// Every editable part's record, in id order.
    pub fn records(&self) -> impl Iterator<Item = &PartRecord> {
        self.records.iter().flatten()
    }

    pub fn params(&self, id: u32) -> Option<PartParams> {
        self.record(id).map(PartParams::from_record)
    }

    /// The selected parts that can be edited, the reference first.
    fn targets(&self) -> Vec<Target> {
        let mut ids = self.selection.parts.clone();
        if let Some(r) = self.selection.reference
            && let Some(at) = ids.iter().position(|&p| p == r)
        {
            ids.remove(at);
            ids.insert(0, r);
        }
        ids.iter()
            .filter_map(|&id| {
                let record = self.record(id)?;
                Some(Target { id, params: PartParams::from_record(record), obb: PartBox::from_record(&record.obb) })
            })
            .collect()
    }

    /// Starts a drag of `tool` at `start`; false (and nothing starts) when no editable part is
    /// selected.
    pub fn begin(&mut self, tool: Tool, start: DVec2) -> bool {
        let targets = self.targets();
        if targets.is_empty() {
            return false;
        }
        self.gesture = Some(Gesture { tool, start, targets, reference: 0 });
        true
    }

    pub fn dragging(&self) -> bool {
        self.gesture.is_some()
    }

    /// The drag in progress, with the cursor at `now`: the parts it changed (their records are
    /// updated; the undo history is not, until [`Self::end`]).
    pub fn drag_to(&mut self, view: &ScreenView, now: DVec2) -> Vec<u32> {
        let Some(g) = &self.gesture else { return Vec::new() };
        let Some(params) = manipulate(g.tool, &g.targets, g.reference, view, g.start, now) else { return Vec::new() };
        let updates: Vec<(u32, PartParams)> = g.targets.iter().map(|t| t.id).zip(params).collect();
        self.set_params(&updates)
    }

    /// Ends the drag: one undo step from the parameters at its start to the current ones.
    pub fn end(&mut self) -> bool {
        let Some(g) = self.gesture.take() else { return false };
        let parts = self.changed_since(&g.targets);
        self.push(parts)
    }

    /// The parts of `targets` whose parameters differ now from the ones they hold, before and
    /// after.
    fn changed_since(&self, targets: &[Target]) -> Vec<(u32, PartParams, PartParams)> {
        targets
            .iter()
            .filter_map(|t| {
                let now = self.params(t.id)?;
                (now != t.params).then_some((t.id, t.params, now))
            })
            .collect()
    }

    /// A click with the anchor tool: the reference's anchor moves under `cursor` in its reference
    /// plane, the others by the same offset. One undo step.
    pub fn centre_anchor(&mut self, view: &ScreenView, cursor: DVec2) -> Vec<u32> {
        let targets = self.targets();
        let Some(anchor_px) = targets.first().and_then(|t| view.project(t.params.anchor)) else { return Vec::new() };
        let Some(params) = manipulate(Tool::Anchor, &targets, 0, view, anchor_px, cursor) else { return Vec::new() };
        let changes: Vec<(u32, PartParams, PartParams)> =
            targets.iter().zip(params).filter(|(t, p)| t.params != *p).map(|(t, p)| (t.id, t.params, p)).collect();
        self.commit(changes)
    }

    /// A keyboard edit of every selected part. One undo step.
    pub fn adjust(&mut self, adjust: Adjust) -> Vec<u32> {
        let changes: Vec<(u32, PartParams, PartParams)> = self
            .targets()
            .iter()
            .map(|t| (t.id, t.params, adjust.apply(&t.params)))
            .filter(|(_, before, after)| before != after)
            .collect();
        self.commit(changes)
    }

    /// An edit from a panel widget that is held (a slider being dragged): every selected part gets
    /// `adjust` applied to its parameters as they were when the widget was grabbed, the undo
    /// history is left alone until [`Self::end_live`]. The parts changed.
    pub fn adjust_live(&mut self, adjust: Adjust) -> Vec<u32> {
        if self.live.is_none() {
            self.live = Some(self.targets());
        }
        let updates: Vec<(u32, PartParams)> =
            self.live.iter().flatten().map(|t| (t.id, adjust.apply(&t.params))).collect();
        self.set_params(&updates)
    }

    /// The panel widget is released: one undo step from the parameters when it was grabbed to
    /// the current ones. False when nothing changed.
    pub fn end_live(&mut self) -> bool {
        let Some(targets) = self.live.take() else { return false };
        let parts = self.changed_since(&targets);
        self.push(parts)
    }

    /// Undoes the last step; the parts it changed.
    pub fn undo(&mut self) -> Vec<u32> {
        let Some(change) = self.undo.pop() else { return Vec::new() };
        let ids = self.set_params(&change.parts.iter().map(|&(id, before, _)| (id, before)).collect::<Vec<_>>());
        self.redo.push(change);
        ids
    }

    /// Redoes the last undone step; the parts it changed.
    pub fn redo(&mut self) -> Vec<u32> {
        let Some(change) = self.redo.pop() else { return Vec::new() };
        let ids = self.set_params(&change.parts.iter().map(|&(id, _, after)| (id, after)).collect::<Vec<_>>());
        self.undo.push(change);
        ids
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// The parts whose records differ from the file on disk (as loaded, or last saved).
    pub fn unsaved(&self) -> Vec<u32> {
        self.records
            .iter()
            .zip(&self.saved)
            .enumerate()
            .filter(|(_, (now, loaded))| now != loaded)
            .map(|(id, _)| id as u32)
            .collect()
    }

    /// After a save: the current records are what the file holds.
    pub fn mark_saved(&mut self) {
        self.saved = self.records.clone();
    }

    /// The overrides that re-create every edited part when `drafter bake --config` bakes the source
    /// model with them (appended to the config of the first bake, if it had one): one `[[part]]`
    /// table by id with the projector, gradient, style and tone for every part edited since the
    /// session began. `None` when no part has been edited (nothing to export).
    pub fn overrides_toml(&self, file: &str) -> Option<String> {
        let mut out = format!(
            "# Part edits made in `drafter view` on {file}.\n# Re-create them: drafter bake SOURCE --config THIS_FILE (append these tables to the\n# config of the first bake, if it had one).\n"
        );
        let edited = self.edited();
        for &id in &edited {
            if let Some(now) = self.record(id) {
                out.push_str(&override_table(now));
            }
        }
        (!edited.is_empty()).then_some(out)
    }

    /// The parts whose records differ from the ones the session began with.
    pub fn edited(&self) -> Vec<u32> {
        let differs = |(now, first): (&Option<PartRecord>, &Option<PartRecord>)| now.is_some() && now != first;
        (0..).zip(self.records.iter().zip(&self.first)).filter(|&(_, pair)| differs(pair)).map(|(id, _)| id).collect()
    }

    /// Whether any part can be edited (an unbaked model has no records).
    pub fn editable(&self) -> bool {
        self.records.iter().any(Option::is_some)
    }

    fn commit(&mut self, changes: Vec<(u32, PartParams, PartParams)>) -> Vec<u32> {
        let ids = self.set_params(&changes.iter().map(|&(id, _, after)| (id, after)).collect::<Vec<_>>());
        self.push(changes);
        ids
    }

    fn push(&mut self, parts: Vec<(u32, PartParams, PartParams)>) -> bool {
        if parts.is_empty() {
            return false;
        }
        self.undo.push(Change { parts });
        self.redo.clear();
        true
    }

    fn set_params(&mut self, updates: &[(u32, PartParams)]) -> Vec<u32> {
        let mut changed = Vec::new();
        for &(id, params) in updates {
            if let Some(Some(record)) = self.records.get_mut(id as usize) {
                let next = params.to_record(record);
                if next != *record {
                    *record = next;
                    changed.push(id);
                }
            }
        }
        changed
    }
}

/// One `[[part]]` table of `drafter bake --config` that sets `record`'s projector, gradient, style
/// and tone. Floats are written in Rust's shortest round-trip form (`{:?}`, which TOML reads as a
/// float), so they read back to the same bits.
pub fn override_table(record: &PartRecord) -> String {
    let v = |a: [f64; 3]| format!("[{:?}, {:?}, {:?}]", a[0], a[1], a[2]);
    let g = &record.gradient;
    let mut out = format!(
        "\n[[part]]\nid = {}  # {:?}\nanchor = {}\ndirection = {}\nscale = {:?}\nq = {}\nf = {:?}\np = {:?}\ntransfer = \"{}\"\n",
        record.id,
        record.name,
        v(record.projector.anchor),
        v(record.projector.direction),
        record.projector.scale,
        g.q,
        g.f as f32,
        g.p as f32,
        g.transfer,
    );
    if let Some(style) = record.style {
        out.push_str(&format!("style = \"{}\"\n", style.name()));
    }
    if let Some(flat) = record.flat {
        out.push_str(&format!("flat = {:?}\n", flat as f32));
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use drafter_format::ObbMethod;

    const SIZE: (u32, u32) = (800, 600);

    fn views() -> Vec<(&'static str, ScreenView)> {
        use glam::Vec3;
        use glam::camera::rh::{proj::directx, view::look_at_mat4};
        let look = look_at_mat4(Vec3::new(3.0, 2.0, 9.0), Vec3::new(0.5, 0.0, 0.0), Vec3::Y);
        let head_on = look_at_mat4(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y);
        let aspect = SIZE.0 as f32 / SIZE.1 as f32;
        let ortho = directx::orthographic(-4.0, 4.0, -3.0, 3.0, 0.5, 50.0);
        let view = |m: Mat4| ScreenView::from_world(m.as_dmat4(), SIZE);
        vec![
            ("perspective", view(directx::perspective(0.6, aspect, 0.5, 50.0) * look)),
            ("orthographic", view(ortho * look)),
            ("head-on", view(ortho * head_on)),
        ]
    }

    /// A baked record of a 2 × 1 × 0.5 box at `center` with axes along x, y, z; the projector at
    /// the centre along +x, scale 2, gradient q 10, f 0.5, p 1.
    pub(crate) fn record(id: u32, center: [f64; 3]) -> PartRecord {
        let params = PartParams {
            anchor: DVec3::from(center),
            direction: DVec3::X,
            scale: 2.0,
            q: 10,
            f: 0.5,
            p: 1.0,
            transfer: TransferCurve::Identity,
            style: None,
            flat: None,
        };
        let blank = PartRecord {
            id,
            name: format!("part{id}"),
            triangles: 12,
            obb: BoxRecord {
                center,
                axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                half_extents: [1.0, 0.5, 0.25],
                volume: 1.0,
                method: ObbMethod::Default,
            },
            projector: ProjectorRecord { anchor: center, direction: [1.0, 0.0, 0.0], scale: 2.0, matrix: [0.0; 16] },
            gradient: GradientRecord { q: 10.0, f: 0.5, p: 1.0, transfer: TransferCurve::Identity },
            style: None,
            flat: None,
        };
        params.to_record(&blank)
    }

    fn target(id: u32, center: [f64; 3]) -> Target {
        let r = record(id, center);
        Target { id, params: PartParams::from_record(&r), obb: PartBox::from_record(&r.obb) }
    }

    fn close(a: DVec2, b: DVec2, tol: f64) -> bool {
        (a - b).length() <= tol
    }

    #[test]
    fn an_anchor_drag_moves_the_anchor_in_the_reference_plane_by_the_cursor_offset() {
        for (name, view) in views() {
            let t = target(0, [0.5, 0.2, -0.3]);
            let normal = t.obb.reference_normal(view.toward_viewer(t.params.anchor));
            let before = view.project(t.params.anchor).unwrap();
            for (start, offset) in [((400.0, 300.0), (37.0, -12.0)), ((120.0, 500.0), (-80.0, 45.5))] {
                let (start, offset) = (DVec2::from(start), DVec2::from(offset));
                let out = manipulate(Tool::Anchor, &[t], 0, &view, start, start + offset).unwrap();
                let moved = out[0].anchor;
                assert!((moved - t.params.anchor).dot(normal).abs() < 1e-9, "{name}: left the reference plane");
                let after = view.project(moved).unwrap();
                assert!(
                    close(after - before, offset, 1e-6),
                    "{name}: moved {:?} on screen, cursor {offset:?}",
                    after - before
                );
                // Nothing else changes.
                assert_eq!(PartParams { anchor: t.params.anchor, ..out[0] }, t.params);
            }
        }
    }

    #[test]
    fn a_projector_line_sets_the_anchor_at_its_start_and_direction_and_scale_along_it() {
        for (name, view) in views() {
            let t = target(0, [0.0, 0.0, 0.0]);
            let (start, end) = (DVec2::new(300.0, 350.0), DVec2::new(520.0, 210.0));
            let out = manipulate(Tool::Line, &[t], 0, &view, start, end).unwrap();
            let p = out[0];
            assert!(close(view.project(p.anchor).unwrap(), start, 1e-6), "{name}: anchor not at the start");
            let tip = p.anchor + p.direction * p.scale;
            assert!(close(view.project(tip).unwrap(), end, 1e-6), "{name}: direction × scale does not reach the end");
            assert!((p.direction.length() - 1.0).abs() < 1e-12);
            let normal = t.obb.reference_normal(view.toward_viewer(t.params.anchor));
            assert!(p.direction.dot(normal).abs() < 1e-9, "{name}: the line leaves the reference plane");
            // The projector's p is 1/2 at the line's start and grows by 1 over its length.
            let projector = Projector { anchor: p.anchor, direction: p.direction, scale: p.scale };
            assert!((projector.coordinate(p.anchor) - 0.5).abs() < 1e-12);
            assert!((projector.coordinate(tip) - 1.5).abs() < 1e-9);
        }
    }

    #[test]
    fn scale_follows_the_distance_ratio_and_direction_the_angle_about_the_anchor() {
        let (_, view) = views().remove(2); // head-on: the box's z axis faces the viewer
        let t = target(0, [0.0, 0.0, 0.0]);
        let a = view.project(t.params.anchor).unwrap();
        let out =
            manipulate(Tool::Scale, &[t], 0, &view, a + DVec2::new(10.0, 0.0), a + DVec2::new(0.0, 25.0)).unwrap();
        assert!((out[0].scale - 5.0).abs() < 1e-12, "{}", out[0].scale);
        assert!(
            manipulate(Tool::Scale, &[t], 0, &view, a + DVec2::new(10.0, 0.0), a + DVec2::new(1.0, 0.0)).is_none(),
            "no ratio on the anchor"
        );
        // 180 px to the left: a quarter turn counter-clockwise on screen turns +x into +y.
        let out = manipulate(Tool::Direction, &[t], 0, &view, a + DVec2::new(40.0, 0.0), a + DVec2::new(-140.0, -40.0))
            .unwrap();
        assert!((out[0].direction - DVec3::Y).length() < 1e-12, "{:?}", out[0].direction);
        let shown = view.project(out[0].direction).unwrap() - view.project(DVec3::ZERO).unwrap();
        assert!(shown.x.abs() < 1e-9 && shown.y < 0.0, "drawn pointing up: {shown:?}");
    }

    #[test]
    fn a_scale_drag_from_the_anchor_dot_pulls_the_projectors_end() {
        for (name, view) in views() {
            let t = target(0, [0.0, 0.0, 0.0]);
            let a = view.project(t.params.anchor).unwrap();
            let end = view.project(t.params.anchor + t.params.direction * t.params.scale).unwrap();
            let handle = (end - a).length();
            // Pressed on the dot (3 px off the anchor, inside its 5 px radius), dragged to twice the
            // handle's length on screen: the scale doubles.
            let now = a + (end - a) * 2.0;
            let out = manipulate(Tool::Scale, &[t], 0, &view, a + DVec2::new(3.0, 0.0), now)
                .unwrap_or_else(|| panic!("{name}: a drag from the dot is ignored"));
            assert!((out[0].scale - 4.0).abs() < 1e-9, "{name}: scale {} (handle {handle} px)", out[0].scale);
            // Exactly on the anchor too.
            assert!(manipulate(Tool::Scale, &[t], 0, &view, a, now).is_some(), "{name}");
        }
        // A direction towards the viewer has no length on screen: the end goes to the cursor's
        // distance in the reference plane.
        let (_, view) = views().remove(2);
        let mut t = target(0, [0.0, 0.0, 0.0]);
        t.params.direction = DVec3::Z;
        let a = view.project(t.params.anchor).unwrap();
        let out = manipulate(Tool::Scale, &[t], 0, &view, a, a + DVec2::new(0.0, 50.0)).unwrap();
        let cursor = view.on_plane(a + DVec2::new(0.0, 50.0), DVec3::ZERO, DVec3::Z).unwrap();
        assert!((out[0].scale - cursor.length()).abs() < 1e-9, "{} vs {}", out[0].scale, cursor.length());
    }

    #[test]
    fn a_direction_drag_turns_at_a_usable_rate_and_tilts_a_direction_facing_the_viewer() {
        let (_, view) = views().remove(2); // head-on: the box's z axis faces the viewer
        let mut t = target(0, [0.0, 0.0, 0.0]);
        let toward = view.toward_viewer(t.params.anchor);
        assert!(!t.obb.faces(t.params.direction, toward), "+x lies in the reference plane");
        // A direction 5° off the normal (the case: a turn about the normal moved it 2.5°).
        t.params.direction = DQuat::from_rotation_y(5f64.to_radians()) * DVec3::Z;
        assert!(t.obb.faces(t.params.direction, toward));
        let a = view.project(t.params.anchor).unwrap();
        let (start, now) = (a + DVec2::new(60.0, 10.0), a + DVec2::new(160.0, 10.0));
        let out = manipulate(Tool::Direction, &[t], 0, &view, start, now).unwrap();
        let turned = t.params.direction.angle_between(out[0].direction).to_degrees();
        assert!((turned - 100.0 * TURN_DEGREES_PER_PIXEL).abs() < 1e-6, "a 100 px drag turned it {turned}°");
        // Tilted towards the drag (right on screen: +x).
        assert!(out[0].direction.x > t.params.direction.x + 0.5, "{:?}", out[0].direction);
        assert!((out[0].direction.length() - 1.0).abs() < 1e-12);
        // A direction in the plane turns 50° for a 100 px drag wherever it starts: the drag
        // away from the anchor (the angle about it: 2.5°), far from it, across it.
        let t = target(0, [0.0, 0.0, 0.0]);
        for (from, to) in
            [((60.0, 10.0), (160.0, 10.0)), ((-400.0, 200.0), (-300.0, 205.0)), ((-50.0, 0.0), (50.0, 0.0))]
        {
            let (from, to) = (a + DVec2::from(from), a + DVec2::from(to));
            let out = manipulate(Tool::Direction, &[t], 0, &view, from, to).unwrap();
            let turned = t.params.direction.angle_between(out[0].direction).to_degrees();
            assert!((turned - 50.0).abs() < 1e-9, "{from} → {to}: {turned}°");
            // To the right: clockwise on screen (+x towards -y, drawn pointing down).
            assert!(out[0].direction.y < -0.7, "{:?}", out[0].direction);
        }
    }

    #[test]
    fn an_editor_without_edits_has_nothing_to_export() {
        let mut editor = Editor::new(vec![Some(record(0, [0.0; 3])), None]);
        assert!(editor.editable());
        assert_eq!(editor.overrides_toml("x.glb"), None);
        editor.selection.click(Some(0));
        editor.adjust(Adjust::Q(1));
        assert_eq!(editor.edited(), vec![0]);
        assert!(editor.overrides_toml("x.glb").is_some_and(|t| t.contains("[[part]]")));
        // Undone: the records are the first ones again, nothing to export.
        editor.undo();
        assert_eq!(editor.overrides_toml("x.glb"), None);
        // An unbaked model (a plain OBJ): no part can be edited.
        let plain = Editor::new(vec![None, None]);
        assert!(!plain.editable() && plain.overrides_toml("plain.obj").is_none());
    }

    #[test]
    fn a_multi_selection_takes_the_reference_offset_scale_and_angle() {
        for (name, view) in views() {
            let parts = [target(4, [0.0, 0.0, 0.0]), target(7, [2.0, 1.0, -1.0]), target(9, [-1.5, 0.5, 0.5])];
            let (start, now) = (DVec2::new(400.0, 300.0), DVec2::new(430.0, 280.0));
            let out = manipulate(Tool::Anchor, &parts, 0, &view, start, now).unwrap();
            let offset = out[0].anchor - parts[0].params.anchor;
            for (p, t) in out.iter().zip(&parts).skip(1) {
                assert!((p.anchor - t.params.anchor - offset).length() < 1e-12, "{name}: offset not shared");
            }
            let a = view.project(parts[0].params.anchor).unwrap();
            let out = manipulate(Tool::Scale, &parts, 0, &view, a + DVec2::new(20.0, 0.0), a + DVec2::new(30.0, 0.0))
                .unwrap();
            assert!(out.iter().all(|p| (p.scale - 3.0).abs() < 1e-12), "{name}: same scale");
            let out =
                manipulate(Tool::Direction, &parts, 0, &view, a + DVec2::new(20.0, 0.0), a + DVec2::new(200.0, 20.0))
                    .unwrap();
            for (p, t) in out.iter().zip(&parts) {
                let n = t.obb.reference_normal(view.toward_viewer(t.params.anchor));
                let angle = t.params.direction.cross(p.direction).dot(n).atan2(t.params.direction.dot(p.direction));
                assert!((angle + std::f64::consts::FRAC_PI_2).abs() < 1e-9, "{name}: part {} turned {angle}", t.id);
            }
        }
    }

    #[test]
    fn clicks_shift_clicks_and_lassos_select() {
        let mut s = Selection::default();
        s.click(Some(3));
        assert_eq!(s, Selection { parts: vec![3], reference: Some(3) });
        s.toggle(5);
        s.toggle(8);
        assert_eq!((s.parts.clone(), s.reference), (vec![3, 5, 8], Some(3)));
        s.click(Some(8));
        assert_eq!(
            (s.parts.clone(), s.reference),
            (vec![3, 5, 8], Some(8)),
            "a click on a selected part makes it the reference"
        );
        s.toggle(8);
        assert_eq!((s.parts.clone(), s.reference), (vec![3, 5], Some(3)));
        s.click(Some(11));
        assert_eq!((s.parts.clone(), s.reference), (vec![11], Some(11)));
        s.click(None);
        assert!(s.is_empty() && s.reference.is_none());

        let square = [DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0), DVec2::new(10.0, 10.0), DVec2::new(0.0, 10.0)];
        assert!(inside_polygon(DVec2::new(5.0, 5.0), &square));
        assert!(!inside_polygon(DVec2::new(15.0, 5.0), &square));
        // A concave lasso (a U): its notch is outside.
        let u = [(0.0, 0.0), (3.0, 0.0), (3.0, 7.0), (7.0, 7.0), (7.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
            .map(DVec2::from);
        assert!(!inside_polygon(DVec2::new(5.0, 3.0), &u));
        assert!(inside_polygon(DVec2::new(5.0, 8.5), &u) && inside_polygon(DVec2::new(1.0, 1.0), &u));

        let (_, view) = views().remove(2);
        let boxes: Vec<(u32, PartBox)> = [(1, [-2.0, 0.0, 0.0]), (2, [2.0, 0.0, 0.0]), (3, [-0.5, 2.0, 0.0])]
            .iter()
            .map(|&(id, c)| (id, PartBox::from_record(&record(id, c).obb)))
            .collect();
        // A box around the right half of the screen.
        let right = [(400.0, 0.0), (800.0, 0.0), (800.0, 600.0), (400.0, 600.0)].map(DVec2::from);
        assert_eq!(parts_in_lasso(&right, &view, &boxes), vec![2]);
        let mut s = Selection::default();
        s.lasso(&[2], false);
        s.lasso(&[1, 2], true);
        assert_eq!((s.parts.clone(), s.reference), (vec![2, 1], Some(2)));
        s.lasso(&[3], false);
        assert_eq!((s.parts.clone(), s.reference), (vec![3], Some(3)));
    }

    #[test]
    fn keyboard_adjustments_stay_in_range_and_cycle() {
        let p = PartParams::from_record(&record(0, [0.0; 3]));
        assert_eq!(Adjust::Q(1).apply(&p).q, 11);
        assert_eq!(Adjust::Q(-100).apply(&p).q, 1);
        assert_eq!(Adjust::Q(1000).apply(&p).q, 255);
        assert_eq!(Adjust::F(1).apply(&p).f, 0.55);
        assert_eq!(Adjust::F(-20).apply(&p).f, 0.0);
        assert_eq!(Adjust::F(20).apply(&p).f, 1.0);
        assert_eq!(Adjust::P(1).apply(&p).p, 1.25);
        assert_eq!(Adjust::P(-100).apply(&p).p, 0.01);
        let mut q = p;
        let mut styles = Vec::new();
        for _ in 0..=PartStyle::ALL.len() {
            q = Adjust::NextStyle.apply(&q);
            styles.push(q.style);
        }
        assert_eq!(styles.len(), 8);
        assert_eq!(styles.last(), Some(&None), "after the last style: the scene's again");
        let mut q = p;
        let mut tones = Vec::new();
        for _ in 0..=FLAT_GREYS.len() {
            q = Adjust::NextFlat.apply(&q);
            tones.push(q.flat);
        }
        assert_eq!(tones, [Some(0.0), Some(0.25), Some(0.5), Some(0.75), Some(1.0), None]);
        let mut q = p;
        for _ in 0..TransferCurve::ALL.len() {
            q = Adjust::NextTransfer.apply(&q);
        }
        assert_eq!(q.transfer, p.transfer);
    }

    #[test]
    fn records_keep_the_bakes_projector_matrix_and_round_trip() {
        let r = record(2, [1.0e6, -3.5, 0.25]);
        let p = PartParams::from_record(&r);
        let projector = Projector { anchor: p.anchor, direction: p.direction, scale: p.scale };
        assert_eq!(r.projector.matrix, projector.matrix().to_cols_array());
        assert_eq!(p.to_record(&r), r);
        assert!(drafter_format::validate_part_record(&r).is_ok());
    }

    #[test]
    fn undo_and_redo_restore_every_part_exactly() {
        let (_, view) = views().remove(0);
        let mut editor = Editor::new(vec![Some(record(0, [0.0; 3])), None, Some(record(2, [1.0, 1.0, 0.0]))]);
        let original: Vec<PartRecord> = editor.records().cloned().collect();
        editor.selection.click(Some(0));
        editor.selection.toggle(2);
        editor.selection.toggle(1); // not baked: selected, never edited
        assert!(editor.begin(Tool::Anchor, DVec2::new(400.0, 300.0)));
        assert_eq!(editor.drag_to(&view, DVec2::new(420.0, 310.0)), vec![0, 2]);
        assert_eq!(editor.drag_to(&view, DVec2::new(450.0, 330.0)), vec![0, 2]);
        assert!(editor.end());
        let dragged: Vec<PartRecord> = editor.records().cloned().collect();
        assert_eq!(editor.adjust(Adjust::Q(3)), vec![0, 2]);
        assert_eq!(editor.params(2).unwrap().q, 13);
        assert_eq!(editor.unsaved(), vec![0, 2]);
        assert_eq!(editor.undo(), vec![0, 2]);
        assert_eq!(editor.records().cloned().collect::<Vec<_>>(), dragged);
        assert_eq!(editor.undo(), vec![0, 2]);
        assert_eq!(editor.records().cloned().collect::<Vec<_>>(), original, "two undos: the file as loaded");
        assert!(editor.undo().is_empty());
        editor.redo();
        editor.redo();
        assert_eq!(editor.params(0).unwrap().q, 13);
        // A new edit drops the redo branch.
        editor.undo();
        editor.adjust(Adjust::NextStyle);
        assert!(editor.redo().is_empty());
        editor.mark_saved();
        assert!(editor.unsaved().is_empty());
        let toml = editor.overrides_toml("x.glb").expect("edits to export");
        assert_eq!(toml.matches("[[part]]").count(), 2, "{toml}");
        assert!(toml.contains("style = \"gradient\""), "{toml}");
    }

    #[test]
    fn a_held_slider_is_one_undo_step_from_where_it_was_grabbed() {
        let mut editor = Editor::new(vec![Some(record(0, [0.0; 3])), Some(record(1, [3.0, 0.0, 0.0]))]);
        editor.selection.click(Some(0));
        editor.selection.toggle(1);
        // Dragged through three values: each applies to the grabbed parameters, none is a step.
        for q in [12, 40, 25] {
            assert_eq!(editor.adjust_live(Adjust::SetQ(q)), vec![0, 1]);
        }
        assert!(!editor.can_undo());
        assert!(editor.end_live());
        assert_eq!((editor.params(0).unwrap().q, editor.params(1).unwrap().q), (25, 25));
        assert_eq!(editor.undo(), vec![0, 1]);
        assert_eq!((editor.params(0).unwrap().q, editor.params(1).unwrap().q), (10, 10));
        assert!(!editor.can_undo(), "one step only");
        assert_eq!(editor.redo(), vec![0, 1]);
        assert_eq!(editor.params(1).unwrap().q, 25);
        // A release without a change adds nothing; the set values are clamped.
        assert!(!editor.end_live());
        editor.adjust_live(Adjust::SetFlat(Some(2.0)));
        assert!(editor.end_live());
        editor.adjust_live(Adjust::SetP(f32::NAN));
        assert!(!editor.end_live());
        assert_eq!(editor.params(0).unwrap().flat, Some(1.0));
        assert_eq!(editor.params(0).unwrap().p, 1.0);
        let style = Adjust::SetStyle(Some(PartStyle::Hatch)).apply(&editor.params(0).unwrap());
        assert_eq!(style.style, Some(PartStyle::Hatch));
        assert_eq!(Adjust::SetQ(0).apply(&style).q, 1);
    }
}
