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
        comb_points, comb_cage, method="pmvc", resolution=96, backend="cpu",
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
    """Two binds in threads overlap, and this thread runs Python meanwhile.
    No progress callback: calling Python code would itself let other threads
    in, so the ticks below can only land inside a bind that released the GIL."""
    spans = {}

    def run(name):
        started = time.monotonic()
        pmvc.bind(comb_points, comb_cage, method="pmvc", resolution=64, backend="cpu")
        spans[name] = (started, time.monotonic())

    threads = [threading.Thread(target=run, args=(name,)) for name in "ab"]
    for thread in threads:
        thread.start()
    ticks = []
    while any(thread.is_alive() for thread in threads):
        ticks.append(time.monotonic())
        time.sleep(0.001)
    for thread in threads:
        thread.join()
    (a_start, a_end), (b_start, b_end) = spans["a"], spans["b"]
    assert max(a_start, b_start) < min(a_end, b_end), f"the binds did not overlap: {spans}"
    for start, end in spans.values():
        quarter = (end - start) / 4
        assert any(start + quarter < tick < end - quarter for tick in ticks), (
            f"no Python ran in the middle of the bind {start:.3f}..{end:.3f}"
        )


def test_ctrl_c_cancels_a_running_bind(comb_points, comb_cage):
    # A progress callback of C code (no Python bytecode, which would run the
    # signal handler itself): the bind must check for signals on its own.
    seen = {}
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    started = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            # Minutes on two cores when left to finish: the signal comes first
            # on any machine (were the bind done before it, the interrupt would
            # land outside this block).
            pmvc.bind(
                comb_points, comb_cage, method="pmvc", resolution=512, backend="cpu",
                progress=seen.__setitem__,
            )  # fmt: skip
    finally:
        timer.cancel()
    elapsed = time.monotonic() - started
    print(f"KeyboardInterrupt raised {elapsed - 0.3:.3f} s after the signal")
    assert max(seen) < len(comb_points), "the bind ran to the end"
    # The package still works afterwards.
    weights = pmvc.bind(comb_points[:10], comb_cage, method="mvc", backend="cpu")
    assert np.isfinite(weights.matrix).all()
