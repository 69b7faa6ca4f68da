"""The timing of the benchmarks: the best of several runs after one warm-up."""

from __future__ import annotations

import time


def best_of(fn, repeat):
    """``(shortest wall time of repeat calls of fn, the last call's result)``, after one
    untimed call (compiles, caches)."""
    fn()
    ts, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return min(ts), out
