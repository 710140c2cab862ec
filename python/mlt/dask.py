"""Rendering on a Dask cluster: one frame split into jobs that merge into the bits one
machine renders, or a camera sequence as one task per frame.

Needs ``pip install "dask[distributed]"``; the same code runs on a
``distributed.LocalCluster`` and on a real cluster::

    from distributed import Client, LocalCluster
    import mlt, mlt.dask

    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        scene = mlt.dask.SceneFile("/shared/cornell-box.obj")
        image, stats = mlt.dask.render_frame(client, scene, camera, settings, jobs=8)

A :class:`Scene` holds its acceleration structure and does not travel: tasks carry a
*scene source* instead, a picklable callable that builds the scene on the worker
(:class:`SceneFile` for a file every worker can read, :class:`SceneArrays` for arrays sent
with the tasks, or any other picklable callable returning a :class:`Scene`). Each worker
process builds a source once and keeps the scenes of its last few sources.

The plan runs as a task (a Metropolis plan runs the bootstrap), each job as a task given the
plan, then the partial results are added in a tree of combine tasks, ``fan_in`` at a time
(so no worker reads all N), and a merge task makes the image; plans and partial results
move between workers as their checksummed bytes. Only the image and the stats come back to
the client, which needs no scene.
"""

from __future__ import annotations

import collections
import dataclasses
import os
import threading
import uuid
from typing import TYPE_CHECKING, Any, Callable, Iterable, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _mlt
from ._types import Camera, Environment, PunctualLight, RenderSettings, Sun

if TYPE_CHECKING:
    from distributed import Client, Future

__all__ = ["SceneArrays", "SceneFile", "SceneSource", "render_frame", "render_sequence", "submit_frame", "submit_sequence"]

#: A picklable callable that builds the scene on a worker.
SceneSource = Callable[[], _mlt.Scene]

_Image = np.ndarray[Tuple[int, int, int], np.dtype[np.float32]]


@dataclasses.dataclass(frozen=True)
class SceneFile:
    """A scene file loaded on each worker with :meth:`Scene.load`'s options. ``path`` is
    the path as the workers see it (a shared or replicated file system)."""

    path: Union[str, os.PathLike[str]]
    environment: Optional[Environment] = None
    sun: Optional[Sun] = None
    lights: Optional[Sequence[PunctualLight]] = None
    energy_compensation: bool = False
    abbe_number: Optional[float] = None
    backend: str = "bvh"
    build_quality: str = "high"
    variant: Optional[str] = None

    def __call__(self) -> _mlt.Scene:
        scene, _camera = _mlt.Scene.load(
            self.path,
            environment=self.environment,
            sun=self.sun,
            lights=self.lights,
            energy_compensation=self.energy_compensation,
            abbe_number=self.abbe_number,
            backend=self.backend,  # type: ignore[arg-type]
            build_quality=self.build_quality,  # type: ignore[arg-type]
            variant=self.variant,
        )
        return scene


@dataclasses.dataclass(frozen=True)
class SceneArrays:
    """:meth:`Scene.from_arrays`' arguments, sent to the workers with the tasks:
    ``SceneArrays(positions, indices, materials, normals=..., environment=...)``."""

    positions: npt.ArrayLike
    indices: npt.ArrayLike
    materials: Optional[Sequence[Any]] = None
    material_ids: Optional[npt.ArrayLike] = None
    #: The keyword arguments of :meth:`Scene.from_arrays` (normals, texcoords, tangents,
    #: colors, textures, environment, sun, lights, backend, build_quality).
    options: Mapping[str, Any] = dataclasses.field(default_factory=dict)

    def __init__(
        self,
        positions: npt.ArrayLike,
        indices: npt.ArrayLike,
        materials: Optional[Sequence[Any]] = None,
        material_ids: Optional[npt.ArrayLike] = None,
        **options: Any,
    ) -> None:
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "indices", indices)
        object.__setattr__(self, "materials", materials)
        object.__setattr__(self, "material_ids", material_ids)
        object.__setattr__(self, "options", dict(options))

    def __call__(self) -> _mlt.Scene:
        return _mlt.Scene.from_arrays(self.positions, self.indices, self.materials, self.material_ids, **self.options)


# The scenes this worker process built, by source token, most recent last.
_SCENES_KEPT = 2
_scenes: collections.OrderedDict[str, _mlt.Scene] = collections.OrderedDict()
_scenes_lock = threading.Lock()


def _scene(source: SceneSource) -> _mlt.Scene:
    """The scene of `source`, built once per worker process (tasks of one frame or one
    sequence share it)."""
    from dask.base import tokenize

    token = tokenize(source)
    with _scenes_lock:
        scene = _scenes.get(token)
        if scene is None:
            scene = source()
            _scenes[token] = scene
            while len(_scenes) > _SCENES_KEPT:
                _scenes.popitem(last=False)
        _scenes.move_to_end(token)
        return scene


def _plan_task(source: SceneSource, camera: Camera, settings: RenderSettings) -> _mlt.RenderPlan:
    return _mlt.plan(_scene(source), camera, settings)


