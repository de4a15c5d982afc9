//! The binary glTF container (.glb, glTF 2.0 §4.4): a 12-byte header (`glTF`, version 2, total
//! length) and chunks of `length: u32, type: [u8; 4], data`, the JSON chunk first and an optional
//! `BIN\0` chunk second. One framer for the whole workspace: drafter-io's importer, drafter-format's
//! writer and reader, the sample generator and the tests all split and write GLBs here, so the
//! checks below exist once.
//!
//! Pure bytes: [`split`] borrows the chunks from the input and allocates nothing, so a header that
//! lies about its lengths costs an error, never an allocation; every offset is computed with checked
//! arithmetic against the bytes really present, and errors name the byte offset of the field that
//! does not fit. [`write`] pads the JSON with spaces and the BIN chunk with zeros to 4 bytes (the
//! spec's alignment) and leaves the BIN chunk out when it is empty.

use std::fmt;

/// The first four bytes of a GLB.
pub const MAGIC: &[u8; 4] = b"glTF";
/// The container version this module reads and writes.
pub const VERSION: u32 = 2;
/// Chunk type of the JSON chunk.
pub const CHUNK_JSON: &[u8; 4] = b"JSON";
/// Chunk type of the binary buffer chunk.
pub const CHUNK_BIN: &[u8; 4] = b"BIN\0";

/// Bytes of the file header.
const HEADER: usize = 12;
/// Bytes of a chunk header.
const CHUNK_HEADER: usize = 8;

/// A GLB's chunks, borrowed from the file's bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Chunks<'a> {
    /// The JSON chunk's data, padding included.
    pub json: &'a [u8],
    /// The `BIN\0` chunk's data, if the file has one.
    pub bin: Option<&'a [u8]>,
}

/// Why bytes are not a GLB, or why a GLB cannot be written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum GlbError {
    /// The container does not hold together: `message` says what, `offset` where (a byte offset
    /// into the file, of the field that is wrong or of the first byte that is missing).
    Malformed { offset: usize, message: String },
    /// A GLB of this many bytes cannot be written: its length field is 32 bits.
    TooLarge(usize),
}

impl fmt::Display for GlbError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Malformed { offset, message } => write!(f, "GLB container: {message} at byte {offset}"),
            Self::TooLarge(total) => write!(f, "GLB of {total} bytes exceeds the 4 GiB limit of the container"),
        }
    }
}

impl std::error::Error for GlbError {}

fn malformed(offset: usize, message: impl Into<String>) -> GlbError {
    GlbError::Malformed { offset, message: message.into() }
}

/// Whether `bytes` start like a GLB (the magic only; [`split`] checks the rest).
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// The little-endian u32 at `at`, or an error naming `what` when `bytes` end before it.
fn u32_at(bytes: &[u8], at: usize, what: &str) -> Result<u32, GlbError> {
    let field = at.checked_add(4).and_then(|end| bytes.get(at..end)).ok_or_else(|| {
        malformed(at, format!("truncated: {what} needs 4 bytes, {} remain", bytes.len().saturating_sub(at)))
    })?;
    Ok(u32::from_le_bytes([field[0], field[1], field[2], field[3]]))
}

/// One chunk starting at `at` within `bytes` (already cut to the header's total length): its type
/// and data, and the offset after it.
fn chunk_at(bytes: &[u8], at: usize, index: usize) -> Result<([u8; 4], &[u8], usize), GlbError> {
    let length = u32_at(bytes, at, &format!("the length of chunk {index}"))? as usize;
    let type_at = at + 4;
    let ty = type_at
        .checked_add(4)
        .and_then(|end| bytes.get(type_at..end))
        .ok_or_else(|| malformed(type_at, format!("truncated: chunk {index} has no type")))?;
    let ty = [ty[0], ty[1], ty[2], ty[3]];
    let start = at + CHUNK_HEADER;
    let end = start.checked_add(length).filter(|&end| end <= bytes.len()).ok_or_else(|| {
        malformed(
            at,
            format!(
                "chunk {index} ({}) declares {length} bytes but {} remain in the container",
                type_name(ty),
                bytes.len() - start
            ),
        )
    })?;
    Ok((ty, &bytes[start..end], end))
}

/// A chunk type as a message shows it: its letters where it is one of the spec's or another
/// alphanumeric name (`JSON`, `BIN`), else its bytes in hex (a chunk read from the middle of
/// another, where a previous length was wrong, has a type of arbitrary bytes).
fn type_name(ty: [u8; 4]) -> String {
    let letters = ty.iter().rev().skip_while(|&&b| b == 0).all(u8::is_ascii_alphanumeric);
    if letters && ty[0] != 0 {
        String::from_utf8_lossy(&ty).trim_end_matches('\0').to_owned()
    } else {
        format!("type 0x{:08X}", u32::from_le_bytes(ty))
    }
}

/// Bytes of the file header and of the JSON chunk's header: all that [`read_head`] looks at.
pub const HEAD: usize = HEADER + CHUNK_HEADER;

