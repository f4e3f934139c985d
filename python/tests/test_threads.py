"""The GIL is released during a render, Ctrl-C stops one, and progress
reaches a callback."""

import os
import signal
import threading
import time

import pytest

import irsig
from conftest import AIRFIELD


def scene(w, h):
    return irsig.Scene.load(AIRFIELD, overrides={"sensor.width_px": w, "sensor.height_px": h})


def test_a_python_thread_runs_during_a_render():
    s = scene(160, 120)
    count = 0
    stop = threading.Event()

    def spin():
        nonlocal count
        while not stop.is_set():
            count += 1

    t = threading.Thread(target=spin)
    t.start()
    try:
        t0 = time.perf_counter()
        before = count
        irsig.render(s, threads=1)
        during = count - before
        seconds = time.perf_counter() - t0
    finally:
        stop.set()
        t.join()
    # A render holding the GIL would leave the counter (nearly) still; with
    # the GIL released it counts millions of times per second.
    assert seconds > 0.05
    assert during > 20_000 * seconds, (during, seconds)


def test_progress_reaches_the_callback():
    calls = []
    irsig.render(scene(64, 48), progress=lambda d, t: calls.append((d, t)))
    assert calls and calls[-1][0] == calls[-1][1]
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))


def test_an_exception_in_the_callback_stops_the_render():
    def boom(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        irsig.render(scene(64, 48), progress=boom)


@pytest.mark.skipif(threading.current_thread() is not threading.main_thread(), reason="signals go to the main thread")
def test_ctrl_c_interrupts_a_render():
    # SIGINT arrives from another thread once the render has reported
    # progress (so it is surely under way); the full render takes several
    # seconds on one thread, the cancelled one stops at the next block or
    # chunk of samples.
    s = scene(512, 512)
    started = threading.Event()

    def progress(done, total):
        if 0 < done < total:
            started.set()

    def interrupt():
        if started.wait(30):
            os.kill(os.getpid(), signal.SIGINT)

    t = threading.Thread(target=interrupt)
    t.start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        irsig.render(s, threads=1, progress=progress)
    elapsed = time.perf_counter() - t0
    t.join()
    assert elapsed < 3.0, elapsed
    # The package still works afterwards.
    assert irsig.render(scene(16, 12)).sizes == {"y": 12, "x": 16}


def test_a_tqdm_like_bar_is_driven():
    class Bar:
        total, n = None, 0

        def update(self, k):
            self.n += k

    bar = Bar()
    irsig.sequence(scene(16, 12), times=["10:00", "11:00"], progress=bar)
    assert bar.total == 6000 and bar.n == bar.total


def test_sequence_progress_moves_within_frames():
    calls = []
    irsig.sequence(scene(128, 96), times=["10:00", "11:00"], threads=1, progress=lambda d, t: calls.append(d))
    # Reports inside each frame's stages, not only at frame ends.
    assert any(0 < d < 3000 for d in calls) and any(3000 < d < 6000 for d in calls)
    assert calls[-1] == 6000
