"""Rendering: analytic images, determinism, the scene files of the repository."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import CAMERA, SCENES, quad

import mlt

ALGORITHMS = [a.value for a in mlt.Algorithm]


def small(algorithm: str = "path", **fields: object) -> mlt.RenderSettings:
    """A render of 16 x 12 pixels (not square, so a transposed image would show)."""
    settings = mlt.RenderSettings(
        width=16,
        height=12,
        algorithm=algorithm,
        samples_per_pixel=4,
        mutations_per_pixel=4,
        chains=64,
        bootstrap_samples=1024,
    )
    for name, value in fields.items():
        setattr(settings, name, value)
    return settings


# ERPT spreads each camera sample's energy over nearby pixels by its chains: unbiased,
# but not exact per pixel.
@pytest.mark.parametrize("algorithm", [a for a in ALGORITHMS if a != "erpt"])
def test_emitter_filling_the_view_renders_its_emission(algorithm: str) -> None:
    # Every camera ray hits the emitter and nothing else is visible from it: each pixel is
    # exactly the emitted radiance, per channel.
    emission = (0.25, 0.5, 2.0)
    positions, indices = quad()
    scene = mlt.Scene.from_arrays(
        positions, indices, [mlt.Material.diffuse((0.5, 0.5, 0.5), emission=emission)]
    )
    image, stats = mlt.render(scene, CAMERA, small(algorithm))
    assert image.shape == (12, 16, 3)
    assert image.dtype == np.float32
    assert image.flags.c_contiguous
    np.testing.assert_allclose(image, np.broadcast_to(emission, image.shape), rtol=1e-5)
    assert stats.stop == "completed"
    assert stats.rays > 0


def test_constant_environment_seen_everywhere() -> None:
    # No triangles: every ray leaves the scene and sees the sky.
    radiance = (0.2, 0.4, 0.6)
    scene = mlt.Scene.from_arrays(
        np.zeros((0, 3), np.float32),
        np.zeros((0, 3), np.uint32),
        materials=[],
        environment=mlt.Environment.constant(radiance),
    )
    image, _ = mlt.render(scene, CAMERA, small("path"))
    np.testing.assert_allclose(image, np.broadcast_to(radiance, image.shape), rtol=1e-5)


@pytest.mark.parametrize(
    "light",
    [
        mlt.PunctualLight.directional((0.0, 0.0, 1.0), (1.0, 2.0, 3.0)),
        mlt.Sun(direction=(0.0, 0.0, -1.0), irradiance=(1.0, 2.0, 3.0), angular_radius_degrees=0.0),
    ],
    ids=["directional", "delta-sun"],
)
def test_diffuse_plane_under_a_delta_light(light: mlt.PunctualLight | mlt.Sun) -> None:
    # A Lambertian plane of albedo rho facing a delta light of irradiance E along its
    # normal reflects rho E / pi towards the camera; with one bounce and a delta light
    # there is nothing to sample, so every pixel is exact.
    albedo = 0.5
    positions, indices = quad()
    if isinstance(light, mlt.Sun):
        scene = mlt.Scene.from_arrays(positions, indices, [mlt.Material.diffuse((albedo,) * 3)], sun=light)
    else:
        scene = mlt.Scene.from_arrays(
            positions, indices, [mlt.Material.diffuse((albedo,) * 3)], lights=[light]
        )
    image, _ = mlt.render(scene, CAMERA, small("path", max_depth=1))
    expected = np.array([1.0, 2.0, 3.0]) * albedo / math.pi
    np.testing.assert_allclose(image, np.broadcast_to(expected, image.shape), rtol=1e-5)


def test_emission_texture_multiplies_emission() -> None:
    # A 1 x 1 float texture scales the emission per channel.
    positions, indices = quad()
    texcoords = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    texel = np.array([[[0.5, 0.25, 1.0]]], np.float32)
    material = mlt.Material.diffuse((0.5, 0.5, 0.5), emission=(2.0, 2.0, 2.0))
    material.emission_texture = mlt.TextureRef(0)
    scene = mlt.Scene.from_arrays(
        positions, indices, [material], texcoords=texcoords, textures=[mlt.Texture(texel, filter="nearest")]
    )
    image, _ = mlt.render(scene, CAMERA, small("path"))
    np.testing.assert_allclose(image, np.broadcast_to((1.0, 0.5, 2.0), image.shape), rtol=1e-5)


def test_texture_reads_the_texture_coordinate_set_it_names() -> None:
    # Texel 0 is black, texel 1 white; set 0 lies inside texel 0, set 1 inside texel 1.
    positions, indices = quad()
    texcoords = np.array([[0.1, 0.5], [0.3, 0.5], [0.3, 0.6], [0.1, 0.6]], np.float32)
    texcoords1 = texcoords + np.array([0.5, 0.0], np.float32)
    texture = mlt.Texture(np.array([[[0.0], [1.0]]], np.float32), filter="nearest", wrap_u="clamp_to_edge")
    for texcoord, expected in [(0, 0.0), (1, 1.0)]:
        material = mlt.Material.diffuse((0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0))
        material.emission_texture = mlt.TextureRef(0, texcoord=texcoord)
        scene = mlt.Scene.from_arrays(
            positions, indices, [material], texcoords=texcoords, texcoords1=texcoords1, textures=[texture]
        )
        image, _ = mlt.render(scene, CAMERA, small("path"))
        np.testing.assert_allclose(image, np.full(image.shape, expected), atol=1e-5)
    material.emission_texture = mlt.TextureRef(0, texcoord=1)
    with pytest.raises(mlt.InvalidArgumentError, match="texcoords1"):
        mlt.Scene.from_arrays(positions, indices, [material], texcoords=texcoords, textures=[texture])


def test_material_ids_pick_each_triangles_material() -> None:
    # Two emitters side by side: the left half of the image sees one, the right the other.
    positions = np.array(
        [[-10, -10, 0], [0, -10, 0], [0, 10, 0], [-10, 10, 0], [10, -10, 0], [10, 10, 0]], np.float32
    )
    indices = np.array([[0, 2, 1], [0, 3, 2], [1, 5, 4], [1, 2, 5]], np.uint32)
    materials: list[mlt.Material | dict[str, object]] = [
        {"kind": "diffuse", "color": (0.5, 0.5, 0.5), "emission": (1.0, 0.0, 0.0)},
        mlt.Material.diffuse((0.5, 0.5, 0.5), emission=(0.0, 0.0, 1.0)),
    ]
    scene = mlt.Scene.from_arrays(positions, indices, materials, material_ids=[0, 0, 1, 1])
    image, _ = mlt.render(scene, CAMERA, small("path"))
    # Image right is cross(forward, up) = -x here: the material-1 half (+x) is on the left.
    np.testing.assert_allclose(image[:, :7], np.broadcast_to((0.0, 0.0, 1.0), (12, 7, 3)))
    np.testing.assert_allclose(image[:, 9:], np.broadcast_to((1.0, 0.0, 0.0), (12, 7, 3)))


@pytest.fixture(scope="module")
def cornell_box() -> tuple[mlt.Scene, mlt.Camera | None]:
    return mlt.Scene.load(SCENES / "cornell-box.obj")


def test_cornell_box_loads_with_its_camera(cornell_box: tuple[mlt.Scene, mlt.Camera | None]) -> None:
    scene, camera = cornell_box
    # tests/scenes/cornell-box.camera.json
    assert camera is not None
    assert camera.eye == (278.0, 273.0, -800.0)
    assert camera.target == (278.0, 273.0, -799.0)
    assert camera.fov_y_deg == pytest.approx(39.307648)
    assert scene.info.triangle_count > 10
    assert scene.info.emitter_count >= 2


@pytest.mark.parametrize("algorithm", ["path", "mmlt"])
def test_cornell_box_renders(cornell_box: tuple[mlt.Scene, mlt.Camera | None], algorithm: str) -> None:
    scene, camera = cornell_box
    assert camera is not None
    image, stats = mlt.render(scene, camera, small(algorithm, width=24, height=24, samples_per_pixel=8))
    assert image.shape == (24, 24, 3)
    assert np.isfinite(image).all()
    assert (image >= 0).all()
    # Lit walls: a bright image whose left (red wall) is redder than its right (green).
    assert image.mean() > 0.05
    left, right = image[6:18, :4].mean(axis=(0, 1)), image[6:18, -4:].mean(axis=(0, 1))
    assert left[0] > left[1] and right[1] > right[0]
    assert stats.stop == "completed"


@pytest.mark.parametrize("quality", ["fast", "medium", "high"])
def test_every_build_quality_renders_the_same_image(
    cornell_box: tuple[mlt.Scene, mlt.Camera | None], quality: str
) -> None:
    # The qualities build different trees over the same triangles: the same hits up to
    # rounding, so the same samples give the same image but for a rare ray.
    default, camera = cornell_box
    assert camera is not None
    scene, _ = mlt.Scene.load(SCENES / "cornell-box.obj", build_quality=quality)
    info = scene.info
    assert (info.build_quality, default.info.build_quality) == (quality, "high")
    assert info.accel_memory_bytes > 0 and info.accel_build_seconds >= 0.0
    settings = small("path", width=24, height=24, samples_per_pixel=8)
    image, _ = mlt.render(scene, camera, settings)
    reference, _ = mlt.render(default, camera, settings)
    assert np.mean(np.abs(image - reference)) <= 1e-3 * reference.mean()


def test_an_unknown_build_quality_is_refused() -> None:
    positions, indices = quad()
    with pytest.raises(ValueError, match="build_quality"):
        mlt.Scene.from_arrays(positions, indices, build_quality="best")


def test_framing_camera_sees_the_whole_scene() -> None:
    positions, indices = quad(half_size=1.0)
    scene = mlt.Scene.from_arrays(positions, indices)
    camera = scene.framing_camera()
    # From the front (+z) and a little above, looking at the centre.
    assert camera.target == pytest.approx((0.0, 0.0, 0.0))
    assert camera.eye[2] > 0 and camera.eye[1] > 0
    assert camera.fov_y_deg == pytest.approx(40.0)


@pytest.mark.parametrize("algorithm", ["path", "mmlt", "erpt"])
def test_same_seed_same_image_any_thread_count(
    cornell_box: tuple[mlt.Scene, mlt.Camera | None], algorithm: str
) -> None:
    scene, camera = cornell_box
    assert camera is not None
    settings = small(algorithm, width=20, height=20, seed=7)
    images = []
    for threads in (1, 2, 1):
        settings.threads = threads
        image, _ = mlt.render(scene, camera, settings)
        images.append(image)
    np.testing.assert_array_equal(images[0], images[1])
    np.testing.assert_array_equal(images[0], images[2])
    settings.seed = 8
    other, _ = mlt.render(scene, camera, settings)
    assert not np.array_equal(images[0], other), "a different seed should change the noise"


def test_render_with_unfiltered_returns_both_images(cornell_box: tuple[mlt.Scene, mlt.Camera | None]) -> None:
    scene, camera = cornell_box
    assert camera is not None
    settings = small("mmlt", width=20, height=20, filter_buffers=4)
    image, unfiltered, stats = mlt.render_with_unfiltered(scene, camera, settings)
    assert image.shape == unfiltered.shape == (20, 20, 3)
    assert not np.array_equal(image, unfiltered)
    # The filter moves energy between pixels, keeping the total.
    np.testing.assert_allclose(image.sum(axis=(0, 1)), unfiltered.sum(axis=(0, 1)), rtol=1e-3)
    assert stats.filter.mean_neighbours > 1.0
    plain, _ = mlt.render(scene, camera, settings)
    np.testing.assert_array_equal(plain, image)


def test_stats_report_the_work(cornell_box: tuple[mlt.Scene, mlt.Camera | None]) -> None:
    scene, camera = cornell_box
    assert camera is not None
    settings = small("path-space-mlt", width=16, height=16)
    _, stats = mlt.render(scene, camera, settings)
    assert stats.mutations >= 16 * 16 * 4
    assert 0 < stats.accepted_mutations <= stats.mutations
    assert stats.normalization.value > 0 and stats.normalization.samples >= 1024
    assert sum(stats.mutation_counts.proposed) == stats.mutations
    assert len(stats.mutation_weights) == 4
    assert stats.threads >= 1 and stats.seconds > 0
    assert "RenderStats(" in repr(stats)
