//! STL reader: binary and ASCII.
//!
//! Hand-written rather than taken from a crate: no well-kept STL crate reports the place of a fault
//! or refuses a triangle count that the file cannot back, and both are required of every reader here.
//!
//! # What is read
//! * Binary: an 80-byte header, a little-endian u32 triangle count, then 50 bytes per facet (normal,
//!   three corners as f32 triples, a u16 attribute). The file is binary when its length is exactly
//!   `84 + 50 * count`, even when the header starts with `solid` (many exporters write that).
//! * ASCII: `solid [name]`, then facets `facet [normal nx ny nz] outer loop vertex x y z ... endloop
//!   endfacet`, then `endsolid [name]`; several solids in one file are concatenated. Keywords are
//!   matched without regard to case, and any ASCII whitespace (CRLF included) separates tokens. A
//!   loop of more than 3 vertices is fan-triangulated.
//!
//! Every facet gives 3 new vertices (its corners are not welded here; `drafter_core::Topology`
//! welds later). Facet normals and attribute bytes are ignored: they are often zero or stale, and the
//! pipeline recomputes normals from the geometry. Non-finite coordinates are passed through: `raw`
//! drops the faces that use them with a diagnostic.
//!
//! # What is refused
//! * A file that is neither: when the length does not match the binary count, a file starting with
//!   `solid` is read as ASCII; if that fails and the file holds non-text bytes, the error is the
//!   count mismatch at byte 80 ("header says N triangles but the file holds M"), otherwise the ASCII
//!   error with its line.
//! * ASCII: a missing keyword, a coordinate that is not a number, a loop of fewer than 3 vertices,
//!   a file that ends inside a solid (no `endsolid`).
//!
//! # Safety rules
//! The binary reader allocates by the count only after the exact length check has proved the file
//! holds every facet; the ASCII reader has no count and grows with what it reads. Bytes are reached
//! only through `get` and fixed-size chunks, indices through checked conversions: no input panics.

use crate::error::ParseError;
use crate::off::text::{Tokens, parse_f32, show};
use crate::raw::RawMesh;

/// Bytes of the binary header before the triangle count.
const HEADER_BYTES: usize = 80;
/// Bytes of the header and the triangle count.
const PREAMBLE_BYTES: usize = 84;
/// Bytes of one binary facet.
const FACET_BYTES: usize = 50;

pub(crate) fn read(bytes: &[u8]) -> Result<RawMesh, ParseError> {
    if bytes.is_empty() {
        return Err(ParseError::in_file("empty file"));
    }
    if is_binary(bytes) {
        return read_binary(bytes);
    }
    // Some exporters pad an ASCII file with NUL bytes up to a block size: not part of the text.
    let text = bytes.iter().rposition(|&b| b != 0).map_or(&bytes[..0], |end| &bytes[..=end]);
    if starts_with_solid(text) {
        match read_ascii(text) {
            Ok(mesh) => return Ok(mesh),
            Err(error) if !looks_binary(text) => return Err(error),
            Err(_) => {} // a binary file whose header starts with "solid" and whose count is wrong
        }
    }
    Err(count_mismatch(bytes))
}

/// True when `bytes` is a binary STL: an 80-byte header, a u32 triangle count and exactly 50 bytes
/// per triangle. This holds even when the header starts with "solid".
pub(crate) fn is_binary(bytes: &[u8]) -> bool {
    // At most 84 + 50 * u32::MAX, far inside u64.
    triangle_count(bytes).is_some_and(|count| 84 + 50 * u64::from(count) == bytes.len() as u64)
}

/// The binary header's triangle count, if the file is long enough to have one.
fn triangle_count(bytes: &[u8]) -> Option<u32> {
    let field = bytes.get(HEADER_BYTES..PREAMBLE_BYTES)?;
    Some(u32::from_le_bytes(field.try_into().ok()?))
}

