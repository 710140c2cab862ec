"""Bad input raises clear errors: the class, the status and a message naming the culprit."""

from __future__ import annotations

import base64
import json
import pathlib
import pickle
import re

import numpy as np
import numpy.typing as npt
import pytest
from conftest import CAMERA, REPOSITORY, SCENES, quad

import mlt


def build(positions: npt.ArrayLike | None = None, indices: npt.ArrayLike | None = None, **kwargs: object) -> mlt.Scene:
    good_positions, good_indices = quad()
    return mlt.Scene.from_arrays(
        good_positions if positions is None else positions,
        good_indices if indices is None else indices,
        **kwargs,  # type: ignore[arg-type]
    )


def invalid(match: str) -> pytest.RaisesExc[mlt.InvalidArgumentError]:
    return pytest.raises(mlt.InvalidArgumentError, match=match)


@pytest.mark.parametrize(
    ("positions", "match"),
    [
        (np.zeros((4, 2), np.float32), r"positions has shape \(4, 2\); expected \(N, 3\)"),
        (np.zeros(12, np.float32), r"positions has shape \(12,\); expected \(N, 3\)"),
        (np.zeros((4, 3), np.complex64), "positions has dtype complex64"),
        ([["a", "b", "c"]] * 4, "positions has dtype <U1"),
    ],
)
def test_positions_of_the_wrong_shape_or_dtype(positions: npt.ArrayLike, match: str) -> None:
    with invalid(match):
        build(positions=positions)


@pytest.mark.parametrize(
    ("indices", "match"),
    [
        (np.array([[0, 1], [2, 3]]), r"indices has shape \(2, 2\); expected \(M, 3\)"),
        (np.array([[0.0, 2.0, 1.0]]), "indices has dtype float64; expected integers"),
        (np.array([[0, 2, 1], [0, -3, 2]]), r"indices\[1, 1\] is -3; it must be in \[0, 2\^32 - 1\]"),
        (np.array([[0, 2, 1], [0, 2**40, 2]]), r"indices\[1, 1\] is 1099511627776"),
        # Past the vertices: the Rust API's check, naming the element and the count.
        (np.array([[0, 2, 1], [0, 9, 2]]), r"desc.indices\[4\] \(triangle 1\) is 9, but there are only 4 vertices"),
    ],
)
def test_bad_indices(indices: npt.ArrayLike, match: str) -> None:
    with invalid(match):
        build(indices=indices)


def test_nan_position_names_the_vertex() -> None:
    positions, _ = quad()
    positions[2, 1] = np.nan
    with invalid(r"desc.positions\[7\] \(vertex 2, y\) is NaN; vertex coordinates must be finite"):
        build(positions=positions)


def test_float64_beyond_float32_is_rejected_not_clamped() -> None:
    positions = quad()[0].astype(np.float64)
    positions[1, 0] = 1e300
    with pytest.warns(RuntimeWarning), invalid(r"desc.positions\[3\] \(vertex 1, x\) is inf"):
        build(positions=positions)


