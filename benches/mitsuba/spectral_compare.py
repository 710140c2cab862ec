#!/usr/bin/env python3
"""mlt's spectral mode against Mitsuba 3's scalar_spectral variant, an independent spectral
renderer (also RGB against scalar_rgb, to tell the models' differences from the renderers').

Both path-trace a canonical OBJ scene of tests/scenes (Lambertian `Kd` and emissive `Ke`
materials only: the Cornell box) with the same triangles, camera, max depth and size, and the
script prints each image's per-channel mean and the largest difference of a 4 x 4 grid of
region means, relative to Mitsuba's, with the noise of each (from the spread of independent
renders). Mitsuba upsamples RGB reflectances with the same method (Jakob and Hanika 2019, its
own table) and RGB emission times D65, so the two spectral images should agree within the
noise plus the tables' interpolation differences. Reported, never asserted (a bench, not a
test): `pip install mitsuba`, build mlt (`cargo build --release`), then from the repository
root:

    python3 benches/mitsuba/spectral_compare.py [SCENE] [SIZE] [SPP] [RENDERS]

(defaults: cornell-box 64 256 4). Mitsuba's dielectrics have no dispersion (a constant index),
so dispersion is checked against Snell's law instead, in tests/dispersion.rs.
"""
import json
import os
import struct
import subprocess
import sys
import tempfile
import time

import mitsuba as mi

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def read_obj(path):
    """Triangles per material (positions) and the MTL's Kd / Ke of a simple OBJ."""
    vertices, groups, material = [], {}, None
    mtl_file = None
    for line in open(path):
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            vertices.append(tuple(float(x) for x in parts[1:4]))
        elif parts[0] == "usemtl":
            material = parts[1]
        elif parts[0] == "mtllib":
            mtl_file = os.path.join(os.path.dirname(path), parts[1])
        elif parts[0] == "f":
            ids = [int(p.split("/")[0]) for p in parts[1:]]
            ids = [i - 1 if i > 0 else len(vertices) + i for i in ids]
            for k in range(1, len(ids) - 1):
                groups.setdefault(material, []).append((ids[0], ids[k], ids[k + 1]))
    materials, name = {}, None
    for line in open(mtl_file):
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "newmtl":
            name = parts[1]
            materials[name] = {"Kd": (0.8, 0.8, 0.8), "Ke": (0.0, 0.0, 0.0)}
        elif parts[0] in ("Kd", "Ke"):
            materials[name][parts[0]] = tuple(float(x) for x in parts[1:4])
    return vertices, groups, materials


def mitsuba_scene(scene, size, spp, seed, directory):
    """The scene as a Mitsuba dict: one OBJ per material group, written to `directory`."""
    vertices, groups, materials = read_obj(os.path.join(ROOT, "tests/scenes", scene + ".obj"))
    camera = json.load(open(os.path.join(ROOT, "tests/scenes", scene + ".camera.json")))
    d = {
        "type": "scene",
        # Mitsuba counts the emitter vertex: mlt's 5 scattering vertices are its depth 6.
        "integrator": {"type": "path", "max_depth": 6},
        "sensor": {
            "type": "perspective",
            "fov": camera["fov_y_deg"],
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=camera["eye"], target=camera["target"], up=camera["up"]
            ),
            "film": {
                "type": "hdrfilm",
                "width": size,
                "height": size,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
    }
    for index, (name, faces) in enumerate(groups.items()):
        used = sorted({i for f in faces for i in f})
        remap = {v: k + 1 for k, v in enumerate(used)}
        path = os.path.join(directory, f"group{index}.obj")
        with open(path, "w") as f:
            for v in used:
                f.write("v %r %r %r\n" % vertices[v])
            for a, b, c in faces:
                f.write(f"f {remap[a]} {remap[b]} {remap[c]}\n")
        m = materials[name]
        shape = {
            "type": "obj",
            "filename": path,
            "face_normals": True,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(m["Kd"])}},
        }
        if any(m["Ke"]):
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": list(m["Ke"])}}
        d[f"group{index}"] = shape
    return d


