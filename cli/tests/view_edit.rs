//! The scripted editing session: `drafter view` in a real window on a virtual X display
//! (Xvfb), driven by xdotool as a user would — select two parts (click, shift-click), drag the
//! anchor with the anchor tool, raise q twice, save, quit — then `drafter inspect` shows the new
//! values, the file reads back with only those two part records changed, and a headless render of
//! the saved file differs from the original's only on those two parts' pixels.
//!
//! A second session checks what a user is told in the window: a save over a read-only file is
//! refused (the title says why, the file stays), a save keeps a 0600 file 0600, `Esc` with unsaved
//! edits asks before quitting, and `Ctrl`+`E` on a plain OBJ writes nothing and says so.
//!
//! Xvfb and xdotool are installed by scripts/test; without them these tests fail (they never skip).
//! The sessions take turns (one window at a time on a 2-core machine), and the second waits for
//! what it expects (the title, the log) rather than for fixed times.

mod common;

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use drafter_format::PartRecord;
use drafter_render::{Model, RenderOptions, Renderer, Style, View};

const SIZE: (u32, u32) = (800, 600);
/// Time for the window to draw after an input on lavapipe (a frame is ~0.2 s at this size).
const SETTLE: Duration = Duration::from_millis(1200);
/// The longest wait for a window to show what an input should change (a loaded machine).
const PATIENCE: Duration = Duration::from_secs(60);

/// One window session at a time.
static WINDOWS: Mutex<()> = Mutex::new(());

