"""The forward model compares in the demonstrator's own style, estimated online (issue 18; K&G §4.4, §6; B&B §7.1):
``posture`` and ``tempo`` of ``forward-model`` (:mod:`plugins.lib.online_style`).

On the hand-built ``arms`` graph of ``tests/test_forward_model.py`` (``out``: the left wrist 30 cm along x in one
second): ``out`` performed from a shifted posture is followed to its end with the posture removed, and its imitation
is stopped (a deviation, Fig. 3) without it; at half the pace the fitted pace is a half; a command that moves a part
the demonstrator keeps still predicts it moving on the fitted pace's clock, and not on each part's path length;
performed as learned, every setting answers as the paper's comparison does.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.test_forward_model import arms, demonstration, stroke_path  # noqa: F401 (arms: the fixture)
from tests.test_forward_model_relative import use
from toolkit.watching import feed

E = {"dropout": "relative", "error": "moving", "relative": True, "learn": False}
"""The displacements' comparison the styled settings are added to (fm18's best, without travel)."""

STYLED = {"tempo": 2.0, "posture": "removed"}
"""The values fixed before any run: the factor the posegraph's ``tempo`` allows, and the posture removed."""


def follow(arms, path: np.ndarray, **params):
    """``path`` (the left wrist) demonstrated and followed to its end: the answers, the matcher."""
    arms.motor.reset()
    matcher = use(arms, **{**E, "posture": "kept", "tempo": 0.0, **params})
    demo = demonstration(arms, path)
    answers = [a for a in feed(matcher, demo) if a is not None]
    matcher.conclude(demo)
    return answers, matcher


def fitted(matcher, arms) -> dict:
    """What the styled comparison fitted last for ``out`` (its pace, error)."""
    return matcher.tracks["wrists"].styled[(arms.out,)].extra


def test_out_from_a_shifted_posture_is_followed_with_posture_removed_and_stopped_without(arms):
    """Positions (``relative`` off): the wrist held 5 cm lower and 5 cm forward through ``out``."""
    path = stroke_path(arms.motor.rest[2] + [0.0, -0.05, 0.05], [0.3, 0.0, 0.0])
    _, matcher = follow(arms, path, relative=False)
    assert matcher.inspect()["deviated"]
    answers, matcher = follow(arms, path, relative=False, posture="removed")
    assert [a.path for a in answers] == [(arms.out,)] and not matcher.inspect()["deviated"]


def test_at_half_the_pace_the_pace_fitted_is_a_half(arms):
    """``out`` over two seconds: with ``tempo`` the command is predicted at half its own pace (the grid's 0.5), and
    followed to its end, as the path-length clock of §4.4 does without it."""
    path = stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0], 2.0)
    for params in ({}, {"tempo": 2.0}, STYLED):
        answers, matcher = follow(arms, path, **params)
        assert [a.path for a in answers] == [(arms.out,)] and not matcher.inspect()["deviated"]
    assert fitted(matcher, arms)["pace"] == pytest.approx(0.5)
    _, matcher = follow(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0]), **STYLED)
    assert fitted(matcher, arms)["pace"] == pytest.approx(1.0)


def test_a_command_moving_a_part_held_still_is_told_apart_on_the_paces_clock_and_not_on_each_parts(arms):
    """``both`` moves the left wrist as ``out`` does and the right wrist 30 cm down. The demonstration moves only the
    left: on each part's path length (the default) ``both``'s right wrist is predicted where it is seen (it has walked
    no path), so ``both`` predicts as well as ``out`` and neither prevails until the end; on the fitted pace's clock
    the right wrist is predicted moving, ``both`` drops out and ``out`` is committed to early."""
    from plugins.lib.guiding_stroke import GuidingStroke

    motor = arms.motor
    left, right = motor.rest[2], motor.rest[3]
    both = motor.learn("wrists", "hub", [GuidingStroke(left, left + [0.3, 0.0, 0.0], 1.0),
                                         GuidingStroke(right, right + [0.0, -0.3, 0.0], 1.0)])
    path = stroke_path(left, [0.3, 0.0, 0.0])
    answers, matcher = follow(arms, path)
    assert not answers  # both alive to the end: the race's leader, not a commitment
    assert matcher.inspect()["trace"][-1][1][(both,)] < 0.02
    answers, matcher = follow(arms, path, tempo=2.0)
    assert [a.path for a in answers] == [(arms.out,)] and answers[0].decided_at <= 0.5 * len(path)
    assert (both,) not in matcher.tracks["wrists"].candidates  # dropped out


def test_out_as_learned_keeps_its_answer_under_every_setting(arms):
    path = stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0])
    plain, _ = follow(arms, path)
    for params in ({"tempo": 2.0}, {"posture": "removed"}, STYLED):
        answers, matcher = follow(arms, path, **params)
        assert [a.path for a in answers] == [a.path for a in plain] and not matcher.inspect()["deviated"]
        assert answers[0].decided_at <= 0.5 * len(path)  # early (a wrong candidate's extent may match: later)
        assert fitted(matcher, arms)["error"] < 0.01


def test_the_paper_settings_leave_the_styled_fits_empty(arms):
    """Off (the plugin's defaults), nothing of the styled comparison is computed."""
    arms.motor.reset()
    matcher = use(arms, dropout="absolute", error="max", relative=False, posture="kept", tempo=0.0, learn=False)
    list(feed(matcher, demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0]))))
    assert matcher.tracks["wrists"].styled == {} and matcher.tracks["wrists"].seen is None


def test_unexplained_compares_with_standing_still_in_the_same_styled_way(arms):
    """With the posture removed, predicting that nothing moves is compared as the candidates are (each part about
    its mean over the frames seen): a movement inwards and down, 135 degrees from both edges, is explained by
    neither (unknown, whatever the ceiling), and ``out`` itself is explained and committed to early."""
    rest = arms.motor.rest[2]
    params = {**STYLED, "unexplained": 1.0, "ceiling": 10.0}
    answers, matcher = follow(arms, stroke_path(rest, [-0.25, -0.25, 0.0]), **params)
    assert not answers
    away = demonstration(arms, stroke_path(rest, [-0.25, -0.25, 0.0]))
    arms.motor.reset()
    matcher = use(arms, **{**E, **params})
    list(feed(matcher, away))
    assert matcher.conclude(away).movement is None
    answers, _ = follow(arms, stroke_path(rest, [0.3, 0.0, 0.0]), **params)
    assert [a.path for a in answers] == [(arms.out,)] and answers[0].decided_at <= 0.5 * 31
