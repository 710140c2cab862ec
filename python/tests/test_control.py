"""Progress, cancellation, KeyboardInterrupt and the GIL during a render."""

from __future__ import annotations

import _thread
import signal
import threading
import time

import numpy as np
import pytest
from conftest import CAMERA

import mlt

#: A render that would run until its time limit (no sample count): long enough to stop
#: early, bounded if stopping fails.
LIMIT = 20.0


def until_limit(seconds: float = LIMIT) -> mlt.RenderSettings:
    return mlt.RenderSettings(
        width=32, height=32, algorithm="path", samples_per_pixel=0, time_limit_seconds=seconds, threads=1
    )


def test_progress_reports_rising_fractions_ending_at_one(lit_plane: mlt.Scene) -> None:
    fractions: list[float] = []
    settings = mlt.RenderSettings(width=64, height=64, algorithm="path", samples_per_pixel=512, threads=1)
    # A callable returning None goes on.
    _, stats = mlt.render(lit_plane, CAMERA, settings, progress=fractions.append)
    assert stats.stop == "completed"
    assert len(fractions) >= 2, "the render should last several 50 ms progress periods"
    assert fractions == sorted(fractions)
    assert all(0.0 <= f <= 1.0 for f in fractions)
    assert fractions[-1] == 1.0


def test_progress_returning_false_cancels(lit_plane: mlt.Scene) -> None:
    calls: list[float] = []

    def stop_at_once(fraction: float) -> bool:
        calls.append(fraction)
        return False

    start = time.monotonic()
    image, stats = mlt.render(lit_plane, CAMERA, until_limit(), progress=stop_at_once)
    assert stats.stop == "cancelled"
    assert time.monotonic() - start < LIMIT / 4
    assert len(calls) == 1, "a cancelled render does not call progress again"
    # The image is valid: normalized by the samples taken.
    assert np.isfinite(image).all() and image.mean() > 0


def test_exception_in_progress_cancels_and_is_reraised(lit_plane: mlt.Scene) -> None:
    class Stop(Exception):
        pass

    def fail(fraction: float) -> None:
        raise Stop(f"at {fraction}")

    start = time.monotonic()
    with pytest.raises(Stop, match="at 0"):
        mlt.render(lit_plane, CAMERA, until_limit(), progress=fail)
    assert time.monotonic() - start < LIMIT / 4


def test_progress_must_be_callable(lit_plane: mlt.Scene) -> None:
    with pytest.raises(TypeError, match="progress must be callable .*, not int"):
        mlt.render(lit_plane, CAMERA, until_limit(), progress=1)  # type: ignore[arg-type]


def test_cancel_token_from_another_thread(lit_plane: mlt.Scene) -> None:
    token = mlt.CancelToken()
    timer = threading.Timer(0.3, token.cancel)
    timer.start()
    start = time.monotonic()
    _, stats = mlt.render(lit_plane, CAMERA, until_limit(), cancel=token)
    elapsed = time.monotonic() - start
    timer.join()
    assert stats.stop == "cancelled"
    assert 0.25 < elapsed < LIMIT / 4
    assert token.cancelled
    # A cancelled token stops the next render at once, until reset.
    _, stats = mlt.render(lit_plane, CAMERA, until_limit(), cancel=token)
    assert stats.stop == "cancelled"
    token.reset()
    assert not token.cancelled
    _, stats = mlt.render(lit_plane, CAMERA, until_limit(0.2), cancel=token)
    assert stats.stop == "time_limit_reached"


def test_keyboard_interrupt_stops_the_render(lit_plane: mlt.Scene) -> None:
    # What Ctrl-C does: the main thread's signal flag is set while it renders. Python's own
    # handler, whatever the process inherited: a shell starting it in the background sets
    # SIGINT to be ignored, and interrupt_main then does nothing.
    assert threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        timer = threading.Timer(0.3, _thread.interrupt_main)
        timer.start()
        start = time.monotonic()
        with pytest.raises(KeyboardInterrupt):
            mlt.render(lit_plane, CAMERA, until_limit())
        timer.join()
        assert time.monotonic() - start < LIMIT / 4
    finally:
        signal.signal(signal.SIGINT, previous)


def test_gil_is_released_while_rendering(lit_plane: mlt.Scene) -> None:
    # A Python thread counts while the main thread renders for 1 s: with the GIL held by
    # the render it could not run at all until the render returned.
    counts = []
    stop = threading.Event()

    def count() -> None:
        n = 0
        while not stop.is_set():
            n += 1
            if n % 1000 == 0:
                counts.append(time.monotonic())

    counter = threading.Thread(target=count)
    counter.start()
    try:
        time.sleep(0.05)
        start = time.monotonic()
        _, stats = mlt.render(lit_plane, CAMERA, until_limit(1.0))
        end = time.monotonic()
    finally:
        stop.set()
        counter.join()
    assert stats.stop == "time_limit_reached"
    during = [t for t in counts if start < t < end]
    # Counting continued through the render, not only around it.
    assert len(during) > 10
    assert during[0] - start < 0.3 and end - during[-1] < 0.3


def test_renders_from_several_threads_share_a_scene(lit_plane: mlt.Scene) -> None:
    settings = mlt.RenderSettings(width=16, height=16, algorithm="path", samples_per_pixel=16)
    expected, _ = mlt.render(lit_plane, CAMERA, settings)
    results: list[np.ndarray] = []

    def run() -> None:
        image, _ = mlt.render(lit_plane, CAMERA, settings)
        results.append(image)

    threads = [threading.Thread(target=run) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(results) == 3
    for image in results:
        np.testing.assert_array_equal(image, expected)
