//! The view controls the desktop window (drafter-app's `window`) and the browser page (`web/`) share:
//! the orbit a drag, the wheel and a pan change, and what a key does to the frame's options. Pure
//! functions of plain data, so both front ends behave alike and the tests need no display.

use crate::style::{Enhancements, RenderOptions, ShadowMode, Style, View, ZOOM_RANGE};

/// Degrees the object turns per pixel of drag.
pub const DEGREES_PER_PIXEL: f32 = 0.4;
/// Zoom factor per wheel line.
pub const ZOOM_PER_LINE: f32 = 1.1;
/// Pixels of wheel movement counted as one line (touchpads report pixels).
pub const PIXELS_PER_LINE: f32 = 40.0;
/// Largest elevation the orbit reaches, degrees (the renderer accepts (−90, 90)).
pub const MAX_ELEVATION_DEG: f32 = 89.0;
/// The view the mouse controls: the object's turn, the zoom and the pan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub view: View,
    pub zoom: f32,
    /// Normalised device units (see [`RenderOptions::pan`]).
    pub pan: [f32; 2],
}

impl Default for Orbit {
    fn default() -> Self {
        Orbit { view: View::default(), zoom: 1.0, pan: [0.0, 0.0] }
    }
}

impl Orbit {
    /// Turns the object by a drag of (`dx`, `dy`) pixels (x right, y down): dragging right turns
    /// the object's front to the right (the camera's azimuth decreases), dragging down tips its top
    /// towards the viewer (the elevation increases), clamped short of the poles.
    pub fn rotate(&mut self, dx: f32, dy: f32) {
        let az = self.view.azimuth_deg - dx * DEGREES_PER_PIXEL;
        self.view.azimuth_deg = az.rem_euclid(360.0);
        self.view.elevation_deg =
            (self.view.elevation_deg + dy * DEGREES_PER_PIXEL).clamp(-MAX_ELEVATION_DEG, MAX_ELEVATION_DEG);
    }

    /// Zooms by `lines` wheel lines (positive: closer), keeping the point under the frame's centre.
    pub fn zoom_by(&mut self, lines: f32) {
        let zoom = self.zoom * ZOOM_PER_LINE.powf(lines);
        let zoom = zoom.clamp(ZOOM_RANGE.0, ZOOM_RANGE.1);
        // The pan is applied after the zoom: scale it too so the image centre stays put.
        let k = zoom / self.zoom;
        self.pan = [self.pan[0] * k, self.pan[1] * k];
        self.zoom = zoom;
    }

    /// Pans by a drag of (`dx`, `dy`) pixels in a frame of `size` pixels: the image follows the
    /// cursor.
    pub fn pan_by(&mut self, dx: f32, dy: f32, size: (u32, u32)) {
        let (w, h) = (size.0.max(1) as f32, size.1.max(1) as f32);
        self.pan =
            [(self.pan[0] + 2.0 * dx / w).clamp(-100.0, 100.0), (self.pan[1] - 2.0 * dy / h).clamp(-100.0, 100.0)];
    }

    /// Writes the orbit into `options`.
    pub fn apply(&self, options: &mut RenderOptions) {
        options.view = self.view;
        options.zoom = self.zoom;
        options.pan = self.pan;
    }
}

/// What a key does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    SetStyle(Style),
    NextStyle,
    ToggleEdges,
    ToggleLines,
    NextShadow,
    ToggleOrthographic,
    ResetView,
    Screenshot,
    Quit,
}

/// The action of a typed character, if any (case-insensitive): `1`–`7` a style, `s` the next
/// style, `e` image-space edges, `l` baked lines, `h` the next shadow, `o` orthographic, `r` reset
/// the view, `p` screenshot, `q` quit.
pub fn action_for_char(c: char) -> Option<Action> {
    match c.to_ascii_lowercase() {
        c @ '1'..='7' => Some(Action::SetStyle(Style::ALL[(c as usize) - ('1' as usize)])),
        's' => Some(Action::NextStyle),
        'e' => Some(Action::ToggleEdges),
        'l' => Some(Action::ToggleLines),
        'h' => Some(Action::NextShadow),
        'o' => Some(Action::ToggleOrthographic),
        'r' => Some(Action::ResetView),
        'p' => Some(Action::Screenshot),
        'q' => Some(Action::Quit),
        _ => None,
    }
}

impl Action {
    /// Applies a view or style change to `options` and `orbit`; `false` for the actions the
    /// window carries out itself (screenshot, quit).
    pub fn apply(self, options: &mut RenderOptions, orbit: &mut Orbit) -> bool {
        match self {
            Action::SetStyle(s) => options.style = s,
            Action::NextStyle => {
                let k = Style::ALL.iter().position(|&s| s == options.style).unwrap_or(0);
                options.style = Style::ALL[(k + 1) % Style::ALL.len()];
            }
            Action::ToggleEdges => {
                options.enhancements =
                    if options.enhancements.any() { Enhancements::default() } else { Enhancements::ALL };
            }
            Action::ToggleLines => options.lines = !options.lines,
            Action::NextShadow => {
                let at = ShadowMode::ALL.iter().position(|&m| m == options.shadow).unwrap_or(0);
                options.shadow = ShadowMode::ALL[(at + 1) % ShadowMode::ALL.len()];
            }
            Action::ToggleOrthographic => options.orthographic = !options.orthographic,
            Action::ResetView => *orbit = Orbit::default(),
            Action::Screenshot | Action::Quit => return false,
        }
        true
    }
}
