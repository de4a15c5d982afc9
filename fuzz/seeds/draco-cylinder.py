#!/usr/bin/env python3
"""Writes cylinder.gltf + cylinder.bin: a 12-sided capped cylinder (52 points, 48 triangles) with
NORMAL, TEXCOORD_0 and COLOR_0 (u, v, 0.5, 1), instanced twice. draco-cylinder.glb beside this
script is its Draco form, made with Google's transcoder (Debian's `draco` 1.5.5):

    python3 draco-cylinder.py && draco_transcoder -i cylinder.gltf -o draco-cylinder.glb

(positions 11 bits, texture coordinates 10, normals 8 (octahedral), colors 8; indices as bytes).
The fuzzer mutates it (fuzz/src/seeds.rs) and crates/drafter-format/tests/draco.rs checks its
decoding against this definition."""
import json, math, struct

SEGMENTS = 12
pos, nor, uv, idx = [], [], [], []


def add(p, n, t):
    pos.append(p)
    nor.append(n)
    uv.append(t)
    return len(pos) - 1


for i in range(SEGMENTS + 1):
    a = 2 * math.pi * i / SEGMENTS
    c, s = math.cos(a), math.sin(a)
    add((c, s, 0.0), (c, s, 0.0), (i / SEGMENTS, 0.0))
    add((c, s, 2.0), (c, s, 0.0), (i / SEGMENTS, 1.0))
for i in range(SEGMENTS):
    a, b, c, d = 2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3
    idx += [a, c, b, b, c, d]
for z, nz in ((0.0, -1.0), (2.0, 1.0)):
    centre = add((0, 0, z), (0, 0, nz), (0.5, 0.5))
    ring = []
    for i in range(SEGMENTS):
        a = 2 * math.pi * i / SEGMENTS
        ring.append(add((math.cos(a), math.sin(a), z), (0, 0, nz), (0.5 + 0.5 * math.cos(a), 0.5 + 0.5 * math.sin(a))))
    for i in range(SEGMENTS):
        j = (i + 1) % SEGMENTS
        idx += [centre, ring[j], ring[i]] if nz < 0 else [centre, ring[i], ring[j]]
col = [(t[0], t[1], 0.5, 1.0) for t in uv]

data, views, accessors = b"", [], []


def view(chunk):
    global data
    data += b"\0" * (-len(data) % 4)
    views.append({"buffer": 0, "byteOffset": len(data), "byteLength": len(chunk)})
    data += chunk
    return len(views) - 1


def floats(values, kind, bounds=False):
    k = len(values[0])
    accessor = {"bufferView": view(b"".join(struct.pack("<%df" % k, *v) for v in values)),
                "componentType": 5126, "count": len(values), "type": kind}
    if bounds:
        accessor["min"] = [min(v[i] for v in values) for i in range(k)]
        accessor["max"] = [max(v[i] for v in values) for i in range(k)]
    accessors.append(accessor)
    return len(accessors) - 1


P, N, T, C = floats(pos, "VEC3", True), floats(nor, "VEC3"), floats(uv, "VEC2"), floats(col, "VEC4")
accessors.append({"bufferView": view(b"".join(struct.pack("<H", i) for i in idx)), "componentType": 5123,
                  "count": len(idx), "type": "SCALAR"})
doc = {
    "asset": {"version": "2.0", "generator": "drafter issue 61 Draco seed"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"name": "cylinder", "mesh": 0}, {"name": "copy", "mesh": 0, "translation": [3, 0, 0]}],
    "meshes": [{"name": "cylinder", "primitives": [
        {"attributes": {"POSITION": P, "NORMAL": N, "TEXCOORD_0": T, "COLOR_0": C}, "indices": len(accessors) - 1,
         "material": 0}]}],
    "materials": [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1]}}],
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(data), "uri": "cylinder.bin"}],
}
open("cylinder.bin", "wb").write(data)
json.dump(doc, open("cylinder.gltf", "w"), indent=1)
