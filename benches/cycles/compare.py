#!/usr/bin/env python3
"""mlt against Blender Cycles on the Khronos glTF sample assets in benches/cycles/assets.

For each asset both renderers get the same file, the same camera (the model's bounding box
framed from the front, +Z in glTF's frame), the same HDR sky as the only light besides the
asset's own, the same size, samples and path depth:
- mlt: `mlt-render ASSET --camera CAMERA.json --env SKY.hdr --algorithm path
  --full-resolution-textures`, linear EXR (Cycles reads its images at full resolution, no
  mip-maps, so both estimate the same pixel integral: prefiltering is not linear where
  textures multiply each other below a pixel);
- Cycles (Blender as a Python module, `bpy`): the stock glTF importer (glTF's PBR on the
  Principled BSDF), every Principled BSDF switched to single-scattering GGX (the glTF
  specification's BRDF has no multiple-scattering term), a 1-pixel box filter, no denoising,
  no adaptive sampling, no clamping, no glossy blur, the Standard view transform, the sky
  looked up by its nearest texel (as mlt does), linear EXR with a transparent film.

First it renders the sky alone (no model) with both, from four directions, and reports how
far the two environments are apart: that they agree pixel for pixel is the precondition of
everything after. Then, per asset, over the pixels the model covers (Cycles' alpha = 1):
- the ratio of the mean luminances, mlt / Cycles;
- the worst 16 x 16 block: the block ratio furthest from 1 among blocks at least a quarter
  covered.
Furnaces show single lobes where Cycles departs from the specification, or where a
block's difference needs one: sheen alone, the transmission's tint through a closed
object, anisotropy alone, a specular colour of 0, and a normal-mapped square (with the
assets that have normal maps rendered again without them).
An asset mlt refuses (an unsupported required extension, say) is reported as refused, with
mlt's message; the other assets go on. Numbers are reported, never asserted: a bench, not a
test. It writes docs/cycles.md (the table and the images) and docs/images/cycles/NAME.png
(mlt | Cycles | the ratio mlt / Cycles as a heat map, blue where mlt is darker).

Setup (Blender as a module needs Python 3.11):

    python3.11 -m venv target/cycles-venv
    target/cycles-venv/bin/pip install bpy==5.0.1 numpy imageio
    cargo build --release

Run from the repository root (mlt-render from $CARGO_TARGET_DIR, else target/):

    nice -n 10 target/cycles-venv/bin/python benches/cycles/compare.py [--spp 64] [--size 128]
        [--depth 8] [--sky pedestrian_overpass] [--sky-rotate 0] [--threads 2]
        [--assets ClearCoatTest,SheenCloth,...] [--flat-normals] [--no-docs]

Defaults: 128 x 128, 64 spp, depth 8 (scattering vertices; Cycles' bounces are one fewer),
the soft pedestrian_overpass sky, 2 threads each.
"""
import argparse
import base64
import json
import math
import os
import struct
import subprocess
import sys
import time

import bpy
import imageio.v3 as iio
import mathutils
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
ASSETS = os.path.join(HERE, "assets")
DEFAULT_ASSETS = [
    # No extension: metals and dielectrics over roughness, the control.
    "MetalRoughSpheresNoTextures",
    "ClearCoatTest",
    "SpecularTest",
    "SheenCloth",
    "TransmissionRoughnessTest",
    "TransmissionTest",
    "AttenuationTest",
    "AnisotropyStrengthTest",
    "MultiUVTest",
    "AlphaBlendModeTest",
]
FOV_Y_DEG = 40.0
BLOCK = 16
# Rec. 709 luminance of linear RGB.
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


# ---------------------------------------------------------------- the assets


def asset_file(name):
    folder = os.path.join(ASSETS, name)
    for extension in (".glb", ".gltf"):
        path = os.path.join(folder, name + extension)
        if os.path.exists(path):
            return path
    raise FileNotFoundError(f"no {name}.glb or {name}.gltf in {folder}")


def gltf_json(path):
    """The JSON of a .gltf, or of a .glb's first chunk."""
    with open(path, "rb") as f:
        data = f.read()
    if path.endswith(".gltf"):
        return json.loads(data)
    length, kind = struct.unpack_from("<II", data, 12)
    assert kind == 0x4E4F534A, "a glb's first chunk is its JSON"
    return json.loads(data[20 : 20 + length])


def features_of(path):
    """The file's `extensionsUsed` (shortened), and the core features mlt may lack: texture
    coordinate sets past the first, alpha modes other than OPAQUE."""
    document = gltf_json(path)
    required = set(document.get("extensionsRequired", []))
    features = [e.replace("KHR_materials_", "").replace("KHR_", "")
                + (" (required)" if e in required else "")
                for e in document.get("extensionsUsed", [])]

    def texture_sets(value):
        if isinstance(value, dict):
            if "index" in value and value.get("texCoord", 0) > 0:
                yield value["texCoord"]
            for item in value.values():
                yield from texture_sets(item)
        elif isinstance(value, list):
            for item in value:
                yield from texture_sets(item)

    materials = document.get("materials", [])
    features += [f"texCoord {n}" for n in sorted(set(texture_sets(materials)))]
    features += [f"alpha {mode}" for mode in
                 sorted({m.get("alphaMode", "OPAQUE") for m in materials} - {"OPAQUE"})]
    return ", ".join(features) if features else "—"


def without_normal_maps(path, directory):
    """A copy of the asset in `directory` without its normal maps (`normalTexture`, and
    `KHR_materials_clearcoat`'s `clearcoatNormalTexture`), for both renderers: how much of a
    difference the normal maps make (`--flat-normals`). Returns the copy's path."""
    document = gltf_json(path)
    for material in document.get("materials", []):
        material.pop("normalTexture", None)
        material.get("extensions", {}).get("KHR_materials_clearcoat", {}).pop(
            "clearcoatNormalTexture", None)
    name, extension = os.path.splitext(os.path.basename(path))
    copy = os.path.join(directory, name + "_flat" + extension)
    if extension == ".gltf":
        # Files beside the original, reached from the copy's folder.
        for item in document.get("buffers", []) + document.get("images", []):
            uri = item.get("uri")
            if uri and not uri.startswith("data:"):
                item["uri"] = os.path.relpath(os.path.join(os.path.dirname(path), uri),
                                              directory)
        with open(copy, "w") as f:
            json.dump(document, f)
        return copy
    with open(path, "rb") as f:
        data = f.read()
    length = struct.unpack_from("<I", data, 12)[0]
    chunk = json.dumps(document).encode()
    chunk += b" " * (-len(chunk) % 4)
    rest = data[20 + length :]
    header = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(chunk) + len(rest))
    with open(copy, "wb") as f:
        f.write(header + struct.pack("<II", len(chunk), 0x4E4F534A) + chunk + rest)
    return copy


# ---------------------------------------------------------------- frames and cameras


def gltf_to_blender(v):
    """glTF is +Y up; Blender (and its importer) +Z up: (x, y, z) -> (x, -z, y)."""
    return mathutils.Vector((v[0], -v[2], v[1]))


def blender_to_gltf(v):
    return [v[0], v[2], -v[1]]


def framing_camera(low, high, size):
    """A camera looking along -Z at the centre of the glTF-frame box [low, high], far enough
    that the box's front face fits the square view with a margin."""
    centre = [(a + b) / 2 for a, b in zip(low, high)]
    half = [(b - a) / 2 for a, b in zip(low, high)]
    distance = 1.08 * max(half[0], half[1]) / math.tan(math.radians(FOV_Y_DEG) / 2) + half[2]
    return {
        "eye": [centre[0], centre[1], centre[2] + distance],
        "target": centre,
        "up": [0.0, 1.0, 0.0],
        "fov_y_deg": FOV_Y_DEG,
        "width": size,
        "height": size,
    }