fn count_mismatch(bytes: &[u8]) -> ParseError {
    let Some(count) = triangle_count(bytes) else {
        return ParseError::in_file(format!(
            "{} bytes: too short for a binary STL (header and count take 84) and no ASCII 'solid'",
            bytes.len()
        ));
    };
    let body = bytes.len().saturating_sub(PREAMBLE_BYTES);
    let (holds, extra) = (body / FACET_BYTES, body % FACET_BYTES);
    let message = if extra == 0 {
        format!("header says {count} triangles but the file holds {holds}")
    } else {
        format!("header says {count} triangles but the file holds {holds} and {extra} bytes more")
    };
    ParseError::at_byte(HEADER_BYTES as u64, message)
}

fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    bytes.get(start..start + 5).is_some_and(|word| word.eq_ignore_ascii_case(b"solid"))
}

/// True when `bytes` holds a byte no text file has (NUL or another control character): the binary
/// facets' attribute bytes and floats practically always do.
fn looks_binary(bytes: &[u8]) -> bool {
    bytes.iter().any(|&b| (b < 0x20 && !b.is_ascii_whitespace()) || b == 0x7f)
}

fn read_binary(bytes: &[u8]) -> Result<RawMesh, ParseError> {
    let body = bytes.get(PREAMBLE_BYTES..).unwrap_or_default();
    let (facets, rest) = body.as_chunks::<FACET_BYTES>();
    let count = triangle_count(bytes).map_or(0, u64::from);
    if facets.len() as u64 != count || !rest.is_empty() {
        return Err(count_mismatch(bytes));
    }
    // The length check above proved the file holds every facet, so these allocations are backed.
    let corners = facets.len().saturating_mul(3);
    if u32::try_from(corners).is_err() {
        return Err(ParseError::at_byte(
            HEADER_BYTES as u64,
            format!("{count} triangles need more vertices than 32-bit indices address"),
        ));
    }
    let mut positions = Vec::with_capacity(corners);
    let mut triangles = Vec::with_capacity(facets.len());
    for (facet, first) in facets.iter().zip((0u32..).step_by(3)) {
        // 12 little-endian f32: the normal (ignored), then the three corners; 2 attribute bytes follow.
        let (words, _attribute) = facet.as_chunks::<4>();
        let (corner_words, _) = words.get(3..).unwrap_or_default().as_chunks::<3>();
        positions.extend(corner_words.iter().map(|corner| corner.map(f32::from_le_bytes)));
        triangles.push([first, first + 1, first + 2]);
    }
    Ok(RawMesh { positions, triangles, normals: None })
}

fn read_ascii(bytes: &[u8]) -> Result<RawMesh, ParseError> {
    let mut tokens = Tokens::new(bytes, 1, None);
    let mut mesh = RawMesh::default();
    while let Some(token) = tokens.next_token() {
        if !token.eq_ignore_ascii_case(b"solid") {
            return Err(ParseError::at_line(tokens.line(), format!("expected 'solid', found {}", show(token))));
        }
        let solid_line = tokens.line();
        tokens.skip_line(); // the solid's name
        read_solid(&mut tokens, solid_line, &mut mesh)?;
    }
    Ok(mesh)
}

fn read_solid(tokens: &mut Tokens<'_>, solid_line: usize, mesh: &mut RawMesh) -> Result<(), ParseError> {
    loop {
        let Some(token) = tokens.next_token() else {
            return Err(ParseError::at_line(
                tokens.line(),
                format!("unexpected end of file: the solid begun on line {solid_line} has no 'endsolid'"),
            ));
        };
        if token.eq_ignore_ascii_case(b"endsolid") {
            tokens.skip_line(); // the solid's name
            return Ok(());
        }
        if !token.eq_ignore_ascii_case(b"facet") {
            return Err(ParseError::at_line(
                tokens.line(),
                format!("expected 'facet' or 'endsolid', found {}", show(token)),
            ));
        }
        read_facet(tokens, mesh)?;
    }
}

