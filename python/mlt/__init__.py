"""mlt: an embeddable Metropolis light transport renderer.

Build a :class:`Scene` from numpy arrays (:meth:`Scene.from_arrays`) or load one from an
OBJ or glTF file (:meth:`Scene.load`), then :func:`render` it with a :class:`Camera` and
:class:`RenderSettings` into a float32 numpy array of shape (height, width, 3), linear
RGB::

    import mlt

    scene, camera = mlt.Scene.load("tests/scenes/cornell-box.obj")
    image, stats = mlt.render(scene, camera, mlt.RenderSettings(width=128, height=128))

The GIL is released while rendering. ``progress=`` takes a callable of the fraction done
(return False to stop), ``cancel=`` a :class:`CancelToken` another thread may cancel; Ctrl-C
stops a render too.

A frame too big for one machine splits into jobs that merge into the same bits:
:func:`plan` once, :func:`render_job` for job k of N on any process holding the same scene,
:func:`merge` of the :class:`PartialRender` results; :func:`combine` adds a few partial
results into one, so a cluster can merge in a tree. Plans and partial results pickle (as
their checksummed bytes); :mod:`mlt.dask` runs the steps on a Dask cluster.

Errors from mlt are :class:`MltError`; invalid input is
:class:`InvalidArgumentError`, also a ``ValueError``.
"""

from __future__ import annotations

from ._errors import InvalidArgumentError, LoadError, MltError, UnsupportedError
from ._mlt import (
    EMBREE_AVAILABLE,
    CancelToken,
    FilterStats,
    MutationCounts,
    NormalizationStats,
    PartialRender,
    RenderPlan,
    RenderStats,
    Scene,
    SceneInfo,
    __version__,
    combine,
    load_environment,
    merge,
    plan,
    render,
    render_job,
    render_with_unfiltered,
)
from ._types import (
    Algorithm,
    Camera,
    Environment,
    Material,
    PunctualLight,
    RenderSettings,
    Sun,
    Texture,
    TextureRef,
)

__all__ = [
    "EMBREE_AVAILABLE",
    "Algorithm",
    "Camera",
    "CancelToken",
    "Environment",
    "FilterStats",
    "InvalidArgumentError",
    "LoadError",
    "Material",
    "MltError",
    "MutationCounts",
    "NormalizationStats",
    "PartialRender",
    "PunctualLight",
    "RenderPlan",
    "RenderSettings",
    "RenderStats",
    "Scene",
    "SceneInfo",
    "Sun",
    "Texture",
    "TextureRef",
    "UnsupportedError",
    "__version__",
    "load_environment",
    "merge",
    "plan",
    "render",
    "render_job",
    "combine",
    "render_with_unfiltered",
]