/// What a GLB's first [`HEAD`] bytes say: the container's length and where the JSON chunk's data
/// lie, both checked against the file's length.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Head {
    /// The header's total length (at most the file's; bytes after it are not the container's).
    pub total: usize,
    /// The JSON chunk's data (padding included), as byte offsets into the file.
    pub json: std::ops::Range<usize>,
}

/// Reads a GLB's header and its first chunk's header from `head`, the first bytes of a file of
/// `file_length` bytes (at least [`HEAD`] of them, or the whole file when it is shorter), without
/// the rest: for a reader that wants the JSON chunk alone from disk. The same checks as [`split`]
/// makes of the header and the first chunk: the magic, the version, that the total length fits in
/// the file and that the first chunk is JSON and fits inside the total.
pub fn read_head(head: &[u8], file_length: u64) -> Result<Head, GlbError> {
    let file_length = usize::try_from(file_length).unwrap_or(usize::MAX);
    if file_length < HEADER || head.len() < HEADER {
        let has = file_length.min(head.len());
        return Err(malformed(has, format!("header truncated: {HEADER} bytes needed, the file has {has}")));
    }
    if !is_glb(head) {
        return Err(malformed(0, "magic is not \"glTF\""));
    }
    let version = u32_at(head, 4, "the version")?;
    if version != VERSION {
        return Err(malformed(4, format!("version {version} is not supported (only {VERSION})")));
    }
    let total = u32_at(head, 8, "the length")? as usize;
    if total > file_length {
        return Err(malformed(8, format!("header declares {total} bytes but the file has {file_length}")));
    }
    if total < HEAD {
        return Err(malformed(8, format!("header declares {total} bytes, too few for a JSON chunk")));
    }
    let length = u32_at(head, HEADER, "the length of chunk 0")? as usize;
    let ty = head.get(HEADER + 4..HEAD).ok_or_else(|| malformed(HEADER + 4, "truncated: chunk 0 has no type"))?;
    let ty = [ty[0], ty[1], ty[2], ty[3]];
    let end = HEAD.checked_add(length).filter(|&end| end <= total).ok_or_else(|| {
        malformed(
            HEADER,
            format!("chunk 0 ({}) declares {length} bytes but {} remain in the container", type_name(ty), total - HEAD),
        )
    })?;
    if &ty != CHUNK_JSON {
        return Err(malformed(HEADER + 4, "first chunk is not JSON"));
    }
    Ok(Head { total, json: HEAD..end })
}

/// Splits a GLB into its JSON and BIN chunks. Checks what [`read_head`] checks (bytes after the
/// header's total length are ignored) and that every further chunk fits inside the total. A second
/// chunk of type `BIN\0` is the buffer; chunks of other types are skipped, as the spec asks of
/// readers.
pub fn split(bytes: &[u8]) -> Result<Chunks<'_>, GlbError> {
    let head = read_head(bytes, bytes.len() as u64)?;
    let bytes = &bytes[..head.total];
    let json = &bytes[head.json.clone()];
    let mut at = head.json.end;
    let mut bin = None;
    let mut index = 1;
    while at < bytes.len() {
        let (ty, data, next) = chunk_at(bytes, at, index)?;
        if index == 1 && &ty == CHUNK_BIN {
            bin = Some(data);
        }
        at = next;
        index += 1;
    }
    Ok(Chunks { json, bin })
}