/// Reads one facet after its `facet` keyword.
fn read_facet(tokens: &mut Tokens<'_>, mesh: &mut RawMesh) -> Result<(), ParseError> {
    let facet_line = tokens.line();
    let mut token = next(tokens, facet_line)?;
    if token.eq_ignore_ascii_case(b"normal") {
        read_triple(tokens, facet_line, "facet normal")?;
        token = next(tokens, facet_line)?;
    }
    expect(tokens, token, "outer")?;
    let token = next(tokens, facet_line)?;
    expect(tokens, token, "loop")?;
    let first = mesh.positions.len();
    loop {
        let token = next(tokens, facet_line)?;
        if token.eq_ignore_ascii_case(b"endloop") {
            break;
        }
        if !token.eq_ignore_ascii_case(b"vertex") {
            return Err(ParseError::at_line(
                tokens.line(),
                format!("expected 'vertex' or 'endloop', found {}", show(token)),
            ));
        }
        let position = read_triple(tokens, facet_line, "vertex")?;
        mesh.positions.push(position);
    }
    let corners = mesh.positions.len() - first;
    if corners < 3 {
        return Err(ParseError::at_line(
            tokens.line(),
            format!("the facet begun on line {facet_line} has {corners} vertices; a facet needs 3"),
        ));
    }
    let index = |i: usize| {
        u32::try_from(i)
            .map_err(|_| ParseError::at_line(facet_line, "more vertices than 32-bit indices address".to_owned()))
    };
    let apex = index(first)?;
    for i in first + 1..first + corners - 1 {
        mesh.triangles.push([apex, index(i)?, index(i + 1)?]);
    }
    let token = next(tokens, facet_line)?;
    expect(tokens, token, "endfacet")
}

/// The next token, or an error naming the facet the file ended in.
fn next<'a>(tokens: &mut Tokens<'a>, facet_line: usize) -> Result<&'a [u8], ParseError> {
    tokens.next_token().ok_or_else(|| {
        ParseError::at_line(tokens.line(), format!("unexpected end of file in the facet begun on line {facet_line}"))
    })
}

fn expect(tokens: &Tokens<'_>, token: &[u8], keyword: &str) -> Result<(), ParseError> {
    if token.eq_ignore_ascii_case(keyword.as_bytes()) {
        Ok(())
    } else {
        Err(ParseError::at_line(tokens.line(), format!("expected '{keyword}', found {}", show(token))))
    }
}

fn read_triple(tokens: &mut Tokens<'_>, facet_line: usize, what: &str) -> Result<[f32; 3], ParseError> {
    let mut triple = [0.0f32; 3];
    for value in &mut triple {
        let token = next(tokens, facet_line)?;
        *value = parse_f32(token).ok_or_else(|| {
            ParseError::at_line(tokens.line(), format!("{what}: expected 3 coordinates, found {}", show(token)))
        })?;
    }
    Ok(triple)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Place;
    use crate::off::testing;

    fn binary_stl(header: &[u8], facets: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut bytes = header.to_vec();
        bytes.resize(80, b' ');
        bytes.extend_from_slice(&(facets.len() as u32).to_le_bytes());
        for facet in facets {
            bytes.extend_from_slice(&[0u8; 12]); // normal
            for corner in facet {
                for value in corner {
                    bytes.extend_from_slice(&value.to_le_bytes());
                }
            }
            bytes.extend_from_slice(&[0u8; 2]); // attribute
        }
        bytes
    }

    const TWO_FACETS: [[[f32; 3]; 3]; 2] =
        [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.5]]];

    const ASCII: &str = "solid  two facets\r
  FACET NORMAL 0 0 1\r
    outer loop\r
      vertex 0 0 0\r
      Vertex\t1.0e0 0 0\r
      vertex 0 1 0\r
    endloop\r
  endfacet\r
  facet normal 0 0 1\r
    outer loop\r
      vertex 1 0 0\r
      vertex 1 1 0\r
      vertex 0 1 0.5\r
    endloop\r
  endfacet\r
