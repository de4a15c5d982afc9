//! `drafter view` without a display: one line on stderr, exit code 2, no panic (the window's event
//! handling itself is unit-tested in `drafter_app::window`); `drafter view --help` tells a new
//! user how to edit, save and export.

mod common;

#[test]
fn view_without_a_display_fails_with_one_line() {
    let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb");
    let out = common::drafter()
        .args(["view", sample.to_str().expect("utf-8 path")])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .expect("drafter runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("drafter: error")).collect();
    assert_eq!(errors.len(), 1, "stderr: {stderr}");
    assert!(errors[0].contains("cannot open a window"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn view_help_describes_editing_saving_exporting_and_the_manipulators() {
    let out = common::run(&["view", "--help"]);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for words in [
        "Editing the parts' gradients",
        "A, then drag         anchor",
        "X, then drag         scale",
        "D, then drag         direction",
        "V, then drag         draw the projector",
        "Ctrl+Z, Ctrl+Y       undo, redo",
        "Ctrl+S               save",
        "read-only file is refused",
        "Ctrl+E               export",
        "Esc again quits without saving",
    ] {
        assert!(help.contains(words), "{words:?} is not in drafter view --help:\n{help}");
    }
    let top = String::from_utf8_lossy(&common::run(&["--help"]).stdout).into_owned();
    let line = top.lines().find(|l| l.trim_start().starts_with("view")).expect("view in drafter --help");
    assert!(line.contains("edit"), "{line}");
}
