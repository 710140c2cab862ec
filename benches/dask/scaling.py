#!/usr/bin/env python3
"""What splitting a frame into jobs costs, on this machine: a frame rendered by one
process (every core) against the same frame as 1, 2 and 4 jobs over a Dask LocalCluster of
two single-threaded worker processes (and 4 jobs merged through a tree of combines), with
the parts of the difference (plan, each job's render, the partial results' bytes, the
combine, the merge) measured one by one; then an estimate, from those per-pixel and per-job
costs, of a 4K frame on 64 machines, merged by one machine or through a tree.

    pip install ./python "dask[distributed]"
    python3 benches/dask/scaling.py            # about 2½ minutes on 2 cores

Environment: MLT_SCALING_SIZE (default 384: the frame is SIZE x SIZE), MLT_SCALING_REPEATS
(default 3; medians are printed), MLT_SCALING_ALGORITHMS (default "path,mmlt").
"""

from __future__ import annotations

import os
import pathlib
import statistics
import time
from typing import Callable, TypeVar

import numpy as np
from distributed import Client, LocalCluster

import mlt
import mlt.dask

T = TypeVar("T")

REPOSITORY = pathlib.Path(__file__).resolve().parents[2]
SCENE = mlt.dask.SceneFile(str(REPOSITORY / "tests" / "scenes" / "cornell-box.obj"))
SIZE = int(os.environ.get("MLT_SCALING_SIZE", "384"))
REPEATS = int(os.environ.get("MLT_SCALING_REPEATS", "3"))
ALGORITHMS = os.environ.get("MLT_SCALING_ALGORITHMS", "path,mmlt").split(",")
JOB_COUNTS = [1, 2, 4]
CORES = 2


def timed(work: Callable[[], T]) -> tuple[float, T]:
    start = time.perf_counter()
    result = work()
    return time.perf_counter() - start, result


def median_time(work: Callable[[], object]) -> float:
    return statistics.median(timed(work)[0] for _ in range(REPEATS))


def settings_for(algorithm: str) -> mlt.RenderSettings:
    # About 5 core-seconds of rendering either way.
    return mlt.RenderSettings(
        width=SIZE,
        height=SIZE,
        algorithm=algorithm,
        samples_per_pixel=24,
        mutations_per_pixel=24,
        threads=0,
    )


