"""Scenes the tests share."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

import mlt

#: The repository's root (python/tests/ is two levels below it).
REPOSITORY = pathlib.Path(__file__).resolve().parents[2]
SCENES = REPOSITORY / "tests" / "scenes"


def quad(half_size: float = 10.0, z: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """A square in the plane z, facing -z (towards the tests' cameras), as two triangles."""
    s = half_size
    positions = np.array([[-s, -s, z], [s, -s, z], [s, s, z], [-s, s, z]], dtype=np.float32)
    indices = np.array([[0, 2, 1], [0, 3, 2]], dtype=np.uint32)
    return positions, indices


#: Looks along +z at the quad from 3 units away; a quad of half-size 10 fills its view.
CAMERA = mlt.Camera(eye=(0.0, 0.0, -3.0), target=(0.0, 0.0, 0.0))


@pytest.fixture
def camera() -> mlt.Camera:
    return CAMERA


@pytest.fixture
def lit_plane() -> mlt.Scene:
    """A white diffuse plane filling the view under a directional light: enough work to
    render for as long as a time limit allows."""
    positions, indices = quad()
    return mlt.Scene.from_arrays(
        positions,
        indices,
        [mlt.Material.diffuse((0.5, 0.5, 0.5))],
        lights=[mlt.PunctualLight.directional((0.0, 0.0, 1.0), (1.0, 1.0, 1.0))],
    )
