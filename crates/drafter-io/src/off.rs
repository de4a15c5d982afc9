//! OFF reader (the Object File Format of Geomview, as written by CGAL, MeshLab, trimesh and v-hacd).
//!
//! Hand-written rather than taken from a crate: no well-kept OFF crate reports the line of a fault or
//! refuses counts that the file cannot back, and both are required of every reader here.
//!
//! # What is read
//! * The header keyword `OFF`, optionally prefixed by `ST`, `C` and `N` (`COFF`, `NOFF`, `CNOFF`,
//!   `STOFF`, ...). The texture, colour and normal columns these announce are tolerated and ignored.
//! * The counts `vertices faces [edges]`, on the header line or a later one; the edge count is ignored.
//! * Comments (`#` to the end of the line) and blank lines anywhere.
//! * One vertex per line: `x y z`, then any further columns (ignored).
//! * One face per line: `n i0 i1 ... i(n-1)`, then any further columns (a face colour; ignored).
//!   Indices are 0-based; polygons are fan-triangulated around `i0`. Faces are numbered from 0 in
//!   messages, like vertices.
//! * Anything after the last face is ignored.
//!
//! Non-finite coordinates (`nan`, `inf`) are passed through: `raw` drops the faces that use them
//! with a diagnostic.
//!
//! # What is refused, with the line
//! Binary OFF (`OFF BINARY`), 4D and n-dimensional OFF (`4OFF`, `nOFF`), a vertex line with fewer
//! than 3 numbers, a token that is not a number, a face with fewer than 3 vertices or fewer indices
//! than it announces, a negative index or one `>=` the vertex count, a file that ends before the
//! counts are met, and counts the rest of the file cannot hold (blamed on the header line, unless a
//! record before the end is too short to be valid: a face `2 0 1` is shorter than any valid face,
//! and its own line is the better place to point at).
//!
//! # Safety rules
//! Nothing is allocated by a count until the bytes left can back it: a vertex takes at least 6
//! bytes (`0 0 0` and a separator), a face at least 8 (`3 0 1 2` and a separator), so a 100-byte
//! file claiming 4e9 vertices reserves room for at most 16 and fails at the end of its records.
//! Other allocations grow with the bytes actually read.
//! Bytes are reached only through `get`, counts through checked conversions: no input panics.

use crate::error::ParseError;
use crate::raw::RawMesh;

use text::{Tokens, fits, parse_f32, parse_i64, show};

/// Fewest bytes a valid vertex line can take: three one-digit numbers and their separators.
const MIN_VERTEX_BYTES: u64 = 6;
/// Fewest bytes a valid face line can take: `3 0 1 2` and its separators.
const MIN_FACE_BYTES: u64 = 8;

pub(crate) fn read(bytes: &[u8]) -> Result<RawMesh, ParseError> {
    if bytes.is_empty() {
        return Err(ParseError::in_file("empty file"));
    }
    let mut tokens = Tokens::new(bytes, 1, Some(b'#'));
    let keyword = tokens
        .next_token()
        .ok_or_else(|| ParseError::at_line(tokens.line(), "no OFF header, only comments and blank lines"))?;
    check_keyword(keyword).map_err(|message| ParseError::at_line(tokens.line(), message))?;
    let vertex_count = read_count(&mut tokens, "vertex")?;
    let face_count = read_count(&mut tokens, "face")?;
    let counts_line = tokens.line();
    tokens.skip_line(); // the edge count, if present, is not used

    if vertex_count > u64::from(u32::MAX) {
        return Err(ParseError::at_line(
            counts_line,
            format!("header says {vertex_count} vertices; 32-bit indices address at most {}", u32::MAX),
        ));
    }
    // A count the bytes left cannot back is refused at the header line, unless a record before the
    // end of the file is too short to be valid (a face `2 0 1`, a vertex of 2 coordinates), which is
    // what made the count look too large: that record's line is the better place to point at.
    let budget = Budget::of(&tokens, vertex_count, MIN_VERTEX_BYTES, counts_line);
    let positions = read_vertices(&mut tokens, vertex_count, budget.capacity).map_err(|fault| {
        budget.blame(fault, |room, most| {
            format!("header says {vertex_count} vertices but the {room} bytes left can hold at most {most}")
        })
    })?;
    let budget = Budget::of(&tokens, face_count, MIN_FACE_BYTES, counts_line);
    let triangles = read_faces(&mut tokens, face_count, vertex_count, budget.capacity).map_err(|fault| {
        budget.blame(fault, |room, most| {
            format!("header says {face_count} faces but the {room} bytes after the vertices can hold at most {most}")
        })
    })?;
    Ok(RawMesh { positions, triangles, normals: None })
}

