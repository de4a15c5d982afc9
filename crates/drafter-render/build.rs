//! The passes' WGSL as the binaries embed it: comments and indentation removed, every line kept (so
//! a shader error's line number is the source file's). The browser's module carries each pass's
//! source, the shared declarations once per pass that uses them; the comments are for the reader of
//! `src/passes/*.wgsl`, which the tests read as written. WGSL has no string literals, so `//` always
//! starts a comment.

use std::path::Path;

fn main() {
    let Some(out) = std::env::var_os("OUT_DIR") else { panic!("cargo sets OUT_DIR for build scripts") };
    let passes = Path::new("src/passes");
    println!("cargo:rerun-if-changed=src/passes");
    let entries = std::fs::read_dir(passes).unwrap_or_else(|e| panic!("{}: {e}", passes.display()));
    for entry in entries {
        let path = entry.unwrap_or_else(|e| panic!("{}: {e}", passes.display())).path();
        if path.extension().is_none_or(|e| e != "wgsl") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let stripped: String = text
            .lines()
            .map(|line| {
                let code = line.find("//").map_or(line, |i| &line[..i]);
                format!("{}\n", code.trim())
            })
            .collect();
        let Some(name) = path.file_name() else { continue };
        let target = Path::new(&out).join(name);
        std::fs::write(&target, stripped).unwrap_or_else(|e| panic!("{}: {e}", target.display()));
    }
}