def direction_camera(direction, size, fov=60.0):
    """A camera at the origin looking along a glTF-frame direction (for the sky alone)."""
    return {"eye": [0.0, 0.0, 0.0], "target": list(direction), "up": [0.0, 1.0, 0.0],
            "fov_y_deg": fov, "width": size, "height": size}


def model_bounds():
    """The glTF-frame bounding box of every mesh object Blender holds."""
    low, high = [math.inf] * 3, [-math.inf] * 3
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH":
            continue
        evaluated = obj.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        matrix = obj.matrix_world
        for vertex in mesh.vertices:
            p = blender_to_gltf(matrix @ vertex.co)
            low = [min(a, b) for a, b in zip(low, p)]
            high = [max(a, b) for a, b in zip(high, p)]
        evaluated.to_mesh_clear()
    return low, high


# ---------------------------------------------------------------- Cycles


def reset_blender():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def setup_cycles(args, transparent):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = args.spp
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.seed = 1
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    # mlt's depth counts scattering vertices, Cycles' bounces the ones after the first.
    bounces = max(args.depth - 1, 0)
    cycles.max_bounces = bounces
    for kind in ("diffuse", "glossy", "transmission", "volume"):
        setattr(cycles, kind + "_bounces", bounces)
    cycles.transparent_max_bounces = max(args.depth, 1) * 8
    scene.render.film_transparent = transparent
    scene.render.resolution_x = args.size
    scene.render.resolution_y = args.size
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGBA"
    settings.color_depth = "32"


def setup_world(sky, rotate_deg):
    """The sky as Cycles' world, turned so that it matches mlt's lookup (mlt: +Y up, the
    map's centre looking along glTF's +Z, `--env-rotate` counter-clockwise seen from above;
    Blender's equirectangular map has its centre along +X of its Z-up frame, which is glTF's
    +X: a quarter turn about the up axis, and the Mapping node turns the direction looked
    up, so mlt's rotation with the opposite sign). Nearest-texel lookups, as mlt's."""
    world = bpy.data.worlds.new("sky")
    bpy.context.scene.world = world
    nodes, links = world.node_tree.nodes, world.node_tree.links
    nodes.clear()
    coordinates = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(90.0 - rotate_deg))
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(sky)
    texture.interpolation = "Closest"
    texture.projection = "EQUIRECTANGULAR"
    background = nodes.new("ShaderNodeBackground")
    output = nodes.new("ShaderNodeOutputWorld")
    links.new(coordinates.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    links.new(texture.outputs["Color"], background.inputs["Color"])
    links.new(background.outputs["Background"], output.inputs["Surface"])


def setup_camera(camera):
    data = bpy.data.cameras.new("camera")
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(camera["fov_y_deg"])
    eye, target = gltf_to_blender(camera["eye"]), gltf_to_blender(camera["target"])
    span = (target - eye).length
    data.clip_start = span * 1e-4
    data.clip_end = span * 1e3
    obj = bpy.data.objects.new("camera", data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = eye
    obj.rotation_euler = (target - eye).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = obj


def single_scattering_ggx():
    """Every Principled BSDF to single-scattering GGX; returns how many."""
    count = 0
    for material in bpy.data.materials:
        if not material.node_tree:
            continue
        for node in material.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                node.distribution = "GGX"
                count += 1
    return count


def squared_transmission_tint():
    """Every transmissive Principled BSDF's unlinked base colour c to c², so that Cycles'
    √ at each refraction tints by c at each crossing, as the glTF specification does
    (`--spec-tint`); returns how many."""
    count = 0
    for material in bpy.data.materials:
        if not material.node_tree:
            continue
        for node in material.node_tree.nodes:
            if node.type != "BSDF_PRINCIPLED":
                continue
            weight = node.inputs["Transmission Weight"]
            colour = node.inputs["Base Color"]
            if (weight.is_linked or weight.default_value > 0) and not colour.is_linked:
                r, g, b, a = colour.default_value
                colour.default_value = (r * r, g * g, b * b, a)
                count += 1
    return count


def render_cycles(path):
    bpy.context.scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def read_exr(path):
    """Rows from the top, RGBA float (alpha 1 where the file has none), via Blender's reader."""
    image = bpy.data.images.load(path)
    width, height = image.size
    channels = image.channels
    pixels = np.empty(width * height * channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    pixels = pixels.reshape(height, width, channels)[::-1]
    if channels == 3:
        pixels = np.concatenate([pixels, np.ones((height, width, 1), np.float32)], axis=2)
    return pixels.astype(np.float64)


# ---------------------------------------------------------------- mlt


def mlt_binary():
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    return os.path.join(target, "release", "mlt-render")


def render_mlt(args, scene, camera, sky, out, directory):
    """Renders with mlt-render; returns (seconds, None) or (None, the error message)."""
    camera_path = os.path.join(directory, "camera.json")
    with open(camera_path, "w") as f:
        json.dump(camera, f)
    command = [mlt_binary(), scene, "--camera", camera_path, "--env", sky,
               "--env-rotate", str(args.sky_rotate), "--algorithm", "path",
               "--spp", str(args.spp), "--max-depth", str(args.depth), "--seed", "1",
               "--threads", str(args.threads), "--width", str(camera["width"]),
               "--height", str(camera["height"]), "--out", out, "--full-resolution-textures"]
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if result.returncode != 0:
        lines = [line for line in result.stderr.strip().splitlines() if line.strip()]
        message = lines[-1] if lines else f"exit status {result.returncode}"
        # The page names the file, not where this checkout lives.
        return None, message.replace(scene, os.path.basename(scene))
    return seconds, None


def far_triangle_gltf(path):
    """A glTF with one tiny triangle far below the origin (mlt refuses a scene with no
    triangles): the sky-only scene, seen from the origin by cameras looking sideways."""
    positions = struct.pack("<9f", 0.0, -1000.0, 0.0, 0.001, -1000.0, 0.0, 0.0, -1000.0, 0.001)
    document = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0.0, -1000.0, 0.0], "max": [0.001, -1000.0, 0.001]}],
        "bufferViews": [{"buffer": 0, "byteLength": len(positions)}],
        "buffers": [{"byteLength": len(positions),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(positions).decode()}],
    }
    with open(path, "w") as f:
        json.dump(document, f)


# ---------------------------------------------------------------- measures and pictures


def luminance(image):
    return image[..., :3] @ LUMINANCE


def compare(ours, theirs, mask):
    """Covered-pixel mean luminance ratio and the worst block's ratio (None without one)."""
    lo, lt = luminance(ours), luminance(theirs)
    mean_ratio = lo[mask].sum() / max(lt[mask].sum(), 1e-30)
    worst = None
    height, width = mask.shape
    for y in range(0, height, BLOCK):
        for x in range(0, width, BLOCK):
            m = mask[y : y + BLOCK, x : x + BLOCK]
            if m.sum() < BLOCK * BLOCK // 4:
                continue
            a = lo[y : y + BLOCK, x : x + BLOCK][m].sum()
            b = lt[y : y + BLOCK, x : x + BLOCK][m].sum()
            if a <= 0 or b <= 0:
                ratio = 0.0 if b > 0 else math.inf
            else:
                ratio = a / b
            if worst is None or abs(math.log(max(ratio, 1e-9))) > abs(math.log(max(worst, 1e-9))):
                worst = ratio
    return mean_ratio, worst