def main() -> None:
    scene = SCENE()
    _, camera = mlt.Scene.load(SCENE.path)
    assert camera is not None
    pixels = SIZE * SIZE
    print(f"cornell-box, {SIZE} x {SIZE}, {CORES} cores; medians of {REPEATS}\n")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, Client(cluster) as client:
        workers = sorted(client.scheduler_info()["workers"])
        for algorithm in ALGORITHMS:
            settings = settings_for(algorithm)
            single = median_time(lambda: mlt.render(scene, camera, settings))
            wanted, _ = mlt.render(scene, camera, settings)

            # The parts, in this process, each job on one thread as on a worker.
            plan_seconds = median_time(lambda: mlt.plan(scene, camera, settings))
            plan = mlt.plan(scene, camera, settings)
            parts: dict[int, dict[str, float]] = {}
            for jobs in JOB_COUNTS:
                job_seconds, partials = [], []
                for job in range(jobs):
                    seconds, partial = timed(lambda: mlt.render_job(scene, plan, job, jobs, threads=1))
                    job_seconds.append(seconds)
                    partials.append(partial)
                encode, blobs = timed(lambda: [p.to_bytes() for p in partials])
                decode, _ = timed(lambda: [mlt.PartialRender.from_bytes(b) for b in blobs])
                merge = median_time(lambda: mlt.merge(plan, blobs))
                image, _ = mlt.merge(plan, blobs)
                assert np.array_equal(image, wanted), f"{algorithm}: {jobs} jobs differ from the render"
                # A node of a merge tree: reads the partial results, writes their sum's bytes.
                combine = median_time(lambda: mlt.combine(plan, blobs).to_bytes())
                image, _ = mlt.merge(plan, [mlt.combine(plan, blobs)])
                assert np.array_equal(image, wanted), f"{algorithm}: {jobs} combined jobs differ from the render"
                parts[jobs] = {
                    "job": max(job_seconds),
                    "work": sum(job_seconds),
                    "bytes": sum(len(b) for b in blobs) / jobs,
                    "encode": encode / jobs,
                    "decode": decode / jobs,
                    "merge": merge,
                    "combine": combine,
                }

            # End to end on the cluster: plan task, job tasks alternating between the two
            # workers (each on one thread), merge task, image back to this process.
            mlt.dask.render_frame(client, SCENE, camera, settings, jobs=2, threads=1, workers=workers)  # builds the scene on both
            cluster_seconds = {}
            for jobs in JOB_COUNTS:
                def frame() -> None:
                    image, _ = mlt.dask.render_frame(client, SCENE, camera, settings, jobs=jobs, threads=1, workers=workers)
                    assert np.array_equal(image, wanted)

                cluster_seconds[jobs] = median_time(frame)

            def tree_frame() -> None:
                image, _ = mlt.dask.render_frame(client, SCENE, camera, settings, jobs=4, threads=1, workers=workers, fan_in=2)
                assert np.array_equal(image, wanted)

            tree_seconds = median_time(tree_frame)

            print(f"## {algorithm}: one process on {CORES} threads {single:.2f} s")
            print(f"plan {plan_seconds * 1000:.0f} ms\n")
            print(
                "| jobs | on the cluster | vs one process | slowest job (1 thread) | all jobs' work | partial result"
                " | to_bytes | from_bytes | merge | combine |"
            )
            print("|---|---|---|---|---|---|---|---|---|---|")
            for jobs in JOB_COUNTS:
                p = parts[jobs]
                print(
                    f"| {jobs} | {cluster_seconds[jobs]:.2f} s | {cluster_seconds[jobs] / single:.2f}x "
                    f"| {p['job']:.2f} s | {p['work']:.2f} s | {p['bytes'] / 1e6:.2f} MB "
                    f"| {p['encode'] * 1000:.0f} ms | {p['decode'] * 1000:.0f} ms | {p['merge'] * 1000:.0f} ms "
                    f"| {p['combine'] * 1000:.0f} ms |"
                )
            print(f"\n4 jobs merged through a tree (fan_in=2: two combines, then the merge of two): {tree_seconds:.2f} s, {tree_seconds / single:.2f}x")

            # The estimate: a job's time is a fixed part plus its share of the work; a
            # partial result's bytes and the merge's time grow with the pixels, the merge's
            # with the jobs too. Fitted from 1 and 4 jobs.
            work_per_pixel = parts[1]["work"] / pixels
            fixed_per_job = max(0.0, (parts[4]["work"] - parts[1]["work"]) / 3)
            bytes_per_pixel = parts[4]["bytes"] / pixels
            merge_per_pixel_job = parts[4]["merge"] / (4 * pixels)
            combine_per_pixel_job = parts[4]["combine"] / (4 * pixels)
            codec_per_pixel = (parts[4]["encode"] + parts[4]["decode"]) / pixels
            k4 = 3840 * 2160
            machines = 64
            work = work_per_pixel * k4
            job = work / (machines * CORES) + fixed_per_job * (k4 / pixels) / CORES
            transfer_bytes = bytes_per_pixel * k4 * machines
            merge = merge_per_pixel_job * k4 * machines
            codec = codec_per_pixel * k4
            total = plan_seconds * (k4 / pixels if settings.algorithm != "path" else 1) + job + codec + merge
            print(
                f"\n4K ({k4 / 1e6:.1f} Mpx, the same samples per pixel) on {machines} machines of {CORES} cores:"
                f" {work / CORES:.0f} s on one machine; per job {job:.1f} s, each partial result"
                f" {bytes_per_pixel * k4 / 1e6:.0f} MB ({transfer_bytes / 1e9:.1f} GB to the merging machine),"
                f" to/from bytes {codec:.1f} s, merge {merge:.1f} s: about {total:.0f} s,"
                f" {work / CORES / total:.1f}x one machine"
            )
            # Through a tree of fan-in 8: 8 combines of 8 in parallel, then one merge of 8.
            fan_in = 8
            tree_merge = fan_in * combine_per_pixel_job * k4 + fan_in * merge_per_pixel_job * k4
            tree_total = total - merge + tree_merge
            print(
                f"merged through a tree of fan-in {fan_in} (8 combines of 8 partial results on 8 machines at once,"
                f" then one merge of 8): merge {tree_merge:.1f} s, {fan_in * bytes_per_pixel * k4 / 1e9:.1f} GB"
                f" into each merging machine: about {tree_total:.0f} s, {work / CORES / tree_total:.1f}x one machine\n"
            )


if __name__ == "__main__":
    main()
