//! `make-samples [OUT_DIR]`: writes bracket.glb, gear.glb, shaft.glb and assembly.glb into OUT_DIR (default: the
//! `samples/` crate folder, where they are committed).

use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "usage: make-samples [OUT_DIR]\n\nWrites bracket.glb, gear.glb, shaft.glb and assembly.glb into \
                     OUT_DIR (default: the samples/ crate folder).";

fn main() -> ExitCode {
    let args: Vec<_> = std::env::args_os().skip(1).collect();
    let dir = match args.as_slice() {
        [] => PathBuf::from(env!("CARGO_MANIFEST_DIR")),
        [flag] if flag == "-h" || flag == "--help" => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        [dir] => PathBuf::from(dir),
        _ => {
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("error: cannot create {}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    match drafter_samples::write_samples(&dir) {
        Ok(written) => {
            for (path, size) in written {
                println!("{:>9} bytes  {}", size, path.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