def to_srgb8(image, scale):
    linear = np.clip(image[..., :3] * scale, 0.0, 1.0)
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
    return (srgb * 255 + 0.5).astype(np.uint8)


def box3(values):
    padded = np.pad(values, 1, mode="constant")
    total = np.zeros_like(values)
    for dy in range(3):
        for dx in range(3):
            total += padded[dy : dy + values.shape[0], dx : dx + values.shape[1]]
    return total


def heat_map(ours, theirs, mask, stops=0.5):
    """log2(mlt / Cycles) over 3 x 3 neighbourhoods of covered pixels: white at 1, red where
    mlt is brighter, blue where darker, full colour at ±`stops`; grey off the model."""
    m = mask.astype(np.float64)
    a, b = box3(luminance(ours) * m), box3(luminance(theirs) * m)
    t = np.clip(np.log2(np.maximum(a, 1e-12) / np.maximum(b, 1e-12)) / stops, -1.0, 1.0)
    rgb = np.ones(mask.shape + (3,))
    rgb[..., 1] = 1 - np.abs(t)
    rgb[..., 0] = np.where(t < 0, 1 + t, 1.0)
    rgb[..., 2] = np.where(t > 0, 1 - t, 1.0)
    rgb[~mask] = 0.25
    return (rgb * 255 + 0.5).astype(np.uint8)


def side_by_side(path, ours, theirs, mask, upscale=2):
    # One exposure for both, set by the model (the sky behind it may clip).
    seen = luminance(theirs)[mask] if mask.any() else luminance(theirs)
    scale = 0.8 / max(np.percentile(seen, 99), 1e-12)
    panels = [to_srgb8(ours, scale), to_srgb8(theirs, scale), heat_map(ours, theirs, mask)]
    gap = np.full((ours.shape[0], 2, 3), 255, np.uint8)
    row = np.concatenate([panels[0], gap, panels[1], gap, panels[2]], axis=1)
    row = row.repeat(upscale, axis=0).repeat(upscale, axis=1)
    iio.imwrite(path, row)


# ---------------------------------------------------------------- sheen alone, in a furnace


SHEEN_ROUGHNESSES = (0.3, 0.5, 1.0)
FURNACE_COSINES = (0.95, 0.8, 0.6, 0.4, 0.25)


def sheen_sphere_gltf(path, roughness):
    """A unit sphere of sheen alone: black base, `KHR_materials_specular`'s factor 0 (no
    specular lobe at any angle: an index of refraction of 1 would leave Schlick's grazing
    term), white sheen of the given roughness."""
    sphere_gltf(path, {
        "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0,
                                 "roughnessFactor": 1},
        "extensions": {
            "KHR_materials_specular": {"specularFactor": 0.0},
            "KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1],
                                    "sheenRoughnessFactor": roughness},
        },
    })


def sphere_gltf(path, material, rings=96, segments=192):
    """A unit sphere at the origin of glTF material `material` (its extensions listed as
    used)."""
    positions, indices = [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2 * math.pi * j / segments
            positions += [math.sin(theta) * math.sin(phi), math.cos(theta),
                          math.sin(theta) * math.cos(phi)]
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            indices += [a, b, a + 1, a + 1, b, b + 1]
    vertex_bytes = struct.pack(f"<{len(positions)}f", *positions)
    index_bytes = struct.pack(f"<{len(indices)}I", *indices)
    data = vertex_bytes + vertex_bytes + index_bytes
    count = len(positions) // 3
    document = {
        "asset": {"version": "2.0"},
        "extensionsUsed": sorted(material.get("extensions", {})),
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2,
                                    "material": 0}]}],
        "materials": [material],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
             "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": len(indices), "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(vertex_bytes)},
            {"buffer": 0, "byteOffset": len(vertex_bytes), "byteLength": len(vertex_bytes)},
            {"buffer": 0, "byteOffset": 2 * len(vertex_bytes), "byteLength": len(index_bytes)},
        ],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(data).decode()}],
    }
    with open(path, "w") as f:
        json.dump(document, f)


def sheen_albedo(cos_o, roughness, n=256):
    """The directional albedo of KHR_materials_sheen's BRDF (Charlie distribution and
    visibility, F = 1, sheen colour 1, alphaG = sheenRoughness as the specification
    writes it) at cos θo, by the midpoint rule over the hemisphere."""
    alpha = max(roughness, 1e-3)

    def l(x):
        t = (1 - alpha) ** 2
        a, b, c = 21.5473 + t * (25.3245 - 21.5473), 3.82987 + t * (3.32435 - 3.82987), \
            0.19823 + t * (0.16801 - 0.19823)
        d, e = -1.97760 + t * (-1.27393 + 1.97760), -4.32054 + t * (-4.85967 + 4.32054)
        return a / (1 + b * x ** c) + d * x + e

    def lam(cos):
        return np.where(cos < 0.5, np.exp(l(np.minimum(cos, 0.5))),
                        np.exp(2 * l(0.5) - l(np.maximum(1 - cos, 1e-9))))

    theta = (np.arange(n) + 0.5) * (math.pi / 2) / n
    phi = (np.arange(2 * n) + 0.5) * (2 * math.pi) / (2 * n)
    theta, phi = np.meshgrid(theta, phi, indexing="ij")
    light = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    view = np.array([math.sqrt(1 - cos_o ** 2), 0.0, cos_o])[:, None, None]
    half = light + view
    cos_h = half[2] / np.linalg.norm(half, axis=0)
    sin2_h = np.maximum(1 - cos_h ** 2, 0.0)
    distribution = (2 + 1 / alpha) * sin2_h ** (0.5 / alpha) / (2 * math.pi)
    cos_i = light[2]
    visibility = 1 / ((1 + lam(cos_o) + lam(cos_i)) * (4 * cos_o * cos_i))
    integrand = distribution * visibility * cos_i * np.sin(theta)
    return integrand.sum() * (math.pi / 2 / n) * (2 * math.pi / (2 * n))


def cosines_seen(camera, size):
    """cos θo at each pixel centre of a camera looking at the unit sphere at the origin
    (NaN off the sphere)."""
    eye = np.array(camera["eye"], dtype=np.float64)
    forward = -eye / np.linalg.norm(eye)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half = math.tan(math.radians(camera["fov_y_deg"]) / 2)
    centres = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(centres * half, -centres * half)
    direction = forward + x[..., None] * right + y[..., None] * up
    direction /= np.linalg.norm(direction, axis=2, keepdims=True)
    b = direction @ eye
    disc = b ** 2 - (eye @ eye - 1)
    t = -b - np.sqrt(np.maximum(disc, 0))
    normal = eye + t[..., None] * direction
    cos = -(normal * direction).sum(axis=2)
    return np.where(disc > 0, cos, np.nan)


def furnace_camera(size):
    """A camera 30 units away on +Z framing the unit sphere at the origin."""
    return {"eye": [0.0, 0.0, 30.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0],
            "fov_y_deg": 2 * math.degrees(math.atan(1.04 / 30.0)), "width": size,
            "height": size}