/// Why a list of records could not be read.
enum Fault {
    /// A record is shorter than any valid one (fewer than 3 vertices or coordinates, or fewer
    /// indices than it announces) before the end of the file: its own line is to blame.
    Short(ParseError),
    /// A record is malformed otherwise (a token that is not a number, an index out of range).
    Record(ParseError),
    /// The file ended before the count was met, possibly inside a record.
    End(ParseError),
}

/// [`Fault::End`] where nothing but blanks and comments follows, [`Fault::Short`] otherwise: a
/// record that lacks values at the end of the file is a truncation, not a short record.
fn short_or_end(tokens: &Tokens<'_>, e: ParseError) -> Fault {
    if tokens.clone().next_token().is_none() { Fault::End(e) } else { Fault::Short(e) }
}

/// Whether the bytes left can back a list's count ([`fits`]), and the capacity to reserve: the
/// count where they can, otherwise as many records of the smallest valid size as the bytes hold.
struct Budget {
    fits: bool,
    capacity: usize,
    /// The bytes left and the most records they hold, for the header's message.
    room: (usize, u64),
    /// The line of the header's counts.
    counts_line: usize,
}

impl Budget {
    fn of(tokens: &Tokens<'_>, count: u64, min_bytes: u64, counts_line: usize) -> Budget {
        let room = text_room(tokens);
        let fits = fits(count, min_bytes, room);
        let most = room / min_bytes;
        // `fits` has bounded the count by the file length, so it also fits a usize.
        let capacity = usize::try_from(if fits { count } else { most }).unwrap_or(0);
        Budget { fits, capacity, room: (tokens.remaining(), most), counts_line }
    }

    /// The error to report for `fault`: a short record is its own line's fault; where the bytes
    /// could never hold the count, any other fault (the end of the file, a malformed record) is
    /// the header's (`header(room, most)` says so); otherwise the record's or the end's own.
    fn blame(&self, fault: Fault, header: impl Fn(usize, u64) -> String) -> ParseError {
        match fault {
            Fault::Short(e) => e,
            Fault::Record(e) | Fault::End(e) if self.fits => e,
            Fault::Record(_) | Fault::End(_) => ParseError::at_line(self.counts_line, header(self.room.0, self.room.1)),
        }
    }
}

/// Bytes available to records, counting the separator the last record may lack.
fn text_room(tokens: &Tokens<'_>) -> u64 {
    (tokens.remaining() as u64).saturating_add(1)
}

/// Accepts `[ST][C][N]OFF` in any order of the prefixes; refuses the 4D, n-dimensional and binary forms.
fn check_keyword(keyword: &[u8]) -> Result<(), String> {
    let Some(prefix) = keyword.strip_suffix(b"OFF") else {
        return Err(format!("expected an OFF header (OFF, COFF, NOFF, ...), found {}", show(keyword)));
    };
    if prefix.iter().all(|b| matches!(b, b'S' | b'T' | b'C' | b'N')) {
        Ok(())
    } else if prefix.iter().any(|b| matches!(b, b'4' | b'n')) {
        Err(format!("{} (4D or n-dimensional OFF) is not supported", show(keyword)))
    } else {
        Err(format!("unknown OFF header {}", show(keyword)))
    }
}

fn read_count(tokens: &mut Tokens<'_>, what: &str) -> Result<u64, ParseError> {
    let token = tokens.next_token().ok_or_else(|| {
        ParseError::at_line(tokens.line(), format!("unexpected end of file: expected the {what} count"))
    })?;
    if token.eq_ignore_ascii_case(b"BINARY") {
        return Err(ParseError::at_line(tokens.line(), "binary OFF is not supported"));
    }
    let count = std::str::from_utf8(token).ok().and_then(|t| t.parse::<u64>().ok());
    count.ok_or_else(|| ParseError::at_line(tokens.line(), format!("expected the {what} count, found {}", show(token))))
}

