"""A render split into jobs: plan, render_job, merge give render's bits; bad input raises."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from conftest import SCENES

import mlt

ALGORITHMS = [a.value for a in mlt.Algorithm]


@pytest.fixture(scope="module")
def cornell_box() -> tuple[mlt.Scene, mlt.Camera]:
    scene, camera = mlt.Scene.load(SCENES / "cornell-box.obj")
    assert camera is not None
    return scene, camera


def settings(algorithm: str, **fields: object) -> mlt.RenderSettings:
    """24 x 20 pixels of the Cornell box: light bounces, so every job's share differs."""
    settings = mlt.RenderSettings(
        width=24,
        height=20,
        algorithm=algorithm,
        samples_per_pixel=2,
        mutations_per_pixel=2,
        chains=48,
        bootstrap_samples=2048,
        threads=2,
    )
    for name, value in fields.items():
        setattr(settings, name, value)
    return settings


@pytest.mark.parametrize("algorithm", ALGORITHMS)
def test_merged_jobs_are_the_single_render_bit_for_bit(
    cornell_box: tuple[mlt.Scene, mlt.Camera], algorithm: str
) -> None:
    scene, camera = cornell_box
    wanted = settings(algorithm, filter_buffers=4 if algorithm == "pssmlt" else 0)
    image, stats = mlt.render(scene, camera, wanted)
    plan = mlt.plan(scene, camera, wanted)
    jobs = 3
    # Each job on one thread, travelling as pickles (as to another process), merged out of
    # order, some as objects and some as bytes.
    partials = [pickle.loads(pickle.dumps(mlt.render_job(scene, plan, k, jobs, threads=1))) for k in range(jobs)]
    assert [(p.job, p.jobs, p.plan_id) for p in partials] == [(k, jobs, plan.id) for k in range(jobs)]
    merged, merged_stats = mlt.merge(plan, [partials[2], partials[0].to_bytes(), partials[1]])
    assert merged.shape == image.shape and merged.dtype == image.dtype
    assert np.array_equal(merged.view(np.uint32), image.view(np.uint32))
    assert merged_stats.stop == "completed"
    assert merged_stats.samples == stats.samples
    assert merged_stats.mutations == stats.mutations
    assert merged_stats.normalization.value == stats.normalization.value
    assert merged_stats.threads == 1
    assert sum(p.stats.samples for p in partials) == stats.samples


def test_one_job_is_the_render(cornell_box: tuple[mlt.Scene, mlt.Camera]) -> None:
    scene, camera = cornell_box
    wanted = settings("mmlt")
    image, _ = mlt.render(scene, camera, wanted)
    plan = mlt.plan(scene, camera, wanted)
    merged, _ = mlt.merge(plan, [mlt.render_job(scene, plan, 0, 1)])
    assert np.array_equal(merged, image)


def test_plan_carries_its_settings_and_camera(cornell_box: tuple[mlt.Scene, mlt.Camera]) -> None:
    scene, camera = cornell_box
    wanted = settings("pssmlt-bdpt", seed=7, large_step_probability=0.3, mutation_weights=(0.5, 0.2, 0.2, 0.1))
    plan = mlt.plan(scene, camera, wanted)
    assert plan.settings == wanted
    assert plan.settings.algorithm is mlt.Algorithm.PSSMLT_BDPT
    assert plan.camera == camera
    assert mlt.RenderPlan.from_bytes(plan.to_bytes()) == plan
    assert pickle.loads(pickle.dumps(plan)) == plan
    assert mlt.RenderPlan.from_bytes(plan.to_bytes()).id == plan.id
    # Another seed is another plan.
    other = mlt.plan(scene, camera, settings("pssmlt-bdpt", seed=8))
    assert other.id != plan.id and other != plan
    assert f"{plan.id:016x}" in repr(plan)


def test_stats_pickle(cornell_box: tuple[mlt.Scene, mlt.Camera]) -> None:
    scene, camera = cornell_box
    _, stats = mlt.render(scene, camera, settings("path-space-mlt"))
    copy = pickle.loads(pickle.dumps(stats))
    for name in ["stop", "samples", "mutations", "rays", "invalid_samples", "seconds", "threads", "accepted_mutations", "mutation_weights"]:
        assert getattr(copy, name) == getattr(stats, name), name
    for name in ["value", "samples", "relative_error", "largest_share"]:
        assert getattr(copy.normalization, name) == getattr(stats.normalization, name), name
    assert copy.mutation_counts.proposed == stats.mutation_counts.proposed
    assert copy.mutation_counts.accepted == stats.mutation_counts.accepted
    assert copy.filter.changed_fraction == stats.filter.changed_fraction
    assert sum(stats.mutation_counts.proposed) > 0