endsolid two facets\r
";

    fn error(result: Result<RawMesh, ParseError>) -> (Place, String) {
        match result {
            Err(ParseError { place, message }) => (place, message),
            Ok(mesh) => panic!("expected an error, got a mesh of {} triangles", mesh.triangles.len()),
        }
    }

    #[test]
    fn binary_with_solid_header_is_read_as_binary() {
        let bytes = binary_stl(b"solid this header lies", &TWO_FACETS);
        assert!(is_binary(&bytes));
        let mesh = read(&bytes).expect("binary STL");
        assert_eq!(mesh.positions.len(), 6);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(mesh.positions[5], [0.0, 1.0, 0.5]);
        assert!(mesh.normals.is_none());
        let plain = read(&binary_stl(b"exported by something", &TWO_FACETS)).expect("binary STL");
        assert_eq!(plain, mesh);
    }

    #[test]
    fn ascii_with_mixed_case_tabs_and_crlf() {
        let mesh = read(ASCII.as_bytes()).expect("ASCII STL");
        assert!(!is_binary(ASCII.as_bytes()));
        let binary = read(&binary_stl(b"", &TWO_FACETS)).expect("binary STL");
        assert_eq!(mesh, binary);
    }

    #[test]
    fn ascii_padded_with_nul_bytes() {
        for pad in [1, 3, 4096] {
            let mut bytes = ASCII.as_bytes().to_vec();
            bytes.resize(bytes.len() + pad, 0);
            assert_eq!(read(&bytes).expect("padded ASCII STL"), read(ASCII.as_bytes()).expect("ASCII STL"), "{pad}");
        }
    }

    #[test]
    fn ascii_with_several_solids_and_polygon_loops() {
        let text = format!(
            "{ASCII}solid quad\nfacet outer loop vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 vertex 0 1 0 endloop endfacet\nendsolid\n"
        );
        let mesh = read(text.as_bytes()).expect("two solids");
        assert_eq!(mesh.positions.len(), 10);
        assert_eq!(mesh.triangles[2..], [[6, 7, 8], [6, 8, 9]]);
    }

    #[test]
    fn nan_literal_passes_through() {
        let text = "solid\nfacet normal nan nan nan\nouter loop\nvertex NaN 0 0\nvertex 1 0 0\nvertex 0 -inf 0\nendloop\nendfacet\nendsolid\n";
        let mesh = read(text.as_bytes()).expect("NaN is not a parse error");
        assert!(mesh.positions[0][0].is_nan());
        assert!(mesh.positions[2][1].is_infinite());
        let mut nan_facet = TWO_FACETS;
        nan_facet[1][2][0] = f32::NAN;
        assert!(read(&binary_stl(b"", &nan_facet)).expect("binary").positions[5][0].is_nan());
    }

    #[test]
    fn refuses_empty_and_short_files() {
        assert_eq!(error(read(b"")), (Place::File, "empty file".to_owned()));
        assert_eq!(error(read(b"hello")).0, Place::File);
        assert_eq!(error(read(b"solid")).0, Place::Line(1));
        assert_eq!(error(read(&[0u8; 83])).0, Place::File);
    }

    #[test]
    fn every_ascii_truncation_fails_with_a_line() {
        let end = ASCII.find("endsolid").expect("endsolid");
        for len in "solid".len()..end {
            let (place, message) = error(read(&ASCII.as_bytes()[..len]));
            assert!(matches!(place, Place::Line(1..=16)), "{place:?} {message} at {len} bytes");
        }
        let cut = ASCII.find("      vertex 1 1 0").expect("second facet");
        assert_eq!(
            error(read(&ASCII.as_bytes()[..cut + "      vertex".len()])),
            (Place::Line(12), "unexpected end of file in the facet begun on line 9".to_owned())
        );
        assert_eq!(
            error(read(&ASCII.as_bytes()[..end])),
            (Place::Line(16), "unexpected end of file: the solid begun on line 1 has no 'endsolid'".to_owned())
        );
    }

    #[test]
    fn truncated_binary_reports_the_count_mismatch() {
        for header in [&b"solid name"[..], b"binary"] {
            let bytes = binary_stl(header, &TWO_FACETS);
            for (len, expected) in [
                (bytes.len() - 1, "header says 2 triangles but the file holds 1 and 49 bytes more"),
                (84 + 50, "header says 2 triangles but the file holds 1"),
                (84 + 7, "header says 2 triangles but the file holds 0 and 7 bytes more"),
                (84, "header says 2 triangles but the file holds 0"),
            ] {
                assert_eq!(error(read(&bytes[..len])), (Place::Byte(80), expected.to_owned()));
            }
        }
    }

    #[test]
    fn huge_triangle_count_fails_without_allocating() {
        let mut bytes = binary_stl(b"solid huge", &TWO_FACETS);
        bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let check = || {
            assert_eq!(
                error(read(&bytes)),
                (Place::Byte(80), "header says 4294967295 triangles but the file holds 2".to_owned())
            );
        };
        #[cfg(target_os = "linux")]
        assert!(testing::peak_growth(check) < testing::PEAK_LIMIT);
        #[cfg(not(target_os = "linux"))]
        check();
    }

    #[test]
    fn refuses_bad_ascii_with_its_line() {
        let bad_number = ASCII.replace("vertex 1 1 0", "vertex 1 one 0");
        assert_eq!(
            error(read(bad_number.as_bytes())),
            (Place::Line(12), "vertex: expected 3 coordinates, found 'one'".to_owned())
        );
        let short_vertex = ASCII.replace("vertex 1 1 0", "vertex 1 1");
        assert_eq!(
            error(read(short_vertex.as_bytes())),
            (Place::Line(13), "vertex: expected 3 coordinates, found 'vertex'".to_owned())
        );
        let two_corners = ASCII.replace("      vertex 1 1 0\r\n", "");
        assert_eq!(
            error(read(two_corners.as_bytes())),
            (Place::Line(13), "the facet begun on line 9 has 2 vertices; a facet needs 3".to_owned())
        );
        let no_loop = ASCII.replace("outer loop", "outer");
        assert_eq!(error(read(no_loop.as_bytes())), (Place::Line(4), "expected 'loop', found 'vertex'".to_owned()));
        let stray = ASCII.replace("endsolid", "facets");
        assert_eq!(
            error(read(stray.as_bytes())),
            (Place::Line(16), "expected 'facet' or 'endsolid', found 'facets'".to_owned())
        );
    }

    #[test]
    fn garbage_never_panics() {
        let mut rng = drafter_core::rng::Rng::new(0x9e37_79b9_7f4a_7c15u64);
        let mut next = || rng.next_u64();
        let words: [&[u8]; 9] = [
            b"solid ",
            b"facet ",
            b"normal ",
            b"outer loop ",
            b"vertex ",
            b"1 ",
            b"endloop ",
            b"endfacet ",
            b"endsolid\n",
        ];
        let mut outcomes = [0; 2];
        for _ in 0..2000 {
            let mut bytes = Vec::new();
            for _ in 0..next() % 40 {
                bytes.extend_from_slice(words[(next() % words.len() as u64) as usize]);
            }
            let read_ok = testing::check_outcome(&bytes, &read(&bytes));
            outcomes[usize::from(read_ok)] += 1;
            let binary_len = (next() % 300) as usize;
            let binary: Vec<u8> = (0..binary_len).map(|_| next() as u8).collect();
            let read_ok = testing::check_outcome(&binary, &read(&binary));
            outcomes[usize::from(read_ok)] += 1;
        }
        assert!(outcomes[0] > 0, "none of the garbage was refused ({} read)", outcomes[1]);
    }

    #[test]
    fn reads_occt_sh1_ascii() {
        let bytes = testing::model("obj/occt/sh1.stl");
        assert!(!is_binary(&bytes));
        let mesh = read(&bytes).expect("sh1.stl");
        assert_eq!(mesh.triangles.len(), 3_290);
        assert_eq!(mesh.positions.len(), 9_870);
    }

    #[test]
    fn reads_trimesh_binary_files_with_solid_headers() {
        for (path, triangles) in [
            ("obj/trimesh/plate_holes.STL", 1_252),
            ("obj/trimesh/idler_riser.STL", 1_572),
            ("obj/trimesh/angle_block.STL", 704),
        ] {
            let bytes = testing::model(path);
            assert!(bytes.starts_with(b"solid") && is_binary(&bytes), "{path}");
            let mesh = read(&bytes).expect(path);
            assert_eq!(mesh.triangles.len(), triangles, "{path}");
            assert_eq!(mesh.positions.len(), 3 * triangles, "{path}");
        }
    }
}
