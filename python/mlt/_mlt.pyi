"""Typed stubs of the Rust extension ``mlt._mlt`` (python/src/). Keep in step with it:
``tests/test_stubs.py`` runs mypy's stubtest over the package."""

import os
from typing import Callable, Iterable, Literal, Mapping, Optional, Tuple, Union, final

import numpy as np
import numpy.typing as npt

from ._types import Camera, Environment, Material, PunctualLight, RenderSettings, Sun, Texture

__all__ = [
    "Scene",
    "SceneInfo",
    "CancelToken",
    "RenderStats",
    "NormalizationStats",
    "MutationCounts",
    "FilterStats",
    "render",
    "render_with_unfiltered",
    "RenderPlan",
    "PartialRender",
    "plan",
    "render_job",
    "combine",
    "merge",
    "load_environment",
    "_defaults_mismatches",
    "_settings_declarations",
    "_material_declarations",
    "__version__",
    "EMBREE_AVAILABLE",
]

__version__: str
EMBREE_AVAILABLE: bool

_Path = Union[str, os.PathLike[str]]
_Image = np.ndarray[Tuple[int, int, int], np.dtype[np.float32]]
_Progress = Callable[[float], Optional[bool]]
_Vec3 = Tuple[float, float, float]
_Backend = Literal["bvh", "embree"]
_BuildQuality = Literal["fast", "medium", "high"]

@final
class SceneInfo:
    @property
    def triangle_count(self) -> int: ...
    @property
    def degenerate_triangle_count(self) -> int: ...
    @property
    def emitter_count(self) -> int: ...
    @property
    def bounds_min(self) -> _Vec3: ...
    @property
    def bounds_max(self) -> _Vec3: ...
    @property
    def build_quality(self) -> _BuildQuality: ...
    @property
    def accel_memory_bytes(self) -> int: ...
    @property
    def accel_build_seconds(self) -> float: ...

@final
class Scene:
    @staticmethod
    def from_arrays(
        positions: npt.ArrayLike,
        indices: npt.ArrayLike,
        materials: Optional[Iterable[Union[Material, Mapping[str, object]]]] = None,
        material_ids: Optional[npt.ArrayLike] = None,
        *,
        normals: Optional[npt.ArrayLike] = None,
        texcoords: Optional[npt.ArrayLike] = None,
        texcoords1: Optional[npt.ArrayLike] = None,
        tangents: Optional[npt.ArrayLike] = None,
        colors: Optional[npt.ArrayLike] = None,
        textures: Optional[Iterable[Texture]] = None,
        environment: Optional[Environment] = None,
        sun: Optional[Sun] = None,
        lights: Optional[Iterable[PunctualLight]] = None,
        backend: _Backend = "bvh",
        build_quality: _BuildQuality = "high",
    ) -> Scene: ...
    @staticmethod
    def load(
        path: _Path,
        *,
        environment: Optional[Environment] = None,
        sun: Optional[Sun] = None,
        lights: Optional[Iterable[PunctualLight]] = None,
        energy_compensation: bool = False,
        abbe_number: Optional[float] = None,
        backend: _Backend = "bvh",
        build_quality: _BuildQuality = "high",
        variant: Optional[str] = None,
    ) -> Tuple[Scene, Optional[Camera]]: ...
    @property
    def info(self) -> SceneInfo: ...
    def framing_camera(self) -> Camera: ...

@final
class CancelToken:
    def __init__(self) -> None: ...
    def cancel(self) -> None: ...
    def reset(self) -> None: ...
    @property
    def cancelled(self) -> bool: ...

@final
class NormalizationStats:
    @property
    def value(self) -> float: ...
    @property
    def samples(self) -> int: ...
    @property
    def relative_error(self) -> float: ...
    @property
    def largest_share(self) -> float: ...

@final
class MutationCounts:
    @property
    def proposed(self) -> Tuple[int, int, int, int]: ...
    @property
    def accepted(self) -> Tuple[int, int, int, int]: ...

