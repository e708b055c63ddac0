"""The forward model's compiled loops (issue 22: numba) give the watching loop the answers of numpy's steps.

:func:`plugins.matchers.forward_model._kernels` compiles the anchors' nearest points (:class:`_Halves`) and the points
along the table of every stroke (:class:`_StrokeRows`); without numba numpy's steps run. Both are held to the plain
computation on random data in ``tests/test_forward_model_fast.py``; here velocity-direction + the forward model
watch the project's generated streams both ways, with learning (so learned edges are predicted too), and every
observation, the matcher's state after every segment (candidates, traces, anchors to the bit) and the motor graph's
edges are the same.
"""

from __future__ import annotations

import pytest

from plugins.bench.mocap import _streams
from plugins.matchers.forward_model import ForwardModel
from tests.test_forward_model_fast import kernels
from tests.toolkit.test_watching_settled import data, pm_, profile, watched  # noqa: F401 (fixtures)
from toolkit.observe import compose_observer


@pytest.mark.parametrize("settings", [{}, {"threshold": 0.02}, {"together": False, "threshold": 0.03}])
def test_compiled_loops_watch_as_numpys_steps(pm_, data, profile, monkeypatch, settings):  # noqa: F811
    streams = [profile.read(path, None) for path, _ in _streams(data / "streams")]
    runs = []
    for mode in ("numpy", "compiled"):
        character = compose_observer(pm_, profile, data / "repertoire", segmenter="velocity-direction",
                                     matcher="forward-model", settings={"matcher": dict(settings)})
        assert isinstance(character.matcher, ForwardModel)
        with kernels(mode):
            runs.append(watched(character, profile, streams, monkeypatch, True))
    (plain, plain_states, plain_edges, _), (fast, fast_states, fast_edges, _) = runs
    assert any(o[4] is not None and o[4][0] is not None for o in plain)  # something was recognised or learned
    assert fast == plain
    assert fast_states == plain_states
    assert fast_edges == plain_edges
