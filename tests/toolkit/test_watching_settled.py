"""The first stroke of a split movement concluded from the state the forward model settled in (issue 22).

When the segmenter closes a followed movement as several strokes and nothing was committed, the watching loop
must match the first stroke on its own frames. The forward model says after how many frames nothing more changed
(``ForwardModel.settled``); when that is within the stroke, the loop concludes the state it has, its working memory
cut to the stroke, instead of beginning again and feeding the stroke's frames. These tests pin the shortcut to the
plain computation: the same observations, the same matcher state after every segment, the same motor graph.
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.bench.data import make_data
from plugins.bench.mocap import _streams
from plugins.matchers.forward_model import ForwardModel
from toolkit import create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile
from toolkit.watching import WatchingLoop


@pytest.fixture(scope="module")
def pm_():
    return create_plugin_manager(autoload=False, trace=False)


@pytest.fixture(scope="module")
def data(tmp_path_factory, pm_):
    return make_data(pm_, tmp_path_factory.mktemp("settled"), seed=3, streams=2, per_stream=4)


@pytest.fixture(scope="module")
def profile(data):
    return load_profile(data / "profile.toml")


def frozen(value):
    """A comparable copy of ``value``: arrays as (shape, bytes), mappings and sequences element by element."""
    if isinstance(value, np.ndarray):
        return ("array", value.shape, value.dtype.str, value.tobytes())
    if isinstance(value, float):
        return ("float", np.float64(value).tobytes())
    if hasattr(value, "items"):
        return ("map", tuple((frozen(k), frozen(v)) for k, v in value.items()))
    if isinstance(value, (list, tuple, set, frozenset)):
        items = sorted(value, key=repr) if isinstance(value, (set, frozenset)) else value
        return (type(value).__name__, tuple(frozen(v) for v in items))
    return value


def watched(character, profile, streams, monkeypatch, shortcut: bool):
    """Every observation, the matcher's state after each segment, and the motor graph's edges at the end, of
    watching ``streams`` one after another; with or without the shortcut; and how often it was taken."""
    states, taken = [], []
    matcher = character.matcher
    conclude = type(matcher).conclude

    def concluded(self, motion):
        out = conclude(self, motion)
        states.append(frozen(dict(self.inspect())))
        return out

    within = WatchingLoop._settled_within

    def counted(self, segment):
        answer = within(self, segment)
        taken.append(answer)
        return answer

    with monkeypatch.context() as m:
        m.setattr(type(matcher), "conclude", concluded)
        m.setattr(WatchingLoop, "_settled_within", counted)
        if not shortcut:
            m.setattr(type(matcher), "settled", lambda self: None)
        found = []
        for positions in streams:
            observer = Observer(character, profile.body, positions.fps)
            for o in observer.watch(positions):
                match = o.match
                found.append((o.segment.start, o.segment.end, o.decided_at, o.cut, None if match is None else (
                    match.movement, frozen(match.confidence), match.decided_at, match.path, frozen(match.details))))
    motor = character.motor
    edges = {name: sorted(e.name for e in motor.edges(name)) for name in motor.subsystems}
    return found, states, edges, sum(taken)


@pytest.mark.parametrize("settings", [{"threshold": 0.01}, {"threshold": 0.02}, {"threshold": 0.03},
                                      {"together": False, "threshold": 0.01}, {"threshold": 0.01, "learn": False}])
def test_a_settled_first_stroke_is_concluded_as_if_fed_again(pm_, data, profile, monkeypatch, settings):
    """Velocity-direction + the forward model on the project's generated streams (thresholds at which candidates
    drop within a movement's first stroke, so the follow settles there; learning on and off): every observation,
    the matcher's state after every segment (candidates, trace, anchors, commitments) and every edge learned are
    the same with the shortcut as without it, and the shortcut was taken."""
    streams = [profile.read(path, None) for path, _ in _streams(data / "streams")]
    runs = []
    for shortcut in (False, True):
        character = compose_observer(pm_, profile, data / "repertoire", segmenter="velocity-direction",
                                     matcher="forward-model", settings={"matcher": {"comparison": "strokes", **settings},
                                                                               "segmenter": {"level": "stroke"}})
        assert isinstance(character.matcher, ForwardModel)
        runs.append(watched(character, profile, streams, monkeypatch, shortcut))
    (plain, plain_states, plain_edges, never), (fast, fast_states, fast_edges, taken) = runs
    assert never == 0 and taken > 0
    assert fast == plain
    assert fast_states == plain_states
    assert fast_edges == plain_edges