fn read_vertices(tokens: &mut Tokens<'_>, count: u64, capacity: usize) -> Result<Vec<[f32; 3]>, Fault> {
    let mut positions = Vec::with_capacity(capacity);
    for i in 0..count {
        let first = tokens.next_token().ok_or_else(|| {
            Fault::End(ParseError::at_line(
                tokens.line(),
                format!("unexpected end of file in vertex list (read {i} of {count} vertices)"),
            ))
        })?;
        let line = tokens.line();
        let mut position = [0.0f32; 3];
        for (k, coordinate) in position.iter_mut().enumerate() {
            let token = if k == 0 {
                first
            } else {
                let missing = ParseError::at_line(line, format!("vertex {i}: expected 3 coordinates, found {k}"));
                match tokens.next_on_line() {
                    Some(token) => token,
                    None => return Err(short_or_end(tokens, missing)),
                }
            };
            *coordinate = parse_f32(token).ok_or_else(|| {
                Fault::Record(ParseError::at_line(
                    line,
                    format!("vertex {i}: expected a number, found {}", show(token)),
                ))
            })?;
        }
        tokens.skip_line(); // colour, normal or texture columns
        positions.push(position);
    }
    Ok(positions)
}

fn read_faces(tokens: &mut Tokens<'_>, count: u64, vertex_count: u64, capacity: usize) -> Result<Vec<[u32; 3]>, Fault> {
    let mut triangles = Vec::with_capacity(capacity);
    for face in 0..count {
        let first = tokens.next_token().ok_or_else(|| {
            Fault::End(ParseError::at_line(
                tokens.line(),
                format!("unexpected end of file in face list (read {face} of {count} faces)"),
            ))
        })?;
        let line = tokens.line();
        let corners = parse_i64(first).ok_or_else(|| {
            Fault::Record(ParseError::at_line(
                line,
                format!("face {face}: expected a vertex count, found {}", show(first)),
            ))
        })?;
        if corners < 3 {
            return Err(Fault::Short(ParseError::at_line(
                line,
                format!("face {face} has {corners} vertices; a face needs at least 3"),
            )));
        }
        let mut index = |k: i64| -> Result<u32, Fault> {
            let Some(token) = tokens.next_on_line() else {
                let missing =
                    ParseError::at_line(line, format!("face {face}: expected {corners} vertex indices, found {k}"));
                return Err(short_or_end(tokens, missing));
            };
            vertex_index(token, face, vertex_count).map_err(|message| Fault::Record(ParseError::at_line(line, message)))
        };
        let apex = index(0)?;
        let mut previous = index(1)?;
        for k in 2..corners {
            let next = index(k)?;
            triangles.push([apex, previous, next]);
            previous = next;
        }
        tokens.skip_line(); // a face colour, if any
    }
    Ok(triangles)
}

/// Parses a 0-based vertex index of `face` and checks it against `vertex_count`.
fn vertex_index(token: &[u8], face: u64, vertex_count: u64) -> Result<u32, String> {
    let value =
        parse_i64(token).ok_or_else(|| format!("face {face}: expected a vertex index, found {}", show(token)))?;
    if value < 0 {
        return Err(format!("face {face} has negative vertex index {value}"));
    }
    match u32::try_from(value) {
        Ok(index) if u64::from(index) < vertex_count => Ok(index),
        _ => Err(format!("face {face} uses vertex {value} but the file has {vertex_count} vertices")),
    }
}

