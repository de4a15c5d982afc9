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

/** The 4x4 column-major matrix of a glTF node (its `matrix`, or translation * rotation * scale). */
function nodeMatrix(node) {
  if (Array.isArray(node.matrix) && node.matrix.length === 16) return node.matrix;
  const [tx, ty, tz] = node.translation ?? [0, 0, 0];
  const [x, y, z, w] = node.rotation ?? [0, 0, 0, 1];
  const [sx, sy, sz] = node.scale ?? [1, 1, 1];
  return [
    (1 - 2 * (y * y + z * z)) * sx, 2 * (x * y + z * w) * sx, 2 * (x * z - y * w) * sx, 0,
    2 * (x * y - z * w) * sy, (1 - 2 * (x * x + z * z)) * sy, 2 * (y * z + x * w) * sy, 0,
    2 * (x * z + y * w) * sz, 2 * (y * z - x * w) * sz, (1 - 2 * (x * x + y * y)) * sz, 0,
    tx, ty, tz, 1,
  ];
}

function multiply(a, b) {
  const out = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) out[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return out;
}

/**
 * The box, in the glTF's scene axes, around every corner of the POSITION accessors' min/max boxes of the
 * default scene's meshes, each carried through its node's world matrix; null if there is none. CesiumJS 1.145's
 * Model.boundingSphere carries only the two points (min) and (max) through a node's matrix, which shrinks the
 * box of a scene whose nodes are rotated differently (two instances of one mesh, one turned 90 degrees and one
 * upside down, framed a sphere a third of the size), so the harness frames the camera on this box instead.
 */
export function sceneBox(json) {
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  const scene = json.scenes?.[json.scene ?? 0];
  const visit = (index, parent, depth) => {
    const node = json.nodes?.[index];
    if (!node || depth > 64) return;
    const m = multiply(parent, nodeMatrix(node));
    for (const primitive of json.meshes?.[node.mesh]?.primitives ?? []) {
      const accessor = json.accessors?.[primitive.attributes?.POSITION];
      if (!accessor?.min || !accessor?.max) continue;
      for (let corner = 0; corner < 8; corner++) {
        const p = [0, 1, 2].map((i) => ((corner >> i) & 1 ? accessor.max[i] : accessor.min[i]));
        for (let i = 0; i < 3; i++) {
          const v = m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i];
          min[i] = Math.min(min[i], v);
          max[i] = Math.max(max[i], v);
        }
      }
    }
    for (const child of node.children ?? []) visit(child, m, depth + 1);
  };
  const identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  for (const index of scene?.nodes ?? []) visit(index, identity, 0);
  return min.every(Number.isFinite) && max.every(Number.isFinite) ? [...min, ...max] : null;
}
