#!/usr/bin/env python3
"""Writes tests/scenes/prism.{obj,mtl,camera.json}: white light through a slit, spread into
a spectrum by a flint-glass prism (index 1.5, Abbe number 20) onto a white floor.

The room (4 x 2.5 x 4 m, y up) is split by a black wall at x = -1.2 with a 1 cm slit at
height 1 m; behind it a small lamp (1 cm x 30 cm) faces the slit, so a narrow beam crosses
the room, enters the prism's left face and leaves it bent down towards the floor, where the
wavelengths land apart. Everything the camera sees is lit through the prism: a caustic of
light from a small source, the case bidirectional and Metropolis methods are for.

Run from the repository root: python3 tools/prism_scene.py
"""
import math

vertices, faces = [], []
lines_obj = []


def quad(name, material, a, b, c, d):
    """Quad a-b-c-d (counter-clockwise seen from its front) as two triangles."""
    lines_obj.append(f"o {name}\nusemtl {material}")
    base = len(vertices) + 1
    vertices.extend([a, b, c, d])
    lines_obj.append("\n".join(f"v {x:.6g} {y:.6g} {z:.6g}" for x, y, z in (a, b, c, d)))
    lines_obj.append(f"f {base} {base + 1} {base + 2}\nf {base} {base + 2} {base + 3}")


def tri(name, material, a, b, c):
    lines_obj.append(f"o {name}\nusemtl {material}")
    base = len(vertices) + 1
    vertices.extend([a, b, c])
    lines_obj.append("\n".join(f"v {x:.6g} {y:.6g} {z:.6g}" for x, y, z in (a, b, c)))
    lines_obj.append(f"f {base} {base + 1} {base + 2}")


X0, X1, Y1, Z0, Z1 = -2.0, 2.0, 2.5, -2.0, 2.0
# Room, faces towards the inside.
quad("floor", "white", (X0, 0, Z0), (X0, 0, Z1), (X1, 0, Z1), (X1, 0, Z0))
quad("ceiling", "grey", (X0, Y1, Z0), (X1, Y1, Z0), (X1, Y1, Z1), (X0, Y1, Z1))
quad("back", "grey", (X0, 0, Z0), (X1, 0, Z0), (X1, Y1, Z0), (X0, Y1, Z0))
quad("front", "grey", (X0, 0, Z1), (X0, Y1, Z1), (X1, Y1, Z1), (X1, 0, Z1))
quad("left", "grey", (X0, 0, Z0), (X0, Y1, Z0), (X0, Y1, Z1), (X0, 0, Z1))
quad("right", "grey", (X1, 0, Z0), (X1, 0, Z1), (X1, Y1, Z1), (X1, Y1, Z0))

# The black wall with the slit, both sides (two-sided blocker: one quad per side).
XW, SLIT_Y, SLIT_HALF = -1.2, 1.0, 0.005
for side, sign in (("lampside", -1), ("roomside", 1)):
    for part, (ya, yb) in (("low", (0.0, SLIT_Y - SLIT_HALF)), ("high", (SLIT_Y + SLIT_HALF, Y1))):
        a, b, c, d = (XW, ya, Z0), (XW, ya, Z1), (XW, yb, Z1), (XW, yb, Z0)
        if sign > 0:  # faces +x
            quad(f"slit_wall_{part}_{side}", "black", a, d, c, b)
        else:  # faces -x
            quad(f"slit_wall_{part}_{side}", "black", a, b, c, d)

# The lamp: 1 cm tall, 30 cm long, facing +x.
XL, LAMP_HALF_Y, LAMP_HALF_Z = -1.9, 0.005, 0.15
quad("lamp", "lamp",
     (XL, SLIT_Y - LAMP_HALF_Y, -LAMP_HALF_Z), (XL, SLIT_Y + LAMP_HALF_Y, -LAMP_HALF_Z),
     (XL, SLIT_Y + LAMP_HALF_Y, LAMP_HALF_Z), (XL, SLIT_Y - LAMP_HALF_Y, LAMP_HALF_Z))

# The prism: equilateral cross-section of side 0.3 m, apex up, centroid at (0, 1, 0),
# 0.6 m long along z; faces outwards.
S, L = 0.3, 0.3
h = S / math.sqrt(3)
apex, left, right = (0.0, 1.0 + h), (-S / 2, 1.0 - h / 2), (S / 2, 1.0 - h / 2)
for name, (p, q) in (("prism_left", (left, apex)), ("prism_right", (apex, right)),
                     ("prism_base", (right, left))):
    # Edge p -> q goes counter-clockwise around the centroid seen from +z, so q -> p at -z,
    # then p -> q at +z winds counter-clockwise seen from outside.
    quad(name, "flint", (q[0], q[1], -L), (p[0], p[1], -L), (p[0], p[1], L), (q[0], q[1], L))
tri("prism_cap_front", "flint", (apex[0], apex[1], L), (left[0], left[1], L), (right[0], right[1], L))
tri("prism_cap_back", "flint", (apex[0], apex[1], -L), (right[0], right[1], -L), (left[0], left[1], -L))

header = (
    "# White light through a slit, spread into a spectrum by a flint-glass prism onto a white\n"
    "# floor. Written by tools/prism_scene.py; metres, y up. Render with --spectral: in RGB the\n"
    "# prism does not disperse (the Abbe number, MTL keyword Vd, is read but RGB has no\n"
    "# wavelengths).\n"
    "mtllib prism.mtl\n"
)
with open("tests/scenes/prism.obj", "w") as f:
    f.write(header + "\n".join(lines_obj) + "\n")
with open("tests/scenes/prism.mtl", "w") as f:
    f.write(
        "# Materials of prism.obj (tools/prism_scene.py). Vd is mlt's keyword for the Abbe number.\n"
        "newmtl white\nKd 0.8 0.8 0.8\n\n"
        "newmtl grey\nKd 0.3 0.3 0.3\n\n"
        "newmtl black\nKd 0 0 0\n\n"
        "newmtl lamp\nKd 0 0 0\nKe 4000 4000 4000\n\n"
        "newmtl flint\nillum 7\nNi 1.5\nVd 20\n"
    )
with open("tests/scenes/prism.camera.json", "w") as f:
    f.write(
        '{\n  "eye": [-0.2, 1.45, 1.9],\n  "target": [0.65, 0.45, 0.0],\n  "up": [0.0, 1.0, 0.0],\n'
        '  "fov_y_deg": 55.0,\n  "width": 320,\n  "height": 240\n}\n'
    )