def furnace_renders(args, directory, name, scene, camera):
    """Cycles' and mlt's renders (RGBA, RGB or None) of glTF `scene` under a white sky of
    radiance 1, and mlt's message where it refused the scene."""
    reset_blender()
    setup_cycles(args, transparent=True)
    world = bpy.data.worlds.new("white")
    bpy.context.scene.world = world
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    bpy.ops.import_scene.gltf(filepath=scene)
    single_scattering_ggx()
    setup_camera(camera)
    cycles_path = os.path.join(directory, f"{name}_cycles.exr")
    render_cycles(cycles_path)
    theirs = read_exr(cycles_path)
    out = os.path.join(directory, f"{name}_mlt.exr")
    camera_path = os.path.join(directory, "camera.json")
    with open(camera_path, "w") as f:
        json.dump(camera, f)
    command = [mlt_binary(), scene, "--camera", camera_path, "--background", "1,1,1",
               "--algorithm", "path", "--spp", str(args.spp), "--max-depth",
               str(args.depth), "--seed", "1", "--threads", str(args.threads), "--out", out]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        return theirs, None, "refused: " + result.stderr.strip().splitlines()[-1]
    return theirs, read_exr(out)[..., :3], None


def sheen_furnace(args, directory):
    """Rows (roughness, cos θo, specification, Cycles, mlt or its error) for a sphere of
    sheen alone under a white sky of radiance 1, where a pixel's value is the directional
    albedo at its cos θo (a convex sphere sees only the sky)."""
    camera = furnace_camera(args.size)
    cosines = cosines_seen(camera, args.size)
    rows = []
    for roughness in SHEEN_ROUGHNESSES:
        scene = os.path.join(directory, f"sheen_{roughness}.gltf")
        sheen_sphere_gltf(scene, roughness)
        theirs, ours, error = furnace_renders(args, directory, f"sheen_{roughness}", scene,
                                              camera)
        # Pixels the sphere covers fully: the silhouette's would mix in the sky.
        inside = theirs[..., 3] >= 0.999
        theirs = luminance(theirs)
        ours = luminance(ours) if ours is not None else None
        for cos_o in FURNACE_COSINES:
            ring = (np.abs(cosines - cos_o) < 0.02) & inside
            mlt = f"{ours[ring].mean():.3f}" if ours is not None else error
            rows.append((roughness, cos_o, sheen_albedo(cos_o, roughness),
                         sheen_albedo(cos_o, roughness ** 2), theirs[ring].mean(), mlt))
    return rows


# The base colour of the transmission tint's sphere.
TINT = (0.25, 0.5, 0.9)


def tint_furnace(args, directory):
    """Rows (channel, base colour, specification, Cycles, mlt or its error) for a smooth
    index-matched sphere (KHR_materials_volume, so a closed object, without attenuation) of
    base colour TINT and transmission 1 under a white sky of radiance 1: the sky seen
    straight through it, over the pixels within cos θ > 0.95 of its centre (Schlick's F
    with F0 = 0 is below 1e-6 there). The specification tints by the base colour at each
    crossing of the surface (its BTDF is specular_btdf × baseColor), so c²."""
    camera = furnace_camera(args.size)
    cosines = cosines_seen(camera, args.size)
    scene = os.path.join(directory, "tint.gltf")
    sphere_gltf(scene, {
        "pbrMetallicRoughness": {"baseColorFactor": [*TINT, 1], "metallicFactor": 0,
                                 "roughnessFactor": 0},
        "extensions": {
            "KHR_materials_transmission": {"transmissionFactor": 1.0},
            "KHR_materials_ior": {"ior": 1.0},
            "KHR_materials_volume": {"thicknessFactor": 1.0},
        },
    })
    theirs, ours, error = furnace_renders(args, directory, "tint", scene, camera)
    centre = (cosines > 0.95) & (theirs[..., 3] >= 0.999)
    rows = []
    for channel, name in enumerate("RGB"):
        c = TINT[channel]
        mlt = f"{ours[centre][:, channel].mean():.3f}" if ours is not None else error
        rows.append((name, c, c * c, theirs[centre][:, channel].mean(), mlt))
    return rows


# (roughness, anisotropyStrength) of the anisotropy furnace's white metal spheres.
ANISOTROPY_CASES = ((0.3, 0.5), (0.3, 1.0), (0.6, 1.0))


def anisotropic_metal_albedo(cos_o, roughness, strength, n=512, azimuths=8):
    """The directional albedo of a white (F = 1) metal under KHR_materials_anisotropy's
    GGX (α_t = mix(α, 1, strength²) along the direction, α_b = α across, α = roughness²;
    height-correlated Smith masking) at cos θo, averaged over the view's azimuth to the
    direction (the sphere's tangents turn around it): ∫ D(h) G2 (wo·h) / μo dω_h over the
    half vectors that reflect wo above the surface, by the midpoint rule."""
    alpha = roughness ** 2
    ax, ay = alpha + (1 - alpha) * strength ** 2, alpha
    theta = (np.arange(n) + 0.5) * (math.pi / 2) / n
    phi = (np.arange(4 * n) + 0.5) * (2 * math.pi) / (4 * n)
    theta, phi = np.meshgrid(theta, phi, indexing="ij")
    h = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    d = 1 / (math.pi * ax * ay * (h[0] ** 2 / ax ** 2 + h[1] ** 2 / ay ** 2 + h[2] ** 2) ** 2)

    def lam(w):
        return (np.sqrt(1 + (ax ** 2 * w[0] ** 2 + ay ** 2 * w[1] ** 2) / w[2] ** 2) - 1) / 2

    total = 0.0
    sin_o = math.sqrt(1 - cos_o ** 2)
    for k in range(azimuths):
        a = math.pi * (k + 0.5) / azimuths
        wo = np.array([sin_o * math.cos(a), sin_o * math.sin(a), cos_o])[:, None, None]
        cos_oh = (wo * h).sum(axis=0)
        wi = 2 * cos_oh * h - wo
        ok = (cos_oh > 0) & (wi[2] > 0)
        g2 = 1 / (1 + lam(wo) + lam(np.where(ok, wi, wo)))
        integrand = np.where(ok, d * g2 * cos_oh / cos_o, 0.0) * np.sin(theta)
        total += integrand.sum() * (math.pi / 2 / n) * (2 * math.pi / (4 * n))
    return total / azimuths


def anisotropy_furnace(args, directory):
    """Rows (roughness, strength, cos θo, specification, the same isotropic, Cycles, mlt)
    for white metal spheres with KHR_materials_anisotropy under a white sky of radiance 1:
    a pixel's value is the directional albedo at its cos θo. The specification's column is
    its GGX integrated by the script; the isotropic column leaves the strength out (what a
    renderer that kept the roughness would lose)."""
    camera = furnace_camera(args.size)
    cosines = cosines_seen(camera, args.size)
    rows = []
    for roughness, strength in ANISOTROPY_CASES:
        name = f"anisotropy_{roughness}_{strength}"
        scene = os.path.join(directory, name + ".gltf")
        sphere_gltf(scene, {
            "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 1,
                                     "roughnessFactor": roughness},
            "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": strength}},
        })
        theirs, ours, error = furnace_renders(args, directory, name, scene, camera)
        inside = theirs[..., 3] >= 0.999
        theirs = luminance(theirs)
        ours = luminance(ours) if ours is not None else None
        for cos_o in (0.95, 0.6):
            ring = (np.abs(cosines - cos_o) < 0.02) & inside
            mlt = f"{ours[ring].mean():.3f}" if ours is not None else error
            rows.append((roughness, strength, cos_o,
                         anisotropic_metal_albedo(cos_o, roughness, strength),
                         anisotropic_metal_albedo(cos_o, roughness, 0.0),
                         theirs[ring].mean(), mlt))
    return rows


