#!/usr/bin/env python3
"""How far a Metropolis render's normalization b strays from seed to seed when it comes from
the bootstrap alone, against the error the render reports for it.

Each render is a bootstrap of N samples and as few chain mutations as the CLI allows
(`--normalization-fraction 0 --mutations-per-pixel 1`), so the b it prints is the
bootstrap's estimate. Per scene and algorithm the script prints, over the seeds, b's mean,
its relative spread (the standard deviation over the mean, with that spread's own standard
error, about 1/sqrt(2(n - 1)) of it) and the median of the errors the renders reported. The
reported error is the sample variance's, which is exact for independent samples and an
overstatement when the samples are stratified. Reported, never asserted (a bench, not a
test). `cargo build --release`, then from the repository root:

    python3 benches/bootstrap_spread.py [SCENES] [ALGORITHMS] [SEEDS] [BOOTSTRAP] [SIZE]

(defaults: cornell-box,cornell-glass,door-ajar pssmlt,mmlt 64 65536 128). The script runs
$CARGO_TARGET_DIR/release/mlt-render (target/ without the variable); with MLT_BASELINE set to
another mlt-render (a build of an earlier commit), its rows are added, seed for seed.
"""
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
B_LINE = re.compile(r"b = ([0-9.eE+-]+) ± ([0-9.]+)%")


def mlt_render_binary():
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    return os.path.join(target, "release/mlt-render")


def bootstrap_b(binary, scene, algorithm, seed, bootstrap, size, out):
    """b and its reported relative error (in percent) of one render."""
    command = [
        binary, os.path.join(ROOT, "tests/scenes", scene + ".obj"),
        "--algorithm", algorithm, "--bootstrap", str(bootstrap),
        "--normalization-fraction", "0", "--mutations-per-pixel", "1",
        "--width", str(size), "--height", str(size), "--max-depth", "5",
        "--seed", str(seed), "--out", out,
    ]
    result = subprocess.run(command, check=True, capture_output=True, text=True)
    match = B_LINE.search(result.stdout + result.stderr)
    if not match:
        sys.exit(f"no 'b = ...' in the output of {' '.join(command)}")
    return float(match.group(1)), float(match.group(2))


def main():
    args = sys.argv[1:]
    scenes = (args[0] if len(args) > 0 else "cornell-box,cornell-glass,door-ajar").split(",")
    algorithms = (args[1] if len(args) > 1 else "pssmlt,mmlt").split(",")
    seeds = int(args[2]) if len(args) > 2 else 64
    bootstrap = int(args[3]) if len(args) > 3 else 65536
    size = int(args[4]) if len(args) > 4 else 128
    builds = [("mlt", mlt_render_binary())]
    if os.environ.get("MLT_BASELINE"):
        builds.append(("baseline", os.environ["MLT_BASELINE"]))
    out = os.path.join(tempfile.mkdtemp(), "bootstrap.pfm")
    print(f"{seeds} seeds, {bootstrap} bootstrap samples, {size}x{size}, max depth 5")
    print(f"{'scene':<16} {'algorithm':<15} {'build':<9} {'mean b':>10} "
          f"{'spread':>16} {'reported':>9}")
    for scene in scenes:
        for algorithm in algorithms:
            for label, binary in builds:
                values = [bootstrap_b(binary, scene, algorithm, seed, bootstrap, size, out)
                          for seed in range(1, seeds + 1)]
                b = [value for value, _ in values]
                mean = statistics.mean(b)
                spread = 100 * statistics.stdev(b) / mean
                spread_error = spread / math.sqrt(2 * (len(b) - 1))
                reported = statistics.median(error for _, error in values)
                print(f"{scene:<16} {algorithm:<15} {label:<9} {mean:>10.6f} "
                      f"{spread:>7.3f}% ± {spread_error:.3f} {reported:>8.3f}%", flush=True)


if __name__ == "__main__":
    main()
