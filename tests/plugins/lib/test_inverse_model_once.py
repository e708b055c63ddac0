"""The inverse model filters a piece's speed profiles once, side by side, and imports scipy's heavy modules late:
the same commands as stroke by stroke, bit for bit."""

from __future__ import annotations

import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from plugins.lib.guiding_stroke import GuidingStroke
from plugins.lib.inverse_model import _timing, _timings, commands_from_segment, stroke_from_segment
from plugins.lib.strokes import breaks


def _observed(seed: int, n: int, k: int) -> np.ndarray:
    """k parts moving by curved and straight guiding strokes with noise, (n, k, 3)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 30.0
    shapes = ["linear", "left-c", "right-s", "right-c", "left-s"]
    parts = []
    for j in range(k):
        stroke = GuidingStroke(rng.normal(0, 0.3, 3), rng.normal(0, 0.3, 3), t[-1], peak=rng.uniform(0.2, 0.8),
                               shape=shapes[(seed + j) % len(shapes)], curvature=rng.uniform(0.1, 0.6))
        parts.append(stroke.position(t) + rng.normal(0, 0.004, (n, 3)))
    return np.stack(parts, axis=1)


@pytest.mark.parametrize("n", [2, 3, 7, 8, 9, 40, 211])
@pytest.mark.parametrize("k", [1, 2, 5, 13])
def test_speed_profiles_filtered_side_by_side_are_each_part_own(n, k):
    observed = _observed(n * k, n, k)
    parts = [observed[:, j] for j in range(k)]
    assert _timings(parts, 30.0) == [_timing(p, 30.0) for p in parts]


def _stroke_by_stroke(observed, fps, cuts, refine):
    """commands_from_segment as it was: stroke_from_segment for every part of every piece."""
    n, k, _ = observed.shape
    cuts = [0, *cuts, n - 1]
    return [([stroke_from_segment(observed[a : b + 1, j], fps, refine=refine) for j in range(k)], i == len(cuts) - 2)
            for i, (a, b) in enumerate(zip(cuts, cuts[1:])) if b - a >= 2]


@pytest.mark.parametrize("refine", [False, True])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_commands_are_bit_for_bit_those_of_stroke_by_stroke(seed, refine):
    observed = _observed(seed, 90 + 17 * seed, 4)
    cuts = breaks(observed.reshape(len(observed), -1), 30.0) or [30, 31, 60]
    fast = commands_from_segment(observed, 30.0, cuts, hand=False, refine=refine)
    slow = _stroke_by_stroke(observed, 30.0, cuts, refine)
    assert len(fast) == len(slow) > 0
    assert pickle.dumps(fast) == pickle.dumps(slow)


def test_a_hidden_sample_is_still_the_same_error():
    observed = _observed(3, 40, 3)
    observed[10, 2, 1] = np.nan
    with pytest.raises(ValueError, match="two or more finite positions"):
        commands_from_segment(observed, 30.0, [20], hand=False)


def test_importing_the_inverse_model_does_not_import_scipy_signal_or_integrate():
    code = ("import sys, plugins.lib.inverse_model; "
            "print(sorted(m for m in ('scipy.signal', 'scipy.integrate') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).resolve().parents[3])
    assert out.stdout.strip() == "[]"