def anisotropy_table(rows):
    lines = ["| roughness | strength | cos θo | specification | isotropic | Cycles | mlt |",
             "|---:|---:|---:|---:|---:|---:|---:|"]
    for roughness, strength, cos_o, spec, iso, cycles, mlt in rows:
        lines.append(f"| {roughness} | {strength} | {cos_o} | {spec:.3f} | {iso:.3f} | "
                     f"{cycles:.3f} | {mlt} |")
    return "\n".join(lines)


def specular_furnace(args, directory):
    """Rows (cos θo, specification, Cycles, mlt or its error) for a smooth sphere of black
    base colour and `KHR_materials_specular`'s colour 0 under a white sky of radiance 1:
    the specification's F0 = min(F0(ior) · specularColor, 1) · specular is 0 and its F90 =
    specular is 1, so a pixel reflects Schlick's (1 − cos θo)⁵ of the sky."""
    camera = furnace_camera(args.size)
    cosines = cosines_seen(camera, args.size)
    scene = os.path.join(directory, "specular_colour_0.gltf")
    sphere_gltf(scene, {
        "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0,
                                 "roughnessFactor": 0},
        "extensions": {"KHR_materials_specular": {"specularColorFactor": [0, 0, 0]}},
    })
    theirs, ours, error = furnace_renders(args, directory, "specular_colour_0", scene, camera)
    inside = theirs[..., 3] >= 0.999
    theirs = luminance(theirs)
    ours = luminance(ours) if ours is not None else None
    rows = []
    for cos_o in FURNACE_COSINES:
        ring = (np.abs(cosines - cos_o) < 0.02) & inside
        mlt = f"{ours[ring].mean():.4f}" if ours is not None else error
        # The ring's mean of (1 − cos)⁵ over its pixels' cosines.
        rows.append((cos_o, float(((1 - cosines[ring]) ** 5).mean()), theirs[ring].mean(), mlt))
    return rows


def specular_table(rows):
    lines = ["| cos θo | specification, (1 − cos θo)⁵ | Cycles | mlt |",
             "|---:|---:|---:|---:|"]
    for cos_o, spec, cycles, mlt in rows:
        lines.append(f"| {cos_o} | {spec:.4f} | {cycles:.4f} | {mlt} |")
    return "\n".join(lines)


def tint_table(rows):
    lines = ["| channel | base colour c | specification, c² | Cycles | mlt |",
             "|---|---:|---:|---:|---:|"]
    for name, c, spec, cycles, mlt in rows:
        lines.append(f"| {name} | {c} | {spec:.3f} | {cycles:.3f} | {mlt} |")
    return "\n".join(lines)


def furnace_table(rows):
    lines = ["| sheen roughness | cos θo | specification | the same, alphaG = roughness² | "
             "Cycles | mlt |",
             "|---:|---:|---:|---:|---:|---:|"]
    for roughness, cos_o, spec, squared, cycles, mlt in rows:
        lines.append(f"| {roughness} | {cos_o} | {spec:.3f} | {squared:.3f} | {cycles:.3f} | "
                     f"{mlt} |")
    return "\n".join(lines)


# ---------------------------------------------------------------- a normal-mapped square


# The tilts of the normal map's single texel, and the turns of the square about the vertical
# axis (the view's angle to the geometric normal; positive: the map tilts the normal
# further from the view, negative: towards it).
NORMAL_MAP_TILTS = (30.0, 60.0)
NORMAL_MAP_TURNS = (0.0, 20.0, -20.0, 45.0, -45.0)
# (label, glTF material without its normal texture) of the normal-mapped squares.
NORMAL_MAP_MATERIALS = (
    ("white metal, roughness 0.3",
     {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 1,
                               "roughnessFactor": 0.3}}),
    # KHR_materials_specular's factor 0: no specular layer, Lambert alone.
    ("white diffuse",
     {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
                               "roughnessFactor": 1},
      "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}),
)


def normal_texel(tilt_deg):
    """The 8-bit texel of a tangent-space normal tilted by `tilt_deg` towards the tangent,
    and the unit normal it decodes to."""
    t = math.radians(tilt_deg)
    texel = [round((c + 1) / 2 * 255) for c in (math.sin(t), 0.0, math.cos(t))]
    normal = np.array([c / 255 * 2 - 1 for c in texel])
    return texel, normal / np.linalg.norm(normal)


def square_gltf(path, material, texel, turn_deg):
    """A single-sided square [-1, 1]² facing +Z, turned by `turn_deg` about +Y (towards +X),
    texture coordinates u along +X (so its MikkTSpace tangent is +X), with glTF material
    `material` and a normal texture of the single `texel`."""
    image = np.array(texel, np.uint8)[None, None, :].repeat(4, 0).repeat(4, 1)
    png = iio.imwrite("<bytes>", image, extension=".png")
    positions = struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0)
    normals = struct.pack("<12f", *([0, 0, 1] * 4))
    uvs = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
    indices = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    data = positions + normals + uvs + indices
    half = math.radians(turn_deg) / 2
    material = dict(material, normalTexture={"index": 0})
    document = {
        "asset": {"version": "2.0"},
        "extensionsUsed": sorted(material.get("extensions", {})),
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "rotation": [0, math.sin(half), 0, math.cos(half)]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1,
                                                   "TEXCOORD_0": 2},
                                    "indices": 3, "material": 0}]}],
        "materials": [material],
        "samplers": [{"magFilter": 9728, "minFilter": 9728}],
        "textures": [{"source": 0, "sampler": 0}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32},
            {"buffer": 0, "byteOffset": 128, "byteLength": 12},
        ],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(data).decode()}],
    }
    with open(path, "w") as f:
        json.dump(document, f)


def frame_of(normal):
    """Two unit vectors completing `normal` to a right-handed orthonormal frame."""
    helper = np.array([1.0, 0, 0]) if abs(normal[0]) < 0.9 else np.array([0, 1.0, 0])
    x = np.cross(helper, normal)
    x /= np.linalg.norm(x)
    return x, np.cross(normal, x)


def normal_mapped_albedo(metal, wo, ns, ng, above_geometric, n=512):
    """What a white sky of radiance 1 gives, seen from `wo`, on a surface whose
    specification BRDF scatters about shading normal `ns`: ∫ f(wo, wi) (wi·ns) dwi over the
    directions above ns, and with `above_geometric` only over those also above geometric
    normal `ng` (Veach's rule: light from below the surface does not reach it). Where `wo`
    is below ns, about -ns (mlt's model is two-sided: it scatters into the side of ns the
    view is on). `metal`: white GGX metal of roughness 0.3 (F = 1, height-correlated
    Smith masking), integrated over the half vectors; else Lambert of albedo 1. Midpoint
    rule."""
    if wo @ ns < 0:
        ns = -ns
    cos_o = wo @ ns
    x, y = frame_of(ns)
    theta = (np.arange(n) + 0.5) * (math.pi / 2) / n
    phi = (np.arange(4 * n) + 0.5) * (2 * math.pi) / (4 * n)
    theta, phi = np.meshgrid(theta, phi, indexing="ij")
    local = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                      np.cos(theta)])
    w = (x[:, None, None] * local[0] + y[:, None, None] * local[1]
         + ns[:, None, None] * local[2])
    area = np.sin(theta) * (math.pi / 2 / n) * (2 * math.pi / (4 * n))
    if not metal:
        keep = (np.einsum("i,ijk->jk", ng, w) > 0) if above_geometric else True
        return float((np.where(keep, local[2], 0.0) / math.pi * area).sum())
    alpha2 = 0.3 ** 4
    h, cos_h = w, local[2]
    d = alpha2 / (math.pi * (cos_h ** 2 * (alpha2 - 1) + 1) ** 2)
    cos_oh = np.einsum("i,ijk->jk", wo, h)
    wi = 2 * cos_oh * h - wo[:, None, None]
    cos_i = np.einsum("i,ijk->jk", ns, wi)
    keep = (cos_oh > 0) & (cos_i > 0)
    if above_geometric:
        keep &= np.einsum("i,ijk->jk", ng, wi) > 0

    def lam(cos):
        cos = np.clip(cos, 1e-6, 1.0)
        return (np.sqrt(1 + alpha2 * (1 - cos ** 2) / cos ** 2) - 1) / 2

    g2 = 1 / (1 + lam(cos_o) + lam(cos_i))
    return float((np.where(keep, d * g2 * cos_oh / cos_o, 0.0) * area).sum())


