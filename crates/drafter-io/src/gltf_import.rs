//! glTF 2.0 importer (.gltf with external or data-URI buffers, and .glb).
//!
//! The JSON is parsed and validated by the `gltf` crate; buffers and accessors are resolved here by
//! hand, because the crate's `import` follows any URI (absolute paths, `..`) and its accessor reader
//! assumes float positions, while we must (a) confine URIs to the file's folder, (b) read
//! KHR_mesh_quantization's integer positions and normals, and (c) check every accessor against its
//! buffer view and buffer, naming the accessor when it does not fit. KHR_draco_mesh_compression
//! streams are decoded by drafter-format (`draco::decompress`) once the buffers are loaded, and the
//! rest of the import reads the plain document it returns.
//!
//! Scene model: every glTF mesh becomes one [`Mesh`] (its primitives concatenated, one
//! [`TriangleGroup`] per primitive, so `MeshId` = glTF mesh index); every node of the default scene
//! (else the first) that has a mesh becomes an [`Instance`] with its world transform composed in f64.
//! Strips and fans are turned into triangle lists with the spec's winding rule; points and lines are
//! skipped with a diagnostic. Mirrored instances keep the mesh as stored: [`Instance::flips_winding`]
//! tells consumers to flip it in the world.

use std::path::Path;