def test_array_likes_are_accepted() -> None:
    # Nested lists of ints and float64 arrays convert; the result is the same scene.
    scene = build(positions=[[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], indices=[[0, 2, 1], [0, 3, 2]])
    assert scene.info.triangle_count == 2
    assert scene.info.bounds_max == (1.0, 1.0, 0.0)


def test_error_carries_status_code_and_message() -> None:
    with pytest.raises(mlt.MltError) as caught:
        build(material_ids=[0, 5])
    error = caught.value
    # Invalid arguments are also ValueErrors (and MltErrors, RuntimeErrors).
    assert isinstance(error, ValueError) and isinstance(error, RuntimeError)
    assert error.status == "invalid_argument"
    assert error.code == 1  # MLT_STATUS_INVALID_ARGUMENT
    assert error.message == "desc.material_ids[1] is 5, but there are only 1 materials"
    assert str(error) == "invalid argument: " + error.message
    # Errors pickle with their fields (they cross process boundaries in distributed use).
    again = pickle.loads(pickle.dumps(error))
    assert type(again) is mlt.InvalidArgumentError and again.message == error.message


def test_bad_materials() -> None:
    with invalid(r'materials\[0\].kind is "plastic"; expected one of "diffuse", "mirror", "dielectric", "metallic-roughness"$'):
        build(materials=[mlt.Material(kind="plastic")])
    with invalid(r"desc.materials\[1\].color.y is 1.5; a reflectance must be in \[0, 1\]; above 1 would create energy"):
        build(materials=[mlt.Material(), mlt.Material(color=(0.5, 1.5, 0.5))])
    with pytest.raises(TypeError, match=r"materials\[0\]: .*unexpected keyword argument 'colour'"):
        build(materials=[{"colour": (1, 0, 0)}])
    with pytest.raises(TypeError, match=r"materials\[0\].roughness: "):
        build(materials=[mlt.Material(roughness="smooth")])  # type: ignore[arg-type]
    with invalid(r"materials\[0\].color: "):
        build(materials=[mlt.Material(color=(1.0, 0.0))])  # type: ignore[arg-type]
    with invalid("desc.materials is empty"):
        build(materials=[])
    with invalid(r"desc.materials\[0\].roughness is NaN; it must be a finite number$"):
        build(materials=[mlt.Material(kind="metallic-roughness", roughness=float("nan"))])
    with invalid(r"desc.materials\[0\].thickness is -1; a thickness must not be negative \(0: thin-walled\)$"):
        build(materials=[mlt.Material(kind="dielectric", thickness=-1.0)])


def test_names_ignore_case_and_dashes() -> None:
    # Enumerations are strings: "metallic-roughness", "PSSMLT_BDPT" and "BVH" name the same.
    scene = build(
        materials=[mlt.Material(kind="Metallic-Roughness", emission=(1.0, 1.0, 1.0))], backend="BVH"  # type: ignore[arg-type]
    )
    image, _ = mlt.render(scene, CAMERA, mlt.RenderSettings(width=4, height=4, algorithm="PSSMLT_BDPT", mutations_per_pixel=1, bootstrap_samples=64, chains=4))
    assert np.isfinite(image).all() and image.mean() > 0


def test_bad_settings_and_camera() -> None:
    scene = build()
    with invalid("settings.width is 0; it must be between 1 and 65536"):
        mlt.render(scene, CAMERA, mlt.RenderSettings(width=0))
    with invalid(r'RenderSettings.algorithm is "metropolis"; expected one of "path", "bdpt"'):
        mlt.render(scene, CAMERA, mlt.RenderSettings(algorithm="metropolis"))
    with invalid("settings.height is -1; it must be between 1 and 65536"):
        mlt.render(scene, CAMERA, mlt.RenderSettings(height=-1))
    with pytest.raises(TypeError, match="RenderSettings.seed: "):
        mlt.render(scene, CAMERA, mlt.RenderSettings(seed="seven"))  # type: ignore[arg-type]
    with invalid("camera.eye .* and camera.target .* coincide"):
        mlt.render(scene, mlt.Camera(eye=(0, 0, 0), target=(0, 0, 0)))
    with pytest.raises(TypeError, match="Camera has no field eye"):
        mlt.render(scene, object())  # type: ignore[arg-type]


def test_bad_lights_and_backend() -> None:
    with invalid(r"desc.sun.direction is \[0.0, 0.0, 0.0\]"):
        build(sun=mlt.Sun(direction=(0, 0, 0), irradiance=(1, 1, 1)))
    with invalid(r"Environment.pixels has shape \(2, 3\); expected \(height, width, 3\)"):
        build(environment=mlt.Environment(pixels=np.ones((2, 3))))
    with invalid(r'lights\[0\].kind is "area"'):
        build(lights=[mlt.PunctualLight(kind="area")])
    with invalid(r'Scene.backend is "optix"; expected one of "bvh", "embree"'):
        build(backend="optix")  # type: ignore[arg-type]


@pytest.mark.skipif(mlt.EMBREE_AVAILABLE, reason="this build has Embree")
def test_embree_without_the_feature_is_unsupported() -> None:
    with pytest.raises(mlt.UnsupportedError) as caught:
        build(backend="embree")
    assert caught.value.status == "unsupported" and caught.value.code == 2
    assert not isinstance(caught.value, ValueError)


def variants_gltf(path: pathlib.Path, mappings: list[dict[str, object]]) -> pathlib.Path:
    """A quad whose default material is plain and whose variant "lit" makes it emit; the
    file's variants are "lit" and "plain"; `mappings` is the quad's mapping list."""
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], "<f4")
    indices = np.array([0, 1, 2, 0, 2, 3], "<u2")
    buffer = positions.tobytes() + indices.tobytes()
    document = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_variants"],
        "extensions": {"KHR_materials_variants": {"variants": [{"name": "lit"}, {"name": "plain"}]}},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [
            {
                "primitives": [
                    {
                        "attributes": {"POSITION": 0},
                        "indices": 1,
                        "material": 0,
                        "extensions": {"KHR_materials_variants": {"mappings": mappings}},
                    }
                ]
            }
        ],
        "materials": [{"name": "plain"}, {"name": "lamp", "emissiveFactor": [1, 1, 1]}],
        "buffers": [
            {
                "uri": "data:application/octet-stream;base64," + base64.b64encode(buffer).decode(),
                "byteLength": len(buffer),
            }
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 12},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    path.write_text(json.dumps(document))
    return path


def test_material_variants_are_picked_by_name(tmp_path: pathlib.Path) -> None:
    path = variants_gltf(tmp_path / "variants.gltf", [{"material": 1, "variants": [0]}])
    assert mlt.Scene.load(path)[0].info.emitter_count == 0
    assert mlt.Scene.load(path, variant="plain")[0].info.emitter_count == 0
    assert mlt.Scene.load(path, variant="lit")[0].info.emitter_count == 2
    with pytest.raises(mlt.LoadError, match=re.escape('no material variant "dim"; its variants are "lit", "plain"')):
        mlt.Scene.load(path, variant="dim")
    with pytest.raises(mlt.LoadError, match="only glTF files have material variants"):
        mlt.Scene.load(SCENES / "cornell-box.obj", variant="lit")
    with pytest.raises(mlt.LoadError, match="no material variants"):
        mlt.Scene.load(SCENES / "sky-spheres.gltf", variant="lit")
    path = variants_gltf(tmp_path / "bad.gltf", [{"material": 1, "variants": [2]}])
    with pytest.raises(mlt.LoadError, match="names variant 2, but there are 2 variants"):
        mlt.Scene.load(path)


def test_loading_errors(tmp_path: object) -> None:
    with pytest.raises(FileNotFoundError, match="no-such-scene.obj does not exist"):
        mlt.Scene.load(SCENES / "no-such-scene.obj")
    with pytest.raises(mlt.LoadError, match=re.escape("unsupported file extension (expected .obj, .gltf or .glb)")) as caught:
        mlt.Scene.load(REPOSITORY / "README.md")
    assert caught.value.status == "load_error" and caught.value.code is None
    with pytest.raises(mlt.LoadError, match="unsupported file extension"):
        mlt.load_environment(REPOSITORY / "README.md")