/// Tokens of the text formats, shared by the OFF, ASCII PLY and ASCII STL readers.
///
/// Every byte is reached through `get`, so no input can make these panic.
pub(crate) mod text {
    /// A cursor over whitespace-separated ASCII tokens that knows its 1-based line.
    ///
    /// `next_token` crosses line ends (and comments, when a comment byte is set); `next_on_line` stops
    /// at the end of the current line, which is how line-oriented records detect missing values.
    #[derive(Clone, Debug)]
    pub(crate) struct Tokens<'a> {
        bytes: &'a [u8],
        pos: usize,
        line: usize,
        comment: Option<u8>,
    }

    impl<'a> Tokens<'a> {
        /// `first_line` is the line number of `bytes[0]`; `comment` starts a comment that runs to the
        /// end of the line (`#` in OFF).
        pub(crate) fn new(bytes: &'a [u8], first_line: usize, comment: Option<u8>) -> Self {
            Self { bytes, pos: 0, line: first_line, comment }
        }

        /// The line of the last token returned (or of the cursor, past the last token).
        pub(crate) fn line(&self) -> usize {
            self.line
        }

        /// Bytes not yet consumed.
        pub(crate) fn remaining(&self) -> usize {
            self.bytes.len().saturating_sub(self.pos)
        }

        /// The next token on this or a later line, or `None` at the end of the input.
        pub(crate) fn next_token(&mut self) -> Option<&'a [u8]> {
            loop {
                let byte = *self.bytes.get(self.pos)?;
                if byte == b'\n' {
                    self.line += 1;
                    self.pos += 1;
                } else if byte.is_ascii_whitespace() {
                    self.pos += 1;
                } else if Some(byte) == self.comment {
                    self.pos = self.end_of_line();
                } else {
                    return Some(self.take_token());
                }
            }
        }

        /// The next token of the current line, or `None` at its end (or at a comment).
        pub(crate) fn next_on_line(&mut self) -> Option<&'a [u8]> {
            loop {
                let byte = *self.bytes.get(self.pos)?;
                if byte == b'\n' || Some(byte) == self.comment {
                    return None;
                } else if byte.is_ascii_whitespace() {
                    self.pos += 1;
                } else {
                    return Some(self.take_token());
                }
            }
        }

        /// Skips the rest of the current line and its line end.
        pub(crate) fn skip_line(&mut self) {
            let end = self.end_of_line();
            if end < self.bytes.len() {
                self.pos = end + 1;
                self.line += 1;
            } else {
                self.pos = end;
            }
        }

        /// Position of the next `\n`, or the input length.
        fn end_of_line(&self) -> usize {
            let rest = self.bytes.get(self.pos..).unwrap_or_default();
            self.pos + rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len())
        }

        fn take_token(&mut self) -> &'a [u8] {
            let start = self.pos;
            let rest = self.bytes.get(start..).unwrap_or_default();
            let len =
                rest.iter().position(|&b| b.is_ascii_whitespace() || Some(b) == self.comment).unwrap_or(rest.len());
            self.pos = start + len;
            rest.get(..len).unwrap_or_default()
        }
    }

    /// Parses a decimal float as `str::parse::<f32>` does (so `nan`, `inf` and `1e-3` are numbers).
    pub(crate) fn parse_f32(token: &[u8]) -> Option<f32> {
        std::str::from_utf8(token).ok()?.parse().ok()
    }

    /// Parses a decimal integer with an optional sign.
    pub(crate) fn parse_i64(token: &[u8]) -> Option<i64> {
        std::str::from_utf8(token).ok()?.parse().ok()
    }

    /// A token as it appears in a message: quoted, escaped, at most 24 characters.
    pub(crate) fn show(token: &[u8]) -> String {
        const MAX: usize = 24;
        let shown = String::from_utf8_lossy(token.get(..MAX).unwrap_or(token));
        let more = if token.len() > MAX { "..." } else { "" };
        format!("'{}{more}'", shown.escape_debug())
    }

    /// True when `count` records of at least `min_bytes` each fit in `room` bytes, without overflow.
    pub(crate) fn fits(count: u64, min_bytes: u64, room: u64) -> bool {
        count.checked_mul(min_bytes).is_some_and(|needed| needed <= room)
    }
}

/// Helpers shared by the tests of the STL, OFF and PLY readers.
#[cfg(test)]
pub(crate) mod testing {
    /// The shared test models, found relative to this crate: `../shared/models` beside the
    /// repository (`crates/drafter-io/../../../shared/models`).
    const MODELS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/models/");

    /// Reads one of the shared test models; panics (the test fails, never skips) when it is missing.
    pub(crate) fn model(relative: &str) -> Vec<u8> {
        let path = format!("{MODELS}{relative}");
        std::fs::read(&path).unwrap_or_else(|e| {
            panic!("test model {path} cannot be read ({e}); the real-file tests need ../shared/models beside the repository")
        })
    }