use drafter_core::{
    DiagnosticKind, Diagnostics, Instance, Material, MaterialId, Mesh, MeshId, Node, NodeId, Scene, SourceDocument,
    SourceFormat, TriangleGroup,
};
use drafter_format::accessor::{self, ComponentType, Layout};
use drafter_format::uri::read_buffer_uri;
use drafter_format::{draco, glb};
use glam::{DMat4, DQuat, DVec3, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::json::validation::Validate as _;
use gltf::mesh::Mode;

use crate::Limits;
use crate::error::{ImportError, ParseError};
use crate::raw::drop_nonfinite_faces;

/// Required extensions we can honour: quantized attributes are decoded here, Draco streams by
/// drafter-format before the scene is built; the others change only appearance or textures, which
/// the bake does not decode.
const ACCEPTED_REQUIRED_EXTENSIONS: &[&str] = &[
    "KHR_mesh_quantization",
    // Decoded into plain accessors before the scene is built (drafter-format's draco.rs).
    "KHR_draco_mesh_compression",
    "KHR_texture_transform",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "KHR_lights_punctual",
];

pub(crate) fn import(
    path: &Path,
    bytes: &[u8],
    limits: &Limits,
    diagnostics: &mut Diagnostics,
) -> Result<Scene, ImportError> {
    // The container is split by drafter-core's framer (the workspace's one GLB reader), so the gltf
    // crate only ever sees JSON and a lying header is refused with the offset of the bad field.
    let (format, json_bytes, blob) = if glb::is_glb(bytes) {
        let chunks = glb::split(bytes).map_err(|e| glb_error(e).in_path(path))?;
        (SourceFormat::Glb, chunks.json, chunks.bin)
    } else {
        (SourceFormat::Gltf, bytes, None)
    };
    // Parsed as JSON and wrapped, never through `gltf::Gltf::from_slice*`: that reads a text that
    // begins with `glTF` as a GLB of its own, and gltf-1.4.1 `src/binary.rs:252` subtracts the
    // header's size from its length unchecked (a panic in builds with overflow checks, for a JSON
    // chunk that is a GLB header claiming fewer than 12 bytes).
    let root: gltf::json::Root = gltf::json::deserialize::from_slice(json_bytes)
        .map_err(|e| gltf_error(gltf::Error::Deserialize(e)).in_path(path))?;
    let document = gltf::Document::from_json_without_validation(root);
    check_required_extensions(document.as_json()).map_err(|e| e.in_path(path))?;
    // Draco-compressed accessors have no bufferView until the streams are decoded below (and
    // validated again then).
    let draco_pending = draco::mentions_extension(json_bytes);
    validate(document.as_json(), draco_pending).map_err(|e| e.in_path(path))?;
    check_listed_triangles(&document, limits).map_err(|e| e.in_path(path))?;
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut buffers = load_buffers(&document, blob, folder).map_err(|e| e.in_path(path))?;
    // KHR_draco_mesh_compression: the streams are decoded once, by drafter-format, into a document
    // whose accessors point at the decoded data in one more buffer; everything below, and the
    // writer's pass-through, reads that plain document. The face counts were held against the
    // limit above (the decoder refuses a stream that declares other counts than the accessors).
    let (document, json) = match draco::decompress(json_bytes, &buffers) {
        Ok(None) => (document, String::from_utf8_lossy(json_bytes).into_owned()),
        Ok(Some(decoded)) => {
            buffers.push(decoded.buffer);
            let root: gltf::json::Root = gltf::json::deserialize::from_str(&decoded.json)
                .map_err(|e| ParseError::in_file(format!("{}: {e}", draco::EXTENSION)).in_path(path))?;
            validate(&root, false).map_err(|e| e.in_path(path))?;
            (gltf::Document::from_json_without_validation(root), decoded.json)
        }
        Err(e) => {
            return Err(ParseError::at_json(e.place, format!("{}: {}", draco::EXTENSION, e.message)).in_path(path));
        }
    };
    let doc = &document;
    let mut scene = build_scene(doc, &buffers, format, diagnostics).map_err(|e| e.in_path(path))?;
    // Keep the JSON text as written (not re-serialised), so nothing the gltf crate does not model is
    // lost; only image files beside it are taken in (`embed_image_files`). A Draco input's is the
    // decoded document's.
    let names_files =
        doc.images().any(|i| matches!(i.source(), gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:")));
    let json = if names_files { embed_image_files(json, &mut buffers, folder, diagnostics) } else { json };
    scene.source = Some(std::sync::Arc::new(SourceDocument { json, buffers }));
    Ok(scene)
}

/// Refuses a document whose primitives list more than `limits.max_triangles` triangles, counted
/// from the accessors' counts before any is read: primitives may list the same accessors again, so
/// a few kilobytes of JSON can describe billions of triangles (each of which the import would
/// build). Names the primitive at which the count passes the limit.
fn check_listed_triangles(doc: &gltf::Document, limits: &Limits) -> Result<(), ParseError> {
    let mut listed = 0u64;
    for mesh in doc.meshes() {
        for primitive in mesh.primitives() {
            listed += drafter_format::gltf::triangle_count(
                Some(u64::from(primitive.mode().as_gl_enum())),
                primitive.indices().map(|a| a.count() as u64),
                primitive.get(&gltf::Semantic::Positions).map(|a| a.count() as u64),
            );
            if listed > limits.max_triangles {
                let place = format!("/meshes/{}/primitives/{}", mesh.index(), primitive.index());
                return Err(ParseError::at_json(
                    place,
                    format!(
                        "the meshes list {} triangles up to here, more than the limit of {} (--max-triangles; \
                         primitives may list the same accessors again)",
                        drafter_core::thousands(listed.min(usize::MAX as u64) as usize),
                        drafter_core::thousands(limits.max_triangles.min(usize::MAX as u64) as usize)
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn glb_error(e: glb::GlbError) -> ParseError {
    match e {
        glb::GlbError::Malformed { offset, message } => {
            ParseError::at_byte(offset as u64, format!("invalid GLB container: {message}"))
        }
        too_large @ glb::GlbError::TooLarge(_) => ParseError::in_file(too_large.to_string()),
    }
}

fn gltf_error(e: gltf::Error) -> ParseError {
    match e {
        gltf::Error::Deserialize(e) => {
            ParseError::at_line(e.line(), format!("invalid glTF JSON: {}", strip_position(&e.to_string())))
        }
        gltf::Error::Binary(e) => ParseError::in_file(format!("invalid GLB container: {e}")),
        gltf::Error::Validation(errors) => validation_error(&errors),
        other => ParseError::in_file(other.to_string()),
    }
}

/// serde_json appends " at line L column C"; the place is reported separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}

/// Turns gltf-json's `meshes[0].primitives[1].attributes["POSITION"]` into a JSON pointer.
fn json_pointer(path: &str) -> String {
    let mut out = String::new();
    for part in path.split('.') {
        let mut rest = part;
        if let Some(i) = rest.find('[') {
            out.push('/');
            out.push_str(&rest[..i]);
            rest = &rest[i..];
            while let Some(end) = rest.find(']') {
                out.push('/');
                out.push_str(rest[1..end].trim_matches('"'));
                rest = &rest[end + 1..];
            }
        } else {
            out.push('/');
            out.push_str(rest);
        }
    }
    out
}

fn validation_error(errors: &[(gltf::json::Path, gltf::json::validation::Error)]) -> ParseError {
    let Some((path, error)) = errors.first() else {
        return ParseError::in_file("invalid glTF");
    };
    let more = if errors.len() > 1 { format!(" (and {} more problems)", errors.len() - 1) } else { String::new() };
    ParseError::at_json(json_pointer(path.as_str()), format!("invalid glTF: {error}{more}"))
}

fn check_required_extensions(root: &gltf::json::Root) -> Result<(), ParseError> {
    for (i, name) in root.extensions_required.iter().enumerate() {
        let accepted = ACCEPTED_REQUIRED_EXTENSIONS.contains(&name.as_str()) || name.starts_with("KHR_materials_");
        if !accepted {
            return Err(ParseError::at_json(
                format!("/extensionsRequired/{i}"),
                format!(
                    "requires extension {name}, which drafter cannot decode (decompress or convert the file first)"
                ),
            ));
        }
    }
    Ok(())
}

/// Validates `root`; with `draco_pending`, an accessor's missing `bufferView` is let through (a
/// Draco stream fills it, and the decoded document is validated again).
fn validate(root: &gltf::json::Root, draco_pending: bool) -> Result<(), ParseError> {
    // gltf-json 1.4's validation indexes `accessors` with a primitive's POSITION unchecked (its
    // min/max rule in mesh.rs), so an out-of-range POSITION would panic inside the dependency:
    // refuse it here first, as the validator would.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(index) = primitive.attributes.get(&position)
                && index.value() >= root.accessors.len()
            {
                return Err(ParseError::at_json(
                    format!("/meshes/{m}/primitives/{p}/attributes/POSITION"),
                    format!("accessor {} does not exist (the file has {})", index.value(), root.accessors.len()),
                ));
            }
        }
    }
    // glTF requires every accessor to hold at least one element; the writer passes the source's
    // accessors through, so an empty one would make the baked file invalid as well.
    if let Some(a) = root.accessors.iter().position(|a| a.count.0 == 0) {
        return Err(ParseError::at_json(format!("/accessors/{a}/count"), "count is 0 (glTF requires at least 1)"));
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path();
        // Required extensions were checked above against what we really support.
        let is_required_extension = path.as_str().starts_with("extensionsRequired");
        let filled_by_draco = draco_pending
            && error == gltf::json::validation::Error::Missing
            && path.as_str().starts_with("accessors[")
            && path.as_str().ends_with(".bufferView");
        if filled_by_draco {
            return;
        }
        if !(is_required_extension && error == gltf::json::validation::Error::Unsupported) {
            errors.push((path, error));
        }
    });
    if !errors.is_empty() {
        return Err(validation_error(&errors));
    }
    check_what_the_crate_unwraps(root)
}

/// What gltf-json 1.4.1's validation lets through but the gltf crate's accessors unwrap, so that a
/// call panics (read from the crate's source; every other `unwrap`, `expect`, index and
/// `unreachable!` on the paths drafter calls is an index or enum the validation above checks):
///
/// * gltf-1.4.1 `src/image.rs:128`: `Image::source` unwraps `uri` when there is no `bufferView`
///   (an image `{}`); the importer asks every image's source;
/// * `src/image.rs:125`: it unwraps `mimeType` when there is a `bufferView` (the spec requires it
///   there);
/// * `src/camera.rs:82` and `:86`: `Camera::projection` unwraps the member its `type` names (the
///   crate's validation asks only for one of the two). drafter does not ask, but the writer passes
///   cameras through, and such a camera is invalid glTF in the baked file as well.
///
/// Each is refused here, before any of these is called, naming the object.
fn check_what_the_crate_unwraps(root: &gltf::json::Root) -> Result<(), ParseError> {
    use gltf::json::camera::Type;
    use gltf::json::validation::Checked;
    for (i, image) in root.images.iter().enumerate() {
        match (&image.uri, &image.buffer_view, &image.mime_type) {
            (None, None, _) => {
                return Err(ParseError::at_json(format!("/images/{i}"), "an image needs a uri or a bufferView"));
            }
            (_, Some(_), None) => {
                return Err(ParseError::at_json(format!("/images/{i}"), "an image in a bufferView needs a mimeType"));
            }
            _ => {}
        }
    }
    for (i, camera) in root.cameras.iter().enumerate() {
        let missing = match camera.type_ {
            Checked::Valid(Type::Perspective) if camera.perspective.is_none() => "perspective",
            Checked::Valid(Type::Orthographic) if camera.orthographic.is_none() => "orthographic",
            _ => continue,
        };
        return Err(ParseError::at_json(
            format!("/cameras/{i}"),
            format!("a camera of type {missing} needs the member {missing}"),
        ));
    }
    Ok(())
}

/// Images the source names by a file URI, moved into buffers of their own (a buffer view and a
/// MIME type instead of the URI), so that the baked file, which is written elsewhere and passes
/// the source's images through, does not point at files that are not beside it. An image file
/// that cannot be read (the same rules as buffers: inside the folder) or is neither PNG nor JPEG
/// keeps its URI, with a note. Called only where some image names a file (the text is parsed
/// again here, so most inputs skip it).
fn embed_image_files(json: String, buffers: &mut Vec<Vec<u8>>, folder: &Path, diagnostics: &mut Diagnostics) -> String {
    // drafter-format's typed document, which writes back every member it does not name.
    use drafter_format::gltf as typed;
    let Ok(mut root) = typed::Root::from_slice(json.as_bytes()) else { return json };
    let mut kept = Vec::new();
    for i in 0..root.images().len() {
        let Some(uri) = root.images()[i].uri.clone().filter(|u| !u.starts_with("data:")) else { continue };
        let mime = match read_buffer_uri(folder, &uri) {
            Ok(bytes) if bytes.starts_with(b"\x89PNG\r\n\x1a\n") => Ok(("image/png", bytes)),
            Ok(bytes) if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) => Ok(("image/jpeg", bytes)),
            Ok(_) => Err("neither PNG nor JPEG".to_owned()),
            Err(e) => Err(e),
        };
        let (mime, bytes) = match mime {
            Ok(found) => found,
            Err(why) => {
                kept.push(format!("/images/{i} ({uri}): {why}"));
                continue;
            }
        };
        let (buffer, length) = (buffers.len() as u64, Some(bytes.len() as u64));
        buffers.push(bytes);
        root.buffers.get_or_insert_default().push(typed::Buffer { byte_length: length, ..typed::Buffer::default() });
        let views = root.buffer_views.get_or_insert_default();
        views.push(typed::BufferView { buffer: Some(buffer), byte_length: length, ..typed::BufferView::default() });
        let view = Some(views.len() as u64 - 1);
        if let Some(image) = root.images.as_mut().and_then(|images| images.get_mut(i)) {
            image.uri = None;
            image.buffer_view = view;
            image.mime_type = Some(mime.to_owned());
        }
    }
    if let Some(first) = kept.first() {
        diagnostics.push(DiagnosticKind::Output, kept.len(), || {
            format!("{first}; the image keeps its URI, which the baked file's folder may not have")
        });
    }
    serde_json::Value::from(root).to_string()
}

fn load_buffers(doc: &gltf::Document, blob: Option<&[u8]>, folder: &Path) -> Result<Vec<Vec<u8>>, ParseError> {
    let mut out = Vec::with_capacity(doc.buffers().len());
    for buffer in doc.buffers() {
        let pointer = format!("/buffers/{}", buffer.index());
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => match blob {
                Some(bin) if buffer.index() == 0 => bin.to_vec(),
                _ => return Err(ParseError::at_json(pointer, "buffer has no uri and there is no GLB BIN chunk")),
            },
            gltf::buffer::Source::Uri(uri) => {
                read_buffer_uri(folder, uri).map_err(|m| ParseError::at_json(&pointer, m))?
            }
        };
        if data.len() < buffer.length() {
            return Err(ParseError::at_json(
                pointer,
                format!("byteLength is {} but only {} bytes are available", buffer.length(), data.len()),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// Reads accessor `accessor` as `N`-component float vectors, de-quantising integer types
/// (normalised or not, KHR_mesh_quantization) and applying sparse substitution.
fn read_vectors<const N: usize>(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<[f32; N]>, ParseError> {
    let pointer = format!("/accessors/{}", accessor.index());
    let expected = match N {
        1 => Dimensions::Scalar,
        2 => Dimensions::Vec2,
        3 => Dimensions::Vec3,
        _ => Dimensions::Vec4,
    };
    if accessor.dimensions() != expected {
        return Err(ParseError::at_json(
            pointer,
            format!("expected type {expected:?}, found {:?}", accessor.dimensions()),
        ));
    }
    let count = accessor.count();
    let ty = component_type(accessor.data_type());
    let component = ty.size();
    let element = component * N;
    let normalized = accessor.normalized();
    let mut out = match accessor.view() {
        Some(view) => {
            let bytes = view_bytes(&view, buffers)?;
            let start = accessor.offset();
            // A stride below one element is read as packed, as before the shared decoder.
            let stride = view.stride().unwrap_or(element).max(element);
            let Ok(layout) = Layout::new(bytes.len(), Some(stride), start, count, element) else {
                return Err(ParseError::at_json(
                    pointer,
                    format!(
                        "{count} elements of {element} bytes (stride {stride}, offset {start}) do not fit in bufferView {} of {} bytes",
                        view.index(),
                        bytes.len()
                    ),
                ));
            };
            accessor::read_vectors::<N>(bytes, &layout, ty, normalized)
        }
        None => {
            // No buffer view: zeros (then sparse). The count has no data behind it, so it is bounded
            // by what the file holds: its elements, stored densely, must fit in the file's buffers
            // (a real sparse accessor, a morph target's, has as many elements as a dense accessor
            // beside it). Without that, 30 bytes of JSON would allocate gigabytes.
            if accessor.sparse().is_none() {
                return Err(ParseError::at_json(pointer, "accessor has neither bufferView nor sparse data"));
            }
            let held: usize = buffers.iter().map(Vec::len).sum();
            if count.checked_mul(element).is_none_or(|bytes| bytes > held) {
                return Err(ParseError::at_json(
                    pointer,
                    format!(
                        "sparse accessor without bufferView has {count} elements of {element} bytes, more than the file's {held} buffer bytes"
                    ),
                ));
            }
            vec![[0.0f32; N]; count]
        }
    };
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices_view = sparse.indices().view();
        let index_bytes = view_bytes(&indices_view, buffers)?;
        let index_type = sparse.indices().index_type();
        let index_size = match index_type {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let index_start = sparse.indices().offset();
        let values_view = sparse.values().view();
        let value_bytes = view_bytes(&values_view, buffers)?;
        let value_start = sparse.values().offset();
        let fits = |start: usize, size: usize, len: usize| {
            n.checked_mul(size).and_then(|x| x.checked_add(start)).is_some_and(|end| end <= len)
        };
        if !fits(index_start, index_size, index_bytes.len()) || !fits(value_start, element, value_bytes.len()) {
            return Err(ParseError::at_json(
                format!("{pointer}/sparse"),
                format!("{n} sparse entries do not fit in their buffer views"),
            ));
        }
        for k in 0..n {
            let at = index_start + k * index_size;
            let target = match index_size {
                1 => index_bytes[at] as usize,
                2 => u16::from_le_bytes([index_bytes[at], index_bytes[at + 1]]) as usize,
                _ => {
                    u32::from_le_bytes([index_bytes[at], index_bytes[at + 1], index_bytes[at + 2], index_bytes[at + 3]])
                        as usize
                }
            };
            let Some(slot) = out.get_mut(target) else {
                return Err(ParseError::at_json(
                    format!("{pointer}/sparse"),
                    format!("sparse index {target} is out of range ({count} elements)"),
                ));
            };
            let at = value_start + k * element;
            for (c, value) in slot.iter_mut().enumerate() {
                *value = ty.decode(&value_bytes[at + c * component..], normalized);
            }
        }
    }
    Ok(out)
}

fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Vec<u8>]) -> Result<&'b [u8], ParseError> {
    let buffer = &buffers[view.buffer().index()];
    let declared = view.buffer().length().min(buffer.len());
    let start = view.offset();
    match start.checked_add(view.length()) {
        Some(end) if end <= declared => Ok(&buffer[start..end]),
        _ => Err(ParseError::at_json(
            format!("/bufferViews/{}", view.index()),
            format!(
                "bytes {start}..{} lie outside buffer {} of {declared} bytes",
                start.saturating_add(view.length()),
                view.buffer().index()
            ),
        )),
    }
}

/// The shared decoder's name for a component type.
fn component_type(data_type: DataType) -> ComponentType {
    match data_type {
        DataType::I8 => ComponentType::I8,
        DataType::U8 => ComponentType::U8,
        DataType::I16 => ComponentType::I16,
        DataType::U16 => ComponentType::U16,
        DataType::U32 => ComponentType::U32,
        DataType::F32 => ComponentType::F32,
    }
}

fn read_indices(accessor: &gltf::Accessor, buffers: &[Vec<u8>], vertex_count: usize) -> Result<Vec<u32>, ParseError> {
    let pointer = format!("/accessors/{}", accessor.index());
    if accessor.dimensions() != Dimensions::Scalar {
        return Err(ParseError::at_json(pointer, "index accessor is not SCALAR"));
    }
    let ty = component_type(accessor.data_type());
    if !matches!(ty, ComponentType::U8 | ComponentType::U16 | ComponentType::U32) {
        return Err(ParseError::at_json(
            pointer,
            format!("index component type {:?} is not unsigned", accessor.data_type()),
        ));
    }
    if accessor.sparse().is_some() || accessor.view().is_none() {
        // Sparse or view-less indices are legal but meaningless for geometry; read generically.
        let values = read_vectors::<1>(accessor, buffers)?;
        return values
            .into_iter()
            .enumerate()
            .map(|(i, [v])| check_index(v as u32, i, vertex_count, &pointer))
            .collect();
    }
    let Some(view) = accessor.view() else { return Ok(Vec::new()) };
    let bytes = view_bytes(&view, buffers)?;
    let count = accessor.count();
    let start = accessor.offset();
    let stride = view.stride().unwrap_or(ty.size()).max(ty.size());
    let Ok(layout) = Layout::new(bytes.len(), Some(stride), start, count, ty.size()) else {
        return Err(ParseError::at_json(
            pointer,
            format!(
                "{count} indices (offset {start}) do not fit in bufferView {} of {} bytes",
                view.index(),
                bytes.len()
            ),
        ));
    };
    // Decoded in one loop, then checked in a second pass.
    let out = accessor::read_indices(bytes, &layout, ty).unwrap_or_default();
    if let Some(i) = out.iter().position(|&v| v as usize >= vertex_count) {
        check_index(out[i], i, vertex_count, &pointer)?;
    }
    Ok(out)
}

fn check_index(v: u32, i: usize, vertex_count: usize, pointer: &str) -> Result<u32, ParseError> {
    if (v as usize) < vertex_count {
        Ok(v)
    } else {
        Err(ParseError::at_json(pointer, format!("index {v} at element {i} is out of range ({vertex_count} vertices)")))
    }
}

/// Triangles of a primitive in list form (glTF 2.0 spec §3.7.2.1 for strips and fans).
fn assemble_triangles(mode: Mode, indices: &[u32]) -> (Vec<[u32; 3]>, usize) {
    let n = indices.len();
    match mode {
        Mode::Triangles => {
            let tris = indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            (tris, n % 3)
        }
        Mode::TriangleStrip => {
            let tris = (0..n.saturating_sub(2))
                .map(|i| {
                    if i % 2 == 0 {
                        [indices[i], indices[i + 1], indices[i + 2]]
                    } else {
                        [indices[i + 1], indices[i], indices[i + 2]]
                    }
                })
                .collect();
            (tris, 0)
        }
        Mode::TriangleFan => {
            let tris = (1..n.saturating_sub(1)).map(|i| [indices[i], indices[i + 1], indices[0]]).collect();
            (tris, 0)
        }
        _ => (Vec::new(), 0),
    }
}

fn build_scene(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    format: SourceFormat,
    diagnostics: &mut Diagnostics,
) -> Result<Scene, ParseError> {
    let mut scene = Scene::new(format);
    scene.materials = doc
        .materials()
        .map(|m| {
            let pbr = m.pbr_metallic_roughness();
            Material {
                name: m.name().unwrap_or_default().to_owned(),
                base_color: pbr.base_color_factor(),
                metallic: pbr.metallic_factor(),
                roughness: pbr.roughness_factor(),
            }
        })
        .collect();
    for mesh in doc.meshes() {
        scene.meshes.push(import_mesh(&mesh, buffers, diagnostics)?);
    }
    if doc.skins().len() > 0 || doc.animations().len() > 0 {
        diagnostics.push(DiagnosticKind::Ignored, doc.skins().len() + doc.animations().len(), || {
            "skins and animations are ignored; meshes are taken in their bind/rest pose".into()
        });
    }

    // Nodes, with parents derived from the children lists (first parent wins).
    let node_count = doc.nodes().len();
    scene.nodes = doc
        .nodes()
        .map(|n| Node {
            name: n.name().unwrap_or_default().to_owned(),
            parent: None,
            children: n.children().map(|c| NodeId::from(c.index())).collect(),
            parent_from_local: local_transform(&n),
            mesh: n.mesh().map(|m| MeshId::from(m.index())),
        })
        .collect();
    for i in 0..node_count {
        for c in scene.nodes[i].children.clone() {
            if scene.nodes[c.index()].parent.is_none() && c.index() != i {
                scene.nodes[c.index()].parent = Some(NodeId::from(i));
            }
        }
    }
    let roots: Vec<NodeId> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().map(|n| NodeId::from(n.index())).collect(),
        None => {
            diagnostics.push(DiagnosticKind::NoScene, 1, || "every parentless node is taken as a root".into());
            (0..node_count).filter(|&i| scene.nodes[i].parent.is_none()).map(NodeId::from).collect()
        }
    };
    scene.roots = roots.clone();

    // Depth-first walk; a node reached twice (cycle or shared child) is reported and skipped.
    let mut visited = vec![false; node_count];
    let mut stack: Vec<(NodeId, DMat4)> = roots.iter().rev().map(|&r| (r, DMat4::IDENTITY)).collect();
    while let Some((id, parent_world)) = stack.pop() {
        if std::mem::replace(&mut visited[id.index()], true) {
            diagnostics
                .push(DiagnosticKind::NodeCycle, 1, || format!("node {id} is reached more than once; repeat skipped"));
            continue;
        }
        let node = &scene.nodes[id.index()];
        let world = parent_world * node.parent_from_local;
        if !world.is_finite() {
            diagnostics.push(DiagnosticKind::BadTransform, 1, || {
                format!("node {id} has a non-finite transform; subtree skipped")
            });
            continue;
        }
        if let Some(mesh) = node.mesh {
            let name = if node.name.is_empty() {
                let mesh_name = &scene.meshes[mesh.index()].name;
                if mesh_name.is_empty() { format!("node {id}") } else { mesh_name.clone() }
            } else {
                node.name.clone()
            };
            scene.instances.push(Instance { name, mesh, node: Some(id), world_from_object: world });
        }
        for &child in node.children.iter().rev() {
            stack.push((child, world));
        }
    }
    Ok(scene)
}

fn local_transform(node: &gltf::Node) -> DMat4 {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from))),
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            let rotation = DQuat::from_array(rotation.map(f64::from));
            let rotation = if rotation.length_squared() > 0.0 { rotation.normalize() } else { DQuat::IDENTITY };
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                rotation,
                DVec3::from_array(translation.map(f64::from)),
            )
        }
    }
}

fn import_mesh(mesh: &gltf::Mesh, buffers: &[Vec<u8>], diagnostics: &mut Diagnostics) -> Result<Mesh, ParseError> {
    let mut out = Mesh { name: mesh.name().unwrap_or_default().to_owned(), ..Mesh::default() };
    let mut normals: Vec<Vec3> = Vec::new();
    let mut uvs: Vec<Vec2> = Vec::new();
    let mut all_have_normals = true;
    let mut all_have_uvs = true;
    for primitive in mesh.primitives() {
        let place = || format!("/meshes/{}/primitives/{}", mesh.index(), primitive.index());
        let mode = primitive.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            diagnostics.push(DiagnosticKind::SkippedPrimitive, 1, || {
                format!("{}: mode {mode:?} is not triangles; skipped", place())
            });
            continue;
        }
        let Some(position_accessor) = primitive.get(&gltf::Semantic::Positions) else {
            diagnostics.push(DiagnosticKind::SkippedPrimitive, 1, || format!("{}: no POSITION; skipped", place()));
            continue;
        };
        let positions = read_vectors::<3>(&position_accessor, buffers)?;
        let vertex_count = positions.len();
        let indices = match primitive.indices() {
            Some(a) => read_indices(&a, buffers, vertex_count)?,
            None => (0..vertex_count as u32).collect(),
        };
        let (triangles, leftover) = assemble_triangles(mode, &indices);
        diagnostics.push(DiagnosticKind::IncompleteTriangle, leftover.min(1), || {
            format!("{}: index count {} is not a multiple of 3; the rest was dropped", place(), indices.len())
        });
        let base = out.positions.len() as u32;
        let start = out.triangles.len() as u32;
        let mut part_normals = None;
        if let Some(a) = primitive.get(&gltf::Semantic::Normals) {
            match read_vectors::<3>(&a, buffers) {
                Ok(n) if n.len() == vertex_count => part_normals = Some(n),
                Ok(_) => diagnostics.push(DiagnosticKind::InvalidNormals, 1, || {
                    format!("{}: NORMAL count differs from POSITION; ignored", place())
                }),
                Err(e) => diagnostics.push(DiagnosticKind::InvalidNormals, 1, || {
                    format!("{}: NORMAL unreadable ({e}); ignored", place())
                }),
            }
        }
        let mut part_uvs = None;
        if let Some(a) = primitive.get(&gltf::Semantic::TexCoords(0)) {
            match read_vectors::<2>(&a, buffers) {
                Ok(t) if t.len() == vertex_count => part_uvs = Some(t),
                _ => diagnostics
                    .push(DiagnosticKind::InvalidTexcoords, 1, || format!("{}: TEXCOORD_0 unusable; ignored", place())),
            }
        }
        all_have_normals &= part_normals.is_some();
        all_have_uvs &= part_uvs.is_some();
        if all_have_normals {
            normals.extend(part_normals.unwrap_or_default().into_iter().map(Vec3::from));
        }
        if all_have_uvs {
            uvs.extend(part_uvs.unwrap_or_default().into_iter().map(Vec2::from));
        }
        out.positions.extend(positions.into_iter().map(Vec3::from));
        out.triangles.extend(triangles.into_iter().map(|t| t.map(|v| v + base)));
        out.groups.push(TriangleGroup {
            start,
            count: out.triangles.len() as u32 - start,
            material: primitive.material().index().map(MaterialId::from),
            primitive: Some(primitive.index() as u32),
            first_vertex: base,
            vertex_count: vertex_count as u32,
        });
    }
    drop_nonfinite_faces(
        &mut out.positions,
        &mut out.triangles,
        &mut out.groups,
        diagnostics,
        &format!("mesh {}", mesh.index()),
    );
    if all_have_normals && !out.positions.is_empty() {
        if normals.iter().all(|n| n.is_finite()) {
            out.normals = Some(normals);
        } else {
            diagnostics.push(DiagnosticKind::InvalidNormals, 1, || {
                format!("mesh {}: NORMAL has non-finite values; ignored", mesh.index())
            });
        }
    }
    if all_have_uvs && !out.positions.is_empty() && uvs.iter().all(|t| t.is_finite()) {
        out.uvs = Some(uvs);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_pointers() {
        assert_eq!(
            json_pointer("meshes[0].primitives[1].attributes[\"POSITION\"]"),
            "/meshes/0/primitives/1/attributes/POSITION"
        );
        assert_eq!(json_pointer("asset"), "/asset");
    }

    #[test]
    fn strips_and_fans_follow_the_spec() {
        let (strip, _) = assemble_triangles(Mode::TriangleStrip, &[0, 1, 2, 3, 4]);
        assert_eq!(strip, vec![[0, 1, 2], [2, 1, 3], [2, 3, 4]]);
        let (fan, _) = assemble_triangles(Mode::TriangleFan, &[0, 1, 2, 3]);
        assert_eq!(fan, vec![[1, 2, 0], [2, 3, 0]]);
        let (list, leftover) = assemble_triangles(Mode::Triangles, &[0, 1, 2, 3]);
        assert_eq!((list.len(), leftover), (1, 1));
    }

    #[test]
    fn image_files_move_into_buffers_and_the_rest_keep_their_uri() {
        let folder = std::env::temp_dir().join(format!("drafter-embed-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        std::fs::write(folder.join("a.png"), b"\x89PNG\r\n\x1a\nrest").unwrap();
        std::fs::write(folder.join("b.txt"), b"text").unwrap();
        let json = r#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":4,"uri":"m.bin"}],
            "images":[{"uri":"a.png","name":"a"},{"uri":"data:image/png;base64,AA=="},{"uri":"b.txt"},
            {"uri":"../c.png"}],"zUnknown":[1.0]}"#;
        let mut buffers = vec![vec![0; 4]];
        let mut diagnostics = Diagnostics::new();
        let out = embed_image_files(json.to_owned(), &mut buffers, &folder, &mut diagnostics);
        std::fs::remove_dir_all(&folder).unwrap();
        // The document's text with sorted members, everything but the embedded image as it was.
        assert_eq!(
            out,
            r#"{"asset":{"version":"2.0"},"bufferViews":[{"buffer":1,"byteLength":12}],"#.to_owned()
                + r#""buffers":[{"byteLength":4,"uri":"m.bin"},{"byteLength":12}],"#
                + r#""images":[{"bufferView":0,"mimeType":"image/png","name":"a"},"#
                + r#"{"uri":"data:image/png;base64,AA=="},{"uri":"b.txt"},{"uri":"../c.png"}],"zUnknown":[1.0]}"#
        );
        assert_eq!(buffers.len(), 2);
        assert!(!diagnostics.is_empty(), "the two images that keep their URI are noted");
        let same = embed_image_files("not json".to_owned(), &mut buffers, Path::new("."), &mut diagnostics);
        assert_eq!(same, "not json");
    }
}