def normal_map_furnace(args, directory):
    """Rows (material, tilt, turn, wo·ns, shading hemisphere, Veach, Cycles, mlt or its
    error) for a flat single-sided square whose normal map is one texel tilting the normal
    by a known angle, turned about the vertical axis and seen along -Z from far away,
    under a white sky of radiance 1 (over the pixels the square covers fully)."""
    camera = {"eye": [0.0, 0.0, 100.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0],
              "fov_y_deg": 2 * math.degrees(math.atan(1.04 / 100.0)), "width": args.size,
              "height": args.size}
    wo = np.array([0.0, 0.0, 1.0])
    rows = []
    for label, material in NORMAL_MAP_MATERIALS:
        metal = material["pbrMetallicRoughness"]["metallicFactor"] == 1
        for tilt in NORMAL_MAP_TILTS:
            texel, local_normal = normal_texel(tilt)
            for turn in NORMAL_MAP_TURNS:
                name = f"normal_map_{'metal' if metal else 'diffuse'}_{tilt:.0f}_{turn:.0f}"
                scene = os.path.join(directory, name + ".gltf")
                square_gltf(scene, material, texel, turn)
                theirs, ours, error = furnace_renders(args, directory, name, scene, camera)
                covered = theirs[..., 3] >= 0.999
                # The square's frame turned about +Y: tangent, bitangent and normal.
                t = math.radians(turn)
                ng = np.array([math.sin(t), 0.0, math.cos(t)])
                tangent = np.array([math.cos(t), 0.0, -math.sin(t)])
                ns = local_normal[0] * tangent + local_normal[2] * ng
                mlt = (f"{luminance(ours)[covered].mean():.3f}" if ours is not None
                       else error)
                # The specification's BRDF has no value for a view below the normal.
                rows.append((label, tilt, turn, float(wo @ ns),
                             normal_mapped_albedo(metal, wo, ns, ng, False)
                             if wo @ ns > 0 else None,
                             normal_mapped_albedo(metal, wo, ns, ng, True),
                             luminance(theirs)[covered].mean(), mlt))
    return rows


def normal_map_table(rows):
    lines = ["| material | tilt | view to ng | the map tilts the normal | wo·ns | "
             "over ns's hemisphere | Veach: also above ng | Cycles | mlt |",
             "|---|---:|---:|---|---:|---:|---:|---:|---:|"]
    for label, tilt, turn, cos_o, hemisphere, veach, cycles, mlt in rows:
        way = "—" if turn == 0 else ("away from the view" if turn > 0 else "towards the view")
        hemisphere = "—" if hemisphere is None else f"{hemisphere:.3f}"
        lines.append(f"| {label} | {tilt:.0f}° | {abs(turn):.0f}° | {way} | {cos_o:.3f} | "
                     f"{hemisphere} | {veach:.3f} | {cycles:.3f} | {mlt} |")
    return "\n".join(lines)


def flat_table(pairs):
    lines = ["| asset | mean luminance | worst 16×16 block | without normal maps: mean | "
             "worst block |",
             "|---|---:|---:|---:|---:|"]
    for with_maps, without in pairs:
        def cell(r, key):
            return "—" if r.get(key) is None else f"{r[key]:.3f}"
        lines.append(f"| {with_maps['name']} | {cell(with_maps, 'mean')} | "
                     f"{cell(with_maps, 'worst')} | {cell(without, 'mean')} | "
                     f"{cell(without, 'worst')} |")
    return "\n".join(lines)


# ---------------------------------------------------------------- the runs


def sky_check(args, sky, directory):
    """Both renderers' skies alone, from four directions 10° above the horizon: the mean
    ratio, the largest and the 99th percentile of |pixel ratio - 1|, and that percentile
    between two Cycles renders of different seeds (the noise floor)."""
    scene = os.path.join(directory, "far_triangle.gltf")
    far_triangle_gltf(scene)
    rows = []
    rise = math.tan(math.radians(10.0))
    for label, direction in (("+Z", (0, rise, 1)), ("+X", (1, rise, 0)), ("-Z", (0, rise, -1)),
                             ("-X", (-1, rise, 0))):
        camera = direction_camera(direction, args.size)
        out = os.path.join(directory, "sky_mlt.exr")
        seconds, error = render_mlt(args, scene, camera, sky, out, directory)
        if error:
            sys.exit(f"mlt cannot render the sky alone: {error}")
        ours = read_exr(out)
        reset_blender()
        setup_cycles(args, transparent=False)
        setup_world(sky, args.sky_rotate)
        setup_camera(camera)
        path = os.path.join(directory, "sky_cycles.exr")
        render_cycles(path)
        theirs = read_exr(path)
        # The noise floor: Cycles against itself with another seed.
        bpy.context.scene.cycles.seed = 2
        render_cycles(path)
        again = luminance(read_exr(path))
        lo, lt = luminance(ours), luminance(theirs)
        deviation = np.abs(lo / np.maximum(lt, 1e-12) - 1)
        noise = np.abs(again / np.maximum(lt, 1e-12) - 1)
        rows.append((label, lo.sum() / lt.sum(), deviation.max(), np.percentile(deviation, 99),
                     np.percentile(noise, 99)))
    return rows


def has_normal_maps(path):
    return any("normalTexture" in m or "clearcoatNormalTexture"
               in json.dumps(m.get("extensions", {}))
               for m in gltf_json(path).get("materials", []))


def run_asset(args, name, sky, directory, flat=False):
    """Renders asset `name` with both renderers and compares them; `flat`: a copy without
    its normal maps (and no picture)."""
    scene = asset_file(name)
    if flat:
        scene = without_normal_maps(scene, directory)
    reset_blender()
    setup_cycles(args, transparent=True)
    setup_world(sky, args.sky_rotate)
    bpy.ops.import_scene.gltf(filepath=scene)
    for obj in list(bpy.context.scene.objects):
        if obj.type in ("CAMERA",):
            bpy.data.objects.remove(obj)
    single_scattering_ggx()
    if args.spec_tint:
        squared_transmission_tint()
    low, high = model_bounds()
    camera = framing_camera(low, high, args.size)
    setup_camera(camera)
    start = time.perf_counter()
    cycles_path = os.path.join(directory, name + "_cycles.exr")
    render_cycles(cycles_path)
    cycles_seconds = time.perf_counter() - start
    theirs = read_exr(cycles_path)

    # The sky behind the model from the same camera (Cycles' film was transparent): its
    # alpha composites the sky back in, exactly, with a box filter.
    reset_blender()
    setup_cycles(args, transparent=False)
    setup_world(sky, args.sky_rotate)
    setup_camera(camera)
    sky_path = os.path.join(directory, name + "_sky.exr")
    render_cycles(sky_path)
    background = read_exr(sky_path)
    alpha = theirs[..., 3:4]
    mask = alpha[..., 0] >= 0.999
    composite = theirs.copy()
    composite[..., :3] += (1 - alpha) * background[..., :3]

    mlt_path = os.path.join(directory, name + "_mlt.exr")
    mlt_seconds, error = render_mlt(args, scene, camera, sky, mlt_path, directory)
    result = {"name": name, "features": features_of(scene), "coverage": mask.mean(),
              "cycles_seconds": cycles_seconds, "mlt_seconds": mlt_seconds, "error": error}
    if error is None:
        ours = read_exr(mlt_path)
        result["mean"], result["worst"] = compare(ours, composite, mask)
        if args.docs and not flat:
            side_by_side(os.path.join(args.images, name + ".png"), ours, composite, mask)
    return result


