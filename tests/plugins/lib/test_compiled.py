"""plugins.lib.compiled: numba's loops with and without its disk cache, and None without numba."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from plugins.lib.compiled import compiled


def _summed(x):
    total = 0.0
    for v in x:
        total += v
    return total


def test_a_compiled_loop_gives_the_plain_loops_bits():
    numba = pytest.importorskip("numba")
    (fast,) = compiled(_summed)
    assert isinstance(fast, numba.core.registry.CPUDispatcher)
    x = np.random.default_rng(1).normal(size=1001)
    assert fast(x) == _summed(x)  # the same order of additions, no fastmath


def test_without_a_writable_cache_it_compiles_in_the_process(monkeypatch):
    numba = pytest.importorskip("numba")
    njit, calls = numba.njit, []

    def refusing(*args, **kwargs):
        calls.append(kwargs.get("cache", False))
        if kwargs.get("cache"):
            raise RuntimeError("cannot cache function: no locator available")
        return njit(*args, **kwargs)

    monkeypatch.setattr(numba, "njit", refusing)
    (fast,) = compiled(_summed)
    assert calls == [True, False] and fast(np.arange(4.0)) == 6.0


def test_without_numba_it_is_none(monkeypatch):
    monkeypatch.setitem(sys.modules, "numba", None)  # import numba raises ImportError
    assert compiled(_summed) is None
