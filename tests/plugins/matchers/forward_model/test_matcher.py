"""The matcher as the watching loop uses it (:mod:`plugins.matchers.forward_model.matcher`): its shortcuts (issue 22)
give the answers of the plain computation, to the bit, and the compiled loops those of numpy's steps.

- a segment in which every subsystem is followed and no track has a candidate or a commitment left returns at once
  each frame (:meth:`ForwardModel._quiet`), without placing the rows (placed at the end, the same values);
- one-command candidates are extended at once from the stacked strokes (:meth:`Predictions.extended_at_once`);
- the stacked strokes' point counts come from one binary search over complex keys (:func:`tables.row_keys`), not
  from comparing every point;
- the anchors and the points along the table of every stroke come from compiled loops (numba) or from numpy's steps
  when numba is absent (:func:`helpers.kernels`): velocity-direction + the forward model watch the project's
  generated streams both ways, with learning (so learned edges are predicted too), and every observation, the
  matcher's state after every segment (candidates, traces, anchors to the bit) and the motor graph's edges are the
  same.

Each is compared with the plain way on Fig. 3's games and on demonstrations, every answer and every frame's trace.
The variants the parameters choose (the clock, the subsystems followed, the learning) are chosen again when the
parameters are replaced.
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.bench.mocap import _streams
from plugins.matchers.forward_model import ForwardModel, tables
from plugins.matchers.forward_model.prediction import Predictions
from plugins.matchers.forward_model.speed import Elapsed, PathLength
from plugins.matchers.forward_model.tracks import EveryMoving, FirstToMove
from tests.plugins.matchers.forward_model.helpers import both_ways, kernels, play_fig3_games, random_strokes
from tests.toolkit.test_watching_settled import data, pm_, profile, watched  # noqa: F401 (fixtures)
from toolkit import Motion
from toolkit.observe import compose_observer
from toolkit.watching import follow


def _demonstrations(write, pm, monkeypatch, fast: bool):
    """The two-wrist body with five commands from the hub and the paper's threshold, shown a sequence of
    demonstrations frame by frame (:func:`~toolkit.watching.follow`): a command as learned, one at another speed,
    movements no command explains (every candidate drops out: learned), one that begins like a command and goes
    elsewhere; every answer and the matcher's view after each, with the shortcuts or without."""
    used = _shortcuts(monkeypatch, fast)
    character, names = random_strokes(write, pm, strokes=5, seed=7, threshold=0.05)
    matcher, motor = character.matcher, character.motor
    rest, rng = motor.rest, np.random.default_rng(11)
    parts = character.body.parts

    def along(name: str, n: int, speed: float = 1.0) -> np.ndarray:
        edge = motor.edge(name)
        t = np.minimum(np.arange(n) / 30.0 * speed, edge.duration)
        frames = np.repeat(rest[None], n, axis=0)
        for j, part in enumerate((2, 3)):
            frames[:, part] = edge.commands[j].position(t)
        return frames

    shows = [along(names[0], 35), along(names[2], 25, 1.3), along(names[4], 40, 0.8)]
    away = np.repeat(rest[None], 30, axis=0)
    away[:, 2] += np.linspace(0.0, 1.0, 30)[:, None] * rng.normal(0, 0.4, 3)
    shows.append(away)
    turn = along(names[1], 30)
    turn[15:, 2] = turn[15, 2] + np.linspace(0.0, 1.0, 15)[:, None] * np.array([0.0, 0.3, 0.0])
    shows.append(turn)
    shows.append(along(names[3], 30) + rng.normal(0, 0.003, (30, 4, 3)))
    answers = []
    for frames in shows:
        motion = Motion(frames - rest[0], 30.0, parts, np.ones(frames.shape[:2], dtype=bool))
        early, late = follow(matcher, motion)
        view = matcher.inspect()
        answers.append((repr(early), repr(late), repr(view["trace"]), repr(view["anchors"]), view["committed"],
                        view["committed_path"], view["committed_at"], view["deviated_at"]))
    return answers, used


def test_the_shortcuts_give_the_same_answers_on_demonstrations(write, pm):
    (fast, used), (plain, _) = both_ways(lambda monkeypatch, on: _demonstrations(write, pm, monkeypatch, on))
    assert used["quiet"] > 0 and used["at_once"] > 0  # both shortcuts were taken
    assert fast == plain


def _shortcuts(monkeypatch, fast: bool) -> dict[str, int]:
    """Count the shortcuts taken (``fast``), or replace them by the plain computation."""

    used = {"quiet": 0, "at_once": 0}
    quiet, at_once = ForwardModel._quiet, Predictions.extended_at_once

    def counted_quiet(self, tracks):
        answer = quiet(self, tracks) and fast
        used["quiet"] += answer
        return answer

    def counted_at_once(self, track, paths, lengths):
        if not fast:  # the loop of extended, path by path
            out = []
            for path in paths:
                lead = self.tables.lead(path[0])
                seen = self.anchors.along(track, path[0], lengths)[lead]
                total = sum(self.tables.edge(e).arcs[lead, -1] for e in path)
                out.extend(self.next(track, path) if seen > total + 0.01 / track.scale else [path])
            return out
        used["at_once"] += 1
        return at_once(self, track, paths, lengths)

    monkeypatch.setattr(ForwardModel, "_quiet", counted_quiet)
    monkeypatch.setattr(Predictions, "extended_at_once", counted_at_once)
    if not fast:
        monkeypatch.setattr(tables, "row_keys", lambda arcs, first=0: None)
    return used


def _play(monkeypatch, fast: bool):
    """Fig. 3's games: every answer, and each frame's view of the matcher; with the shortcuts, or without."""
    used = _shortcuts(monkeypatch, fast)

    matches, seen = play_fig3_games(lambda view: (view["frames"], repr(view["trace"]), view["committed"],
                                                  view["committed_path"], view["committed_at"], view["deviated_at"],
                                                  repr(view["anchors"])))
    return matches, seen, used


@pytest.fixture(scope="module")
def plays():
    return both_ways(_play)  # with the shortcuts, then without


def test_the_shortcuts_give_the_same_answers_and_traces_to_the_bit(plays):
    (matches, seen, _), (matches_plain, seen_plain, _) = plays
    assert matches and matches == matches_plain
    assert seen == seen_plain


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


def test_the_variants_are_chosen_again_when_the_parameters_are_replaced(write, pm):
    """The clock, the subsystems followed and the learning are chosen when the matcher is attached, and again at
    the next segment when its parameters were replaced (as a scenario's test may replace them)."""
    character, names = random_strokes(write, pm)
    matcher = character.matcher
    assert isinstance(matcher.clock, PathLength) and isinstance(matcher.tracking.following, EveryMoving)
    assert matcher.learning is not None
    matcher.params = {**matcher.params, "reparameterise": False, "together": False, "learn": False}
    rest = character.motor.rest
    frames = np.repeat(rest[None], 5, axis=0)
    follow(matcher, Motion(frames - rest[0], 30.0, character.body.parts))
    assert isinstance(matcher.clock, Elapsed) and isinstance(matcher.tracking.following, FirstToMove)
    assert matcher.learning is None