    /// Runs `f` and returns how far it raised the process's peak virtual size (VmPeak), in bytes.
    /// An allocation sized by a hostile header count (tens of GiB) shows up here even when the
    /// kernel lends the address space without touching it, or aborts the test when it does not.
    #[cfg(target_os = "linux")]
    pub(crate) fn peak_growth(f: impl FnOnce()) -> u64 {
        fn vm_peak() -> u64 {
            let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status is readable on Linux");
            let line = status.lines().find(|l| l.starts_with("VmPeak:")).expect("VmPeak in /proc/self/status");
            let kib: u64 = line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).expect("VmPeak value in kB");
            kib * 1024
        }
        let before = vm_peak();
        f();
        vm_peak().saturating_sub(before)
    }

    /// More growth than this means something was sized by a header count. Generous, because the
    /// tests of other modules run in parallel threads and their arenas count too.
    #[cfg(target_os = "linux")]
    pub(crate) const PEAK_LIMIT: u64 = 2 << 30;

    /// What a reader owes any input, garbage included: a mesh whose every index names one of its
    /// vertices and that holds no more than the bytes can back (every vertex and triangle takes at
    /// least one byte in each format), or an error with a message at a place inside the input.
    /// Returns whether the input was read.
    pub(crate) fn check_outcome(bytes: &[u8], result: &Result<crate::raw::RawMesh, crate::error::ParseError>) -> bool {
        use crate::error::Place;
        match result {
            Ok(mesh) => {
                let vertices = mesh.positions.len();
                assert!(vertices <= bytes.len(), "{vertices} vertices from {} bytes", bytes.len());
                assert!(
                    mesh.triangles.len() <= bytes.len(),
                    "{} triangles from {} bytes",
                    mesh.triangles.len(),
                    bytes.len()
                );
                let outside = mesh.triangles.iter().flatten().find(|&&i| i as usize >= vertices);
                assert!(outside.is_none(), "index {outside:?} of {vertices} vertices from {bytes:?}");
                if let Some(normals) = &mesh.normals {
                    assert_eq!(normals.len(), vertices, "one normal per vertex");
                }
                true
            }
            Err(e) => {
                assert!(!e.message.trim().is_empty(), "an error without a message at {}", e.place);
                let lines = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
                match e.place {
                    Place::Line(line) => assert!((1..=lines).contains(&line), "{e} of {lines} lines"),
                    Place::Byte(offset) => assert!(offset <= bytes.len() as u64, "{e} of {} bytes", bytes.len()),
                    Place::File => {}
                    Place::Json(_) => panic!("{e}: a JSON place from a mesh reader"),
                }
                false
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Place;

    fn line_of(result: Result<RawMesh, ParseError>) -> (usize, String) {
        match result {
            Err(ParseError { place: Place::Line(line), message }) => (line, message),
            other => panic!("expected an error with a line, got {other:?}"),
        }
    }

    const CUBE_QUADS: &str = "\
# a unit cube written as quads
OFF
# counts: vertices faces edges
8 6 12

0 0 0
1 0 0   # trailing comment
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 4 5 6 7
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7  255 0 0
";

    #[test]
    fn reads_comments_and_fan_triangulates_quads() {
        let mesh = read(CUBE_QUADS.as_bytes()).expect("valid OFF");
        assert_eq!(mesh.positions.len(), 8);
        assert_eq!(mesh.triangles.len(), 12);
        assert_eq!(mesh.positions[1], [1.0, 0.0, 0.0]);
        assert_eq!(&mesh.triangles[..2], &[[0, 3, 2], [0, 2, 1]]);
        assert_eq!(mesh.triangles[11], [3, 4, 7]);
        assert!(mesh.normals.is_none());
    }

    #[test]
    fn tolerates_colour_and_normal_columns_and_counts_on_the_header_line() {
        let coff = "COFF 3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n";
        assert_eq!(read(coff.as_bytes()).expect("COFF").triangles, vec![[0, 1, 2]]);
        let noff = "NOFF\n3 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2 0.5 0.5 0.5\n";
        let mesh = read(noff.as_bytes()).expect("NOFF");
        assert_eq!(mesh.positions[2], [0.0, 1.0, 0.0]);
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        let crlf = "OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n";
        assert_eq!(read(crlf.as_bytes()).expect("CRLF").triangles.len(), 1);
    }

    #[test]
    fn nan_literal_passes_through() {
        let mesh = read(b"OFF\n3 1 0\nnan 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n").expect("NaN is not a parse error");
        assert!(mesh.positions[0][0].is_nan());
        assert!(mesh.positions[1][1].is_infinite());
        assert_eq!(mesh.triangles.len(), 1);
    }

    #[test]
    fn refuses_empty_and_header_only_files() {
        assert_eq!(read(b"").map_err(|e| e.place), Err(Place::File));
        assert!(line_of(read(b"# nothing here\n")).1.contains("no OFF header"));
        assert!(line_of(read(b"OFF\n")).1.contains("vertex count"));
        assert!(line_of(read(b"OFF BINARY\n3 1 0\n")).1.contains("binary OFF"));
        assert!(line_of(read(b"4OFF\n1 0 0\n0 0 0 0\n")).1.contains("not supported"));
        assert!(line_of(read(b"PLY\n")).1.contains("expected an OFF header"));
    }

    #[test]
    fn every_truncation_fails_with_a_line() {
        let full = CUBE_QUADS.as_bytes();
        // The last face ends at its last index; anything shorter than that must be refused.
        let last_face = CUBE_QUADS.rfind("4 3 0 4 7").expect("last face") + "4 3 0 4 7".len();
        for len in 1..last_face {
            let prefix = &full[..len];
            let (line, _) = line_of(read(prefix));
            assert!((1..=21).contains(&line), "line {line} for prefix of {len} bytes");
        }
        // Cut in the face list: the counts no longer fit the bytes left, which the header line hears of ...
        let (line, message) = line_of(read(&full[..CUBE_QUADS.find("4 4 5").expect("face 1")]));
        assert_eq!(
            (line, message.as_str()),
            (4, "header says 6 faces but the 10 bytes after the vertices can hold at most 1")
        );
        // ... or, when they still fit, the face that is cut short.
        let (line, message) = line_of(read(&full[..last_face - 2]));
        assert_eq!((line, message.as_str()), (19, "face 5: expected 4 vertex indices, found 3"));
    }

    /// A record too short to be valid makes the counts look too large for the file: the record's
    /// line is blamed, not the header's (the fuzzing notes had `2 0 1` blamed on the face count).
    #[test]
    fn a_short_record_is_blamed_rather_than_the_counts() {
        let cases: [(&[u8], (usize, &str)); 4] = [
            (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", (6, "face 0 has 2 vertices; a face needs at least 3")),
            (
                b"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n",
                (6, "face 0 has 2 vertices; a face needs at least 3"),
            ),
            (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1 0\n", (6, "face 0 has 1 vertices; a face needs at least 3")),
            (b"OFF\n2 0 0\n0 0\n1\n", (3, "vertex 0: expected 3 coordinates, found 2")),
        ];
        for (text, expected) in cases {
            let (line, message) = line_of(read(text));
            assert_eq!((line, message.as_str()), expected, "{}", String::from_utf8_lossy(text));
        }
        // A file that ends before counts it could never hold still blames the header, also inside a
        // record, and so does a record that is malformed but not short (here text after the list).
        let (line, message) = line_of(read(b"OFF\n3 1 0\n0 0 0\n1 0"));
        assert_eq!((line, message.as_str()), (2, "header says 3 vertices but the 9 bytes left can hold at most 1"));
        let (line, message) = line_of(read(b"OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\nend\n"));
        assert_eq!((line, message.as_str()), (2, "header says 4 vertices but the 22 bytes left can hold at most 3"));
        // And a face list cut short:
        let (line, message) = line_of(read(b"OFF\n3 5 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
        assert_eq!(
            (line, message.as_str()),
            (2, "header says 5 faces but the 8 bytes after the vertices can hold at most 1")
        );
    }

    #[test]
    fn refuses_counts_the_file_cannot_hold_without_allocating() {
        let hostile = b"OFF\n4000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let check = || {
            let (line, message) = line_of(read(hostile));
            assert_eq!(line, 2);
            assert!(message.starts_with("header says 4000000000 vertices but the"), "{message}");
        };
        #[cfg(target_os = "linux")]
        assert!(testing::peak_growth(check) < testing::PEAK_LIMIT);
        #[cfg(not(target_os = "linux"))]
        check();
        let (_, message) = line_of(read(b"OFF\n3 4294967295 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
        assert!(message.starts_with("header says 4294967295 faces"), "{message}");
        let (_, message) = line_of(read(b"OFF\n18446744073709551615 1 0\n"));
        assert!(message.contains("32-bit indices"), "{message}");
        let (_, message) = line_of(read(b"OFF\n99999999999999999999999 1 0\n"));
        assert!(message.contains("expected the vertex count"), "{message}");
    }

    #[test]
    fn refuses_bad_indices_and_tokens_with_their_line() {
        let base = "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n";
        let cases = [
            ("3 0 1 3\n", "face 0 uses vertex 3 but the file has 3 vertices"),
            ("3 0 -1 2\n", "face 0 has negative vertex index -1"),
            ("3 0 1 x\n", "face 0: expected a vertex index, found 'x'"),
            ("3 0 1\n2\n", "face 0: expected 3 vertex indices, found 2"),
            ("2 0 1 255 0 0\n", "face 0 has 2 vertices; a face needs at least 3"),
            ("-3 0 1 2\n", "face 0 has -3 vertices; a face needs at least 3"),
            ("three 0 1 2\n", "face 0: expected a vertex count, found 'three'"),
            ("3 0 1 99999999999\n", "face 0 uses vertex 99999999999 but the file has 3 vertices"),
        ];
        for (face, expected) in cases {
            let (line, message) = line_of(read(format!("{base}{face}3 2 1 0\n").as_bytes()));
            assert_eq!((line, message.as_str()), (6, expected));
        }
        let (line, message) = line_of(read(b"OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n"));
        assert_eq!((line, message.as_str()), (4, "vertex 1: expected 3 coordinates, found 2"));
        let (line, message) = line_of(read(b"OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"));
        assert_eq!((line, message.as_str()), (4, "vertex 1: expected a number, found 'zero'"));
    }

    #[test]
    fn garbage_never_panics() {
        let mut rng = drafter_core::rng::Rng::new(0x2545_f491_4f6c_dd1d);
        let alphabet = b"OFF 0123456789-.#\n e";
        let mut outcomes = [0; 2];
        for _ in 0..2000 {
            let len = rng.below(64) as usize;
            let bytes: Vec<u8> = (0..len).map(|_| alphabet[rng.below(alphabet.len() as u64) as usize]).collect();
            let read_ok = testing::check_outcome(&bytes, &read(&bytes));
            outcomes[usize::from(read_ok)] += 1;
        }
        assert!(outcomes[0] > 0, "none of the garbage was refused ({} read)", outcomes[1]);
    }

    #[test]
    fn reads_cgal_couplingdown() {
        let mesh = read(&testing::model("obj/cgal/couplingdown.off")).expect("couplingdown.off");
        assert_eq!(mesh.positions.len(), 1_841);
        assert_eq!(mesh.triangles.len(), 3_714);
    }

    #[test]
    fn reads_vhacd_crank() {
        let mesh = read(&testing::model("obj/v-hacd/crank.off")).expect("crank.off");
        assert_eq!(mesh.positions.len(), 49_986);
        assert_eq!(mesh.triangles.len(), 100_028);
    }

    #[test]
    fn text_tokens_track_lines() {
        let mut tokens = Tokens::new(b"a b # c\n\n  d\ne", 1, Some(b'#'));
        assert_eq!(tokens.next_token(), Some(&b"a"[..]));
        assert_eq!(tokens.next_on_line(), Some(&b"b"[..]));
        assert_eq!(tokens.next_on_line(), None);
        assert_eq!(tokens.line(), 1);
        assert_eq!(tokens.next_token(), Some(&b"d"[..]));
        assert_eq!(tokens.line(), 3);
        tokens.skip_line();
        assert_eq!(tokens.next_on_line(), Some(&b"e"[..]));
        assert_eq!(tokens.line(), 4);
        assert_eq!(tokens.next_token(), None);
        assert_eq!(show(b"abcdefghijklmnopqrstuvwxyz"), "'abcdefghijklmnopqrstuvwx...'");
        assert!(fits(3, 6, 18) && !fits(3, 6, 17) && !fits(u64::MAX, 2, u64::MAX));
    }
}