/// A virtual X server on a free display, stopped on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Xvfb {
        let tool = |name: &str| {
            let found = Command::new("sh").arg("-c").arg(format!("command -v {name}")).output().expect("sh runs");
            assert!(found.status.success(), "{name} is missing: scripts/test installs it (apt xvfb xdotool)");
        };
        tool("Xvfb");
        tool("xdotool");
        for n in (0..50).map(|k| 150 + (std::process::id() + k) % 400) {
            if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() || Path::new(&format!("/tmp/.X{n}-lock")).exists() {
                continue;
            }
            let display = format!(":{n}");
            let mut child = Command::new("Xvfb")
                .args([display.as_str(), "-screen", "0", "1280x1024x24", "-nolisten", "tcp"])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("Xvfb starts");
            let started = Instant::now();
            while started.elapsed() < Duration::from_secs(10) {
                if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
                    return Xvfb { child, display };
                }
                if child.try_wait().expect("Xvfb status").is_some() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(50));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        panic!("no Xvfb display could be started");
    }

    fn xdotool(&self, args: &[&str]) -> String {
        let out = Command::new("xdotool").args(args).env("DISPLAY", &self.display).output().expect("xdotool runs");
        assert!(out.status.success(), "xdotool {args:?}: {}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).trim().to_owned()
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The options `drafter view FILE --size 800x600` starts with (see cli/src/cmd/view.rs).
fn window_options() -> RenderOptions {
    RenderOptions {
        size: SIZE,
        style: Style::Gradient,
        view: View { azimuth_deg: 35.0, elevation_deg: 25.0 },
        ..RenderOptions::default()
    }
}

fn render(path: &Path) -> (Vec<u8>, Vec<Option<u32>>) {
    let model = Model::load(path).expect("loads");
    let mut renderer = Renderer::new().expect("lavapipe");
    renderer.set_model(&model).expect("uploads");
    let image = renderer.render(&window_options()).expect("renders");
    let map = renderer.part_map().expect("reads back").expect("a frame");
    assert_eq!(map.size, SIZE);
    (image.rgba, map.ids)
}

/// A pixel well inside part `id` (its 9×9 neighbourhood all that part), nearest its region's
/// centroid, left of the editing panel (anchored to the window's top-right corner, 8 points in).
fn inside(ids: &[Option<u32>], id: u32) -> Option<(i32, i32)> {
    let (w, h) = (SIZE.0 as i32, SIZE.1 as i32);
    let at = |x: i32, y: i32| ids[(y * w + x) as usize];
    let pixels: Vec<(i32, i32)> =
        (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).filter(|&(x, y)| at(x, y) == Some(id)).collect();
    let n = pixels.len().max(1) as i64;
    let (cx, cy) = (
        pixels.iter().map(|p| i64::from(p.0)).sum::<i64>() / n,
        pixels.iter().map(|p| i64::from(p.1)).sum::<i64>() / n,
    );
    pixels
        .into_iter()
        .filter(|&(x, y)| {
            x >= 4
                && y >= 4
                && x < w - 16 - drafter_app::panel::PANEL_WIDTH as i32
                && y < h - 4
                && (-4..=4).all(|dy| (-4..=4).all(|dx| at(x + dx, y + dy) == Some(id)))
        })
        .min_by_key(|&(x, y)| (i64::from(x) - cx).pow(2) + (i64::from(y) - cy).pow(2))
}

fn records(path: &Path) -> Vec<PartRecord> {
    let bytes = std::fs::read(path).expect("reads");
    drafter_format::read(&bytes, &|_| None).expect("baked").parts().into_iter().cloned().collect()
}

#[test]
fn a_scripted_session_selects_drags_raises_q_and_saves_only_those_parts() {
    let dir = common::scratch("view-edit");
    let file = dir.join("sample.glb");
    let original = dir.join("original.glb");
    assert!(common::drafter().args(["bake", "-o"]).arg(&file).arg("--quiet").status().expect("bakes").success());
    std::fs::copy(&file, &original).expect("copy");

    // Two parts large on screen, and a point well inside each.
    let (before_rgba, ids) = render(&file);
    let mut counts = std::collections::BTreeMap::<u32, usize>::new();
    for id in ids.iter().flatten() {
        *counts.entry(*id).or_default() += 1;
    }
    let mut by_size: Vec<(u32, usize)> = counts.into_iter().collect();
    by_size.sort_by_key(|&(id, n)| (std::cmp::Reverse(n), id));
    let (a, b) = (by_size[0].0, by_size[1].0);
    let (pa, pb) = (inside(&ids, a).expect("a point inside"), inside(&ids, b).expect("a point inside"));

    let _turn = WINDOWS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let x = Xvfb::start();
    let log = dir.join("view.log");
    let mut view = common::drafter()
        .args(["view", "--size", "800x600"])
        .arg(&file)
        .env("DISPLAY", &x.display)
        .stdout(std::fs::File::create(&log).expect("log"))
        .stderr(Stdio::piped())
        .spawn()
        .expect("drafter view starts");
    let pid = view.id().to_string();
    let window = x.xdotool(&["search", "--sync", "--onlyvisible", "--pid", &pid]);
    let window = window.lines().next().expect("a window").to_owned();
    std::thread::sleep(SETTLE * 2);
    let step = |args: &[&str]| {
        x.xdotool(&["windowfocus", "--sync", &window]);
        x.xdotool(args);
        std::thread::sleep(SETTLE);
    };
    let point = |p: (i32, i32)| [p.0.to_string(), p.1.to_string()];
    let [ax, ay] = point(pa);
    let [bx, by] = point(pb);
    step(&["mousemove", "--window", &window, &ax, &ay, "click", "1"]);
    step(&["key", "p"]);
    step(&["mousemove", "--window", &window, &bx, &by, "keydown", "shift", "click", "1", "keyup", "shift"]);
    step(&["key", "p"]);
    step(&["key", "a"]);
    let drag: Vec<String> = (1..=8).map(|k| (pa.0 + 15 * k).to_string()).collect();
    let mut args = vec!["mousemove", "--window", &window, &ax, &ay, "mousedown", "1"];
    for dx in &drag {
        args.extend(["mousemove", "--window", &window, dx, &ay]);
    }
    args.extend(["mouseup", "1"]);
    step(&args);
    step(&["key", "p"]);
    step(&["key", "bracketright", "bracketright"]);
    step(&["key", "p"]);
    step(&["key", "ctrl+s"]);
    step(&["key", "q"]);
    let started = Instant::now();
    let status = loop {
        if let Some(status) = view.try_wait().expect("status") {
            break status;
        }
        assert!(started.elapsed() < Duration::from_secs(20), "drafter view did not quit");
        std::thread::sleep(Duration::from_millis(100));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(view.stderr.as_mut().expect("stderr"), &mut stderr).expect("stderr");
    let stdout = std::fs::read_to_string(&log).expect("log");
    assert!(status.success(), "{status}\nstdout:\n{stdout}\nstderr:\n{stderr}");
    assert!(stdout.contains("selected 2 parts:"), "{stdout}");
    assert!(stdout.contains("tool: anchor"), "{stdout}");
    assert!(stdout.contains("saved: "), "{stdout}\n{stderr}");
    assert_eq!(stdout.matches("screenshot: ").count(), 4, "{stdout}");
    let leftovers: Vec<String> = std::fs::read_dir(&dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    // The file: parts a and b have q 12 and moved anchors; every other record is unchanged.
    let (old, new) = (records(&original), records(&file));
    for (o, n) in old.iter().zip(&new) {
        if [a, b].contains(&o.id) {
            assert_eq!(n.gradient.q, o.gradient.q + 2.0, "part {}", o.id);
            assert_ne!(n.projector.anchor, o.projector.anchor, "part {}", o.id);
            assert_eq!((&n.obb, &n.name, n.projector.direction), (&o.obb, &o.name, o.projector.direction));
        } else {
            assert_eq!(n, o, "part {} changed", o.id);
        }
    }
    let inspect = common::run(&["inspect", file.to_str().expect("utf-8")]);
    let table = String::from_utf8_lossy(&inspect.stdout);
    for id in [a, b] {
        let row = table
            .lines()
            .find(|l| l.split_whitespace().next() == Some(&id.to_string()) && l.contains(&new[id as usize].name))
            .unwrap_or_else(|| panic!("part {id} in:\n{table}"));
        assert!(row.contains(&format!("{}/0.5/1", old[id as usize].gradient.q + 2.0)), "{row}");
    }

    // A headless render of the saved file differs from the original's only on parts a and b.
    let (after_rgba, after_ids) = render(&file);
    assert_eq!(after_ids, ids, "the geometry is the same");
    let mut changed = 0;
    for (k, (p, q)) in before_rgba.chunks_exact(4).zip(after_rgba.chunks_exact(4)).enumerate() {
        if p != q {
            changed += 1;
            assert!(ids[k].is_some_and(|id| id == a || id == b), "pixel {k} of part {:?} changed", ids[k]);
        }
    }
    assert!(changed > 100, "only {changed} pixels changed");
    for n in 1..=4 {
        assert!(dir.join(format!("sample-{n}.png")).is_file(), "screenshot {n}");
    }
    let _: PathBuf = dir;
}

/// `drafter view` on `file` in `x`, its stdout in `log`: the child and its window's id.
fn open_window(x: &Xvfb, file: &Path, log: &Path) -> (Child, String) {
    let child = common::drafter()
        .args(["view", "--size", "800x600"])
        .arg(file)
        .env("DISPLAY", &x.display)
        .stdout(std::fs::File::create(log).expect("log"))
        .stderr(Stdio::piped())
        .spawn()
        .expect("drafter view starts");
    let window = x.xdotool(&["search", "--sync", "--onlyvisible", "--pid", &child.id().to_string()]);
    let window = window.lines().next().expect("a window").to_owned();
    (child, window)
}

/// Waits until `ready` holds, up to [`PATIENCE`]; `what` names it in the failure, with `state()`.
fn wait_for(what: &str, mut ready: impl FnMut() -> bool, state: impl Fn() -> String) {
    let started = Instant::now();
    while !ready() {
        assert!(started.elapsed() < PATIENCE, "waited {PATIENCE:?} for {what}; {}", state());
        std::thread::sleep(Duration::from_millis(200));
    }
}

fn mode(path: &Path) -> u32 {
    std::fs::metadata(path).expect("stat").permissions().mode() & 0o7777
}

fn set_mode(path: &Path, mode: u32) {
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).expect("chmod");
}

#[test]
fn the_window_refuses_a_read_only_file_keeps_a_0600_one_and_asks_before_quitting_unsaved() {
    let dir = common::scratch("view-save");
    let file = dir.join("sample.glb");
    assert!(common::drafter().args(["bake", "-o"]).arg(&file).arg("--quiet").status().expect("bakes").success());
    let (_, ids) = render(&file);
    let mut counts = std::collections::BTreeMap::<u32, usize>::new();
    for id in ids.iter().flatten() {
        *counts.entry(*id).or_default() += 1;
    }
    let part = counts.iter().max_by_key(|&(id, n)| (n, std::cmp::Reverse(id))).map(|(&id, _)| id).expect("a part");
    let (px, py) = inside(&ids, part).expect("a point inside");
    let (px, py) = (px.to_string(), py.to_string());
    let original = std::fs::read(&file).expect("reads");
    let q = records(&file)[part as usize].gradient.q;
    set_mode(&file, 0o444);

    let _turn = WINDOWS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let x = Xvfb::start();
    let log = dir.join("view.log");
    let (mut view, window) = open_window(&x, &file, &log);
    let stdout = || std::fs::read_to_string(&log).unwrap_or_default();
    let title = || x.xdotool(&["getwindowname", &window]);
    let input = |args: &[&str]| {
        x.xdotool(&["windowfocus", "--sync", &window]);
        x.xdotool(args);
    };
    let state = || format!("title {:?}\nstdout:\n{}", title(), stdout());
    // The first frame is drawn (the window's first click picks from it).
    wait_for("the first frame", || title().contains("drafter — sample.glb"), state);
    std::thread::sleep(SETTLE);
    input(&["mousemove", "--window", &window, &px, &py, "click", "1"]);
    wait_for("the part to be selected", || stdout().contains("selected 1 part:"), state);
    input(&["key", "bracketright"]);
    wait_for("an unsaved edit", || title().contains("| unsaved"), state);

    // Ctrl+S on a read-only file: refused, said in the window, the file as it was.
    input(&["key", "ctrl+s"]);
    wait_for("the refusal in the window", || title().contains("not saved"), state);
    assert!(title().contains("read-only (mode 0444); not replaced"), "{}", state());
    assert_eq!(std::fs::read(&file).expect("reads"), original, "a read-only file was replaced");
    assert_eq!(mode(&file), 0o444);

    // Esc with the unsaved edit asks and stays open.
    input(&["key", "Escape"]);
    wait_for("the question", || title().contains("Unsaved edits (1 part): press Esc again to quit"), state);
    std::thread::sleep(SETTLE);
    assert!(view.try_wait().expect("status").is_none(), "Esc quit with unsaved edits; {}", state());

    // Writable by its owner only: the save goes through and the file stays 0600.
    set_mode(&file, 0o600);
    input(&["key", "ctrl+s"]);
    wait_for("the save", || title().contains("saved: sample.glb (1 part record changed)"), state);
    assert_eq!(mode(&file), 0o600, "a save changed the file's mode");
    assert_eq!(records(&file)[part as usize].gradient.q, q + 1.0);

    // Another edit, then Esc twice: asked, then quit without saving it.
    input(&["key", "bracketright"]);
    wait_for("a second unsaved edit", || title().contains("| unsaved"), state);
    input(&["key", "Escape"]);
    wait_for("the question again", || title().contains("Unsaved edits"), state);
    assert!(view.try_wait().expect("status").is_none(), "Esc quit with unsaved edits; {}", state());
    input(&["key", "Escape"]);
    let started = Instant::now();
    let status = loop {
        if let Some(status) = view.try_wait().expect("status") {
            break status;
        }
        assert!(started.elapsed() < PATIENCE, "the second Esc did not quit; {}", state());
        std::thread::sleep(Duration::from_millis(100));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(view.stderr.as_mut().expect("stderr"), &mut stderr).expect("stderr");
    assert!(status.success(), "{status}\nstdout:\n{}\nstderr:\n{stderr}", stdout());
    let refused = format!("drafter: not saved: {}: read-only (mode 0444); not replaced\n", file.display());
    assert_eq!(stderr.matches(&refused).count(), 1, "{refused:?} once in:\n{stderr}");
    assert_eq!(stdout().matches("Unsaved edits (1 part): press Esc again").count(), 2, "{}", stdout());
    assert_eq!(records(&file)[part as usize].gradient.q, q + 1.0, "the edit after the save was not saved");
    assert_eq!(mode(&file), 0o600);

    // Ctrl+E on a plain OBJ: nothing to export, nothing written, and Esc quits at once.
    let obj = dir.join("plain.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n").expect("obj");
    let log = dir.join("plain.log");
    let (mut view, window) = open_window(&x, &obj, &log);
    let stdout = || std::fs::read_to_string(&log).unwrap_or_default();
    let title = || x.xdotool(&["getwindowname", &window]);
    let state = || format!("title {:?}\nstdout:\n{}", title(), stdout());
    wait_for("the first frame", || title().contains("drafter — plain.obj"), state);
    x.xdotool(&["windowfocus", "--sync", &window]);
    x.xdotool(&["key", "ctrl+e"]);
    wait_for("the export's answer", || title().contains("nothing to export"), state);
    assert!(stdout().contains("nothing to export: plain.obj is not baked"), "{}", stdout());
    assert!(!dir.join("plain.edits.toml").exists(), "an edits file was written");
    x.xdotool(&["windowfocus", "--sync", &window]);
    x.xdotool(&["key", "Escape"]);
    let started = Instant::now();
    while view.try_wait().expect("status").is_none() {
        assert!(started.elapsed() < PATIENCE, "Esc did not quit without edits; {}", state());
        std::thread::sleep(Duration::from_millis(100));
    }
}
