"""Binding releases the GIL, reports progress, and stops on Ctrl-C."""

from __future__ import annotations

import _thread
import threading
import time

import numpy as np
import pytest

import pmvc


def test_progress_goes_from_zero_to_total_without_going_back(comb_points, comb_cage):
    calls = []
    pmvc.bind(
        comb_points, comb_cage, method="pmvc", resolution=48, backend="cpu",
        progress=lambda done, total: calls.append((done, total)),
    )  # fmt: skip
    total = len(comb_points)
    assert calls[0] == (0, total) and calls[-1] == (total, total)
    done = [d for d, _ in calls]
    assert done == sorted(done) and len(set(done)) == len(done)
    assert all(t == total for _, t in calls)
    assert len(calls) > 2, f"no intermediate progress in {calls}"


def test_an_exception_in_the_progress_callback_cancels_the_bind(comb_points, comb_cage):
    def progress(done, total):
        if done > 0:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        pmvc.bind(comb_points, comb_cage, method="pmvc", resolution=96, progress=progress)


def test_two_binds_in_threads_run_at_the_same_time(comb_points, comb_cage):
    """With the GIL held through a bind, the second thread's bind could only
    start (report (0, total)) once the first had ended (reported (total, total))."""
    spans = {}

    def run(name):
        times = []
        pmvc.bind(
            comb_points, comb_cage, method="pmvc", resolution=64, backend="cpu",
            progress=lambda done, total: times.append(time.monotonic()),
        )  # fmt: skip
        spans[name] = (times[0], times[-1])

    threads = [threading.Thread(target=run, args=(name,)) for name in "ab"]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    (a_start, a_end), (b_start, b_end) = spans["a"], spans["b"]
    assert max(a_start, b_start) < min(a_end, b_end), f"no overlap: {spans}"


def test_ctrl_c_cancels_a_running_bind(comb_points, comb_cage):
    calls = []
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    started = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            # About 16 s on two cores when left to finish.
            pmvc.bind(
                comb_points, comb_cage, method="pmvc", resolution=256, backend="cpu",
                progress=lambda done, total: calls.append(done),
            )  # fmt: skip
    finally:
        timer.cancel()
    elapsed = time.monotonic() - started
    print(f"KeyboardInterrupt raised {elapsed - 0.3:.3f} s after the signal")
    assert calls[-1] < len(comb_points), "the bind ran to the end"
    # The package still works afterwards.
    weights = pmvc.bind(comb_points[:10], comb_cage, method="mvc", backend="cpu")
    assert np.isfinite(weights.matrix).all()
