// Rewrites a glTF/GLB in memory so that EXT_mesh_primitive_edge_visibility edges get a colour of our choosing.
//
// Without the extension's `material`, CesiumJS draws edges in the primitive's own (lit) material colour,
// which is hard to tell apart from the faces in a screenshot. This adds one material whose baseColorFactor
// is the requested colour and points every edge extension (and its lineStrings) at it. CesiumJS writes that
// colour after lighting and without conversion, so an edge pixel comes out as the given 8-bit RGB
// (antialiasing aside).

const EXT = 'EXT_mesh_primitive_edge_visibility';
const GLB_MAGIC = 0x46546c67; // "glTF"
const CHUNK_JSON = 0x4e4f534a; // "JSON"

/** Splits a GLB into { json, rest } where rest is every chunk after the JSON one, as raw bytes. */
function splitGlb(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (view.getUint32(0, true) !== GLB_MAGIC) return null;
  const jsonLength = view.getUint32(12, true);
  if (view.getUint32(16, true) !== CHUNK_JSON) throw new Error('GLB: first chunk is not JSON');
  const json = JSON.parse(Buffer.from(bytes.subarray(20, 20 + jsonLength)).toString('utf8'));
  return { json, rest: bytes.subarray(20 + jsonLength, view.getUint32(8, true)) };
}

/** Packs a JSON object and the following raw chunks back into a GLB. */
function joinGlb(json, rest) {
  let text = Buffer.from(JSON.stringify(json), 'utf8');
  const pad = (4 - (text.length % 4)) % 4;
  text = Buffer.concat([text, Buffer.alloc(pad, 0x20)]); // JSON chunks are padded with spaces
  const header = Buffer.alloc(20);
  header.writeUInt32LE(GLB_MAGIC, 0);
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(20 + text.length + rest.length, 8);
  header.writeUInt32LE(text.length, 12);
  header.writeUInt32LE(CHUNK_JSON, 16);
  return Buffer.concat([header, text, rest]);
}

/** The JSON of a .glb or .gltf file. */
export function readGltfJson(bytes) {
  const glb = splitGlb(bytes);
  return glb ? glb.json : JSON.parse(Buffer.from(bytes).toString('utf8'));
}

/**
 * Returns { bytes, primitives }: the file with every edge extension drawn in `rgb` (three 0..255 numbers),
 * and how many primitives carry the extension. A .gltf (JSON) file is handled as well.
 */
export function withEdgeColor(bytes, rgb) {
  const glb = splitGlb(bytes);
  const json = glb ? glb.json : JSON.parse(Buffer.from(bytes).toString('utf8'));
  json.materials ??= [];
  const material = json.materials.length;
  json.materials.push({
    name: 'browser-test edge colour',
    pbrMetallicRoughness: { baseColorFactor: [...rgb.map((c) => c / 255), 1], metallicFactor: 0 },
  });
  let primitives = 0;
  for (const mesh of json.meshes ?? []) {
    for (const primitive of mesh.primitives ?? []) {
      const ext = primitive.extensions?.[EXT];
      if (!ext) continue;
      primitives++;
      ext.material = material;
      for (const lineString of ext.lineStrings ?? []) lineString.material = material;
    }
  }
  const out = glb ? joinGlb(json, glb.rest) : Buffer.from(JSON.stringify(json), 'utf8');
  return { bytes: out, primitives };
}
