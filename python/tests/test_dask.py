"""mlt.dask on a LocalCluster of two worker processes: a frame split into jobs merges into
the bits of one render, and a camera sequence renders one task per frame."""

from __future__ import annotations

import dataclasses
from typing import Iterator

import numpy as np
import pytest
from conftest import CAMERA, SCENES, quad

import mlt
import mlt.dask

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def client() -> Iterator[distributed.Client]:
    # Worker processes, as on a cluster: each builds its own scene and receives the plan
    # and the partial results as bytes.
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster, distributed.Client(cluster) as client:
        yield client


CORNELL_BOX = mlt.dask.SceneFile(str(SCENES / "cornell-box.obj"))


def cornell_camera() -> mlt.Camera:
    _, camera = mlt.Scene.load(SCENES / "cornell-box.obj")
    assert camera is not None
    return camera


@pytest.mark.parametrize(("algorithm", "jobs"), [("mmlt", 3), ("path-space-mlt", 2), ("bdpt", 4)])
def test_a_frame_split_over_the_cluster_is_the_single_render(
    client: distributed.Client, algorithm: str, jobs: int
) -> None:
    camera = cornell_camera()
    settings = mlt.RenderSettings(
        width=32, height=24, algorithm=algorithm, samples_per_pixel=2, mutations_per_pixel=2, chains=64, threads=1
    )
    # The jobs alternate between the two worker processes (the scheduler would keep work
    # this small on one).
    workers = sorted(client.scheduler_info()["workers"])
    assert len(workers) == 2
    image, stats = mlt.dask.render_frame(
        client, CORNELL_BOX, camera, settings, jobs=jobs, threads=1, workers=workers
    )
    wanted, wanted_stats = mlt.render(CORNELL_BOX(), camera, settings)
    assert np.array_equal(image.view(np.uint32), wanted.view(np.uint32))
    assert stats.samples == wanted_stats.samples
    assert stats.mutations == wanted_stats.mutations
    assert stats.stop == "completed"
    # Both worker processes built the scene: the jobs ran on both.
    built = client.run(lambda: len(mlt.dask._scenes))
    assert sorted(built) == workers and all(count > 0 for count in built.values())


def test_a_tree_of_combines_merges_into_the_same_bits(client: distributed.Client) -> None:
    # 9 jobs, 2 at a time: 9 partial results, then 5, 3 and 2 after three levels of
    # combines, and the merge.
    settings = mlt.RenderSettings(
        width=24, height=20, algorithm="mmlt", mutations_per_pixel=2, chains=24, bootstrap_samples=2048, threads=1
    )
    image, stats = mlt.dask.render_frame(client, CORNELL_BOX, cornell_camera(), settings, jobs=9, threads=1, fan_in=2)
    wanted, wanted_stats = mlt.render(CORNELL_BOX(), cornell_camera(), settings)
    assert np.array_equal(image.view(np.uint32), wanted.view(np.uint32))
    assert stats.mutations == wanted_stats.mutations
    with pytest.raises(ValueError, match="fan_in is 1"):
        mlt.dask.submit_frame(client, CORNELL_BOX, cornell_camera(), settings, jobs=2, fan_in=1)


def test_a_scene_from_arrays_travels_with_the_tasks(client: distributed.Client) -> None:
    positions, indices = quad()
    source = mlt.dask.SceneArrays(
        positions,
        indices,
        [mlt.Material.diffuse((0.5, 0.5, 0.5))],
        lights=[mlt.PunctualLight.point((0.0, 0.0, -2.0), (4.0, 4.0, 4.0))],
    )
    settings = mlt.RenderSettings(width=20, height=16, algorithm="pssmlt", mutations_per_pixel=4, chains=32, threads=1)
    image, _ = mlt.dask.render_frame(client, source, CAMERA, settings, jobs=5, threads=1)
    wanted, _ = mlt.render(source(), CAMERA, settings)
    assert np.array_equal(image, wanted)
    assert image.sum() > 0


def test_a_sequence_renders_one_task_per_frame(client: distributed.Client) -> None:
    camera = cornell_camera()
    cameras = [dataclasses.replace(camera, eye=(278.0 + 40.0 * i, 273.0, -800.0)) for i in range(3)]
    settings = mlt.RenderSettings(width=24, height=24, algorithm="path", samples_per_pixel=2, threads=1)
    frames = mlt.dask.render_sequence(client, CORNELL_BOX, cameras, settings)
    scene = CORNELL_BOX()
    assert len(frames) == 3
    for (image, stats), frame_camera in zip(frames, cameras):
        wanted, _ = mlt.render(scene, frame_camera, settings)
        assert np.array_equal(image, wanted)
        assert stats.stop == "completed"
    # The frames differ: each task rendered its own camera.
    assert not np.array_equal(frames[0][0], frames[2][0])
