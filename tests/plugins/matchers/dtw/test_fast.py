"""The dtw matcher calls dtaidistance's C distance with the settings computed once (issue 22): the same numbers."""

from __future__ import annotations

import numpy as np
from dtaidistance import dtw_ndim
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.matchers.dtw import frame_distance


@given(seed=st.integers(0, 10_000), n=st.integers(1, 40), m=st.integers(1, 40), dims=st.integers(1, 12),
       window=st.sampled_from([0.0, 0.1, 0.3, 1.0]), zeros=st.booleans())
@settings(max_examples=80, deadline=None)
def test_frame_distance_is_dtaidistances_distance_fast_bit_for_bit(seed, n, m, dims, window, zeros):
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=(n, dims)), rng.normal(size=(m, dims))
    if zeros:  # parts never seen: filled with 0
        a[:, 0], b[:, 0] = 0.0, 0.0
    band = int(window * max(n, m)) or None
    if band is not None:
        band = max(band, abs(n - m) + 1)
    d = dtw_ndim.distance_fast(a, b, window=band)
    assert frame_distance(a, b, window) == float(np.sqrt(d * d / (n + m)))
    assert frame_distance(a[:, ::1].T.copy().T, b, window) == frame_distance(a, b, window)  # any memory layout


def test_without_dtaidistances_c_module_the_public_function_gives_the_same_number(monkeypatch):
    import builtins

    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(17, 6)), rng.normal(size=(23, 6))
    fast = frame_distance(a, b, 0.3)
    real_import = builtins.__import__

    def no_c(name, globals=None, locals=None, fromlist=(), level=0):
        if name == "dtaidistance" and fromlist and "dtw_cc" in fromlist:
            raise ImportError("no C module")
        return real_import(name, globals, locals, fromlist, level)

    monkeypatch.setattr(builtins, "__import__", no_c)
    assert frame_distance(a, b, 0.3) == fast