@final
class FilterStats:
    @property
    def changed_fraction(self) -> float: ...
    @property
    def mean_neighbours(self) -> float: ...

@final
class RenderStats:
    @property
    def stop(self) -> Literal["completed", "cancelled", "time_limit_reached"]: ...
    @property
    def samples(self) -> int: ...
    @property
    def mutations(self) -> int: ...
    @property
    def rays(self) -> int: ...
    @property
    def invalid_samples(self) -> int: ...
    @property
    def seconds(self) -> float: ...
    @property
    def threads(self) -> int: ...
    @property
    def accepted_mutations(self) -> int: ...
    @property
    def normalization(self) -> NormalizationStats: ...
    @property
    def mutation_counts(self) -> MutationCounts: ...
    @property
    def mutation_weights(self) -> Tuple[float, float, float, float]: ...
    @property
    def filter(self) -> FilterStats: ...
    @staticmethod
    def _from_state(
        state: Tuple[
            str,
            int,
            int,
            int,
            int,
            float,
            int,
            int,
            Tuple[float, int, float, float],
            Tuple[Tuple[int, int, int, int], Tuple[int, int, int, int]],
            Tuple[float, float, float, float],
            Tuple[float, float],
        ],
    ) -> RenderStats: ...
    def __reduce__(self) -> Tuple[Callable[..., RenderStats], Tuple[object, ...]]: ...

@final
class RenderPlan:
    @staticmethod
    def from_bytes(data: bytes) -> RenderPlan: ...
    def to_bytes(self) -> bytes: ...
    @property
    def id(self) -> int: ...
    @property
    def settings(self) -> RenderSettings: ...
    @property
    def camera(self) -> Camera: ...
    def __reduce__(self) -> Tuple[Callable[[bytes], RenderPlan], Tuple[bytes]]: ...
    def __eq__(self, value: object, /) -> bool: ...

@final
class PartialRender:
    @staticmethod
    def from_bytes(data: bytes) -> PartialRender: ...
    def to_bytes(self) -> bytes: ...
    @property
    def job(self) -> int: ...
    @property
    def held_jobs(self) -> list[int]: ...
    @property
    def jobs(self) -> int: ...
    @property
    def plan_id(self) -> int: ...
    @property
    def stats(self) -> RenderStats: ...
    def __reduce__(self) -> Tuple[Callable[[bytes], PartialRender], Tuple[bytes]]: ...

def render(
    scene: Scene,
    camera: Camera,
    settings: Optional[RenderSettings] = None,
    *,
    progress: Optional[_Progress] = None,
    cancel: Optional[CancelToken] = None,
) -> Tuple[_Image, RenderStats]: ...
def render_with_unfiltered(
    scene: Scene,
    camera: Camera,
    settings: Optional[RenderSettings] = None,
    *,
    progress: Optional[_Progress] = None,
    cancel: Optional[CancelToken] = None,
) -> Tuple[_Image, _Image, RenderStats]: ...
def plan(scene: Scene, camera: Camera, settings: Optional[RenderSettings] = None) -> RenderPlan: ...
def render_job(
    scene: Scene,
    plan: RenderPlan,
    job: int,
    jobs: int,
    *,
    threads: int = 0,
    progress: Optional[_Progress] = None,
    cancel: Optional[CancelToken] = None,
) -> PartialRender: ...
def combine(
    plan: RenderPlan, partials: Iterable[Union[PartialRender, bytes]]
) -> PartialRender: ...
def merge(
    plan: RenderPlan, partials: Iterable[Union[PartialRender, bytes]]
) -> Tuple[_Image, RenderStats]: ...
def load_environment(path: _Path) -> _Image: ...
def _defaults_mismatches(
    settings: RenderSettings, camera: Camera, material: Material
) -> list[Tuple[str, str, str]]: ...
def _settings_declarations() -> list[Tuple[str, object, Optional[object], Optional[str]]]: ...
def _material_declarations() -> list[Tuple[str, object, Optional[object], Optional[str]]]: ...