# Partial results travel between tasks as bytes: the task that reads one decodes it once,
# where a PartialRender would be decoded when unpickled and copied again when combined.
def _job_task(source: SceneSource, plan: _mlt.RenderPlan, job: int, jobs: int, threads: int) -> bytes:
    return _mlt.render_job(_scene(source), plan, job, jobs, threads=threads).to_bytes()


def _combine_task(plan: _mlt.RenderPlan, *partials: bytes) -> bytes:
    return _mlt.combine(plan, partials).to_bytes()


def _merge_task(plan: _mlt.RenderPlan, *partials: bytes) -> Tuple[_Image, _mlt.RenderStats]:
    return _mlt.merge(plan, partials)


def _frame_task(source: SceneSource, camera: Camera, settings: RenderSettings) -> Tuple[_Image, _mlt.RenderStats]:
    return _mlt.render(_scene(source), camera, settings)


def submit_frame(
    client: Client,
    scene: SceneSource,
    camera: Camera,
    settings: Optional[RenderSettings] = None,
    *,
    jobs: int,
    threads: int = 0,
    workers: Optional[Sequence[str]] = None,
    fan_in: int = 8,
) -> Future:
    """Submits a frame split into `jobs` jobs: a plan task, `jobs` job tasks, combine tasks
    and a merge task. Returns the merge's future, of ``(image, stats)``: the image
    :func:`mlt.render` returns for `settings`, bit for bit, whatever `jobs` and wherever the
    jobs ran.

    `threads` is each job's thread count (0: every core of its worker's machine; give 1
    when a machine runs as many single-threaded workers as it has cores); the plan uses
    ``settings.threads``. `workers` (addresses), if given, pins job k to worker
    ``workers[k % len(workers)]``; else the scheduler places every task.

    `fan_in` (at least 2) is the most partial results one task reads: while there are more,
    they are added `fan_in` at a time by combine tasks (:func:`mlt.combine`), level after
    level, and the merge reads the last `fan_in` or fewer. Each task then holds at most
    `fan_in` partial results' bytes, and the levels' tasks run in parallel.
    """
    if fan_in < 2:
        raise ValueError(f"fan_in is {fan_in}: a combine reads at least 2 partial results")
    if settings is None:
        settings = RenderSettings()
    name = uuid.uuid4().hex
    plan = client.submit(_plan_task, scene, camera, settings, key=f"mlt-plan-{name}")
    partials = [
        client.submit(
            _job_task,
            scene,
            plan,
            job,
            jobs,
            threads,
            key=f"mlt-job-{job}-of-{jobs}-{name}",
            workers=None if not workers else [workers[job % len(workers)]],
        )
        for job in range(jobs)
    ]
    level = 0
    while len(partials) > fan_in:
        groups = [partials[start : start + fan_in] for start in range(0, len(partials), fan_in)]
        partials = [
            group[0]
            if len(group) == 1
            else client.submit(_combine_task, plan, *group, key=f"mlt-combine-{level}-{index}-{name}")
            for index, group in enumerate(groups)
        ]
        level += 1
    return client.submit(_merge_task, plan, *partials, key=f"mlt-merge-{name}")


def render_frame(
    client: Client,
    scene: SceneSource,
    camera: Camera,
    settings: Optional[RenderSettings] = None,
    *,
    jobs: int,
    threads: int = 0,
    workers: Optional[Sequence[str]] = None,
    fan_in: int = 8,
) -> Tuple[_Image, _mlt.RenderStats]:
    """Renders a frame as `jobs` jobs on the cluster (see :func:`submit_frame`) and returns
    ``(image, stats)``."""
    future = submit_frame(client, scene, camera, settings, jobs=jobs, threads=threads, workers=workers, fan_in=fan_in)
    result: Tuple[_Image, _mlt.RenderStats] = future.result()
    return result


def submit_sequence(
    client: Client,
    scene: SceneSource,
    cameras: Iterable[Camera],
    settings: Optional[RenderSettings] = None,
) -> list[Future]:
    """Submits one task per camera, each rendering the frame with :func:`mlt.render` and
    `settings` (``settings.threads`` per task). Returns the futures of ``(image, stats)``,
    in the cameras' order."""
    if settings is None:
        settings = RenderSettings()
    name = uuid.uuid4().hex
    return [
        client.submit(_frame_task, scene, camera, settings, key=f"mlt-frame-{index}-{name}")
        for index, camera in enumerate(cameras)
    ]


def render_sequence(
    client: Client,
    scene: SceneSource,
    cameras: Iterable[Camera],
    settings: Optional[RenderSettings] = None,
) -> list[Tuple[_Image, _mlt.RenderStats]]:
    """Renders one frame per camera, one task each (see :func:`submit_sequence`), and
    returns their ``(image, stats)`` in the cameras' order."""
    futures = submit_sequence(client, scene, cameras, settings)
    results: list[Tuple[_Image, _mlt.RenderStats]] = client.gather(futures)
    return results
