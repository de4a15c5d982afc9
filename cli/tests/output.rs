//! Output to a reader that stops early (`drafter inspect … | head`): every command that prints
//! ends quietly with exit 0, no panic message.

mod common;

use std::process::Stdio;

/// Runs drafter with its standard output closed before it writes anything.
fn closed_stdout(args: &[&str]) -> (std::process::ExitStatus, String) {
    let mut child =
        common::drafter().args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("spawns drafter");
    // The reader goes away at once: the command's first write meets a closed pipe.
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("waits");
    (out.status, String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn a_closed_stdout_is_not_an_error() {
    let fandisk = common::shared_models().join("obj/common-3d-test-models/fandisk.obj");
    let fandisk = fandisk.to_str().expect("utf-8 path");
    let baked = common::scratch("output-closed").join("fandisk.glb");
    let baked = baked.to_str().expect("utf-8 path");
    for args in [
        vec!["inspect", fandisk],
        vec!["inspect", fandisk, "--json"],
        vec!["bake", fandisk, "-o", baked, "--json"],
        vec!["bench", "silhouettes", fandisk, "--views", "4", "--json"],
    ] {
        let (status, stderr) = closed_stdout(&args);
        assert!(status.success(), "{args:?}: {status}, stderr: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}