def table(results):
    lines = ["| asset | features | covered | mean luminance | worst 16×16 block | mlt s | "
             "Cycles s |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for r in results:
        if r["error"] is not None:
            lines.append(f"| {r['name']} | {r['features']} | {100 * r['coverage']:.0f}% | refused: "
                         f"{r['error'].replace('|', '/')} | — | — | "
                         f"{r['cycles_seconds']:.1f} |")
            continue
        worst = "—" if r["worst"] is None else f"{r['worst']:.3f}"
        lines.append(f"| {r['name']} | {r['features']} | {100 * r['coverage']:.0f}% | "
                     f"{r['mean']:.3f} | {worst} | {r['mlt_seconds']:.1f} | "
                     f"{r['cycles_seconds']:.1f} |")
    return "\n".join(lines)


def sky_table(rows):
    lines = ["| looking along | mean ratio | largest pixel deviation | 99th percentile | "
             "Cycles against itself, 99th percentile |",
             "|---|---:|---:|---:|---:|"]
    for label, mean, largest, p99, noise in rows:
        lines.append(f"| {label} | {mean:.4f} | {100 * largest:.2f}% | {100 * p99:.2f}% | "
                     f"{100 * noise:.2f}% |")
    return "\n".join(lines)


def command_line(args):
    parts = ["nice -n 10 target/cycles-venv/bin/python benches/cycles/compare.py"]
    if args.spp != 64:
        parts.append(f"--spp {args.spp}")
    if args.size != 128:
        parts.append(f"--size {args.size}")
    if args.depth != 8:
        parts.append(f"--depth {args.depth}")
    if args.sky != "pedestrian_overpass":
        parts.append(f"--sky {args.sky}")
    if args.sky_rotate != 0:
        parts.append(f"--sky-rotate {args.sky_rotate}")
    if args.assets != ",".join(DEFAULT_ASSETS):
        parts.append(f"--assets {args.assets}")
    return " ".join(parts)


def write_page(args, sky_rows, results, furnace_rows, tint_rows, anisotropy_rows, specular_rows,
               flat_results, normal_rows, seconds):
    images = os.path.relpath(args.images, os.path.join(ROOT, "docs"))
    lines = [
        "# mlt against Blender Cycles",
        "",
        "<!-- Written by benches/cycles/compare.py: edit the script, not this page. -->",
        "",
        "Khronos glTF sample assets (`benches/cycles/assets`, each with its licence) rendered by",
        "mlt's path tracer and by Blender Cycles (`bpy` 5.0.1, its stock glTF importer), with the",
        "same camera (the model's bounding box framed from the front), the same sky",
        f"(`{args.sky}`, the only light), {args.size}² pixels, {args.spp} samples per pixel,",
        f"depth {args.depth}, a 1-pixel box filter, textures at full resolution in both (mlt's",
        "`--full-resolution-textures`: Cycles has no mip-maps), single-scattering GGX in Cycles' Principled",
        "BSDF, no denoising or clamping, linear EXR. What the script does and why is in its",
        "doc comment; [benchmarks](benchmarks.md#gltf-assets-against-blender-cycles) says what",
        f"the figures mean. Command (about {seconds / 60:.0f} minutes on the 2-core development",
        "machine, shared with other work):",
        "",
        f"    {command_line(args)}",
        "",
        "## The sky alone",
        "",
        "Both renderers' environments, no model, 10° above the horizon in four directions",
        "(luminance mlt / Cycles per pixel; the last column compares two Cycles renders of",
        "different seeds, the noise floor the others can reach):",
        "",
        sky_table(sky_rows),
        "",
        "## The assets",
        "",
        "Ratios mlt / Cycles of luminance over the pixels the model covers fully (Cycles'",
        "alpha); the worst block is the 16×16 block (at least a quarter covered) whose ratio is",
        "furthest from 1; seconds are wall-clock (mlt's include loading the file and building",
        "its acceleration structure), each renderer on the same threads. Features are the",
        "file's `extensionsUsed`, shortened (`KHR_materials_` left out), texture coordinate",
        "sets past the first and alpha modes other than OPAQUE. An asset mlt cannot",
        "load is marked refused, with its message.",
        "",
        table(results),
        "",
        "Each picture: mlt | Cycles | log₂ of mlt / Cycles over 3×3 pixels, white where they",
        "agree, red where mlt is brighter, blue where darker, full colour at ±0.5 stops (grey:",
        "not covered). Both renders share one exposure.",
        "",
    ]
    for r in results:
        if r["error"] is None:
            lines += [f"**{r['name']}**", "", f"![{r['name']}]({images}/{r['name']}.png)", ""]
        else:
            lines += [f"**{r['name']}**: mlt refused it ({r['error']}).", ""]
    if furnace_rows:
        lines += [
            "## Sheen alone in a white furnace",
            "",
            "Where Cycles departs from the specification: its sheen is Blender's own model, not",
            "the Charlie sheen of `KHR_materials_sheen`. A unit sphere of sheen alone (black",
            "base, `KHR_materials_specular`'s factor 0 so no specular lobe, white sheen) under a",
            "white sky of radiance 1: a pixel's value is the directional albedo at its cos θo",
            "(averaged over the pixels the sphere covers whose centre's cos θo is within ±0.02).",
            "The specification's column is its BRDF (Charlie distribution and visibility, no",
            "Fresnel, alphaG = sheenRoughness as it writes) integrated numerically by the",
            "script; the next column squares the roughness first, as the Khronos sample viewer",
            "does. mlt's column is whatever mlt makes of that material: the sheen where it reads",
            "it, else the black base's specular lobe.",
            "",
            furnace_table(furnace_rows),
            "",
        ]
    if tint_rows:
        lines += [
            "## Transmission's tint through a closed object",
            "",
            "Where Cycles departs from the specification: `KHR_materials_transmission`'s BTDF",
            "is specular_btdf × baseColor, a tint at each crossing of the surface, so light",
            "through a closed object (`KHR_materials_volume`) is tinted by c²; Cycles'",
            "Principled BSDF tints each refraction by √c, so by c in all. A smooth sphere of",
            f"base colour {TINT}, index of refraction 1 (nothing bends, and Schlick's F is",
            "below 10⁻⁶ face-on), transmission 1, under a white sky of radiance 1: the sky",
            "seen straight through its centre (cos θ > 0.95). This is most of",
            "TransmissionRoughnessTest's difference above: its tiles' base colour is",
            "(0.5, 0.7, 0.9), and mlt / Cycles per channel over a smooth tile approaches it as",
            "the index (and with it the untinted reflection) goes down.",
            "",
            tint_table(tint_rows),
            "",
        ]
    if anisotropy_rows:
        lines += [
            "## Anisotropy alone in a white furnace",
            "",
            "White metal spheres (F = 1) with `KHR_materials_anisotropy` under a white sky of",
            "radiance 1: a pixel's value is the directional albedo at its cos θo. The",
            "specification widens GGX along the direction to α_t = mix(α, 1, strength²); its",
            "column is that lobe integrated by the script (averaged over the view's azimuth to",
            "the direction), the next the isotropic lobe of the same roughness. Blender's",
            "importer passes the strength to the Principled BSDF's Anisotropic input and keeps",
            "the roughness, so Cycles stretches its own way.",
            "",
            anisotropy_table(anisotropy_rows),
            "",
        ]
    if specular_rows:
        lines += [
            "## Specular colour 0 in a white furnace",
            "",
            "A smooth sphere of black base colour and `KHR_materials_specular`'s colour 0 (as",
            "SpecularTest's first column) under a white sky of radiance 1. The specification",
            "scales F0 by the colour and keeps F90 = specular = 1, so the sphere reflects",
            "Schlick's (1 − cos θo)⁵ of the sky: nothing face-on, all at grazing angles.",
            "",
            specular_table(specular_rows),
            "",
        ]
    if normal_rows:
        lines += [
            "## Normal maps",
            "",
            "Where the conventions part: a normal map bends the shading normal ns away from the",
            "geometric normal ng, and a direction can then be above one and below the other.",
            "mlt follows Veach: the model scatters about ns (about −ns for a view below ns: its",
            "model is two-sided), light from below the geometric surface does not reach it,",
            "and a direction that is a reflection for one normal and a transmission for the",
            "other scatters nothing. Cycles bends a glossy lobe's normal towards ng until the",
            "view's mirror reflection is just above the surface (`ensure_valid_specular_reflection`,",
            "for the Principled BSDF's specular, metallic, transmission and coat lobes), and",
            "darkens a diffuse lobe by Estevez, Lecocq and Stein's shadowing term for bumped",
            "normals (Smith's G1 of GGX with α² = tan²θ/8, θ the normal map's tilt, at the",
            "light's angle to the unmapped normal; the furnace's 0.880 and 0.564 are that",
            "term integrated). A rough or smooth glossy surface whose map tilts the normal",
            "far from the view therefore shows the sky's horizon in Cycles where it reflects",
            "below the surface, into itself, in mlt.",
            "",
            "The assets that have normal maps, rendered again from copies without them (both",
            "renderers; `--flat-normals` does it for every asset):",
            "",
            flat_table(flat_results),
            "",
            "A flat single-sided square whose normal map is a single texel tilting the",
            "normal by a known angle towards the tangent, turned about the vertical axis so",
            "that the view makes a known angle with ng, under a white sky of radiance 1. The",
            "reference columns integrate the specification's BRDF (the metal: GGX of",
            "roughness 0.3, F = 1; the diffuse: Lambert, `KHR_materials_specular`'s factor 0)",
            "times wi·ns over the directions above ns (what a rasteriser such as the Khronos",
            "sample viewer shows; — where the view is below ns, where the BRDF has no value),",
            "and over those also above ng (Veach's rule; about −ns where the view is below ns):",
            "the last is what mlt's path tracer converges to.",
            "",
            normal_map_table(normal_rows),
            "",
        ]
    lines += [
        "## A thin film alone in a white furnace",
        "",
        "Blender's importer does not read `KHR_materials_iridescence`; Cycles' Principled BSDF",
        "has a thin film of its own (Thin Film Thickness and IOR). `benches/cycles/thin_film.py`",
        "compares the two on a smooth sphere under a white sky and writes",
        "[its table](cycles-thin-film.md).",
        "",
    ]
    with open(os.path.join(ROOT, "docs", "cycles.md"), "w") as f:
        f.write("\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--depth", type=int, default=8)
    parser.add_argument("--sky", default="pedestrian_overpass",
                        help="pedestrian_overpass, quarry_01 or royal_esplanade")
    parser.add_argument("--sky-rotate", type=float, default=0.0,
                        help="degrees about the up axis, counter-clockwise seen from above")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--assets", default=",".join(DEFAULT_ASSETS))
    parser.add_argument("--no-furnace", dest="furnace", action="store_false",
                        help="leave out the furnaces (and the assets again without normal maps)")
    parser.add_argument("--spec-tint", action="store_true",
                        help="square transmissive base colours in Cycles (see "
                             "squared_transmission_tint); for a look, with --no-docs")
    parser.add_argument("--flat-normals", action="store_true",
                        help="render copies of the assets without their normal maps (see "
                             "without_normal_maps); for a look, with --no-docs")
    parser.add_argument("--no-docs", dest="docs", action="store_false",
                        help="print the tables only; leave docs/ alone")
    args = parser.parse_args()
    args.images = os.path.join(ROOT, "docs", "images", "cycles")
    sky = os.path.join(ASSETS, "sky", args.sky + "_1k.hdr")
    if not os.path.exists(mlt_binary()):
        sys.exit(f"{mlt_binary()} is missing: cargo build --release")
    if args.docs:
        os.makedirs(args.images, exist_ok=True)
    start = time.perf_counter()
    # The renders' EXR files stay there for a closer look.
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    directory = os.path.join(target, "mlt-bench", "cycles")
    os.makedirs(directory, exist_ok=True)
    sky_rows = sky_check(args, sky, directory)
    print("The sky alone, luminance mlt / Cycles:")
    print(sky_table(sky_rows), flush=True)
    results = []
    for name in args.assets.split(","):
        result = run_asset(args, name, sky, directory, flat=args.flat_normals)
        results.append(result)
        print(f"{name}: {result.get('mean', result['error'])}", flush=True)
    print(table(results), flush=True)
    # What the normal maps change: each asset that has some, again without them.
    flat_results = []
    if args.furnace and not args.flat_normals:
        for result in results:
            if result["error"] is None and has_normal_maps(asset_file(result["name"])):
                flat_results.append((result, run_asset(args, result["name"], sky, directory,
                                                       flat=True)))
        if flat_results:
            print(flat_table(flat_results), flush=True)
    normal_rows = normal_map_furnace(args, directory) if args.furnace else []
    if normal_rows:
        print("A normal-mapped square in a white furnace:")
        print(normal_map_table(normal_rows), flush=True)
    furnace_rows = sheen_furnace(args, directory) if args.furnace else []
    if furnace_rows:
        print("Sheen alone in a white furnace, directional albedo:")
        print(furnace_table(furnace_rows))
    tint_rows = tint_furnace(args, directory) if args.furnace else []
    anisotropy_rows = anisotropy_furnace(args, directory) if args.furnace else []
    specular_rows = specular_furnace(args, directory) if args.furnace else []
    if specular_rows:
        print("A smooth black sphere of specular colour 0 in a white furnace:")
        print(specular_table(specular_rows))
    if anisotropy_rows:
        print("White anisotropic metals in a white furnace, directional albedo:")
        print(anisotropy_table(anisotropy_rows))
    if tint_rows:
        print("The white sky through an index-matched sphere of base colour TINT:")
        print(tint_table(tint_rows))
    seconds = time.perf_counter() - start
    print(f"{seconds:.0f} s in all")
    if args.docs:
        write_page(args, sky_rows, results, furnace_rows, tint_rows, anisotropy_rows,
                   specular_rows, flat_results, normal_rows, seconds)


if __name__ == "__main__":
    main()