/// A GLB of `json` and `bin`: JSON padded with spaces, BIN with zeros, both to 4 bytes; no BIN
/// chunk when `bin` is empty.
pub fn write(json: &[u8], bin: &[u8]) -> Result<Vec<u8>, GlbError> {
    let json_padded = json.len().next_multiple_of(4);
    let bin_padded = bin.len().next_multiple_of(4);
    let bin_chunk = if bin.is_empty() { 0 } else { CHUNK_HEADER + bin_padded };
    let total = HEADER + CHUNK_HEADER + json_padded + bin_chunk;
    let to_u32 = |n: usize| u32::try_from(n).map_err(|_| GlbError::TooLarge(total));
    let total_u32 = to_u32(total)?;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&total_u32.to_le_bytes());
    out.extend_from_slice(&to_u32(json_padded)?.to_le_bytes());
    out.extend_from_slice(CHUNK_JSON);
    out.extend_from_slice(json);
    out.resize(out.len() + json_padded - json.len(), b' ');
    if !bin.is_empty() {
        out.extend_from_slice(&to_u32(bin_padded)?.to_le_bytes());
        out.extend_from_slice(CHUNK_BIN);
        out.extend_from_slice(bin);
        out.resize(out.len() + bin_padded - bin.len(), 0);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunk_types_are_named_or_shown_in_hex() {
        assert_eq!(type_name(*b"JSON"), "JSON");
        assert_eq!(type_name(*b"BIN\0"), "BIN");
        assert_eq!(type_name(*b"ene\""), "type 0x22656E65");
        assert_eq!(type_name([0, 0, 0, 0]), "type 0x00000000");
    }

    fn offset_of(e: GlbError) -> usize {
        match e {
            GlbError::Malformed { offset, .. } => offset,
            GlbError::TooLarge(_) => usize::MAX,
        }
    }

    #[test]
    fn write_then_split_round_trips_with_padding() {
        let glb = write(b"{\"a\":1}", &[1, 2, 3, 4, 5]).expect("write");
        assert_eq!(glb.len() % 4, 0);
        assert_eq!(u32::from_le_bytes([glb[8], glb[9], glb[10], glb[11]]) as usize, glb.len());
        let chunks = split(&glb).expect("split");
        assert_eq!(chunks.json, b"{\"a\":1} ");
        assert_eq!(chunks.bin, Some(&[1, 2, 3, 4, 5, 0, 0, 0][..]));
    }

    #[test]
    fn an_empty_buffer_writes_no_bin_chunk() {
        let glb = write(b"{}", &[]).expect("write");
        assert_eq!(glb.len(), 12 + 8 + 4);
        assert_eq!(split(&glb).expect("split"), Chunks { json: b"{}  ", bin: None });
    }

    #[test]
    fn unknown_chunks_are_skipped_and_trailing_bytes_ignored() {
        let mut glb = write(b"{}", &[9; 4]).expect("write");
        glb.extend_from_slice(&4u32.to_le_bytes());
        glb.extend_from_slice(b"XTRA");
        glb.extend_from_slice(&[7; 4]);
        let total = glb.len() as u32;
        glb[8..12].copy_from_slice(&total.to_le_bytes());
        glb.extend_from_slice(b"trailing");
        assert_eq!(split(&glb).expect("split").bin, Some(&[9; 4][..]));
    }

    #[test]
    fn lies_and_truncations_are_errors_at_their_offset() {
        let glb = write(b"{}", &[1; 8]).expect("write");
        // Total length larger than the file: the header's length field.
        let mut liar = glb.clone();
        liar[8..12].copy_from_slice(&1_000_000u32.to_le_bytes());
        assert_eq!(offset_of(split(&liar).expect_err("liar")), 8);
        // JSON chunk length beyond the container (and beyond usize arithmetic).
        let mut liar = glb.clone();
        liar[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(offset_of(split(&liar).expect_err("json")), 12);
        // BIN chunk length beyond the container.
        let mut liar = glb.clone();
        liar[24..28].copy_from_slice(&64u32.to_le_bytes());
        assert_eq!(offset_of(split(&liar).expect_err("bin")), 24);
        // Version and first chunk type.
        let mut v1 = glb.clone();
        v1[4] = 1;
        assert_eq!(offset_of(split(&v1).expect_err("version")), 4);
        let mut not_json = glb.clone();
        not_json[16..20].copy_from_slice(b"BIN\0");
        assert_eq!(offset_of(split(&not_json).expect_err("type")), 16);
        // Every prefix of a valid file is refused (the header's length no longer fits), none panics.
        for cut in 0..glb.len() {
            assert!(split(&glb[..cut]).is_err(), "prefix of {cut} bytes");
        }
        let message = split(&glb[..5]).expect_err("short").to_string();
        assert!(message.contains("at byte 5"), "{message}");
    }

    #[test]
    fn the_head_alone_finds_the_json_chunk_as_split_does() {
        let glb = write(b"{\"asset\":{}}", &[1; 8]).expect("write");
        let head = read_head(&glb[..HEAD], glb.len() as u64).expect("head");
        assert_eq!(head.total, glb.len());
        assert_eq!(&glb[head.json.clone()], split(&glb).expect("split").json);
        // Trailing bytes after the container are not its own.
        assert_eq!(read_head(&glb[..HEAD], glb.len() as u64 + 7).expect("longer file"), head);
        // The head refuses what split refuses for the header and the JSON chunk, at the same offset.
        let mut cases = Vec::new();
        for (at, value) in [(4, 1u32), (8, 1_000_000), (8, 16), (12, u32::MAX), (12, 1000)] {
            let mut liar = glb.clone();
            liar[at..at + 4].copy_from_slice(&value.to_le_bytes());
            cases.push(liar);
        }
        let mut not_json = glb.clone();
        not_json[16..20].copy_from_slice(b"BIN\0");
        cases.push(not_json);
        let mut not_glb = glb.clone();
        not_glb[0] = b'x';
        cases.push(not_glb);
        for case in &cases {
            let from_head = read_head(&case[..HEAD], case.len() as u64).expect_err("head");
            assert_eq!(from_head, split(case).expect_err("split"));
        }
        // A file shorter than the header, and a head cut shorter than the file has.
        for cut in 0..HEADER {
            assert_eq!(offset_of(read_head(&glb[..cut], cut as u64).expect_err("short file")), cut);
            assert_eq!(offset_of(read_head(&glb[..cut], glb.len() as u64).expect_err("short head")), cut);
        }
        assert!(read_head(&glb[..HEAD - 1], glb.len() as u64).is_err(), "no chunk type");
    }

    #[test]
    fn a_chunk_header_cut_short_is_an_error() {
        let mut glb = write(b"{}", &[]).expect("write");
        glb.extend_from_slice(&[0; 4]);
        let total = glb.len() as u32;
        glb[8..12].copy_from_slice(&total.to_le_bytes());
        assert_eq!(offset_of(split(&glb).expect_err("cut chunk")), 24 + 4);
    }
}
