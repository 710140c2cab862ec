#!/usr/bin/env python3
"""Per-sample error of mlt's camera samples against Mitsuba 3's samplers: the path tracer on
the Cornell scenes at a few sample counts, each image's RMSE against a converged reference,
and the time it took on one thread.

mlt renders with its low-discrepancy camera samples (a padded, shuffled, digitally
shifted (0, 2)-sequence per pixel: src/sampling/sobol.rs); Mitsuba 3 (`scalar_rgb`, its `path`
integrator, the same triangles, camera, max depth and size, as spectral_compare.py builds
them) with its `independent` sampler and with its low-discrepancy `ldsampler`. The
reference is mlt's path tracer at REFERENCE_SPP samples per pixel (unbiased, so any
renderer's error is measured against the same image); the lamp's pixels, which the camera
sees directly and every renderer gets exactly, are left out. RMSE is over the other pixels'
RGB values, the mean of the seeds' RMSEs. Reported, never asserted (a bench, not a test):
`pip install mitsuba`, `cargo build --release` (the script runs $CARGO_TARGET_DIR/release/
mlt-render if that variable is set), then from the repository root:

    python3 benches/mitsuba/sampler_compare.py [SCENES] [SIZE] [SPPS] [SEEDS]

(defaults: cornell-box,cornell-glass 256 16,64,256 3). With MLT_BASELINE set to another
mlt-render (a build of an earlier commit, say), its column is added: a before-and-after in one
run. The reference takes a few minutes per
scene and is kept in $TMPDIR between runs (delete mlt-sampler-reference-* to remake it).
"""
import os
import struct
import subprocess
import sys
import tempfile
import time

import drjit as dr
import mitsuba as mi

import spectral_compare as common

REFERENCE_SPP = 4096
# src/integrators/path.rs's ROULETTE_START_DEPTH (Mitsuba counts depth the same way).
ROULETTE_START_DEPTH = 3


def mlt_render_binary():
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(common.ROOT, "target"))
    return os.path.join(target, "release/mlt-render")


def render_mlt(scene, size, spp, seed, threads, binary=None):
    out = os.path.join(tempfile.mkdtemp(), "mlt.pfm")
    command = [
        binary or mlt_render_binary(),
        os.path.join(common.ROOT, "tests/scenes", scene + ".obj"),
        "--algorithm", "path", "--spp", str(spp), "--max-depth", "5",
        "--width", str(size), "--height", str(size), "--seed", str(seed),
        "--threads", str(threads), "--out", out,
    ]
    start = time.time()
    subprocess.run(command, check=True, capture_output=True)
    return common.read_pfm(out), time.time() - start


def render_mitsuba(scene, size, spp, seed, sampler):
    mi.set_variant("scalar_rgb")
    mi.logger().clear_appenders()
    d = common.mitsuba_scene("scalar_rgb", scene, size, size, spp, tempfile.mkdtemp(), "path",
                             common.glass_bsdf)
    d["sensor"]["sampler"] = {"type": sampler, "sample_count": spp}
    # Russian roulette from the third bounce on, as mlt's path tracer (Mitsuba's default
    # starts at the fifth, which at this depth is almost none): the same estimator, so the
    # errors compare the samples alone.
    d["integrator"]["rr_depth"] = ROULETTE_START_DEPTH
    loaded = mi.load_dict(d)
    start = time.time()
    image = mi.render(loaded, seed=seed)
    seconds = time.time() - start
    values = list(mi.TensorXf(image).array)
    pixels = size * size
    channels = len(values) // pixels
    return [values[p * channels + c] for p in range(pixels) for c in range(3)], seconds


def reference(scene, size):
    path = os.path.join(tempfile.gettempdir(), f"mlt-sampler-reference-{scene}-{size}.pfm")
    if not os.path.exists(path):
        print(f"rendering the {REFERENCE_SPP}-spp reference of {scene} (once)...", flush=True)
        image, _ = render_mlt(scene, size, REFERENCE_SPP, 12345, os.cpu_count())
        # Written back as a PFM with rows bottom to top, as read_pfm expects.
        with open(path, "wb") as f:
            f.write(b"PF\n%d %d\n-1.0\n" % (size, size))
            rows = [image[y * size * 3:(y + 1) * size * 3] for y in range(size)]
            for row in reversed(rows):
                f.write(struct.pack("<" + "f" * len(row), *row))
    return common.read_pfm(path)


def rmse(image, truth, keep):
    total = sum((image[i] - truth[i]) ** 2 for i in keep)
    return (total / len(keep)) ** 0.5


def main():
    scenes = (sys.argv[1] if len(sys.argv) > 1 else "cornell-box,cornell-glass").split(",")
    size = int(sys.argv[2]) if len(sys.argv) > 2 else 256
    spps = [int(s) for s in (sys.argv[3] if len(sys.argv) > 3 else "16,64,256").split(",")]
    seeds = int(sys.argv[4]) if len(sys.argv) > 4 else 3
    # One thread each: per-sample costs compare directly.
    dr.set_thread_count(1)
    for scene in scenes:
        truth = reference(scene, size)
        # The lamp's pixels (radiance above 1 in a channel) are left out.
        lamp = {p for p in range(size * size) if max(truth[3 * p:3 * p + 3]) > 1.0}
        keep = [3 * p + c for p in range(size * size) if p not in lamp for c in range(3)]
        print(f"{scene}, {size}², RMSE over {len(keep) // 3} pixels (lamp's {len(lamp)} left "
              f"out), mean of {seeds} seeds; seconds on one thread")
        baseline = os.environ.get("MLT_BASELINE")
        print("  spp | mlt RMSE, s | " + ("baseline mlt RMSE, s | " if baseline else "")
              + "Mitsuba independent RMSE, s | Mitsuba ldsampler RMSE, s")
        for spp in spps:
            row = []
            renderers = [
                lambda seed: render_mlt(scene, size, spp, seed, 1),
                lambda seed: render_mitsuba(scene, size, spp, seed, "independent"),
                lambda seed: render_mitsuba(scene, size, spp, seed, "ldsampler"),
            ]
            if baseline:
                renderers.insert(1, lambda seed: render_mlt(scene, size, spp, seed, 1, baseline))
            for render in renderers:
                errors, times = [], []
                for seed in range(seeds):
                    image, seconds = render(seed)
                    errors.append(rmse(image, truth, keep))
                    times.append(seconds)
                row.append(f"{sum(errors) / seeds:.5f}, {sorted(times)[seeds // 2]:.2f}")
            print(f"  {spp:4d} | " + " | ".join(row), flush=True)


if __name__ == "__main__":
    main()
