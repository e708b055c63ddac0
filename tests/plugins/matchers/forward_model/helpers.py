"""What the forward model's tests share: a motor command graph small enough to work out by hand, and ways to run the
matcher with and without its shortcuts.

The two-wrist body ``ARMS``: one subsystem, both wrists; the tests learn straight guiding strokes of one second
(minimum-jerk profile) from its hub. :func:`kernels` runs the compiled loops as numba's, as their plain-Python
references or as numpy's steps; :func:`both_ways` plays something with a shortcut on and off;
:func:`play_fig3_games` plays Fig. 3's games.
"""

from __future__ import annotations

import contextlib

import numpy as np
import pytest

from plugins.lib.guiding_stroke import GuidingStroke
from plugins.matchers.forward_model import anchors, tables
from tests.conftest import CHARACTERS
from toolkit import Motion, create_plugin_manager, hookimpl, load_character, load_scenario

ARMS = """
[character]
name = "Arms"

[body]
parts = ["root", "head", "left_wrist", "right_wrist"]
root = "root"
facing = { left = "left_wrist", right = "right_wrist", forward = "head" }

[motor]
plugin = "motor-command-graph"
rest = "rest"
subsystems = { wrists = ["left_wrist", "right_wrist"] }
hands = false
arms = []

[motor.poses.rest]
root = [0.0, 1.0, 0.0]
head = [0.0, 1.6, 0.1]
left_wrist = [0.25, 0.9, 0.05]
right_wrist = [-0.25, 0.9, 0.05]

[matcher]
plugin = "forward-model"
"""

FPS = 30.0
THRESHOLD = 0.05


def out_and_up(write, pm, matcher: str = ""):
    """The two-wrist body with two edges from the hub: ``out`` moves the left wrist 30 cm to the side, ``up`` 30 cm
    up; the right wrist holds still. The character, with ``out`` and ``up`` (the edges' names) set on it. ``matcher``:
    more of the [matcher] table (TOML lines)."""
    character = load_character(write("arms.toml", ARMS + matcher), pm)
    motor = character.motor
    left, right = motor.rest[2], motor.rest[3]
    hold = GuidingStroke(right, right, 1.0)
    character.out = motor.learn("wrists", "hub", [GuidingStroke(left, left + [0.3, 0.0, 0.0], 1.0), hold])
    character.up = motor.learn("wrists", "hub", [GuidingStroke(left, left + [0.0, 0.3, 0.0], 1.0), hold])
    return character


def random_strokes(write, pm, *, strokes: int = 4, seed: int = 0, threshold: float = 10.0):
    """The two-wrist body with ``strokes`` random one-second commands from the hub (the right wrist held still in
    every other one); the character and the commands' names."""
    text = ARMS + f'threshold = {threshold}\n'
    character = load_character(write("arms.toml", text), pm)
    motor, rng = character.motor, np.random.default_rng(seed)
    left, right = motor.rest[2], motor.rest[3]
    names = []
    for i in range(strokes):  # the right wrist moves a little, or holds still (a stroke of no length)
        held = right + (rng.normal(0, 0.05, 3) if i % 2 else 0.0)
        names.append(motor.learn("wrists", "hub", [GuidingStroke(left, left + rng.normal(0, 0.2, 3), 1.0),
                                                   GuidingStroke(right, held, 1.0)]))
    return character, names


def demonstration(character, left_path: np.ndarray) -> Motion:
    """The left wrist along ``left_path`` (n, 3) in the body frame, everything else at rest; root-relative."""
    rest = character.motor.rest
    frames = np.repeat(rest[None], len(left_path), axis=0)
    frames[:, 2] = left_path
    return Motion(frames - rest[0], FPS, character.body.parts)


def stroke_path(start: np.ndarray, chord, duration: float = 1.0) -> np.ndarray:
    return GuidingStroke(start, start + np.asarray(chord, dtype=float), duration).trajectory(FPS)


KERNELS = ("compiled", "python", "numpy")
"""How :class:`~plugins.matchers.forward_model.anchors.Halves` and
:class:`~plugins.matchers.forward_model.tables.StrokeRows` compute: numba's compiled loops, the same loops run as
plain Python (the references they are compiled from), or numpy's steps (numba absent)."""


@contextlib.contextmanager
def kernels(mode: str):
    """A context in which the forward model's loops run as ``mode`` says (:data:`KERNELS`)."""
    with pytest.MonkeyPatch.context() as patch:
        if mode == "python":
            patch.setattr(anchors, "_kernel", lambda: anchors.place_rows)
            patch.setattr(tables, "_kernel", lambda: tables.along_table)
        elif mode == "numpy":
            patch.setattr(anchors, "_kernel", lambda: None)
            patch.setattr(tables, "_kernel", lambda: None)
        else:
            assert anchors._kernel() is not None and tables._kernel() is not None, \
                "numba is a dependency: the compiled loops must be there"
        yield


def both_ways(play, *args):
    """``play(monkeypatch, *args, on)`` with a shortcut on, then off, each under a monkeypatch of its own."""
    out = []
    for on in (True, False):
        with pytest.MonkeyPatch.context() as monkeypatch:
            out.append(play(monkeypatch, *args, on))
    return tuple(out)


def play_fig3_games(snapshot):
    """Fig. 3's games played once: every answer Max gives, and ``snapshot(view)`` of the forward model's
    ``inspect()`` after each world step in which it holds a segment."""

    class Traces:
        def __init__(self) -> None:
            self.seen: list = []

        @hookimpl
        def likeme_world_stepped(self, world):
            matcher = world.actors["max"].character.matcher
            if matcher.observation.memory is not None:
                self.seen.append(snapshot(matcher.inspect()))

    pm = create_plugin_manager(autoload=False)
    traces = Traces()
    pm.register(traces, name="traces")
    world = load_scenario(CHARACTERS / "scenarios" / "fig3_games.toml", pm).run()
    matches = [(m.movement, m.confidence, m.decided_at, m.path, repr(m.details))
               for m in (e.data["match"] for e in world.events_of("movement_recognised", "max"))]
    return matches, traces.seen
