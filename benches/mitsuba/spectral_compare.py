#!/usr/bin/env python3
"""mlt's spectral mode against Mitsuba 3's scalar_spectral variant, an independent spectral
renderer (also RGB against scalar_rgb, to tell the models' differences from the renderers').

Both path-trace a canonical OBJ scene of tests/scenes (Lambertian `Kd`, emissive `Ke` and
`illum 7` dielectric materials: the Cornell box) with the same triangles, camera, max depth and
size, and the script prints each image's per-channel mean and the largest difference of a
4 x 4 grid of region means, with the noise of each (from the spread of independent renders).
Mitsuba upsamples RGB reflectances with the same method (Jakob and Hanika 2019, its own table)
and RGB emission times D65, so the two spectral images should agree within the noise plus the
tables' interpolation differences. Reported, never asserted (a bench, not a test):
`pip install mitsuba`, build mlt (`cargo build --release`; the script runs
$CARGO_TARGET_DIR/release/mlt-render if that variable is set), then from the repository root:

    python3 benches/mitsuba/spectral_compare.py [SCENE] [SIZE] [SPP] [RENDERS]

(defaults: cornell-box 64 256 4). Mitsuba's own `dielectric` has one index for all
wavelengths: a dielectric with an Abbe number (`Vd`) gets the plugin of
dispersive_dielectric.py instead, with mlt's index, and prism_compare.py compares the two
renderers' dispersion through a prism with it.
"""
import json
import os
import struct
import subprocess
import sys
import tempfile
import time

import mitsuba as mi

import dispersive_dielectric

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def read_obj(path):
    """Triangles per material (positions) and the MTL's Kd, Ke, illum, Ni and Vd of a simple
    OBJ."""
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
            materials[name] = {"Kd": (0.8, 0.8, 0.8), "Ke": (0.0, 0.0, 0.0), "illum": 0,
                               "Ni": 1.5, "Vd": 0.0}
        elif parts[0] in ("Kd", "Ke"):
            materials[name][parts[0]] = tuple(float(x) for x in parts[1:4])
        elif parts[0] == "illum":
            materials[name]["illum"] = int(parts[1])
        elif parts[0] in ("Ni", "Vd"):
            materials[name][parts[0]] = float(parts[1])
    return vertices, groups, materials


def glass_bsdf(material, variant):
    """The dielectric of an `illum 7` material: Mitsuba's own when there is no dispersion
    (or no wavelengths), else the plugin with the same Cauchy index as mlt's."""
    if material["Vd"] > 0 and "spectral" in variant:
        return {"type": "dispersive_dielectric", "ior": material["Ni"], "abbe": material["Vd"]}
    return {"type": "dielectric", "int_ior": material["Ni"], "ext_ior": 1.0}


def mitsuba_scene(variant, scene, width, height, spp, directory, integrator, glass):
    """The scene as a Mitsuba dict: one OBJ per material group, written to `directory`;
    `glass(material, variant)` gives the BSDF of `illum 7` materials."""
    vertices, groups, materials = read_obj(os.path.join(ROOT, "tests/scenes", scene + ".obj"))
    camera = json.load(open(os.path.join(ROOT, "tests/scenes", scene + ".camera.json")))
    d = {
        "type": "scene",
        # Mitsuba counts the emitter vertex: mlt's 5 scattering vertices are its depth 6.
        "integrator": {"type": integrator, "max_depth": 6},
        "sensor": {
            "type": "perspective",
            "fov": camera["fov_y_deg"],
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=camera["eye"], target=camera["target"], up=camera["up"]
            ),
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": spp},
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
        if m["illum"] == 7:
            bsdf = glass(m, variant)
        else:
            bsdf = {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(m["Kd"])}}
        shape = {"type": "obj", "filename": path, "face_normals": True, "bsdf": bsdf}
        if any(m["Ke"]):
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": list(m["Ke"])}}
        d[f"group{index}"] = shape
    return d


def render_mitsuba(variant, scene, width, height, spp, seed, integrator="path", glass=glass_bsdf):
    """An image (rows top to bottom, RGB interleaved) and the seconds it took."""
    mi.set_variant(variant)
    # No log (progress bars, warnings that Python plugins are slow) amid the report; errors
    # still raise.
    mi.logger().clear_appenders()
    if "spectral" in variant:
        dispersive_dielectric.register()
    d = mitsuba_scene(variant, scene, width, height, spp, tempfile.mkdtemp(), integrator, glass)
    start = time.time()
    # The seed goes to `render`: `ptracer` ignores most of the sampler's own `seed`.
    image = mi.render(mi.load_dict(d), seed=seed)
    seconds = time.time() - start
    values = list(mi.TensorXf(image).array)
    pixels = width * height
    channels = len(values) // pixels
    return [values[p * channels + c] for p in range(pixels) for c in range(3)], seconds


