#!/usr/bin/env python3
"""A thin film alone in a white furnace, mlt against Blender Cycles: a smooth unit sphere
(roughness 0, a mirror) under a white sky of radiance 1, so a pixel's colour is the
reflectance of the surface at its cos θo. Blender's glTF importer does not read
`KHR_materials_iridescence`; the script sets the Principled BSDF's Thin Film Thickness and
Thin Film IOR by hand after the import. Two bases: a black dielectric of index 1.5 (only
the specular reflection, through the film) and a metal of base colour (0.95, 0.64, 0.54).
mlt renders the same glTF file (with the extension) in RGB and with `--spectral`.
Numbers are reported, never asserted: a bench, not a test. Small renders (64 x 64, 32
samples per pixel, 2 threads); setup as benches/cycles/compare.py's. Run from the
repository root:
    nice -n 10 target/cycles-venv/bin/python benches/cycles/thin_film.py
"""
import json
import math
import os
import subprocess
import sys
from types import SimpleNamespace

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402  (bpy, the sphere, the camera and Cycles' settings)
import bpy  # noqa: E402
import numpy as np  # noqa: E402

FILMS = ((1.3, 200.0), (1.3, 400.0), (2.0, 300.0))
BASES = (("dielectric", [0.0, 0.0, 0.0], 0.0), ("metal", [0.95, 0.64, 0.54], 1.0))
COSINES = (0.95, 0.7, 0.4)


def run(args, directory):
    size = args.size
    camera = {"eye": [0.0, 0.0, 30.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0],
              "fov_y_deg": 2 * math.degrees(math.atan(1.04 / 30.0)), "width": size,
              "height": size}
    camera_path = os.path.join(directory, "camera.json")
    with open(camera_path, "w") as f:
        json.dump(camera, f)
    cosines = compare.cosines_seen(camera, size)
    rows = []
    for base, colour, metallic in BASES:
        for ior, thickness in FILMS:
            name = f"film_{base}_{ior}_{thickness:.0f}"
            scene = os.path.join(directory, name + ".gltf")
            compare.sphere_gltf(scene, {
                "pbrMetallicRoughness": {"baseColorFactor": colour + [1],
                                         "metallicFactor": metallic, "roughnessFactor": 0},
                "extensions": {"KHR_materials_iridescence": {
                    "iridescenceFactor": 1.0, "iridescenceIor": ior,
                    "iridescenceThicknessMaximum": thickness}},
            })
            compare.reset_blender()
            compare.setup_cycles(args, transparent=True)
            world = bpy.data.worlds.new("white")
            bpy.context.scene.world = world
            world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
            world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
            bpy.ops.import_scene.gltf(filepath=scene)
            compare.single_scattering_ggx()
            for material in bpy.data.materials:
                for node in (material.node_tree.nodes if material.node_tree else []):
                    if node.type == "BSDF_PRINCIPLED":
                        node.inputs["Thin Film Thickness"].default_value = thickness
                        node.inputs["Thin Film IOR"].default_value = ior
            compare.setup_camera(camera)
            cycles_path = os.path.join(directory, name + "_cycles.exr")
            compare.render_cycles(cycles_path)
            theirs = compare.read_exr(cycles_path)
            inside = theirs[..., 3] >= 0.999
            ours = {}
            for mode, extra in (("rgb", []), ("spectral", ["--spectral"])):
                out = os.path.join(directory, f"{name}_mlt_{mode}.exr")
                command = [compare.mlt_binary(), scene, "--camera", camera_path,
                           "--background", "1,1,1", "--algorithm", "path", "--spp",
                           str(args.spp), "--max-depth", "2", "--seed", "1", "--threads",
                           str(args.threads), "--out", out] + extra
                subprocess.run(command, check=True, capture_output=True)
                ours[mode] = compare.read_exr(out)
            for cos_o in COSINES:
                ring = (np.abs(cosines - cos_o) < 0.02) & inside
                mean = lambda image: image[ring][:, :3].mean(axis=0)
                rows.append((base, ior, thickness, cos_o, mean(theirs), mean(ours["rgb"]),
                             mean(ours["spectral"])))
    return rows


def table(rows):
    triple = lambda c: "(" + ", ".join(f"{v:.3f}" for v in c) + ")"
    lines = ["| base | film index | thickness (nm) | cos θo | Cycles | mlt RGB | mlt spectral |",
             "|---|---:|---:|---:|---|---|---|"]
    for base, ior, thickness, cos_o, cycles, rgb, spectral in rows:
        lines.append(f"| {base} | {ior} | {thickness:.0f} | {cos_o} | {triple(cycles)} | "
                     f"{triple(rgb)} | {triple(spectral)} |")
    return "\n".join(lines)


def main():
    args = SimpleNamespace(spp=32, size=64, depth=2, threads=2)
    if not os.path.exists(compare.mlt_binary()):
        sys.exit(f"{compare.mlt_binary()} is missing: cargo build --release")
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(compare.ROOT, "target"))
    directory = os.path.join(target, "mlt-bench", "thin-film")
    os.makedirs(directory, exist_ok=True)
    rows = run(args, directory)
    print("A thin film alone in a white furnace, linear sRGB reflectance at cos θo:")
    print(table(rows))
    lines = [
        "# A thin film alone: mlt against Blender Cycles",
        "",
        "<!-- Written by benches/cycles/thin_film.py: edit the script, not this page. -->",
        "",
        "A smooth unit sphere (roughness 0) under a white sky of radiance 1: a pixel's colour",
        "is the surface's reflectance at its cos θo (averaged over the covered pixels whose",
        "centre's cos θo is within ±0.02), linear sRGB. Blender's importer does not read",
        "`KHR_materials_iridescence`, so the script sets the Principled BSDF's Thin Film",
        "Thickness and Thin Film IOR by hand after the import. Bases: a black dielectric of",
        "index 1.5 (the specular reflection alone) and a metal of base colour",
        "(0.95, 0.64, 0.54). mlt renders the file with the extension in RGB and with",
        f"`--spectral` ({args.size}², {args.spp} samples per pixel, as Cycles). mlt follows the",
        "specification (Schlick's Fresnel at both interfaces, a metal's index derived from its",
        "F0); Cycles evaluates its own film model (see",
        "[lights and surfaces](lights-and-surfaces.md#thin-film-iridescence)).",
        "",
        "    nice -n 10 target/cycles-venv/bin/python benches/cycles/thin_film.py",
        "",
        table(rows),
        "",
    ]
    with open(os.path.join(compare.ROOT, "docs", "cycles-thin-film.md"), "w") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    main()
