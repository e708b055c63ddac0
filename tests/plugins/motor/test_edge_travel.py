"""Where the body went while a command was shown (``Edge.travel`` of the motor command graph; issue 18).

Kopp & Graeser's motor commands move parts relative to the root (root-relative coordinates, B&B §5.1), so a step
to the left and a step to the right with the same leg swings are the same commands. The motor command graph keeps,
with each edge, where the body went while it was shown (``Edge.travel``: the root's velocity in the body's frame at
each frame of ``Edge.shown``). These tests check that clips' edges carry their travel, that a learned graph with
travel is saved and loaded, and that an edge's travel must match its demonstration. The clips (side steps to the
left and to the right, a raise of the hand) are also the forward model's ranked candidates' data
(``tests/plugins/matchers/forward_model/test_ranking.py``).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import STICK_PARTS, write_stick_clip, write_stick_profile
from toolkit import ConfigError, create_plugin_manager
from toolkit.observe import compose_observer
from toolkit.recordings.profile import load_profile

PARTS = STICK_PARTS
STAND = np.array([[0.0, 1.0, 0.0], [0.0, 1.6, 0.1], [0.1, 0.5, 0.0], [-0.1, 0.5, 0.0], [0.3, 1.0, 0.0],
                  [0.1, 0.0, 0.0], [-0.1, 0.0, 0.0]])
SIDE = 0.6  # m/s: a side step's pace


def _side_steps(frames: int, vx: float, fps: float = 30.0) -> np.ndarray:
    """Side steps (world positions, heading 0: the body's frame is the world's): the feet lift and swing out and
    back once while the hand swings up; the root travels sideways at ``vx`` m/s (+x: the body's left). The
    root-relative poses do not depend on ``vx``."""
    k = np.arange(frames)
    phase = np.sin(np.pi * k / (frames - 1))
    pose = np.repeat(STAND[None], frames, axis=0).copy()
    pose[:, 5, 1] += 0.15 * phase  # the left foot lifts
    pose[:, 5, 0] += 0.2 * phase   # and swings out
    pose[:, 6, 0] -= 0.1 * phase
    pose[:, 4, 1] += 0.3 * phase   # the hand swings up
    pose[:, :, 0] += vx * (k / fps)[:, None]
    return pose


def _raise(frames: int = 30) -> np.ndarray:
    pose = np.repeat(STAND[None], frames, axis=0).copy()
    pose[:, 4, 1] += 0.5 * np.sin(np.linspace(0, np.pi, frames))
    pose[:, 4, 2] += 0.3 * np.sin(np.linspace(0, np.pi, frames))
    return pose


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    """A repertoire: ``left`` and ``right`` (the same side steps, the body travelling to its left and to its right)
    and ``raise`` (a gesture on the spot); and a profile."""
    root = tmp_path_factory.mktemp("fmtravel")
    write_stick_clip(root / "repertoire" / "left" / "a.bvh", _side_steps(40, SIDE))
    write_stick_clip(root / "repertoire" / "right" / "a.bvh", _side_steps(40, -SIDE))
    write_stick_clip(root / "repertoire" / "raise" / "a.bvh", _raise())
    write_stick_profile(root)
    return root


def _observer(clips, **matcher):
    pm = create_plugin_manager(autoload=False, trace=False)
    profile = load_profile(clips / "profile.toml")
    return profile, compose_observer(pm, profile, clips / "repertoire", matcher="forward-model",
                                     lengths_for_height=0, settings={"matcher": {"comparison": "strokes", "learn": False, **matcher}})


def test_a_clips_edges_carry_where_the_body_went(clips):
    _, observer = _observer(clips)
    motor = observer.motor
    for movement, vx in (("left", SIDE), ("right", -SIDE), ("raise", 0.0)):
        (sequence,) = [n for n, label in motor.labels.items() if label == movement]
        for name in motor.sequences[sequence]:
            edge = motor.edge(name)
            assert edge.travel.shape == (len(edge.shown), 3)
            inner = edge.travel[2:-2] if len(edge.travel) > 6 else edge.travel  # the ends' one-sided differences
            assert np.allclose(inner, [vx, 0.0, 0.0], atol=0.05)


def test_a_graph_learned_with_travel_is_saved_and_loaded(clips):
    """Edges learned by watching keep their travel through get_state and set_state (as JSON would carry it)."""
    import json

    _, observer = _observer(clips)
    motor = observer.motor
    observed = _raise(24)[:, 1:]
    travel = np.tile([0.0, 0.0, 1.0], (len(observed), 1)) + np.linspace(0, 0.2, len(observed))[:, None]
    names = motor.learn_observed("body", "hub", observed, 30.0, travel=travel)
    state = json.loads(json.dumps(motor.get_state()))
    _, fresh = _observer(clips)
    fresh.motor.set_state(state)
    for name in names:
        assert np.allclose(fresh.motor.edge(name).travel, motor.edge(name).travel, atol=1e-6)
    first = fresh.motor.edge(names[0]).travel
    assert np.allclose(first, travel[: len(first)], atol=1e-6)  # the rows of the frames it was learned from
    bad = json.loads(json.dumps(state))
    edge = next(e for e in bad["body"]["edges"] if "travel" in e)
    edge["travel"] = edge["travel"][:-1]
    with pytest.raises(ConfigError, match="invalid travel"):
        fresh.motor.set_state(bad)


def test_an_edges_travel_must_match_its_demonstration(clips):
    _, observer = _observer(clips)
    motor = observer.motor
    observed = _raise(24)[:, 1:]
    with pytest.raises(ValueError, match="travel"):
        motor.learn("body", "hub", [], shown=observed, shown_fps=30.0, travel=np.zeros((3, 3)))