def read_pfm(path):
    with open(path, "rb") as f:
        f.readline()
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = struct.unpack(("<" if scale < 0 else ">") + "f" * (width * height * 3), f.read())
    # PFM rows run bottom to top.
    rows = [data[(height - 1 - y) * width * 3:(height - y) * width * 3] for y in range(height)]
    return [v for row in rows for v in row]


def render_mlt(spectral, scene, width, height, spp, seed, algorithm="path"):
    """mlt-render's image (as `render_mitsuba`'s) and seconds, from CARGO_TARGET_DIR's (else
    target/'s) release build."""
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    out = os.path.join(tempfile.mkdtemp(), "mlt.pfm")
    command = [
        os.path.join(target, "release/mlt-render"),
        os.path.join(ROOT, "tests/scenes", scene + ".obj"),
        "--algorithm", algorithm, "--spp", str(spp), "--max-depth", "5",
        "--width", str(width), "--height", str(height), "--seed", str(seed), "--out", out,
    ] + (["--spectral"] if spectral else [])
    start = time.time()
    subprocess.run(command, check=True, capture_output=True)
    return read_pfm(out), time.time() - start


def statistics(images, width, height, cells=4):
    """Per-channel image means and the means of a cells x cells grid of regions (row by row,
    RGB interleaved), each over the images with its standard error."""
    def region_means(image):
        out = [sum(image[c::3]) / (width * height) for c in range(3)]
        for j in range(cells):
            rows = range(j * height // cells, (j + 1) * height // cells)
            for i in range(cells):
                columns = range(i * width // cells, (i + 1) * width // cells)
                for c in range(3):
                    total = sum(image[(y * width + x) * 3 + c] for y in rows for x in columns)
                    out.append(total / (len(rows) * len(columns)))
        return out

    return mean_and_error([region_means(image) for image in images])


def mean_and_error(samples):
    """Per-component mean of equally long lists and the standard error of each."""
    k = len(samples)
    mean = [sum(column) / k for column in zip(*samples)]
    error = [(sum((x - m) ** 2 for x in column) / (k - 1) / k) ** 0.5
             for column, m in zip(zip(*samples), mean)]
    return mean, error


def report(ours, theirs, width, height, our_name="mlt", their_name="Mitsuba"):
    """Prints each image channel's mean and the region differing most (in standard errors)."""
    (a, ea), (b, eb) = statistics(ours, width, height), statistics(theirs, width, height)
    for c in range(3):
        diff = (a[c] - b[c]) / b[c]
        noise = (ea[c] ** 2 + eb[c] ** 2) ** 0.5 / b[c]
        print(f"  image channel {c}: {our_name} {a[c]:.5f} ± {ea[c]:.5f}, {their_name} "
              f"{b[c]:.5f} ± {eb[c]:.5f}: {100 * diff:+.2f}% ± {100 * noise:.2f}%")
    sigmas = [abs(a[i] - b[i]) / max((ea[i] ** 2 + eb[i] ** 2) ** 0.5, 1e-12)
              for i in range(3, len(a))]
    worst = max(range(len(sigmas)), key=sigmas.__getitem__)
    i = worst + 3
    print(f"  largest region difference: region {worst // 3} channel {worst % 3}: "
          f"{our_name} {a[i]:.5f} ± {ea[i]:.5f}, {their_name} {b[i]:.5f} ± {eb[i]:.5f} "
          f"({sigmas[worst]:.1f} standard errors; {len(sigmas)} region channels)")


def main():
    scene = sys.argv[1] if len(sys.argv) > 1 else "cornell-box"
    size = int(sys.argv[2]) if len(sys.argv) > 2 else 64
    spp = int(sys.argv[3]) if len(sys.argv) > 3 else 256
    renders = int(sys.argv[4]) if len(sys.argv) > 4 else 4
    for variant, spectral in (("scalar_rgb", False), ("scalar_spectral", True)):
        ours, theirs = [], []
        our_seconds = their_seconds = 0.0
        for seed in range(renders):
            image, seconds = render_mlt(spectral, scene, size, size, spp, seed)
            ours.append(image)
            our_seconds += seconds
            image, seconds = render_mitsuba(variant, scene, size, size, spp, seed)
            theirs.append(image)
            their_seconds += seconds
        label = "spectral" if spectral else "RGB"
        print(f"{scene} {label}: mlt {our_seconds:.1f} s, Mitsuba {variant} {their_seconds:.1f} s "
              f"({renders} renders of {size}² at {spp} spp)")
        report(ours, theirs, size, size)


if __name__ == "__main__":
    main()