def render_mitsuba(variant, scene, size, spp, seed):
    mi.set_variant(variant)
    d = mitsuba_scene(scene, size, spp, seed, tempfile.mkdtemp())
    start = time.time()
    image = mi.render(mi.load_dict(d))
    seconds = time.time() - start
    image = mi.TensorXf(image)
    values = list(image.array)
    channels = len(values) // (size * size)
    return [values[p * channels + c] for p in range(size * size) for c in range(3)], seconds


def read_pfm(path):
    with open(path, "rb") as f:
        f.readline()
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = struct.unpack(("<" if scale < 0 else ">") + "f" * (width * height * 3), f.read())
    # PFM rows run bottom to top.
    rows = [data[(height - 1 - y) * width * 3:(height - y) * width * 3] for y in range(height)]
    return [v for row in rows for v in row]


def render_mlt(spectral, scene, size, spp, seed):
    out = os.path.join(tempfile.mkdtemp(), "mlt.pfm")
    command = [
        os.path.join(ROOT, "target/release/mlt-render"),
        os.path.join(ROOT, "tests/scenes", scene + ".obj"),
        "--algorithm", "path", "--spp", str(spp), "--max-depth", "5",
        "--width", str(size), "--height", str(size), "--seed", str(seed), "--out", out,
    ] + (["--spectral"] if spectral else [])
    start = time.time()
    subprocess.run(command, check=True, capture_output=True)
    return read_pfm(out), time.time() - start


def statistics(images, size):
    """Per-channel image means and 4 x 4 region means, each with its standard error."""
    def region_means(image):
        cells = 4
        step = size // cells
        out = []
        for j in range(cells):
            for i in range(cells):
                for c in range(3):
                    total = 0.0
                    for y in range(j * step, (j + 1) * step):
                        row = y * size
                        for x in range(i * step, (i + 1) * step):
                            total += image[(row + x) * 3 + c]
                    out.append(total / (step * step))
        means = [sum(image[c::3]) / (size * size) for c in range(3)]
        return means + out

    per_render = [region_means(im) for im in images]
    k = len(per_render)
    mean = [sum(r[i] for r in per_render) / k for i in range(len(per_render[0]))]
    error = [
        (sum((r[i] - mean[i]) ** 2 for r in per_render) / (k - 1) / k) ** 0.5
        for i in range(len(mean))
    ]
    return mean, error


def main():
    scene = sys.argv[1] if len(sys.argv) > 1 else "cornell-box"
    size = int(sys.argv[2]) if len(sys.argv) > 2 else 64
    spp = int(sys.argv[3]) if len(sys.argv) > 3 else 256
    renders = int(sys.argv[4]) if len(sys.argv) > 4 else 4
    for variant, spectral in (("scalar_rgb", False), ("scalar_spectral", True)):
        ours, theirs = [], []
        our_seconds = their_seconds = 0.0
        for seed in range(renders):
            image, seconds = render_mlt(spectral, scene, size, spp, seed)
            ours.append(image)
            our_seconds += seconds
            image, seconds = render_mitsuba(variant, scene, size, spp, seed)
            theirs.append(image)
            their_seconds += seconds
        (a, ea), (b, eb) = statistics(ours, size), statistics(theirs, size)
        label = "spectral" if spectral else "RGB"
        print(f"{scene} {label}: mlt {our_seconds:.1f} s, Mitsuba {variant} {their_seconds:.1f} s "
              f"({renders} renders of {size}² at {spp} spp)")
        for c in range(3):
            diff = (a[c] - b[c]) / b[c]
            noise = (ea[c] ** 2 + eb[c] ** 2) ** 0.5 / b[c]
            print(f"  image channel {c}: mlt {a[c]:.5f}, Mitsuba {b[c]:.5f}: "
                  f"{100 * diff:+.2f}% ± {100 * noise:.2f}%")
        worst = max(range(3, len(a)), key=lambda i: abs(a[i] - b[i]) / max((ea[i] ** 2 + eb[i] ** 2) ** 0.5, 1e-12))
        sigma = abs(a[worst] - b[worst]) / max((ea[worst] ** 2 + eb[worst] ** 2) ** 0.5, 1e-12)
        print(f"  largest region difference: region {(worst - 3) // 3} channel {(worst - 3) % 3}: "
              f"mlt {a[worst]:.5f}, Mitsuba {b[worst]:.5f} ({sigma:.1f} standard errors)")


if __name__ == "__main__":
    main()