def test_a_cancelled_job_still_merges(cornell_box: tuple[mlt.Scene, mlt.Camera]) -> None:
    scene, camera = cornell_box
    # Long enough that the job is still running at its first progress report (50 ms).
    plan = mlt.plan(scene, camera, settings("mmlt", width=64, height=64, mutations_per_pixel=4096))
    token = mlt.CancelToken()
    token.cancel()
    stopped = mlt.render_job(scene, plan, 0, 2, cancel=token)
    assert stopped.stats.stop == "cancelled"
    fractions: list[float] = []

    def progress(fraction: float) -> bool:
        fractions.append(fraction)
        return len(fractions) < 3

    stopped_later = mlt.render_job(scene, plan, 1, 2, progress=progress)
    assert stopped_later.stats.stop == "cancelled"
    assert len(fractions) == 3
    image, stats = mlt.merge(plan, [stopped, stopped_later])
    assert stats.stop == "cancelled"
    assert np.isfinite(image).all() and image.sum() > 0


def test_bad_jobs_and_buffers_raise(cornell_box: tuple[mlt.Scene, mlt.Camera]) -> None:
    scene, camera = cornell_box
    plan = mlt.plan(scene, camera, settings("path"))
    partials = [mlt.render_job(scene, plan, k, 2) for k in range(2)]
    with pytest.raises(mlt.InvalidArgumentError, match="missing"):
        mlt.merge(plan, partials[:1])
    with pytest.raises(mlt.InvalidArgumentError):
        mlt.merge(plan, [partials[0], partials[0], partials[1]])
    with pytest.raises(mlt.InvalidArgumentError, match="another plan"):
        mlt.merge(mlt.plan(scene, camera, settings("path", seed=1)), partials)
    with pytest.raises(TypeError, match="PartialRender"):
        mlt.merge(plan, [partials[0], 1.5])
    with pytest.raises(mlt.InvalidArgumentError, match="job 2 does not exist"):
        mlt.render_job(scene, plan, 2, 2)
    with pytest.raises(mlt.InvalidArgumentError, match="jobs is 0"):
        mlt.render_job(scene, plan, 0, 0)
    # A scene built from another description is refused, not rendered into a wrong image.
    other, _ = mlt.Scene.load(SCENES / "cornell-box.obj", energy_compensation=True)
    with pytest.raises(mlt.InvalidArgumentError, match="not the one the plan was made for"):
        mlt.render_job(other, plan, 0, 2)
    # Every corrupted byte of a buffer is caught (by the checksum or the framing).
    data = partials[0].to_bytes()
    for position in range(0, len(data), max(1, len(data) // 50)):
        corrupted = bytearray(data)
        corrupted[position] ^= 0x10
        with pytest.raises(mlt.InvalidArgumentError):
            mlt.PartialRender.from_bytes(bytes(corrupted))
    with pytest.raises(mlt.InvalidArgumentError):
        mlt.PartialRender.from_bytes(data[:-1])
    with pytest.raises(mlt.InvalidArgumentError):
        mlt.RenderPlan.from_bytes(data)
    plan_bytes = plan.to_bytes()
    with pytest.raises(mlt.InvalidArgumentError):
        mlt.RenderPlan.from_bytes(plan_bytes[: len(plan_bytes) // 2])


@pytest.mark.parametrize("algorithm", ["path", "mmlt"])
def test_combined_partials_merge_into_the_same_bits(cornell_box: tuple[mlt.Scene, mlt.Camera], algorithm: str) -> None:
    scene, camera = cornell_box
    wanted = settings(algorithm)
    image, stats = mlt.render(scene, camera, wanted)
    plan = mlt.plan(scene, camera, wanted)
    jobs = 5
    partials = [mlt.render_job(scene, plan, k, jobs, threads=1).to_bytes() for k in range(jobs)]
    pair = mlt.combine(plan, [partials[3], partials[0]])
    assert pair.held_jobs == [0, 3] and pair.job == 0 and pair.jobs == jobs
    # Combined again (from an object and from bytes), then merged with the rest.
    three = pickle.loads(pickle.dumps(mlt.combine(plan, [pair, partials[4]])))
    assert three.held_jobs == [0, 3, 4]
    assert three.stats.samples == sum(mlt.PartialRender.from_bytes(partials[k]).stats.samples for k in (0, 3, 4))
    merged, merged_stats = mlt.merge(plan, [partials[2], three, partials[1]])
    assert np.array_equal(merged.view(np.uint32), image.view(np.uint32))
    assert merged_stats.samples == stats.samples and merged_stats.mutations == stats.mutations
    with pytest.raises(mlt.InvalidArgumentError, match="job 3 of 5 is given twice"):
        mlt.combine(plan, [three, partials[3]])
    with pytest.raises(TypeError, match="combine takes PartialRender"):
        mlt.combine(plan, [partials[1], "not a partial"])
