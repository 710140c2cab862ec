#!/usr/bin/env python3
"""Writes tests/scenes/punctual-room.gltf: a room lit only by punctual lights (glTF's
KHR_lights_punctual), for renders that must reach every kind of light that is not a
surface through several bounces: a point light in a corner, a spot aimed at a block, and a
directional light (the sun) shining down through an opening in the ceiling. White diffuse
walls, a rough metal block; the camera stands by the front wall looking at the block.

Run from the repository root: python3 tools/punctual_room_scene.py
"""
import base64
import json
import math
import struct

W, H, D = 4.0, 3.0, 5.0  # room: x in [0, W], y in [0, H], z in [0, D]
HOLE = (1.5, 2.5)  # the ceiling's opening, in x and in z


def quad(out, a, b, c, d):
    """Quad a-b-c-d (counter-clockwise seen from its front) as two triangles."""
    out += [a, b, c, a, c, d]


walls = []
quad(walls, (0, 0, 0), (0, 0, D), (W, 0, D), (W, 0, 0))  # floor, facing +y
quad(walls, (0, 0, 0), (0, H, 0), (0, H, D), (0, 0, D))  # x = 0, facing +x
quad(walls, (W, 0, 0), (W, 0, D), (W, H, D), (W, H, 0))  # x = W, facing -x
quad(walls, (0, 0, 0), (W, 0, 0), (W, H, 0), (0, H, 0))  # z = 0, facing +z
quad(walls, (0, 0, D), (0, H, D), (W, H, D), (W, 0, D))  # z = D, facing -z
# The ceiling (facing -y) around the opening.
h0, h1 = HOLE


def ceiling(x0, x1, z0, z1):
    quad(walls, (x0, H, z0), (x1, H, z0), (x1, H, z1), (x0, H, z1))


ceiling(0, W, 0, h0)
ceiling(0, W, h1, D)
ceiling(0, h0, h0, h1)
ceiling(h1, W, h0, h1)

block = []
bx, bz, bs, bh = 1.4, 2.0, 1.0, 0.9  # corner, side, height
corners = [(bx + dx * bs, y, bz + dz * bs) for y in (0, bh) for dx in (0, 1) for dz in (0, 1)]
c = corners  # index: y * 4 + dx * 2 + dz
quad(block, c[4], c[5], c[7], c[6])  # top, facing +y
quad(block, c[0], c[4], c[6], c[2])  # z = bz, facing -z
quad(block, c[1], c[3], c[7], c[5])  # z = bz + bs, facing +z
quad(block, c[0], c[1], c[5], c[4])  # x = bx, facing -x
quad(block, c[2], c[6], c[7], c[3])  # x = bx + bs, facing +x


def look_rotation(direction):
    """The unit quaternion (x, y, z, w) turning -Z into `direction`."""
    n = math.sqrt(sum(v * v for v in direction))
    d = [v / n for v in direction]
    # Axis -Z x d, angle acos(-Z . d).
    axis = (d[1], -d[0], 0.0)
    s = math.sqrt(sum(v * v for v in axis))
    angle = math.acos(max(-1.0, min(1.0, -d[2])))
    if s < 1e-9:
        return [0.0, 0.0, 0.0, 1.0]
    k = math.sin(angle / 2) / s
    return [axis[0] * k, axis[1] * k, axis[2] * k, math.cos(angle / 2)]


blob = b""
accessors, views, primitives = [], [], []
for material, triangles in ((0, walls), (1, block)):
    data = b"".join(struct.pack("<3f", *v) for v in triangles)
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
    accessors.append({
        "bufferView": len(views) - 1,
        "componentType": 5126,
        "count": len(triangles),
        "type": "VEC3",
        "min": [min(v[i] for v in triangles) for i in range(3)],
        "max": [max(v[i] for v in triangles) for i in range(3)],
    })
    primitives.append({"attributes": {"POSITION": len(accessors) - 1}, "material": material})
    blob += data

gltf = {
    "asset": {"version": "2.0", "generator": "tools/punctual_room_scene.py"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"name": "corner lamp", "type": "point", "color": [1.0, 0.85, 0.7],
         "intensity": 683.0 * 1.0},
        {"name": "spot on the block", "type": "spot", "color": [0.8, 0.9, 1.0],
         "intensity": 683.0 * 40.0,
         "spot": {"innerConeAngle": 0.15, "outerConeAngle": 0.35}},
        {"name": "sun", "type": "directional", "color": [1.0, 0.95, 0.85],
         "intensity": 683.0 * 5.0},
    ]}},
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
    "nodes": [
        {"name": "room", "mesh": 0},
        {"name": "camera", "camera": 0, "translation": [2.0, 1.5, 4.8]},
        {"name": "corner lamp", "translation": [0.4, 2.6, 0.5],
         "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "spot", "translation": [3.6, 2.8, 4.0],
         "rotation": look_rotation((bx + bs / 2 - 3.6, bh - 2.8, bz + bs / 2 - 4.0)),
         "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"name": "sun", "rotation": look_rotation((0.45, -1.0, -0.3)),
         "extensions": {"KHR_lights_punctual": {"light": 2}}},
    ],
    "cameras": [{"type": "perspective",
                 "perspective": {"aspectRatio": 1.0, "yfov": 1.1, "znear": 0.01}}],
    "meshes": [{"primitives": primitives}],
    "materials": [
        {"name": "white", "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0,
            "roughnessFactor": 1.0}},
        {"name": "rough metal", "pbrMetallicRoughness": {
            "baseColorFactor": [0.9, 0.6, 0.4, 1.0], "metallicFactor": 1.0,
            "roughnessFactor": 0.4}},
    ],
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "bufferViews": views,
    "accessors": accessors,
}
with open("tests/scenes/punctual-room.gltf", "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
