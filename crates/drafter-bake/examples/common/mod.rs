//! What the survey examples share.

/// The scenes of the files named on the command line, in order, each with its path as given; a file
/// that does not import is reported on stderr and passed over.
pub fn scenes_from_args() -> impl Iterator<Item = (String, drafter_core::Scene)> {
    std::env::args().skip(1).filter_map(|path| match drafter_io::import(std::path::Path::new(&path)) {
        Ok(imported) => Some((path, imported.scene)),
        Err(e) => {
            eprintln!("{path}: {e}");
            None
        }
    })
}
