//! A stable, in-process mutation fuzzer for drafter's hostile-input contract: no panic,
//! no internal error, no runaway time or memory on any input.
//!
//! # How it works
//! Each [`Target`] is one entry point fed with bytes: the six importers (through
//! [`drafter_io::import_bytes`], then the whole [`drafter_bake::bake`] of whatever imports, then
//! drafter-format's reader on the bake's own output), and the baked-file side (drafter-format's
//! readers and the CPU model the renderer and the drawings build, [`drafter_scene::Model::load_bytes`],
//! plus one silhouette query). A case takes a seed of its target ([`seeds`]), applies one to four
//! mutations ([`mutate`]: byte flips, truncation, splices between seeds, number mutations,
//! structure-aware JSON mutations for glTF, header mutations for OBJ/PLY/OFF/STL) and runs it under
//! `catch_unwind`. A case is a finding when it panics, returns an internal error (what the CLI maps
//! to exit 1), runs past the time budget or grows the process's peak memory past the memory budget
//! ([`campaign`]).
//!
//! Everything is deterministic: case `n` of target `t` under seed `s` is the same bytes on every
//! machine (SplitMix64, drafter-testkit's `Rng`, seeded by `s`, `t` and `n`), so a campaign's counts
//! reproduce exactly; only the time-boxed mode (`--minutes`) depends on the machine's speed.
//!
//! No nightly toolchain and no coverage feedback: this is a black-box mutator, which is what a fresh
//! machine can always run. The CI runs a bounded number of cases per target (`tests/smoke.rs`);
//! long campaigns run the binary in release (`docs/fuzzing.md`).

pub mod campaign;
pub mod mutate;
pub mod seeds;

use std::panic::AssertUnwindSafe;
use std::path::Path;

use drafter_bake::{BakeConfig, BakeError};
use drafter_scene::Model;
use drafter_scene::edges::WorldView;

pub use drafter_testkit::Rng;

/// One entry point under test; its name is the folder of its findings and regressions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, clap::ValueEnum)]
pub enum Target {
    /// glTF JSON with embedded (data: URI) buffers, imported then baked.
    Gltf,
    /// Binary glTF, imported then baked.
    Glb,
    /// Wavefront OBJ, imported then baked.
    Obj,
    /// ASCII STL, imported then baked.
    StlAscii,
    /// Binary STL, imported then baked.
    StlBinary,
    /// OFF, imported then baked.
    Off,
    /// PLY (ASCII and binary little-endian), imported then baked.
    Ply,
    /// A baked .glb: drafter-format's readers and drafter-scene's model building (CPU only).
    Baked,
}

impl Target {
    pub const ALL: [Target; 8] = [
        Target::Gltf,
        Target::Glb,
        Target::Obj,
        Target::StlAscii,
        Target::StlBinary,
        Target::Off,
        Target::Ply,
        Target::Baked,
    ];

    /// The folder name of this target under `tests/regressions/` and a findings folder.
    pub fn name(self) -> &'static str {
        match self {
            Target::Gltf => "gltf",
            Target::Glb => "glb",
            Target::Obj => "obj",
            Target::StlAscii => "stl-ascii",
            Target::StlBinary => "stl-binary",
            Target::Off => "off",
            Target::Ply => "ply",
            Target::Baked => "baked",
        }
    }

    pub fn from_name(name: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == name)
    }

    /// The file name a case is imported as (the extension breaks ties in format detection).
    pub fn file_name(self) -> &'static str {
        match self {
            Target::Gltf => "case.gltf",
            Target::Glb | Target::Baked => "case.glb",
            Target::Obj => "case.obj",
            Target::StlAscii | Target::StlBinary => "case.stl",
            Target::Off => "case.off",
            Target::Ply => "case.ply",
        }
    }
}

/// How one case ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Imported and baked, or read and loaded.
    Accepted,
    /// Refused with a typed input error (what the CLI reports as exit 2, one line).
    Rejected(String),
    /// A typed internal error (exit 1): a bug.
    Internal(String),
    /// A panic, caught; the message and its place.
    Panic(String),
}

impl Outcome {
    /// Whether this case breaks the contract (a panic or an internal error).
    pub fn is_finding(&self) -> bool {
        matches!(self, Outcome::Internal(_) | Outcome::Panic(_))
    }
}

/// Runs `bytes` through `target` under `catch_unwind`. `dir` is the folder the case is named in
/// (its external URIs resolve there; keep it empty). Rayon's pool is whatever the caller set up.
/// Panics are caught but still reach the panic hook: [`campaign::quiet_panics`] silences it and
/// keeps the message.
pub fn run_case(target: Target, bytes: &[u8], dir: &Path) -> Outcome {
    let path = dir.join(target.file_name());
    let result = std::panic::catch_unwind(AssertUnwindSafe(|| match target {
        Target::Baked => load_baked(&path, bytes),
        _ => import_and_bake(&path, bytes),
    }));
    match result {
        Ok(outcome) => outcome,
        Err(payload) => Outcome::Panic(campaign::take_panic_message(payload.as_ref())),
    }
}

fn import_and_bake(path: &Path, bytes: &[u8]) -> Outcome {
    let imported = match drafter_io::import_bytes(path, bytes) {
        Ok(imported) => imported,
        Err(e) => return Outcome::Rejected(e.to_string()),
    };
    let baked = match drafter_bake::bake(&imported.scene, &BakeConfig::default()) {
        Ok(baked) => baked,
        Err(e @ BakeError::Input(_)) => return Outcome::Rejected(e.to_string()),
        Err(e) => return Outcome::Internal(e.to_string()),
    };
    // What the bake writes, drafter-format must read back.
    match drafter_format::read(&baked.written.main, &|_| None) {
        Ok(_) => Outcome::Accepted,
        Err(e) => Outcome::Internal(format!("the bake's output does not read back: {e}")),
    }
}

fn load_baked(path: &Path, bytes: &[u8]) -> Outcome {
    let none = |_: &str| None;
    // The readers `inspect` runs; each may refuse, none may panic.
    let _ = drafter_format::read(bytes, &none);
    let _ = drafter_format::read_textures(bytes, &none);
    let _ = drafter_format::read_normal_sets(bytes, &none);
    let _ = drafter_format::byte_sections(bytes, &none);
    let model = match Model::load_bytes(path, bytes) {
        Ok(model) => model,
        Err(e) => return Outcome::Rejected(e.to_string()),
    };
    // What the renderer asks of a model on the CPU before and during a frame.
    let _ = model.part_table();
    let _ = model.triangle_count();
    if !model.lines.is_empty() {
        let corner = model.bounds.max - model.origin;
        let _ = model.lines.silhouettes(WorldView::Perspective { eye: model.origin + corner * 3.0 + 1.0 });
        let _ = model.lines.silhouettes(WorldView::Orthographic { direction: glam::DVec3::new(0.3, -0.5, 0.8) });
        let _ = model.lines.hard_segments();
    }
    Outcome::Accepted
}
